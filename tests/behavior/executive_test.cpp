// The executive's construction: the robot's geometry comes from its description (the URDF),
// whatever the configs' defaults say.

#include "egress/behavior/executive.h"

#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress::behavior {
namespace {

MissionMap EmptyRoom() {
  MissionMap map;
  map.grid = perception::OccupancyGrid::FromBoxes(
      {{{5.0, 0.05, 0.0}, {10.0, 0.1}}, {{5.0, 5.95, 0.0}, {10.0, 0.1}}}, {0, 0}, {10, 6}, 0.05);
  return map;
}

MissionTree GoTo() {
  MissionTree tree;
  tree.file = std::filesystem::path(EGRESS_TREES_DIR) / "go_to_goal.xml";
  tree.blackboard["goal"] = "8.0;3.0;0.0";
  return tree;
}

std::shared_ptr<const RobotModel> HsrWithBaseRadius(const std::string& radius) {
  std::ifstream in(RobotModel::DefaultUrdfPath());
  std::stringstream text;
  text << in.rdbuf();
  std::string urdf = text.str();
  const std::string from = "<cylinder radius=\"0.215\" length=\"0.24\"/>";
  const auto at = urdf.find(from);
  EXPECT_NE(at, std::string::npos);
  urdf.replace(at, from.size(), "<cylinder radius=\"" + radius + "\" length=\"0.24\"/>");
  return std::make_shared<const RobotModel>(RobotModel::LoadFromString(urdf, "wide_base.urdf"));
}

TEST(ExecutiveTest, TheFootprintComesFromTheRobotDescription) {
  ExecutiveConfig config;
  config.costmap.robot_radius = 0.1;  // overridden by the model
  config.tasks.footprint_radius = 0.1;
  const Executive wide(HsrWithBaseRadius("0.26"), EmptyRoom(), GoTo(), {2.0, 3.0, 0.0}, config);
  EXPECT_DOUBLE_EQ(wide.costmap().config().robot_radius, 0.26);
  EXPECT_DOUBLE_EQ(wide.context().config.footprint_radius, 0.26);
  const Executive hsr(std::make_shared<const RobotModel>(RobotModel::LoadDefault()), EmptyRoom(),
                      GoTo(), {2.0, 3.0, 0.0}, config);
  EXPECT_DOUBLE_EQ(hsr.costmap().config().robot_radius, 0.215);
  ASSERT_NE(hsr.octomap(), nullptr);
  ExecutiveConfig laser_only;
  laser_only.use_octomap = false;
  const Executive blind(std::make_shared<const RobotModel>(RobotModel::LoadDefault()), EmptyRoom(),
                        GoTo(), {2.0, 3.0, 0.0}, laser_only);
  EXPECT_EQ(blind.octomap(), nullptr);
}

TEST(ExecutiveTest, BadConfigurationsAreRefusedNamingTheField) {
  ExecutiveConfig config;
  config.octomap_person_radius = -1.0;
  try {
    Executive e(std::make_shared<const RobotModel>(RobotModel::LoadDefault()), EmptyRoom(), GoTo(),
                {2.0, 3.0, 0.0}, config);
    FAIL() << "accepted a negative radius";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("octomap_person_radius"), std::string::npos) << e.what();
  }
  ExecutiveConfig grasp;
  grasp.grasp.min_opening = 0.0;
  EXPECT_THROW(Executive(std::make_shared<const RobotModel>(RobotModel::LoadDefault()), EmptyRoom(),
                         GoTo(), {2.0, 3.0, 0.0}, grasp),
               InvalidArgument);
}

}  // namespace
}  // namespace egress::behavior
