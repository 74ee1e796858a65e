#include "egress/ros2/robot_port_server.h"

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <vector>

#include <geometry_msgs/msg/TwistPubSubTypes.h>
#include <nav_msgs/msg/OdometryPubSubTypes.h>
#include <rosgraph_msgs/msg/ClockPubSubTypes.h>
#include <sensor_msgs/msg/CameraInfoPubSubTypes.h>
#include <sensor_msgs/msg/ImagePubSubTypes.h>
#include <sensor_msgs/msg/JointStatePubSubTypes.h>
#include <sensor_msgs/msg/LaserScanPubSubTypes.h>
#include <std_msgs/msg/StringPubSubTypes.h>
#include <tf2_msgs/msg/TFMessagePubSubTypes.h>
#include <tmc_control_msgs/action/GripperApplyEffortPubSubTypes.h>
#include <trajectory_msgs/msg/JointTrajectoryPubSubTypes.h>
#include <vision_msgs/msg/Detection2DArrayPubSubTypes.h>

#include "egress/hsr_interface/frames.h"
#include "egress/ros2/conversions.h"
#include "egress/ros2/dds_node.h"

namespace egress::ros2 {

struct RobotPortServer::Impl {
  RobotPort& robot;
  Ros2Topics topics;
  DdsNode node;

  mutable std::mutex mutex;
  std::condition_variable changed;
  std::deque<std::function<void()>> commands;  // applied on the caller's thread
  std::vector<std::string> rejected;
  std::optional<Time> step_done;
  // Wall time of the last PublishSensors, and the delay from it to each base command's receipt.
  std::chrono::steady_clock::time_point published_at{};
  std::vector<double> command_latencies;
  std::optional<std::string> status;
  Time robot_time{};  // the robot's time at the last PublishSensors (goal replies' stamps)

  std::unique_ptr<Publisher<rosgraph_msgs::msg::ClockPubSubType>> clock;
  std::unique_ptr<Publisher<sensor_msgs::msg::LaserScanPubSubType>> scan;
  std::unique_ptr<Publisher<nav_msgs::msg::OdometryPubSubType>> odometry;
  std::unique_ptr<Publisher<sensor_msgs::msg::JointStatePubSubType>> joints;
  std::unique_ptr<Publisher<sensor_msgs::msg::ImagePubSubType>> depth, color;
  std::unique_ptr<Publisher<sensor_msgs::msg::CameraInfoPubSubType>> camera_info;
  std::unique_ptr<Publisher<tf2_msgs::msg::TFMessagePubSubType>> tf;
  std::unique_ptr<Publisher<vision_msgs::msg::Detection2DArrayPubSubType>> detections;
  std::unique_ptr<Subscription<geometry_msgs::msg::TwistPubSubType>> cmd_vel;
  std::vector<std::unique_ptr<eprosima::fastdds::dds::DataReaderListener>> subscriptions;
  using GripperGoalServer =
      ServiceServer<tmc_control_msgs::action::GripperApplyEffort_SendGoal_RequestPubSubType,
                    tmc_control_msgs::action::GripperApplyEffort_SendGoal_ResponsePubSubType>;
  std::unique_ptr<GripperGoalServer> grasp_goals, apply_force_goals;
  std::optional<Time> last_odometry, last_joints;
  // The latest of each, for RepublishLatest().
  std::optional<sensor_msgs::msg::LaserScan> scan_msg;
  std::optional<nav_msgs::msg::Odometry> odometry_msg;
  std::optional<sensor_msgs::msg::JointState> joints_msg;
  std::optional<rosgraph_msgs::msg::Clock> clock_msg;

  Impl(RobotPort& r, Ros2Topics t, int domain, bool udp_only, std::string_view name)
      : robot(r), topics(std::move(t)), node(name, domain, udp_only) {}

  template <class F>
  void Queue(const std::string& topic, F apply) {
    {
      const std::lock_guard<std::mutex> lock(mutex);
      commands.push_back([this, topic, apply = std::move(apply)] {
        try {
          apply();
        } catch (const std::exception& e) {
          const std::lock_guard<std::mutex> lock(mutex);
          rejected.push_back(topic + ": " + e.what());
        }
      });
    }
    changed.notify_all();
  }
};

RobotPortServer::RobotPortServer(RobotPort& robot, Ros2Topics topics, int domain_id,
                                 bool reliable_sensors, std::string_view node_name) {
  topics.Validate();
  impl_ = std::make_unique<Impl>(robot, std::move(topics), domain_id,
                                 /*udp_only=*/reliable_sensors, node_name);
  Impl& m = *impl_;
  const Ros2Topics& t = m.topics;
  const QosProfile reliable = QosProfile::Default();
  const QosProfile sensor = reliable_sensors ? reliable : QosProfile::SensorData();
  m.clock = m.node.CreatePublisher<rosgraph_msgs::msg::ClockPubSubType>(
      t.clock, reliable_sensors ? reliable : QosProfile::Clock());
  m.scan = m.node.CreatePublisher<sensor_msgs::msg::LaserScanPubSubType>(t.scan, sensor);
  m.odometry = m.node.CreatePublisher<nav_msgs::msg::OdometryPubSubType>(t.odometry, sensor);
  m.joints = m.node.CreatePublisher<sensor_msgs::msg::JointStatePubSubType>(t.joint_states, sensor);
  m.depth = m.node.CreatePublisher<sensor_msgs::msg::ImagePubSubType>(t.depth_image, sensor);
  m.color = m.node.CreatePublisher<sensor_msgs::msg::ImagePubSubType>(t.color_image, sensor);
  m.camera_info =
      m.node.CreatePublisher<sensor_msgs::msg::CameraInfoPubSubType>(t.depth_camera_info, sensor);
  m.tf = m.node.CreatePublisher<tf2_msgs::msg::TFMessagePubSubType>(t.tf, reliable);
  m.detections =
      m.node.CreatePublisher<vision_msgs::msg::Detection2DArrayPubSubType>(t.detections, reliable);
  m.cmd_vel = m.node.CreateSubscription<geometry_msgs::msg::TwistPubSubType>(
      t.cmd_vel, reliable, [&m](const geometry_msgs::msg::Twist& msg) {
        {
          const std::lock_guard<std::mutex> lock(m.mutex);
          m.command_latencies.push_back(
              std::chrono::duration<double>(std::chrono::steady_clock::now() - m.published_at)
                  .count());
        }
        m.Queue(m.topics.cmd_vel, [&m, V = FromRos(msg)] { m.robot.SendBaseVelocity(V); });
      });
  m.subscriptions.push_back(
      m.node.CreateSubscription<trajectory_msgs::msg::JointTrajectoryPubSubType>(
          t.arm_trajectory, reliable, [&m](const trajectory_msgs::msg::JointTrajectory& msg) {
            m.Queue(m.topics.arm_trajectory,
                    [&m, msg] { m.robot.SendArmTrajectory(FromRos(msg)); });
          }));
  m.subscriptions.push_back(
      m.node.CreateSubscription<trajectory_msgs::msg::JointTrajectoryPubSubType>(
          t.head_trajectory, reliable, [&m](const trajectory_msgs::msg::JointTrajectory& msg) {
            try {
              const HeadCommand command = HeadFromTrajectory(FromRos(msg));
              m.Queue(m.topics.head_trajectory,
                      [&m, command] { m.robot.SendHeadCommand(command); });
            } catch (const std::exception& e) {
              const std::lock_guard<std::mutex> lock(m.mutex);
              m.rejected.push_back(m.topics.head_trajectory + ": " + e.what());
            }
          }));
  // The gripper controller's action goals: accepted (and queued) or refused with why.
  const auto serve_goals = [&m](const std::string& action, GripperGoal::Action kind) {
    return m.node.CreateServiceServer<
        tmc_control_msgs::action::GripperApplyEffort_SendGoal_RequestPubSubType,
        tmc_control_msgs::action::GripperApplyEffort_SendGoal_ResponsePubSubType>(
        ActionSendGoalService(action),
        [&m, action, kind](const tmc_control_msgs::action::GripperApplyEffort_SendGoal_Request& r) {
          tmc_control_msgs::action::GripperApplyEffort_SendGoal_Response reply;
          try {
            const GripperCommand command = GripperFromRos({kind, r.goal()});
            m.Queue(action, [&m, command] { m.robot.SendGripperCommand(command); });
            reply.accepted(true);
          } catch (const std::exception& e) {
            const std::lock_guard<std::mutex> lock(m.mutex);
            m.rejected.push_back(action + ": " + e.what());
            reply.accepted(false);
          }
          const std::lock_guard<std::mutex> lock(m.mutex);
          reply.stamp(ToRos(m.robot_time));
          return reply;
        });
  };
  m.grasp_goals = serve_goals(t.gripper_grasp_action, GripperGoal::Action::kGrasp);
  m.apply_force_goals = serve_goals(t.gripper_apply_force_action, GripperGoal::Action::kApplyForce);
  m.subscriptions.push_back(m.node.CreateSubscription<rosgraph_msgs::msg::ClockPubSubType>(
      t.brain_clock, reliable, [&m](const rosgraph_msgs::msg::Clock& msg) {
        {
          const std::lock_guard<std::mutex> lock(m.mutex);
          m.step_done = FromRos(msg.clock());
        }
        m.changed.notify_all();
      }));
  m.subscriptions.push_back(m.node.CreateSubscription<std_msgs::msg::StringPubSubType>(
      t.status, reliable, [&m](const std_msgs::msg::String& msg) {
        const std::lock_guard<std::mutex> lock(m.mutex);
        m.status = msg.data();
      }));
}

RobotPortServer::~RobotPortServer() = default;

void RobotPortServer::PublishSensors() {
  Impl& m = *impl_;
  const SensorSnapshot s = m.robot.Sense();
  if (s.scan) {
    m.scan_msg = ToRos(*s.scan);
    m.scan->Publish(*m.scan_msg);
  }
  if (!m.last_odometry || s.odometry.stamp != *m.last_odometry) {
    m.odometry_msg = ToRos(s.odometry);
    m.odometry->Publish(*m.odometry_msg);
    m.last_odometry = s.odometry.stamp;
  }
  if (!m.last_joints || s.joints.stamp != *m.last_joints) {
    // The gripper's state rides on the joint states, as the HSR's does: hand_motor_joint's
    // position and, as its effort, the grip force.
    JointState joints = s.joints;
    auto it = std::find(joints.names.begin(), joints.names.end(), "hand_motor_joint");
    if (it == joints.names.end()) {
      joints.names.push_back("hand_motor_joint");
      joints.positions.push_back(s.gripper.hand_motor_position);
      if (!joints.velocities.empty()) joints.velocities.push_back(0.0);
      it = joints.names.end() - 1;
    }
    joints.efforts.resize(joints.names.size(), 0.0);
    joints.efforts[std::size_t(it - joints.names.begin())] = s.gripper.effort;
    m.joints_msg = ToRos(joints);
    m.joints->Publish(*m.joints_msg);
    m.last_joints = s.joints.stamp;
  }
  if (s.depth) {
    // The camera's pose at the image's time first, so that it is there when the image is.
    if (s.X_BC) {
      tf2_msgs::msg::TFMessage tf;
      geometry_msgs::msg::TransformStamped T;
      T.header().stamp(ToRos(s.depth->stamp));
      T.header().frame_id(std::string(frames::kBase));
      T.child_frame_id(std::string(frames::kHeadCamera));
      T.transform(ToRos(*s.X_BC));
      tf.transforms().push_back(T);
      m.tf->Publish(tf);
    }
    m.camera_info->Publish(ToRos(s.depth_intrinsics, s.depth->stamp, s.depth->frame_id));
    m.depth->Publish(ToRos(*s.depth));
  }
  if (s.color) m.color->Publish(ToRos(*s.color));
  if (!s.detections.empty()) {
    // One array per captured image.
    std::size_t begin = 0;
    for (std::size_t i = 1; i <= s.detections.size(); ++i) {
      if (i < s.detections.size() && s.detections[i].stamp == s.detections[begin].stamp) continue;
      const std::vector<Detection2D> same(s.detections.begin() + long(begin),
                                          s.detections.begin() + long(i));
      m.detections->Publish(ToRos(same, same.front().stamp, same.front().frame_id));
      begin = i;
    }
  }
  // The clock last: a brain that steps when its clock moves finds this step's readings there.
  rosgraph_msgs::msg::Clock clock;
  clock.clock(ToRos(s.stamp));
  m.clock->Publish(clock);
  m.clock_msg = clock;
  const std::lock_guard<std::mutex> lock(m.mutex);
  m.published_at = std::chrono::steady_clock::now();
  m.robot_time = s.stamp;
}

std::vector<double> RobotPortServer::TakeCommandLatencies() {
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  return std::exchange(impl_->command_latencies, {});
}

void RobotPortServer::RepublishLatest() {
  Impl& m = *impl_;
  if (m.scan_msg) m.scan->Publish(*m.scan_msg);
  if (m.odometry_msg) m.odometry->Publish(*m.odometry_msg);
  if (m.joints_msg) m.joints->Publish(*m.joints_msg);
  if (m.clock_msg) m.clock->Publish(*m.clock_msg);
}

int RobotPortServer::ApplyCommands() {
  Impl& m = *impl_;
  std::deque<std::function<void()>> pending;
  {
    const std::lock_guard<std::mutex> lock(m.mutex);
    pending.swap(m.commands);
  }
  for (auto& apply : pending)
    apply();
  return int(pending.size());
}

bool RobotPortServer::WaitForStepDone(Time t, std::chrono::milliseconds timeout) {
  Impl& m = *impl_;
  std::unique_lock<std::mutex> lock(m.mutex);
  return m.changed.wait_for(lock, timeout, [&] { return m.step_done && *m.step_done >= t; });
}

std::optional<std::string> RobotPortServer::brain_status() const {
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->status;
}

bool RobotPortServer::BrainConnected() const {
  // Every sensor topic read and the base command written: a brain matched on some topics only
  // would miss the first readings of the others (volatile topics keep nothing for late
  // readers). Its gripper goals wait for their server themselves (Ros2RobotPort).
  const Impl& m = *impl_;
  const bool sensors =
      m.scan->MatchedSubscriptions() > 0 && m.odometry->MatchedSubscriptions() > 0 &&
      m.joints->MatchedSubscriptions() > 0 && m.depth->MatchedSubscriptions() > 0 &&
      m.camera_info->MatchedSubscriptions() > 0 && m.tf->MatchedSubscriptions() > 0 &&
      m.clock->MatchedSubscriptions() > 0;
  return sensors && m.cmd_vel->MatchedPublications() > 0;
}

std::vector<std::string> RobotPortServer::TakeRejected() {
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  return std::exchange(impl_->rejected, {});
}

}  // namespace egress::ros2
