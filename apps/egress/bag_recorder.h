#pragma once
/// @file
/// A twin run by the brain recorded as a rosbag2 bag (`sim run --bag DIR`): what the brain read
/// and believed, on the topics a ROS 2 robot would have, for Foxglove or `ros2 bag play`.

#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "egress/behavior/executive.h"
#include "egress/hsr_interface/robot_port.h"
#include "egress/ros2/rosbag2_writer.h"

namespace egress::apps {

/// Topics: /scan and /odom (as read), /tf (10 Hz: map -> odom from the brain's localized pose,
/// odom -> base_footprint from odometry, base_footprint -> head camera), /tf_static (the laser's
/// mount, once, latched), /map (the building map, nav_msgs/OccupancyGrid, once, latched), /plan
/// (the planned path, nav_msgs/Path, when it changes), /people (tracked people as
/// visualization_msgs/MarkerArray: a cylinder, a velocity arrow and an id each; 10 Hz),
/// /egress/status (the running action and the tree's status, when they change).
class BagRecorder {
 public:
  /// @throws InvalidArgument if `dir` exists (see Rosbag2Writer).
  explicit BagRecorder(const std::filesystem::path& dir);
  /// A recorder in `dir`: an existing folder is replaced only with `overwrite` and only if it is
  /// a bag (has metadata.yaml). @throws CommandFailed otherwise.
  static std::unique_ptr<BagRecorder> Open(const std::filesystem::path& dir, bool overwrite);
  void OnSense(const SensorSnapshot& s);
  void AfterStep(Time now, const behavior::Executive& brain);
  /// Writes metadata.yaml; returns the number of messages.
  std::size_t Close();

 private:
  ros2::Rosbag2Writer bag_;
  bool map_written_{false}, static_written_{false};
  Pose2 last_X_OB_;                 // odom -> base, from the latest odometry
  std::optional<Pose3> last_X_BC_;  // base -> head camera, from the latest depth image
  Time last_odometry_{-1}, next_sample_{0};
  std::vector<Pose2> last_path_;  // the path last written to /plan
  std::string last_status_;
};

}  // namespace egress::apps
