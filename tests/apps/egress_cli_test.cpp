// Runs the real `egress` program as a user would and checks what it prints and returns.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "navigation_server.h"
#include "test_paths.h"

namespace {

using ::testing::HasSubstr;
using ::testing::Not;

struct Result {
  int exit_code;
  std::string output;  // stdout and stderr
};

Result RunEgress(const std::string& arguments) {
  const std::string command = std::string(EGRESS_CLI_PATH) + " " + arguments + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return {-1, "popen failed"};
  std::string output;
  std::array<char, 4096> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr)
    output += buffer.data();
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

TEST(EgressCliTest, VersionListsEveryModulesLibraries) {
  const Result result = RunEgress("--version");
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("egress 0.1.0"));
  for (const char* library : {"Eigen", "urdfdom", "Bullet", "sdformat", "assimp", "OpenCV",
                              "OctoMap", "OMPL", "FCL", "tinyxml2", "gRPC", "ZeroMQ"}) {
    EXPECT_THAT(result.output, HasSubstr(library));
  }
  EXPECT_THAT(result.output, HasSubstr("double precision"));
}

TEST(EgressCliTest, ModelFkPrintsPalmPoseAsJson) {
  const Result result = RunEgress("model fk --arm 0 -1.5707963267948966 --json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const auto json = nlohmann::json::parse(result.output);
  const auto xyz = json.at("X_MG").at("xyz");
  EXPECT_NEAR(xyz[0].get<double>(), 0.627, 1e-3);
  EXPECT_NEAR(xyz[1].get<double>(), 0.078, 1e-3);
  EXPECT_NEAR(xyz[2].get<double>(), 0.323, 1e-3);
  EXPECT_TRUE(json.at("within_limits").get<bool>());
}

TEST(EgressCliTest, ModelInfoTable) {
  const Result result = RunEgress("model info");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("footprint radius      0.215 m"));
  EXPECT_THAT(result.output, HasSubstr("arm_flex_joint"));
}

TEST(EgressCliTest, ClearErrors) {
  Result result = RunEgress("model info --urdf /nonexistent.urdf");
  EXPECT_NE(result.exit_code, 0);
  EXPECT_THAT(result.output, HasSubstr("/nonexistent.urdf"));

  result = RunEgress("model fk --arm 0 nan");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.output, HasSubstr("arm_flex_joint"));

  result = RunEgress("sim batch");
  EXPECT_NE(result.exit_code, 0);
  EXPECT_THAT(result.output, HasSubstr("scenarios is required"));

  result = RunEgress("no-such-command");
  EXPECT_NE(result.exit_code, 0);
}

// Found by probing (kept as regression tests): values that were accepted silently (a run of
// NaN seconds, a batch of 2e9 trials that allocated gigabytes before any ran) are refused by
// name before anything runs; CLI11's own range checks let NaN through.
TEST(EgressCliTest, BadNumbersAreRefusedByName) {
  const std::string s1 = (std::filesystem::path(EGRESS_OFFICE_MAP).parent_path().parent_path() /
                          "scenarios/s1_nominal.yaml")
                             .string();
  for (const char* duration : {"0", "-1", "nan", "inf", "1e300", "abc"}) {
    const Result result = RunEgress("sim run " + s1 + " --duration " + duration);
    EXPECT_NE(result.exit_code, 0) << duration;
    EXPECT_THAT(result.output, HasSubstr("--duration")) << duration;
  }
  Result result = RunEgress("sim batch " + s1 + " --trials 2000000000");
  EXPECT_NE(result.exit_code, 0);
  EXPECT_THAT(result.output, HasSubstr("--trials"));
  result = RunEgress("sim batch " + s1 + " --jobs 0");
  EXPECT_THAT(result.output, HasSubstr("--jobs"));
  result = RunEgress("costmap --robot-radius nan");
  EXPECT_THAT(result.output, HasSubstr("--robot-radius"));
  result = RunEgress("twin serve --ros2 " + s1 + " --speed nan");
  EXPECT_THAT(result.output, HasSubstr("--speed"));
}

// ---- egress bt

// Scratch files written by the tests, removed when the test program ends.
struct TempFiles {
  std::vector<std::filesystem::path> paths;
  ~TempFiles() {
    std::error_code ignored;
    for (const auto& path : paths)
      std::filesystem::remove(path, ignored);
  }
};

std::string WriteTemp(const std::string& name, const std::string& text) {
  static TempFiles written;
  const auto path = egress::testing::TestTempPath(name);
  std::ofstream(path) << text;
  written.paths.push_back(path);
  return path.string();
}

const char* kDoorTree = R"(<root BTCPP_format="4">
  <BehaviorTree ID="Door">
    <ReactiveSequence>
      <IsPathClear/>
      <Fallback>
        <IsDoorOpen/>
        <PressButton stroke="0.004"/>
      </Fallback>
      <TraverseDoor/>
    </ReactiveSequence>
  </BehaviorTree>
</root>)";

TEST(EgressCliTest, BtValidateListsUnknownNodes) {
  const std::string tree = WriteTemp("door.xml", kDoorTree);
  const Result result = RunEgress("bt validate " + tree);
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_THAT(result.output, HasSubstr("door.xml:4: unknown node type 'IsPathClear'"));
  EXPECT_THAT(
      result.output,
      HasSubstr("unknown node types (4): IsPathClear, IsDoorOpen, PressButton, TraverseDoor"));

  const std::string ok = WriteTemp("ok.xml",
                                   "<root BTCPP_format='4'><BehaviorTree ID='A'><AlwaysSuccess/>"
                                   "</BehaviorTree></root>");
  const Result valid = RunEgress("bt validate " + ok);
  EXPECT_EQ(valid.exit_code, 0) << valid.output;
  EXPECT_THAT(valid.output, HasSubstr("OK"));

  const std::string broken = WriteTemp("broken.xml",
                                       "<root BTCPP_format='4'>\n<BehaviorTree ID='A'>\n<Repeat>"
                                       "<AlwaysSuccess/></Repeat></BehaviorTree></root>");
  const Result bad = RunEgress("bt validate " + broken);
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_THAT(bad.output,
              HasSubstr("broken.xml:3: node 'Repeat': missing required port 'num_cycles'"));
}

TEST(EgressCliTest, BtTracePrintsTransitionsTickByTick) {
  const std::string tree = WriteTemp("door.xml", kDoorTree);
  const std::string script = WriteTemp("door.yaml", R"(tick_period_ms: 100
max_ticks: 10
default: SUCCESS
ticks:
  - outcomes: {IsDoorOpen: FAILURE, PressButton: SUCCESS, TraverseDoor: RUNNING}
  - outcomes: {IsPathClear: FAILURE}
  - outcomes: {IsDoorOpen: SUCCESS, TraverseDoor: SUCCESS}
)");
  const Result result = RunEgress("bt trace " + tree + " --script " + script);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output,
              HasSubstr("stand-ins: IsPathClear, IsDoorOpen, PressButton, TraverseDoor"));
  EXPECT_THAT(result.output, HasSubstr("tick 2 (t = 100 ms)"));
  EXPECT_THAT(result.output,
              ::testing::ContainsRegex("TraverseDoor::6 +RUNNING -> IDLE"));  // preempted
  EXPECT_THAT(result.output, HasSubstr("result: FAILURE after 2 ticks"));

  const Result json = RunEgress("bt trace " + tree + " --script " + script + " --json");
  ASSERT_EQ(json.exit_code, 0) << json.output;
  const auto parsed = nlohmann::json::parse(json.output);
  EXPECT_EQ(parsed.at("result"), "FAILURE");
  EXPECT_EQ(parsed.at("ticks").size(), 2u);
  // Every blackboard after each tick, as Groot2 shows them (the main tree's under "").
  EXPECT_TRUE(parsed.at("ticks").at(0).at("blackboard").contains(""));

  // --ticks N runs exactly N ticks, the root starting over after it completes.
  const Result exact =
      RunEgress("bt trace " + tree + " --script " + script + " --ticks 5 --format btcpp");
  ASSERT_EQ(exact.exit_code, 0) << exact.output;
  EXPECT_THAT(exact.output, HasSubstr("tick 2 -> FAILURE"));
  EXPECT_THAT(exact.output, HasSubstr("tick 5 -> "));
  EXPECT_THAT(exact.output, HasSubstr("halt TraverseDoor::6 TraverseDoor\n"
                                      "status TraverseDoor::6 TraverseDoor RUNNING -> IDLE"));
}

TEST(EgressCliTest, BtTraceScriptErrorsNameTheLine) {
  const std::string tree = WriteTemp("door.xml", kDoorTree);
  const std::string bad_status =
      WriteTemp("bad.yaml", "ticks:\n  - outcomes: {PressButton: DONE}\n");
  Result result = RunEgress("bt trace " + tree + " --script " + bad_status);
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.output,
              HasSubstr("bad.yaml:2: outcome of 'PressButton': 'DONE' is not an outcome"));
  const std::string bad_key = WriteTemp("key.yaml", "tick_period: 100\n");
  result = RunEgress("bt trace " + tree + " --script " + bad_key);
  EXPECT_THAT(result.output, HasSubstr("key.yaml:1: unknown field 'tick_period'"));
  const std::string bad_node =
      WriteTemp("node.yaml", "ticks:\n  - outcomes: {OpenDoor: SUCCESS}\n");
  result = RunEgress("bt trace " + tree + " --script " + bad_node);
  EXPECT_THAT(result.output, HasSubstr("no node is named 'OpenDoor'"));
}

// ---- egress costmap

// A 4 m x 2 m room split by a wall with a 1 m door at y in [0.5, 1.5] (x = 2).
std::filesystem::path WriteRoomMap() {
  const auto dir = egress::testing::TestTempPath("room");
  std::filesystem::create_directories(dir);
  {
    std::ofstream pgm(dir / "map.pgm", std::ios::binary);
    pgm << "P5\n80 40\n255\n";
    for (int row = 0; row < 40; ++row) {
      for (int col = 0; col < 80; ++col) {
        const bool wall =
            row < 1 || row > 38 || col < 1 || col > 78 || (col == 40 && (row < 10 || row > 29));
        pgm.put(static_cast<char>(wall ? 0 : 254));
      }
    }
  }
  std::ofstream(dir / "map.yaml") << "image: map.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\n";
  return dir;
}

// Images are written by a module opened on first use (perception/image_io.h): one that cannot be
// loaded is an error naming where it was looked for, not a crash; nothing else needs it.
TEST(EgressCliTest, AnImageModuleThatCannotBeLoadedIsAClearError) {
  const auto dir = WriteRoomMap();
  const std::string out = (dir / "costmap.png").string();
  std::filesystem::remove(out);
  ASSERT_EQ(setenv("EGRESS_IMAGE_IO_MODULE", "/nonexistent/libegress_image_io.so", 1), 0);
  const Result result = RunEgress("costmap " + (dir / "map.yaml").string() + " --out " + out);
  const Result version = RunEgress("--version");
  unsetenv("EGRESS_IMAGE_IO_MODULE");
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_THAT(result.output, HasSubstr("cannot load egress's image module"));
  EXPECT_THAT(result.output, HasSubstr("/nonexistent/libegress_image_io.so"));
  EXPECT_THAT(result.output, HasSubstr("EGRESS_IMAGE_IO_MODULE"));
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_EQ(version.exit_code, 0) << version.output;
  std::filesystem::remove_all(dir);
}

TEST(EgressCliTest, CostmapRendersAPng) {
  const auto dir = WriteRoomMap();
  const std::string out = (dir / "costmap.png").string();
  std::filesystem::remove(out);
  const std::string args =
      "costmap " + (dir / "map.yaml").string() + " --out " + out + " --doorway 2.0 0.5 2.0 1.5";
  Result result = RunEgress(args);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("costmap 80x40 cells at 0.050 m"));
  EXPECT_THAT(result.output, HasSubstr("1 doorways"));
  EXPECT_GT(std::filesystem::file_size(out), 100u);
  result = RunEgress(args);  // never overwrite without asking
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.output, HasSubstr("pass --overwrite"));
  result = RunEgress("costmap " + (dir / "map.yaml").string() + " --out " + out +
                     " --overwrite --doorway 1 2 3");
  EXPECT_NE(result.exit_code, 0);
  std::ofstream(dir / "bad.yaml") << "image: map.pgm\nresolution: fine\norigin: [0, 0, 0]\n";
  result = RunEgress("costmap " + (dir / "bad.yaml").string() + " --out " + out + " --overwrite");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.output, HasSubstr("bad.yaml:2: field 'resolution' (fine) must be a number"));
  std::filesystem::remove_all(dir);
}

// ---- egress plan

TEST(EgressCliTest, PlanLocallyAndThroughTheService) {
  const auto dir = WriteRoomMap();
  const std::string common = "plan --map " + (dir / "map.yaml").string() +
                             " --start 0.6 1.0 0 --goal 3.4 1.0 0 --door D:2.0,0.5,2.0,1.5";
  Result local = RunEgress(common + " --local --json");
  ASSERT_EQ(local.exit_code, 0) << local.output;
  auto json = nlohmann::json::parse(local.output);
  EXPECT_EQ(json.at("status"), "success");
  EXPECT_EQ(json.at("doors_crossed")[0], "D");
  EXPECT_GT(json.at("length").get<double>(), 2.7);

  Result closed = RunEgress(common + " --local --closed D");
  EXPECT_EQ(closed.exit_code, 1);
  EXPECT_THAT(closed.output, HasSubstr("goal_unreachable"));

  egress::navd::NavigationServerConfig config;
  config.listen = "127.0.0.1:0";
  egress::navd::NavigationServer server(config);
  const std::string png = (dir / "path.png").string();
  Result remote =
      RunEgress(common + " --server 127.0.0.1:" + std::to_string(server.port()) + " --png " + png);
  ASSERT_EQ(remote.exit_code, 0) << remote.output;
  EXPECT_THAT(remote.output, HasSubstr("status         success"));
  EXPECT_THAT(remote.output, HasSubstr("doors crossed  D"));
  EXPECT_GT(std::filesystem::file_size(png), 100u);

  Result in_wall = RunEgress(
      "plan --map " + (dir / "map.yaml").string() +
      " --start 2.0 0.1 0 --goal 3.4 1.0 0 --server 127.0.0.1:" + std::to_string(server.port()));
  EXPECT_EQ(in_wall.exit_code, 1);
  EXPECT_THAT(in_wall.output, HasSubstr("in collision"));
  Result no_server = RunEgress(common + " --server 127.0.0.1:1");
  EXPECT_EQ(no_server.exit_code, 1);
  EXPECT_THAT(no_server.output, HasSubstr("127.0.0.1:1"));
  std::filesystem::remove_all(dir);
}

TEST(EgressCliTest, PlanOnAnSdfWorldFindsItsDoors) {
  const std::string office =
      (std::filesystem::path(EGRESS_OFFICE_MAP).parent_path() / "office.sdf").string();
  Result local =
      RunEgress("plan --map " + office + " --start 1.5 4.5 0 --goal 12.5 1.5 0 --local --json");
  ASSERT_EQ(local.exit_code, 0) << local.output;
  const auto json = nlohmann::json::parse(local.output);
  EXPECT_EQ(json.at("doors_crossed"), nlohmann::json::array({"door_a", "door_b"}));
  Result closed = RunEgress("plan --map " + office +
                            " --start 1.5 4.5 0 --goal 12.5 1.5 0 --local --closed door_a");
  EXPECT_EQ(closed.exit_code, 1);
  EXPECT_THAT(closed.output, HasSubstr("goal_unreachable"));
}

// ---- egress sim / render

TEST(EgressCliTest, SimRunsAScenarioWritesVerdictTraceAndPictures) {
  const std::string scenario =
      (std::filesystem::path(EGRESS_OFFICE_MAP).parent_path().parent_path() /
       "lab/lab_hold_door.yaml")
          .string();
  const auto dir = egress::testing::TestTempPath("sim");
  std::filesystem::create_directories(dir);
  const std::string outputs = " --trace " + (dir / "run.jsonl").string() + " --json " +
                              (dir / "verdict.json").string() + " --png " +
                              (dir / "run.png").string();
  // The dead-reckoning baseline passes the held door: the verdict table says so, exit 0.
  Result run =
      RunEgress("sim run " + scenario + " --driver dead-reckoning --duration 25" + outputs);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("SUCCESS"));
  EXPECT_THAT(run.output, HasSubstr("PASS  door_open_when_crossed:lab_door"));
  EXPECT_THAT(run.output, HasSubstr("person_holding_door"));
  const auto verdict = nlohmann::json::parse(std::ifstream(dir / "verdict.json"));
  EXPECT_TRUE(verdict.at("success").get<bool>());
  EXPECT_EQ(verdict.at("metrics").at("crossings").size(), 1u);
  EXPECT_GT(std::filesystem::file_size(dir / "run.png"), 1000u);
  // Same seed, same trace; outputs are never overwritten without --overwrite.
  Result again =
      RunEgress("sim run " + scenario + " --driver dead-reckoning --duration 25" + outputs);
  EXPECT_EQ(again.exit_code, 1);
  EXPECT_THAT(again.output, HasSubstr("--overwrite"));
  const auto trace_text = [&] {
    std::ifstream in(dir / "run.jsonl");
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const std::string first = trace_text();
  Result rerun = RunEgress("sim run " + scenario +
                           " --driver dead-reckoning --duration 25 --overwrite -q" + outputs);
  ASSERT_EQ(rerun.exit_code, 0) << rerun.output;
  EXPECT_EQ(trace_text(), first);
  // Standing still, the robot never reaches the goal: FAIL lines and exit 1.
  Result idle = RunEgress("sim run " + scenario + " --duration 5 -q");
  EXPECT_EQ(idle.exit_code, 1);
  EXPECT_THAT(idle.output, HasSubstr("FAIL  reach_goal"));
  // egress render: the trace to a PNG; a bad trace names its line.
  Result render = RunEgress("render " + (dir / "run.jsonl").string() + " --out " +
                            (dir / "again.png").string());
  ASSERT_EQ(render.exit_code, 0) << render.output;
  EXPECT_GT(std::filesystem::file_size(dir / "again.png"), 1000u);
  std::ofstream(dir / "bad.jsonl") << first.substr(0, first.find('\n') + 1) << "{not json\n";
  Result bad =
      RunEgress("render " + (dir / "bad.jsonl").string() + " --out " + (dir / "bad.png").string());
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_THAT(bad.output, HasSubstr("bad.jsonl:2"));
  Result broken = RunEgress("sim run " + (dir / "verdict.json").string());
  EXPECT_EQ(broken.exit_code, 1);
  EXPECT_THAT(broken.output, HasSubstr("verdict.json"));
  std::filesystem::remove_all(dir);
}

// ---- egress sim batch

const std::string kWorldsDir =
    std::filesystem::path(EGRESS_OFFICE_MAP).parent_path().parent_path().string();

// The lab with one evacuee, who sets off at 1 s to go out through lab_door, and the escort.
// `mobility`: the evacuee's mobility mix (YAML flow map), if any.
std::string WriteOneResidentLab(const std::string& name, double time_limit,
                                const std::string& mobility = "") {
  return WriteTemp(name, R"(name: lab, one resident
world: )" + kWorldsDir + R"(/lab/lab.sdf
seed: 1
time_limit: )" + std::to_string(time_limit) +
                             R"(
robot:
  start: {x: 1.6, y: 1.9, yaw_deg: 90}
  goal: {x: 1.8, y: 5.2}
doors:
  - door: lab_door
    operator: push
people:
  - name: resident
    behavior: evacuate
    route: [lab_door]
    start: {x: -1.5, y: 0.4}
    goal: {x: -1.5, y: 6.0}
)" + (mobility.empty() ? "" : "    mobility: " + mobility + "\n") +
                             R"(    trigger: {at: 1.0}
mission:
  tree: )" + kWorldsDir + R"(/../behavior/trees/evacuation_escort.xml
)");
}

TEST(EgressCliTest, SimRunWithTheBrainPrintsDecisionsAndTracesTheRunningAction) {
  const auto dir = egress::testing::TestTempPath("brain");
  std::filesystem::create_directories(dir);
  const std::string scenario = kWorldsDir + "/scenarios/s3_held_door.yaml";
  Result run = RunEgress("sim run " + scenario + " --trace " + (dir / "run.jsonl").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("driver brain"));
  EXPECT_THAT(run.output, HasSubstr("traverse_open started"));
  EXPECT_THAT(run.output, HasSubstr("mission succeeded"));
  std::ifstream in(dir / "run.jsonl");
  const std::string trace((std::istreambuf_iterator<char>(in)), {});
  EXPECT_THAT(trace, HasSubstr("\"label\":\"traverse_open\""));
  EXPECT_THAT(trace, HasSubstr("\"path\":[["));
  // The person holding the door, in the costmap snapshots' proxemic layer.
  EXPECT_THAT(trace, HasSubstr("\"personal\":["));
  std::filesystem::remove_all(dir);
}

TEST(EgressCliTest, TheCrowdsRatesAreOptionsOfSimRunAndEvacStudy) {
  const auto dir = egress::testing::TestTempPath("social_rate");
  std::filesystem::create_directories(dir);
  const std::string scenario = kWorldsDir + "/scenarios/evacuation/lab_escort.yaml";
  // The residents set off at 25 s: by 35 s the held social terms have moved them otherwise.
  const auto hash = [&](const std::string& extra, const std::string& name) {
    const Result run = RunEgress("sim run " + scenario + " --duration 35 -q --trace " +
                                 (dir / name).string() + extra);
    const std::size_t at = run.output.find("hash ");
    EXPECT_NE(at, std::string::npos) << run.output;
    return at == std::string::npos ? std::string() : run.output.substr(at, 21);
  };
  const std::string every = hash("", "every.jsonl");
  EXPECT_EQ(hash(" --crowd-social-rate 120", "every_again.jsonl"), every);  // the default
  EXPECT_NE(hash(" --crowd-social-rate 60", "held.jsonl"), every);
  EXPECT_EQ(hash(" --crowd-rate 120", "crowd_default.jsonl"), every);  // the default
  EXPECT_NE(hash(" --crowd-rate 240", "crowd_240.jsonl"), every);
  for (const std::string& command :
       {"sim run " + scenario + " -q",
        "evac study " + scenario + " -q --trials 1 --out " + (dir / "study").string()}) {
    const Result bad = RunEgress(command + " --crowd-social-rate 480");
    EXPECT_NE(bad.exit_code, 0) << command;
    EXPECT_THAT(bad.output, HasSubstr("--crowd-social-rate")) << command;
    EXPECT_THAT(bad.output, HasSubstr("240")) << command;  // at most the physics rate
    const Result not_a_divisor = RunEgress(command + " --crowd-rate 100");
    EXPECT_NE(not_a_divisor.exit_code, 0) << command;
    EXPECT_THAT(not_a_divisor.output, HasSubstr("crowd_rate_hz")) << command;
    const Result above_crowd = RunEgress(command + " --crowd-rate 120 --crowd-social-rate 240");
    EXPECT_NE(above_crowd.exit_code, 0) << command;
    EXPECT_THAT(above_crowd.output, HasSubstr("crowd_social_rate_hz")) << command;
  }
  std::filesystem::remove_all(dir);
}

TEST(EgressCliTest, EvacStudyComparesTheThreeConditionsOnTheSameSeeds) {
  const auto dir = egress::testing::TestTempPath("study");
  const std::string scenario = kWorldsDir + "/scenarios/evacuation/lab_escort.yaml";
  Result two = RunEgress("evac study " + scenario + " --trials 1 --jobs 2 -q --out " +
                         (dir / "two").string());
  ASSERT_EQ(two.exit_code, 0) << two.output;
  for (const char* c : {"no_robot", "robot", "propped_open"})
    EXPECT_THAT(two.output, HasSubstr(c));
  EXPECT_THAT(two.output, HasSubstr("lab_door"));
  const auto study = nlohmann::json::parse(std::ifstream(dir / "two" / "study.json"));
  ASSERT_EQ(study.at("conditions").size(), 3u);
  std::map<std::string, nlohmann::json> by;
  for (const auto& c : study.at("conditions"))
    by[c.at("condition").get<std::string>()] = c;
  // Everyone out in every condition; doors propped open are the fastest (the upper bound), and
  // nobody is out faster than with them.
  for (const auto& [name, c] : by) {
    EXPECT_EQ(c.at("left_behind").get<int>(), 0) << name;
    // Only the door on the route: waits count for the door waited for.
    ASSERT_EQ(c.at("doors").size(), 1u) << name << ": " << c.at("doors").dump();
    EXPECT_TRUE(c.at("doors").contains("lab_door")) << name;
  }
  // Who opened the door: without the robot, residents (it starts shut); escorting, the robot
  // presses it on arriving; propped open, nobody.
  const auto opened = [&](const std::string& c, const char* key) {
    return by[c].at("doors").at("lab_door").at(key).get<double>();
  };
  EXPECT_GE(opened("no_robot", "operated_by_residents_median"), 1.0);
  EXPECT_EQ(opened("no_robot", "operated_by_robot_median"), 0.0);
  EXPECT_GE(opened("robot", "operated_by_robot_median"), 1.0);
  EXPECT_EQ(opened("propped_open", "operated_by_residents_median"), 0.0);
  EXPECT_EQ(opened("propped_open", "operated_by_robot_median"), 0.0);
  EXPECT_LE(by["propped_open"].at("t_evac_median_s").get<double>(),
            by["no_robot"].at("t_evac_median_s").get<double>());
  EXPECT_EQ(by["robot"].at("contacts").get<int>(), 0);
  // The brain's belief against the truth: the robot's alone (no brain, no belief otherwise).
  const auto& localization = by["robot"].at("localization_error");
  ASSERT_TRUE(localization.is_object()) << by["robot"].dump();
  EXPECT_GT(localization.at("max_m").get<double>(), 0.0);  // odometry drifts, the scan corrects
  EXPECT_LT(localization.at("max_m").get<double>(), 0.2);
  EXPECT_EQ(localization.at("max_seed").get<std::uint64_t>(), 1u);
  EXPECT_TRUE(by["no_robot"].at("localization_error").is_null());
  EXPECT_THAT(two.output, HasSubstr("localization error (belief against truth): worst"));
  EXPECT_EQ(study.at("crowd_social_rate_hz").get<double>(), 120.0);  // every crowd step
  // What each buys over no robot, seed by seed: one seed, one pair, the difference of the times.
  EXPECT_TRUE(by["no_robot"].at("vs_no_robot").is_null());
  for (const char* c : {"robot", "propped_open"}) {
    const auto& vs = by[c].at("vs_no_robot");
    ASSERT_TRUE(vs.is_object()) << c;
    EXPECT_EQ(vs.at("pairs").get<int>(), 1) << c;
    EXPECT_NEAR(vs.at("t_evac_diff_median_s").get<double>(),
                by[c].at("t_evac_median_s").get<double>() -
                    by["no_robot"].at("t_evac_median_s").get<double>(),
                1e-9)
        << c;
  }
  EXPECT_THAT(two.output, HasSubstr("vs no_robot, same seeds"));
  EXPECT_TRUE(std::filesystem::exists(dir / "two" / "evacuated.png"));
  // The same with one worker: the results do not depend on the number of jobs.
  Result one = RunEgress("evac study " + scenario + " --trials 1 --jobs 1 -q --out " +
                         (dir / "one").string());
  ASSERT_EQ(one.exit_code, 0) << one.output;
  const auto read = [&](const std::string& run) {
    std::ifstream in(dir / run / "trials.csv");
    return std::string((std::istreambuf_iterator<char>(in)), {});
  };
  EXPECT_EQ(read("one"), read("two"));
  // Never overwrites; refuses a scenario without evacuees, naming it.
  Result again =
      RunEgress("evac study " + scenario + " --trials 1 -q --out " + (dir / "one").string());
  EXPECT_EQ(again.exit_code, 1);
  EXPECT_THAT(again.output, HasSubstr("--overwrite"));
  Result none = RunEgress("evac study " + kWorldsDir + "/scenarios/s3_held_door.yaml -q --out " +
                          (dir / "x").string());
  EXPECT_EQ(none.exit_code, 1);
  EXPECT_THAT(none.output, HasSubstr("no people with behavior evacuate"));
  // One condition alone: the same rows as in the full study, the others absent.
  Result robot = RunEgress("evac study " + scenario + " --trials 1 -q --conditions robot --out " +
                           (dir / "robot").string());
  ASSERT_EQ(robot.exit_code, 0) << robot.output;
  const std::string rows = read("robot");
  EXPECT_THAT(rows, Not(HasSubstr("no_robot,")));
  EXPECT_THAT(robot.output, Not(HasSubstr("vs no_robot")));  // nothing to pair with
  const std::string full = read("one");
  const std::size_t at = full.find("\nrobot,");
  ASSERT_NE(at, std::string::npos);
  EXPECT_THAT(rows, HasSubstr(full.substr(at + 1, full.find('\n', at + 1) - at)));
  Result bad = RunEgress("evac study " + scenario + " -q --conditions nobody --out " +
                         (dir / "bad").string());
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_THAT(bad.output, HasSubstr("nobody"));
  std::filesystem::remove_all(dir);
}

// Trial seeds are seed-base + i: the last must be a seed a scenario may have (2^53), not wrap past
// 2^64 to 0 (it did: trials 18446744073709551615 and 0).
TEST(EgressCliTest, BatchesRefuseASeedBaseWhoseLastTrialIsPastTheLargestSeed) {
  const auto dir = egress::testing::TestTempPath("seed_base");
  const std::string lab = kWorldsDir + "/scenarios/evacuation/lab_escort.yaml";
  const std::string s1 = kWorldsDir + "/scenarios/s1_nominal.yaml";
  const std::string top = "9007199254740992";  // 2^53
  for (const std::string& command :
       {"sim batch " + s1 + " --trials 2 --seed-base " + top,
        "sim batch " + s1 + ":3 --seed-base 9007199254740991",
        "sim batch " + s1 + " --trials 1 --seed-base 18446744073709551615",
        "evac study " + lab + " --conditions no_robot --trials 2 --seed-base " + top}) {
    const Result bad = RunEgress(command + " -q --out " + (dir / "bad").string());
    EXPECT_EQ(bad.exit_code, 1) << command;
    EXPECT_THAT(bad.output, HasSubstr("--seed-base")) << command;
    EXPECT_THAT(bad.output, HasSubstr(top)) << command;
    EXPECT_FALSE(std::filesystem::exists(dir / "bad" / "trials.csv")) << command;
  }
  // One run's seed alike: a seed a scenario file may hold, so the run can be written down.
  const Result run = RunEgress("sim run " + s1 + " -q --seed 9007199254740993");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_THAT(run.output, HasSubstr("--seed"));
  EXPECT_THAT(run.output, HasSubstr(top));
  // The largest seed itself is a trial's.
  const Result last = RunEgress("sim batch " + s1 + " --trials 1 -q --seed-base " + top +
                                " --out " + (dir / "last").string());
  ASSERT_EQ(last.exit_code, 0) << last.output;
  std::ifstream csv(dir / "last" / "trials.csv");
  const std::string rows((std::istreambuf_iterator<char>(csv)), {});
  EXPECT_THAT(rows, HasSubstr("," + top + ","));
  std::filesystem::remove_all(dir);
}

// Who is left behind is named, with the door they wait at and since when (the seeds worth a
// look): a wheelchair user who cannot operate the lab's shut door waits at it to the time limit
// with no robot; one who can gets out.
TEST(EgressCliTest, EvacStudyNamesWhoIsLeftBehindAndTheDoorTheyWaitAt) {
  const auto dir = egress::testing::TestTempPath("study_left");
  const std::string scenario = WriteOneResidentLab("wheelchair_lab.yaml", 40.0, "{wheelchair: 1}");
  Result run = RunEgress("evac study " + scenario + " --trials 6 -q --conditions no_robot --out " +
                         (dir / "out").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto study = nlohmann::json::parse(std::ifstream(dir / "out" / "study.json"));
  const auto& c = study.at("conditions").at(0);
  const auto& people = c.at("left_behind_people");
  ASSERT_EQ(int(people.size()), c.at("left_behind").get<int>());
  ASSERT_GT(people.size(), 0u) << "no seed of six drew someone who cannot operate the door";
  ASSERT_LT(people.size(), 6u) << "no seed of six drew someone who can";
  for (const auto& p : people) {
    EXPECT_EQ(p.at("name"), "resident") << p.dump();
    EXPECT_EQ(p.at("mobility"), "wheelchair");
    EXPECT_FALSE(p.at("can_operate").get<bool>());
    EXPECT_EQ(p.at("phase"), "waiting_for_door");
    EXPECT_EQ(p.at("waiting_for"), "lab_door");
    EXPECT_GT(p.at("waiting_since_s").get<double>(), 1.0);  // after they set off
    EXPECT_LT(p.at("waiting_since_s").get<double>(), 40.0);
    EXPECT_LT(p.at("position")[1].get<double>(), 3.0);  // on the room's side of the door
    const std::string line =
        "seed " + std::to_string(p.at("seed").get<std::uint64_t>()) +
        ": resident (wheelchair, cannot operate doors), waiting for lab_door since";
    EXPECT_THAT(run.output, HasSubstr(line));
  }
  std::filesystem::remove_all(dir);
}

// The escort's sweep (evacuation_escort.xml): the robot starts in the clinic's corridor, its goal
// just past door_e (its route: door_e alone); a wheelchair user in room A sets off at 1 s for the
// same place through door_a and door_e. Seed 6 draws one who cannot operate door_a (the no-robot
// condition leaves them behind it). Before leaving by door_e the robot sweeps the rooms whose way
// out leaves by it, room A first (the farthest), opens door_a and holds door_e for them. Seed 5
// draws one who can, and reaches door_e after the robot's hold there has ended: the robot, at
// door_e's button beside the lane with nowhere to back off to, squeezes aside along the door line
// (RetractToSafe) so that they get between the leaf, opening towards them, and the robot. Stop
// 96's code left both behind.
TEST(EgressCliTest, TheEscortSweepsTheRoomsOffItsRouteAndLetsOutWhoeverWaitsBehindADoor) {
  const auto dir = egress::testing::TestTempPath("study_sweep");
  const std::string scenario = WriteTemp("room_a_wheelchair.yaml", R"(name: clinic, room A
world: )" + kWorldsDir + R"(/clinic/clinic.sdf
seed: 1
time_limit: 400
robot:
  start: {x: 18.0, y: 1.0, yaw_deg: 0}
  goal: {x: 21.0, y: 5.5, yaw_deg: 90}
people:
  - name: resident
    behavior: evacuate
    route: [door_a, door_e]
    start: {x: 4.0, y: 4.5}
    goal: {x: 21.0, y: 6.5}
    mobility: {wheelchair: 1}
    trigger: {at: 1.0}
mission:
  tree: )" + kWorldsDir + R"(/../behavior/trees/evacuation_escort.xml
  blackboard: {max_yields: "30", clear_for: "3", wait_for: "5", keep_clear: "3.5"}
)");
  Result run = RunEgress("evac study " + scenario +
                         " --trials 2 --seed-base 5 -q --conditions robot no_robot --out " +
                         (dir / "out").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto study = nlohmann::json::parse(std::ifstream(dir / "out" / "study.json"));
  const auto condition = [&](const std::string& name) {
    for (const auto& c : study.at("conditions"))
      if (c.at("condition") == name) return c;
    ADD_FAILURE() << "no condition " << name << " in study.json";
    return nlohmann::json::object();
  };
  const nlohmann::json robot = condition("robot"), alone = condition("no_robot");
  ASSERT_EQ(alone.value("left_behind", -1), 1)
      << "seeds 5 and 6 no longer draw one who can and one who cannot operate door_a";
  EXPECT_EQ(alone.at("left_behind_people").at(0).at("waiting_for"), "door_a");
  EXPECT_EQ(robot.value("left_behind", -1), 0) << run.output;
  EXPECT_EQ(robot.at("contacts").get<int>(), 0);
  EXPECT_EQ(robot.at("obstacle_contacts").get<int>(), 0);  // no wall or leaf touched either
  EXPECT_TRUE(robot.at("obstacle_contacts_by_seed").empty());
  const auto& door_a = robot.at("doors").at("door_a");
  // Per trial: seed 6's door_a opened by the robot alone, seed 5's by the resident.
  EXPECT_EQ(door_a.at("operated_by_robot_median").get<double>(), 0.5) << door_a.dump();
  EXPECT_EQ(door_a.at("operated_by_residents_median").get<double>(), 0.5);
  std::filesystem::remove_all(dir);
}

// A door's flow is a rate: two residents through at least. One resident alone gives none (null,
// "n/a"), not a flow of 0 persons/s; their queue time and who opened the door are still given.
TEST(EgressCliTest, EvacStudyGivesNoFlowThroughADoorOnlyOneResidentPassed) {
  const auto dir = egress::testing::TestTempPath("study_one");
  const std::string scenario = WriteOneResidentLab("one_resident.yaml", 120.0);
  Result run = RunEgress("evac study " + scenario + " --trials 1 -q --conditions no_robot --out " +
                         (dir / "out").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("lab_door     flow n/a (under two through)"));
  const auto study = nlohmann::json::parse(std::ifstream(dir / "out" / "study.json"));
  const auto& door = study.at("conditions").at(0).at("doors").at("lab_door");
  EXPECT_TRUE(door.at("flow_median").is_null()) << door.dump();
  EXPECT_GE(door.at("operated_by_residents_median").get<double>(), 1.0);  // they opened it
  EXPECT_EQ(study.at("conditions").at(0).at("left_behind").get<int>(), 0);
  std::filesystem::remove_all(dir);
}

// The seeds to look at are named: a resident who cannot be out in the time limit is left behind
// in every seed, each named with the count, in the table and in study.json.
TEST(EgressCliTest, EvacStudyNamesTheSeedsThatLeftPeopleBehind) {
  const auto dir = egress::testing::TestTempPath("study_left");
  const std::string scenario = WriteOneResidentLab("left_behind.yaml", 3.0);
  Result run = RunEgress("evac study " + scenario +
                         " --trials 2 --seed-base 7 -q --conditions no_robot --out " +
                         (dir / "out").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("left behind in seeds 7 (1), 8 (1)"));
  EXPECT_THAT(run.output, Not(HasSubstr("contacts in seeds")));
  const auto study = nlohmann::json::parse(std::ifstream(dir / "out" / "study.json"));
  const auto& c = study.at("conditions").at(0);
  EXPECT_EQ(c.at("left_behind").get<int>(), 2);
  EXPECT_EQ(c.at("left_behind_by_seed"), nlohmann::json({{"7", 1}, {"8", 1}}));
  EXPECT_TRUE(c.at("contacts_by_seed").empty());
  std::filesystem::remove_all(dir);
}

// Issue 21's figures: closest approach per trial with the robot's speed then, median and worst
// per scenario; the preemption latency of people the base laser saw; brain settings in the plan.
TEST(EgressCliTest, SimBatchReportsClosestApproachesAndTheLaserPeopleSetting) {
  const auto dir = egress::testing::TestTempPath("batch_people");
  const std::string scenario = kWorldsDir + "/scenarios/s2_person_crosses.yaml";
  // Laser people are the default.
  Result run =
      RunEgress("sim batch " + scenario + " --trials 2 --jobs 2 -q --out " + (dir / "lp").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("closest med/worst"));
  EXPECT_THAT(run.output, HasSubstr("the person in the base laser's view on entering"));
  const auto j = nlohmann::json::parse(std::ifstream(dir / "lp" / "batch.json"));
  EXPECT_EQ(j.at("batch").at("brain").at("laser_people"), true);
  // The camera-only brain (the paper's) is recorded as such too (a resume must not mix them).
  Result camera = RunEgress("sim batch " + scenario + " --trials 1 -q --camera-people-only --out " +
                            (dir / "cam").string());
  ASSERT_EQ(camera.exit_code, 0) << camera.output;
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(dir / "cam" / "batch.json"))
                .at("batch")
                .at("brain")
                .at("laser_people"),
            false);
  const auto& summary = j.at("summary").at(0);
  double worst = 1e9;
  std::vector<double> closest, in_sight;
  // How often the brain read someone standing still as walking (StandingTrackJudge): the
  // crosser waits for the door before crossing, and the robot drives and stands.
  EXPECT_THAT(run.output, HasSubstr("standing people read walking"));
  int samples = 0;
  for (const auto& t : j.at("trials")) {
    EXPECT_TRUE(t.contains("closest_robot_speed"));
    EXPECT_TRUE(t.contains("preemption_laser_view_latencies"));
    for (const char* robot : {"robot_moving", "robot_still"}) {
      const auto& c = t.at("standing_tracks").at(robot);
      EXPECT_LE(c.at("walking").get<int>(), c.at("samples").get<int>()) << robot;
      samples += c.at("samples").get<int>();
    }
    closest.push_back(t.at("min_person_distance").get<double>());
    worst = std::min(worst, closest.back());
    // In sight (nothing of the building between): never nearer than the closest approach.
    in_sight.push_back(t.at("min_person_distance_in_sight").get<double>());
    EXPECT_GE(in_sight.back(), closest.back());
  }
  EXPECT_GT(samples, 0);
  EXPECT_DOUBLE_EQ(summary.at("closest_worst_m").get<double>(), worst);
  // Of two, the median is their mean (the same rule as the times').
  EXPECT_DOUBLE_EQ(summary.at("closest_median_m").get<double>(), (closest[0] + closest[1]) / 2);
  EXPECT_DOUBLE_EQ(summary.at("closest_in_sight_median_m").get<double>(),
                   (in_sight[0] + in_sight[1]) / 2);
  EXPECT_DOUBLE_EQ(summary.at("closest_in_sight_worst_m").get<double>(),
                   std::min(in_sight[0], in_sight[1]));
  EXPECT_THAT(run.output, HasSubstr("in sight"));
  std::ifstream csv(dir / "lp" / "trials.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_THAT(header, HasSubstr(",closest_in_sight_m,closest_in_sight_robot_speed_mps,"));
  std::filesystem::remove_all(dir);
}

TEST(EgressCliTest, SimBatchPrintsTheTableAndWritesTheSameResultsForAnyJobCount) {
  const auto dir = egress::testing::TestTempPath("batch");
  const std::string scenario = kWorldsDir + "/scenarios/s3_held_door.yaml";
  Result two = RunEgress("sim batch " + scenario + " --trials 2 --jobs 2 -q --out " +
                         (dir / "two").string());
  ASSERT_EQ(two.exit_code, 0) << two.output;
  // 2 of 2: the 95% Wilson interval is [34.2%, 100%] (the paper's table reads like this).
  EXPECT_THAT(two.output, HasSubstr("S3 held door"));
  EXPECT_THAT(two.output, HasSubstr("[ 34.2, 100.0]"));
  Result one = RunEgress("sim batch " + scenario + " --trials 2 --jobs 1 -q --out " +
                         (dir / "one").string());
  ASSERT_EQ(one.exit_code, 0) << one.output;
  const auto trials = [&](const std::string& run) {
    const auto j = nlohmann::json::parse(std::ifstream(dir / run / "batch.json"));
    nlohmann::json out = j.at("trials");
    for (auto& t : out)
      t.erase("wall_time");
    return out;
  };
  EXPECT_EQ(trials("one"), trials("two"));
  EXPECT_EQ(trials("one").size(), 2u);
  // Bumps into walls or furniture are counted per trial (not a failure, but reported).
  EXPECT_THAT(two.output, HasSubstr("bumps"));
  EXPECT_TRUE(trials("one")[0].contains("static_contacts"));
  std::ifstream csv(dir / "one" / "trials.csv");
  int lines = 0;
  for (std::string line; std::getline(csv, line);)
    ++lines;
  EXPECT_EQ(lines, 3);
  // FILE:N runs N trials of that scenario; a bad count is refused naming the argument.
  Result counted = RunEgress("sim batch " + scenario + ":1 -q --out " + (dir / "n").string());
  ASSERT_EQ(counted.exit_code, 0) << counted.output;
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(dir / "n" / "batch.json")).at("trials").size(), 1u);
  Result bad_count = RunEgress("sim batch " + scenario + ":x -q --out " + (dir / "m").string());
  EXPECT_EQ(bad_count.exit_code, 1);
  EXPECT_THAT(bad_count.output, HasSubstr("SCENARIO:TRIALS"));
  // Results are never overwritten without --overwrite; a scenario without a mission is refused.
  Result again =
      RunEgress("sim batch " + scenario + " --trials 1 -q --out " + (dir / "one").string());
  EXPECT_EQ(again.exit_code, 1);
  EXPECT_THAT(again.output, HasSubstr("--overwrite"));
  Result no_mission =
      RunEgress("sim batch " + kWorldsDir + "/lab/lab_hold_door.yaml --trials 1 -q --out " +
                (dir / "x").string());
  EXPECT_EQ(no_mission.exit_code, 1);
  EXPECT_THAT(no_mission.output, HasSubstr("no 'mission' section"));
  std::filesystem::remove_all(dir);
}

// A batch killed (SIGKILL, no chance to clean up) after some trials continues with --resume:
// no trial lost or run twice, and the files equal an uninterrupted run's. Shards merged with
// `sim merge` equal one machine's run too.
TEST(EgressCliTest, SimBatchResumesAfterAKillAndShardsMergeToOneMachinesRun) {
  const auto dir = egress::testing::TestTempPath("resume");
  const std::string scenarios =
      kWorldsDir + "/scenarios/s3_held_door.yaml " + kWorldsDir + "/scenarios/s1_nominal.yaml:2";
  const std::string batch = "sim batch " + scenarios + " --trials 5 --jobs 2 -q --out ";
  ASSERT_EQ(RunEgress(batch + (dir / "whole").string()).exit_code, 0);
  const auto trials = [&](const std::string& run) {
    nlohmann::json j = nlohmann::json::parse(std::ifstream(dir / run / "batch.json"));
    for (auto& t : j.at("trials"))
      t.erase("wall_time");
    return nlohmann::json{
        {"batch", j.at("batch")}, {"summary", j.at("summary")}, {"trials", j.at("trials")}};
  };
  const auto journal_trials = [&](const std::string& run) {
    std::ifstream in(dir / run / "journal.jsonl");
    std::vector<std::size_t> items;
    std::string line;
    std::getline(in, line);  // the plan
    while (std::getline(in, line))
      items.push_back(nlohmann::json::parse(line).at("i").get<std::size_t>());
    return items;
  };
  // Killed once three trials are in the journal.
  const pid_t pid = fork();
  if (pid == 0) {
    const std::string command =
        std::string(EGRESS_CLI_PATH) + " " + batch + (dir / "killed").string() + " >/dev/null";
    execl("/bin/sh", "sh", "-c", ("exec " + command).c_str(), nullptr);
    _exit(127);
  }
  // Generous: a trial takes ~0.7 s in a Release build, many seconds under ASan on a busy machine.
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(180);
  while (std::chrono::steady_clock::now() < give_up &&
         !std::filesystem::exists(dir / "killed" / "journal.jsonl"))
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  while (std::chrono::steady_clock::now() < give_up && journal_trials("killed").size() < 3)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  kill(pid, SIGKILL);
  waitpid(pid, nullptr, 0);
  const std::size_t before = journal_trials("killed").size();
  ASSERT_GE(before, 3u);
  ASSERT_LT(before, 7u) << "the batch finished before it was killed";
  EXPECT_FALSE(std::filesystem::exists(dir / "killed" / "batch.json"));
  // Without --resume the journal is never overwritten.
  const Result refused = RunEgress(batch + (dir / "killed").string());
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_THAT(refused.output, HasSubstr("--resume"));
  const Result resumed = RunEgress(batch + (dir / "killed").string() + " --resume");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  std::vector<std::size_t> items = journal_trials("killed");
  std::sort(items.begin(), items.end());
  EXPECT_EQ(items, (std::vector<std::size_t>{0, 1, 2, 3, 4, 5, 6}));  // each trial exactly once
  EXPECT_EQ(trials("killed"), trials("whole"));
  // A resume of another batch is refused.
  const Result other = RunEgress("sim batch " + scenarios + " --trials 4 -q --resume --out " +
                                 (dir / "killed").string());
  EXPECT_EQ(other.exit_code, 1);
  EXPECT_THAT(other.output, HasSubstr("another batch"));

  // Shards 1/3..3/3, merged in any order, equal the whole batch.
  for (int i = 1; i <= 3; ++i) {
    const Result shard = RunEgress(batch + (dir / ("shard" + std::to_string(i))).string() +
                                   " --shard " + std::to_string(i) + "/3");
    ASSERT_EQ(shard.exit_code, 0) << shard.output;
  }
  const Result merged =
      RunEgress("sim merge " + (dir / "shard3").string() + " " + (dir / "shard1").string() + " " +
                (dir / "shard2").string() + " --out " + (dir / "merged").string());
  ASSERT_EQ(merged.exit_code, 0) << merged.output;
  EXPECT_THAT(merged.output, HasSubstr("S3 held door"));
  EXPECT_EQ(trials("merged"), trials("whole"));
  const auto csv = [&](const std::string& run) {  // without the wall-time column
    std::ifstream in(dir / run / "trials.csv");
    std::string out, line;
    while (std::getline(in, line))
      out += line.substr(0, line.rfind(',')) + "\n";
    return out;
  };
  EXPECT_EQ(csv("merged"), csv("whole"));
  const Result missing =
      RunEgress("sim merge " + (dir / "shard1").string() + " --out " + (dir / "partial").string());
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_THAT(missing.output, HasSubstr("shard 2 of 3 is missing"));
  const Result bad_shard = RunEgress(batch + (dir / "x").string() + " --shard 4/3");
  EXPECT_EQ(bad_shard.exit_code, 1);
  EXPECT_THAT(bad_shard.output, HasSubstr("1 <= I <= N"));
  std::filesystem::remove_all(dir);
}

// ---- egress bench plan

TEST(EgressCliTest, BenchPlanWritesOmplLogsAndACsv) {
  const auto out = egress::testing::TestTempPath("bench");
  const Result result = RunEgress(
      "bench plan --out " + out.string() +
      " --planner RRTConnect --runs 2 --time 0.2 --movingai-problems 0 --reference /nonexistent");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("office_two_doors"));
  std::ifstream log(out / "office_two_doors.log");
  const std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  EXPECT_THAT(text, HasSubstr("Experiment office_two_doors"));  // OMPL's benchmark log format
  EXPECT_THAT(text, HasSubstr("geometric_RRTConnect"));
  std::ifstream csv(out / "summary.csv");
  std::string header, row;
  std::getline(csv, header);
  std::getline(csv, row);
  EXPECT_EQ(
      header,
      "problem,planner,runs,solved,median_time_s,median_length_m,reference_length_m,length_ratio");
  EXPECT_THAT(row, ::testing::StartsWith("office_two_doors,geometric_RRTConnect,2,2,"));
  EXPECT_NE(RunEgress("bench plan --runs 0").exit_code, 0);
  std::filesystem::remove_all(out);
}

}  // namespace
