#include "bag_recorder.h"

#include <algorithm>

#include <fmt/format.h>

#include <nav_msgs/msg/OccupancyGridPubSubTypes.h>
#include <nav_msgs/msg/OdometryPubSubTypes.h>
#include <nav_msgs/msg/PathPubSubTypes.h>
#include <sensor_msgs/msg/LaserScanPubSubTypes.h>
#include <std_msgs/msg/StringPubSubTypes.h>
#include <tf2_msgs/msg/TFMessagePubSubTypes.h>
#include <visualization_msgs/msg/MarkerArrayPubSubTypes.h>

#include "commands.h"
#include "egress/hsr_interface/frames.h"
#include "egress/ros2/conversions.h"

namespace egress::apps {
namespace {
constexpr double kSamplePeriodSec = 0.1;  // /tf and /people
// A person as drawn: a standing cylinder of a shoulder's width and a body's height [m].
constexpr double kPersonDiameter = 0.5;
constexpr double kPersonHeight = 1.7;
// visualization_msgs/Marker's type and action constants (Marker.msg).
constexpr std::int32_t kMarkerArrow = 0, kMarkerCylinder = 3, kMarkerText = 9;
constexpr std::int32_t kMarkerAdd = 0, kMarkerDeleteAll = 3;

std_msgs::msg::Header Header(Time t, std::string_view frame) {
  std_msgs::msg::Header h;
  h.stamp(ros2::ToRos(t));
  h.frame_id(std::string(frame));
  return h;
}

geometry_msgs::msg::Pose PoseOf(const Pose2& X) {
  geometry_msgs::msg::Pose pose;
  pose.position().x(X.x);
  pose.position().y(X.y);
  pose.orientation().z(std::sin(X.yaw / 2));
  pose.orientation().w(std::cos(X.yaw / 2));
  return pose;
}
geometry_msgs::msg::TransformStamped TransformOf(Time t, std::string_view parent,
                                                 std::string_view child, const Pose3& X) {
  geometry_msgs::msg::TransformStamped T;
  T.header(Header(t, parent));
  T.child_frame_id(std::string(child));
  T.transform(ros2::ToRos(X));
  return T;
}

visualization_msgs::msg::Marker PersonMarker(Time t, std::int32_t type, std::int32_t id) {
  visualization_msgs::msg::Marker m;
  m.header(Header(t, frames::kMap));
  m.ns("people");
  m.id(id);
  m.type(type);
  m.action(kMarkerAdd);
  m.pose().orientation().w(1.0);
  m.color().r(0.94f);
  m.color().g(0.59f);
  m.color().b(0.24f);
  m.color().a(0.8f);
  return m;
}

// The tracked people as markers: a cylinder each, an arrow for its velocity (0.5 s of it) and
// its track id over its head; a DELETEALL first, so people no longer tracked disappear.
visualization_msgs::msg::MarkerArray PeopleMarkers(
    Time t, const std::vector<perception::TrackedPersonWithIntent>& people) {
  visualization_msgs::msg::MarkerArray out;
  visualization_msgs::msg::Marker clear;
  clear.header(Header(t, frames::kMap));
  clear.ns("people");
  clear.action(kMarkerDeleteAll);
  out.markers().push_back(clear);
  for (const auto& tracked : people) {
    const auto& p = tracked.person;
    auto body = PersonMarker(t, kMarkerCylinder, 3 * p.id);
    body.pose().position().x(p.p_MP.x());
    body.pose().position().y(p.p_MP.y());
    body.pose().position().z(kPersonHeight / 2);
    body.scale().x(kPersonDiameter);
    body.scale().y(kPersonDiameter);
    body.scale().z(kPersonHeight);
    out.markers().push_back(body);
    auto label = PersonMarker(t, kMarkerText, 3 * p.id + 1);
    label.pose(body.pose());
    label.pose().position().z(kPersonHeight + 0.2);
    label.scale().z(0.25);
    label.text(fmt::format("person {}", p.id));
    out.markers().push_back(label);
    if (p.v_MP.norm() > 0.05) {
      auto arrow = PersonMarker(t, kMarkerArrow, 3 * p.id + 2);
      arrow.pose().orientation().w(1.0);
      geometry_msgs::msg::Point a, b;
      a.x(p.p_MP.x());
      a.y(p.p_MP.y());
      a.z(1.0);
      b.x(p.p_MP.x() + 0.5 * p.v_MP.x());
      b.y(p.p_MP.y() + 0.5 * p.v_MP.y());
      b.z(1.0);
      arrow.points({a, b});
      arrow.scale().x(0.05);  // shaft diameter
      arrow.scale().y(0.1);   // head diameter
      out.markers().push_back(arrow);
    }
  }
  return out;
}
}  // namespace

BagRecorder::BagRecorder(const std::filesystem::path& dir) : bag_(dir) {}

std::unique_ptr<BagRecorder> BagRecorder::Open(const std::filesystem::path& dir, bool overwrite) {
  if (std::filesystem::exists(dir)) {
    if (!overwrite)
      throw CommandFailed(fmt::format("'{}' exists; pass --overwrite to replace it", dir.string()));
    if (!std::filesystem::exists(dir / "metadata.yaml"))
      throw CommandFailed(fmt::format(
          "'{}' exists and is not a rosbag2 bag (no metadata.yaml): not replaced", dir.string()));
    std::filesystem::remove_all(dir);
  }
  return std::make_unique<BagRecorder>(dir);
}

void BagRecorder::OnSense(const SensorSnapshot& s) {
  if (s.scan)
    bag_.Write<sensor_msgs::msg::LaserScanPubSubType>("/scan", ros2::ToRos(*s.scan), s.scan->stamp,
                                                      ros2::QosProfile::SensorData());
  if (s.odometry.stamp != last_odometry_) {
    bag_.Write<nav_msgs::msg::OdometryPubSubType>("/odom", ros2::ToRos(s.odometry),
                                                  s.odometry.stamp, ros2::QosProfile::SensorData());
    last_odometry_ = s.odometry.stamp;
    last_X_OB_ = s.odometry.X_OB;
  }
  if (s.X_BC) last_X_BC_ = s.X_BC;
}

void BagRecorder::AfterStep(Time now, const behavior::Executive& brain) {
  if (!map_written_) {
    // The building map as map_server would publish it: 0 free, 100 occupied, -1 unknown.
    const auto& grid = brain.services().map->grid;
    const auto& g = grid.geometry();
    nav_msgs::msg::OccupancyGrid map;
    map.header(Header(now, frames::kMap));
    map.info().map_load_time(ros2::ToRos(now));
    map.info().resolution(float(g.resolution));
    map.info().width(std::uint32_t(g.width));
    map.info().height(std::uint32_t(g.height));
    map.info().origin().position().x(g.origin.x());
    map.info().origin().position().y(g.origin.y());
    map.info().origin().orientation().w(1.0);
    map.data().reserve(grid.cells().size());
    for (const std::uint8_t c : grid.cells()) {
      map.data().push_back(c == perception::kUnknownCost  ? char(-1)
                           : c >= perception::kLethalCost ? char(100)
                                                          : char(0));
    }
    bag_.Write<nav_msgs::msg::OccupancyGridPubSubType>("/map", map, now,
                                                       ros2::QosProfile::TransientLocal());
    map_written_ = true;
  }
  const auto& path = brain.services().motion->path();
  const auto same = [](const Pose2& a, const Pose2& b) {
    return a.x == b.x && a.y == b.y && a.yaw == b.yaw;
  };
  if (!std::equal(path.begin(), path.end(), last_path_.begin(), last_path_.end(), same)) {
    nav_msgs::msg::Path plan;
    plan.header(Header(now, frames::kMap));
    for (const Pose2& X : path) {
      geometry_msgs::msg::PoseStamped p;
      p.header(plan.header());
      p.pose(PoseOf(X));
      plan.poses().push_back(p);
    }
    bag_.Write<nav_msgs::msg::PathPubSubType>("/plan", plan, now);
    last_path_ = path;
  }
  const std::string status = std::string(bt::ToString(brain.status())) +
                             (brain.active_action().empty() ? "" : ": " + brain.active_action());
  if (status != last_status_) {
    std_msgs::msg::String msg;
    msg.data(status);
    bag_.Write<std_msgs::msg::StringPubSubType>("/egress/status", msg, now);
    last_status_ = status;
  }
  if (!static_written_) {
    // The laser's mount, as robot_state_publisher would latch it.
    tf2_msgs::msg::TFMessage tf_static;
    tf_static.transforms().push_back(
        TransformOf(now, frames::kBase, frames::kLaser, Pose3::FromPose2(brain.belief().X_BL)));
    bag_.Write<tf2_msgs::msg::TFMessagePubSubType>("/tf_static", tf_static, now,
                                                   ros2::QosProfile::TransientLocal());
    static_written_ = true;
  }
  if (now < next_sample_) return;
  next_sample_ = now + SecondsToDuration(kSamplePeriodSec);
  // The ROS tree: map -> odom (the localizer's correction), odom -> base (odometry), base ->
  // head camera (it pans and tilts).
  tf2_msgs::msg::TFMessage tf;
  const Pose2 X_MO = brain.X_MB() * last_X_OB_.Inverse();
  tf.transforms().push_back(TransformOf(now, frames::kMap, frames::kOdom, Pose3::FromPose2(X_MO)));
  tf.transforms().push_back(
      TransformOf(now, frames::kOdom, frames::kBase, Pose3::FromPose2(last_X_OB_)));
  if (last_X_BC_)
    tf.transforms().push_back(TransformOf(now, frames::kBase, frames::kHeadCamera, *last_X_BC_));
  bag_.Write<tf2_msgs::msg::TFMessagePubSubType>("/tf", tf, now);
  bag_.Write<visualization_msgs::msg::MarkerArrayPubSubType>(
      "/people", PeopleMarkers(now, brain.belief().world.people), now);
}

std::size_t BagRecorder::Close() {
  bag_.Close();
  return bag_.message_count();
}

}  // namespace egress::apps
