// Evacuees: mobility classes, multi-door exit routes, queueing and operating doors, and the
// crowd model's flow through a fully open door against the hydraulic values.

#include <algorithm>
#include <filesystem>
#include <functional>
#include <map>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"
#include "egress/hsr_interface/geometry.h"
#include "egress/twin/mobility.h"
#include "egress/twin/twin_model.h"
#include "twin_test_util.h"

namespace egress::twin {
namespace {

using testing::CountEvents;
using ::testing::HasSubstr;
using testing::Hsr;
using testing::LoadText;
using testing::WorldsDir;

// When each person first crossed the line y = y_line going north, stepping the world to `until`.
std::vector<double> CrossingTimes(TwinWorld& world, double y_line, double until) {
  std::map<std::string, double> crossed;
  std::map<std::string, double> last_y;
  while (world.time() < until) {
    world.Step();
    for (const auto& p : world.people()) {
      const auto it = last_y.find(p.name);
      if (it != last_y.end() && it->second < y_line && p.position.y() >= y_line &&
          crossed.count(p.name) == 0)
        crossed[p.name] = world.time();
      last_y[p.name] = p.position.y();
    }
  }
  std::vector<double> times;
  for (const auto& [name, t] : crossed)
    times.push_back(t);
  std::sort(times.begin(), times.end());
  return times;
}

// A dense group of `count` in the lab's south room going north through the lab door (1.0 m
// between the jambs, a 0.95 m leaf), which stands open at 90 degrees from the start.
std::string LabDoorFlow(int count, const std::string& mobility = "") {
  return "world: lab.sdf\n"
         "robot: {start: {x: 2.6, y: -0.6}}\n"
         "doors: [{door: lab_door, operator: push, open_angle_deg: 90, hold_open_s: 1000, "
         "open_at: [0.0]}]\n"
         "people:\n"
         "  - {name: e, behavior: evacuate, door: lab_door, start: [0.0, 1.0], goal: [0.0, 6.2], "
         "speed: [1.1, 1.4], radius: 0.23, count: " +
         std::to_string(count) + mobility + ", trigger: {at: 3.0}}\n";
}

// Clear width 0.95 m: SFPE 1.3 /(s m) x (0.95 - 0.3) = 0.85 /s; IMO 1.3 x 0.95 = 1.24 /s.
// Steady flow: 5th to 25th crossing (the group's head and tail left out). The mean over twelve
// groups is in the band; one group of 30 varies widely (seeds 1-12: 0.61 to 1.20 /s), so each
// is only held to within 40 % of the band: far outside it is a model bug. Returns the mean.
double ExpectDenseFlowInTheHydraulicBand(const TwinConfig& config) {
  double sum = 0.0;
  constexpr int kGroups = 12;
  for (std::uint64_t seed = 1; seed <= kGroups; ++seed) {
    auto loaded = LoadText(LabDoorFlow(30), WorldsDir() / "lab");
    TwinWorld world(std::make_shared<const TwinModel>(loaded.scenario, loaded.world, Hsr(), config),
                    seed);
    const std::vector<double> t = CrossingTimes(world, 3.0, 90.0);
    EXPECT_EQ(t.size(), 30u) << "seed " << seed;
    if (t.size() < 25) return 0.0;
    const double flow = 20.0 / (t[24] - t[4]);
    ::testing::Test::RecordProperty("flow_persons_per_s_seed_" + std::to_string(seed),
                                    std::to_string(flow));
    EXPECT_GT(flow, 0.85 * 0.6) << "seed " << seed;
    EXPECT_LT(flow, 1.24 * 1.4) << "seed " << seed;
    sum += flow;
  }
  ::testing::Test::RecordProperty("flow_persons_per_s_mean", std::to_string(sum / kGroups));
  EXPECT_GT(sum / kGroups, 0.85);
  EXPECT_LT(sum / kGroups, 1.24);
  return sum / kGroups;
}

TEST(EvacueesTest, DenseFlowThroughAFullyOpenDoorIsWithinTheHydraulicBand) {
  ExpectDenseFlowInTheHydraulicBand(TwinConfig{});
}

TEST(EvacueesTest, WithSocialTermsHeldAt60HzTheDenseFlowStaysInTheHydraulicBand) {
  // TwinConfig::crowd_social_rate_hz below the physics rate (the drive and contact still every
  // step): the same groups, the same band.
  TwinConfig config;
  config.crowd_social_rate_hz = 60.0;
  ExpectDenseFlowInTheHydraulicBand(config);
}

TEST(EvacueesTest, WithThePeopleSteppedAt120HzTheDenseFlowStaysInTheHydraulicBand) {
  // TwinConfig::crowd_rate_hz at half the physics rate: every person's decisions and forces every
  // other physics step, their bodies carried on between.
  TwinConfig config;
  config.crowd_rate_hz = 120.0;
  config.crowd_social_rate_hz = 120.0;
  ExpectDenseFlowInTheHydraulicBand(config);
}

// The office: room 1 (x < 5), door_a (x = 5, push buttons), room 2, door_b (x = 9, glass,
// proximity plates), room 3; both doors closed; the robot parked in room 1's corner.
std::string OfficeExitRoute(int count, const std::string& mobility) {
  return "world: office.sdf\n"
         "robot: {start: {x: 0.6, y: 5.4}}\n"
         "doors: [{door: door_a, operator: push}, {door: door_b, operator: proximity}]\n"
         "people:\n"
         "  - {name: e, behavior: evacuate, route: [door_a, door_b], start: [2.5, 3.0], "
         "goal: [12.5, 1.5], count: " +
         std::to_string(count) + mobility + "}\n";
}

TEST(EvacueesTest, AGroupFollowsItsExitRouteOperatingEachClosedDoor) {
  auto loaded = LoadText(OfficeExitRoute(6, ""), WorldsDir() / "office");
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  world.StepFor(120.0);
  for (const auto& p : world.people()) {
    EXPECT_TRUE(p.out) << p.name << " at " << p.position.transpose();
    EXPECT_GT(p.arrived_at, 0.0);
  }
  // Each door opened by one of them, and only when it was shut.
  EXPECT_GE(CountEvents(world, "door_operated", "door_a"), 1);
  EXPECT_GE(CountEvents(world, "door_operated", "door_b"), 1);
  EXPECT_EQ(CountEvents(world, "button_pressed"), 0);  // the robot pressed nothing
}

TEST(EvacueesTest, SteppedBelowThePhysicsRateWalkersAreCarriedOnEveryPhysicsStep) {
  auto loaded = LoadText(OfficeExitRoute(6, ""), WorldsDir() / "office");
  TwinConfig config;
  config.crowd_rate_hz = 80.0;  // every third physics step
  config.crowd_social_rate_hz = 80.0;
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr(), config);
  world.StepFor(2.0);
  // Someone walking: over each of the next six physics steps they move by their velocity.
  std::vector<PersonState> before = world.people();
  int walking = 0;
  for (int k = 0; k < 6; ++k) {
    world.Step();
    const std::vector<PersonState> after = world.people();
    for (std::size_t i = 0; i < after.size(); ++i) {
      if (before[i].velocity.norm() < 0.2) continue;
      ++walking;
      const Eigen::Vector2d moved = after[i].position - before[i].position;
      EXPECT_GT(moved.norm(), 0.5 * before[i].velocity.norm() * world.step_size())
          << after[i].name << " step " << k;
    }
    before = after;
  }
  EXPECT_GT(walking, 0);
  world.StepFor(118.0);
  for (const auto& p : world.people())
    EXPECT_TRUE(p.out) << p.name << " at " << p.position.transpose();
}

// A group of 12 put 0.8 m from room 1's west wall (its face at x = 0.1): the 4 x 4 grid's
// west column, at x = -0.69, lay outside the building, and those standing there never got out.
TEST(EvacueesTest, AGroupPutAgainstAWallStandsInsideItAndGetsOut) {
  const std::string text =
      "world: office.sdf\n"
      "robot: {start: {x: 0.6, y: 5.4}}\n"
      "doors: [{door: door_a, operator: push}, {door: door_b, operator: proximity}]\n"
      "people:\n"
      "  - {name: e, behavior: evacuate, route: [door_a, door_b], start: [0.8, 3.0], "
      "goal: [12.5, 1.5], count: 12, mobility: {walker: 2, wheelchair: 1}}\n";
  auto loaded = LoadText(text, WorldsDir() / "office");
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  ASSERT_EQ(world.people().size(), 12u);
  for (const auto& p : world.people())  // inside (a body may touch the wall, not be beyond it)
    EXPECT_GT(p.position.x(), 0.1) << p.name << " at " << p.position.transpose();
  world.StepFor(150.0);
  for (const auto& p : world.people())
    EXPECT_TRUE(p.out) << p.name << " at " << p.position.transpose();
}

TEST(EvacueesTest, AGroupTheRoomHasNoSpaceForIsAnErrorNamingIt) {
  // 150 of mixed sizes, 0.99 m apart, in a room of about 6 x 6 m.
  auto loaded = LoadText(OfficeExitRoute(150, ", mobility: {walker: 1}"), WorldsDir() / "office");
  try {
    TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
    FAIL() << "a group of 150 in room 1 was laid out";
  } catch (const LoadError& e) {
    EXPECT_THAT(e.what(), HasSubstr("test.yaml: field 'people[0].count' ('e'): a group of 150 "
                                    "does not fit around its start"));
  }
}

// door_a opens into room 1, towards the group: they wait clear of its sweep and step out of
// it when it opens, so the leaf swings wide open (a group standing in the sweep held it shut
// below the angle they wait for, and waited for ever).
TEST(EvacueesTest, PeopleKeepOutOfTheSweepOfALeafOpeningTowardsThem) {
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    auto loaded = LoadText(OfficeExitRoute(10, ""), WorldsDir() / "office");
    TwinWorld world(loaded.scenario, loaded.world, seed, Hsr());
    double widest = 0.0;
    while (world.time() < 40.0) {
      world.Step();
      widest = std::max(widest, world.door_angle(0));
    }
    EXPECT_GT(widest, 75.0 * M_PI / 180.0) << "seed " << seed;
    world.StepFor(150.0);
    for (const auto& p : world.people())
      EXPECT_TRUE(p.out) << "seed " << seed << ": " << p.name << " at " << p.position.transpose();
  }
}

// The clinic's south ward, 20 residents of mixed mobility, out through door_d (into the
// corridor), door_e and the exit to the assembly point; `setting` gives the robot and the
// doors.
std::string ClinicWardEvacuation(const std::string& setting) {
  return "world: clinic.sdf\n" + setting +
         "people:\n"
         "  - {name: r, behavior: evacuate, route: [door_d, door_e, exit_door], start: [2.8, -3.0],"
         " goal: [21.0, 11.5], count: 20, trigger: {at: 5.0},"
         " mobility: {walker: 10, cane: 3, frame: 3, wheelchair: 2, wheelchair_pushed: 2}}\n";
}

// Every resident of `text` (ClinicWardEvacuation) is out by `until` [s], for each seed; with
// `one_unable_may_wait`, but for one who cannot operate a door, left waiting at it after all
// the others went (nobody is left to open it for them: what the robot is there for).
void ExpectAllOut(const std::string& text, std::initializer_list<std::uint64_t> seeds, double until,
                  bool one_unable_may_wait = false) {
  for (const std::uint64_t seed : seeds) {
    auto loaded = LoadText(text, WorldsDir() / "clinic");
    TwinWorld world(loaded.scenario, loaded.world, seed, Hsr());
    world.StepFor(until);
    EXPECT_EQ(world.people().size(), 20u);
    std::vector<const PersonState*> left;
    for (const auto& p : world.people())
      if (!p.out) left.push_back(&p);
    if (one_unable_may_wait && left.size() == 1 && !left[0]->can_operate &&
        left[0]->phase == PersonPhase::kWaitingForDoor)
      continue;
    for (const PersonState* p : left)
      ADD_FAILURE() << "seed " << seed << ": " << p->name << " (" << p->mobility << ") at "
                    << p->position.transpose() << " phase " << int(p->phase) << " operated "
                    << p->doors_operated << (p->can_operate ? "" : ", cannot operate");
  }
}

// All doors propped open: everyone reaches the assembly point (the leaf of door_d pushed shut
// by the crowd, people waiting in its sweep, used to strand most of them).
// Every evacuation scenario (worlds/scenarios/evacuation, what `egress evac study` runs) fits its
// world and has residents with an exit route; the atrium's (a building the escort was not tuned
// on) gets its 16 residents out through its three push-button doors on their own, no robot.
TEST(EvacueesTest, EveryEvacuationScenarioLoadsAndTheAtriumsResidentsGetOutOnTheirOwn) {
  int scenarios = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(WorldsDir() / "scenarios" / "evacuation")) {
    if (entry.path().extension() != ".yaml") continue;
    ++scenarios;
    SCOPED_TRACE(entry.path().string());
    const Scenario scenario = LoadScenario(entry.path());
    TwinWorld world(scenario, LoadSdfWorld(scenario.world_file), 1, Hsr());
    int evacuees = 0;
    for (const auto& p : world.people())
      evacuees += p.behavior == PersonBehavior::kEvacuate ? 1 : 0;
    EXPECT_GT(evacuees, 0);
    if (entry.path().filename() != "atrium_escort.yaml") continue;
    EXPECT_EQ(evacuees, 16);
    world.StepFor(250.0);  // they set off at 45 s; 111-155 s over 10 seeds
    for (const auto& p : world.people())
      EXPECT_TRUE(p.out) << p.name << " (" << p.mobility << ") at " << p.position.transpose();
  }
  EXPECT_GE(scenarios, 7);
}

TEST(EvacueesTest, AMixedGroupLeavesTheClinicThroughProppedDoors) {
  ExpectAllOut(ClinicWardEvacuation(
                   "robot: {start: {x: 9.0, y: -1.6}}\n"
                   "doors:\n"
                   "  - {door: door_d, operator: push, open_at: [0.0], hold_open_s: 1000000}\n"
                   "  - {door: door_e, operator: push, open_at: [0.0], hold_open_s: 1000000}\n"
                   "  - {door: exit_door, operator: push, open_at: [0.0], hold_open_s: 1000000}\n"),
               {1, 2}, 300.0);
}

TEST(EvacueesTest, AMixedGroupOpensTheClinicsShutDoorsItself) {
  // No robot, every door shut: the residents who can operate the actuators (the exit's is on
  // the inside only). Seeds 5 and 9 left all 20 at a shut door before: each waiting resident
  // deferred to someone nearer the actuator who was not in reach of it. Seed 17 once pushed
  // someone back into the ward through door_d after they passed it (they now take up their
  // route from before it); since people carried into a doorway go on through it, no seed of
  // 1-150 does: that case is no longer exercised here.
  ExpectAllOut(ClinicWardEvacuation("robot: {off_scene: true}\n"), {5, 9, 17}, 360.0);
}

// door_d held open from the start (as the robot holds it for them), door_e and the exit shut:
// the group reaches them dense, and the crowd carries people on past their waypoints. Before,
// with these seeds, 1 to 11 of them stayed at a doorway to the end:
// - 10, 13: someone carried on past their way round door_e's open leaf walked back to it, into
//   the doorway against the crowd, and everyone behind waited for the doorway;
// - 15: someone pushed into door_d's doorway before reaching the spot before it did the same.
// (Seed 22 still leaves 9 at the exit door: wheelchairs converging on its line-up spot squeeze
// each other short of the doorway — see the README.) Since those held up near the spot before a
// shut door queue for it, seed 13's last wheelchair user, who cannot open the exit, reaches it
// after the others went and waits there alone.
TEST(EvacueesTest, NobodyCarriedOnByTheCrowdWalksBackIntoADoorway) {
  ExpectAllOut(
      ClinicWardEvacuation(
          "robot: {off_scene: true}\n"
          "doors: [{door: door_d, operator: push, open_at: [0.0], hold_open_s: 1000000}]\n"),
      {10, 13, 15}, 300.0, /*one_unable_may_wait=*/true);
}

TEST(EvacueesTest, SomeoneWhoCannotOperateTheDoorWaitsAtItAndTheRestGoOn) {
  // Wheelchair users alone: half of them cannot operate an actuator (mobility.h).
  int stuck = 0, through = 0;
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    auto loaded =
        LoadText(OfficeExitRoute(1, ", mobility: {wheelchair: 1}"), WorldsDir() / "office");
    TwinWorld world(loaded.scenario, loaded.world, seed, Hsr());
    world.StepFor(90.0);
    const PersonState& p = world.people().front();
    EXPECT_EQ(p.mobility, "wheelchair");
    EXPECT_DOUBLE_EQ(p.radius, FindMobilityClass("wheelchair")->radius);
    if (p.can_operate) {
      EXPECT_TRUE(p.out) << "seed " << seed << " at " << p.position.transpose() << " phase "
                         << int(p.phase) << " operated " << p.doors_operated;
      EXPECT_EQ(p.waiting_for, "") << "seed " << seed << ": out, waiting for nothing";
      ++through;
    } else {
      EXPECT_EQ(p.phase, PersonPhase::kWaitingForDoor) << "seed " << seed;
      EXPECT_EQ(p.waiting_for, "door_a") << "seed " << seed;
      EXPECT_LT(p.position.x(), 5.0);
      EXPECT_EQ(CountEvents(world, "door_operated"), 0);
      ++stuck;
    }
  }
  EXPECT_GT(stuck, 0);
  EXPECT_GT(through, 0);
}

// For each seed 1..`seeds` of the clinic with `people` (YAML list items), 30 s on: the last
// person, if they cannot operate a door, is waiting for `door` and passes `check`. The number
// of seeds that drew such a person.
// `robot`: the scenario's robot entry (off the scene unless given).
int CheckWhoCannotOperateWaitingAt(const std::string& people, const std::string& door, int seeds,
                                   const std::function<void(const PersonState&, int)>& check,
                                   const std::string& robot = "{off_scene: true}") {
  int unable = 0;
  for (int seed = 1; seed <= seeds; ++seed) {
    auto loaded = LoadText("world: clinic.sdf\nrobot: " + robot + "\npeople:\n" + people,
                           WorldsDir() / "clinic");
    TwinWorld world(loaded.scenario, loaded.world, std::uint64_t(seed), Hsr());
    world.StepFor(30.0);
    const PersonState& p = world.people().back();
    if (p.can_operate) continue;
    ++unable;
    EXPECT_EQ(p.phase, PersonPhase::kWaitingForDoor) << "seed " << seed;
    EXPECT_EQ(p.waiting_for, door) << "seed " << seed;
    check(p, seed);
  }
  return unable;
}

// Someone who cannot operate a door, waiting at it, keeps the front of its actuator clear for
// whoever can (a resident, the robot): at door_e, whose button is on the corridor's side wall
// beside the way in, a wheelchair user held up by those before them waited at the button,
// where nobody else could stand to press it (two-wards seed 17: the robot found no free
// standoff, and they waited to the end). Here someone stands where they would wait (the spot
// before the doorway), and they come from beside the button.
TEST(EvacueesTest, SomeoneWhoCannotOperateTheDoorKeepsItsActuatorClear) {
  // Where one stands to press door_e's button (on the east wall at (21.99, 1.9)).
  const Eigen::Vector2d stand_at = Eigen::Vector2d(21.99, 1.9) + Eigen::Vector2d(-0.45, 0.0);
  const int unable = CheckWhoCannotOperateWaitingAt(
      "  - {name: s, behavior: approach_and_wait, start: [20.8, 1.0], goal: [21.1, 1.35]}\n"
      "  - {name: w, behavior: evacuate, route: [door_e, exit_door], start: [21.55, 1.7],"
      " goal: [21.0, 11.5], mobility: {wheelchair: 1}}\n",
      "door_e", 8, [&](const PersonState& p, int seed) {
        // Someone at the button (0.3 m) and a 0.15 m margin between them, less the walk's
        // settling.
        EXPECT_GT((p.position - stand_at).norm(), 0.3 + 0.15 + p.radius - 0.05)
            << "seed " << seed << " at " << p.position.transpose();
        EXPECT_LT((p.position - Eigen::Vector2d(21.0, 2.65)).norm(), 2.5)
            << "seed " << seed << ": still waiting at the door";
      });
  EXPECT_GT(unable, 0);
}

// Someone who cannot operate a door, waiting at it, keeps the way to its actuator clear too:
// before the clinic's exit door (a 2 m corridor, its button on the end wall beside the east
// wall, its leaf swinging into the corridor), a wheelchair user waited in the corridor's middle
// out of the leaf's sweep and left 0.5 m by the east wall: the robot could not get by to press
// the button, and they waited to the time limit (clinic room A seeds 11, 22).
TEST(EvacueesTest, SomeoneWhoCannotOperateTheDoorLeavesTheWayToItsActuatorClear) {
  constexpr double kEastWallFaceX = 22.0;
  constexpr double kRobotWidthM = 0.43;
  const int unable = CheckWhoCannotOperateWaitingAt(
      "  - {name: w, behavior: evacuate, route: [exit_door], start: [21.4, 6.0],"
      " goal: [21.0, 11.5], mobility: {wheelchair: 1}}\n",
      "exit_door", 12, [&](const PersonState& p, int seed) {
        // The robot's width and a hand's breadth either side.
        EXPECT_GT(kEastWallFaceX - (p.position.x() + p.radius), kRobotWidthM + 2 * 0.1)
            << "seed " << seed << " at " << p.position.transpose();
        // ... and out of the sweep of the exit's leaf (0.95 m, hinged at (20.525, 9.05)),
        // which opens towards them: not beside its hinge, across the lane.
        EXPECT_GT((p.position - Eigen::Vector2d(20.525, 9.05)).norm(), 0.95 + p.radius)
            << "seed " << seed << " at " << p.position.transpose();
        EXPECT_LT((p.position - Eigen::Vector2d(21.0, 9.05)).norm(), 2.5)
            << "seed " << seed << ": still waiting at the door";
      });
  EXPECT_GT(unable, 0);
}

// Someone who cannot operate a door, waiting at it, steps out of the robot's straight way to
// its actuator when the robot is near (kMakeWayForRobotM): two wheelchair users waiting across
// the clinic's 2 m corridor before door_e left the robot, coming along the corridor, no way to
// the button on the east wall; it stood 1.3 m from it for 390 s and both were left behind (two
// wards seed 54). Here the robot stands in the corridor west of door_e, and a wheelchair user
// who cannot press waits between it and the button; with the robot off the scene, the same
// resident waits in that way on some seed (the rule is the robot's presence, not the lane's).
TEST(EvacueesTest, SomeoneWhoCannotOperateTheDoorMakesWayForTheRobotComingToItsActuator) {
  const Eigen::Vector2d p_WR(20.15, 1.6);  // the robot, facing the button
  const Eigen::Vector2d stand_at = Eigen::Vector2d(21.99, 1.9) + Eigen::Vector2d(-0.45, 0.0);
  const std::string resident =
      "  - {name: w, behavior: evacuate, route: [door_e, exit_door], start: [20.95, 1.45],"
      " goal: [21.0, 11.5], mobility: {wheelchair: 1}}\n";
  const auto off_the_way = [&](const PersonState& p) {
    const Eigen::Vector2d foot = egress::ClosestPointOnSegment(p.position, p_WR, stand_at);
    return (p.position - foot).norm() - p.radius - 0.215;
  };
  double least_without_robot = 1e9;
  CheckWhoCannotOperateWaitingAt(resident, "door_e", 8, [&](const PersonState& p, int) {
    least_without_robot = std::min(least_without_robot, off_the_way(p));
  });
  const int unable = CheckWhoCannotOperateWaitingAt(
      resident, "door_e", 8,
      [&](const PersonState& p, int seed) {
        // The robot's room beside them (the rule's margin, 0.3 m, less the walk's settling).
        EXPECT_GT(off_the_way(p), 0.25) << "seed " << seed << " at " << p.position.transpose();
        EXPECT_LT((p.position - Eigen::Vector2d(21.0, 2.65)).norm(), 2.5)
            << "seed " << seed << ": still waiting at the door";
      },
      "{start: {x: 20.15, y: 1.6, yaw_deg: 0}}");
  EXPECT_GT(unable, 0);
  EXPECT_LT(least_without_robot, 0.25);
}

// Carried by the crowd past a via point of their route (here: started 1 m past it, along the
// clinic's corridor towards door_e), an evacuee goes on from where they are, not back to it
// against the crowd (clinic two wards seed 26: a pushed wheelchair swept 0.6 m past the point
// beyond door_d and 10 m on by the group behind walked back the 10 m to it, and met the robot
// in door_d's doorway).
TEST(EvacueesTest, SomeoneCarriedPastAWaypointGoesOnFromThere) {
  for (const char* mobility : {"walker", "wheelchair_pushed"}) {
    auto loaded = LoadText(std::string("world: clinic.sdf\nrobot: {off_scene: true}\npeople:\n"
                                       "  - {name: e, behavior: evacuate, via: [[9.0, 0.9]],"
                                       " route: [door_e, exit_door], start: [10.0, 0.9],"
                                       " goal: [21.0, 11.5], mobility: {") +
                               mobility + ": 1}}\n",
                           WorldsDir() / "clinic");
    TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
    const double x0 = world.people().front().position.x();
    double west_most = x0;
    while (world.time() < 6.0) {
      world.Step();
      west_most = std::min(west_most, world.people().front().position.x());
    }
    EXPECT_GT(west_most, x0 - 0.1) << mobility << " walked back to the via point";
    EXPECT_GT(world.people().front().position.x(), x0 + 2.0) << mobility << " did not go on";
  }
}

// Carried by the crowd through the doorway of a room off their route, an evacuee who finds a
// wall between them and their way on goes back out through that doorway (clinic two wards seed
// 1, doors propped open: a north-ward resident pressed through door_b into the room beyond
// leaned on its wall, the corridor on the other side, to the time limit). They start where that
// resident stood, in the room east of door_b (open, into the corridor), the exit route beyond
// the room's south wall.
TEST(EvacueesTest, SomeoneCarriedIntoARoomOffTheirRouteFindsTheWayBackOut) {
  for (const char* mobility : {"walker", "wheelchair"}) {
    auto loaded = LoadText(
        std::string(
            "world: clinic.sdf\nrobot: {off_scene: true}\n"
            "doors: [{door: door_b, operator: proximity, hold_open_s: 1000, open_at: [0.0]}]\n"
            "people:\n"
            "  - {name: e, behavior: evacuate, route: [door_e, exit_door], start: [10.9,"
            " 2.6], goal: [21.0, 11.5], mobility: {") +
            mobility + ": 1}, trigger: {at: 3.0}}\n",
        WorldsDir() / "clinic");
    TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
    world.StepFor(90.0);
    // On along the corridor to door_e and beyond (a wheelchair user then waits at the exit,
    // whose button they cannot reach).
    const auto& e = world.people().front();
    EXPECT_TRUE(e.out || e.position.x() > 19.5) << mobility << " at " << e.position.transpose();
    EXPECT_TRUE(std::any_of(world.events().begin(), world.events().end(), [](const TwinEvent& ev) {
      return ev.kind == "person_finds_way_back";
    })) << mobility;
  }
}

// Pushed by the crowd into the doorway of a door not on their route, whose open leaf stands
// across their way on, an evacuee steps back out into the corridor, not round the leaf into the
// room beyond it (clinic two wards seed 23: a north-ward resident walking east along the
// corridor's south wall was pressed into door_d's doorway as it stood open for the south ward;
// round the leaf's free edge they were in the south ward, a wall between them and the corridor,
// to the time limit). door_d, hinged at (7.475, -0.05), opens south; the via point (in the south
// ward) brings the resident into its doorway from the corridor, a shoulder south of the wall's
// midline, where the leaf stands between them and the corridor to the east.
TEST(EvacueesTest, SomeonePushedIntoTheDoorwayOfAnotherRoomStepsBackOutOfIt) {
  for (const char* mobility : {"walker", "wheelchair", "frame"}) {
    auto loaded = LoadText(
        std::string("world: clinic.sdf\nrobot: {off_scene: true}\n"
                    "doors: [{door: door_d, operator: push, open_angle_deg: 80, hold_open_s: 1000,"
                    " open_at: [0.0]}]\n"
                    "people:\n"
                    "  - {name: e, behavior: evacuate, via: [[7.1, -0.7]], route: [door_e,"
                    " exit_door], start: [6.5, 1.7], goal: [21.0, 11.5], mobility: {") +
            mobility + ": 1}, trigger: {at: 7.0}}\n",
        WorldsDir() / "clinic");
    TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
    double south_most = 0.0;
    while (world.time() < 30.0) {
      world.Step();
      south_most = std::min(south_most, world.people().front().position.y());
    }
    const Eigen::Vector2d p = world.people().front().position;
    EXPECT_GT(south_most, -0.6) << mobility << " went round door_d's leaf into the south ward";
    EXPECT_GT(p.y(), 0.5) << mobility << " is not in the corridor at " << p.transpose();
    EXPECT_GT(p.x(), 9.0) << mobility << " did not go on along the corridor";
  }
}

// Held up short of the spot before a shut door, an evacuee queues for the door where they are,
// and operates it if they can (clinic seed 21, no robot, the study's clinic escort group:
// everyone who could press the exit's button stood round the spot before it, held there by
// someone who could not; none of them was waiting for the door, so nobody pressed it, and 9
// were left to the end).
TEST(EvacueesTest, SomeoneHeldUpShortOfTheSpotBeforeAShutDoorQueuesForIt) {
  auto loaded = LoadText(
      "world: clinic.sdf\nrobot: {off_scene: true}\npeople:\n"
      "  - {name: r, behavior: evacuate, route: [door_d, door_e, exit_door], start: [2.8, -3.0],"
      " goal: [21.0, 11.5], count: 20, trigger: {at: 60.0},"
      " mobility: {walker: 10, cane: 3, frame: 3, wheelchair: 2, wheelchair_pushed: 2}}\n",
      WorldsDir() / "clinic");
  TwinWorld world(loaded.scenario, loaded.world, 21, Hsr());
  world.StepFor(420.0);
  for (const auto& p : world.people())
    EXPECT_TRUE(p.out) << p.name << " (" << p.mobility << ") at " << p.position.transpose()
                       << " phase " << int(p.phase);
}

struct Resident {
  std::string name;
  double x, y;  // start in W [m]
  std::string mobility;
};
// The clinic with its exit door held open and `residents` before it, each evacuating through it.
std::string AtTheOpenExit(const std::vector<Resident>& residents) {
  std::string yaml =
      "world: clinic.sdf\nrobot: {off_scene: true}\n"
      "doors: [{door: exit_door, operator: push, open_angle_deg: 80, hold_open_s: 1000,"
      " open_at: [0.0]}]\npeople:\n";
  for (const Resident& r : residents)
    yaml += "  - {name: " + r.name +
            ", behavior: evacuate, route: [exit_door], goal: [21.0, 11.5], start: [" +
            std::to_string(r.x) + ", " + std::to_string(r.y) + "], mobility: {" + r.mobility +
            ": 1}}\n";
  return yaml;
}
// The names of those not yet out, space-separated ("" when everyone is).
std::string StillInside(const TwinWorld& world) {
  std::string names;
  for (const auto& p : world.people())
    if (!p.out) names += " " + p.name;
  return names;
}

// Twenty-two residents as the clinic's two wards left them at its open exit (seed 48, 598 s): a
// pushed wheelchair on the door's axis 0.55 m before it, two more pressed into the corners beside
// the jambs, the rest behind. The vestibule (2 m) is narrower than three wide bodies abreast.
// Without the jam's front going first (GiveWayIfJammed) and the corner ones lining up level with
// where they stand, the social forces held them still for good on several of these seeds.
TEST(EvacueesTest, AJamOfWideBodiesBeforeAnOpenDoorClears) {
  const std::string yaml = AtTheOpenExit({
      {"south_1", 21.34, 5.01, "frame"},
      {"south_2", 20.99, 8.50, "wheelchair_pushed"},
      {"south_3", 20.81, 7.85, "frame"},
      {"south_4", 21.71, 7.62, "frame"},
      {"south_5", 21.20, 7.49, "walker"},
      {"south_7", 21.67, 5.54, "wheelchair"},
      {"south_8", 20.57, 5.45, "cane"},
      {"south_10", 21.65, 8.67, "wheelchair_pushed"},
      {"south_12", 20.33, 8.67, "wheelchair_pushed"},
      {"south_17", 20.98, 6.95, "wheelchair_pushed"},
      {"north_1", 21.74, 6.11, "cane"},
      {"north_3", 21.06, 5.69, "frame"},
      {"north_4", 20.31, 6.92, "wheelchair"},
      {"north_5", 20.58, 5.98, "walker"},
      {"north_6", 21.71, 6.66, "frame"},
      {"north_7", 20.32, 8.08, "cane"},
      {"north_8", 20.30, 7.54, "frame"},
      {"north_10", 20.64, 6.45, "cane"},
      {"north_11", 21.52, 7.14, "walker"},
      {"north_16", 21.33, 8.01, "cane"},
      {"north_18", 21.78, 8.13, "walker"},
      {"north_19", 21.20, 6.31, "wheelchair"},
  });
  auto loaded = LoadText(yaml, WorldsDir() / "clinic");
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    TwinWorld world(loaded.scenario, loaded.world, seed, Hsr());
    world.StepFor(150.0);
    EXPECT_EQ(StillInside(world), "") << "seed " << seed;
    EXPECT_GT(CountEvents(world, "person_gives_way"), 0) << "seed " << seed;
  }
}

// Eight residents as the clinic's two wards left them at its open exit with the robot (seed 36,
// 600 s, people stepped at 120 Hz): three pushed wheelchairs abreast, one on the door's axis
// 0.6 m before it and one pressed into each corner beside the jambs, and five behind. Those in
// the corners stepped back from the doorway's centre, into the side walls they were pressed
// against, and the arch held for 210 s.
TEST(EvacueesTest, AnArchOfThreeWheelchairsBeforeAnOpenDoorClears) {
  const std::string yaml = AtTheOpenExit({
      {"south_4", 21.00, 8.44, "wheelchair_pushed"},
      {"south_8", 21.61, 7.36, "wheelchair_pushed"},
      {"south_17", 20.60, 8.00, "cane"},
      {"south_18", 20.34, 8.65, "wheelchair_pushed"},
      {"north_1", 21.66, 8.65, "wheelchair_pushed"},
      {"north_5", 20.53, 7.40, "wheelchair_pushed"},
      {"north_9", 21.08, 7.74, "frame"},
      {"north_15", 21.62, 8.01, "frame"},
  });
  auto loaded = LoadText(yaml, WorldsDir() / "clinic");
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    TwinWorld world(loaded.scenario, loaded.world, seed, Hsr());
    world.StepFor(120.0);
    EXPECT_EQ(StillInside(world), "") << "seed " << seed;
  }
}

TEST(EvacueesTest, TheMobilityMixIsDrawnBySeedFromTheShares) {
  auto loaded =
      LoadText(OfficeExitRoute(20, ", mobility: {walker: 3, frame: 1}"), WorldsDir() / "office");
  TwinWorld a(loaded.scenario, loaded.world, 7, Hsr()), b(loaded.scenario, loaded.world, 7, Hsr());
  int frames = 0;
  for (std::size_t i = 0; i < a.people().size(); ++i) {
    EXPECT_EQ(a.people()[i].mobility, b.people()[i].mobility);  // a function of the seed
    EXPECT_THAT(a.people()[i].mobility, ::testing::AnyOf("walker", "frame"));
    frames += a.people()[i].mobility == "frame" ? 1 : 0;
  }
  EXPECT_GT(frames, 1);  // about 5 of 20 (room 1 holds no more of mixed sizes)
  EXPECT_LT(frames, 11);
}

TEST(EvacueesTest, BadMobilityOrRouteIsAClearError) {
  const auto load = [](const std::string& person) {
    auto loaded = LoadText(
        "world: office.sdf\nrobot: {start: {x: 0.6, y: 5.4}}\npeople:\n  - " + person + "\n",
        WorldsDir() / "office");
    TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  };
  EXPECT_THAT(
      [&] {
        load(
            "{behavior: evacuate, route: [door_a], start: [2, 3], goal: [12, 1.5], mobility: "
            "{skater: 1}}");
      },
      ::testing::ThrowsMessage<LoadError>(HasSubstr("mobility.skater")));
  EXPECT_THAT(
      [&] {
        load("{behavior: evacuate, route: [door_a, door_q], start: [2, 3], goal: [12, 1.5]}");
      },
      ::testing::ThrowsMessage<LoadError>(HasSubstr("route[1]")));
  EXPECT_THAT(
      [&] {
        load(
            "{behavior: cross_doorway, door: door_a, start: [2, 3], goal: [7, 3], mobility: "
            "{walker: 1}}");
      },
      ::testing::ThrowsMessage<LoadError>(HasSubstr("evacuate")));
}

}  // namespace
}  // namespace egress::twin
