#pragma once
/// @file
/// TrackingController: follows a WholeBodyTrajectory at 100 Hz with feedforward + PD on the base
/// (the paper's Kp = 3.0, Kd = 0.01), with velocity and acceleration limits, and a watchdog that
/// commands zero velocity when the base is more than 0.5 m or 0.5 rad off the reference and
/// reports why. A tripped watchdog latches until the next Start (the authors' code killed the
/// node instead). Arm joints are handed to the robot's joint controller as position + velocity
/// references.

#include <optional>
#include <string>

#include "egress/hsr_interface/geometry.h"
#include "egress/hsr_interface/time.h"
#include "egress/planning/trajectory.h"

namespace egress::planning {

struct ControllerConfig {
  double kp{3.0};  ///< [1/s]
  double kd{0.01};
  double rate_hz{100.0};
  double max_linear_speed{0.8};   ///< [m/s]
  double max_angular_speed{1.2};  ///< [rad/s]
  double max_linear_accel{1.0};   ///< [m/s²]
  double max_angular_accel{2.0};  ///< [rad/s²]
  double watchdog_position{0.5};  ///< [m]
  double watchdog_yaw{0.5};       ///< [rad]
  void Validate() const;
};

struct ControlCommand {
  Twist2 V_B;                      ///< Base velocity in the base frame.
  std::array<double, 5> arm_q{};   ///< arm_lift … wrist_roll position references.
  std::array<double, 5> arm_qd{};  ///< and velocity references.
  bool active{false};              ///< False when done or stopped.
  bool finished{false};
  bool watchdog_tripped{false};
  std::string watchdog_reason;
};

class TrackingController {
 public:
  explicit TrackingController(ControllerConfig config = {});
  /// Starts following `trajectory` at time t0.
  void Start(WholeBodyTrajectory trajectory, Time t0);
  /// One control step. X_MB is the measured base pose, V_B_measured the measured base velocity
  /// (base frame). @throws InvalidArgument for non-finite measurements.
  ControlCommand Update(Time now, const Pose2& X_MB, const Twist2& V_B_measured);
  /// Stops: zero commands until the next Start.
  void Stop();
  /// From the next Update on, the reference advances at `scale` times the clock (0: it waits
  /// where it is, 1: as planned) and its velocities are scaled alike: slowing down near people
  /// without the reference running away from the base (and the watchdog tripping).
  /// @throws InvalidArgument unless 0 <= scale <= 1.
  void SetTimeScale(double scale);
  bool tripped() const { return tripped_; }
  /// The planned base velocity in M where the reference was at the last Update, before any
  /// time scaling (zero when idle): which way the base is going.
  const Eigen::Vector2d& planned_velocity() const { return planned_v_M_; }
  const std::string& trip_reason() const { return trip_reason_; }
  /// How long the trajectory being tracked was planned to take (0 when idle) [s].
  double trajectory_duration() const { return trajectory_ ? trajectory_->duration() : 0.0; }

 private:
  ControllerConfig config_;
  std::optional<WholeBodyTrajectory> trajectory_;
  Time t0_{};
  double time_scale_{1.0};
  double lag_{0.0};  ///< [s] the reference is behind the clock by this (time scaled below 1)
  Eigen::Vector2d planned_v_M_{Eigen::Vector2d::Zero()};
  bool tripped_{false};
  std::string trip_reason_;
  Twist2 last_command_;
  std::optional<Time> last_time_;
};

}  // namespace egress::planning
