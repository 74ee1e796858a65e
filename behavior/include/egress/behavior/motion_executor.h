#pragma once
/// @file
/// MotionExecutor: runs the motions the task nodes start. Base paths become the paper's quintic
/// whole-body trajectories (T = max(L/v, 1.5 s), 0.4 m/s through doors) followed by the
/// feedforward-PD TrackingController at the control rate, with its watchdog; arm motions become
/// timed joint trajectories for the robot's own arm controller. One motion of each kind at a
/// time: a new one replaces the old. Time is the robot's clock, so a twin run is lock-step.

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "egress/hsr_interface/command_types.h"
#include "egress/hsr_interface/geometry.h"
#include "egress/hsr_interface/robot_model.h"
#include "egress/hsr_interface/time.h"
#include "egress/planning/bug2_navigator.h"
#include "egress/planning/tracking_controller.h"
#include "egress/planning/trajectory.h"

namespace egress::behavior {

/// arm_lift [m], arm_flex, arm_roll, wrist_flex, wrist_roll [rad].
using ArmPose = std::array<double, 5>;

/// The URDF names of ArmPose's joints, in its order.
inline constexpr std::array<std::string_view, 5> kArmJointNames{
    "arm_lift_joint", "arm_flex_joint", "arm_roll_joint", "wrist_flex_joint", "wrist_roll_joint"};

/// The arm joints of a whole-body vector, and back.
ArmPose ArmOf(const WholeBodyVector& q);
WholeBodyVector WithArm(const WholeBodyVector& q, const ArmPose& arm);

/// The arm folded over the base, nothing outside the footprint: the robot description's
/// tucked configuration (RobotModel::tucked_configuration).
ArmPose TuckedArm(const RobotModel& model);

/// How an arm motion is judged complete: by the measured joints, not the clock.
struct ArmMotionConfig {
  /// Done when every arm joint is within this of its target [m or rad].
  double tolerance{0.02};
  /// Failed when the joints are not there this long after the motion's planned end [s].
  double timeout{3.0};
  /// @throws InvalidArgument naming the field.
  void Validate() const;
};

class MotionExecutor {
 public:
  MotionExecutor(const RobotModel& model, planning::TrajectoryConfig trajectory = {},
                 planning::ControllerConfig controller = {}, ArmMotionConfig arm = {});

  /// Follows `path` (X_MB waypoints, the first one the current pose); `through_door[i]` marks
  /// segment i as a door crossing (0.4 m/s). The arm holds `arm`. `speed` [m/s], if given,
  /// replaces the nominal speed of the other segments (a retreat from someone). `brisk`: the
  /// segments accelerate at the base's limit from the start (TrajectoryConfig::brisk), for a
  /// step out of someone's way.
  /// @throws InvalidArgument for fewer than 2 waypoints, non-finite poses or a speed <= 0.
  void FollowPath(const std::vector<Pose2>& path, const std::vector<bool>& through_door,
                  const ArmPose& arm, Time now, std::optional<double> speed = std::nullopt,
                  bool brisk = false);
  /// Drives the base to `p_MGoal` with the Bug2 local planner instead (head for the goal,
  /// follow an obstacle's boundary round it, stop for people ahead) — the detour when the
  /// costmap has no path. It sees what SetSurroundings last gave it.
  void FollowBug(const Pose2& X_MB, const Eigen::Vector2d& p_MGoal,
                 const planning::BugConfig& config, Time now);
  /// The laser's obstacle points and the tracked people (in M) for the Bug2 detour.
  void SetSurroundings(std::vector<Eigen::Vector2d> p_MObstacles,
                       std::vector<Eigen::Vector2d> p_MPeople);
  bool bug_active() const { return bug_.has_value(); }
  /// Base paths go at this fraction of their planned pace from the next Update (0..1; the
  /// executive slows near people). @throws InvalidArgument outside [0, 1].
  void SetSpeedScale(double scale) { controller_.SetTimeScale(scale); }
  /// Which way the path being followed goes now, at its planned pace (M; zero when idle).
  Eigen::Vector2d planned_velocity() const {
    return base_active_ && !bug_ ? controller_.planned_velocity() : Eigen::Vector2d::Zero();
  }
  /// How long the path being followed was planned to take (0 when idle or on a Bug2 detour) [s].
  double base_duration() const {
    return base_active_ && !bug_ ? controller_.trajectory_duration() : 0.0;
  }
  /// Stops the base: zero velocity from the next control step.
  void StopBase();
  /// Moves the arm through `knots` (seconds from now, pose). Sent with the next control step.
  /// The arm's own controller rate-limits each joint: a knot asked for too soon is reached
  /// late, and arm_moving() waits for it.
  void MoveArm(const std::vector<std::pair<double, ArmPose>>& knots, Time now);
  /// The arm joints as measured (joint states), each control step.
  void SetMeasuredArm(const ArmPose& arm) { measured_arm_ = arm; }

  const planning::TrajectoryConfig& trajectory_config() const { return trajectory_config_; }
  bool base_moving() const { return base_active_; }
  /// The base is on a path given with `brisk` (a step out of someone's way, a retreat).
  bool stepping_out_of_way() const { return base_active_ && brisk_step_; }
  /// The path being followed (empty when the base is idle).
  const std::vector<Pose2>& path() const { return path_; }
  /// The last base motion ended by the watchdog (tracking error beyond its limits).
  bool base_failed() const { return base_failed_; }
  const std::string& base_failure() const { return base_failure_; }
  /// The arm motion is under way: before its planned end, or after it while the measured
  /// joints are not yet at the target (until the timeout). Without measurements, the clock.
  bool arm_moving(Time now) const;
  /// The last arm motion did not reach its target within the timeout (see arm_failure()).
  bool arm_failed() const { return !arm_failure_.empty(); }
  /// Which joint stopped where, against which target.
  const std::string& arm_failure() const { return arm_failure_; }
  /// The planned end of the last arm motion.
  Time arm_done() const { return arm_done_; }
  /// The arm pose the last arm motion ends in.
  const ArmPose& arm_target() const { return arm_target_; }

  /// One control step: the base twist to send (zero when idle); checks the arm's timeout.
  Twist2 Update(Time now, const Pose2& X_MB, const Twist2& V_B_measured);
  /// The arm trajectory to send, once.
  std::optional<JointTrajectory> TakeArmCommand();
  /// Commands the gripper (sent with the next control step).
  void SetGripper(const GripperCommand& command) { pending_gripper_ = command; }
  /// The gripper command to send, once.
  std::optional<GripperCommand> TakeGripperCommand() {
    auto out = pending_gripper_;
    pending_gripper_.reset();
    return out;
  }

 private:
  const RobotModel& model_;
  planning::TrajectoryConfig trajectory_config_;
  planning::TrackingController controller_;
  bool base_active_{false};
  std::vector<Pose2> path_;
  bool brisk_step_{false};  ///< path_ was given with `brisk`
  bool base_failed_{false};
  std::string base_failure_;
  std::optional<planning::Bug2Navigator> bug_;
  Time bug_last_step_{};
  std::vector<Eigen::Vector2d> obstacles_M_, people_M_;
  std::optional<JointTrajectory> pending_arm_;
  std::optional<GripperCommand> pending_gripper_;
  Time arm_done_{};
  ArmPose arm_target_{};  // the tucked arm, set from the model
  ArmMotionConfig arm_config_;
  std::optional<ArmPose> measured_arm_;
  std::string arm_failure_;
  bool arm_settled_{false};  // the measured joints reached the target after the planned end
  // The measured joint farthest from the target: its index and error.
  std::pair<std::size_t, double> ArmError() const;
};

}  // namespace egress::behavior
