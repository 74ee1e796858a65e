#include "egress/twin/twin_world.h"

#include <algorithm>
#include <fstream>
#include <functional>
#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "../test_paths.h"
#include "egress/hsr_interface/error.h"
#include "egress/planning/ik_solver.h"
#include "egress/twin/trace.h"
#include "twin_test_util.h"

namespace egress::twin {
namespace {

using testing::CountEvents;
using testing::Hsr;
using testing::LoadText;
using testing::WorldsDir;

constexpr double kDeg = M_PI / 180.0;

std::optional<double> FirstEvent(const TwinWorld& w, const std::string& kind) {
  for (const auto& e : w.events()) {
    if (e.kind == kind) return e.t;
  }
  return std::nullopt;
}

// An arm trajectory through the given whole-body configurations (arm joints only).
JointTrajectory ArmThrough(const std::vector<std::pair<double, WholeBodyVector>>& knots) {
  JointTrajectory traj;
  traj.joint_names = {"arm_lift_joint", "arm_flex_joint", "arm_roll_joint", "wrist_flex_joint",
                      "wrist_roll_joint"};
  for (const auto& [t, q] : knots) {
    JointTrajectoryPoint p;
    p.positions = {q[kArmLift], q[kArmFlex], q[kArmRoll], q[kWristFlex], q[kWristRoll]};
    p.time_from_start = SecondsToDuration(t);
    traj.points.push_back(p);
  }
  return traj;
}

std::string LabScenario(const Pose2& start, const std::string& extra = "") {
  return "world: lab.sdf\nrobot:\n  start: {x: " + std::to_string(start.x) +
         ", y: " + std::to_string(start.y) + ", yaw: " + std::to_string(start.yaw) + "}\n" + extra;
}

TEST(TwinWorldTest, ThePressedButtonOpensTheDoorWithAdaTiming) {
  // Stand off the lab button (face at y = 2.93, 1.0 m high), press it with the fingertip.
  const Eigen::Vector3d p_button(1.075, 2.93, 1.0);
  const auto targets =
      planning::MakeButtonTargets(p_button, {0, -1, 0}, planning::ButtonType::kPushButton);
  // Whole-body IK for the pre-press pose from the tucked arm at the standoff; the robot starts
  // at the base pose it found; the press itself moves the arm only.
  planning::IkConfig ik;
  ik.fingertip = true;
  WholeBodyVector q0;
  q0 << targets.X_MB_standoff.x, targets.X_MB_standoff.y, targets.X_MB_standoff.yaw, 0.0, 0.0,
      -M_PI / 2, -M_PI / 2, 0.0;
  const auto approach = planning::DlsIkSolver(*Hsr(), ik).Solve(targets.approach, q0);
  ASSERT_TRUE(approach.converged);
  ik.use_base = false;
  planning::IkTarget press_target = targets.press;
  press_target.approach_M.reset();  // the arm alone cannot also hold the approach axis exactly
  const auto press = planning::DlsIkSolver(*Hsr(), ik).Solve(press_target, approach.q);
  ASSERT_TRUE(press.converged) << press.position_error << " " << press.orientation_error << " "
                               << press.iterations;
  const Pose2 start{approach.q[kBaseX], approach.q[kBaseY], approach.q[kBaseYaw]};
  auto loaded = LoadText(
      LabScenario(start, "doors:\n  - {door: lab_door, operator: push, actuator: lab_button}\n"),
      WorldsDir() / "lab");
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  world.SetArmTrajectory(ArmThrough({{2.0, approach.q}, {3.0, press.q}, {4.0, approach.q}}));
  world.StepFor(5.0);
  ASSERT_EQ(CountEvents(world, "button_pressed", "lab_door"), 1);
  EXPECT_EQ(world.button_presses(0), 1);
  const double pressed_at = *FirstEvent(world, "button_pressed");
  EXPECT_GT(pressed_at, 2.0);
  EXPECT_LT(pressed_at, 3.1);
  // Opening to 80° takes about 3.5 s through the hinge motor.
  world.StepFor(pressed_at + 2.0 - world.time());
  EXPECT_LT(world.door_angle(0), 70 * kDeg);
  EXPECT_GT(world.door_angle(0), 20 * kDeg);
  world.StepFor(pressed_at + 5.0 - world.time());
  EXPECT_NEAR(world.door_angle(0), 80 * kDeg, 4 * kDeg);
  EXPECT_EQ(world.door_phase(0), DoorPhase::kHeldOpen);
  // Held for the 10 s window, then closed again within ~5 s.
  world.StepFor(pressed_at + 12.0 - world.time());
  EXPECT_EQ(world.door_phase(0), DoorPhase::kHeldOpen);
  world.StepFor(pressed_at + 20.0 - world.time());
  EXPECT_LT(world.door_angle(0), 2 * kDeg);
  EXPECT_EQ(world.door_phase(0), DoorPhase::kClosed);
  EXPECT_EQ(CountEvents(world, "contact"), 0);
}

TEST(TwinWorldTest, ABlockedLeafStopsAgainstTheRobot) {
  // The robot stands in the leaf's sweep on the far side; the door is operated at t = 0.5 s.
  auto loaded = LoadText(
      LabScenario(
          {0.0, 3.55, 0.0},
          "doors:\n  - {door: lab_door, operator: push, actuator: lab_button, open_at: [0.5]}\n"),
      WorldsDir() / "lab");
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  world.StepFor(6.0);
  EXPECT_GT(world.door_angle(0), 5 * kDeg);
  EXPECT_LT(world.door_angle(0), 60 * kDeg);
  EXPECT_GE(CountEvents(world, "contact", "lab_door"), 1);
  EXPECT_LT((world.robot_pose().translation() - Eigen::Vector2d(0.0, 3.55)).norm(), 0.1);
}

// A door on its own, its model turned `yaw` [rad] about its hinge, opening counter-clockwise,
// and its button 0.4 m behind the hinge.
std::string LoneDoorSdf(double yaw) {
  return R"(<?xml version="1.0" ?>
<sdf version="1.7"><world name="lone_door">
  <model name="door">
    <pose>0 0 1 0 0 )" +
         std::to_string(yaw) + R"(</pose>
    <link name="frame"/>
    <link name="leaf">
      <inertial><mass>40.0</mass><inertia><ixx>13.4</ixx><iyy>13.4</iyy><izz>12.0</izz></inertia></inertial>
      <collision name="c"><pose>0 0.5 0 0 0 0</pose><geometry><box><size>0.04 1.0 2.0</size></box></geometry></collision>
    </link>
    <joint name="hinge" type="revolute"><parent>frame</parent><child>leaf</child>
      <axis><xyz>0 0 1</xyz><limit><lower>0.0</lower><upper>1.57</upper></limit></axis></joint>
    <joint name="fixed_to_world" type="fixed"><parent>world</parent><child>frame</child></joint>
  </model>
  <model name="door_button"><static>true</static>
    <pose>)" +
         std::to_string(0.4 * std::sin(yaw)) + " " + std::to_string(-0.4 * std::cos(yaw)) +
         " 1 0 0 " + std::to_string(yaw) + R"(</pose>
    <link name="link"><collision name="c"><geometry><box><size>0.02 0.1 0.1</size></box></geometry></collision></link>
  </model>
</world></sdf>
)";
}

TEST(TwinWorldTest, ADoorOpensWhicheverWayItFaces) {
  // Bullet reads a hinge's angle in [-pi, pi]: a leaf whose closed angle lies near pi (a door
  // turned ~176 degrees, as in a building turned 86 degrees) opened the wrong way, into its
  // stop, and never opened. Every heading, those next to pi among them, opens to the operator's
  // angle.
  const auto dir = egress::testing::TestTempPath("lone_door");
  std::filesystem::create_directories(dir);
  for (const double yaw : {0.0, 1.0, 2.0, 3.0, 3.076, M_PI, 3.2, 4.0, -3.05, -1.5}) {
    SCOPED_TRACE(yaw);
    std::ofstream(dir / "door.sdf") << LoneDoorSdf(yaw);
    auto loaded = LoadText(
        "world: door.sdf\nrobot: {start: {x: 3.0, y: 3.0}}\n"
        "doors:\n  - {door: door, operator: push, open_at: [0.2], hold_open_s: 100}\n",
        dir);
    TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
    world.StepFor(6.0);
    EXPECT_NEAR(world.door_angle(0), 80 * kDeg, 4 * kDeg);
    EXPECT_EQ(world.door_phase(0), DoorPhase::kHeldOpen);
  }
  std::filesystem::remove_all(dir);
}

// The robot's body is its description's shapes: above the base it is a slim column (torso and
// head behind the base's centre, the tucked arm ahead of it), not the base's circle extruded.
// Each shelf reaches 0.12 m over the front of the footprint (edge 0.10 m ahead of B's origin).
std::vector<std::string> ContactsUnderAShelfAt(double z_centre) {
  const std::string shelf =
      "obstacles: [{name: shelf, box: [0.6, 0.8, 0.05], x: -1.8, y: 0.8, z: " +
      std::to_string(z_centre) + "}]\n";
  auto loaded = LoadText(LabScenario({-2.2, 0.8, 0.0}, shelf), WorldsDir() / "lab");
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  world.StepFor(0.5);
  std::vector<std::string> parts;
  for (const auto& e : world.events()) {
    if (e.kind == "contact" && e.subject == "shelf") parts.push_back(e.detail);
  }
  return parts;
}

TEST(TwinWorldTest, AShelfOverTheBaseAboveTheArmTouchesNothing) {
  // 0.90-0.95 m: above the tucked forearm (to 0.83 m), ahead of the head.
  EXPECT_THAT(ContactsUnderAShelfAt(0.925), ::testing::IsEmpty());
}

TEST(TwinWorldTest, AShelfOverTheBaseAtTheArmsHeightTouchesTheArm) {
  // 0.72-0.77 m: the tucked forearm stands there, ahead of B's origin.
  EXPECT_THAT(ContactsUnderAShelfAt(0.745),
              ::testing::Contains(::testing::HasSubstr("hsrb_forearm")));
}

// The forearm runs from the arm roll link to the wrist flex link, which coincide in the shipped
// model: a ball at the wrist (0.64-0.73 m tucked), not an upright capsule to 0.54 m below it
// whatever the arm's pose (which touched what a level reach passed over).
TEST(TwinWorldTest, AShelfJustUnderTheTuckedWristTouchesTheUpperArmOnly) {
  const std::vector<std::string> parts = ContactsUnderAShelfAt(0.585);  // 0.56-0.61 m
  EXPECT_THAT(parts, ::testing::Contains(::testing::HasSubstr("hsrb_upper_arm")));
  EXPECT_THAT(parts, ::testing::Not(::testing::Contains(::testing::HasSubstr("hsrb_forearm"))));
}

TEST(TwinWorldTest, AShelfOverTheBaseAtBaseHeightTouchesTheBase) {
  // 0.20-0.25 m: the base's own top (0.01-0.25 m) is the footprint's full circle.
  EXPECT_THAT(ContactsUnderAShelfAt(0.225), ::testing::Contains(::testing::HasSubstr("by hsrb")));
}

TEST(TwinWorldTest, APersonHoldsTheDoorOpenThenItCloses) {
  const Scenario s = LoadScenario(WorldsDir() / "lab/lab_hold_door.yaml");
  TwinWorld world(s, LoadSdfWorld(s.world_file), 1, Hsr());
  world.StepFor(9.0);
  ASSERT_EQ(CountEvents(world, "person_holding_door"), 1);
  EXPECT_NEAR(world.door_angle(0), 75 * kDeg, 8 * kDeg);
  EXPECT_EQ(world.button_presses(0), 0);
  const double released = *FirstEvent(world, "person_holding_door") + 12.0;
  world.StepFor(released + 8.0 - world.time());
  EXPECT_EQ(CountEvents(world, "person_released_door"), 1);
  EXPECT_LT(world.door_angle(0), 5 * kDeg);
}

TEST(TwinWorldTest, APersonReachesAHoldSpotInACornerAndAWalkerStepsAsideOnArrival) {
  // The clinic's door_e: its hinge 0.5 m from the corridor's side wall, so the spot beside the
  // hinge is against that wall; the holder comes from 3 m away and still holds it.
  const auto loaded = LoadText(
      "world: clinic.sdf\nrobot: {start: {x: 1.2, y: 1.0}}\npeople:\n"
      "  - {name: holder, behavior: hold_door, door: door_e, start: [21.2, 6.0],"
      " goal: [21.2, 6.0], hold_angle_deg: 75, hold_duration: 20}\n"
      "  - {name: walker, behavior: walk_past, start: [3.0, 1.0], goal: [6.0, 1.0]}\n",
      WorldsDir() / "clinic");
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  world.StepFor(12.0);
  EXPECT_EQ(CountEvents(world, "person_holding_door"), 1);
  EXPECT_GT(world.door_angle(4), 60 * kDeg);
  // The walker arrived in the corridor's middle (y = 1) and then stands by a wall (the social
  // forces of the walls settle it 0.6 m from the nearer), leaving the middle to the robot.
  const auto& walker = world.people()[1];
  EXPECT_GT(std::abs(walker.position.y() - 1.0), 0.35) << walker.position.y();
}

TEST(TwinWorldTest, TheHoldAngleIsRandomizedBySeedWithinItsRange) {
  std::ifstream in(WorldsDir() / "lab/lab_hold_door.yaml");
  std::string yaml((std::istreambuf_iterator<char>(in)), {});
  yaml += "randomize:\n  hold_angle_deg: [30, 60]\n";
  const auto loaded = LoadText(yaml, WorldsDir() / "lab");
  std::vector<double> held;
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    TwinWorld world(loaded.scenario, loaded.world, seed, Hsr());
    world.StepFor(9.0);
    ASSERT_EQ(CountEvents(world, "person_holding_door"), 1) << "seed " << seed;
    held.push_back(world.door_angle(0));
    EXPECT_GE(held.back(), 28 * kDeg) << "seed " << seed;
    EXPECT_LE(held.back(), 62 * kDeg) << "seed " << seed;
    // The same seed holds it at the same angle.
    TwinWorld again(loaded.scenario, loaded.world, seed, Hsr());
    again.StepFor(9.0);
    EXPECT_DOUBLE_EQ(again.door_angle(0), held.back());
  }
  EXPECT_GT(
      *std::max_element(held.begin(), held.end()) - *std::min_element(held.begin(), held.end()),
      2 * kDeg);
}

TEST(TwinWorldTest, PeopleCrossAnOpenDoorBothWaysWithoutOverlap) {
  const std::string yaml = R"(world: office.sdf
robot: {start: {x: 1.0, y: 5.0}}
doors: [{door: door_a, operator: push, actuator: door_a_button, open_at: [0.0], hold_open_s: 30}]
people:
  - {name: east, behavior: cross_doorway, door: door_a, start: [3.0, 3.2], goal: [7.5, 2.5], speed: 1.3, trigger: {event: "door_opened:door_a"}}
  - {name: west, behavior: cross_doorway, door: door_a, start: [7.0, 2.8], goal: [3.0, 3.5], speed: 1.2, trigger: {event: "door_opened:door_a"}}
)";
  auto loaded = LoadText(yaml, WorldsDir() / "office");
  TwinWorld world(loaded.scenario, loaded.world, 3, Hsr());
  double min_gap = 1e9;
  while (world.time() < 20.0) {
    world.Step();
    const auto& p = world.people();
    min_gap = std::min(min_gap, (p[0].position - p[1].position).norm() - p[0].radius - p[1].radius);
  }
  EXPECT_GT(min_gap, 0.0);
  EXPECT_LT((world.people()[0].position - Eigen::Vector2d(7.5, 2.5)).norm(), 0.5);
  EXPECT_LT((world.people()[1].position - Eigen::Vector2d(3.0, 3.5)).norm(), 0.5);
  EXPECT_EQ(world.people()[0].phase, PersonPhase::kDone);
}

TEST(TwinWorldTest, PeopleWaitAtAClosedDoor) {
  const std::string yaml = R"(world: office.sdf
robot: {start: {x: 1.0, y: 5.0}}
doors: [{door: door_a, operator: push, actuator: door_a_button, open_at: [6.0]}]
people:
  - {name: p, behavior: cross_doorway, door: door_a, start: [3.0, 3.0], goal: [7.5, 3.0], speed: 1.3}
)";
  auto loaded = LoadText(yaml, WorldsDir() / "office");
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  world.StepFor(5.0);
  EXPECT_EQ(world.people()[0].phase, PersonPhase::kWaitingForDoor);
  EXPECT_LT(world.people()[0].position.x(), 4.95 - 0.25);
  world.StepFor(10.0);
  EXPECT_GT(world.people()[0].position.x(), 7.0);
}

TEST(TwinWorldTest, AWalkerBlockedByAnOpenLeafStepsRoundItsFreeEdge) {
  // S6's passer: along the far side of the lab door, across the sweep of its leaf held open at
  // 80 deg (the leaf is a wall to the social forces). Without stepping round, the walker stood
  // against the leaf in the doorway's zone for good.
  const std::string yaml = R"(world: lab.sdf
robot: {start: {x: 0.0, y: 1.0}}
doors: [{door: lab_door, operator: push, actuator: lab_button, open_at: [0.0], hold_open_s: 60}]
people:
  - {name: passer, behavior: walk_past, start: [-2.6, 3.9], via: [[-1.0, 3.6]], goal: [2.6, 3.6], speed: 1.2, trigger: {event: "door_opened:lab_door"}}
)";
  auto loaded = LoadText(yaml, WorldsDir() / "lab");
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  world.StepFor(25.0);
  EXPECT_GT(world.door_angle(0), 70 * kDeg);  // still held open: the leaf was in the way
  EXPECT_EQ(CountEvents(world, "person_steps_round_leaf", "passer"), 1);
  EXPECT_LT((world.people()[0].position - Eigen::Vector2d(2.6, 3.6)).norm(), 0.5);
}

// The first time an event of this kind and subject fired, or -1.
double FirstEventTime(const TwinWorld& w, const std::string& kind, const std::string& subject) {
  for (const auto& e : w.events())
    if (e.kind == kind && e.subject == subject) return e.t;
  return -1.0;
}

TEST(TwinWorldTest, APersonStartsTheRandomizedDelayAfterTheirTriggerWhateverItsKind) {
  // person_delay_s was added to time triggers only: a person waiting for an event or for the
  // robot to come near started at once, and the scenarios' delays did nothing.
  const std::string yaml = R"(world: lab.sdf
robot: {start: {x: 0.0, y: 1.0}}
doors: [{door: lab_door, operator: push, actuator: lab_button, open_at: [0.5]}]
people:
  - {name: on_event, behavior: walk_past, start: [-2.6, 3.9], goal: [2.6, 3.9], trigger: {event: "door_opened:lab_door"}}
  - {name: on_robot, behavior: walk_past, start: [-2.0, 0.0], goal: [2.0, 0.0], trigger: {robot_within: 3.0}}
  - {name: at_time, behavior: walk_past, start: [-2.0, 6.0], goal: [2.0, 6.0], trigger: {at: 1.0}}
randomize:
  person_delay_s: [1.5, 1.5]
)";
  auto loaded = LoadText(yaml, WorldsDir() / "lab");
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  world.StepFor(12.0);
  const double opened = FirstEventTime(world, "door_opened", "lab_door");
  ASSERT_GT(opened, 0.5);
  const double step = 1.0 / 240.0 + 1e-9;
  EXPECT_NEAR(FirstEventTime(world, "person_started", "on_event"), opened + 1.5, step);
  EXPECT_NEAR(FirstEventTime(world, "person_started", "on_robot"), 1.5, step);
  EXPECT_NEAR(FirstEventTime(world, "person_started", "at_time"), 2.5, step);
}

class GraspTest : public ::testing::Test {
 protected:
  // A bottle on the office table; the robot reaches it from the table's north side.
  std::unique_ptr<TwinWorld> MakeWorld(double reach_offset, const std::string& extra = "") {
    const Eigen::Vector3d p_bottle(2.3, 1.35, 0.856);
    planning::IkConfig ik;
    ik.use_base = true;
    const planning::DlsIkSolver solver(*Hsr(), ik);
    WholeBodyVector q0 = WholeBodyVector::Zero();
    q0 << 2.3, 2.05, -M_PI / 2, 0.2, -1.0, 0.0, -0.5, 0.0;
    // Palm approach axis horizontal towards −y; the grasp centre is 7 cm ahead of the palm.
    const Eigen::Vector3d approach(0, -1, 0);
    const Eigen::Vector3d grasp_centre = p_bottle - approach * reach_offset;  // > 0: short of it
    planning::IkTarget target{grasp_centre - approach * 0.07, approach};
    const auto solution = solver.Solve(target, q0);
    EXPECT_TRUE(solution.converged);
    planning::IkTarget pre{target.p_MT - approach * 0.12, approach};
    planning::IkConfig arm_only = ik;
    arm_only.use_base = false;
    const planning::DlsIkSolver arm_solver(*Hsr(), arm_only);
    pre_ = arm_solver.Solve(pre, solution.q).q;
    grasp_ = solution.q;
    const std::string yaml =
        "world: office.sdf\nrobot: {start: {x: " + std::to_string(solution.q[kBaseX]) +
        ", y: " + std::to_string(solution.q[kBaseY]) +
        ", yaw: " + std::to_string(solution.q[kBaseYaw]) +
        "}}\npayloads: [{name: bottle, kind: water_bottle, x: 2.3, y: 1.35, z: 0.856}]\n" + extra;
    auto loaded = LoadText(yaml, WorldsDir() / "office");
    return std::make_unique<TwinWorld>(loaded.scenario, loaded.world, 1, Hsr());
  }
  void ReachAndClose(TwinWorld* world) {
    world->SetArmTrajectory(ArmThrough({{2.0, pre_}, {3.5, grasp_}}));
    world->StepFor(4.0);
    GripperCommand close;
    close.mode = GripperCommand::Mode::kGrasp;
    close.effort = 10.0;
    world->SetGripperCommand(close);
    world->StepFor(2.0);
  }
  WholeBodyVector pre_, grasp_;
};

TEST_F(GraspTest, InsideToleranceTheBottleIsHeldAndLiftedAndReleasedOntoTheTable) {
  auto world = MakeWorld(0.0);
  ReachAndClose(world.get());
  ASSERT_EQ(world->held_payload(), "bottle");
  EXPECT_EQ(CountEvents(*world, "grasp", "bottle"), 1);
  // Lift 10 cm: the bottle follows.
  WholeBodyVector up = grasp_;
  up[kArmLift] += 0.1;
  world->SetArmTrajectory(ArmThrough({{1.0, up}}));
  world->StepFor(1.5);
  EXPECT_NEAR(world->payload_pose("bottle").translation().z(), 0.856 + 0.1, 0.02);
  // Lower and open: released, it stays on the table.
  world->SetArmTrajectory(ArmThrough({{1.0, grasp_}}));
  world->StepFor(1.5);
  GripperCommand open;
  world->SetGripperCommand(open);
  world->StepFor(2.0);
  EXPECT_FALSE(world->held_payload().has_value());
  EXPECT_EQ(CountEvents(*world, "release", "bottle"), 1);
  EXPECT_NEAR(world->payload_pose("bottle").translation().z(), 0.856, 0.02);
}

TEST_F(GraspTest, AHeldBottleTuckedOverTheBaseDoesNotPushTheRobot) {
  auto world = MakeWorld(0.0);
  ReachAndClose(world.get());
  ASSERT_EQ(world->held_payload(), "bottle");
  const Pose2 before = world->robot_pose();
  // The HSR's "go" pose: the hand (and the bottle in it) over the base.
  WholeBodyVector tucked = grasp_;
  tucked[kArmLift] = 0.0;
  tucked[kArmFlex] = 0.0;
  tucked[kArmRoll] = -M_PI / 2;
  tucked[kWristFlex] = -M_PI / 2;
  tucked[kWristRoll] = 0.0;
  world->SetArmTrajectory(ArmThrough({{4.0, tucked}}));
  world->StepFor(6.0);
  EXPECT_EQ(world->held_payload(), "bottle");
  const Pose2 after = world->robot_pose();
  EXPECT_LT((after.translation() - before.translation()).norm(), 0.01);
  EXPECT_LT(std::abs(after.yaw - before.yaw), 0.01);
}

// An injected grasp slip (faults: grasp_slip) drops a held bottle at its time.
TEST_F(GraspTest, AGraspSlipDropsTheHeldBottle) {
  auto world = MakeWorld(0.0, "faults: [{kind: grasp_slip, start: 7.0}]\n");
  ReachAndClose(world.get());  // t = 6
  ASSERT_EQ(world->held_payload(), std::optional<std::string>("bottle"));
  world->StepFor(1.5);
  EXPECT_FALSE(world->held_payload().has_value());
  EXPECT_EQ(CountEvents(*world, "fault", "grasp_slip"), 1);
}

TEST_F(GraspTest, OutsideToleranceTheGraspFails) {
  auto world = MakeWorld(0.07);  // the fingers close 7 cm short of the bottle
  ReachAndClose(world.get());
  EXPECT_FALSE(world->held_payload().has_value());
  EXPECT_EQ(CountEvents(*world, "grasp"), 0);
  EXPECT_EQ(CountEvents(*world, "grasp_failed", "bottle"), 1);
}

TEST(TwinWorldTest, APayloadStartingInsideFurnitureIsABadScenario) {
  const std::string table =
      "obstacles: [{name: table, box: [0.6, 0.8, 0.72], x: -1.8, y: 1.2},\n"
      "            {name: books, box: [0.1, 0.24, 0.07], x: -1.55, y: 1.2, z: 0.755}]\n";
  // Clear of the books (1 cm behind them): builds, and the bottle stays upright where it is.
  auto clear = LoadText(LabScenario({0.0, 0.5, 0.0}, table + "payloads: [{name: bottle, kind: "
                                                             "water_bottle, x: -1.643, y: 1.2, z: "
                                                             "0.825}]\n"),
                        WorldsDir() / "lab");
  TwinWorld world(clear.scenario, clear.world, 1, Hsr());
  world.StepFor(0.5);
  EXPECT_NEAR(world.payload_pose("bottle").translation().x(), -1.643, 2e-3);
  EXPECT_NEAR(world.payload_pose("bottle").translation().z(), 0.825, 2e-3);
  // 2.5 cm into them: the first physics step would knock it over. A clear error instead.
  auto inside = LoadText(LabScenario({0.0, 0.5, 0.0}, table + "payloads: [{name: bottle, kind: "
                                                              "water_bottle, x: -1.608, y: 1.2, z: "
                                                              "0.825}]\n"),
                         WorldsDir() / "lab");
  try {
    TwinWorld bad(inside.scenario, inside.world, 1, Hsr());
    ADD_FAILURE() << "a payload inside the books was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("payload 'bottle'"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("inside 'books'"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("randomize.payload_xy"));
  }
}

TEST(TwinWorldTest, BaseFollowsVelocityWithAccelerationLimitAndStopsAfterTimeout) {
  auto loaded = LoadText(LabScenario({0.0, 0.0, 0.0}), WorldsDir() / "lab");
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  world.SetBaseVelocity({0.5, 0.0, 0.0});
  world.StepFor(0.25);
  EXPECT_NEAR(world.robot_velocity().vx, 0.25, 0.01);  // 1 m/s² limit
  for (int i = 0; i < 10; ++i) {
    world.SetBaseVelocity({0.5, 0.0, 0.0});
    world.StepFor(0.2);
  }
  EXPECT_NEAR(world.robot_velocity().vx, 0.5, 1e-6);
  const double x = world.robot_pose().x;
  world.StepFor(2.0);  // no new command: stops after the 0.5 s timeout
  EXPECT_NEAR(world.robot_velocity().vx, 0.0, 1e-9);
  EXPECT_LT(world.robot_pose().x - x, 0.5 * 0.5 + 0.5 * 0.5 * 0.5 + 0.02);
  // The base cannot drive through a wall: 3 m to the east wall.
  for (int i = 0; i < 80; ++i) {
    world.SetBaseVelocity({0.8, 0.0, 0.0});
    world.StepFor(0.1);
  }
  EXPECT_LT(world.robot_pose().x, 3.0 - 0.2);
  EXPECT_GE(CountEvents(world, "contact", "wall_east"), 1);
  EXPECT_THROW(world.SetBaseVelocity({std::nan(""), 0, 0}), InvalidArgument);
  JointTrajectory bad;
  bad.joint_names = {"base_x"};
  bad.points.push_back({{1.0}, {}, {}, SecondsToDuration(1.0)});
  EXPECT_THROW(world.SetArmTrajectory(bad), InvalidArgument);
}

// Drives the robot (from 4 s on, at 0.3 m/s straight ahead) in two worlds of `scenario`, one
// with people's bodies asleep far from the robot (the default), one with them always awake:
// the runs must be the same step for step. Returns the worlds' robot-person contact events.
int SameRunAsleepAndAwake(const testing::Loaded& loaded, double seconds, double* closest,
                          double speed = 0.3,
                          const std::function<void(const TwinWorld&)>& at_end = {}) {
  TwinConfig awake;
  awake.person_body_awake_reach = std::numeric_limits<double>::infinity();
  TwinWorld sleeping_world(loaded.scenario, loaded.world, 1, Hsr());
  TwinWorld awake_world(loaded.scenario, loaded.world, 1, Hsr(), awake);
  *closest = std::numeric_limits<double>::infinity();
  while (sleeping_world.time() < seconds) {
    for (TwinWorld* w : {&sleeping_world, &awake_world}) {
      if (w->time() > 4.0) w->SetBaseVelocity({speed, 0.0, 0.0});
      w->Step();
    }
    const Pose2 a = sleeping_world.robot_pose(), b = awake_world.robot_pose();
    EXPECT_TRUE(a.x == b.x && a.y == b.y && a.yaw == b.yaw) << "t " << sleeping_world.time();
    EXPECT_EQ(sleeping_world.people().front().position, awake_world.people().front().position);
    if (::testing::Test::HasFailure()) return -1;
    *closest =
        std::min(*closest, (sleeping_world.people().front().position - a.translation()).norm());
  }
  EXPECT_EQ(CountEvents(sleeping_world, "contact"), CountEvents(awake_world, "contact"));
  for (const auto& payload : loaded.scenario.payloads) {
    EXPECT_EQ(sleeping_world.payload_pose(payload.name).translation(),
              awake_world.payload_pose(payload.name).translation());
  }
  if (at_end) at_end(sleeping_world);
  return CountEvents(sleeping_world, "contact");
}

TEST(TwinWorldTest, PeoplesBodiesAsleepFarFromTheRobotGiveTheSameRunAsAwake) {
  // Someone walks from 5 m away towards the robot, which drives at them (they step aside): their
  // Bullet body sleeps until within person_body_awake_reach, then wakes moving, with the bounds
  // and velocity it would have had awake.
  double closest = 0.0;
  const auto walker = LoadText(
      "world: lab.sdf\nrobot: {start: {x: -2.4, y: 0.8, yaw: 0.0}}\npeople:\n"
      "  - {name: p, behavior: approach_and_wait, start: [2.6, 1.0], goal: [0.0, 0.8], "
      "wait_s: 60}\n",
      WorldsDir() / "lab");
  SameRunAsleepAndAwake(walker, 20.0, &closest);
  EXPECT_LT(closest, 1.0) << "they never came near: their body never woke";
  // Someone standing 4 m ahead (yet to set off), whom the robot drives into: the contact is the
  // same as with their body awake all along, and it stops the robot.
  const auto stander = LoadText(
      "world: lab.sdf\nrobot: {start: {x: -2.4, y: 0.8, yaw: 0.0}}\npeople:\n"
      "  - {name: p, behavior: approach_and_wait, start: [1.6, 0.8], goal: [1.6, 2.0], "
      "trigger: {at: 100}}\n",
      WorldsDir() / "lab");
  EXPECT_GE(SameRunAsleepAndAwake(stander, 20.0, &closest), 1);
  // Someone walks from 5 m away into a bottle on the floor (people do not avoid payloads) and
  // kicks it: their body wakes 3 m before it, and what Bullet makes of the kick is the same.
  const auto kicker = LoadText(
      "world: lab.sdf\nrobot: {start: {x: -2.5, y: -0.5, yaw: 0.0}}\npeople:\n"
      "  - {name: p, behavior: walk_past, start: [2.6, 1.5], goal: [-1.5, 1.5]}\n"
      "payloads:\n  - {name: bottle, kind: water_bottle, x: -0.6, y: 1.5, z: 0.11}\n",
      WorldsDir() / "lab");
  const Eigen::Vector3d p_WBottle = [&] {
    TwinWorld w(kicker.scenario, kicker.world, 1, Hsr());
    return w.payload_pose("bottle").translation();
  }();
  double moved = 0.0;
  SameRunAsleepAndAwake(kicker, 8.0, &closest, 0.0, [&](const TwinWorld& w) {
    moved = (w.payload_pose("bottle").translation() - p_WBottle).norm();
  });
  EXPECT_GT(moved, 0.05) << "the bottle was not kicked";
  TwinConfig too_near;
  too_near.person_body_awake_reach = 1.0;
  EXPECT_THROW(too_near.Validate(), InvalidArgument);
}

TEST(TwinWorldTest, SameSeedSameTraceOtherSeedOtherTrace) {
  const Scenario s = LoadScenario(WorldsDir() / "office/office_evacuation.yaml");
  const WorldDescription w = LoadSdfWorld(s.world_file);
  auto run = [&](std::uint64_t seed) {
    TwinWorld world(s, w, seed, Hsr());
    TraceRecorder trace;
    while (world.time() < 12.0) {
      world.SetBaseVelocity({0.3, 0.0, 0.1});
      world.Step();
      trace.Observe(world);
    }
    return std::make_pair(trace.Hash(), trace.sample_count());
  };
  const auto a = run(5), b = run(5), c = run(6);
  EXPECT_EQ(a.first, b.first);
  EXPECT_EQ(a.second, 12u * 20u + 1u);
  EXPECT_NE(a.first, c.first);
}

// Issue 21: the head is commanded apart from the arm; the twin turns it at the URDF's 1 rad/s
// within its limits, and the head camera (what the detector sees from) turns with it.
TEST(TwinWorldTest, AHeadCommandTurnsTheHeadAtItsSpeedAndTheCameraWithIt) {
  const auto loaded = LoadText(LabScenario({0.0, 1.0, M_PI / 2}), WorldsDir() / "lab");
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  const Pose3 before = world.head_camera_pose();
  world.SetHeadCommand({0.8, -0.2});
  world.StepFor(0.4);
  EXPECT_NEAR(world.arm_joint("head_pan_joint"), 0.4, 0.02);  // 1 rad/s: not there yet
  world.StepFor(1.0);
  EXPECT_NEAR(world.arm_joint("head_pan_joint"), 0.8, 1e-9);
  EXPECT_NEAR(world.arm_joint("head_tilt_joint"), -0.2, 1e-9);
  // The camera's optical axis (z) turned left by the pan, in the floor's plane.
  const Eigen::Vector3d z0 = before.rotation().col(2),
                        z1 = world.head_camera_pose().rotation().col(2);
  const double turned = std::atan2(z1.y(), z1.x()) - std::atan2(z0.y(), z0.x());
  EXPECT_NEAR(turned, 0.8, 0.02);
  // Beyond the joint's limit (head_pan_joint upper 1.75 rad): clamped.
  world.SetHeadCommand({3.0, 0.0});
  world.StepFor(3.0);
  EXPECT_NEAR(world.arm_joint("head_pan_joint"), 1.75, 1e-9);
  // An arm trajectory naming a head joint takes the head over again.
  JointTrajectory head;
  head.joint_names = {"head_pan_joint"};
  JointTrajectoryPoint p;
  p.positions = {0.0};
  p.time_from_start = SecondsToDuration(0.1);
  head.points.push_back(p);
  world.SetArmTrajectory(head);
  world.StepFor(2.5);
  EXPECT_NEAR(world.arm_joint("head_pan_joint"), 0.0, 1e-9);
  EXPECT_THROW(world.SetHeadCommand({std::nan(""), 0.0}), InvalidArgument);
}

TEST(TwinWorldTest, SomeoneWhoWaitedLeavesForTheirLeavePoint) {
  const auto loaded =
      LoadText(LabScenario({0.0, 1.0, M_PI / 2}) +
                   "people:\n  - {name: talker, behavior: approach_and_wait, start: [-1.5, 5.0],"
                   " goal: [-1.5, 4.0], wait_s: 2, leave: [-2.0, 6.0]}\n",
               WorldsDir() / "lab");
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  world.StepFor(2.0);
  EXPECT_LT((world.people()[0].position - Eigen::Vector2d(-1.5, 4.0)).norm(), 0.2);
  // (The walls' social forces keep a standing walker a little off a point 1 m from them.)
  world.StepFor(6.0);
  const Eigen::Vector2d there = world.people()[0].position;
  EXPECT_LT((there - Eigen::Vector2d(-2.0, 6.0)).norm(), 0.5);
  world.StepFor(4.0);  // and stays there
  EXPECT_LT((world.people()[0].position - Eigen::Vector2d(-2.0, 6.0)).norm(), 0.5);
  EXPECT_LT((world.people()[0].position - there).norm(), 0.25);
}

}  // namespace
}  // namespace egress::twin
