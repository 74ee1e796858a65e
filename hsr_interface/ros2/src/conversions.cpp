#include "egress/ros2/conversions.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "egress/hsr_interface/error.h"

namespace egress::ros2 {
namespace {

constexpr std::int64_t kNsPerSec = 1'000'000'000;
// What a planar base reports for z, roll and pitch: nothing known (a large variance).
constexpr double kUnknownVariance = 1e6;

std_msgs::msg::Header MakeHeader(Time stamp, std::string_view frame_id) {
  std_msgs::msg::Header header;
  header.stamp(ToRos(stamp));
  header.frame_id(std::string(frame_id));
  return header;
}

}  // namespace

builtin_interfaces::msg::Time ToRos(Time t) {
  const std::int64_t ns = t.count();
  ThrowUnless(ns >= 0 && ns / kNsPerSec <= std::numeric_limits<std::int32_t>::max(),
              "builtin_interfaces/Time: ", ns, " ns is outside ROS's range (0 to 2^31 s)");
  builtin_interfaces::msg::Time msg;
  msg.sec(std::int32_t(ns / kNsPerSec));
  msg.nanosec(std::uint32_t(ns % kNsPerSec));
  return msg;
}

Time FromRos(const builtin_interfaces::msg::Time& t) {
  ThrowUnless(t.nanosec() < kNsPerSec, "builtin_interfaces/Time: nanosec (", t.nanosec(),
              ") must be below 1e9");
  return Time{std::int64_t(t.sec()) * kNsPerSec + std::int64_t(t.nanosec())};
}

builtin_interfaces::msg::Duration DurationToRos(Duration d) {
  const std::int64_t ns = d.count();
  // ROS's Duration: sec may be negative, nanosec always in [0, 1e9).
  std::int64_t sec = ns / kNsPerSec, rem = ns % kNsPerSec;
  if (rem < 0) {
    rem += kNsPerSec;
    --sec;
  }
  ThrowUnless(sec >= std::numeric_limits<std::int32_t>::min() &&
                  sec <= std::numeric_limits<std::int32_t>::max(),
              "builtin_interfaces/Duration: ", ns, " ns is outside ROS's range (2^31 s)");
  builtin_interfaces::msg::Duration msg;
  msg.sec(std::int32_t(sec));
  msg.nanosec(std::uint32_t(rem));
  return msg;
}

Duration FromRos(const builtin_interfaces::msg::Duration& d) {
  ThrowUnless(d.nanosec() < kNsPerSec, "builtin_interfaces/Duration: nanosec (", d.nanosec(),
              ") must be below 1e9");
  return Duration{std::int64_t(d.sec()) * kNsPerSec + std::int64_t(d.nanosec())};
}

sensor_msgs::msg::LaserScan ToRos(const LaserScan& scan) {
  sensor_msgs::msg::LaserScan msg;
  msg.header(MakeHeader(scan.stamp, scan.frame_id));
  msg.angle_min(float(scan.angle_min));
  msg.angle_max(float(scan.angle_max()));
  msg.angle_increment(float(scan.angle_increment));
  msg.range_min(float(scan.range_min));
  msg.range_max(float(scan.range_max));
  msg.ranges(scan.ranges);
  msg.intensities(scan.intensities);
  return msg;
}

LaserScan FromRos(const sensor_msgs::msg::LaserScan& msg) {
  ThrowUnless(msg.intensities().empty() || msg.intensities().size() == msg.ranges().size(),
              "sensor_msgs/LaserScan: intensities (", msg.intensities().size(),
              ") must be empty or as many as ranges (", msg.ranges().size(), ")");
  LaserScan scan;
  scan.frame_id = msg.header().frame_id();
  scan.stamp = FromRos(msg.header().stamp());
  scan.angle_min = msg.angle_min();
  scan.angle_increment = msg.angle_increment();
  scan.range_min = msg.range_min();
  scan.range_max = msg.range_max();
  scan.ranges = msg.ranges();
  scan.intensities = msg.intensities();
  return scan;
}

sensor_msgs::msg::Image ToRos(const DepthImage& depth) {
  sensor_msgs::msg::Image msg;
  msg.header(MakeHeader(depth.stamp, depth.frame_id));
  msg.height(std::uint32_t(depth.height));
  msg.width(std::uint32_t(depth.width));
  msg.encoding("32FC1");
  msg.is_bigendian(0);
  msg.step(std::uint32_t(depth.width) * sizeof(float));
  msg.data().resize(depth.depth.size() * sizeof(float));
  std::memcpy(msg.data().data(), depth.depth.data(), msg.data().size());
  return msg;
}

namespace {
// Checks an image's size fields against its data for `bytes_per_pixel`; returns width, height.
std::pair<int, int> CheckImage(const sensor_msgs::msg::Image& msg, std::size_t bytes_per_pixel) {
  const std::string& e = msg.encoding();
  ThrowUnless(
      msg.width() > 0 && msg.height() > 0 && msg.width() < (1u << 16) && msg.height() < (1u << 16),
      "sensor_msgs/Image (", e, "): size ", msg.width(), "x", msg.height(),
      " must be positive and below 65536");
  ThrowUnless(msg.step() >= msg.width() * bytes_per_pixel, "sensor_msgs/Image (", e, "): step (",
              msg.step(), ") is shorter than a row (", msg.width() * bytes_per_pixel, " bytes)");
  ThrowUnless(msg.data().size() == std::size_t(msg.step()) * msg.height(), "sensor_msgs/Image (", e,
              "): data holds ", msg.data().size(), " bytes, step x height is ",
              std::size_t(msg.step()) * msg.height());
  ThrowUnless(msg.is_bigendian() == 0 || bytes_per_pixel == 1 || e == "bgr8" || e == "rgb8",
              "sensor_msgs/Image (", e, "): big-endian data is not supported");
  return {int(msg.width()), int(msg.height())};
}
}  // namespace

DepthImage DepthFromRos(const sensor_msgs::msg::Image& msg) {
  const std::string& e = msg.encoding();
  const bool metres = e == "32FC1";
  ThrowUnless(metres || e == "16UC1", "sensor_msgs/Image: depth encoding '", e,
              "' is not supported (32FC1 metres or 16UC1 millimetres)");
  const auto [w, h] = CheckImage(msg, metres ? 4 : 2);
  DepthImage depth;
  depth.frame_id = msg.header().frame_id();
  depth.stamp = FromRos(msg.header().stamp());
  depth.width = w;
  depth.height = h;
  depth.depth.resize(std::size_t(w) * std::size_t(h));
  for (int v = 0; v < h; ++v) {
    const std::uint8_t* row = msg.data().data() + std::size_t(v) * msg.step();
    for (int u = 0; u < w; ++u) {
      float z;
      if (metres) {
        std::memcpy(&z, row + std::size_t(u) * 4, 4);
      } else {
        std::uint16_t mm;
        std::memcpy(&mm, row + std::size_t(u) * 2, 2);
        z = mm == 0 ? std::numeric_limits<float>::quiet_NaN() : float(mm) * 1e-3f;
      }
      depth.depth[std::size_t(v) * std::size_t(w) + std::size_t(u)] = z;
    }
  }
  return depth;
}

sensor_msgs::msg::Image ToRos(const ColorImage& color) {
  sensor_msgs::msg::Image msg;
  msg.header(MakeHeader(color.stamp, color.frame_id));
  msg.height(std::uint32_t(color.height));
  msg.width(std::uint32_t(color.width));
  msg.encoding("bgr8");
  msg.is_bigendian(0);
  msg.step(std::uint32_t(color.width) * 3);
  msg.data().assign(color.bgr.begin(), color.bgr.end());
  return msg;
}

ColorImage ColorFromRos(const sensor_msgs::msg::Image& msg) {
  const std::string& e = msg.encoding();
  ThrowUnless(e == "bgr8" || e == "rgb8", "sensor_msgs/Image: colour encoding '", e,
              "' is not supported (bgr8 or rgb8)");
  const auto [w, h] = CheckImage(msg, 3);
  ColorImage color;
  color.frame_id = msg.header().frame_id();
  color.stamp = FromRos(msg.header().stamp());
  color.width = w;
  color.height = h;
  color.bgr.resize(std::size_t(w) * std::size_t(h) * 3);
  for (int v = 0; v < h; ++v) {
    const std::uint8_t* row = msg.data().data() + std::size_t(v) * msg.step();
    for (int u = 0; u < w; ++u) {
      std::uint8_t* out = &color.bgr[(std::size_t(v) * std::size_t(w) + std::size_t(u)) * 3];
      const std::uint8_t* in = row + std::size_t(u) * 3;
      for (int c = 0; c < 3; ++c)
        out[c] = in[e == "bgr8" ? c : 2 - c];
    }
  }
  return color;
}

sensor_msgs::msg::CameraInfo ToRos(const CameraIntrinsics& K, Time stamp,
                                   std::string_view frame_id) {
  sensor_msgs::msg::CameraInfo msg;
  msg.header(MakeHeader(stamp, frame_id));
  msg.height(std::uint32_t(K.height));
  msg.width(std::uint32_t(K.width));
  msg.distortion_model("plumb_bob");
  msg.d(std::vector<double>(5, 0.0));
  msg.k({K.fx, 0.0, K.cx, 0.0, K.fy, K.cy, 0.0, 0.0, 1.0});
  msg.r({1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0});
  msg.p({K.fx, 0.0, K.cx, 0.0, 0.0, K.fy, K.cy, 0.0, 0.0, 0.0, 1.0, 0.0});
  return msg;
}

CameraIntrinsics FromRos(const sensor_msgs::msg::CameraInfo& msg) {
  const auto& k = msg.k();
  ThrowUnless(k[0] > 0.0 && k[4] > 0.0,
              "sensor_msgs/CameraInfo: K has no focal length (an uncalibrated camera)");
  CameraIntrinsics K;
  K.width = int(msg.width());
  K.height = int(msg.height());
  K.fx = k[0];
  K.fy = k[4];
  K.cx = k[2];
  K.cy = k[5];
  return K;
}

sensor_msgs::msg::JointState ToRos(const JointState& joints) {
  sensor_msgs::msg::JointState msg;
  msg.header(MakeHeader(joints.stamp, ""));
  msg.name(joints.names);
  msg.position(joints.positions);
  msg.velocity(joints.velocities);
  msg.effort(joints.efforts);
  return msg;
}

JointState FromRos(const sensor_msgs::msg::JointState& msg) {
  JointState joints;
  joints.stamp = FromRos(msg.header().stamp());
  joints.names = msg.name();
  joints.positions = msg.position();
  joints.velocities = msg.velocity();
  joints.efforts = msg.effort();
  return joints;
}

nav_msgs::msg::Odometry ToRos(const Odometry& odometry) {
  nav_msgs::msg::Odometry msg;
  msg.header(MakeHeader(odometry.stamp, frames::kOdom));
  msg.child_frame_id(std::string(frames::kBase));
  auto& pose = msg.pose().pose();
  pose.position().x(odometry.X_OB.x);
  pose.position().y(odometry.X_OB.y);
  pose.orientation().z(std::sin(odometry.X_OB.yaw / 2));
  pose.orientation().w(std::cos(odometry.X_OB.yaw / 2));
  auto& twist = msg.twist().twist();
  twist.linear().x(odometry.V_B.vx);
  twist.linear().y(odometry.V_B.vy);
  twist.angular().z(odometry.V_B.wz);
  // (x, y, yaw) are rows/columns 0, 1, 5 of ROS's (x, y, z, roll, pitch, yaw).
  constexpr int kIndex[3] = {0, 1, 5};
  auto& pc = msg.pose().covariance();
  auto& tc = msg.twist().covariance();
  for (int i : {2, 3, 4}) {
    pc[std::size_t(i * 6 + i)] = kUnknownVariance;
    tc[std::size_t(i * 6 + i)] = kUnknownVariance;
  }
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c)
      pc[std::size_t(kIndex[r] * 6 + kIndex[c])] = odometry.covariance(r, c);
  }
  return msg;
}

namespace {
double YawOf(const geometry_msgs::msg::Quaternion& q, std::string_view what) {
  const double n = q.x() * q.x() + q.y() * q.y() + q.z() * q.z() + q.w() * q.w();
  ThrowUnless(n > 1e-12 && std::isfinite(n), what,
              ": the orientation quaternion is zero or "
              "not finite");
  // Yaw of the rotation (ZYX convention), in a form that holds for any scale of q.
  return std::atan2(2.0 * (q.w() * q.z() + q.x() * q.y()),
                    q.w() * q.w() + q.x() * q.x() - q.y() * q.y() - q.z() * q.z());
}
}  // namespace

Odometry FromRos(const nav_msgs::msg::Odometry& msg) {
  Odometry odometry;
  odometry.stamp = FromRos(msg.header().stamp());
  const auto& pose = msg.pose().pose();
  odometry.X_OB = {pose.position().x(), pose.position().y(),
                   YawOf(pose.orientation(), "nav_msgs/Odometry pose")};
  const auto& twist = msg.twist().twist();
  odometry.V_B = {twist.linear().x(), twist.linear().y(), twist.angular().z()};
  constexpr int kIndex[3] = {0, 1, 5};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c)
      odometry.covariance(r, c) = msg.pose().covariance()[std::size_t(kIndex[r] * 6 + kIndex[c])];
  }
  return odometry;
}

geometry_msgs::msg::Twist ToRos(const Twist2& V_B) {
  geometry_msgs::msg::Twist msg;
  msg.linear().x(V_B.vx);
  msg.linear().y(V_B.vy);
  msg.angular().z(V_B.wz);
  return msg;
}

Twist2 FromRos(const geometry_msgs::msg::Twist& msg) {
  return {msg.linear().x(), msg.linear().y(), msg.angular().z()};
}

geometry_msgs::msg::Transform ToRos(const Pose3& X_AB) {
  geometry_msgs::msg::Transform msg;
  const Eigen::Vector3d& p = X_AB.translation();
  msg.translation().x(p.x());
  msg.translation().y(p.y());
  msg.translation().z(p.z());
  const Eigen::Quaterniond q = X_AB.quaternion().normalized();
  msg.rotation().x(q.x());
  msg.rotation().y(q.y());
  msg.rotation().z(q.z());
  msg.rotation().w(q.w());
  return msg;
}

Pose3 FromRos(const geometry_msgs::msg::Transform& msg) {
  const auto& r = msg.rotation();
  const Eigen::Quaterniond q(r.w(), r.x(), r.y(), r.z());
  ThrowUnless(q.norm() > 1e-6 && std::isfinite(q.norm()),
              "geometry_msgs/Transform: the rotation quaternion is zero or not finite");
  return Pose3(q.normalized(), Eigen::Vector3d(msg.translation().x(), msg.translation().y(),
                                               msg.translation().z()));
}

trajectory_msgs::msg::JointTrajectory ToRos(const JointTrajectory& trajectory) {
  trajectory_msgs::msg::JointTrajectory msg;
  msg.header(MakeHeader(trajectory.start, ""));
  msg.joint_names(trajectory.joint_names);
  for (const JointTrajectoryPoint& p : trajectory.points) {
    trajectory_msgs::msg::JointTrajectoryPoint point;
    point.positions(p.positions);
    point.velocities(p.velocities);
    point.accelerations(p.accelerations);
    point.time_from_start(DurationToRos(p.time_from_start));
    msg.points().push_back(std::move(point));
  }
  return msg;
}

JointTrajectory FromRos(const trajectory_msgs::msg::JointTrajectory& msg) {
  JointTrajectory trajectory;
  trajectory.start = FromRos(msg.header().stamp());
  trajectory.joint_names = msg.joint_names();
  for (const auto& p : msg.points()) {
    trajectory.points.push_back(
        {p.positions(), p.velocities(), p.accelerations(), FromRos(p.time_from_start())});
  }
  return trajectory;
}

JointTrajectory HeadTrajectory(const HeadCommand& command, const std::optional<JointState>& from) {
  constexpr double kMinMoveSec = 0.1;
  double travel = 0.0;
  if (from) {
    if (const auto pan = from->Position("head_pan_joint"))
      travel = std::max(travel, std::abs(command.pan - *pan));
    if (const auto tilt = from->Position("head_tilt_joint"))
      travel = std::max(travel, std::abs(command.tilt - *tilt));
  }
  JointTrajectory trajectory;
  trajectory.joint_names = {"head_pan_joint", "head_tilt_joint"};
  JointTrajectoryPoint point;
  point.positions = {command.pan, command.tilt};
  point.time_from_start = SecondsToDuration(std::max(kMinMoveSec, travel / kHeadSpeedRadPerSec));
  trajectory.points.push_back(std::move(point));
  return trajectory;
}

HeadCommand HeadFromTrajectory(const JointTrajectory& trajectory) {
  trajectory.Validate();
  ThrowUnless(!trajectory.points.empty(), "head trajectory: no points");
  ThrowUnless(trajectory.joint_names.size() == 2, "head trajectory: expected head_pan_joint and ",
              "head_tilt_joint, got ", trajectory.joint_names.size(), " joint(s)");
  std::optional<double> pan, tilt;
  const auto& last = trajectory.points.back().positions;
  for (std::size_t j = 0; j < 2; ++j) {
    const std::string& name = trajectory.joint_names[j];
    if (name == "head_pan_joint") {
      pan = last[j];
    } else if (name == "head_tilt_joint") {
      tilt = last[j];
    } else {
      throw InvalidArgument(StrCat("head trajectory: '", name,
                                   "' is not a head joint (head_pan_joint, head_tilt_joint)"));
    }
  }
  ThrowUnless(pan && tilt, "head trajectory: needs both head_pan_joint and head_tilt_joint");
  HeadCommand command{*pan, *tilt};
  command.Validate();
  return command;
}

GripperGoal GripperToRos(const GripperCommand& command, double open_torque) {
  GripperGoal out;
  switch (command.mode) {
    case GripperCommand::Mode::kOpen:
      ThrowUnless(std::isfinite(open_torque) && open_torque > 0.0,
                  "gripper: the opening torque must be > 0 Nm, not ", open_torque);
      out.action = GripperGoal::Action::kGrasp;
      out.goal.effort(open_torque);
      break;
    case GripperCommand::Mode::kGrasp:
      out.action = GripperGoal::Action::kApplyForce;
      out.goal.effort(command.effort);
      break;
    case GripperCommand::Mode::kPosition:
      throw InvalidArgument(
          "gripper: a position command has no HSR action here (the HSR takes positions as a "
          "FollowJointTrajectory action, not built); send open or grasp");
  }
  out.goal.do_control_stop(false);
  return out;
}

GripperCommand GripperFromRos(const GripperGoal& goal) {
  const double effort = goal.goal.effort();
  ThrowUnless(std::isfinite(effort), "gripper goal: effort is not finite");
  GripperCommand command;
  if (goal.action == GripperGoal::Action::kApplyForce) {
    ThrowUnless(effort >= 0.0, "gripper apply_force: the force must be >= 0 N, not ", effort);
    command.mode = GripperCommand::Mode::kGrasp;
    command.effort = effort;
  } else {
    ThrowUnless(effort > 0.0, "gripper grasp: a closing torque (", effort,
                " Nm) is not modelled; grip with apply_force and a force in N");
    command.mode = GripperCommand::Mode::kOpen;
  }
  return command;
}

vision_msgs::msg::Detection2DArray ToRos(const std::vector<Detection2D>& detections, Time stamp,
                                         std::string_view frame_id) {
  vision_msgs::msg::Detection2DArray msg;
  msg.header(MakeHeader(stamp, frame_id));
  for (const Detection2D& d : detections) {
    vision_msgs::msg::Detection2D out;
    out.header(MakeHeader(d.stamp, d.frame_id));
    vision_msgs::msg::ObjectHypothesisWithPose hypothesis;
    hypothesis.hypothesis().class_id(d.label);
    hypothesis.hypothesis().score(d.confidence);
    out.results().push_back(hypothesis);
    out.bbox().center().position().x(0.5 * (d.box.u_min + d.box.u_max));
    out.bbox().center().position().y(0.5 * (d.box.v_min + d.box.v_max));
    out.bbox().size_x(d.box.width());
    out.bbox().size_y(d.box.height());
    msg.detections().push_back(std::move(out));
  }
  return msg;
}

std::vector<Detection2D> FromRos(const vision_msgs::msg::Detection2DArray& msg) {
  std::vector<Detection2D> detections;
  for (std::size_t i = 0; i < msg.detections().size(); ++i) {
    const auto& in = msg.detections()[i];
    ThrowUnless(!in.results().empty(), "vision_msgs/Detection2DArray: detection ", i,
                " has no hypothesis (results is empty)");
    ThrowUnless(in.bbox().center().theta() == 0.0, "vision_msgs/Detection2DArray: detection ", i,
                " has a rotated box (theta ", in.bbox().center().theta(), ")");
    // The best hypothesis.
    const auto& best = *std::max_element(in.results().begin(), in.results().end(),
                                         [](const auto& a, const auto& b) {
                                           return a.hypothesis().score() < b.hypothesis().score();
                                         });
    Detection2D d;
    d.label = best.hypothesis().class_id();
    d.confidence = best.hypothesis().score();
    const double cx = in.bbox().center().position().x(), cy = in.bbox().center().position().y();
    d.box = {cx - in.bbox().size_x() / 2, cy - in.bbox().size_y() / 2, cx + in.bbox().size_x() / 2,
             cy + in.bbox().size_y() / 2};
    // A detection without its own stamp or frame is the array's image's.
    const bool own_stamp = in.header().stamp().sec() != 0 || in.header().stamp().nanosec() != 0;
    d.stamp = FromRos(own_stamp ? in.header().stamp() : msg.header().stamp());
    d.frame_id = in.header().frame_id().empty() ? msg.header().frame_id() : in.header().frame_id();
    detections.push_back(std::move(d));
  }
  return detections;
}

}  // namespace egress::ros2
