#include "goal_scenario.h"

#include <filesystem>

#include <fmt/format.h>

#include "egress/behavior/task_nodes.h"
#include "egress/hsr_interface/error.h"
#include "egress/twin/building.h"
#include "egress/twin/sdf_world_loader.h"

namespace egress::apps {
namespace {

// "x;y;yaw" (or "x;y") as a YAML pose, or a place name as {place: ..}.
std::string PoseOrPlaceYaml(const std::string& text, const char* option) {
  if (text.find(';') == std::string::npos) {
    if (text.empty() || text.find_first_of("{}[]:,#\"'") != std::string::npos)
      throw InvalidArgument(fmt::format("{} '{}': expected a place name or x;y;yaw", option, text));
    return fmt::format("{{place: {}}}", text);
  }
  Pose2 X;
  try {
    X = behavior::ParsePose2(text);
  } catch (const std::exception& e) {
    throw InvalidArgument(fmt::format("{}: {}", option, e.what()));
  }
  return fmt::format("{{x: {}, y: {}, yaw: {}}}", X.x, X.y, X.yaw);
}

}  // namespace

bool IsWorldFile(const std::string& path) {
  const std::string ext = std::filesystem::path(path).extension().string();
  return ext == ".sdf" || ext == ".world";
}

twin::Scenario GoalScenario(const GoalMission& m) {
  if (m.goal.empty()) throw InvalidArgument("a world file needs --goal (a place or x;y;yaw)");
  const std::filesystem::path world = std::filesystem::absolute(m.world);
  std::string start = m.start;
  if (start.empty()) {
    const twin::BuildingDescription building = twin::DescribeBuilding(
        twin::LoadSdfWorld(world), twin::FindBuildingYamlBeside(world).value_or(""));
    if (building.places.empty())
      throw InvalidArgument(
          fmt::format("{}: the building has no places; pass --start x;y;yaw", m.world));
    start = building.places.front().name;
  }
  const std::string goal = PoseOrPlaceYaml(m.goal, "--goal");
  const std::string yaml = fmt::format(
      "name: '{} to {}'\nworld: '{}'\ntime_limit: {}\nrobot:\n  start: {}\n  goal: {}\n"
      "mission:\n  tree: '{}'\n  blackboard: {{max_yields: \"5\"}}\n"
      "success: [reach_goal, no_person_contact, no_door_strike]\n",
      world.stem().string(), m.goal, world.string(), m.time_limit,
      PoseOrPlaceYaml(start, "--start"), goal.substr(0, goal.size() - 1) + ", tolerance: 0.3}",
      m.tree);
  return twin::LoadScenarioFromString(yaml, m.world + " --goal " + m.goal, world.parent_path());
}

}  // namespace egress::apps
