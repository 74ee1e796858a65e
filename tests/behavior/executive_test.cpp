// The executive's construction: the robot's geometry comes from its description (the URDF),
// whatever the configs' defaults say.

#include "egress/behavior/executive.h"

#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "egress/hsr_interface/error.h"

namespace egress::behavior {
namespace {

const ExecutiveConfig& Defaults() {
  static const ExecutiveConfig config;
  return config;
}

MissionMap EmptyRoom() {
  MissionMap map;
  map.grid = perception::OccupancyGrid::FromBoxes(
      {{{5.0, 0.05, 0.0}, {10.0, 0.1}}, {{5.0, 5.95, 0.0}, {10.0, 0.1}}}, {0, 0}, {10, 6}, 0.05);
  return map;
}

MissionTree GoTo() {
  MissionTree tree;
  tree.file = std::filesystem::path(EGRESS_TREES_DIR) / "go_to.xml";
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
  EXPECT_DOUBLE_EQ(wide.services().config.footprint_radius, 0.26);
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

// A robot that gives colour images and depth, no detections of its own (a real robot without
// an on-board detector): a fixed pose, a flat wall 1.5 m ahead of the camera.
class ImageOnlyRobot final : public RobotPort {
 public:
  explicit ImageOnlyRobot(const RobotModel& model) : X_BC_(model.CalcHeadCameraPose(0.0, {})) {}
  const Clock& clock() const override { return clock_; }
  void Advance() { clock_.AdvanceBy(SecondsToDuration(0.1)); }

 private:
  SensorSnapshot DoSense() override {
    SensorSnapshot s;
    s.stamp = clock_.Now();
    s.depth_intrinsics = CameraIntrinsics::FromHorizontalFov(64, 48, 1.0);
    DepthImage depth;
    depth.stamp = s.stamp;
    depth.width = 64;
    depth.height = 48;
    depth.depth.assign(64 * 48, 1.5f);
    s.depth = depth;
    s.X_BC = X_BC_;
    ColorImage color;
    color.stamp = s.stamp;
    color.width = 64;
    color.height = 48;
    color.bgr.assign(64 * 48 * 3, 0);
    color.bgr[0] = 200;  // a mark the detector checks it sees
    s.color = color;
    s.odometry.stamp = s.stamp;
    s.joints.stamp = s.stamp;
    s.gripper.stamp = s.stamp;
    return s;
  }
  void DoSendBaseVelocity(const Twist2&) override {}
  void DoSendArmTrajectory(const JointTrajectory&) override {}
  void DoSendGripperCommand(const GripperCommand&) override {}
  void DoSendHeadCommand(const HeadCommand&) override {}
  SimClock clock_;
  Pose3 X_BC_;
};

// A detector stage that finds a bottle in the middle of every image it is given, and records
// what it was given.
class CentreBottleDetector final : public perception::Detector {
 public:
  explicit CentreBottleDetector(int* calls) : calls_(calls) {}
  std::vector<Detection2D> Detect(const perception::CameraFrame& frame) override {
    EXPECT_EQ(frame.image.cols, 64);
    EXPECT_EQ(frame.image.rows, 48);
    EXPECT_EQ(frame.image.at<cv::Vec3b>(0, 0)[0], 200);
    ++*calls_;
    Detection2D d;
    d.label = "bottle";
    d.confidence = 0.9;
    d.box = {28, 18, 36, 30};
    d.stamp = frame.stamp;
    return {d};
  }

 private:
  int* calls_;
};

TEST(ExecutiveTest, ColourImagesGoThroughTheDetectorStage) {
  const auto model = std::make_shared<const RobotModel>(RobotModel::LoadDefault());
  ImageOnlyRobot robot(*model);
  Executive brain(model, EmptyRoom(), GoTo(), {2.0, 3.0, 0.0}, Defaults());
  int calls = 0;
  brain.SetDetector(std::make_unique<CentreBottleDetector>(&calls));
  for (int i = 0; i < 6; ++i) {
    brain.Step(robot);
    robot.Advance();
  }
  EXPECT_EQ(calls, 6);
  // The detector's bottle, placed with the depth image, is a confirmed payload in the belief.
  ASSERT_EQ(brain.belief().world.payloads.size(), 1u);
  const Eigen::Vector3d p_MP = brain.belief().world.payloads[0].p_MO;
  EXPECT_GT(p_MP.x(), 2.0 + 1.0);  // ahead of the robot, about 1.5 m from the camera
  EXPECT_NEAR(p_MP.y(), 3.0, 0.3);

  // Without a detector the images are ignored: nothing is found.
  ImageOnlyRobot other(*model);
  Executive blind(model, EmptyRoom(), GoTo(), {2.0, 3.0, 0.0}, Defaults());
  for (int i = 0; i < 6; ++i) {
    blind.Step(other);
    other.Advance();
  }
  EXPECT_TRUE(blind.belief().world.payloads.empty());
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
