#include "egress/ros2/ros2_robot_port.h"

#include <cmath>
#include <cstring>
#include <random>
#include <thread>
#include <vector>

#include <geometry_msgs/msg/TwistPubSubTypes.h>
#include <nav_msgs/msg/OdometryPubSubTypes.h>
#include <rosgraph_msgs/msg/ClockPubSubTypes.h>
#include <sensor_msgs/msg/CameraInfoPubSubTypes.h>
#include <sensor_msgs/msg/ImagePubSubTypes.h>
#include <sensor_msgs/msg/JointStatePubSubTypes.h>
#include <sensor_msgs/msg/LaserScanPubSubTypes.h>
#include <std_msgs/msg/BoolPubSubTypes.h>
#include <std_msgs/msg/StringPubSubTypes.h>
#include <tf2_msgs/msg/TFMessagePubSubTypes.h>
#include <tmc_control_msgs/action/GripperApplyEffortPubSubTypes.h>
#include <trajectory_msgs/msg/JointTrajectoryPubSubTypes.h>
#include <vision_msgs/msg/Detection2DArrayPubSubTypes.h>

#include "egress/hsr_interface/error.h"
#include "egress/hsr_interface/frames.h"
#include "egress/ros2/conversions.h"
#include "egress/ros2/dds_node.h"

namespace egress::ros2 {
namespace {
// How long a gripper goal waits for the controller's action server to be matched.
constexpr std::chrono::milliseconds kGripperServerWait{2000};
}  // namespace

void Ros2RobotPortConfig::Validate() const {
  topics.Validate();
  for (const auto& [name, value] : {std::pair{"scan_timeout_s", scan_timeout_s},
                                    std::pair{"odometry_timeout_s", odometry_timeout_s},
                                    std::pair{"joints_timeout_s", joints_timeout_s},
                                    std::pair{"command_timeout_s", command_timeout_s},
                                    std::pair{"gripper_open_torque", gripper_open_torque}}) {
    ThrowUnless(std::isfinite(value) && value > 0.0, "Ros2RobotPortConfig: ", name, " (", value,
                ") must be finite and > 0");
  }
}

Time SystemClock::Now() const {
  return std::chrono::duration_cast<Time>(std::chrono::system_clock::now().time_since_epoch());
}

struct Ros2RobotPort::Impl {
  Ros2RobotPortConfig config;
  SystemClock system_clock;
  SimClock sim_clock;
  const Clock& clock() const {
    return config.use_sim_time ? static_cast<const Clock&>(sim_clock) : system_clock;
  }
  DdsNode node;

  mutable std::mutex mutex;
  std::condition_variable changed;
  // What arrived since the last Sense() (the latest of each), and when (by the port's clock).
  std::optional<LaserScan> scan;
  std::optional<DepthImage> depth;
  std::optional<ColorImage> color;
  std::optional<CameraIntrinsics> intrinsics;
  std::optional<Pose3> X_BC;
  std::vector<Detection2D> detections;
  std::optional<Odometry> odometry;
  std::optional<JointState> joints;
  std::optional<Time> scan_at, odometry_at, joints_at;
  // When WaitForSensors found the robot up: a sensor that never sent counts as stale from then.
  std::optional<Time> ready_at;
  bool clock_seen{false};
  bool estop{false};
  std::string bad_message;  // the last message that could not be converted
  // Command freshness: when the brain last sensed, when it last sent a base command, and
  // whether that command moves the base (the watchdog stops it if no other follows).
  std::optional<Time> sensed_at, base_command_at;
  bool base_moving{false};
  int stale_base_commands{0}, watchdog_stops{0};
  std::mutex publish_mutex;  // cmd_vel is written by the brain's thread and the watchdog
  std::thread watchdog;
  bool stopping{false};  // under `mutex`

  std::vector<std::unique_ptr<eprosima::fastdds::dds::DataReaderListener>> subscriptions;
  std::unique_ptr<Publisher<geometry_msgs::msg::TwistPubSubType>> cmd_vel;
  std::unique_ptr<Publisher<trajectory_msgs::msg::JointTrajectoryPubSubType>> arm;
  std::unique_ptr<Publisher<trajectory_msgs::msg::JointTrajectoryPubSubType>> head;
  using GripperGoalClient =
      ServiceClient<tmc_control_msgs::action::GripperApplyEffort_SendGoal_RequestPubSubType,
                    tmc_control_msgs::action::GripperApplyEffort_SendGoal_ResponsePubSubType>;
  std::unique_ptr<GripperGoalClient> grasp_goals, apply_force_goals;
  int gripper_goals_accepted{0}, gripper_goals_refused{0};  // under `mutex`
  // Goal ids: a random 8-byte prefix per port and a counter (unique_identifier_msgs/UUID).
  std::uint64_t goal_prefix{std::random_device{}() * 0x100000001ull};
  std::uint64_t goals_sent{0};
  std::unique_ptr<Publisher<std_msgs::msg::StringPubSubType>> status;
  std::unique_ptr<Publisher<rosgraph_msgs::msg::ClockPubSubType>> step_done;
  std::unique_ptr<Publisher<std_msgs::msg::BoolPubSubType>> estop_pub;

  std::optional<std::string> FaultLocked() const;  // with `mutex` held
  void PublishBase(const Twist2& V_B) {
    const std::lock_guard<std::mutex> lock(publish_mutex);
    cmd_vel->Publish(ToRos(V_B));
  }
  void Watch();

  Impl(Ros2RobotPortConfig c, std::string_view name)
      : config(std::move(c)), node(name, config.domain_id, /*udp_only=*/config.reliable_sensors) {}

  // Runs `convert` on a received message under the lock; a message that cannot be converted is
  // dropped and remembered (Fault() names it if it makes a sensor go stale).
  template <class F>
  void Take(const std::string& topic, F convert) {
    {
      const std::lock_guard<std::mutex> lock(mutex);
      try {
        convert();
      } catch (const std::exception& e) {
        bad_message = topic + ": " + e.what();
      }
    }
    changed.notify_all();
  }
};

Ros2RobotPort::Ros2RobotPort(Ros2RobotPortConfig config, std::string_view node_name) {
  config.Validate();
  impl_ = std::make_unique<Impl>(std::move(config), node_name);
  Impl& m = *impl_;
  const Ros2Topics& t = m.config.topics;
  const QosProfile reliable = QosProfile::Default();
  const QosProfile sensor = m.config.reliable_sensors ? reliable : QosProfile::SensorData();
  auto add = [&](auto subscription) { m.subscriptions.push_back(std::move(subscription)); };
  add(m.node.CreateSubscription<sensor_msgs::msg::LaserScanPubSubType>(
      t.scan, sensor, [&m, &t](const sensor_msgs::msg::LaserScan& msg) {
        m.Take(t.scan, [&] {
          m.scan = FromRos(msg);
          m.scan_at = m.clock().Now();
        });
      }));
  add(m.node.CreateSubscription<nav_msgs::msg::OdometryPubSubType>(
      t.odometry, sensor, [&m, &t](const nav_msgs::msg::Odometry& msg) {
        m.Take(t.odometry, [&] {
          m.odometry = FromRos(msg);
          m.odometry_at = m.clock().Now();
        });
      }));
  add(m.node.CreateSubscription<sensor_msgs::msg::JointStatePubSubType>(
      t.joint_states, sensor, [&m, &t](const sensor_msgs::msg::JointState& msg) {
        m.Take(t.joint_states, [&] {
          m.joints = FromRos(msg);
          m.joints_at = m.clock().Now();
        });
      }));
  add(m.node.CreateSubscription<sensor_msgs::msg::ImagePubSubType>(
      t.depth_image, sensor, [&m, &t](const sensor_msgs::msg::Image& msg) {
        m.Take(t.depth_image, [&] { m.depth = DepthFromRos(msg); });
      }));
  add(m.node.CreateSubscription<sensor_msgs::msg::ImagePubSubType>(
      t.color_image, sensor, [&m, &t](const sensor_msgs::msg::Image& msg) {
        m.Take(t.color_image, [&] { m.color = ColorFromRos(msg); });
      }));
  add(m.node.CreateSubscription<sensor_msgs::msg::CameraInfoPubSubType>(
      t.depth_camera_info, sensor, [&m, &t](const sensor_msgs::msg::CameraInfo& msg) {
        m.Take(t.depth_camera_info, [&] { m.intrinsics = FromRos(msg); });
      }));
  add(m.node.CreateSubscription<tf2_msgs::msg::TFMessagePubSubType>(
      t.tf, reliable, [&m, &t](const tf2_msgs::msg::TFMessage& msg) {
        m.Take(t.tf, [&] {
          for (const auto& T : msg.transforms()) {
            if (T.header().frame_id() == frames::kBase && T.child_frame_id() == frames::kHeadCamera)
              m.X_BC = FromRos(T.transform());
          }
        });
      }));
  add(m.node.CreateSubscription<vision_msgs::msg::Detection2DArrayPubSubType>(
      t.detections, reliable, [&m, &t](const vision_msgs::msg::Detection2DArray& msg) {
        m.Take(t.detections, [&] {
          for (auto& d : FromRos(msg))
            m.detections.push_back(std::move(d));
        });
      }));
  add(m.node.CreateSubscription<std_msgs::msg::BoolPubSubType>(
      t.estop, reliable, [&m, &t](const std_msgs::msg::Bool& msg) {
        m.Take(t.estop, [&] { m.estop = msg.data(); });
      }));
  if (m.config.use_sim_time) {
    add(m.node.CreateSubscription<rosgraph_msgs::msg::ClockPubSubType>(
        t.clock, m.config.reliable_sensors ? reliable : QosProfile::Clock(),
        [&m, &t](const rosgraph_msgs::msg::Clock& msg) {
          m.Take(t.clock, [&] {
            const Time now = FromRos(msg.clock());
            if (now > m.sim_clock.Now()) m.sim_clock.AdvanceTo(now);
            m.clock_seen = true;
          });
        }));
  }
  m.cmd_vel = m.node.CreatePublisher<geometry_msgs::msg::TwistPubSubType>(t.cmd_vel, reliable);
  m.arm = m.node.CreatePublisher<trajectory_msgs::msg::JointTrajectoryPubSubType>(t.arm_trajectory,
                                                                                  reliable);
  m.head = m.node.CreatePublisher<trajectory_msgs::msg::JointTrajectoryPubSubType>(
      t.head_trajectory, reliable);
  const auto goal_client = [&m](const std::string& action) {
    return m.node.CreateServiceClient<
        tmc_control_msgs::action::GripperApplyEffort_SendGoal_RequestPubSubType,
        tmc_control_msgs::action::GripperApplyEffort_SendGoal_ResponsePubSubType>(
        ActionSendGoalService(action),
        [&m](std::int64_t,
             const tmc_control_msgs::action::GripperApplyEffort_SendGoal_Response& r) {
          {
            const std::lock_guard<std::mutex> lock(m.mutex);
            ++(r.accepted() ? m.gripper_goals_accepted : m.gripper_goals_refused);
          }
          m.changed.notify_all();
        });
  };
  m.grasp_goals = goal_client(t.gripper_grasp_action);
  m.apply_force_goals = goal_client(t.gripper_apply_force_action);
  m.status = m.node.CreatePublisher<std_msgs::msg::StringPubSubType>(t.status, reliable);
  m.step_done =
      m.node.CreatePublisher<rosgraph_msgs::msg::ClockPubSubType>(t.brain_clock, reliable);
  m.estop_pub = m.node.CreatePublisher<std_msgs::msg::BoolPubSubType>(t.estop, reliable);
  m.watchdog = std::thread([&m] { m.Watch(); });
}

void Ros2RobotPort::Impl::Watch() {
  // Checks a few times per timeout (wall time); the age is by the port's clock, so a paused
  // simulation (lock-step) never trips it.
  const auto period = std::chrono::duration_cast<std::chrono::milliseconds>(
      std::chrono::duration<double>(config.command_timeout_s / 4.0));
  std::unique_lock<std::mutex> lock(mutex);
  while (!changed.wait_for(lock, std::max(period, std::chrono::milliseconds(1)),
                           [&] { return stopping; })) {
    if (!base_moving || !base_command_at ||
        ToSeconds(clock().Now() - *base_command_at) <= config.command_timeout_s)
      continue;
    base_moving = false;
    ++watchdog_stops;
    lock.unlock();
    PublishBase(Twist2{});
    lock.lock();
  }
}

Ros2RobotPort::~Ros2RobotPort() {
  {
    const std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->stopping = true;
  }
  impl_->changed.notify_all();
  impl_->watchdog.join();
  // The base stops when the brain goes: the last word on cmd_vel is zero.
  try {
    impl_->PublishBase(Twist2{});
  } catch (...) {
  }
}

const Clock& Ros2RobotPort::clock() const {
  return impl_->clock();
}

std::optional<std::string> Ros2RobotPort::Fault() const {
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->FaultLocked();
}

bool Ros2RobotPort::WaitUntilHealthy(std::chrono::milliseconds timeout) {
  Impl& m = *impl_;
  std::unique_lock<std::mutex> lock(m.mutex);
  return m.changed.wait_for(lock, timeout, [&] { return !m.FaultLocked(); });
}

std::optional<std::string> Ros2RobotPort::Impl::FaultLocked() const {
  const Impl& m = *this;
  if (m.estop) return "e-stop (" + m.config.topics.estop + ")";
  const Time now = m.clock().Now();
  const auto stale = [&](const std::optional<Time>& at, double timeout, const std::string& topic,
                         const char* what) -> std::optional<std::string> {
    const std::optional<Time> since = at ? at : m.ready_at;
    if (since && ToSeconds(now - *since) <= timeout) return std::nullopt;
    std::string reason = std::string(what) + " stale: " +
                         (at ? "nothing on " + topic + " for " +
                                   std::to_string(ToSeconds(now - *at)).substr(0, 5) + " s"
                             : "nothing on " + topic + " yet") +
                         " (limit " + std::to_string(timeout).substr(0, 4) + " s)";
    if (!m.bad_message.empty()) reason += "; last bad message: " + m.bad_message;
    return reason;
  };
  if (auto r = stale(m.scan_at, m.config.scan_timeout_s, m.config.topics.scan, "laser")) return r;
  if (auto r =
          stale(m.odometry_at, m.config.odometry_timeout_s, m.config.topics.odometry, "odometry"))
    return r;
  if (auto r = stale(m.joints_at, m.config.joints_timeout_s, m.config.topics.joint_states,
                     "joint states"))
    return r;
  return std::nullopt;
}

bool Ros2RobotPort::WaitForSensors(std::chrono::milliseconds timeout, std::string* missing) {
  Impl& m = *impl_;
  std::unique_lock<std::mutex> lock(m.mutex);
  // Odometry and joint states (and the clock): a laser's first sweep may come a period later.
  const auto ready = [&] {
    return m.odometry_at && m.joints_at && (!m.config.use_sim_time || m.clock_seen);
  };
  const bool ok = m.changed.wait_for(lock, timeout, ready);
  if (ok && !m.ready_at) m.ready_at = m.clock().Now();
  if (!ok && missing != nullptr) {
    std::string what;
    const auto add = [&](bool have, const std::string& topic) {
      if (!have) what += (what.empty() ? "" : ", ") + topic;
    };
    add(bool(m.odometry_at), m.config.topics.odometry);
    add(bool(m.joints_at), m.config.topics.joint_states);
    if (m.config.use_sim_time) add(m.clock_seen, m.config.topics.clock);
    if (!m.bad_message.empty()) what += "; last bad message: " + m.bad_message;
    *missing = what;
  }
  return ok;
}

bool Ros2RobotPort::WaitUntil(Time t, std::chrono::milliseconds timeout) {
  Impl& m = *impl_;
  if (!m.config.use_sim_time) {
    const Time now = m.system_clock.Now();
    if (t > now) std::this_thread::sleep_for(t - now);
    return true;
  }
  std::unique_lock<std::mutex> lock(m.mutex);
  return m.changed.wait_for(lock, timeout, [&] { return m.sim_clock.Now() >= t; });
}

void Ros2RobotPort::PublishStatus(std::string_view status) {
  std_msgs::msg::String msg;
  msg.data(std::string(status));
  impl_->status->Publish(msg);
}

void Ros2RobotPort::PublishStepDone(Time t) {
  rosgraph_msgs::msg::Clock msg;
  msg.clock(ToRos(t));
  impl_->step_done->Publish(msg);
}

void Ros2RobotPort::PublishEstop(bool stop) {
  std_msgs::msg::Bool msg;
  msg.data(stop);
  impl_->estop_pub->Publish(msg);
}

SensorSnapshot Ros2RobotPort::DoSense() {
  Impl& m = *impl_;
  const std::lock_guard<std::mutex> lock(m.mutex);
  SensorSnapshot s;
  s.stamp = m.clock().Now();
  m.sensed_at = s.stamp;
  s.scan = std::exchange(m.scan, std::nullopt);
  // A depth image is usable with its intrinsics and the camera's pose in the base (the latest
  // transform: they come on other topics, and may arrive after the image; it waits for them).
  if (m.depth && m.intrinsics && m.X_BC && m.intrinsics->width == m.depth->width &&
      m.intrinsics->height == m.depth->height) {
    s.depth = std::exchange(m.depth, std::nullopt);
    s.X_BC = m.X_BC;
  }
  if (m.intrinsics) s.depth_intrinsics = *m.intrinsics;
  s.color = std::exchange(m.color, std::nullopt);
  s.detections = std::exchange(m.detections, {});
  if (m.odometry) s.odometry = *m.odometry;
  if (m.joints) {
    s.joints = *m.joints;
    // The gripper's state is the hand motor joint's.
    for (std::size_t i = 0; i < m.joints->names.size(); ++i) {
      if (m.joints->names[i] != "hand_motor_joint") continue;
      s.gripper.stamp = m.joints->stamp;
      s.gripper.hand_motor_position = m.joints->positions[i];
      if (i < m.joints->efforts.size()) s.gripper.effort = std::abs(m.joints->efforts[i]);
    }
  }
  return s;
}

void Ros2RobotPort::DoSendBaseVelocity(const Twist2& V_B) {
  Impl& m = *impl_;
  Twist2 out = V_B;
  {
    const std::lock_guard<std::mutex> lock(m.mutex);
    const Time now = m.clock().Now();
    // Faulted, the base gets only zero, whatever the brain asks; so does a command decided
    // from a Sense() older than the timeout (the brain acted on a world that has moved on).
    if (m.FaultLocked()) {
      out = Twist2{};
    } else if (!m.sensed_at || ToSeconds(now - *m.sensed_at) > m.config.command_timeout_s) {
      out = Twist2{};
      ++m.stale_base_commands;
    }
    m.base_command_at = now;
    m.base_moving = out.vx != 0.0 || out.vy != 0.0 || out.wz != 0.0;
  }
  m.PublishBase(out);
}

void Ros2RobotPort::DoSendArmTrajectory(const JointTrajectory& trajectory) {
  // A start of 0 means "on receipt"; a set start must be recent, or the controller would
  // truncate (or jump through) the part that lies in the past.
  if (trajectory.start != Time{}) {
    const double age = ToSeconds(clock().Now() - trajectory.start);
    ThrowUnless(age <= impl_->config.command_timeout_s, "arm trajectory: start stamp is ", age,
                " s old (command_timeout_s ", impl_->config.command_timeout_s, "): not sent");
  }
  impl_->arm->Publish(ToRos(trajectory));
}

void Ros2RobotPort::DoSendHeadCommand(const HeadCommand& command) {
  std::optional<JointState> joints;
  {
    const std::lock_guard<std::mutex> lock(impl_->mutex);
    joints = impl_->joints;
  }
  impl_->head->Publish(ToRos(HeadTrajectory(command, joints)));
}

int Ros2RobotPort::stale_base_commands() const {
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->stale_base_commands;
}

int Ros2RobotPort::watchdog_stops() const {
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->watchdog_stops;
}

void Ros2RobotPort::DoSendGripperCommand(const GripperCommand& command) {
  Impl& m = *impl_;
  const GripperGoal goal = GripperToRos(command, m.config.gripper_open_torque);
  tmc_control_msgs::action::GripperApplyEffort_SendGoal_Request request;
  const std::uint64_t id[2] = {m.goal_prefix, ++m.goals_sent};
  std::memcpy(request.goal_id().uuid().data(), id, sizeof(id));
  request.goal(goal.goal);
  auto& client = goal.action == GripperGoal::Action::kGrasp ? m.grasp_goals : m.apply_force_goals;
  // A goal sent before the controller's action server is matched would be lost without a word.
  if (!client->WaitForServer(kGripperServerWait))
    throw std::runtime_error("gripper: no action server on " + client->service() + " after " +
                             std::to_string(kGripperServerWait.count()) +
                             " ms: the goal was not sent");
  client->Call(request);
}

bool Ros2RobotPort::GripperConnected() const {
  return impl_->grasp_goals->ServerMatched() && impl_->apply_force_goals->ServerMatched();
}

bool Ros2RobotPort::CommandsConnected() const {
  const Impl& m = *impl_;
  return m.cmd_vel->MatchedSubscriptions() > 0 && m.arm->MatchedSubscriptions() > 0 &&
         m.head->MatchedSubscriptions() > 0;
}

std::pair<int, int> Ros2RobotPort::gripper_goals() const {
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  return {impl_->gripper_goals_accepted, impl_->gripper_goals_refused};
}

}  // namespace egress::ros2
