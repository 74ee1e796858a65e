// The executive's construction: the robot's geometry comes from its description (the URDF),
// whatever the configs' defaults say.

#include "egress/behavior/executive.h"

#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <optional>
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

// A scripted robot on a simulated clock that ignores every command; subclasses give the
// sensing.
class ScriptedRobot : public RobotPort {
 public:
  const Clock& clock() const override { return clock_; }

 protected:
  // A snapshot stamped now, with odometry, joints and gripper stamped too (and nothing else).
  SensorSnapshot Stamped() const {
    SensorSnapshot s;
    s.stamp = clock_.Now();
    s.odometry.stamp = s.stamp;
    s.joints.stamp = s.stamp;
    s.gripper.stamp = s.stamp;
    return s;
  }
  SimClock clock_;

 private:
  void DoSendBaseVelocity(const Twist2&) override {}
  void DoSendArmTrajectory(const JointTrajectory&) override {}
  void DoSendGripperCommand(const GripperCommand&) override {}
  void DoSendHeadCommand(const HeadCommand&) override {}
};

// A robot that gives colour images and depth, no detections of its own (a real robot without
// an on-board detector): a fixed pose, a flat wall 1.5 m ahead of the camera.
class ImageOnlyRobot final : public ScriptedRobot {
 public:
  explicit ImageOnlyRobot(const RobotModel& model) : X_BC_(model.CalcHeadCameraPose(0.0, {})) {}
  void Advance() { clock_.AdvanceBy(SecondsToDuration(0.1)); }

 private:
  SensorSnapshot DoSense() override {
    SensorSnapshot s = Stamped();
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
    return s;
  }
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

// A robot driving straight ahead at `speed` on odometry alone whose head camera (looking
// ahead) gives a depth image every `depth_every` steps of 0.1 s, each pixel's depth from
// `depth_at(t, p_MC, ray_M)` (ray_M: the pixel's ray in M, scaled to unit optical depth), and a
// late detector: a bottle box in the image's middle delivered at t with the stamp
// `detection_stamp(t)` says (none when it says nothing). Starts at (2, 3, 0) in M.
class LateCameraRobot final : public ScriptedRobot {
 public:
  using DepthAt = std::function<float(double, const Eigen::Vector3d&, const Eigen::Vector3d&)>;
  using StampAt = std::function<std::optional<double>(double)>;
  LateCameraRobot(const RobotModel& model, double speed, int depth_every, DepthAt depth_at,
                  StampAt detection_stamp)
      : X_BC_(model.CalcHeadCameraPose(0.0, {})),
        speed_(speed),
        depth_every_(depth_every),
        depth_at_(std::move(depth_at)),
        detection_stamp_(std::move(detection_stamp)) {}
  void Advance() {
    clock_.AdvanceBy(SecondsToDuration(0.1));
    ++step_;
  }
  double t() const { return 0.1 * step_; }
  Pose3 X_MC() const { return Pose3::FromPose2({2.0 + speed_ * t(), 3.0, 0.0}) * X_BC_; }
  static CameraIntrinsics Intrinsics() { return CameraIntrinsics::FromHorizontalFov(64, 48, 1.0); }
  static constexpr double kBoxU = 32.0, kBoxV = 24.0;  // the box's middle

 private:
  SensorSnapshot DoSense() override {
    SensorSnapshot s = Stamped();
    s.odometry.X_OB = {speed_ * t(), 0.0, 0.0};
    s.odometry.V_B = {speed_, 0.0, 0.0};
    s.depth_intrinsics = Intrinsics();
    if (step_ % depth_every_ == 0) {
      DepthImage depth;
      depth.stamp = s.stamp;
      depth.width = 64;
      depth.height = 48;
      const Pose3 X_MC_now = X_MC();
      for (int v = 0; v < 48; ++v) {
        for (int u = 0; u < 64; ++u) {
          const Eigen::Vector3d ray_M =
              X_MC_now.rotation() * s.depth_intrinsics.Unproject(u + 0.5, v + 0.5, 1.0);
          depth.depth.push_back(depth_at_(t(), X_MC_now.translation(), ray_M));
        }
      }
      s.depth = depth;
      s.X_BC = X_BC_;
    }
    if (const auto stamp = detection_stamp_(t())) {
      Detection2D d;
      d.label = "bottle";
      d.confidence = 0.9;
      d.box = {kBoxU - 4, kBoxV - 6, kBoxU + 4, kBoxV + 6};
      d.stamp = Time{} + SecondsToDuration(*stamp);
      s.detections.push_back(d);
    }
    return s;
  }
  Pose3 X_BC_;
  double speed_;
  int depth_every_;
  DepthAt depth_at_;
  StampAt detection_stamp_;
  int step_{0};
};

// The detector runs behind the depth camera: its boxes are laid on the depth image taken nearest
// their own image, not the latest. Here a bottle 1.5 m ahead is taken away at 0.45 s; boxes of
// it keep coming until 0.7 s, 0.3 s late. Laid on the latest depth image, the last three would
// find the wall 4 m ahead behind where it stood, and "confirm" a bottle there.
TEST(ExecutiveTest, LateBoxesAreLaidOnTheDepthImageTakenNearestTheirImage) {
  const auto model = std::make_shared<const RobotModel>(RobotModel::LoadDefault());
  LateCameraRobot robot(
      *model, 0.0, 1,
      [](double t, const Eigen::Vector3d&, const Eigen::Vector3d&) {
        return t < 0.45 ? 1.5f : 4.0f;
      },
      [](double t) -> std::optional<double> {
        if (t > 0.25 && t < 0.75) return t - 0.3;
        return std::nullopt;
      });
  Executive brain(model, EmptyRoom(), GoTo(), {2.0, 3.0, 0.0}, Defaults());
  for (int i = 0; i <= 7; ++i) {
    brain.Step(robot);
    robot.Advance();
  }
  const auto& payloads = brain.belief().world.payloads;
  ASSERT_EQ(payloads.size(), 1u);
  const Eigen::Vector3d p_MO_expected =
      robot.X_MC() *
      LateCameraRobot::Intrinsics().Unproject(LateCameraRobot::kBoxU, LateCameraRobot::kBoxV, 1.5);
  EXPECT_LT((payloads[0].p_MO - p_MO_expected).norm(), 0.02);
}

// A depth image is placed from where the base was when it was taken, not from where it is when
// a box comes to be laid on it: driving at 1 m/s with a depth image every 0.3 s, a bottle on a
// wall 6 m along x stays on the wall.
TEST(ExecutiveTest, DepthImagesArePlacedFromWhereTheBaseWasWhenTheyWereTaken) {
  const auto model = std::make_shared<const RobotModel>(RobotModel::LoadDefault());
  constexpr double kWallX = 6.0;
  LateCameraRobot robot(
      *model, 1.0, 3,
      [](double, const Eigen::Vector3d& p_MC, const Eigen::Vector3d& ray_M) {
        return float((kWallX - p_MC.x()) / ray_M.x());
      },
      [](double t) -> std::optional<double> { return t; });
  Executive brain(model, EmptyRoom(), GoTo(), {2.0, 3.0, 0.0}, Defaults());
  for (int i = 0; i <= 12; ++i) {
    brain.Step(robot);
    robot.Advance();
  }
  const auto& payloads = brain.belief().world.payloads;
  ASSERT_EQ(payloads.size(), 1u);
  EXPECT_NEAR(payloads[0].p_MO.x(), kWallX, 0.02);
}

// A 270 deg scan of 101 beams that sees nothing in range.
LaserScan EmptyScan(Time stamp) {
  LaserScan scan;
  scan.stamp = stamp;
  scan.angle_min = -0.75 * M_PI;
  scan.angle_increment = 1.5 * M_PI / 100;
  scan.range_max = 20.0;
  scan.ranges.assign(101, std::numeric_limits<float>::infinity());
  return scan;
}

// A robot whose base moves at a set velocity (odometry only; its laser sees nothing in range).
class RollingRobot final : public ScriptedRobot {
 public:
  void Advance(double dt) {
    const Pose2 step{V_B_.vx * dt, V_B_.vy * dt, V_B_.wz * dt};
    X_OB_ = X_OB_ * step;
    clock_.AdvanceBy(SecondsToDuration(dt));
  }
  void set_velocity(const Twist2& V_B) { V_B_ = V_B; }

 private:
  SensorSnapshot DoSense() override {
    SensorSnapshot s = Stamped();
    s.scan = EmptyScan(s.stamp);
    s.odometry.X_OB = X_OB_;
    s.odometry.V_B = V_B_;
    return s;
  }
  Pose2 X_OB_;
  Twist2 V_B_;
};

// Where the base drove the way its laser looks is remembered for kSweptMemorySec (a retreat may
// go back that way unseen); where it backed is not.
TEST(ExecutiveTest, WhereTheBaseDroveFacingTheWayIsRememberedForAWhile) {
  const auto model = std::make_shared<const RobotModel>(RobotModel::LoadDefault());
  RollingRobot robot;
  Executive brain(model, EmptyRoom(), GoTo(), {2.0, 3.0, 0.0}, Defaults());
  const auto step_for = [&](double seconds) {
    for (int i = 0; i < int(std::lround(seconds / 0.1)); ++i) {
      brain.Step(robot);
      robot.Advance(0.1);
    }
  };
  robot.set_velocity({0.4, 0.0, 0.0});  // forwards: 0.8 m in 2 s
  step_for(2.0);
  const auto& swept = brain.belief().swept_p_MB;
  ASSERT_GE(swept.size(), 10u);
  for (std::size_t i = 1; i < swept.size(); ++i) {
    EXPECT_GE((swept[i].second - swept[i - 1].second).norm(), kSweptSampleM - 1e-9);
    EXPECT_GT(swept[i].first, swept[i - 1].first);
  }
  EXPECT_NEAR(swept.front().second.x(), 2.0, 0.1);
  EXPECT_GT(swept.back().second.x(), 2.6);
  const std::size_t forwards = swept.size();
  robot.set_velocity({-0.4, 0.0, 0.0});  // backwards, the blind sector leading: not kept
  step_for(2.0);
  EXPECT_EQ(swept.size(), forwards);
  robot.set_velocity({});
  step_for(kSweptMemorySec);  // all of it older than the memory
  EXPECT_TRUE(swept.empty());
}

// A standing robot whose laser sees the given returns (beam index -> range); beam 50 points
// straight ahead, beam 51 2.7 deg to its left.
class ReturnsRobot final : public ScriptedRobot {
 public:
  explicit ReturnsRobot(std::map<std::size_t, float> returns) : returns_(std::move(returns)) {}

 private:
  SensorSnapshot DoSense() override {
    SensorSnapshot s = Stamped();
    LaserScan scan = EmptyScan(s.stamp);
    for (const auto& [beam, range] : returns_)
      scan.ranges[beam] = range;
    s.scan = scan;
    return s;
  }
  std::map<std::size_t, float> returns_;
};

// The off-map returns after one step of a robot standing at X_MB in a 30 m x 6 m hall (walls
// along y = 0 and y = 6, their faces at y = 0.1 and 5.9) whose laser sees `returns` (beam ->
// range), people detected out to `max_range`.
std::vector<Eigen::Vector2d> OffMapReturnsInAHall(const Pose2& X_MB,
                                                  std::map<std::size_t, float> returns,
                                                  double max_range) {
  MissionMap hall;
  hall.grid = perception::OccupancyGrid::FromBoxes(
      {{{15.0, 0.05, 0.0}, {30.0, 0.1}}, {{15.0, 5.95, 0.0}, {30.0, 0.1}}}, {0, 0}, {30, 6}, 0.05);
  ExecutiveConfig config;
  config.perception.laser_detector.max_range = max_range;
  ReturnsRobot robot(std::move(returns));
  Executive brain(std::make_shared<const RobotModel>(RobotModel::LoadDefault()), hall, GoTo(), X_MB,
                  config);
  brain.Step(robot);
  return brain.belief().off_map_returns;
}

// Off-map returns are read as bodies only as far as the laser's people are detected: farther
// out one is as likely a wall seen a little off (range noise, the pose's yaw error times the
// range; clinic room A seed 22: one by a wall 17 m away took the robot's spot beside a door).
TEST(ExecutiveTest, OffMapReturnsCountOnlyAsFarAsTheLaserDetectsPeople) {
  const auto off_map = [&](double max_range) {
    // In open floor, ahead.
    return OffMapReturnsInAHall({2.0, 3.0, 0.0}, {{50, 4.0f}, {51, 12.0f}}, max_range);
  };
  const auto near_only = off_map(Defaults().perception.laser_detector.max_range);
  ASSERT_EQ(near_only.size(), 1u);
  EXPECT_NEAR(near_only.front().y(), 3.0, 0.05);
  EXPECT_GT(near_only.front().x(), 5.5);
  EXPECT_EQ(off_map(15.0).size(), 2u);
}

// The farther a return, the farther from the map it must be to be off it (the heading error
// moves it sideways): a return ~0.17 m from a wall's face is off the map 2 m away, and the wall
// itself 8 m away (room A seed 11: such returns held the robot's spot beside door_e taken).
TEST(ExecutiveTest, AFarReturnMustBeFartherFromTheMapToBeOffIt) {
  const auto off_map = [&](float range) {
    // Straight ahead, along the wall whose face is y = 0.1.
    return OffMapReturnsInAHall({2.0, 0.26, 0.0}, {{50, range}}, 15.0).size();
  };
  EXPECT_EQ(off_map(2.0f), 1u);
  EXPECT_EQ(off_map(8.0f), 0u);
  EXPECT_GT(kOffMapPerRangeM, 0.0);
}

TEST(ExecutiveTest, BadConfigurationsAreRefusedNamingTheField) {
  // The executive refuses `config`, naming `field`.
  const auto refused_naming = [](const ExecutiveConfig& config, const std::string& field) {
    try {
      Executive e(std::make_shared<const RobotModel>(RobotModel::LoadDefault()), EmptyRoom(),
                  GoTo(), {2.0, 3.0, 0.0}, config);
      ADD_FAILURE() << "accepted a bad " << field;
    } catch (const InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  ExecutiveConfig config;
  config.octomap_person_radius = -1.0;
  refused_naming(config, "octomap_person_radius");
  ExecutiveConfig peek;
  peek.tasks.door_peek_turn_deg = 120.0;  // it would turn its back on the door
  refused_naming(peek, "door_peek_turn_deg");
  ExecutiveConfig watch;
  watch.tasks.near_waiter_time = std::nan("");
  refused_naming(watch, "near_waiter_time");
  ExecutiveConfig grasp;
  grasp.grasp.min_opening = 0.0;
  EXPECT_THROW(Executive(std::make_shared<const RobotModel>(RobotModel::LoadDefault()), EmptyRoom(),
                         GoTo(), {2.0, 3.0, 0.0}, grasp),
               InvalidArgument);
}

}  // namespace
}  // namespace egress::behavior
