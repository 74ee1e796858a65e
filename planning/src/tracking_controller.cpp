#include "egress/planning/tracking_controller.h"

#include <cmath>

#include "egress/hsr_interface/error.h"

namespace egress::planning {

void ControllerConfig::Validate() const {
  ThrowUnless(kp >= 0.0 && kd >= 0.0, "Invalid ControllerConfig: kp and kd must be >= 0.");
  ThrowUnless(rate_hz > 0.0, "Invalid ControllerConfig: rate_hz must be > 0.");
  ThrowUnless(max_linear_speed > 0.0 && max_angular_speed > 0.0 && max_linear_accel > 0.0 &&
                  max_angular_accel > 0.0,
              "Invalid ControllerConfig: speed and acceleration limits must be > 0.");
  ThrowUnless(watchdog_position > 0.0 && watchdog_yaw > 0.0,
              "Invalid ControllerConfig: watchdog thresholds must be > 0.");
}

TrackingController::TrackingController(ControllerConfig config) : config_(config) {
  config_.Validate();
}

void TrackingController::Start(WholeBodyTrajectory trajectory, Time t0) {
  trajectory_ = std::move(trajectory);
  t0_ = t0;
  lag_ = 0.0;
  tripped_ = false;
  trip_reason_.clear();
  last_command_ = {};
  last_time_.reset();
}

void TrackingController::SetTimeScale(double scale) {
  ThrowUnless(std::isfinite(scale) && scale >= 0.0 && scale <= 1.0,
              "TrackingController: the time scale must be in [0, 1], got ", scale);
  time_scale_ = scale;
}

void TrackingController::Stop() {
  trajectory_.reset();
  planned_v_M_.setZero();
  last_command_ = {};
}

ControlCommand TrackingController::Update(Time now, const Pose2& X_MB, const Twist2& V_B_measured) {
  ThrowUnless(X_MB.IsFinite() && V_B_measured.IsFinite(),
              "Invalid controller input: the measured pose and velocity ", "must be finite.");
  ControlCommand command;
  if (!trajectory_ || tripped_) {
    command.watchdog_tripped = tripped_;
    command.watchdog_reason = trip_reason_;
    return command;
  }
  // The reference's time: the clock's, less what scaling held it back (exactly the clock's
  // while the scale is 1).
  if (last_time_ && time_scale_ < 1.0) lag_ += (1.0 - time_scale_) * ToSeconds(now - *last_time_);
  const double t = ToSeconds(now - t0_) - lag_;
  TrajectorySample ref = trajectory_->Sample(t);
  planned_v_M_ = {ref.qd[kBaseX], ref.qd[kBaseY]};
  if (time_scale_ < 1.0) ref.qd *= time_scale_;
  for (int j = 0; j < 5; ++j) {
    command.arm_q[std::size_t(j)] = ref.q[kArmLift + j];
    command.arm_qd[std::size_t(j)] = ref.qd[kArmLift + j];
  }
  // Errors in M.
  const Eigen::Vector2d e_p(ref.q[kBaseX] - X_MB.x, ref.q[kBaseY] - X_MB.y);
  const double e_yaw = WrapAngle(ref.q[kBaseYaw] - X_MB.yaw);
  if (e_p.norm() > config_.watchdog_position || std::abs(e_yaw) > config_.watchdog_yaw) {
    tripped_ = true;
    trip_reason_ = e_p.norm() > config_.watchdog_position
                       ? StrCat("base position error ", e_p.norm(), " m exceeds ",
                                config_.watchdog_position, " m")
                       : StrCat("base yaw error ", std::abs(e_yaw), " rad exceeds ",
                                config_.watchdog_yaw, " rad");
    last_command_ = {};
    command.watchdog_tripped = true;
    command.watchdog_reason = trip_reason_;
    return command;  // zero velocity
  }
  // Feedforward + PD in M, then into the base frame with the measured heading.
  const Eigen::Vector2d v_ref(ref.qd[kBaseX], ref.qd[kBaseY]);
  const Eigen::Vector2d v_meas =
      X_MB.rotation() * Eigen::Vector2d(V_B_measured.vx, V_B_measured.vy);
  Eigen::Vector2d v_M = v_ref + config_.kp * e_p + config_.kd * (v_ref - v_meas);
  double w =
      ref.qd[kBaseYaw] + config_.kp * e_yaw + config_.kd * (ref.qd[kBaseYaw] - V_B_measured.wz);
  if (v_M.norm() > config_.max_linear_speed) v_M *= config_.max_linear_speed / v_M.norm();
  w = std::clamp(w, -config_.max_angular_speed, config_.max_angular_speed);
  Eigen::Vector2d v_B = X_MB.rotation().transpose() * v_M;
  // Acceleration limits against the previous command.
  const double dt = last_time_ ? ToSeconds(now - *last_time_) : 1.0 / config_.rate_hz;
  if (dt > 0.0) {
    const Eigen::Vector2d previous(last_command_.vx, last_command_.vy);
    const Eigen::Vector2d change = v_B - previous;
    if (change.norm() > config_.max_linear_accel * dt)
      v_B = previous + change * (config_.max_linear_accel * dt / change.norm());
    w = last_command_.wz + std::clamp(w - last_command_.wz, -config_.max_angular_accel * dt,
                                      config_.max_angular_accel * dt);
  }
  last_time_ = now;
  const bool finished = t >= trajectory_->duration() && e_p.norm() < 0.01 && std::abs(e_yaw) < 0.01;
  if (finished) {
    last_command_ = {};
    command.finished = true;
    return command;
  }
  last_command_ = {v_B.x(), v_B.y(), w};
  command.V_B = last_command_;
  command.active = true;
  return command;
}

}  // namespace egress::planning
