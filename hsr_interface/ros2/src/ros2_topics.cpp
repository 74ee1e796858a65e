#include "egress/ros2/ros2_topics.h"

#include <filesystem>
#include <utility>

#include <yaml-cpp/yaml.h>

#include "egress/hsr_interface/error.h"
#include "egress/ros2/dds_node.h"

namespace egress::ros2 {
namespace {
std::vector<std::pair<const char*, std::string Ros2Topics::*>> Entries() {
  return {{"scan", &Ros2Topics::scan},
          {"depth_image", &Ros2Topics::depth_image},
          {"depth_camera_info", &Ros2Topics::depth_camera_info},
          {"color_image", &Ros2Topics::color_image},
          {"joint_states", &Ros2Topics::joint_states},
          {"odometry", &Ros2Topics::odometry},
          {"tf", &Ros2Topics::tf},
          {"clock", &Ros2Topics::clock},
          {"detections", &Ros2Topics::detections},
          {"cmd_vel", &Ros2Topics::cmd_vel},
          {"arm_trajectory", &Ros2Topics::arm_trajectory},
          {"head_trajectory", &Ros2Topics::head_trajectory},
          {"gripper_grasp_action", &Ros2Topics::gripper_grasp_action},
          {"gripper_apply_force_action", &Ros2Topics::gripper_apply_force_action},
          {"status", &Ros2Topics::status},
          {"brain_clock", &Ros2Topics::brain_clock},
          {"estop", &Ros2Topics::estop}};
}
}  // namespace

void Ros2Topics::Validate() const {
  for (const auto& [key, member] : Entries()) {
    try {
      DdsTopicName(this->*member);
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(std::string("ROS 2 topic map: ") + key + ": " + e.what());
    }
  }
}

Ros2Topics Ros2Topics::FromYamlFile(const std::string& path) {
  ThrowUnless(std::filesystem::is_regular_file(path), "ROS 2 topic map '", path, "': no such file");
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw InvalidArgument("ROS 2 topic map '" + path + "': " + e.what());
  }
  if (root.IsMap() && root["topics"]) root = root["topics"];
  ThrowUnless(root.IsMap(), "ROS 2 topic map '", path, "': expected a map of topic names");
  Ros2Topics topics;
  const auto entries = Entries();
  for (const auto& item : root) {
    const std::string key = item.first.as<std::string>();
    auto it =
        std::find_if(entries.begin(), entries.end(), [&](const auto& e) { return key == e.first; });
    std::string known;
    for (const auto& e : entries)
      known += std::string(known.empty() ? "" : ", ") + e.first;
    ThrowUnless(it != entries.end(), "ROS 2 topic map '", path, "' line ",
                item.first.Mark().line + 1, ": unknown entry '", key, "' (known: ", known, ")");
    ThrowUnless(item.second.IsScalar(), "ROS 2 topic map '", path, "' line ",
                item.second.Mark().line + 1, ": '", key, "' must be a topic name");
    topics.*(it->second) = item.second.as<std::string>();
  }
  try {
    topics.Validate();
  } catch (const InvalidArgument& e) {
    throw InvalidArgument("'" + path + "': " + e.what());
  }
  return topics;
}

}  // namespace egress::ros2
