#include "egress/ros2/ros2_robot_port.h"

#include <cmath>
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
#include <trajectory_msgs/msg/JointTrajectoryPubSubTypes.h>
#include <vision_msgs/msg/Detection2DArrayPubSubTypes.h>

#include "egress/hsr_interface/error.h"
#include "egress/hsr_interface/frames.h"
#include "egress/ros2/conversions.h"
#include "egress/ros2/dds_node.h"

namespace egress::ros2 {

void Ros2RobotPortConfig::Validate() const {
  topics.Validate();
  for (const auto& [name, value] : {std::pair{"scan_timeout_s", scan_timeout_s},
                                    std::pair{"odometry_timeout_s", odometry_timeout_s},
                                    std::pair{"joints_timeout_s", joints_timeout_s}}) {
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

  std::vector<std::unique_ptr<eprosima::fastdds::dds::DataReaderListener>> subscriptions;
  std::unique_ptr<Publisher<geometry_msgs::msg::TwistPubSubType>> cmd_vel;
  std::unique_ptr<Publisher<trajectory_msgs::msg::JointTrajectoryPubSubType>> arm, gripper;
  std::unique_ptr<Publisher<std_msgs::msg::StringPubSubType>> status;
  std::unique_ptr<Publisher<rosgraph_msgs::msg::ClockPubSubType>> step_done;
  std::unique_ptr<Publisher<std_msgs::msg::BoolPubSubType>> estop_pub;

  std::optional<std::string> FaultLocked() const;  // with `mutex` held

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
  m.gripper = m.node.CreatePublisher<trajectory_msgs::msg::JointTrajectoryPubSubType>(
      t.gripper_trajectory, reliable);
  m.status = m.node.CreatePublisher<std_msgs::msg::StringPubSubType>(t.status, reliable);
  m.step_done =
      m.node.CreatePublisher<rosgraph_msgs::msg::ClockPubSubType>(t.brain_clock, reliable);
  m.estop_pub = m.node.CreatePublisher<std_msgs::msg::BoolPubSubType>(t.estop, reliable);
}

Ros2RobotPort::~Ros2RobotPort() {
  // The base stops when the brain goes: the last word on cmd_vel is zero.
  try {
    impl_->cmd_vel->Publish(ToRos(Twist2{}));
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
  // Faulted, the base gets only zero, whatever the brain asks.
  impl_->cmd_vel->Publish(ToRos(Fault() ? Twist2{} : V_B));
}

void Ros2RobotPort::DoSendArmTrajectory(const JointTrajectory& trajectory) {
  impl_->arm->Publish(ToRos(trajectory));
}

void Ros2RobotPort::DoSendGripperCommand(const GripperCommand& command) {
  impl_->gripper->Publish(GripperToRos(command));
}

}  // namespace egress::ros2
