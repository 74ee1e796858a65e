#pragma once
/// @file
/// LaserPersonDetector: people in one base-laser scan (270°, all round the robot), where the
/// head camera (58°) may not be looking. At laser height (~0.2 m) a person shows as one or two
/// legs (arcs 5-25 cm wide) or, in a long coat, a wheelchair or the twin's capsule bodies, as a
/// body section (an arc up to ~0.7 m wide). The scan's returns off the map (`is_background`
/// false) are split into clusters of neighbouring beams; clusters are classified by width, legs
/// within a stride of each other are paired into one person, and a body section's centre is
/// found by a circle fit (the laser sees only its near side). Points in M (the map frame).
///
/// Straight runs of returns (a box's face) and box corners of faces 0.4 m or more are not
/// bodies: their circle fits leave more than `body_max_residual`.
///
/// A leg-wide cluster on the scan's first or last beam (a 270° scan's edges) may be a leg, or the
/// sliver of a wider body past the edge, whose centre lies a body's radius beyond it: it is
/// reported as a leg marked `at_edge` (and so is a pair with such a leg). Wider clusters there
/// are circle-fitted as anywhere.
///
/// What it cannot tell: a table leg from a person's leg, a round bin from a body, or a smaller
/// box corner (faces under ~0.4 m fit a circle within the range noise) from a body. The tracker
/// that consumes these detections (with the camera's) confirms people over several scans and by
/// motion.

#include <functional>
#include <vector>

#include <Eigen/Core>

#include "egress/hsr_interface/geometry.h"
#include "egress/hsr_interface/sensor_types.h"

namespace egress::perception {

struct LaserPersonDetectorConfig {
  double cluster_gap{0.12};       ///< Neighbouring returns farther apart start a new cluster [m].
  int min_points{3};              ///< Fewer returns than this: noise.
  double leg_min_width{0.04};     ///< A leg is at least this wide [m] ...
  double leg_max_width{0.25};     ///< ... and at most this; wider is a body section.
  double body_max_width{0.80};    ///< Wider than this is not a person (furniture, a wall) [m].
  double leg_pair_max_gap{0.50};  ///< Two legs of one person: centres at most this apart [m].
  double body_min_radius{0.10};   ///< Body sections fit circles of this radius ... [m]
  double body_max_radius{0.45};   ///< ... to this.
  /// ... within this RMS distance of their returns [m]: a box's corner (two straight faces)
  /// fits a circle of a body's radius too, 2-3 cm off; an arc fits to the range noise (1 cm).
  double body_max_residual{0.02};
  double max_range{10.0};  ///< Returns farther than this are left out [m].
  /// @throws InvalidArgument naming the field that is non-finite or out of order.
  void Validate() const;
};

struct LaserPersonDetection {
  Eigen::Vector2d p_MP{Eigen::Vector2d::Zero()};  ///< The person's centre in M [m].
  double radius{0.0};  ///< Estimated body radius [m] (half a leg pair's span for legs).
  int legs{0};         ///< 2: a pair of legs; 1: one leg seen; 0: a body section.
  int points{0};       ///< Returns that make it up.
  /// A leg-wide cluster cut by the field of view's edge: the person's centre may lie up to a
  /// body's radius further on (a wheelchair user's side seen past the edge).
  bool at_edge{false};
};

class LaserPersonDetector {
 public:
  explicit LaserPersonDetector(LaserPersonDetectorConfig config = {});

  /// People in `scan`, taken by a laser at X_ML. `is_background(p_M)` says a return lies on
  /// something mapped (walls, known door leaves); those are left out (none when null).
  /// @throws InvalidArgument for a malformed scan or a non-finite X_ML.
  /// `is_structure(points)`, if given, is asked of each cluster that could be a person; true
  /// leaves it out (a door leaf's edge seen off the map while its angle estimate lags).
  std::vector<LaserPersonDetection> Detect(
      const LaserScan& scan, const Pose2& X_ML,
      const std::function<bool(const Eigen::Vector2d&)>& is_background = {},
      const std::function<bool(const std::vector<Eigen::Vector2d>&)>& is_structure = {}) const;

  const LaserPersonDetectorConfig& config() const { return config_; }

 private:
  LaserPersonDetectorConfig config_;
};

}  // namespace egress::perception
