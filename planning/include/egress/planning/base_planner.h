#pragma once
/// @file
/// BasePlanner: OMPL planning of the omnidirectional base over SE(2).
///  - Validity (FootprintValidityChecker): the round footprint touches no obstacle of the
///    costmap (the centre cell's cost is below kInscribedCost, which encodes the robot radius)
///    and, when an OctoMap is given, the robot's 3D outline (SetBodyShapes: base, torso at its
///    lift, the arm as posed, a held payload; by default an FCL cylinder of the footprint) does
///    not collide with it; when carrying, the arm's swept box is checked too. Motions are checked
///    at the costmap's cell size.
///  - Planner by name (RRTConnect default; RRTstar, PRMstar, BITstar, InformedRRTstar use the
///    time budget to improve), objective path length plus optional costmap cost; shortcutting
///    and smoothing, then a check that the simplified path is still valid.
///  - A path through a known door runs on the door's centreline: an approach pose in front of
///    the door, an exit pose behind it; the result lists the doors crossed.
///  - Narrow passages: when sampling finds nothing within grid_seed_after, the grid shortest
///    path, shortcut by OMPL's simplifier, is the answer.
///  - Failures are statuses with reasons: start or goal in collision, goal unreachable (no
///    free connection on the costmap grid, e.g. a closed door), timeout, invalid request.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <octomap/OcTree.h>

#include "egress/hsr_interface/clock.h"
#include "egress/hsr_interface/geometry.h"
#include "egress/hsr_interface/robot_model.h"
#include "egress/perception/costmap.h"

namespace egress::planning {

/// A box the arm sweeps while carrying, in the base frame: centre offset and full size [m].
struct CarryBox {
  Eigen::Vector3d p_BBox{0.35, 0.0, 0.8};
  Eigen::Vector3d size{0.25, 0.2, 0.3};
};

struct BasePlannerConfig {
  std::string planner{"RRTConnect"};  ///< RRTConnect, RRTstar, PRMstar, BITstar, InformedRRTstar.
  double time_budget{1.0};            ///< [s] wall time; optimizing planners use all of it.
  double simplify_time{0.05};         ///< [s] for shortcutting and smoothing.
  double footprint_radius{0.215};     ///< FCL cylinder radius [m] (the costmap has its own).
  double robot_height{1.35};          ///< FCL cylinder height [m].
  std::optional<CarryBox> carry;      ///< Checked when set.
  double costmap_cost_weight{0.0};    ///< > 0 adds the costmap cost to the objective.
  bool allow_unknown{false};          ///< Plan through unknown cells.
  double door_standoff{0.6};          ///< Approach/exit poses this far from the door line [m].
  /// Narrow passages (1-cell doors, maze corridors) defeat sampling: when the planner finds
  /// nothing within this time, the grid's shortest path seeds the answer and OMPL's simplifier
  /// shortcuts it (the result is re-checked). 0 disables the fallback (pure sampling).
  double grid_seed_after{0.25};  ///< [s]
  std::uint32_t seed{42};        ///< OMPL's process-wide seed (set once per process).
  /// Skip sampling and use the string-pulled grid path alone (still checked by the validity
  /// checker): a pure function of the costmap, for lock-step simulation where a run must be a
  /// pure function of its seed. Wall-clock budgets make sampling planners vary run to run.
  bool deterministic{false};
  /// Clearance of the grid path (the deterministic answer and the narrow-passage seed): it keeps
  /// clearance_margin beyond the footprint from obstacles where the free space allows — a grid
  /// step into a cell closer than that costs (1 + clearance_weight) times its length, and
  /// shortcutting never takes the path closer than the margin unless the grid path itself was.
  /// Why: a path string-pulled on validity alone grazes every corner and open leaf at exactly
  /// the footprint radius, with no room for localization error. Beyond the margin the path is
  /// the shortest, so it still passes close enough to see round corners. clearance_weight 0
  /// (the default): the plain shortest path, shortcut on validity alone. Off by default because
  /// the brain's judgement of a door someone holds depends on what it sees on the way: with the
  /// clearance on (weight 4), S7's robot, passing the cabinet wider, saw the held lab door late
  /// and pressed its button in 51 of 100 trials (issue 16's note).
  double clearance_margin{0.1};  ///< [m] beyond the footprint radius
  double clearance_weight{0.0};
  /// Proxemics: a grid step through a person's personal space (the costmap's proxemic layer)
  /// costs this much more per metre at the layer's peak (linearly less where the cost is lower),
  /// and shortcutting never takes the path deeper into anyone's space than the grid path went.
  /// The sampling planners' costmap objective (costmap_cost_weight > 0) weighs it the same way.
  /// 0: paths ignore personal space (they still never touch anyone: the laser marks people).
  double personal_space_weight{2.0};
  /// Doorways: a grid step into a known door's doorway (within door_standoff of its line, across
  /// its opening widened by the footprint radius on each side) costs this much more per metre,
  /// and a shortcut never runs further through doorways than the grid path it replaces. Why: a
  /// path along the wall that has a door in it runs the robot through that doorway lengthwise,
  /// where it blocks everyone using the door (it may stop there for people passing); crossing a
  /// doorway straight costs the same whatever the path, so a door on the way is still taken.
  /// 0: doorways cost nothing extra.
  double doorway_weight{2.0};
  void Validate() const;
};

enum class PlanStatus {
  kSuccess,
  kInvalidRequest,
  kStartInCollision,
  kGoalInCollision,
  kGoalUnreachable,
  kTimeout
};
std::string_view ToString(PlanStatus status);

struct PlanResult {
  PlanStatus status{PlanStatus::kInvalidRequest};
  std::string message;                     ///< The reason, for failures.
  std::vector<Pose2> path;                 ///< X_MB waypoints, start to goal.
  double length{0.0};                      ///< [m] in the plane.
  double planning_time{0.0};               ///< [s]
  std::vector<std::string> doors_crossed;  ///< In order along the path.
  bool ok() const { return status == PlanStatus::kSuccess; }
};

/// A door the planner knows: its jambs in M.
struct PlannerDoor {
  std::string id;
  Eigen::Vector2d p_MA{Eigen::Vector2d::Zero()};
  Eigen::Vector2d p_MB{Eigen::Vector2d::Zero()};
};

class BasePlanner {
 public:
  /// The costmap (and octree) must outlive the planner; they are read at each Plan, so updates
  /// between calls are seen. `clock` times the planning (a SteadyClock when null).
  BasePlanner(const perception::Costmap2D& costmap, std::shared_ptr<const octomap::OcTree> octree,
              BasePlannerConfig config = {}, std::shared_ptr<const Clock> clock = nullptr);
  ~BasePlanner();
  BasePlanner(BasePlanner&&) noexcept;
  BasePlanner& operator=(BasePlanner&&) noexcept;
  void AddDoor(const PlannerDoor& door);
  /// The robot's 3D outline for the OctoMap check, as shapes in B (RobotModel's collision
  /// shapes at the current arm pose, plus a held payload). Empty (the default): the config's
  /// footprint cylinder of robot_height. A pose is valid when no shape touches an occupied
  /// voxel; a bounding cylinder is tested first, so poses far from 3D obstacles cost one check.
  /// @throws InvalidArgument for a non-finite shape pose or size.
  void SetBodyShapes(std::vector<PlacedShape> shapes);

  PlanResult Plan(const Pose2& X_MB_start, const Pose2& X_MB_goal) const;
  /// Whether the footprint at X_MB is collision-free (costmap and OctoMap).
  bool IsValid(const Pose2& X_MB) const;
  /// Whether every motion of `path` is still valid (for replanning after a costmap update).
  bool IsPathValid(const std::vector<Pose2>& path) const;
  /// One row of RunOmplBenchmark's summary.
  struct BenchmarkSummary {
    std::string planner;
    int runs{0};
    int solved{0};
    double median_time{0.0};    ///< [s]
    double median_length{0.0};  ///< [m] over solved runs
  };
  /// Runs OMPL's own benchmark (ompl::tools::Benchmark) of `planners` on start -> goal with this
  /// planner's validity checking, `runs` times each with `time_limit` seconds, and writes OMPL's
  /// log format (Planner Arena reads it) to `log_path`. Door centrelines are not applied: this
  /// measures the sampling planners themselves.
  std::vector<BenchmarkSummary> RunOmplBenchmark(const Pose2& start, const Pose2& goal,
                                                 const std::vector<std::string>& planners, int runs,
                                                 double time_limit, const std::string& experiment,
                                                 const std::filesystem::path& log_path) const;
  /// Planner names accepted by config.planner.
  static std::vector<std::string> PlannerNames();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The shortest 8-connected grid path (cell centres, no corner cutting) between two points over
/// cells below kInscribedCost; nullopt if there is none.
std::optional<std::vector<Eigen::Vector2d>> GridShortestPath(const perception::Costmap2D& costmap,
                                                             const Eigen::Vector2d& start,
                                                             const Eigen::Vector2d& goal,
                                                             bool allow_unknown = false);
/// What a step of a grid path costs beyond its length.
struct GridStepCosts {
  /// A step into a cell of master cost >= close_cost costs (1 + close_weight) times its length.
  std::uint8_t close_cost{perception::kInscribedCost};
  double close_weight{0.0};
  /// ... plus personal_space_weight times its length times the cell's proxemic cost over
  /// kPersonalSpacePeakCost (0: people's personal space is not weighed).
  double personal_space_weight{0.0};
  /// ... plus doorway_weight times its length for a cell `doorway` marks (non-zero; row-major
  /// like the costmap's costs, or null: no doorways).
  const std::vector<std::uint8_t>* doorway{nullptr};
  double doorway_weight{0.0};
};
/// The costmap cells in any of `doors`' doorways (1, else 0; row-major like the costmap's
/// costs): within `depth` of the door line on either side, across its opening widened by
/// `widen` at each jamb.
std::vector<std::uint8_t> DoorwayCells(const perception::GridGeometry& geometry,
                                       const std::vector<PlannerDoor>& doors, double depth,
                                       double widen);
/// The cheapest 8-connected grid path (cell centres, no corner cutting) over cells below
/// kInscribedCost, each step weighted by `costs` (all weights 0: the shortest path); nullopt if
/// there is none. @throws InvalidArgument for a negative or non-finite weight.
std::optional<std::vector<Eigen::Vector2d>> GridCheapestPath(const perception::Costmap2D& costmap,
                                                             const Eigen::Vector2d& start,
                                                             const Eigen::Vector2d& goal,
                                                             const GridStepCosts& costs,
                                                             bool allow_unknown = false);
/// Length [m] of the shortest 8-connected grid path between two points over cells below
/// kInscribedCost (the reference for path quality); nullopt if there is none.
std::optional<double> GridShortestPathLength(const perception::Costmap2D& costmap,
                                             const Eigen::Vector2d& start,
                                             const Eigen::Vector2d& goal,
                                             bool allow_unknown = false);

}  // namespace egress::planning
