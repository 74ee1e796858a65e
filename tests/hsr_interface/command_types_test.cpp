#include "egress/hsr_interface/command_types.h"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress {
namespace {

using std::chrono::milliseconds;
using ::testing::HasSubstr;

std::string ErrorOf(const auto& value) {
  try {
    value.Validate();
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "";
}

JointTrajectory TwoPointTrajectory() {
  JointTrajectory trajectory;
  trajectory.joint_names = {"arm_lift_joint", "arm_flex_joint"};
  trajectory.points = {{{0.0, 0.0}, {}, {}, milliseconds(0)},
                       {{0.2, -1.0}, {0.0, 0.0}, {0.0, 0.0}, milliseconds(1500)}};
  return trajectory;
}

TEST(JointTrajectoryTest, Validation) {
  JointTrajectory trajectory = TwoPointTrajectory();
  EXPECT_NO_THROW(trajectory.Validate());

  trajectory.points[1].time_from_start = milliseconds(0);
  EXPECT_THAT(ErrorOf(trajectory), HasSubstr("points[1].time_from_start"));
  trajectory = TwoPointTrajectory();
  trajectory.points[1].positions.pop_back();
  EXPECT_THAT(ErrorOf(trajectory), HasSubstr("points[1] has 1 positions for 2 joints"));
  trajectory = TwoPointTrajectory();
  trajectory.points[1].velocities[0] = INFINITY;
  EXPECT_THAT(ErrorOf(trajectory), HasSubstr("points[1].velocity of 'arm_lift_joint'"));
  trajectory = TwoPointTrajectory();
  trajectory.joint_names[1] = "arm_lift_joint";
  EXPECT_THAT(ErrorOf(trajectory), HasSubstr("twice"));
  trajectory = TwoPointTrajectory();
  trajectory.points.clear();
  EXPECT_THAT(ErrorOf(trajectory), HasSubstr("points must not be empty"));
}

TEST(GripperCommandTest, Validation) {
  GripperCommand command{GripperCommand::Mode::kGrasp, 0.0, 20.0};
  EXPECT_NO_THROW(command.Validate());
  command.effort = -5.0;
  EXPECT_THAT(ErrorOf(command), HasSubstr("effort"));
  command = {GripperCommand::Mode::kPosition, std::nan(""), 0.0};
  EXPECT_THAT(ErrorOf(command), HasSubstr("position"));
}

}  // namespace
}  // namespace egress
