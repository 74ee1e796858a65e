#pragma once
/// @file
/// Costmap2D: the 2D world model the base planner reads. Layers, combined into one master grid:
///  - static: the occupancy map (walls);
///  - obstacle: marked and cleared by ray tracing each laser scan;
///  - projection: obstacles the laser misses, projected from the OctoMap (table tops, overhangs);
///  - door leaves: each known door's leaf at its current estimated angle;
///  - inflation: cost decaying with distance to the nearest lethal cell (Nav2's formula:
///    lethal at 0, kInscribedCost within the robot radius, 252·exp(−k·(d − r)) beyond);
///  - doorways: inside a known doorway's threshold the decaying part of the inflation is dropped
///    (only lethal and inscribed remain), so inflation never seals a door the robot fits through
///    — the paper's S7 failure;
///  - personal space (proxemics): a graded cost round each tracked person, now and where they
///    are predicted to walk. It is kept beside the master grid, not in it: it steers the
///    planner's paths (a cost per step) but never makes a pose invalid — the robot may still
///    pass someone standing in a doorway, only not by choice.
/// Updates are local: a scan recomputes only the window it touched plus the inflation margin.

#include <array>
#include <cstdint>
#include <initializer_list>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "egress/hsr_interface/sensor_types.h"
#include "egress/perception/occupancy_grid.h"

namespace egress::perception {

struct CostmapConfig {
  double robot_radius{0.215};        ///< Inscribed radius of the round footprint [m].
  double inflation_radius{0.55};     ///< Cost decays to 0 at this distance [m].
  double cost_scaling_factor{10.0};  ///< k in the exponential decay [1/m].
  double obstacle_max_range{2.5};    ///< Scan returns beyond this do not mark [m].
  double raytrace_max_range{3.0};    ///< Scan rays clear free space up to this range [m].
  /// A mark farther from the laser than raytrace_max_range can be cleared by no scan: once the
  /// robot has moved away, someone who walked on would stay in the map for good (Nav2 keeps
  /// such marks until the robot comes back). Such a mark is forgotten this long after a scan
  /// last marked it [s]; a mark within clearing range is cleared by the rays as before.
  double unseen_mark_lifetime{15.0};
  /// @throws InvalidArgument naming the field.
  void Validate() const;
};

/// A doorway: the two jambs in M. The leaf (if any) hangs on `p_MHinge`'s jamb and swings to
/// the side given by `swing_sign` (+1: counter-clockwise from the closed line, seen from above).
struct Doorway {
  std::string id;
  Eigen::Vector2d p_MHinge{Eigen::Vector2d::Zero()};  ///< Hinge-side jamb [m].
  Eigen::Vector2d p_MLatch{Eigen::Vector2d::Zero()};  ///< Latch-side jamb [m].
  double swing_sign{1.0};
  double threshold_depth{
      0.3};  ///< How far the threshold zone reaches each side of the door line [m].
  double width() const { return (p_MLatch - p_MHinge).norm(); }
};

/// One person's personal space for the proxemic layer, seen from the robot's centre: the cost
/// is the layer's peak (times `weight`) within `inner` of the person's centre, falls linearly to
/// 0 at `outer`. A prediction counts less (weight < 1) the further ahead it is.
struct PersonalSpace {
  Eigen::Vector2d p_MP{Eigen::Vector2d::Zero()};  ///< The person's centre in M [m].
  double inner{0.9};                              ///< [m], >= 0
  double outer{1.7};                              ///< [m], > inner
  double weight{1.0};                             ///< in (0, 1]
};

/// The proxemic layer's highest cost: one below inscribed, so it never reads as a collision.
inline constexpr std::uint8_t kPersonalSpacePeakCost = kInscribedCost - 1;

class Costmap2D {
 public:
  /// A costmap the size of `static_map`. @throws InvalidArgument for a bad config.
  Costmap2D(const OccupancyGrid& static_map, CostmapConfig config = {});

  /// Marks returns within obstacle_max_range and clears cells along every ray (up to
  /// raytrace_max_range); forgets marks out of clearing range that no scan has marked for
  /// unseen_mark_lifetime (the scan's stamp is the clock). X_ML is the laser's pose in M at
  /// the scan's time.
  /// @throws InvalidArgument for an invalid scan or pose.
  void UpdateWithScan(const LaserScan& scan, const Pose2& X_ML);
  /// Replaces the projected 3D obstacles (points in M).
  void SetProjectedObstacles(const std::vector<Eigen::Vector2d>& p_MObstacles);
  /// Whether a cell of the static map, the laser's obstacle layer or a door leaf within
  /// `radius` of p_MQ is lethal: something the costmap knows without the projection layer.
  bool IsNearSensedObstacle(const Eigen::Vector2d& p_MQ, double radius) const;
  /// Whether a lethal cell of the static map or of a door leaf is within `radius` of p_MQ: what
  /// the building explains (a laser return beyond it is someone or something not on the map).
  bool IsNearMappedObstacle(const Eigen::Vector2d& p_MQ, double radius) const;
  /// Whether a cell the laser marked (the obstacle layer) lies within `radius` of p_MQ and
  /// farther than `off_map` from every lethal cell of the static map and the door leaves:
  /// something the building does not explain, as a scan's returns off the map — remembered
  /// where no ray has cleared it since (behind the robot, out of the laser's view).
  bool IsNearUnmappedMark(const Eigen::Vector2d& p_MQ, double radius, double off_map) const;
  /// Replaces the proxemic layer with `spaces` (overlapping spaces keep the higher cost). The
  /// cells are filled when the layer is next read (a hundred people's spaces take milliseconds
  /// to paint, and most control ticks plan nothing).
  /// @throws InvalidArgument naming the space and field: a non-finite centre, inner < 0,
  /// outer <= inner, a weight outside (0, 1], or an outer radius over kMaxPersonalSpaceM.
  void SetPersonalSpaces(const std::vector<PersonalSpace>& spaces);
  /// The proxemic layer's cost of the cell holding p_MQ (0 outside every space or the map).
  std::uint8_t PersonalSpaceCostAt(const Eigen::Vector2d& p_MQ) const;
  /// The proxemic layer, row-major like costs().
  const std::vector<std::uint8_t>& personal_space_costs() const;
  static constexpr double kMaxPersonalSpaceM = 5.0;

  /// Clears the obstacle layer (e.g. after relocalization).
  void ClearObstacles();

  /// Adds a known doorway. @throws InvalidArgument if its id exists or its jambs coincide.
  void AddDoorway(const Doorway& doorway);
  /// Marks the leaf of doorway `id` at `angle` [rad] from closed (0 = closed; nullopt removes it:
  /// no leaf or unknown). @throws InvalidArgument for an unknown id.
  void SetDoorLeafAngle(const std::string& id, std::optional<double> angle);
  const std::map<std::string, Doorway>& doorways() const { return doorways_; }

  /// Cost of the cell holding p_MQ (kUnknownCost outside the map).
  std::uint8_t CostAt(const Eigen::Vector2d& p_MQ) const;
  /// Highest cost over the round footprint centred at X_MB (kUnknownCost if it leaves the map).
  std::uint8_t FootprintCost(const Pose2& X_MB) const;
  /// True when the robot centred at p_MB touches no obstacle (centre cost below inscribed).
  bool IsFree(const Eigen::Vector2d& p_MB) const { return CostAt(p_MB) < kInscribedCost; }

  const GridGeometry& geometry() const { return geometry_; }
  const CostmapConfig& config() const { return config_; }
  /// The master grid, row-major (see GridGeometry).
  const std::vector<std::uint8_t>& costs() const { return master_; }
  /// The inflation's cost at `distance` [m] from the nearest lethal cell (lethal at 0,
  /// kInscribedCost within the robot radius, the exponential decay beyond, free past
  /// inflation_radius): what a cell that far from an obstacle costs.
  std::uint8_t InflatedCost(double distance) const;
  /// The master grid as an 8-bit image, row 0 = highest y (for PNG output); a free cell in
  /// someone's personal space shows the proxemic layer's cost.
  cv::Mat ToImage() const;

 private:
  void RecomputeWindow(int x0, int y0, int x1, int y1);
  // Whether a lethal cell of any of `layers` is within `radius` of p_MQ.
  bool IsNearLethal(const Eigen::Vector2d& p_MQ, double radius,
                    std::initializer_list<const std::vector<std::uint8_t>*> layers) const;
  void MarkLeaf(const Doorway& doorway, double angle, std::uint8_t value);
  // Clears the marks farther than raytrace_max_range from p_MO last marked before
  // now - unseen_mark_lifetime; `touch` widens the window to recompute.
  template <typename Touch>
  void ForgetUnseenMarks(double now, const Eigen::Vector2d& p_MO, Touch&& touch);

  CostmapConfig config_;
  GridGeometry geometry_;
  std::vector<std::uint8_t> static_;
  /// Per cell: the squared distance [cells²] to the nearest lethal cell of static_ (exact; a
  /// large value where there is none), so IsNearLethal answers for the map without a search.
  std::vector<std::uint32_t> static_lethal_d2_;
  std::vector<std::uint8_t> obstacle_;
  std::vector<double> marked_at_;    ///< When a scan last marked each obstacle cell [s].
  std::vector<std::size_t> marked_;  ///< The cells a scan marked, each once (some since cleared).
  std::vector<std::uint8_t> in_marked_;  ///< 1 for a cell in marked_.
  std::vector<std::uint8_t> projection_;
  std::vector<std::uint8_t> leaves_;
  /// The cells [x0, y0, x1, y1] each marked leaf may cover at any angle (its hinge +- its width):
  /// leaves_ has no lethal cell outside them.
  std::vector<std::array<int, 4>> leaf_cell_boxes_;
  std::vector<std::uint8_t> doorway_zone_;  ///< 1 inside a doorway threshold.
  std::vector<std::uint8_t> master_;
  std::vector<Eigen::Vector2i> projected_cells_;
  // The proxemic layer: the spaces last set, painted into personal_space_ on the first read.
  void PaintPersonalSpaces() const;
  std::vector<PersonalSpace> personal_spaces_;
  mutable bool personal_space_painted_{true};
  mutable std::vector<std::uint8_t> personal_space_;
  mutable std::vector<std::size_t> personal_space_cells_;  ///< cells set in personal_space_
  std::map<std::string, Doorway> doorways_;
  std::map<std::string, double> leaf_angles_;
  std::vector<std::uint8_t> inflation_lookup_;  // cost by distance in 1/8 cells
};

}  // namespace egress::perception
