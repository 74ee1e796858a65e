#include "egress/hsr_interface/robot_state_types.h"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress {
namespace {

using ::testing::HasSubstr;

std::string ErrorOf(const auto& value) {
  try {
    value.Validate();
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "";
}

TEST(JointStateTest, LookupAndValidation) {
  JointState state;
  state.names = {"arm_lift_joint", "arm_flex_joint"};
  state.positions = {0.2, -1.0};
  EXPECT_NO_THROW(state.Validate());
  EXPECT_EQ(state.Position("arm_flex_joint"), -1.0);
  EXPECT_FALSE(state.Position("head_pan_joint").has_value());

  state.velocities = {0.0};
  EXPECT_THAT(ErrorOf(state), HasSubstr("velocities"));
  state.velocities.clear();
  state.positions[1] = std::nan("");
  EXPECT_THAT(ErrorOf(state), HasSubstr("arm_flex_joint"));
  state.positions[1] = 0.0;
  state.names[1] = "arm_lift_joint";
  EXPECT_THAT(ErrorOf(state), HasSubstr("twice"));
}

TEST(OdometryTest, Validation) {
  Odometry odometry;
  odometry.X_OB = {1.0, 2.0, 0.3};
  odometry.covariance = Eigen::Vector3d(0.01, 0.01, 0.001).asDiagonal();
  EXPECT_NO_THROW(odometry.Validate());
  odometry.X_OB.yaw = std::nan("");
  EXPECT_THAT(ErrorOf(odometry), HasSubstr("X_OB"));
  odometry.X_OB.yaw = 0.0;
  odometry.covariance(0, 1) = 0.5;
  EXPECT_THAT(ErrorOf(odometry), HasSubstr("symmetric"));
  odometry.covariance(1, 0) = 0.5;  // symmetric but not PSD
  EXPECT_THAT(ErrorOf(odometry), HasSubstr("semi-definite"));
}

TEST(GripperStateTest, Validation) {
  GripperState gripper{Time{0}, 0.5, 10.0};
  EXPECT_NO_THROW(gripper.Validate());
  gripper.effort = -1.0;
  EXPECT_THAT(ErrorOf(gripper), HasSubstr("effort"));
}

}  // namespace
}  // namespace egress
