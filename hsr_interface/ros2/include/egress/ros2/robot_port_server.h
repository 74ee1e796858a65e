#pragma once
/// @file
/// RobotPortServer: serves any RobotPort (the twin's, in `egress twin serve --ros2`) as a ROS 2
/// robot: what its Sense() returns is published on the robot's topics (Ros2Topics), with
/// /clock and the camera's transform on /tf; commands received on cmd_vel and the arm's
/// trajectory topic, and goals of the gripper controller's actions (their send_goal service:
/// accepted, or refused with why in TakeRejected()), are applied to it. The port is not
/// thread-safe: commands are queued as they arrive and applied on the caller's thread by
/// ApplyCommands().

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "egress/hsr_interface/robot_port.h"
#include "egress/ros2/ros2_topics.h"

namespace egress::ros2 {

class RobotPortServer {
 public:
  /// Joins the DDS domain as node `node_name`. @throws InvalidArgument for bad topics,
  /// std::runtime_error if DDS cannot start.
  /// `reliable_sensors`: publish the sensors reliably (a lock-step simulation; a reliable
  /// writer also serves ROS 2's best-effort sensor subscribers), over UDP only (DdsNode).
  RobotPortServer(RobotPort& robot, Ros2Topics topics, int domain_id, bool reliable_sensors = false,
                  std::string_view node_name = "egress_twin");
  ~RobotPortServer();

  /// Reads the robot (Sense()) and publishes what is new, stamped as the robot stamped it, then
  /// /clock at the robot's time.
  void PublishSensors();
  /// Publishes again the latest scan, odometry, joint states and clock (a brain that joined
  /// after they went out, before the robot moves on: best-effort data is not kept for it).
  void RepublishLatest();
  /// Applies to the robot the commands received since the last call, in arrival order.
  /// Returns how many.
  int ApplyCommands();
  /// Waits (wall time, bounded) until the brain reports the control step at `t` done.
  bool WaitForStepDone(Time t, std::chrono::milliseconds timeout);
  /// The brain's last status (egress robot publishes its tree's), if any.
  std::optional<std::string> brain_status() const;
  /// Whether a brain reads every sensor topic and writes the base command (for waiting until
  /// it is fully there).
  bool BrainConnected() const;
  /// Wall-clock delays [s] from the latest PublishSensors to each base velocity command's
  /// arrival (the brain's reaction over DDS, end to end); cleared by the call.
  std::vector<double> TakeCommandLatencies();
  /// Commands that could not be applied (malformed), with why; cleared by the call.
  std::vector<std::string> TakeRejected();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace egress::ros2
