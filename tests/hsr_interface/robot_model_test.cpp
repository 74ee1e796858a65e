#include "egress/hsr_interface/robot_model.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress {
namespace {

using ::testing::HasSubstr;
constexpr double kPi = std::numbers::pi;
constexpr double kFkToleranceM = 1e-3;  // The issue's bound: within 1 mm.

WholeBodyVector Arm(double lift, double flex, double roll, double wrist_flex, double wrist_roll) {
  WholeBodyVector q = WholeBodyVector::Zero();
  q << 0, 0, 0, lift, flex, roll, wrist_flex, wrist_roll;
  return q;
}

class RobotModelTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { model_ = new RobotModel(RobotModel::LoadDefault()); }
  static void TearDownTestSuite() { delete model_; }
  static const RobotModel& model() { return *model_; }

 private:
  static inline RobotModel* model_ = nullptr;
};

// Reference positions of hand_palm_link from ../shared/reference/upstream_code_notes.md §1.2,
// computed from the vendor's HSR-B description.
TEST_F(RobotModelTest, PalmForwardKinematicsMatchesVendorModel) {
  struct Case {
    const char* name;
    WholeBodyVector q;
    Eigen::Vector3d p_BG;
    Eigen::Vector3d palm_z;
  };
  const std::vector<Case> cases = {
      {"all zero", Arm(0, 0, 0, 0, 0), {0.158, 0.078, 0.826}, {0, 0, 1}},
      {"tucked", Arm(0.01, -0.01, 0, 0, 0), {0.163, 0.078, 0.835}, {0, 0, 1}},
      {"flex -pi/2", Arm(0, -kPi / 2, 0, 0, 0), {0.627, 0.078, 0.323}, {1, 0, 0}},
      {"flex -pi/2, lift 0.69", Arm(0.69, -kPi / 2, 0, 0, 0), {0.627, 0.078, 1.013}, {1, 0, 0}},
      {"wrist_flex -pi/2", Arm(0, 0, 0, -kPi / 2, 0), {0.287, 0.078, 0.673}, {1, 0, 0}},
  };
  for (const auto& c : cases) {
    const Pose3 X_BG = model().CalcPalmPose(c.q);
    EXPECT_LT((X_BG.translation() - c.p_BG).norm(), kFkToleranceM)
        << c.name << ": palm at " << X_BG.translation().transpose();
    // The palm's approach axis; the tucked pose leans by only 0.01 rad.
    EXPECT_GT(X_BG.rotation().col(2).dot(c.palm_z), std::cos(0.02)) << c.name;
  }
}

TEST_F(RobotModelTest, FingertipPointLiesAheadOfThePalm) {
  // Expected from the URDF numbers by hand: proximal joint at z = -0.0175 in the palm, distal
  // 0.07 further, fingertip frame (y, z) = (±0.01865, 0.04289) on the distal link, which sits
  // at -0.087 rad (its mimic offset) when hand_motor_joint = 0. Without that offset the tip
  // would be 0.095 m ahead of the palm (upstream_code_notes §1.2).
  const double kDistalAngle = -0.087;
  const double z =
      -0.0175 + 0.07 + std::sin(kDistalAngle) * 0.01865 + std::cos(kDistalAngle) * 0.04289;
  EXPECT_LT((model().fingertip_in_palm() - Eigen::Vector3d(0, 0, z)).norm(), 1e-9)
      << model().fingertip_in_palm().transpose();
  // With the arm vertical the fingertip point is straight above the palm.
  const Eigen::Vector3d p_BF = model().CalcFingertipPosition(Arm(0, 0, 0, 0, 0));
  EXPECT_LT((p_BF - Eigen::Vector3d(0.158, 0.078, 0.826 + z)).norm(), kFkToleranceM)
      << p_BF.transpose();
}

TEST_F(RobotModelTest, BaseJointsMoveThePalmRigidly) {
  const WholeBodyVector q_arm = Arm(0.2, -1.0, 0.3, -0.5, 0.7);
  WholeBodyVector q = q_arm;
  q[kBaseX] = 1.5;
  q[kBaseY] = -2.0;
  q[kBaseYaw] = 0.8;
  const Pose3 X_MB = Pose3::FromPose2({1.5, -2.0, 0.8});
  EXPECT_TRUE(model().CalcPalmPose(q).IsNearlyEqualTo(X_MB * model().CalcPalmPose(q_arm), 1e-12));
}

// The Jacobian equals a central finite difference of FK: linear rows against the point's
// position, angular rows against the rotation (R(q+h) R(q-h)^T ≈ exp(2h [w]x)).
TEST_F(RobotModelTest, JacobianMatchesCentralFiniteDifferences) {
  std::mt19937 generator(20261121);
  constexpr int kConfigurations = 200;
  constexpr double kStep = 1e-6;
  const WholeBodyVector lower = model().lower_limits();
  const WholeBodyVector upper = model().upper_limits();
  for (int n = 0; n < kConfigurations; ++n) {
    WholeBodyVector q;
    for (int i = 0; i < kNumWholeBodyJoints; ++i) {
      const double lo = std::isfinite(lower[i]) ? lower[i] : -3.0;
      const double hi = std::isfinite(upper[i]) ? upper[i] : 3.0;
      q[i] = std::uniform_real_distribution<double>(lo, hi)(generator);
    }
    ASSERT_TRUE(model().IsWithinLimits(q));
    for (const bool fingertip : {false, true}) {
      const WholeBodyJacobian J =
          fingertip ? model().CalcFingertipJacobian(q) : model().CalcPalmJacobian(q);
      for (int i = 0; i < kNumWholeBodyJoints; ++i) {
        WholeBodyVector plus = q, minus = q;
        plus[i] += kStep;
        minus[i] -= kStep;
        const auto point = [&](const WholeBodyVector& x) {
          return fingertip ? model().CalcFingertipPosition(x)
                           : Eigen::Vector3d(model().CalcPalmPose(x).translation());
        };
        const Eigen::Vector3d v = (point(plus) - point(minus)) / (2 * kStep);
        const Eigen::Matrix3d dR = model().CalcPalmPose(plus).rotation() *
                                   model().CalcPalmPose(minus).rotation().transpose();
        const Eigen::AngleAxisd w_aa(dR);
        const Eigen::Vector3d w = w_aa.axis() * w_aa.angle() / (2 * kStep);
        EXPECT_LT((J.block<3, 1>(0, i) - v).norm(), 1e-6)
            << "linear column " << WholeBodyJointNames()[i] << " at q = " << q.transpose();
        EXPECT_LT((J.block<3, 1>(3, i) - w).norm(), 1e-6)
            << "angular column " << WholeBodyJointNames()[i] << " at q = " << q.transpose();
      }
    }
  }
}

TEST_F(RobotModelTest, JointLimitsComeFromTheUrdf) {
  EXPECT_DOUBLE_EQ(model().limits(kArmLift).upper, 0.69);
  EXPECT_DOUBLE_EQ(model().limits(kArmFlex).lower, -2.62);
  EXPECT_DOUBLE_EQ(model().limits(kWristRoll).upper, 3.67);
  EXPECT_FALSE(std::isfinite(model().limits(kBaseX).upper));
  EXPECT_DOUBLE_EQ(model().GetJointLimits("head_tilt_joint").lower, -1.57);
  EXPECT_THROW(model().GetJointLimits("elbow_joint"), InvalidArgument);

  WholeBodyVector q = Arm(1.0, 0.5, 0, 0, 0);
  EXPECT_FALSE(model().IsWithinLimits(q));
  const WholeBodyVector clamped = model().ClampToLimits(q);
  EXPECT_DOUBLE_EQ(clamped[kArmLift], 0.69);
  EXPECT_DOUBLE_EQ(clamped[kArmFlex], 0.0);
  EXPECT_TRUE(model().IsWithinLimits(clamped));
}

TEST_F(RobotModelTest, SensorMountsAndFootprint) {
  EXPECT_DOUBLE_EQ(model().footprint_radius(), 0.215);
  EXPECT_LT((model().laser_pose().translation() - Eigen::Vector3d(0.1675, 0, 0.1844)).norm(), 1e-9);
  // The RGB-D optical origin (−0.060, 0.022, 0.967) at zero lift rises by half the arm lift.
  const Pose3 X_BC0 = model().CalcHeadCameraPose(0.0, {});
  EXPECT_LT((X_BC0.translation() - Eigen::Vector3d(-0.060, 0.022, 0.967)).norm(), kFkToleranceM)
      << X_BC0.translation().transpose();
  const Pose3 X_BC1 = model().CalcHeadCameraPose(0.69, {});
  EXPECT_NEAR(X_BC1.translation().z(), 1.312, kFkToleranceM);
  // Optical convention: camera z looks forward along base x when pan = tilt = 0.
  EXPECT_GT(X_BC0.rotation().col(2).dot(Eigen::Vector3d::UnitX()), 0.9999);
  // Tilting down (negative tilt) turns the optical axis towards the floor.
  const Pose3 X_BC_down = model().CalcHeadCameraPose(0.0, {0.0, -0.5});
  EXPECT_LT(X_BC_down.rotation().col(2).z(), -0.4);
}

TEST_F(RobotModelTest, CollisionShapesComeFromTheUrdfAndFollowTheJoints) {
  const auto& shapes = model().collision_shapes();
  auto find = [&](const std::vector<PlacedShape>& placed, const std::string& name) {
    for (const auto& p : placed) {
      if (p.shape.name == name) return p;
    }
    ADD_FAILURE() << "no collision '" << name << "'";
    return PlacedShape{};
  };
  bool has_base = false, has_finger = false;
  for (const auto& s : shapes) {
    has_base = has_base || (s.name == "base_body" && s.kind == CollisionShape::Kind::kCylinder &&
                            s.size.x() == 0.215 && s.size.z() == 0.24);
    has_finger = has_finger || s.link == "hand_l_distal_link";
  }
  EXPECT_TRUE(has_base);
  EXPECT_TRUE(has_finger);

  const auto low = model().CalcCollisionShapesInBase({});
  const auto high = model().CalcCollisionShapesInBase({{"arm_lift_joint", 0.3}});
  for (const auto& p : low)
    EXPECT_EQ(p.shape.link.find("distal"), std::string::npos) << "fingers are skipped";
  EXPECT_EQ(model().CalcCollisionShapesInBase({}, false).size(), shapes.size());
  // The base stays put, the torso rises with half the lift (mimic joint), the arm with all of it.
  EXPECT_NEAR(find(low, "base_body").X_BS.translation().z(), 0.13, 1e-9);
  EXPECT_NEAR(find(high, "base_body").X_BS.translation().z(), 0.13, 1e-9);
  EXPECT_NEAR(find(high, "torso_column").X_BS.translation().z() -
                  find(low, "torso_column").X_BS.translation().z(),
              0.15, 1e-9);
  EXPECT_NEAR(find(high, "hand_body").X_BS.translation().z() -
                  find(low, "hand_body").X_BS.translation().z(),
              0.3, 1e-9);
  // Flexing the arm forward carries the hand out in front of the base.
  const auto forward = model().CalcCollisionShapesInBase({{"arm_flex_joint", -kPi / 2}});
  EXPECT_GT(find(forward, "hand_body").X_BS.translation().x(), 0.5);
  EXPECT_NEAR(find(low, "base_body").shape.BoundingRadius(), std::hypot(0.215, 0.12), 1e-12);
  CollisionShape box;
  box.kind = CollisionShape::Kind::kBox;
  box.size = {0.2, 0.4, 0.6};
  EXPECT_TRUE(box.Contains({0.09, -0.19, 0.29}));
  EXPECT_FALSE(box.Contains({0.11, 0.0, 0.0}));
  EXPECT_TRUE(box.Contains({0.11, 0.0, 0.0}, 0.02));
  CollisionShape cylinder;
  cylinder.kind = CollisionShape::Kind::kCylinder;
  cylinder.size = {0.1, 0.1, 0.4};
  EXPECT_TRUE(cylinder.Contains({0.07, 0.07, 0.19}));
  EXPECT_FALSE(cylinder.Contains({0.08, 0.08, 0.0}));
  EXPECT_FALSE(cylinder.Contains({0.0, 0.0, 0.21}));
  EXPECT_THROW(model().CalcCollisionShapesInBase({{"no_such_joint", 0.0}}), InvalidArgument);
  EXPECT_THROW(model().CalcCollisionShapesInBase({{"arm_lift_joint", std::nan("")}}),
               InvalidArgument);
}

TEST_F(RobotModelTest, EveryShapeIsPlacedOnItsLinksPoseExactly) {
  // The shapes' link poses are computed once per link on the way down, shared among the
  // shapes: the same as each link's own CalcLinkPoseInBase, bit for bit, whatever the joints
  // (head, arm, lift and its mimic torso).
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> angle(-1.5, 1.5), lift(0.0, 0.6);
  for (int k = 0; k < 50; ++k) {
    std::vector<std::pair<std::string, double>> q;
    for (const char* joint :
         {"head_pan_joint", "head_tilt_joint", "arm_flex_joint", "arm_roll_joint",
          "wrist_flex_joint", "wrist_roll_joint", "hand_motor_joint", "arm_lift_joint"}) {
      q.emplace_back(joint, std::string_view(joint) == "arm_lift_joint" ? lift(rng) : angle(rng));
    }
    if (k % 2 == 0) q.pop_back();  // a joint left out stands at 0
    for (const bool skip_fingers : {true, false}) {
      for (const PlacedShape& placed : model().CalcCollisionShapesInBase(q, skip_fingers)) {
        const Pose3 X_BS = model().CalcLinkPoseInBase(placed.shape.link, q) * placed.shape.X_LS;
        ASSERT_EQ(placed.X_BS.translation(), X_BS.translation()) << placed.shape.name;
        ASSERT_EQ(placed.X_BS.rotation(), X_BS.rotation()) << placed.shape.name;
      }
    }
  }
}

TEST_F(RobotModelTest, RejectsNonFiniteConfigurations) {
  WholeBodyVector q = WholeBodyVector::Zero();
  q[kArmFlex] = std::nan("");
  try {
    model().CalcPalmPose(q);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("arm_flex_joint"));
  }
  EXPECT_THROW(model().CalcLinkPoseInBase("hand_palm_link", {{"no_such_joint", 0.0}}),
               InvalidArgument);
  EXPECT_THROW(model().CalcLinkPoseInBase("no_such_link", {}), InvalidArgument);
}

// --- Loading errors name the file and what is wrong.

std::string DefaultUrdfText() {
  std::ifstream file(RobotModel::DefaultUrdfPath());
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

// Replaces every occurrence of `from` in `text` by `to`; fails the test if there is none.
std::string ReplaceAll(std::string text, const std::string& from, const std::string& to) {
  std::size_t count = 0;
  for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at)) {
    text.replace(at, from.size(), to);
    at += to.size();
    ++count;
  }
  EXPECT_GT(count, 0u) << "'" << from << "' is not in the URDF";
  return text;
}

std::string LoadErrorOf(const std::string& xml) {
  try {
    RobotModel::LoadFromString(xml, "test.urdf");
  } catch (const LoadError& e) {
    return e.what();
  }
  return "";
}

TEST(RobotModelLoadTest, MissingFileIsNamed) {
  try {
    RobotModel::LoadFromFile("/nonexistent/dir/hsrb.urdf");
    FAIL() << "expected LoadError";
  } catch (const LoadError& e) {
    EXPECT_THAT(e.what(), HasSubstr("/nonexistent/dir/hsrb.urdf"));
    EXPECT_THAT(e.what(), HasSubstr("no such URDF file"));
  }
}

TEST(RobotModelLoadTest, MalformedXmlIsReported) {
  const std::string message = LoadErrorOf("<robot name='x'><link name='a'></robot");
  EXPECT_THAT(message, HasSubstr("test.urdf"));
  EXPECT_THAT(message, ::testing::ContainsRegex("XML|xml|parse"));
  EXPECT_THAT(LoadErrorOf("   \n"), HasSubstr("empty"));
}

TEST(RobotModelLoadTest, MissingJointIsNamed) {
  std::string xml = DefaultUrdfText();
  ASSERT_FALSE(xml.empty());
  // Turn the wrist flex into a fixed joint: the whole-body chain then lacks it.
  xml = ReplaceAll(xml, R"(<joint name="wrist_flex_joint" type="revolute">)",
                   R"(<joint name="wrist_flex_joint" type="fixed">)");
  const std::string message = LoadErrorOf(xml);
  EXPECT_THAT(message, HasSubstr("test.urdf"));
  EXPECT_THAT(message, HasSubstr("wrist_flex_joint"));
}

TEST(RobotModelLoadTest, MissingLinkIsNamed) {
  std::string xml = DefaultUrdfText();
  xml = ReplaceAll(xml, "base_range_sensor_link", "laser_link");
  EXPECT_THAT(LoadErrorOf(xml), HasSubstr("'base_range_sensor_link'"));
}

TEST(RobotModelLoadTest, DanglingJointParentIsReported) {
  std::string xml = DefaultUrdfText();
  xml = ReplaceAll(xml, R"(<parent link="arm_roll_link"/>)", R"(<parent link="forearm_link"/>)");
  const std::string message = LoadErrorOf(xml);
  EXPECT_THAT(message, HasSubstr("test.urdf"));
  EXPECT_THAT(message, HasSubstr("forearm_link"));
}

// Found by probing (kept as a regression test): a loop of joints cut off from the root passes
// urdfdom, and walking up from one of its links never ended (memory grew until killed).
TEST(RobotModelLoadTest, AKinematicCycleIsNamedNotWalkedForever) {
  std::string xml = DefaultUrdfText();
  xml = ReplaceAll(xml, "</robot>", R"(<link name="loop_a"/><link name="loop_b"/>
    <joint name="loop_ab" type="fixed"><parent link="loop_a"/><child link="loop_b"/></joint>
    <joint name="loop_ba" type="fixed"><parent link="loop_b"/><child link="loop_a"/></joint>
    </robot>)");
  const std::string message = LoadErrorOf(xml);
  EXPECT_THAT(message, HasSubstr("test.urdf"));
  EXPECT_THAT(message, HasSubstr("kinematic cycle"));
  EXPECT_THAT(message, HasSubstr("'loop_ab'"));
  EXPECT_THAT(message, HasSubstr("'loop_ba'"));
  // Found by the fuzzer: a joint from a link to itself, or a second parent, leaked urdfdom's
  // model (shared pointers owning each other) and is refused on the XML first.
  std::string self = DefaultUrdfText();
  self = ReplaceAll(self, "</robot>", R"(<link name="loop_a"/>
    <joint name="loop_aa" type="fixed"><parent link="loop_a"/><child link="loop_a"/></joint>
    </robot>)");
  EXPECT_THAT(LoadErrorOf(self), HasSubstr("'loop_a' as both its parent and its child"));
  std::string two = DefaultUrdfText();
  two = ReplaceAll(two, "</robot>", R"(<link name="extra"/>
    <joint name="second_parent" type="fixed"><parent link="extra"/><child link="base_link"/></joint>
    </robot>)");
  EXPECT_THAT(LoadErrorOf(two), HasSubstr("link 'base_link' is the child of two joints"));
  std::string ghost = DefaultUrdfText();
  ghost = ReplaceAll(ghost, "</robot>", R"(
    <joint name="to_ghost" type="fixed"><parent link="base_link"/><child link="ghost"/></joint>
    </robot>)");
  EXPECT_THAT(LoadErrorOf(ghost), HasSubstr("joint 'to_ghost'"));
  EXPECT_THAT(LoadErrorOf(ghost),
              HasSubstr("names link 'ghost', which the model does not declare"));
}

TEST(RobotModelLoadTest, FootprintRadiusFollowsTheBaseCylinder) {
  std::string xml = DefaultUrdfText();
  xml = ReplaceAll(xml, R"(<cylinder radius="0.215")", R"(<cylinder radius="0.25")");
  EXPECT_DOUBLE_EQ(RobotModel::LoadFromString(xml, "wide.urdf").footprint_radius(), 0.25);
}

TEST(RobotModelLoadTest, TheTuckedPoseComesFromTheUrdf) {
  const RobotModel model = RobotModel::LoadDefault();
  EXPECT_THAT(model.named_configurations(), ::testing::ElementsAre("tucked"));
  const WholeBodyVector tucked = model.tucked_configuration();
  EXPECT_DOUBLE_EQ(tucked[kArmRoll], -std::numbers::pi / 2);
  EXPECT_DOUBLE_EQ(tucked[kWristFlex], -std::numbers::pi / 2);
  EXPECT_EQ(tucked, model.NamedConfiguration("tucked"));
  // Nothing of the tucked arm sticks out of the footprint.
  const Eigen::Vector3d p_BG = model.CalcPalmPose(tucked).translation();
  EXPECT_LT(p_BG.head<2>().norm(), model.footprint_radius());
  try {
    model.NamedConfiguration("ready");
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("'ready'"));
    EXPECT_THAT(e.what(), HasSubstr("tucked"));
  }
  // Another value in the file is another tucked pose.
  std::string xml = DefaultUrdfText();
  xml = ReplaceAll(xml, R"(<joint name="arm_lift_joint" value="0.0"/>)",
                   R"(<joint name="arm_lift_joint" value="0.1"/>)");
  EXPECT_DOUBLE_EQ(RobotModel::LoadFromString(xml, "t.urdf").tucked_configuration()[kArmLift], 0.1);
}

TEST(RobotModelLoadTest, AUrdfWithoutNamedConfigurationsTucksAtZero) {
  std::string xml = DefaultUrdfText();
  xml = ReplaceAll(xml, R"(<group_state name="tucked" group="arm">)",
                   R"(<group_state name="home" group="arm">)");
  const RobotModel model = RobotModel::LoadFromString(xml, "t.urdf");
  EXPECT_EQ(model.tucked_configuration(), model.ClampToLimits(WholeBodyVector::Zero()));
}

TEST(RobotModelLoadTest, BadNamedConfigurationsAreNamed) {
  const std::string xml = DefaultUrdfText();
  std::string message = LoadErrorOf(ReplaceAll(xml, R"(<joint name="arm_flex_joint" value="0.0"/>)",
                                               R"(<joint name="elbow" value="0.0"/>)"));
  EXPECT_THAT(message, HasSubstr("test.urdf"));
  EXPECT_THAT(message, HasSubstr("'elbow'"));
  EXPECT_THAT(message, ::testing::ContainsRegex("line [0-9]+"));
  message = LoadErrorOf(ReplaceAll(xml, R"(<joint name="arm_lift_joint" value="0.0"/>)",
                                   R"(<joint name="arm_lift_joint" value="2.0"/>)"));
  EXPECT_THAT(message, HasSubstr("outside arm_lift_joint's limits"));
  message = LoadErrorOf(ReplaceAll(xml, R"(<joint name="arm_lift_joint" value="0.0"/>)",
                                   R"(<joint name="arm_lift_joint" value="low"/>)"));
  EXPECT_THAT(message, HasSubstr("finite number"));
  message = LoadErrorOf(ReplaceAll(xml, R"(<group_state name="tucked" group="arm">)",
                                   R"(<group_state group="arm">)"));
  EXPECT_THAT(message, HasSubstr("has no name"));
}

TEST(RobotModelLoadTest, CopiesAreIndependentAndEqual) {
  const RobotModel a = RobotModel::LoadDefault();
  RobotModel b = a;
  const WholeBodyVector q = Arm(0.3, -1.2, 0.4, -0.3, 1.0);
  EXPECT_TRUE(a.CalcPalmPose(q).IsNearlyEqualTo(b.CalcPalmPose(q), 0.0));
  RobotModel c = std::move(b);
  EXPECT_EQ(c.name(), "hsrb");
}

}  // namespace
}  // namespace egress
