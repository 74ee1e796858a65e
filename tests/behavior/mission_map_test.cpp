#include "egress/behavior/mission_map.h"

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress::behavior {
namespace {

// A door in the wall x = 5 (hinge at y = 2.5, latch at y = 3.5) with a push button on each
// side at y = 2.0.
MissionMap TwoSidedDoor() {
  MissionMap map;
  perception::Doorway doorway;
  doorway.id = "door_a";
  doorway.p_MHinge = {5.0, 2.5};
  doorway.p_MLatch = {5.0, 3.5};
  map.doorways.push_back(doorway);
  perception::DoorModel door;
  door.id = "door_a";
  door.p_MHinge = doorway.p_MHinge;
  door.p_MLatch = doorway.p_MLatch;
  door.swing_sign = -1.0;  // opens towards +x
  map.doors.push_back(door);
  MapActuator west{"west",
                   "door_a",
                   planning::ButtonType::kPushButton,
                   {4.93, 2.0, 1.0},
                   -Eigen::Vector3d::UnitX(),
                   0.02};
  MapActuator east{"east",
                   "door_a",
                   planning::ButtonType::kPushButton,
                   {5.07, 2.0, 1.0},
                   Eigen::Vector3d::UnitX(),
                   0.02};
  map.actuators = {west, east};
  return map;
}

TEST(MissionMapTest, TheActuatorOnTheRobotsSideOfTheWallIsChosen) {
  const MissionMap map = TwoSidedDoor();
  ASSERT_NO_THROW(map.Validate());
  const MapActuator* from_west = map.FindActuatorOf("door_a", {3.0, 3.0});
  const MapActuator* from_east = map.FindActuatorOf("door_a", {7.0, 1.0});
  ASSERT_NE(from_west, nullptr);
  ASSERT_NE(from_east, nullptr);
  EXPECT_EQ(from_west->id, "west");
  EXPECT_EQ(from_east->id, "east");
  EXPECT_EQ(map.FindActuatorOf("door_b", {3.0, 3.0}), nullptr);
  EXPECT_EQ(map.FindActuator("east"), from_east);
  EXPECT_EQ(map.FindActuator("north"), nullptr);
}

TEST(MissionMapTest, ADoorWithItsButtonOnTheOtherSideHasNoneOnThisSide) {
  MissionMap map = TwoSidedDoor();
  map.actuators.pop_back();  // only the west button
  EXPECT_EQ(map.FindActuatorOf("door_a", {7.0, 3.0}), nullptr);
  EXPECT_NE(map.FindActuatorOf("door_a", {3.0, 3.0}), nullptr);
}

TEST(MissionMapTest, AnActuatorOfAnUnknownDoorOrWithABadNormalIsRejected) {
  MissionMap map = TwoSidedDoor();
  map.actuators[0].door = "door_z";
  EXPECT_THROW(map.Validate(), InvalidArgument);
  map = TwoSidedDoor();
  map.actuators[1].n_M = {2.0, 0.0, 0.0};
  EXPECT_THROW(map.Validate(), InvalidArgument);
}

TEST(MissionMapTest, TheSwingSideIsTheRoomTheLeafOpensInto) {
  const MissionMap map = TwoSidedDoor();
  const perception::DoorModel& door = map.doors.front();
  EXPECT_NEAR(door.SwingSide().x(), 1.0, 1e-12);
  EXPECT_NEAR(door.SwingSide().y(), 0.0, 1e-12);
  // The leaf opened 90° lies on that side.
  EXPECT_GT((door.LeafTip(M_PI / 2) - door.p_MHinge).dot(door.SwingSide()), 0.9);
}

}  // namespace
}  // namespace egress::behavior
