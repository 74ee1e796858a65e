#pragma once
/// @file
/// Ros2RobotPort: the RobotPort of a robot that speaks ROS 2 (the HSR, or a twin served by
/// RobotPortServer), over Fast DDS. Sensor messages are taken as they arrive (Fast DDS's
/// threads) and handed to the brain at the next Sense(); commands are published at once.
///
/// Safety: Fault() names a sensor that went stale (no scan for scan_timeout_s, no odometry for
/// odometry_timeout_s, no joint states for joints_timeout_s, by the port's clock since the last
/// one arrived) or an e-stop; while it does, the port sends only zero base velocities, whatever
/// the brain asks. The caller halts the tree (egress robot does, within one control step).
///
/// Commands are sent only while fresh (command_timeout_s, by the port's clock): a base velocity
/// only if the Sense() it was decided from is that recent (else zero goes out), an arm
/// trajectory only if its start stamp is (else it is refused); and if the brain sends no base
/// command for that long after a moving one — a stalled brain — the port itself sends zero.

#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "egress/hsr_interface/clock.h"
#include "egress/hsr_interface/robot_port.h"
#include "egress/ros2/ros2_topics.h"

namespace egress::ros2 {

struct Ros2RobotPortConfig {
  Ros2Topics topics;
  int domain_id{0};          ///< ROS_DOMAIN_ID
  bool use_sim_time{false};  ///< The clock is /clock's (a simulation), else the system clock.
  double scan_timeout_s{0.3};
  double odometry_timeout_s{0.2};
  double joints_timeout_s{0.5};
  /// The oldest a command may be when it goes out [s] (see the class comment): a few control
  /// periods (the executive's is 0.01 s), under the sensors' timeouts.
  double command_timeout_s{0.1};
  /// The motor torque the gripper opens with (the HSR's `grasp` action, > 0 opens) [Nm].
  double gripper_open_torque{0.8};
  /// Subscribe to the sensors reliably, not with ROS 2's sensor-data QoS (best effort): for a
  /// lock-step simulation, where a dropped reading would make a sensor look stale. A real
  /// robot's best-effort sensor publishers do not match reliable subscribers: leave it off.
  /// Implies UDP without shared memory (DdsNode's udp_only).
  bool reliable_sensors{false};
  /// @throws InvalidArgument naming the field.
  void Validate() const;
};

/// Nanoseconds since the UNIX epoch: the stamps of a real ROS 2 robot.
class SystemClock final : public Clock {
 public:
  Time Now() const override;
};

class Ros2RobotPort final : public RobotPort {
 public:
  /// Joins the DDS domain as node `node_name`. @throws InvalidArgument for a bad config,
  /// std::runtime_error if DDS cannot start.
  explicit Ros2RobotPort(Ros2RobotPortConfig config, std::string_view node_name = "egress_brain");
  ~Ros2RobotPort() override;

  const Clock& clock() const override;
  /// Why the base must not move (a stale sensor, an e-stop), or nullopt.
  std::optional<std::string> Fault() const;
  /// Waits (wall time, bounded) until Fault() clears; returns whether it did. For lock-step
  /// simulation: the world waits for the brain, so a reading still in flight (a reliable
  /// sample being repaired) is waited for before the sensor is called stale.
  bool WaitUntilHealthy(std::chrono::milliseconds timeout);
  /// Waits until odometry and joint states have arrived (and, with sim time, the clock): the
  /// robot is up. A sensor that has not sent by then is stale once its timeout has passed from
  /// this moment. Returns false on timeout, naming in `missing` what never came.
  bool WaitForSensors(std::chrono::milliseconds timeout, std::string* missing = nullptr);
  /// With sim time: blocks until the clock reaches `t` or `timeout` passes (wall time); returns
  /// whether it did. Without sim time: sleeps until `t`.
  bool WaitUntil(Time t, std::chrono::milliseconds timeout);
  /// The mission tree's status, for whoever watches (lock-step simulation ends on it).
  void PublishStatus(std::string_view status);
  /// The time of the control step just finished (lock-step simulation waits for it).
  void PublishStepDone(Time t);
  /// Publishes an e-stop (true) or its release, as any node may.
  void PublishEstop(bool stop);
  /// How many base commands went out as zero because the Sense() behind them was stale, and
  /// how many times the watchdog stopped a base the brain had stopped commanding.
  int stale_base_commands() const;
  int watchdog_stops() const;
  /// Whether the gripper controller's action servers are matched (a goal waits up to 2 s for
  /// them, then fails with an error naming the action).
  bool GripperConnected() const;
  /// Whether the base, arm and head command writers each see a reader. A reader matched on
  /// its side is not enough: the writer sends only to readers it has discovered itself, and a
  /// command written before that is lost (volatile topics).
  bool CommandsConnected() const;
  /// Gripper goals the controller accepted and refused so far.
  std::pair<int, int> gripper_goals() const;

 protected:
  SensorSnapshot DoSense() override;
  void DoSendBaseVelocity(const Twist2& V_B) override;
  /// @throws InvalidArgument if `trajectory.start` is set and older than command_timeout_s.
  void DoSendArmTrajectory(const JointTrajectory& trajectory) override;
  /// A goal of the gripper controller's `apply_force` (grasp) or `grasp` (open) action
  /// (GripperToRos). @throws InvalidArgument for a position command (no HSR action built),
  /// std::runtime_error if the action server is not matched within 2 s.
  void DoSendGripperCommand(const GripperCommand& command) override;
  /// Publishes a head_trajectory point (HeadTrajectory, timed from the latest joint states).
  void DoSendHeadCommand(const HeadCommand& command) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace egress::ros2
