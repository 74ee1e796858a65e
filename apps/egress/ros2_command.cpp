// `egress twin serve --ros2 SCENARIO` and `egress robot --ros2 --scenario SCENARIO`: the robot
// brain and the twin in two processes, over ROS 2's wire format (Fast DDS). The same brain drives
// a real HSR through the same port (README "Running on an HSR").

#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <thread>

#include <fmt/format.h>

#include "bag_recorder.h"
#include "brain_trial.h"
#include "commands.h"
#include "egress/bt/groot2_publisher.h"
#include "egress/hsr_interface/error.h"
#include "egress/ros2/robot_port_server.h"
#include "egress/ros2/ros2_robot_port.h"
#include "egress/twin/scenario.h"
#include "egress/twin/scenario_judge.h"
#include "egress/twin/sdf_world_loader.h"
#include "egress/twin/twin_run.h"
#include "goal_scenario.h"

namespace egress::apps {
namespace {

std::atomic<bool> g_interrupted{false};
extern "C" void OnSigint(int) {
  g_interrupted = true;
}

struct Ros2Options {
  bool ros2{false};
  std::string scenario;
  std::optional<std::uint64_t> seed;
  int domain{0};
  std::string topics;
  bool lockstep{false};
  double speed{1.0};
  double duration{0.0};
  double wait_s{30.0};
  double command_timeout_s{ros2::Ros2RobotPortConfig{}.command_timeout_s};
  std::string json;
  std::string map, start, goal;  // a world file and a goal instead of a scenario
  std::string tree{std::string(EGRESS_TREES_DIR) + "/go_to.xml"};
  double time_limit{600.0};
  std::string bag;
  bool overwrite{false};
  bool sim_time{false};
  bool quiet{false};
  std::optional<std::uint16_t> groot2_port;
  std::string groot2_bind{"127.0.0.1"};
};

ros2::Ros2Topics TopicsOf(const Ros2Options& o) {
  return o.topics.empty() ? ros2::Ros2Topics{} : ros2::Ros2Topics::FromYamlFile(o.topics);
}

void RequireRos2(const Ros2Options& o, const char* command) {
  if (!o.ros2)
    throw CommandFailed(fmt::format(
        "{}: only --ros2 is built (ROS 2's wire format over Fast DDS); pass --ros2", command));
}

// The scenario's twin model for the run's seed (its variant, for a scenario family) and the seed.
std::pair<std::shared_ptr<const twin::TwinModel>, std::uint64_t> LoadScenarioForSeed(
    const Ros2Options& o) {
  const std::string& file = o.map.empty() ? o.scenario : o.map;
  if (!IsWorldFile(file) && (!o.goal.empty() || !o.start.empty()))
    throw CommandFailed("--start and --goal go with a world file (.sdf/.world), not a scenario");
  const twin::Scenario scenario = IsWorldFile(file)
                                      ? GoalScenario({file, o.start, o.goal, o.time_limit, o.tree})
                                      : twin::LoadScenario(file);
  const std::uint64_t seed = o.seed.value_or(scenario.seed);
  auto model = std::make_shared<const RobotModel>(RobotModel::LoadDefault());
  return {TwinModelForSeed(std::make_shared<const twin::TwinModel>(
                               scenario, twin::LoadSdfWorld(scenario.world_file), model),
                           seed),
          seed};
}

// The twin, served as a ROS 2 robot until the brain says its mission ended, the time limit, or
// SIGINT; then judged as `sim run` judges.
void ServeTwin(const Ros2Options& o) {
  RequireRos2(o, "twin serve");
  const auto [twin_model, seed] = LoadScenarioForSeed(o);
  twin::TwinWorld twin_world(twin_model, seed);
  twin::TwinRobot robot(&twin_world);
  ros2::RobotPortServer server(robot, TopicsOf(o), o.domain, /*reliable_sensors=*/o.lockstep);
  if (!o.quiet)
    fmt::print("serving   {} (seed {}) on ROS 2 domain {}, {}\n", o.scenario, seed, o.domain,
               o.lockstep ? "lock-step with the brain" : fmt::format("{:g}x real time", o.speed));
  std::signal(SIGINT, OnSigint);
  // The brain first: the scenario's clock starts once a brain has taken its first step on the
  // robot's first readings (it says RUNNING).
  const auto wait_until =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(o.wait_s);
  server.PublishSensors();
  while (!server.brain_status() || !server.BrainConnected()) {
    server.RepublishLatest();
    if (g_interrupted) throw CommandFailed("interrupted before a brain connected");
    if (std::chrono::steady_clock::now() > wait_until)
      throw CommandFailed(
          fmt::format("no brain on ROS 2 domain {} within {:g} s (start `egress "
                      "robot --ros2` there)",
                      o.domain, o.wait_s));
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  behavior::ExecutiveConfig executive;  // the brain's control period: the twin steps by it
  twin::RunOptions run;
  run.duration = o.duration;
  run.control_period = 1.0 / executive.control_rate_hz;
  const auto started = std::chrono::steady_clock::now();
  std::string ended_by = "the time limit";
  const twin::RunResult result = twin::RunScenario(
      robot,
      [&](RobotPort& port) {
        const Time now = port.clock().Now();
        server.PublishSensors();
        if (o.lockstep) {
          if (!server.WaitForStepDone(now, std::chrono::milliseconds(int(o.wait_s * 1000)))) {
            throw CommandFailed(
                fmt::format("lock-step: the brain did not finish its step at "
                            "{:.2f} s within {:g} s",
                            ToSeconds(now), o.wait_s));
          }
        } else {
          std::this_thread::sleep_until(started +
                                        std::chrono::duration<double>(ToSeconds(now) / o.speed));
        }
        server.ApplyCommands();
        for (const auto& rejected : server.TakeRejected())
          fmt::print(stderr, "rejected  {}\n", rejected);
        if (g_interrupted) {
          ended_by = "SIGINT";
          return false;
        }
        const auto status = server.brain_status();
        if (status && (status->starts_with("SUCCESS") || status->starts_with("FAILURE") ||
                       status->starts_with("HALTED"))) {
          ended_by = "the brain: " + *status;
          return false;
        }
        return true;
      },
      run);
  if (!o.quiet) {
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    fmt::print("ran       {:.1f} s simulated in {:.1f} s, ended by {}\n", result.simulated_time,
               wall, ended_by);
    std::vector<double> latency = server.TakeCommandLatencies();
    if (!latency.empty()) {
      std::sort(latency.begin(), latency.end());
      const auto at = [&](double q) {
        return latency[std::min(latency.size() - 1, std::size_t(q * double(latency.size())))];
      };
      fmt::print(
          "latency   sensors published -> base command received: median {:.2f} ms, p99 "
          "{:.2f} ms, max {:.2f} ms ({} commands)\n",
          1e3 * at(0.5), 1e3 * at(0.99), 1e3 * latency.back(), latency.size());
    }
  }
  std::cout << twin::FormatVerdict(result.verdict);
  if (!o.json.empty()) {
    std::ofstream out(o.json);
    out << twin::VerdictToJson(result.verdict) << "\n";
    if (!out) throw CommandFailed(fmt::format("cannot write '{}'", o.json));
  }
  if (!result.verdict.success) throw CommandFailed("");
}

// The brain for a scenario's mission (its map, tree and start pose for the seed: what an
// operator gives a robot), driving whatever robot answers on ROS 2.
void RunRobot(const Ros2Options& o) {
  RequireRos2(o, "robot");
  if (o.scenario.empty() == o.map.empty())
    throw CommandFailed(
        "robot --ros2: give --scenario FILE (mission, map and start) or --map WORLD.sdf --goal "
        "PLACE [--start PLACE|x;y;yaw] [--tree T.xml]");
  const auto began = std::chrono::steady_clock::now();
  const auto [twin_model, seed] = LoadScenarioForSeed(o);
  // Only the start pose is read of this world (the operator's initial pose estimate).
  const twin::TwinWorld start(twin_model, seed);
  behavior::ExecutiveConfig config;
  auto brain = MakeScenarioExecutive(twin_model->scenario(), twin_model->world(), start,
                                     twin_model->robot_model(), config);
  ros2::Ros2RobotPortConfig port_config;
  port_config.topics = TopicsOf(o);
  port_config.domain_id = o.domain;
  port_config.use_sim_time = o.sim_time || o.lockstep;
  port_config.reliable_sensors = o.lockstep;
  port_config.command_timeout_s = o.command_timeout_s;
  ros2::Ros2RobotPort port(port_config);
  std::unique_ptr<BagRecorder> bag;
  std::function<void(const SensorSnapshot&)> on_sense;
  if (!o.bag.empty()) {
    bag = BagRecorder::Open(o.bag, o.overwrite);
    on_sense = [&](const SensorSnapshot& s) { bag->OnSense(s); };
  }
  ObservedPort observed(port, on_sense);
  // Declared after the brain: it stops serving (and leaves the tree) before the brain goes.
  std::unique_ptr<bt::Groot2Publisher> groot2;
  if (o.groot2_port) {
    groot2 = std::make_unique<bt::Groot2Publisher>(
        brain->tree(), brain->tree_factory(), bt::Groot2Options{*o.groot2_port, o.groot2_bind});
    if (!o.quiet) {
      fmt::print("groot2    serving the tree on {}:{} (publisher :{})\n", o.groot2_bind,
                 groot2->port(), groot2->port() + 1);
    }
  }
  std::signal(SIGINT, OnSigint);
  std::string missing;
  if (!port.WaitForSensors(std::chrono::milliseconds(int(o.wait_s * 1000)), &missing))
    throw CommandFailed(fmt::format("no robot on ROS 2 domain {} within {:g} s: nothing on {}",
                                    o.domain, o.wait_s, missing));
  if (!o.quiet) fmt::print("brain     {} on ROS 2 domain {}\n", o.scenario, o.domain);
  const Duration period = SecondsToDuration(1.0 / config.control_rate_hz);
  const auto timeout = std::chrono::milliseconds(int(o.wait_s * 1000));
  Time next = port.clock().Now();
  std::string last_status;
  const auto publish_status = [&](const std::string& status) {
    if (status == last_status) return;
    port.PublishStatus(status);
    last_status = status;
    if (!o.quiet) {
      fmt::print("status    {:8.2f}  {}\n", ToSeconds(port.clock().Now()), status);
      std::fflush(stdout);  // watched live (a log file is block-buffered)
    }
  };
  std::string outcome;
  while (true) {
    if (!port.WaitUntil(next, timeout)) {
      brain->Halt(port, "the clock stopped");
      outcome = fmt::format("HALTED: no {} for {:g} s", port_config.topics.clock, o.wait_s);
      break;
    }
    const Time now = port.clock().Now();
    if (g_interrupted) {
      brain->Halt(port, "SIGINT");
      outcome = "HALTED: SIGINT";
      break;
    }
    // Lock-step: the twin waits for this step, so a reading still in flight is waited for.
    if (o.lockstep && port.Fault()) port.WaitUntilHealthy(std::chrono::seconds(2));
    if (const auto fault = port.Fault()) {
      brain->Halt(port, *fault);
      outcome = "HALTED: " + *fault;
      break;
    }
    const bool more = brain->Step(observed);
    if (bag) bag->AfterStep(now, *brain);
    port.PublishStepDone(now);
    if (!more) {
      outcome = brain->status() == bt::NodeStatus::kSuccess ? "SUCCESS" : "FAILURE";
      break;
    }
    publish_status("RUNNING");
    // On the wall clock, a step that overran starts the next one now rather than bunching up.
    next = port_config.use_sim_time ? next + period : std::max(next + period, now);
  }
  // Said more than once: the watcher may have missed the first (it ends on it).
  for (int i = 0; i < 3; ++i) {
    publish_status(outcome);
    last_status.clear();
    port.PublishStepDone(port.clock().Now() + SecondsToDuration(3600.0));
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  if (bag) {
    const std::size_t messages = bag->Close();
    if (!o.quiet) fmt::print("bag       {} (rosbag2, sqlite3: {} messages)\n", o.bag, messages);
  }
  if (!o.quiet) {
    const auto [accepted, refused] = port.gripper_goals();
    fmt::print(
        "commands  {} base command(s) sent as zero for a stale Sense(), {} watchdog stop(s) "
        "(command timeout {:g} s); gripper goals {} accepted, {} refused\n",
        port.stale_base_commands(), port.watchdog_stops(), port_config.command_timeout_s, accepted,
        refused);
    for (const auto& d : brain->decisions())
      fmt::print("  {:7.2f}  {}\n", d.time, d.text);
    // The brain's CPU per second of its life (both cores' worth counts: DDS threads included).
    rusage usage{};
    ::getrusage(RUSAGE_SELF, &usage);
    const double cpu = double(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
                       1e-6 * double(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
    fmt::print("cpu       {:.2f} s of CPU in {:.1f} s of wall time ({:.0f} % of one core)\n", cpu,
               wall, 100.0 * cpu / std::max(wall, 1e-9));
  }
  if (outcome != "SUCCESS") throw CommandFailed(outcome);
}

}  // namespace

void AddRos2Commands(CLI::App& app) {
  auto o = std::make_shared<Ros2Options>();
  auto* twin = app.add_subcommand("twin", "The digital twin as a robot for another process");
  twin->require_subcommand(1);
  auto* serve = twin->add_subcommand(
      "serve", "Serve a twin scenario as a ROS 2 HSR (its topics, /clock), judge it at the end");
  serve->add_flag("--ros2", o->ros2, "Over ROS 2's wire format (Fast DDS)")->required();
  serve->add_option("scenario", o->scenario, "Scenario YAML, or an SDF world with --goal")
      ->required()
      ->check(CLI::ExistingFile);
  serve->add_option("--start", o->start, "With a world: the robot's start (place or x;y;yaw)");
  serve->add_option("--goal", o->goal, "With a world: the goal (place or x;y;yaw)");
  serve->add_option("--tree", o->tree, "With a world: the mission tree")->check(CLI::ExistingFile);
  serve->add_option("--seed", o->seed, "Seed (default: the scenario's)")
      ->check(CLI::Range(std::uint64_t{0}, twin::kMaxScenarioSeed));
  serve->add_option("--domain", o->domain, "ROS_DOMAIN_ID")->check(CLI::Range(0, 232));
  serve->add_option("--topics", o->topics, "Topic map YAML (default: the HSR's ROS 2 names)")
      ->check(CLI::ExistingFile);
  serve->add_flag("--lockstep", o->lockstep,
                  "Step the twin only once the brain has finished each control step (tests)");
  serve->add_option("--speed", o->speed, "Real-time factor without --lockstep")
      ->check(FiniteIn(0.01, 100.0));
  serve->add_option("--duration", o->duration, "Simulated seconds (default: the time limit)")
      ->check(FiniteIn(1e-3, 1e7));
  serve->add_option("--wait", o->wait_s, "Seconds to wait for the brain (and each lock-step)")
      ->check(FiniteIn(0.1, 3600.0));
  serve->add_option("--json", o->json, "Write the verdict as JSON");
  serve->add_flag("-q,--quiet", o->quiet, "Only the verdict");
  serve->callback([o] { ServeTwin(*o); });

  auto* robot = app.add_subcommand(
      "robot", "Run the robot brain against a robot over ROS 2 (a real HSR, or `twin serve`)");
  robot->add_flag("--ros2", o->ros2, "Over ROS 2's wire format (Fast DDS)")->required();
  robot->add_option("--scenario", o->scenario, "Scenario YAML: the mission, map and start pose")
      ->check(CLI::ExistingFile);
  robot->add_option("--map", o->map, "The building (SDF world; its building YAML beside it)")
      ->check(CLI::ExistingFile);
  robot->add_option("--start", o->start, "With --map: the initial pose (place or x;y;yaw)");
  robot->add_option("--goal", o->goal, "With --map: the goal (place or x;y;yaw)");
  robot->add_option("--tree,--mission", o->tree, "With --map: the mission tree (default go_to.xml)")
      ->check(CLI::ExistingFile);
  robot->add_option("--seed", o->seed, "The scenario's seed (its start pose and variant)")
      ->check(CLI::Range(std::uint64_t{0}, twin::kMaxScenarioSeed));
  robot->add_option("--domain", o->domain, "ROS_DOMAIN_ID")->check(CLI::Range(0, 232));
  robot->add_option("--topics", o->topics, "Topic map YAML (default: the HSR's ROS 2 names)")
      ->check(CLI::ExistingFile);
  robot->add_option("--bag", o->bag,
                    "Record the run as a rosbag2 bag in this folder (what the brain read and "
                    "believed: /scan /odom /tf /map /plan /people /egress/status)");
  robot->add_flag("--overwrite", o->overwrite, "Replace an existing bag");
  robot->add_flag("--sim-time", o->sim_time, "Run on /clock (use_sim_time) rather than the wall");
  robot->add_flag("--lockstep", o->lockstep, "With `twin serve --lockstep` (implies --sim-time)");
  robot
      ->add_option("--command-timeout", o->command_timeout_s,
                   "Oldest a command may be when sent [s]: older goes out as zero (base) or "
                   "not at all (arm); the base is stopped if the brain goes quiet this long")
      ->check(FiniteIn(1e-3, 10.0));
  robot->add_option("--wait", o->wait_s, "Seconds to wait for the robot's sensors and clock")
      ->check(FiniteIn(0.1, 3600.0));
  robot->add_option("--groot2", o->groot2_port,
                    "Serve the mission tree to Groot2 live on this port and the next (0: the "
                    "first free pair from 1667)");
  robot->add_option("--groot2-bind", o->groot2_bind,
                    "Interface the Groot2 server binds (default 127.0.0.1; '*' for all)");
  robot->add_flag("-q,--quiet", o->quiet, "Only errors");
  robot->callback([o] { RunRobot(*o); });
}

}  // namespace egress::apps
