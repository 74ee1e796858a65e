#include "egress/behavior/head_gaze.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress::behavior {
namespace {

Time At(double t) {
  return Time{} + SecondsToDuration(t);
}

// The lab's door (wall y = 3, opening x -0.475..0.475); the robot south of it, facing it.
perception::TrackedDoor LabDoor(double open_fraction) {
  perception::TrackedDoor door;
  door.model.id = "lab_door";
  door.model.p_MHinge = {0.475, 3.0};
  door.model.p_MLatch = {-0.475, 3.0};
  door.model.swing_sign = -1.0;
  door.state.observed = true;
  door.state.open_fraction = open_fraction;
  return door;
}

perception::TrackedPersonWithIntent Walker(int id, const Eigen::Vector2d& p_MP,
                                           const Eigen::Vector2d& v_MP) {
  perception::TrackedPersonWithIntent entry;
  entry.person.id = id;
  entry.person.p_MP = p_MP;
  entry.person.v_MP = v_MP;
  return entry;
}

class HeadGazeTest : public ::testing::Test {
 protected:
  HeadGazeTest() {
    belief_.X_MB = {1.15, 2.4, M_PI / 2};  // at the button's standoff, facing the wall
    belief_.now = At(1.0);
  }
  std::optional<HeadCommand> Update(double pan_now) { return gaze_.Update(belief_, pan_now); }
  Belief belief_;
  HeadGaze gaze_;
};

TEST_F(HeadGazeTest, LooksAheadWithNothingToLookAtAndSendsOnlyChanges) {
  const auto first = Update(0.3);
  ASSERT_TRUE(first.has_value());
  EXPECT_DOUBLE_EQ(first->pan, 0.0);
  EXPECT_DOUBLE_EQ(first->tilt, 0.0);
  EXPECT_EQ(gaze_.reason(), GazeReason::kAhead);
  belief_.now = At(1.01);
  EXPECT_FALSE(Update(0.0).has_value());  // the same target: nothing new to send
}

TEST_F(HeadGazeTest, LooksThroughADoorThatOpensToItsFarSide) {
  belief_.world.doors = {LabDoor(0.0)};
  Update(0.0);
  EXPECT_EQ(gaze_.reason(), GazeReason::kAhead);  // closed: nothing to see through it
  belief_.world.doors = {LabDoor(0.3)};
  const auto look = Update(0.0);
  ASSERT_TRUE(look.has_value());
  EXPECT_EQ(gaze_.reason(), GazeReason::kDoor);
  // At the point 1.5 m beyond the doorway's centre: (0, 4.5) from (1.15, 2.4), facing +y.
  const double expected = std::atan2(4.5 - 2.4, 0.0 - 1.15) - M_PI / 2;
  EXPECT_NEAR(look->pan, expected, 1e-9);
  EXPECT_GT(look->pan, 0.0);  // to the left
  // Through it and facing away (the door behind): ahead again, to what the robot goes to.
  belief_.X_MB = {0.0, 4.0, M_PI / 2};
  const auto passed = Update(look->pan);
  ASSERT_TRUE(passed.has_value());
  EXPECT_DOUBLE_EQ(passed->pan, 0.0);
  EXPECT_EQ(gaze_.reason(), GazeReason::kAhead);
  Update(0.0);
  belief_.X_MB = {1.15, 2.4, M_PI / 2};
  ASSERT_TRUE(Update(0.0).has_value());
  // Out of range: ahead again.
  belief_.X_MB = {1.15, -1.0, M_PI / 2};
  const auto away = Update(look->pan);
  ASSERT_TRUE(away.has_value());
  EXPECT_DOUBLE_EQ(away->pan, 0.0);
}

TEST_F(HeadGazeTest, GlancesAtSomeoneComingFromBehindThenLooksBackAndNotAgainAtOnce) {
  belief_.world.doors = {LabDoor(0.5)};
  // Walking up from the left, towards the robot, outside the camera's view.
  belief_.world.people = {Walker(7, {-0.8, 2.2}, {1.0, 0.0})};
  const auto glance = Update(0.0);
  ASSERT_TRUE(glance.has_value());
  EXPECT_EQ(gaze_.reason(), GazeReason::kPerson);
  const double bearing = std::atan2(2.2 - 2.4, -0.8 - 1.15) - M_PI / 2;
  EXPECT_NEAR(glance->pan, std::remainder(bearing, 2 * M_PI), 1e-9);
  // Held for glance_time while the person is tracked, following them.
  belief_.now = At(1.5);
  belief_.world.people = {Walker(7, {-0.3, 2.2}, {1.0, 0.0})};
  Update(glance->pan);
  EXPECT_EQ(gaze_.reason(), GazeReason::kPerson);
  // Then back through the door; and not straight back at them (the cooldown).
  belief_.now = At(2.1);
  const auto back = Update(glance->pan);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(gaze_.reason(), GazeReason::kDoor);
  belief_.now = At(2.2);
  Update(back->pan);
  EXPECT_EQ(gaze_.reason(), GazeReason::kDoor);
}

TEST_F(HeadGazeTest, NoGlanceAtSomeoneInViewStandingOrWalkingAway) {
  belief_.world.people = {Walker(1, {1.15, 4.0}, {0.0, -1.0})};  // ahead, in view
  Update(0.0);
  EXPECT_EQ(gaze_.reason(), GazeReason::kAhead);
  belief_.world.people = {Walker(2, {1.15, 0.5}, {0.0, 0.0})};  // behind, standing
  Update(0.0);
  EXPECT_EQ(gaze_.reason(), GazeReason::kAhead);
  belief_.world.people = {Walker(3, {1.15, 0.5}, {0.0, -1.0})};  // behind, walking away
  Update(0.0);
  EXPECT_EQ(gaze_.reason(), GazeReason::kAhead);
}

TEST_F(HeadGazeTest, LooksAtATasksTargetWithPanAndTiltWhileTheRequestLasts) {
  belief_.X_MC = Pose3(Eigen::Vector3d(1.15, 2.4, 1.0));
  // A payload 1 m ahead, half a metre below the camera; the door open beside: the task wins.
  belief_.world.doors = {LabDoor(1.0)};
  gaze_.RequestLook({1.15, 3.4, 0.5}, At(1.5));
  auto look = Update(0.0);
  ASSERT_TRUE(look.has_value());
  EXPECT_EQ(gaze_.reason(), GazeReason::kTask);
  EXPECT_NEAR(look->pan, 0.0, 1e-9);
  EXPECT_NEAR(look->tilt, std::atan2(-0.5, 1.0), 1e-9);
  // Renewed at a point to the left at the camera's height: pan only.
  belief_.now = At(1.2);
  gaze_.RequestLook({0.15, 2.4, 1.0}, At(1.7));
  look = Update(0.0);
  ASSERT_TRUE(look.has_value());
  EXPECT_NEAR(look->pan, M_PI / 2, 1e-9);
  EXPECT_NEAR(look->tilt, 0.0, 1e-9);
  // Nearly straight below: the tilt stops at its limit.
  gaze_.RequestLook({1.2, 2.4, 0.0}, At(1.7));
  look = Update(0.0);
  ASSERT_TRUE(look.has_value());
  EXPECT_NEAR(look->tilt, -gaze_.config().max_tilt_down_deg * M_PI / 180.0, 1e-9);
  // The request lapsed: back to the door, level.
  belief_.now = At(1.8);
  look = Update(0.0);
  ASSERT_TRUE(look.has_value());
  EXPECT_EQ(gaze_.reason(), GazeReason::kDoor);
  EXPECT_DOUBLE_EQ(look->tilt, 0.0);
  EXPECT_THROW(gaze_.RequestLook({NAN, 0.0, 0.0}, At(2.0)), InvalidArgument);
}

TEST_F(HeadGazeTest, SomeoneComingOutranksTheTasksTarget) {
  belief_.X_MC = Pose3(Eigen::Vector3d(1.15, 2.4, 1.0));
  gaze_.RequestLook({1.15, 3.4, 0.5}, At(2.0));
  belief_.world.people = {Walker(7, {1.15, 0.4}, {0.0, 1.2})};  // behind, coming
  const auto look = Update(0.0);
  ASSERT_TRUE(look.has_value());
  EXPECT_EQ(gaze_.reason(), GazeReason::kPerson);
  EXPECT_DOUBLE_EQ(look->tilt, 0.0);
}

TEST_F(HeadGazeTest, PanStaysWithinItsLimit) {
  HeadGazeConfig config;
  config.min_pan_deg = -90.0;
  config.max_pan_deg = 90.0;
  config.blind_look_pan_deg = -90.0;  // within the range, or refused
  HeadGaze gaze(config);
  belief_.world.people = {Walker(4, {1.15, 0.9}, {0.0, 1.0})};  // straight behind
  const auto look = gaze.Update(belief_, 0.0);
  ASSERT_TRUE(look.has_value());
  EXPECT_NEAR(std::abs(look->pan), M_PI / 2, 1e-9);
}

// The HSR's head turns right round past straight behind (-220 deg) but only 100 deg to the
// left: someone behind and to the left is looked at the long way, to the right.
TEST_F(HeadGazeTest, PanGoesTheWayRoundTheJointAllows) {
  // Behind-left of the robot (facing +y): bearing +150 deg, coming at it.
  const double bearing = 150.0 * M_PI / 180.0;
  const Eigen::Vector2d p(1.15 + 2.0 * std::cos(M_PI / 2 + bearing),
                          2.4 + 2.0 * std::sin(M_PI / 2 + bearing));
  belief_.world.people = {Walker(5, p, (belief_.X_MB.translation() - p).normalized())};
  const auto look = Update(0.0);
  ASSERT_TRUE(look.has_value());
  EXPECT_EQ(gaze_.reason(), GazeReason::kPerson);
  EXPECT_NEAR(look->pan, bearing - 2 * M_PI, 1e-9);  // -210 deg
}

// A laser scan of 270 deg (the HSR's), every beam returning at `range`, but those within
// `ahead_deg` of straight ahead, which return at `ahead_range`.
LaserScan Scan(double range, double ahead_range, double ahead_deg) {
  LaserScan scan;
  scan.angle_min = -135.0 * M_PI / 180.0;
  scan.angle_increment = M_PI / 720.0;
  scan.range_min = 0.05;
  scan.range_max = 20.0;
  for (int i = 0; i <= 1080; ++i) {
    const double a = scan.AngleAt(std::size_t(i));
    scan.ranges.push_back(float(std::abs(a) <= ahead_deg * M_PI / 180.0 ? ahead_range : range));
  }
  return scan;
}

TEST_F(HeadGazeTest, LooksBehindAtAnActuatorWithOnlyAWallToSeeAhead) {
  belief_.scan = Scan(4.0, 0.4, 40.0);  // facing the wall at the button, 0.4 m off
  // Not on its own (at a table the look ahead finds the payload): a task at an actuator asks.
  Update(0.0);
  EXPECT_EQ(gaze_.reason(), GazeReason::kAhead);
  gaze_.WatchBehind(At(10.0));
  const auto behind = Update(0.0);
  ASSERT_TRUE(behind.has_value());
  EXPECT_EQ(gaze_.reason(), GazeReason::kBehind);
  EXPECT_NEAR(behind->pan, -M_PI, 1e-9);
  // Part of the camera's view open (a return beyond wall_ahead_range): ahead again.
  belief_.scan = Scan(4.0, 0.4, 20.0);
  const auto ahead = Update(behind->pan);
  ASSERT_TRUE(ahead.has_value());
  EXPECT_EQ(gaze_.reason(), GazeReason::kAhead);
  // Nothing returned ahead (open space) is no wall either.
  belief_.scan = Scan(4.0, std::numeric_limits<float>::infinity(), 40.0);
  Update(0.0);
  EXPECT_EQ(gaze_.reason(), GazeReason::kAhead);
  // A door opening beside the robot outranks the look behind.
  belief_.scan = Scan(4.0, 0.4, 40.0);
  belief_.world.doors = {LabDoor(0.3)};
  Update(0.0);
  EXPECT_EQ(gaze_.reason(), GazeReason::kDoor);
  // The task's word lapses: ahead.
  belief_.world.doors.clear();
  belief_.now = At(10.1);
  Update(0.0);
  EXPECT_EQ(gaze_.reason(), GazeReason::kAhead);
}

TEST_F(HeadGazeTest, KeepsLookingAtSomeoneComingInTheLasersBlindSector) {
  belief_.scan = Scan(4.0, 4.0, 0.0);
  belief_.world.doors = {LabDoor(0.5)};
  // Straight behind the robot, 3 m off, coming at 0.4 m/s: outside the laser's 270 deg.
  const auto walker_at = [](double t) {
    return Walker(9, {1.15, -0.6 + 0.4 * (t - 1.0)}, {0.0, 0.4});
  };
  belief_.world.people = {walker_at(1.0)};
  Update(0.0);
  EXPECT_EQ(gaze_.reason(), GazeReason::kPerson);
  // Past glance_time (1 s) the glance goes on while they are there and coming, though the
  // camera has them in view (it alone measures them there), up to max_blind_glance (4 s) ...
  for (double t = 1.1; t < 4.95; t += 0.1) {
    belief_.now = At(t);
    belief_.world.people = {walker_at(t)};
    Update(-M_PI);
    ASSERT_EQ(gaze_.reason(), GazeReason::kPerson) << "at " << t << " s";
  }
  // ... then through the door, and not back at them for glance_cooldown.
  for (double t = 5.2; t < 7.9; t += 0.1) {
    belief_.now = At(t);
    belief_.world.people = {walker_at(t)};
    Update(0.0);
    ASSERT_EQ(gaze_.reason(), GazeReason::kDoor) << "at " << t << " s";
  }
  // Someone in the laser's view is glanced at for glance_time only.
  HeadGaze gaze;
  belief_.now = At(10.0);
  belief_.world.people = {Walker(3, {-0.8, 2.2}, {1.0, 0.0})};  // to the left, coming
  gaze.Update(belief_, 0.0);
  EXPECT_EQ(gaze.reason(), GazeReason::kPerson);
  belief_.now = At(10.5);
  gaze.Update(belief_, 0.0);
  EXPECT_EQ(gaze.reason(), GazeReason::kPerson);
  belief_.now = At(11.1);
  gaze.Update(belief_, 0.0);
  EXPECT_EQ(gaze.reason(), GazeReason::kDoor);
}

TEST_F(HeadGazeTest, ADoorBeingOperatedIsLookedThroughUnlessSomeoneIsBehind) {
  belief_.scan = Scan(4.0, 0.4, 40.0);
  belief_.world.doors = {LabDoor(0.0)};  // shut
  gaze_.WatchBehind(At(10.0));
  Update(0.0);
  EXPECT_EQ(gaze_.reason(), GazeReason::kBehind);
  gaze_.ExpectOpening("lab_door", At(1.5));
  Update(-M_PI);
  EXPECT_EQ(gaze_.reason(), GazeReason::kDoor);
  // Someone standing in the laser's blind sector: the head stays behind until the door opens.
  belief_.world.people = {Walker(2, {1.6, 0.6}, {0.0, 0.0})};
  Update(-M_PI);
  EXPECT_EQ(gaze_.reason(), GazeReason::kBehind);
  belief_.world.people.clear();
  Update(-M_PI);
  EXPECT_EQ(gaze_.reason(), GazeReason::kDoor);
  // The expectation lapses.
  belief_.now = At(1.6);
  Update(0.0);
  EXPECT_EQ(gaze_.reason(), GazeReason::kBehind);
}

// Given the door at whose actuator it stands, the look behind goes towards where people walk up
// to that door from (approach_look_range out from its centre on the robot's side), kept within
// the laser's blind sector; at anyone tracked there first, and while they are there, the door
// opening beside the robot does not take the head from them (P4 seed 2073).
TEST_F(HeadGazeTest, BehindAnActuatorItWatchesTheDoorsApproachAndWhoeverStandsThere) {
  const auto pan_of = [&](const Eigen::Vector2d& p_M) {
    const Eigen::Vector2d d = p_M - belief_.X_MB.translation();
    return std::atan2(d.y(), d.x()) - belief_.X_MB.yaw;
  };
  const auto same_angle = [](double a, double b) {
    return std::abs(std::remainder(a - b, 2 * M_PI)) < 1e-9;
  };
  belief_.scan = Scan(4.0, 0.4, 40.0);  // facing the wall at the button
  belief_.world.doors = {LabDoor(0.0)};
  gaze_.WatchBehind(At(10.0), "lab_door");
  auto look = Update(0.0);
  ASSERT_TRUE(look.has_value());
  EXPECT_EQ(gaze_.reason(), GazeReason::kBehind);
  // (0, 0), 3 m out from the doorway's centre (0, 3): behind the robot, to its left, the way
  // round the joint allows (the pan reaches -220 deg, not +154).
  EXPECT_TRUE(same_angle(look->pan, pan_of({0.0, 0.0}))) << look->pan;
  EXPECT_LT(look->pan, -M_PI);
  // Turned so that the laser sees that point: the blind sector's nearer edge (-135 deg).
  belief_.X_MB.yaw = 0.17;
  look = Update(look->pan);
  ASSERT_TRUE(look.has_value());
  EXPECT_NEAR(look->pan, -135.0 * M_PI / 180.0, 1e-9);
  belief_.X_MB.yaw = M_PI / 2;
  // No such door in the belief: straight behind.
  gaze_.WatchBehind(At(10.0), "no_such_door");
  look = Update(0.0);
  ASSERT_TRUE(look.has_value());
  EXPECT_NEAR(look->pan, -M_PI, 1e-9);
  // Someone standing in the blind sector, and the door opening: the head stays on them ...
  gaze_.WatchBehind(At(10.0), "lab_door");
  belief_.world.doors = {LabDoor(0.3)};
  belief_.world.people = {Walker(4, {2.0, 0.5}, {0.0, 0.0})};
  look = Update(0.0);
  ASSERT_TRUE(look.has_value());
  EXPECT_EQ(gaze_.reason(), GazeReason::kBehind);
  EXPECT_TRUE(same_angle(look->pan, pan_of({2.0, 0.5}))) << look->pan;
  // ... while the task watches behind; then through the door.
  belief_.now = At(10.1);
  Update(look->pan);
  EXPECT_EQ(gaze_.reason(), GazeReason::kDoor);
}

TEST_F(HeadGazeTest, DisabledSendsNothingAndBadConfigsAreRefused) {
  HeadGazeConfig config;
  config.enabled = false;
  HeadGaze off(config);
  EXPECT_FALSE(off.Update(belief_, 0.0).has_value());
  for (auto bad : {&HeadGazeConfig::camera_hfov_deg, &HeadGazeConfig::glance_range,
                   &HeadGazeConfig::door_open_fraction, &HeadGazeConfig::max_pan_deg,
                   &HeadGazeConfig::max_tilt_down_deg, &HeadGazeConfig::max_tilt_up_deg}) {
    HeadGazeConfig c;
    c.*bad = -1.0;
    EXPECT_THROW(HeadGaze{c}, InvalidArgument);
  }
  HeadGazeConfig c;
  c.min_pan_deg = 10.0;  // the range must hold straight ahead
  EXPECT_THROW(HeadGaze{c}, InvalidArgument);
  c = {};
  c.blind_look_pan_deg = -230.0;  // past the joint's range
  EXPECT_THROW(HeadGaze{c}, InvalidArgument);
  c = {};
  c.wall_ahead_range = -1.0;
  EXPECT_THROW(HeadGaze{c}, InvalidArgument);
  c = {};
  c.approach_look_range = -1.0;
  EXPECT_THROW(HeadGaze{c}, InvalidArgument);
}

}  // namespace
}  // namespace egress::behavior
