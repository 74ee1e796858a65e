// The task nodes' shared door-zone rules (door_rules.h): who occupies a door's zone, and who
// holds a door open out of the robot's way.

#include <gtest/gtest.h>

#include "egress/behavior/door_rules.h"
#include "egress/hsr_interface/error.h"
#include "task_node_fixture.h"

namespace egress::behavior {
namespace {

// The lab's door in the wall y = 3 (hinge at x = 0.475, latch at x = -0.475); the robot waits
// south of it.
using node_testing::LabDoor;

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
  DoorZoneRulesTest() { belief_.X_MB = {0.0, 2.3, M_PI / 2}; }
  MissionMap map_ = LabDoor();
  Belief belief_;
  TaskServices services_ = [this] {
    TaskServices s;
    s.map = &map_;
    s.belief = &belief_;
    return s;
  }();
};

// A pose on a blackboard (x;y;yaw) is numbers, finite ones: std::stod reads "nan" and "inf",
// which would reach the planners as a goal.
TEST(ParsePose2Test, RefusesNonNumbersAndNonFiniteValues) {
  const Pose2 X = ParsePose2("1.5;-2;0.25");
  EXPECT_DOUBLE_EQ(X.x, 1.5);
  EXPECT_DOUBLE_EQ(X.yaw, 0.25);
  EXPECT_DOUBLE_EQ(ParsePose2("3;4").yaw, 0.0);
  for (const char* bad :
       {"nan;0;0", "0;inf;0", "0;0;-inf", "1e400;0;0", "1;x;0", "1;2;3;4", "1", ""}) {
    EXPECT_THROW(ParsePose2(bad), InvalidArgument) << bad;
  }
}

TEST_F(DoorZoneRulesTest, AHolderBesideTheHingeJambIsNoReasonToWait) {
  // A person holding the door, standing by the hinge jamb, 0.4 m off the line: their disc
  // reaches into the zone, but not into the robot's lane through the opening.
  const auto holder = StillPerson({0.475 + 0.25, 3.4}, perception::PersonIntent::kHoldingDoor);
  belief_.world.people = {holder};
  EXPECT_TRUE(IsHoldingDoorAside(services_, holder, "lab_door"));
  EXPECT_FALSE(IsDoorZoneOccupied(services_, "lab_door"));
  // Holding another door, the same person occupies this one's zone.
  auto elsewhere = holder;
  elsewhere.door_id = "door_b";
  belief_.world.people = {elsewhere};
  EXPECT_FALSE(IsHoldingDoorAside(services_, elsewhere, "lab_door"));
  EXPECT_TRUE(IsDoorZoneOccupied(services_, "lab_door"));
}

TEST_F(DoorZoneRulesTest, APersonStoppedInTheDoorwayBlocksItWhateverTheirIntentReads) {
  // Stopped face to face with the robot, 0.2 m beyond the line in the opening's middle: still and
  // near the open leaf's hinge, so the tracker may read "holding" — but in the robot's lane.
  const auto in_lane = StillPerson({-0.2, 3.2}, perception::PersonIntent::kHoldingDoor);
  belief_.world.people = {in_lane};
  EXPECT_FALSE(IsHoldingDoorAside(services_, in_lane, "lab_door"));
  EXPECT_TRUE(IsDoorZoneOccupied(services_, "lab_door"));
  // The lane is as wide as the footprint plus a person, either side of the opening's middle.
  const double edge = services_.config.footprint_radius + services_.config.person_radius;
  EXPECT_FALSE(IsHoldingDoorAside(
      services_, StillPerson({edge - 0.01, 3.4}, perception::PersonIntent::kHoldingDoor),
      "lab_door"));
  EXPECT_TRUE(IsHoldingDoorAside(
      services_, StillPerson({-edge - 0.01, 3.4}, perception::PersonIntent::kHoldingDoor),
      "lab_door"));
}

TEST_F(DoorZoneRulesTest, AStillPersonInTheZoneOccupiesItAndOneFarAwayDoesNot) {
  belief_.world.people = {StillPerson({0.0, 3.9}, perception::PersonIntent::kStationary)};
  EXPECT_TRUE(IsDoorZoneOccupied(services_, "lab_door"));
  belief_.world.people = {StillPerson({0.0, 5.0}, perception::PersonIntent::kStationary)};
  EXPECT_FALSE(IsDoorZoneOccupied(services_, "lab_door"));
  // Forecast into it: occupied now.
  auto walking_in = StillPerson({0.0, 5.0}, perception::PersonIntent::kApproaching);
  walking_in.person.forecast = {{0.0, 4.6}, {0.0, 4.2}};
  belief_.world.people = {walking_in};
  EXPECT_TRUE(IsDoorZoneOccupied(services_, "lab_door"));
}

// A door held open out of the robot's sight (steady at 80°, no press of ours), seen open for
// `open_for`; the robot 1 m before the line on `side` (+1: north, the side the leaf opens into).
class DoorWindowTest : public DoorZoneRulesTest {
 protected:
  DoorWindowTest() : model_(RobotModel::LoadDefault()), motion_(model_) {
    services_.motion = &motion_;
  }
  bool PassableAfter(double open_for, double side, double estimate_age = 0.0,
                     bool witnessed = true) {
    belief_.now = Time{} + SecondsToDuration(100.0);
    belief_.X_MB = {0.0, 3.0 + side * 1.0, side > 0 ? -M_PI / 2 : M_PI / 2};
    belief_.door_open_since["lab_door"] = belief_.now - SecondsToDuration(open_for);
    belief_.door_opening_witnessed.clear();
    if (witnessed) belief_.door_opening_witnessed.insert("lab_door");
    perception::TrackedDoor door;
    door.model = map_.doors[0];
    door.state.observed = true;
    door.state.angle = 80.0 * M_PI / 180.0;
    door.state.clearance_width = door.model.ClearanceWidth(door.state.angle);
    door.state.motion = perception::DoorMotion::kHeldOpen;
    door.state.stamp = belief_.now - SecondsToDuration(estimate_age);
    belief_.world.doors = {door};
    return DoorPassable(services_, "lab_door", 0.0, nullptr);
  }
  RobotModel model_;
  MotionExecutor motion_;
};

TEST_F(DoorWindowTest, ALeafOpeningTowardsTheRobotLeavesItTheTimeItTakesToCloseOnItsLane) {
  // From the swing side the robot has 1.365 m to go (to just past the line): 3.4 s at 0.4 m/s.
  // Open 7 s, 10.4 s in all: past a 10 s window, but the leaf, closing at most 80° in 3 s, takes
  // over a second to come down from 80° to the lane through the opening.
  EXPECT_TRUE(PassableAfter(7.0, +1.0));
  // Open 8 s: it would still be in the lane when the leaf reaches it.
  EXPECT_FALSE(PassableAfter(8.0, +1.0));
  // From the other side the leaf closes towards the far side, where the robot must get beyond
  // its sweep: no such grace. Open 7 s leaves too little time; 2 s enough.
  EXPECT_FALSE(PassableAfter(7.0, -1.0));
  EXPECT_TRUE(PassableAfter(2.0, -1.0));
}

TEST_F(DoorWindowTest, ADoorSeenOpenLongPastTheWindowIsHeldButOnlyIfSeenSoNow) {
  // Open 15 s, past the 10 s window and its 2 s margin: someone out of sight holds it...
  EXPECT_TRUE(PassableAfter(15.0, -1.0));
  // ...unless that is what the door was 5 s ago, the last time the laser saw the leaf.
  EXPECT_FALSE(PassableAfter(15.0, -1.0, 5.0));
}

TEST_F(DoorWindowTest, AnOpeningNotSeenBeginningMayCloseAnyMoment) {
  // Seen open 2 s, but already open when first seen: it may have opened a window ago. From
  // either side that leaves no time to pass...
  EXPECT_TRUE(PassableAfter(2.0, -1.0));
  EXPECT_FALSE(PassableAfter(2.0, -1.0, 0.0, false));
  EXPECT_FALSE(PassableAfter(2.0, +1.0, 0.0, false));
  // ...until it has stood open past a whole window and its margin: then something holds it.
  EXPECT_TRUE(PassableAfter(15.0, -1.0, 0.0, false));
}

// Issue 17: a robot driving through a door is in the doorway for the seconds the pass takes;
// whoever walks past the doorway meanwhile passes beside it.
TEST_F(DoorZoneRulesTest, SomeoneWalkingPastTheFarSideMakesThePassageBusyOverTheTimeTheyComeNear) {
  // 1 m beyond the line, 3.5 m to the side, walking past at 1 m/s: 3.6 m from the opening's
  // middle now, 1 m when abreast of it 3.5 s from now.
  auto passer = StillPerson({-3.5, 4.0}, perception::PersonIntent::kApproaching);
  passer.person.v_MP = {1.0, 0.0};
  belief_.world.people = {passer};
  ASSERT_DOUBLE_EQ(services_.config.passage_clearance, 2.0);
  EXPECT_FALSE(IsPassageBusy(services_, "lab_door", 0.0));
  EXPECT_FALSE(IsPassageBusy(services_, "lab_door", 1.0));  // 2.7 m away then
  EXPECT_TRUE(IsPassageBusy(services_, "lab_door", 3.0));
  // Walking the other way, away from the doorway: never near it.
  passer.person.v_MP = {-1.0, 0.0};
  belief_.world.people = {passer};
  EXPECT_FALSE(IsPassageBusy(services_, "lab_door", 10.0));
  // Standing 2.9 m from it, the track jittering 0.15 m/s towards it: standing (under
  // kWalkingMps), so not busy however long the pass (S2 seed 2005); walking at that way, busy.
  auto stander = StillPerson({-1.76, 0.74}, perception::PersonIntent::kStationary);
  stander.person.v_MP = {0.04, 0.15};
  belief_.world.people = {stander};
  EXPECT_FALSE(IsPassageBusy(services_, "lab_door", 6.5));
  stander.person.v_MP = {0.3, 0.6};
  belief_.world.people = {stander};
  EXPECT_TRUE(IsPassageBusy(services_, "lab_door", 6.5));
  // Standing 1.5 m from it: busy whatever the horizon; unless the rule is off.
  belief_.world.people = {StillPerson({1.5, 3.0}, perception::PersonIntent::kStationary)};
  EXPECT_TRUE(IsPassageBusy(services_, "lab_door", 0.0));
  services_.config.passage_clearance = 0.0;
  EXPECT_FALSE(IsPassageBusy(services_, "lab_door", 0.0));
  // Someone holding the door aside is why the robot may pass.
  services_.config.passage_clearance = 2.0;
  const auto holder = StillPerson({0.475 + 0.25, 3.4}, perception::PersonIntent::kHoldingDoor);
  belief_.world.people = {holder};
  ASSERT_TRUE(IsHoldingDoorAside(services_, holder, "lab_door"));
  EXPECT_FALSE(IsPassageBusy(services_, "lab_door", 5.0));
}

// From before a door the robot sees a metre or so along the passage beyond: people seen passing
// the doorway lately are a stream still walking by, out of view.
TEST_F(DoorZoneRulesTest, APassageIsClearOnlyOnceNobodyHasBeenNearTheDoorwayForTheQuietTime) {
  belief_.now = Time{} + SecondsToDuration(20.0);
  belief_.world.people = {};
  EXPECT_TRUE(IsPassageClear(services_, "lab_door", 5.0, 5.0));  // nobody ever seen there
  belief_.passage_used_at["lab_door"] = belief_.now - SecondsToDuration(3.0);
  EXPECT_FALSE(IsPassageClear(services_, "lab_door", 5.0, 5.0));
  EXPECT_TRUE(IsPassageClear(services_, "lab_door", 5.0, 2.0));
  belief_.passage_used_at["lab_door"] = belief_.now - SecondsToDuration(6.0);
  EXPECT_TRUE(IsPassageClear(services_, "lab_door", 5.0, 5.0));
  // Quiet long enough, but someone coming: not clear.
  auto passer = StillPerson({-3.5, 4.0}, perception::PersonIntent::kApproaching);
  passer.person.v_MP = {1.0, 0.0};
  belief_.world.people = {passer};
  EXPECT_FALSE(IsPassageClear(services_, "lab_door", 5.0, 5.0));
}

TEST_F(DoorZoneRulesTest, AnUnknownDoorIsAClearError) {
  EXPECT_THROW(IsDoorZoneOccupied(services_, "door_z"), InvalidArgument);
}

// Issue 21: a person the tracker reads as crossing (through the opening within its 2 s horizon)
// occupies the zone already, before the paper's 0.8 s forecast reaches it.
TEST_F(DoorZoneRulesTest, APersonCrossingOccupiesTheZoneBeforeTheForecastReachesIt) {
  auto coming = StillPerson({-0.2, 5.6}, perception::PersonIntent::kCrossing);
  coming.person.v_MP = {0.0, -1.3};
  coming.person.forecast = {{-0.2, 5.3}, {-0.2, 5.1}};  // 0.8 s: not yet in the zone
  belief_.world.people = {coming};
  EXPECT_TRUE(IsDoorZoneOccupied(services_, "lab_door"));
  services_.config.yield_to_crossing = false;
  EXPECT_FALSE(IsDoorZoneOccupied(services_, "lab_door"));
  // Crossing another door: not this one's.
  services_.config.yield_to_crossing = true;
  coming.door_id = "door_b";
  belief_.world.people = {coming};
  EXPECT_FALSE(IsDoorZoneOccupied(services_, "lab_door"));
}

TEST_F(DoorZoneRulesTest, SomeoneWaitingBeyondADoorThatJustOpenedHasTheRightOfWay) {
  services_.config.right_of_way_time = 2.0;
  belief_.now = Time{} + SecondsToDuration(50.0);
  const auto opened = [&](double ago) {
    belief_.door_open_since["lab_door"] = belief_.now - SecondsToDuration(ago);
  };
  const auto waiting = StillPerson({-0.3, 4.7}, perception::PersonIntent::kStationary);
  belief_.world.people = {waiting};
  opened(1.0);
  EXPECT_TRUE(IsDoorZoneOccupied(services_, "lab_door"));
  opened(2.5);  // still standing there once the right of way is over: not coming
  EXPECT_FALSE(IsDoorZoneOccupied(services_, "lab_door"));
  belief_.door_open_since.clear();  // not open yet: the robot has to open it first
  EXPECT_FALSE(IsDoorZoneOccupied(services_, "lab_door"));
  opened(1.0);
  auto leaving = waiting;
  leaving.person.v_MP = {-0.3, 1.0};  // walking off from the doorway
  belief_.world.people = {leaving};
  EXPECT_FALSE(IsDoorZoneOccupied(services_, "lab_door"));
  // Beyond the radius, or on the robot's own side: no right of way over the robot.
  belief_.world.people = {StillPerson({-0.3, 5.7}, perception::PersonIntent::kStationary)};
  EXPECT_FALSE(IsDoorZoneOccupied(services_, "lab_door"));
  belief_.world.people = {StillPerson({-1.3, 1.6}, perception::PersonIntent::kStationary)};
  EXPECT_FALSE(IsDoorZoneOccupied(services_, "lab_door"));
  services_.config.right_of_way_time = 0.0;
  belief_.world.people = {waiting};
  EXPECT_FALSE(IsDoorZoneOccupied(services_, "lab_door"));
}

TEST_F(DoorZoneRulesTest, DoorZonesReachZoneDepthFromTheLineAndCoverTheLeafsSweep) {
  // South (the robot's side), on the axis: within zone_depth (1 m) of the line or not.
  EXPECT_TRUE(IsInAnyDoorZone(services_, {0.0, 2.1}));
  EXPECT_FALSE(IsInAnyDoorZone(services_, {0.0, 1.9}));
  // Beside the opening by more than half a metre past the jamb: not in the way.
  EXPECT_TRUE(IsInAnyDoorZone(services_, {0.9, 2.5}));
  EXPECT_FALSE(IsInAnyDoorZone(services_, {1.2, 2.5}));
  // North, where the leaf swings: in its sweep though beside the opening.
  EXPECT_TRUE(IsInAnyDoorZone(services_, {1.0, 3.3}));
  EXPECT_FALSE(IsInAnyDoorZone(services_, {2.0, 3.3}));
}

// A step aside never goes through a doorway (two wards seed 5: a retreat's spot 1.6 m beyond
// door_d as its leaf closed). The door line runs y = 3 between its jambs at x = ±0.475.
TEST_F(DoorZoneRulesTest, AWayThroughADoorwayCrossesTheDoorLineBetweenItsJambs) {
  EXPECT_TRUE(PassesThroughAnyDoorway(services_, {0.0, 1.3}, {0.0, 4.5}));   // straight through
  EXPECT_TRUE(PassesThroughAnyDoorway(services_, {0.0, 4.5}, {0.0, 1.3}));   // either way
  EXPECT_TRUE(PassesThroughAnyDoorway(services_, {-1.0, 1.5}, {1.0, 4.5}));  // on a slant
  EXPECT_TRUE(PassesThroughAnyDoorway(services_, {0.0, 2.0}, {0.0, 3.0}));   // to the line
  EXPECT_FALSE(PassesThroughAnyDoorway(services_, {0.0, 1.3}, {1.5, 2.9}));  // this side only
  EXPECT_FALSE(PassesThroughAnyDoorway(services_, {0.0, 3.2}, {1.5, 4.5}));  // the far side only
  // Across the wall's line beside the opening (through the wall, which the planner rejects):
  // not through the doorway.
  EXPECT_FALSE(PassesThroughAnyDoorway(services_, {1.0, 2.0}, {1.0, 4.0}));
  EXPECT_FALSE(PassesThroughAnyDoorway(services_, {-3.0, 2.0}, {-0.6, 4.0}));
}

}  // namespace
}  // namespace egress::behavior
