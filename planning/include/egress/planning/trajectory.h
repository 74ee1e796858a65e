#pragma once
/// @file
/// Quintic-polynomial trajectories (the paper's): zero velocity and acceleration at both ends
/// of every segment, base and arm synchronized to arrive together, duration
///   T = max(L / v_target, T_min)  (v_target 0.2 m/s nominal, 0.4 m/s through a door,
///                                  T_min 1.5 s),
/// lengthened where needed so that no joint's peak speed (1.875·Δq/T for a quintic) exceeds
/// its limit. Multi-waypoint motions are a sequence of such segments. Base yaw is unwrapped so
/// that a segment always turns the short way.

#include <vector>

#include "egress/hsr_interface/robot_model.h"

namespace egress::planning {

/// One scalar quintic on [0, T] with given boundary position, velocity and acceleration.
class QuinticPolynomial {
 public:
  QuinticPolynomial(double q0, double v0, double a0, double q1, double v1, double a1,
                    double duration);
  /// Evaluation is clamped to [0, T].
  double Position(double t) const;
  double Velocity(double t) const;
  double Acceleration(double t) const;
  double duration() const { return duration_; }

 private:
  std::array<double, 6> c_{};
  double duration_;
};

struct TrajectoryConfig {
  double nominal_speed{0.2};  ///< v_target [m/s]
  double door_speed{0.4};     ///< v_target through a door [m/s]
  double min_duration{1.5};   ///< T_min [s]
  /// Peak base yaw rate [rad/s]: a segment that turns further takes longer (half the tracking
  /// controller's 1.2 rad/s limit, leaving it room to correct).
  double max_yaw_rate{0.6};
  void Validate() const;
};

/// The paper's duration rule for a segment whose base travels `base_distance` metres.
double SegmentDuration(double base_distance, bool through_door, const TrajectoryConfig& config);
/// The same, stretched so that a base turning `base_turn` radians (either way) peaks at no more
/// than config.max_yaw_rate: what WholeBodyTrajectory::Plan gives a base-only segment [s].
double SegmentDuration(double base_distance, double base_turn, bool through_door,
                       const TrajectoryConfig& config);

/// One sample of a whole-body trajectory.
struct TrajectorySample {
  WholeBodyVector q{WholeBodyVector::Zero()};
  WholeBodyVector qd{WholeBodyVector::Zero()};
  WholeBodyVector qdd{WholeBodyVector::Zero()};
};

class WholeBodyTrajectory {
 public:
  /// Segments through `waypoints` (at least 2); `through_door[i]` marks segment i (optional).
  /// Velocity limits from `model` stretch segments whose joints would move too fast.
  /// @throws InvalidArgument for fewer than 2 waypoints, non-finite values or a size mismatch.
  static WholeBodyTrajectory Plan(const std::vector<WholeBodyVector>& waypoints,
                                  const RobotModel& model, const TrajectoryConfig& config = {},
                                  const std::vector<bool>& through_door = {});
  TrajectorySample Sample(double t) const;
  double duration() const { return end_times_.empty() ? 0.0 : end_times_.back(); }
  std::size_t segment_count() const { return segments_.size(); }
  double segment_duration(std::size_t i) const;

 private:
  std::vector<std::vector<QuinticPolynomial>> segments_;  // per segment, per joint
  std::vector<double> end_times_;
};

}  // namespace egress::planning
