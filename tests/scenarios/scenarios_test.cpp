// The paper's scenarios (worlds/scenarios/) at a fixed seed, driven by the robot brain and
// judged by the twin's ground truth.

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "brain_trial.h"
#include "egress/twin/sdf_world_loader.h"
#include "egress/twin/twin_run.h"

namespace egress {
namespace {

const std::filesystem::path kScenarios = std::filesystem::path(EGRESS_WORLDS_DIR) / "scenarios";

struct BrainRun {
  twin::RunResult result;
  std::unique_ptr<twin::TwinWorld> world;
  std::unique_ptr<behavior::Executive> brain;
  int presses{0};
};

const behavior::ExecutiveConfig& Defaults() {
  static const behavior::ExecutiveConfig config;
  return config;
}

BrainRun RunWithBrain(const std::filesystem::path& file, std::uint64_t seed,
                      const behavior::ExecutiveConfig& config = Defaults()) {
  if (const char* s = std::getenv("EGRESS_SCENARIO_SEED")) seed = std::stoull(s);
  const twin::Scenario scenario = twin::LoadScenario(file);
  const twin::WorldDescription description = twin::LoadSdfWorld(scenario.world_file);
  auto model = std::make_shared<const RobotModel>(RobotModel::LoadDefault());
  apps::BrainTrialOptions options;
  options.config = config;
  options.run.record_trace = false;
  const bool debug = std::getenv("EGRESS_SCENARIO_DEBUG") != nullptr;
  double last = -1.0;
  options.after_step = [&](const twin::TwinWorld& world, const behavior::Executive& brain) {
    if (!debug || world.time() - last < 0.25) return;
    last = world.time();
    const auto f = world.fingertip_position();
    const auto b = world.robot_pose();
    const auto e = brain.X_MB();
    std::printf("%6.2f tip %.3f %.3f %.3f base %.3f %.3f %.3f belief %.3f %.3f %.3f door %.2f %s\n",
                world.time(), f.x(), f.y(), f.z(), b.x, b.y, b.yaw, e.x, e.y, e.yaw,
                world.door_angle(0), brain.active_action().c_str());
    for (const auto& p : world.people()) {
      std::printf("         TRUE %s at %.2f %.2f phase %s\n", p.name.c_str(), p.position.x(),
                  p.position.y(), std::string(twin::ToString(p.phase)).c_str());
    }
    for (const auto& p : brain.belief().world.people) {
      std::printf("         person %d at %.2f %.2f v %.2f %.2f intent %d door %s\n", p.person.id,
                  p.person.p_MP.x(), p.person.p_MP.y(), p.person.v_MP.x(), p.person.v_MP.y(),
                  int(p.intent), p.door_id.c_str());
    }
  };
  apps::BrainTrial trial = apps::RunBrainTrial(scenario, description, seed, model, options);
  BrainRun run;
  run.world = std::move(trial.world);
  run.brain = std::move(trial.brain);
  run.result = std::move(trial.result);
  if (debug) {
    for (const auto& d : run.brain->decisions())
      std::printf("  %7.2f  %s\n", d.time, d.text.c_str());
  }
  for (const auto& e : run.world->events())
    run.presses += e.kind == "button_pressed" ? 1 : 0;
  return run;
}

TEST(ScenarioTest, S1NominalPressesAndPasses) {
  const BrainRun run = RunWithBrain(kScenarios / "s1_nominal.yaml", 1);
  EXPECT_TRUE(run.result.verdict.success) << twin::FormatVerdict(run.result.verdict);
  EXPECT_EQ(run.presses, 1);
}

TEST(ScenarioTest, S2YieldsToThePersonCrossingThenPasses) {
  const BrainRun run = RunWithBrain(kScenarios / "s2_person_crosses.yaml", 1);
  EXPECT_TRUE(run.result.verdict.success) << twin::FormatVerdict(run.result.verdict);
  // The brain saw the person enter the door zone and stopped within one tick (0.1 s).
  ASSERT_FALSE(run.brain->preemptions().empty());
  for (const auto& [known, commanded] : run.brain->preemptions())
    EXPECT_LE(commanded - known, 0.1 + 1e-9);
}

TEST(ScenarioTest, S3HeldDoorIsPassedWithoutPressing) {
  const BrainRun run = RunWithBrain(kScenarios / "s3_held_door.yaml", 1);
  EXPECT_TRUE(run.result.verdict.success) << twin::FormatVerdict(run.result.verdict);
  EXPECT_EQ(run.presses, 0);
  EXPECT_EQ(run.world->button_presses(0), 0);
}

TEST(ScenarioTest, S4aFetchesTheBottleAndTakesItThroughTheDoor) {
  const BrainRun run = RunWithBrain(kScenarios / "s4a_fetch_bottle.yaml", 1);
  EXPECT_TRUE(run.result.verdict.success) << twin::FormatVerdict(run.result.verdict);
  EXPECT_EQ(run.world->held_payload(), "bottle");
}

TEST(ScenarioTest, S4bFetchesTheFlashlightAndTakesItThroughTheDoor) {
  const BrainRun run = RunWithBrain(kScenarios / "s4b_fetch_flashlight.yaml", 1);
  EXPECT_TRUE(run.result.verdict.success) << twin::FormatVerdict(run.result.verdict);
  EXPECT_EQ(run.world->held_payload(), "flashlight");
  // Lying 2 cm high, it is grasped from above: nothing of the robot touches its table (a
  // sideways grasp brushed it in every trial).
  EXPECT_EQ(run.result.verdict.metrics.contacts_with.count("side_table"), 0u)
      << twin::FormatVerdict(run.result.verdict);
}

TEST(ScenarioTest, S5FetchesFromTheFarRoomThroughTwoDoorsAndPlacesOnTheStartTable) {
  const BrainRun run = RunWithBrain(kScenarios / "s5_office_chain.yaml", 1);
  EXPECT_TRUE(run.result.verdict.success) << twin::FormatVerdict(run.result.verdict);
  EXPECT_FALSE(run.world->held_payload().has_value());
  // Out through each door by its west actuator, back by the one on the other side.
  std::vector<std::string> operated;
  for (const auto& e : run.world->events()) {
    if (e.kind == "button_pressed") operated.push_back(e.detail);
  }
  for (const char* actuator :
       {"door_a_button", "door_b_plate", "door_b_plate_east", "door_a_button_east"}) {
    EXPECT_NE(std::find(operated.begin(), operated.end(), actuator), operated.end()) << actuator;
  }
}

TEST(ScenarioTest, S6RetreatsFromAPersonCuttingThePathThenPasses) {
  const BrainRun run = RunWithBrain(kScenarios / "s6_person_cuts_path.yaml", 1);
  EXPECT_TRUE(run.result.verdict.success) << twin::FormatVerdict(run.result.verdict);
  bool retreated = false;
  for (const auto& d : run.brain->decisions())
    retreated = retreated || d.event == behavior::DecisionEvent::kRetreating;
  EXPECT_TRUE(retreated);
}

TEST(ScenarioTest, S7GoesRoundAnUnmappedObstacleAndPassesTheHeldDoor) {
  const BrainRun run = RunWithBrain(kScenarios / "s7_obstacle_held_door.yaml", 1);
  EXPECT_TRUE(run.result.verdict.success) << twin::FormatVerdict(run.result.verdict);
  EXPECT_EQ(run.presses, 0);
}

TEST(ScenarioTest, TheFetchedBottleIsHandedToTheResponder) {
  const BrainRun run = RunWithBrain(kScenarios / "extra" / "hand_over_bottle.yaml", 1);
  EXPECT_TRUE(run.result.verdict.success) << twin::FormatVerdict(run.result.verdict);
  EXPECT_FALSE(run.world->held_payload().has_value());
  bool waited_for_reach = false;
  for (const auto& d : run.brain->decisions())
    waited_for_reach = waited_for_reach || d.event == behavior::DecisionEvent::kResponderInReach;
  EXPECT_TRUE(waited_for_reach);
}

TEST(ScenarioTest, HardHalfOpenDoorIsNotDrivenIntoButOpenedByTheButton) {
  const BrainRun run = RunWithBrain(kScenarios / "hard" / "h1_half_open_held_door.yaml", 1);
  EXPECT_TRUE(run.result.verdict.success) << twin::FormatVerdict(run.result.verdict);
  EXPECT_GE(run.presses, 1);
}

// Seed 2005: the arm swung up into a pre-grasp 12 cm short of the bottle, above the books'
// near edge, and the hand came up through it; the pre-grasp now stands before the books.
class OccludedBottleTest : public ::testing::TestWithParam<std::uint64_t> {};

TEST_P(OccludedBottleTest, IsGraspedOverTheClutterWithoutTouchingIt) {
  const BrainRun run = RunWithBrain(kScenarios / "hard" / "h5_occluded_bottle.yaml", GetParam());
  EXPECT_TRUE(run.result.verdict.success) << twin::FormatVerdict(run.result.verdict);
  for (const auto& e : run.world->events())
    EXPECT_FALSE(e.kind == "contact" && e.subject == "books") << e.t << " " << e.detail;
}

INSTANTIATE_TEST_SUITE_P(Hard, OccludedBottleTest, ::testing::Values(1u, 2005u));

TEST(ScenarioTest, HardNarrowCorridorIsFoundAndPassed) {
  const BrainRun run = RunWithBrain(kScenarios / "hard" / "h3_narrow_corridor.yaml", 1);
  EXPECT_TRUE(run.result.verdict.success) << twin::FormatVerdict(run.result.verdict);
}

// A scenario whose mission names `tree_xml` (written next to it).
std::string LoadError(const std::string& tree_xml, const std::string& mission_extra = "") {
  const auto dir =
      std::filesystem::temp_directory_path() /
      ("egress_scenario_" +
       std::to_string(::testing::UnitTest::GetInstance()->current_test_info()->line()));
  std::filesystem::create_directories(dir);
  const auto tree = dir / "tree.xml";
  if (!tree_xml.empty()) std::ofstream(tree) << tree_xml;
  const auto file = dir / "scenario.yaml";
  std::ofstream(file) << "world: " << EGRESS_WORLDS_DIR << "/lab/lab.sdf\n"
                      << "robot: {start: {x: 0, y: 1}}\n"
                      << "mission:\n  tree: tree.xml\n"
                      << mission_extra;
  try {
    const twin::Scenario scenario = twin::LoadScenario(file);
    const twin::WorldDescription description = twin::LoadSdfWorld(scenario.world_file);
    auto model = std::make_shared<const RobotModel>(RobotModel::LoadDefault());
    twin::TwinWorld world(scenario, description, 1, model);
    const behavior::ExecutiveConfig config;
    apps::MakeScenarioExecutive(scenario, description, world, model, config);
  } catch (const std::exception& e) {
    std::filesystem::remove_all(dir);
    return e.what();
  }
  std::filesystem::remove_all(dir);
  return "";
}

TEST(ScenarioTest, AMissionWithAnUnknownNodeFailsNamingIt) {
  const std::string error = LoadError(
      "<root BTCPP_format=\"4\"><BehaviorTree ID=\"T\"><Sequence>\n"
      "<IsPathClear door=\"lab_door\"/>\n<OpenDoorByMagic door=\"lab_door\"/>\n"
      "</Sequence></BehaviorTree></root>");
  EXPECT_NE(error.find("OpenDoorByMagic"), std::string::npos) << error;
  EXPECT_NE(error.find("tree.xml"), std::string::npos) << error;
}

TEST(ScenarioTest, AMissingTreeFileOrABadFieldFailsNamingTheField) {
  const std::string missing = LoadError("");
  EXPECT_NE(missing.find("mission.tree"), std::string::npos) << missing;
  EXPECT_NE(missing.find("no such file"), std::string::npos) << missing;
  const std::string bad = LoadError(
      "<root BTCPP_format=\"4\"><BehaviorTree ID=\"T\"><AlwaysSuccess/></BehaviorTree></root>",
      "  blackbord: {door: lab_door}\n");
  EXPECT_NE(bad.find("mission.blackbord"), std::string::npos) << bad;
  EXPECT_NE(bad.find("unknown field"), std::string::npos) << bad;
}

// The head camera's 3D map is what keeps the robot from under a table the base laser sees as
// four legs: with it disconnected, the same run drives into the table top.
TEST(ScenarioTest, OverhangTableOnTheRouteIsSeenInThreeDimensionsAndGoneRound) {
  const BrainRun run = RunWithBrain(kScenarios / "overhang" / "o1_table_on_route.yaml", 1);
  EXPECT_TRUE(run.result.verdict.success) << twin::FormatVerdict(run.result.verdict);
  ASSERT_NE(run.brain->octomap(), nullptr);
  EXPECT_FALSE(run.brain->octomap()->ProjectObstacles().empty());

  behavior::ExecutiveConfig laser_only;
  laser_only.use_octomap = false;
  const BrainRun blind =
      RunWithBrain(kScenarios / "overhang" / "o1_table_on_route.yaml", 1, laser_only);
  EXPECT_EQ(blind.brain->octomap(), nullptr);
  EXPECT_FALSE(blind.result.verdict.success);
  EXPECT_GT(blind.result.verdict.metrics.contacts_with.count("table_top"), 0u)
      << twin::FormatVerdict(blind.result.verdict);
}

TEST(ScenarioTest, OverhangTableIsPassedCarryingTheBottle) {
  const BrainRun run = RunWithBrain(kScenarios / "overhang" / "o2_carry_past_table.yaml", 1);
  EXPECT_TRUE(run.result.verdict.success) << twin::FormatVerdict(run.result.verdict);
  EXPECT_EQ(run.world->held_payload(), "bottle");
  // The planner checked the robot's outline with the bottle in it.
  bool has_payload = false;
  for (const auto& s : run.brain->body_shapes())
    has_payload = has_payload || s.shape.name == "held_payload";
  EXPECT_TRUE(has_payload);
}

// The fault variants (issue 19): each injected fault happens in the run, and the brain either
// completes or gives up by itself, with a reason, standing still; nobody is touched.
class FaultScenarioTest : public ::testing::TestWithParam<const char*> {};

TEST_P(FaultScenarioTest, CompletesOrAbortsSafelyWithAReason) {
  const BrainRun run = RunWithBrain(kScenarios / "hard" / GetParam(), 1);
  const twin::RunMetrics& m = run.result.verdict.metrics;
  EXPECT_EQ(m.contacts.count("person") ? m.contacts.at("person") : 0, 0);
  // Every fault drawn for the run began before it ended.
  ASSERT_FALSE(run.world->faults().empty());
  for (const auto& f : run.world->faults())
    EXPECT_LT(f.start, run.world->time()) << twin::ToString(f.spec->kind);
  if (run.result.verdict.success) return;
  EXPECT_EQ(run.brain->status(), bt::NodeStatus::kFailure)
      << twin::FormatVerdict(run.result.verdict);
  ASSERT_GE(run.brain->decisions().size(), 2u);
  EXPECT_EQ(run.brain->decisions().back().text, "mission failed");
}

INSTANTIATE_TEST_SUITE_P(Hard, FaultScenarioTest,
                         ::testing::Values("h6_laser_dropout.yaml", "h7_camera_blackout.yaml",
                                           "h8_odometry_slip_kidnap.yaml",
                                           "h9_door_closes_early.yaml", "h10_door_refuses.yaml",
                                           "h11_grasp_slip.yaml"));

// H8 seed 2015: the kidnap leaves the estimate 0.30 m and 4 deg off; from there the door's leaf
// read as a person in the door zone, and the robot, standing, never corrected (it waited out
// the time limit). The scan's fit at the estimate drops, the localizer finds the pose it fits
// and relocalizes, and the run completes.
TEST(ScenarioTest, AKidnappedRobotRelocalizesAndCompletes) {
  const BrainRun run = RunWithBrain(kScenarios / "hard" / "h8_odometry_slip_kidnap.yaml", 2015);
  EXPECT_TRUE(run.result.verdict.success) << twin::FormatVerdict(run.result.verdict);
  int relocalized = 0;
  for (const auto& d : run.brain->decisions())
    relocalized += d.text.find("relocalized there") != std::string::npos ? 1 : 0;
  EXPECT_EQ(relocalized, 1);
}

TEST(ScenarioTest, ASlippedPayloadStopsTheCarryNamingIt) {
  const BrainRun run = RunWithBrain(kScenarios / "hard" / "h11_grasp_slip.yaml", 1);
  EXPECT_FALSE(run.result.verdict.success);
  bool named = false;
  for (const auto& d : run.brain->decisions())
    named |= d.text.find("the payload is not in the gripper") != std::string::npos;
  EXPECT_TRUE(named);
  int slips = 0;
  for (const auto& e : run.world->events())
    slips += e.kind == "fault" && e.subject == "grasp_slip" ? 1 : 0;
  EXPECT_EQ(slips, 1);
}

// A laser that stays silent: the base is held still at once, and after 10 s the mission is
// given up, naming the laser, with the robot standing.
TEST(ScenarioTest, ALaserThatStaysSilentStopsTheRobotThenTheMission) {
  const auto file = std::filesystem::temp_directory_path() /
                    ("egress_laser_silent_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(file)
      << "name: laser dies\nworld: " << (kScenarios.parent_path() / "lab/lab.sdf").string()
      << "\ntime_limit: 60\nrobot:\n  start: {x: 0.0, y: 1.0, yaw_deg: 90}\n"
         "  goal: {place: room_north}\ndoors: [{door: lab_door, operator: push}]\n"
         "faults: [{kind: laser_dropout, start: 2.0, duration: 100.0}]\n"
         "mission:\n  tree: "
      << (kScenarios.parent_path().parent_path() / "behavior/trees/go_to.xml").string()
      << "\n  blackboard: {max_yields: \"5\"}\nsuccess: [reach_goal, no_person_contact]\n";
  const BrainRun run = RunWithBrain(file, 1);
  std::filesystem::remove(file);
  EXPECT_FALSE(run.result.verdict.success);
  EXPECT_EQ(run.brain->status(), bt::NodeStatus::kFailure);
  EXPECT_NEAR(run.world->time(), 2.0 + 10.0, 0.3);
  bool named = false;
  for (const auto& d : run.brain->decisions())
    named |= d.text.find("laser has been silent") != std::string::npos;
  EXPECT_TRUE(named);
  const Twist2 V = run.world->robot_velocity();
  EXPECT_LT(std::hypot(V.vx, V.vy), 0.02);
}

TEST(ScenarioTest, HardPersonFromBehindTheLeafIsYieldedTo) {
  const BrainRun run = RunWithBrain(kScenarios / "hard" / "h12_person_behind_leaf.yaml", 1);
  EXPECT_TRUE(run.result.verdict.success) << twin::FormatVerdict(run.result.verdict);
  EXPECT_FALSE(run.brain->preemptions().empty());
}

}  // namespace
}  // namespace egress
