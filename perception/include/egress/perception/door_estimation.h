#pragma once
/// @file
/// Doors as a continuous angle (the paper's future work, and the fix for its S3 failure where a
/// half-open door was read as closed).
///  - FitLineRansac: robust line through laser points (RANSAC, then least squares on the
///    inliers) — for glass leaves, whose depth is invalid: the detector's box selects the
///    angular slice of the scan (BoxBearingsInLaser, ScanPointsInBearings).
///  - MeasureDoorAngle: the leaf angle from laser points near the hinge (median of their polar
///    angles about the hinge), or DoorAngleFromLine from a fitted leaf line.
///  - DoorStateTracker: smooths the angle over time and reports open_fraction, the clear width
///    of the opening, and the motion (closed, opening, open, held open, closing).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "egress/hsr_interface/geometry.h"
#include "egress/hsr_interface/sensor_types.h"

namespace egress::perception {

/// A hinged door in M: the hinge-side and latch-side jambs of the closed leaf.
struct DoorModel {
  std::string id;
  Eigen::Vector2d p_MHinge{Eigen::Vector2d::Zero()};
  Eigen::Vector2d p_MLatch{Eigen::Vector2d::Zero()};
  double swing_sign{1.0};  ///< +1: the leaf opens counter-clockwise seen from above.
  double max_open_angle{1.5707963267948966};  ///< [rad]
  double width() const { return (p_MLatch - p_MHinge).norm(); }
  double closed_yaw() const;
  /// Unit normal of the door line pointing into the room the leaf opens into.
  Eigen::Vector2d SwingSide() const;
  /// Whether p_MQ lies on the swing side of the door line (or within `margin` behind it) and
  /// within width + margin of the hinge [m]: the half disc round the quarter disc the leaf turns
  /// through — what a moving leaf, or someone passing it, can reach.
  bool InSweep(const Eigen::Vector2d& p_MQ, double margin) const;
  /// Whether p_MQ lies within `margin` of the quarter disc the leaf itself turns through, from
  /// closed to max_open_angle [m]: wherever the leaf stands, its returns fall here, a wall at the
  /// hinge or not.
  bool InLeafReach(const Eigen::Vector2d& p_MQ, double margin) const;
  /// Whether p_MQ lies between the jambs, within `margin` of the door line on either side [m]:
  /// where the closed leaf stands (or someone in the doorway).
  bool OnDoorLine(const Eigen::Vector2d& p_MQ, double margin) const;
  /// Where the leaf's free edge is at `angle` [m, in M].
  Eigen::Vector2d LeafTip(double angle) const;
  /// Clear width of the opening at `angle`: w·(1 − cos θ) up to 90°, w beyond [m].
  double ClearanceWidth(double angle) const;
  void Validate() const;
};

struct LineFit {
  Eigen::Vector2d p_M{Eigen::Vector2d::Zero()};         ///< Centroid of the inliers [m].
  Eigen::Vector2d direction{Eigen::Vector2d::UnitX()};  ///< Unit direction.
  std::size_t inliers{0};
  double rms{0.0};  ///< RMS distance of the inliers to the line [m].
};

struct LineFitConfig {
  int iterations{100};
  double inlier_distance{0.03};  ///< [m]
  std::size_t min_inliers{5};
  std::uint64_t seed{7};
};

/// nullopt when fewer than min_inliers points support a line.
std::optional<LineFit> FitLineRansac(const std::vector<Eigen::Vector2d>& points,
                                     const LineFitConfig& config = {});

/// Bearings in the laser frame L (angle about +z from L's x axis) of the left and right edges
/// of a camera box, at the box's middle row. X_LC is the camera pose in L.
std::pair<double, double> BoxBearingsInLaser(const PixelBox& box,
                                             const CameraIntrinsics& intrinsics, const Pose3& X_LC);
/// Points in M of the valid returns whose bearing lies in [bearing_min, bearing_max].
std::vector<Eigen::Vector2d> ScanPointsInBearings(const LaserScan& scan, const Pose2& X_ML,
                                                  double bearing_min, double bearing_max);
/// Every valid return of the scan, in M.
std::vector<Eigen::Vector2d> ScanPoints(const LaserScan& scan, const Pose2& X_ML);
/// The unit direction in L of each beam of scans shaped as `scan` (cos and sin of AngleAt(i),
/// exactly): every scan of one laser shares them, so they are computed once per thread and
/// shape (angle_min, angle_increment, beam count) rather than twice per beam per scan. Valid
/// until the next call on this thread with another shape.
const std::vector<Eigen::Vector2d>& BeamDirections(const LaserScan& scan);

struct DoorAngleMeasurement {
  double angle{0.0};       ///< From closed [rad], in [0, max_open_angle].
  std::size_t support{0};  ///< Points that voted.
};

/// The leaf angle from points near the door: those between 15% and 95% of the leaf width from
/// the hinge, within the swept sector (±10° margin), vote with their polar angle in 3° bins; the
/// bins (with their neighbours) whose points spread furthest along the radius — a leaf, not a
/// person standing in the doorway — win, and their median angle is the measurement. nullopt
/// with fewer than `min_support` votes, or when the winning points span less than a quarter of
/// the leaf's width along the radius (leaf not seen, or hidden behind someone).
std::optional<DoorAngleMeasurement> MeasureDoorAngle(const DoorModel& door,
                                                     const std::vector<Eigen::Vector2d>& p_MPoints,
                                                     std::size_t min_support = 4);
/// The leaf angle of a fitted leaf line (a glass door): the line's direction (away from the
/// hinge) against the closed line, on the swing side, clamped to [0, max_open_angle]. nullopt
/// when the line cannot be the leaf: it misses the hinge by more than `hinge_tolerance` [m],
/// its inliers' centroid lies beyond the leaf or within an eighth of its width of the hinge
/// (the jamb), or it points more than 10° outside the leaf's range (a wall past the hinge).
std::optional<double> DoorAngleFromLine(const DoorModel& door, const LineFit& line,
                                        double hinge_tolerance = 0.1);

/// The leaf angle whose leaf (hinge to free edge) spans, seen from V, the bearings closest to
/// a detector box's edges `lo`, `hi` [rad, about V's z from its x axis] — for a glass leaf the
/// laser sees only near normal incidence, i.e. not once it swings open. V is the camera's
/// position with the bearings' axes (e.g. the laser frame's). An edge cut by the image border
/// is passed as nullopt. nullopt when the best angle misses the box by more than `max_error`
/// [rad, summed over the edges], or, with one edge, when that edge is not the free edge's or
/// lies within a few degrees of the hinge's bearing (then any angle explains it).
std::optional<double> DoorAngleFromBearings(const DoorModel& door, const Pose2& X_MV,
                                            std::optional<double> lo, std::optional<double> hi,
                                            double max_error = 0.15);

enum class DoorMotion { kUnknown, kClosed, kOpening, kOpen, kHeldOpen, kClosing };
std::string_view ToString(DoorMotion motion);

struct DoorState {
  bool observed{false};
  double angle{0.0};            ///< Smoothed, from closed [rad].
  double rate{0.0};             ///< [rad/s], positive while opening.
  double open_fraction{0.0};    ///< angle / max_open_angle in [0, 1].
  double clearance_width{0.0};  ///< Clear width of the opening [m].
  DoorMotion motion{DoorMotion::kUnknown};
  double steady_for{0.0};  ///< How long the angle has been steady [s].
  Time stamp{};
};

struct DoorStateConfig {
  double smoothing{0.5};        ///< Weight of a new measurement.
  double closed_angle{0.0873};  ///< Below this the door is closed [rad] (5°).
  double motion_rate{0.1};      ///< |rate| above this is moving [rad/s].
  double held_after{1.0};       ///< Open and steady this long: held open [s].
  /// A measurement this long after the last one replaces the estimate rather than blending into
  /// it, its rate and steadiness unknown [s]: an operator closes a leaf in ~5 s, and the leaf
  /// drawn at an estimate blended with one from seconds ago lands its own returns off the map,
  /// where they read as someone by the door (random building seed 7: door_n1 last seen held open
  /// 12 s before, its leaf seen again shut read as a resident, and the robot held the door for
  /// nobody until the time limit).
  double stale_after{1.0};
};

class DoorStateTracker {
 public:
  DoorStateTracker(DoorModel door, DoorStateConfig config = {});
  /// A new angle measurement at `stamp` (stamps must not decrease).
  void Update(double angle, Time stamp);
  const DoorState& state() const { return state_; }
  /// Observed, but not measured for longer than config.stale_after at `now`: where the leaf is
  /// then is not known (a measurement then replaces the estimate).
  bool IsStaleAt(Time now) const;
  const DoorModel& door() const { return door_; }

 private:
  DoorModel door_;
  DoorStateConfig config_;
  DoorState state_;
};

}  // namespace egress::perception
