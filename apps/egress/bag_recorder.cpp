#include "bag_recorder.h"

#include <algorithm>

#include <fmt/format.h>

#include <geometry_msgs/msg/PoseArrayPubSubTypes.h>
#include <nav_msgs/msg/OccupancyGridPubSubTypes.h>
#include <nav_msgs/msg/OdometryPubSubTypes.h>
#include <nav_msgs/msg/PathPubSubTypes.h>
#include <sensor_msgs/msg/LaserScanPubSubTypes.h>
#include <std_msgs/msg/StringPubSubTypes.h>
#include <tf2_msgs/msg/TFMessagePubSubTypes.h>

#include "commands.h"
#include "egress/hsr_interface/frames.h"
#include "egress/ros2/conversions.h"

namespace egress::apps {
namespace {
constexpr double kSamplePeriodSec = 0.1;  // /tf and /people

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
  }
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
  if (now < next_sample_) return;
  next_sample_ = now + SecondsToDuration(kSamplePeriodSec);
  tf2_msgs::msg::TFMessage tf;
  geometry_msgs::msg::TransformStamped T;
  T.header(Header(now, frames::kMap));
  T.child_frame_id(std::string(frames::kBase));
  T.transform(ros2::ToRos(Pose3::FromPose2(brain.X_MB())));
  tf.transforms().push_back(T);
  bag_.Write<tf2_msgs::msg::TFMessagePubSubType>("/tf", tf, now);
  geometry_msgs::msg::PoseArray people;
  people.header(Header(now, frames::kMap));
  for (const auto& p : brain.belief().world.people) {
    const Eigen::Vector2d& v = p.person.v_MP;
    people.poses().push_back(PoseOf(
        {p.person.p_MP.x(), p.person.p_MP.y(), v.norm() > 0.05 ? std::atan2(v.y(), v.x()) : 0.0}));
  }
  bag_.Write<geometry_msgs::msg::PoseArrayPubSubType>("/people", people, now);
}

std::size_t BagRecorder::Close() {
  bag_.Close();
  return bag_.message_count();
}

}  // namespace egress::apps
