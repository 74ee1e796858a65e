#pragma once
/// @file
/// Quintic-polynomial trajectories (the paper's): zero velocity and acceleration at both ends
/// of every segment, base and arm synchronized to arrive together, duration
///   T = max(L / v_target, T_min)  (v_target 0.2 m/s nominal, 0.4 m/s through a door,
///                                  T_min 1.5 s),
/// lengthened where needed so that no joint's peak speed (1.875·Δq/T for a quintic) exceeds
/// its limit. The base's acceleration is the base's own: a quintic peaks at 5.77·L/T², and at
/// door speed the paper's rule asks up to 1.5 m/s² of a base that gives 1 m/s² (0.4-0.9 m
/// segments; the lagging base then overshot the segment's end, into a wall). Such a segment
/// instead accelerates at the base's limit, coasts and brakes (SegmentTimeScaling), in no less
/// than the 2·sqrt(L/a) that takes: about the paper's time, where a quintic within the limit
/// would take 20 % longer (a step out of someone's way comes that much later). Multi-waypoint
/// motions are a sequence of such segments. Base yaw is unwrapped so that a segment always turns
/// the short way.

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
  /// Peak base acceleration [m/s²]: a segment whose quintic would ask for more accelerates at
  /// this, coasts and brakes instead (the tracking controller's and the HSR base's limit,
  /// ControllerConfig::max_linear_accel).
  double max_base_acceleration{1.0};
  /// Every segment accelerates at max_base_acceleration, coasts and brakes, even where the
  /// quintic would keep within it: a step out of someone's way. The quintic starts gently (a
  /// 1 m retreat's took 0.16 s to reach 5 cm/s, and longer with the tracking lag), and a robot
  /// turning back in a doorway stood there that long beside the resident it made way for.
  bool brisk{false};
  void Validate() const;
};

/// The paper's duration rule for a segment whose base travels `base_distance` metres, and no
/// less than the base needs at config.max_base_acceleration (2·sqrt(L/a)) [s].
double SegmentDuration(double base_distance, bool through_door, const TrajectoryConfig& config);
/// The same, stretched so that a base turning `base_turn` radians (either way) peaks at no more
/// than config.max_yaw_rate: what WholeBodyTrajectory::Plan gives a base-only segment [s].
double SegmentDuration(double base_distance, double base_turn, bool through_door,
                       const TrajectoryConfig& config);

/// How far along its straight line (in joint space) a rest-to-rest segment is at time t: progress
/// σ from 0 to 1 over the duration T, with zero rate at both ends. The paper's quintic
/// (σ = 10τ³ − 15τ⁴ + 6τ⁵, τ = t/T) where the base's acceleration allows it; else accelerating
/// at max_base_acceleration for t_a, coasting, and braking for t_a, with
/// t_a·(T − t_a) = L / a. With TrajectoryConfig::brisk, always the latter (for L > 0): within the
/// same T it peaks no faster than the quintic wherever the quintic would keep within the limit
/// (t_a <= 0.23 T, peak rate 1 / (T − t_a) <= 1.29 / T).
class SegmentTimeScaling {
 public:
  /// @param base_distance L [m], >= 0; @param duration T [s], > 0 (at least SegmentDuration's,
  /// so that the base can cover L within it; shorter is clamped to accelerating half the time).
  /// @throws InvalidArgument for non-finite or out-of-range values.
  SegmentTimeScaling(double base_distance, double duration, const TrajectoryConfig& config);
  double Progress(double t) const;      ///< σ(t), clamped to [0, T]
  double Rate(double t) const;          ///< dσ/dt [1/s]
  double Acceleration(double t) const;  ///< d²σ/dt² [1/s²]
  double duration() const { return duration_; }
  bool quintic() const { return accel_time_ == 0.0; }
  /// The largest dσ/dt over the segment [1/s]: 1.875 / T for the quintic.
  double peak_rate() const;

 private:
  double duration_;
  double accel_time_{0.0};  ///< t_a [s]; 0: the quintic
  double accel_{0.0};       ///< d²σ/dt² while accelerating [1/s²]
};

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
  struct Segment {
    WholeBodyVector from, to;  ///< rest at both (yaw unwrapped: `to` the short way)
    SegmentTimeScaling timing;
  };
  std::vector<Segment> segments_;
  std::vector<double> end_times_;
};

}  // namespace egress::planning
