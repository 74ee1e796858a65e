#include "doorway_judge.h"

#include <gtest/gtest.h>

namespace egress::apps {
namespace {

// A 0.9 m doorway at the origin in a wall along x (the door line), people walking through along y.
twin::DoorwayFrame Doorway() {
  twin::DoorwayFrame d;
  d.centre = Eigen::Vector2d(0.0, 0.0);
  d.normal = Eigen::Vector2d::UnitY();
  d.along = Eigen::Vector2d::UnitX();
  d.half_width = 0.45;
  return d;
}

TEST(DoorwayBlockJudgeTest, TheRobotIsInADoorwayWithinHalfAMetreOfItsLineBetweenTheJambs) {
  const DoorwayBlockJudge judge({Doorway()});
  EXPECT_TRUE(judge.InDoorway({0.0, 0.0}));
  EXPECT_TRUE(judge.InDoorway({0.3, -0.45}));
  EXPECT_FALSE(judge.InDoorway({0.0, 0.55}));  // in front of it
  EXPECT_FALSE(judge.InDoorway({0.6, 0.0}));   // in the wall beside it
  EXPECT_FALSE(judge.InDoorway({-3.0, 0.0}));  // along the wall
}

TEST(DoorwayBlockJudgeTest, InADoorwayWithAResidentNearCountsAndTheTimeStandingThereApart) {
  DoorwayBlockJudge judge({Doorway()});
  const std::vector<Eigen::Vector2d> near{{0.0, 1.5}}, far{{0.0, 2.5}};
  judge.Step(0.1, {0.0, 0.2}, 0.6, far);  // driving through, nobody within 2 m
  EXPECT_DOUBLE_EQ(judge.in_doorway_s(), 0.0);
  judge.Step(0.1, {0.0, 0.2}, 0.6, near);  // driving through beside someone
  EXPECT_DOUBLE_EQ(judge.in_doorway_s(), 0.1);
  EXPECT_DOUBLE_EQ(judge.standing_s(), 0.0);
  judge.Step(0.1, {0.0, 0.2}, 0.01, near);  // standing in it beside someone
  EXPECT_DOUBLE_EQ(judge.in_doorway_s(), 0.2);
  EXPECT_DOUBLE_EQ(judge.standing_s(), 0.1);
  judge.Step(0.1, {0.0, 1.0}, 0.0, near);  // standing before it: not in the doorway
  judge.Step(0.1, {0.0, 0.0}, 0.0, {});    // standing in it with nobody left in the building
  EXPECT_DOUBLE_EQ(judge.in_doorway_s(), 0.2);
  EXPECT_DOUBLE_EQ(judge.standing_s(), 0.1);
}

}  // namespace
}  // namespace egress::apps
