// The task nodes' shared door-zone rules (task_context.h): who occupies a door's zone, and who
// holds a door open out of the robot's way.

#include <gtest/gtest.h>

#include "egress/behavior/task_context.h"
#include "egress/hsr_interface/error.h"

namespace egress::behavior {
namespace {

// A door in the wall y = 3 (hinge at x = 0.475, latch at x = -0.475), as the lab's; the robot
// waits south of it.
MissionMap LabDoor() {
  MissionMap map;
  perception::Doorway doorway;
  doorway.id = "lab_door";
  doorway.p_MHinge = {0.475, 3.0};
  doorway.p_MLatch = {-0.475, 3.0};
  map.doorways.push_back(doorway);
  perception::DoorModel door;
  door.id = "lab_door";
  door.p_MHinge = doorway.p_MHinge;
  door.p_MLatch = doorway.p_MLatch;
  door.swing_sign = -1.0;
  map.doors.push_back(door);
  return map;
}

perception::TrackedPersonWithIntent StillPerson(const Eigen::Vector2d& p_MP,
                                                perception::PersonIntent intent) {
  perception::TrackedPersonWithIntent entry;
  entry.person.p_MP = p_MP;
  entry.person.v_MP = Eigen::Vector2d::Zero();
  entry.intent = intent;
  entry.door_id = "lab_door";
  return entry;
}

class DoorZoneRulesTest : public ::testing::Test {
 protected:
  DoorZoneRulesTest() {
    context_.map = &map_;
    context_.X_MB = {0.0, 2.3, M_PI / 2};
  }
  MissionMap map_ = LabDoor();
  TaskContext context_;
};

TEST_F(DoorZoneRulesTest, AHolderBesideTheHingeJambIsNoReasonToWait) {
  // A person holding the door, standing by the hinge jamb, 0.4 m off the line: their disc
  // reaches into the zone, but not into the robot's lane through the opening.
  const auto holder = StillPerson({0.475 + 0.25, 3.4}, perception::PersonIntent::kHoldingDoor);
  context_.world.people = {holder};
  EXPECT_TRUE(IsHoldingDoorAside(context_, holder, "lab_door"));
  EXPECT_FALSE(IsDoorZoneOccupied(context_, "lab_door"));
  // Holding another door, the same person occupies this one's zone.
  auto elsewhere = holder;
  elsewhere.door_id = "door_b";
  context_.world.people = {elsewhere};
  EXPECT_FALSE(IsHoldingDoorAside(context_, elsewhere, "lab_door"));
  EXPECT_TRUE(IsDoorZoneOccupied(context_, "lab_door"));
}

TEST_F(DoorZoneRulesTest, APersonStoppedInTheDoorwayBlocksItWhateverTheirIntentReads) {
  // Stopped face to face with the robot, 0.2 m beyond the line in the opening's middle: still and
  // near the open leaf's hinge, so the tracker may read "holding" — but in the robot's lane.
  const auto in_lane = StillPerson({-0.2, 3.2}, perception::PersonIntent::kHoldingDoor);
  context_.world.people = {in_lane};
  EXPECT_FALSE(IsHoldingDoorAside(context_, in_lane, "lab_door"));
  EXPECT_TRUE(IsDoorZoneOccupied(context_, "lab_door"));
  // The lane is as wide as the footprint plus a person, either side of the opening's middle.
  const double edge = context_.config.footprint_radius + context_.config.person_radius;
  EXPECT_FALSE(IsHoldingDoorAside(
      context_, StillPerson({edge - 0.01, 3.4}, perception::PersonIntent::kHoldingDoor),
      "lab_door"));
  EXPECT_TRUE(IsHoldingDoorAside(
      context_, StillPerson({-edge - 0.01, 3.4}, perception::PersonIntent::kHoldingDoor),
      "lab_door"));
}

TEST_F(DoorZoneRulesTest, AStillPersonInTheZoneOccupiesItAndOneFarAwayDoesNot) {
  context_.world.people = {StillPerson({0.0, 3.9}, perception::PersonIntent::kStationary)};
  EXPECT_TRUE(IsDoorZoneOccupied(context_, "lab_door"));
  context_.world.people = {StillPerson({0.0, 5.0}, perception::PersonIntent::kStationary)};
  EXPECT_FALSE(IsDoorZoneOccupied(context_, "lab_door"));
  // Forecast into it: occupied now.
  auto walking_in = StillPerson({0.0, 5.0}, perception::PersonIntent::kApproaching);
  walking_in.person.forecast = {{0.0, 4.6}, {0.0, 4.2}};
  context_.world.people = {walking_in};
  EXPECT_TRUE(IsDoorZoneOccupied(context_, "lab_door"));
}

TEST_F(DoorZoneRulesTest, AnUnknownDoorIsAClearError) {
  EXPECT_THROW(IsDoorZoneOccupied(context_, "door_z"), InvalidArgument);
}

}  // namespace
}  // namespace egress::behavior
