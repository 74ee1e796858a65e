#include "egress/behavior/motion_executor.h"

#include <algorithm>
#include <cmath>

#include "egress/hsr_interface/error.h"

namespace egress::behavior {

ArmPose ArmOf(const WholeBodyVector& q) {
  return {q[kArmLift], q[kArmFlex], q[kArmRoll], q[kWristFlex], q[kWristRoll]};
}

ArmPose TuckedArm(const RobotModel& model) {
  return ArmOf(model.tucked_configuration());
}

WholeBodyVector WithArm(const WholeBodyVector& q, const ArmPose& arm) {
  WholeBodyVector out = q;
  for (int i = 0; i < 5; ++i)
    out[kArmLift + i] = arm[std::size_t(i)];
  return out;
}

void ArmMotionConfig::Validate() const {
  ThrowUnless(tolerance > 0 && std::isfinite(tolerance), "ArmMotionConfig: tolerance (", tolerance,
              ") must be > 0");
  ThrowUnless(timeout > 0 && std::isfinite(timeout), "ArmMotionConfig: timeout (", timeout,
              ") must be > 0");
}

MotionExecutor::MotionExecutor(const RobotModel& model, planning::TrajectoryConfig trajectory,
                               planning::ControllerConfig controller, ArmMotionConfig arm)
    : model_(model), trajectory_config_(trajectory), controller_(controller), arm_config_(arm) {
  arm_target_ = TuckedArm(model_);
  trajectory_config_.Validate();
  arm_config_.Validate();
}

std::pair<std::size_t, double> MotionExecutor::ArmError() const {
  std::pair<std::size_t, double> worst{0, 0.0};
  if (!measured_arm_) return worst;
  for (std::size_t j = 0; j < arm_target_.size(); ++j) {
    const double error = std::abs((*measured_arm_)[j] - arm_target_[j]);
    if (error > worst.second) worst = {j, error};
  }
  return worst;
}

bool MotionExecutor::arm_moving(Time now) const {
  if (now < arm_done_) return true;
  if (arm_failed() || arm_settled_ || !measured_arm_) return false;
  return ArmError().second > arm_config_.tolerance;
}

void MotionExecutor::FollowPath(const std::vector<Pose2>& path,
                                const std::vector<bool>& through_door, const ArmPose& arm, Time now,
                                std::optional<double> speed, bool brisk) {
  ThrowUnless(path.size() >= 2, "FollowPath: a path needs at least 2 waypoints");
  ThrowUnless(!speed || (std::isfinite(*speed) && *speed > 0), "FollowPath: speed must be > 0");
  planning::TrajectoryConfig config = trajectory_config_;
  if (speed) config.nominal_speed = *speed;
  config.brisk = config.brisk || brisk;
  std::vector<WholeBodyVector> waypoints;
  double previous_yaw = path.front().yaw;
  for (const Pose2& X_MB : path) {
    ThrowUnless(X_MB.IsFinite(), "FollowPath: non-finite waypoint");
    WholeBodyVector q = WholeBodyVector::Zero();
    // Unwrap the yaw so a quintic never turns the long way round through ±π.
    const double yaw = previous_yaw + std::remainder(X_MB.yaw - previous_yaw, 2 * M_PI);
    previous_yaw = yaw;
    q[kBaseX] = X_MB.x;
    q[kBaseY] = X_MB.y;
    q[kBaseYaw] = yaw;
    waypoints.push_back(WithArm(q, arm));
  }
  controller_.Start(planning::WholeBodyTrajectory::Plan(waypoints, model_, config, through_door),
                    now);
  base_active_ = true;
  path_ = path;
  brisk_step_ = brisk;
  base_failed_ = false;
  base_failure_.clear();
  bug_.reset();
}

void MotionExecutor::FollowBug(const Pose2& X_MB, const Eigen::Vector2d& p_MGoal,
                               const planning::BugConfig& config, Time now) {
  controller_.Stop();
  bug_.emplace(X_MB.translation(), p_MGoal, config);
  bug_last_step_ = now;
  base_active_ = true;
  path_ = {X_MB, {p_MGoal.x(), p_MGoal.y(), X_MB.yaw}};
  brisk_step_ = false;
  base_failed_ = false;
  base_failure_.clear();
}

void MotionExecutor::SetSurroundings(std::vector<Eigen::Vector2d> p_MObstacles,
                                     std::vector<Eigen::Vector2d> p_MPeople) {
  obstacles_M_ = std::move(p_MObstacles);
  people_M_ = std::move(p_MPeople);
}

void MotionExecutor::StopBase() {
  controller_.Stop();
  bug_.reset();
  base_active_ = false;
  path_.clear();
  brisk_step_ = false;
}

void MotionExecutor::MoveArm(const std::vector<std::pair<double, ArmPose>>& knots, Time now) {
  ThrowUnless(!knots.empty(), "MoveArm: no knots");
  JointTrajectory trajectory;
  trajectory.joint_names.assign(kArmJointNames.begin(), kArmJointNames.end());
  double previous_t = 0.0;
  for (const auto& [t, arm] : knots) {
    ThrowUnless(std::isfinite(t) && t >= previous_t, "MoveArm: knot times must be finite and ",
                "non-decreasing");
    previous_t = t;
    JointTrajectoryPoint point;
    point.positions.assign(arm.begin(), arm.end());
    point.time_from_start = SecondsToDuration(t);
    trajectory.points.push_back(std::move(point));
  }
  trajectory.Validate();
  pending_arm_ = std::move(trajectory);
  arm_done_ = now + SecondsToDuration(knots.back().first);
  arm_target_ = knots.back().second;
  arm_failure_.clear();
  arm_settled_ = false;
}

Twist2 MotionExecutor::Update(Time now, const Pose2& X_MB, const Twist2& V_B_measured) {
  if (measured_arm_ && !arm_failed() && !arm_settled_ && now >= arm_done_) {
    const auto [joint, error] = ArmError();
    if (error <= arm_config_.tolerance) {
      arm_settled_ = true;
    } else if (ToSeconds(now - arm_done_) > arm_config_.timeout) {
      arm_failure_ = StrCat("the arm did not reach its target: ", kArmJointNames[joint], " at ",
                            (*measured_arm_)[joint], ", target ", arm_target_[joint], " (",
                            arm_config_.timeout, " s past the motion's end)");
    }
  }
  if (!base_active_) return {};
  if (bug_) {
    const double dt = ToSeconds(now - bug_last_step_);
    bug_last_step_ = now;
    const planning::BugCommand command = bug_->Step(X_MB, obstacles_M_, people_M_, dt);
    if (command.mode == planning::BugMode::kReached || command.mode == planning::BugMode::kFailed) {
      if (command.mode == planning::BugMode::kFailed) {
        base_failed_ = true;
        base_failure_ = "detour gave up: " + command.reason;
      }
      bug_.reset();
      base_active_ = false;
      path_.clear();
      return {};
    }
    return command.V_B;
  }
  const planning::ControlCommand command = controller_.Update(now, X_MB, V_B_measured);
  if (command.watchdog_tripped) {
    base_active_ = false;
    path_.clear();
    base_failed_ = true;
    base_failure_ = command.watchdog_reason;
    return {};
  }
  if (command.finished || !command.active) {
    base_active_ = false;
    path_.clear();
    return {};
  }
  return command.V_B;
}

std::optional<JointTrajectory> MotionExecutor::TakeArmCommand() {
  std::optional<JointTrajectory> out = std::move(pending_arm_);
  pending_arm_.reset();
  return out;
}

}  // namespace egress::behavior
