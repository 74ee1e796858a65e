// `egress sim run`: one twin scenario end to end, with a readable verdict, a JSON verdict, a trace
// and pictures. `egress render`: a recorded trace as a PNG or an MP4.
//
// Drivers: `brain` (the executive running the scenario's mission tree; the default when the
// scenario has a `mission`), `idle` (the robot stands still) and `dead-reckoning` (a naive
// baseline that drives straight at the goal on odometry alone).

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "bag_recorder.h"
#include "batch.h"
#include "brain_trial.h"
#include "commands.h"
#include "crowd_rate_options.h"
#include "egress/behavior/task_nodes.h"
#include "egress/bt/groot2_publisher.h"
#include "egress/bt/loggers.h"
#include "egress/hsr_interface/error.h"
#include "egress/twin/scenario.h"
#include "egress/twin/sdf_world_loader.h"
#include "egress/twin/twin_model.h"
#include "egress/twin/twin_run.h"
#include "goal_scenario.h"
#include "trace_render.h"

namespace egress::apps {
namespace {

constexpr double kCostmapSnapshotPeriodSec = 1.0;

// The costmap's inflated and lethal cells, and the free cells deep in someone's personal space,
// for the trace.
twin::TraceAnnotation::Grid CostmapLayer(const perception::Costmap2D& costmap) {
  twin::TraceAnnotation::Grid grid;
  const auto& g = costmap.geometry();
  grid.origin = g.origin;
  grid.resolution = g.resolution;
  grid.width = g.width;
  grid.height = g.height;
  const auto& costs = costmap.costs();
  const auto& personal = costmap.personal_space_costs();
  for (std::size_t i = 0; i < costs.size(); ++i) {
    if (costs[i] == perception::kUnknownCost) continue;
    if (costs[i] < perception::kInscribedCost &&
        personal[i] >= perception::kPersonalSpacePeakCost / 2)
      grid.personal.push_back(std::uint32_t(i));
    if (costs[i] >= perception::kLethalCost) {
      grid.lethal.push_back(std::uint32_t(i));
    } else if (costs[i] >= perception::kInscribedCost) {
      grid.inflated.push_back(std::uint32_t(i));
    }
  }
  return grid;
}

struct SimOptions {
  std::string scenario;
  std::string start;  // with a world file: a place or x;y;yaw
  std::string goal;   // with a world file: a place or x;y;yaw
  double time_limit{300.0};
  std::string tree{std::string(EGRESS_TREES_DIR) + "/go_to.xml"};
  std::optional<std::uint64_t> seed;
  double duration{0.0};
  std::string driver{"auto"};
  std::string trace;
  std::string json;
  std::string png;
  std::string mp4;
  bool overwrite{false};
  bool quiet{false};
  bool no_octomap{false};
  bool laser_people{egress::perception::PerceptionConfig{}.laser_people};  // the brain's default
  std::string bag;
  std::string btlog;
  std::optional<std::uint16_t> groot2_port;
  std::string groot2_bind{"127.0.0.1"};
  double pace{0.0};  ///< Real-time factor to hold the run to (0: as fast as it goes).
  CrowdRateOptions crowd;
};

void RefuseOverwrite(const std::string& path, bool overwrite) {
  if (!path.empty() && std::filesystem::exists(path) && !overwrite) {
    throw CommandFailed(fmt::format("'{}' exists; pass --overwrite to replace it", path));
  }
}

// Drives straight at the goal from the scenario's nominal start, on odometry alone: what a
// robot without perception would do. Useful as a baseline and to exercise the twin.
twin::Controller DeadReckoningController(const twin::Scenario& scenario) {
  if (!scenario.goal)
    throw CommandFailed("--driver dead-reckoning needs robot.goal in the scenario");
  const Pose2 X_MO = scenario.robot_start;
  const Pose2 goal = *scenario.goal;
  const double tolerance = scenario.goal_tolerance;
  return [=](RobotPort& robot) {
    const SensorSnapshot s = robot.Sense();
    const Pose2 X_MB = X_MO * s.odometry.X_OB;
    const Eigen::Vector2d p_BG = X_MB.Inverse() * goal.translation();
    if (p_BG.norm() <= tolerance / 2) {
      robot.SendBaseVelocity({});
      return true;
    }
    const double speed = std::min(0.3, p_BG.norm());
    const Eigen::Vector2d v = p_BG.normalized() * speed;
    robot.SendBaseVelocity({v.x(), v.y(), 0.0});
    return true;
  };
}

void ProgressBar(double fraction) {
  constexpr int kWidth = 40;
  const int filled = int(fraction * kWidth);
  std::fprintf(stderr, "\r  [%s%s] %3d%%", std::string(std::size_t(filled), '#').c_str(),
               std::string(std::size_t(kWidth - filled), ' ').c_str(), int(fraction * 100));
  if (fraction >= 1.0) std::fprintf(stderr, "\n");
}

// A world and a goal as a scenario (GoalScenario), from the command's options.
twin::Scenario GoalScenarioOf(const SimOptions& o) {
  return GoalScenario({o.scenario, o.start, o.goal, o.time_limit, o.tree});
}

void RunSim(const SimOptions& o) {
  for (const auto* path : {&o.trace, &o.json, &o.png, &o.mp4, &o.btlog})
    RefuseOverwrite(*path, o.overwrite);
  if (!IsWorldFile(o.scenario) && (!o.goal.empty() || !o.start.empty()))
    throw CommandFailed("--start and --goal go with a world file (.sdf/.world), not a scenario");
  const twin::Scenario scenario =
      IsWorldFile(o.scenario) ? GoalScenarioOf(o) : twin::LoadScenario(o.scenario);
  const twin::WorldDescription world_description = twin::LoadSdfWorld(scenario.world_file);
  const std::uint64_t seed = o.seed.value_or(scenario.seed);
  auto model = std::make_shared<const RobotModel>(RobotModel::LoadDefault());
  const std::string driver = o.driver != "auto" ? o.driver : (scenario.mission ? "brain" : "idle");
  twin::Controller controller;
  if (driver == "idle") {
    controller = twin::IdleController();
  } else if (driver == "dead-reckoning") {
    controller = DeadReckoningController(scenario);
  } else if (driver != "brain") {
    throw CommandFailed(
        fmt::format("--driver '{}': expected auto, brain, idle or dead-reckoning", o.driver));
  }
  if (!o.quiet) {
    fmt::print("scenario  {} ({})\n", scenario.name.empty() ? o.scenario : scenario.name,
               o.scenario);
    fmt::print("world     {}: {} static shapes, {} doors\n", scenario.world_file.string(),
               world_description.shapes.size(), world_description.doors.size());
    for (const auto& note : world_description.notes)
      fmt::print("note      {}\n", note);
    fmt::print("seed      {}   driver {}   time limit {:.0f} s\n", seed, driver,
               scenario.time_limit);
    if (scenario.randomize.DrawsVariants()) {
      // Drawn as the run draws it: from the scenario with its building's defaults.
      const twin::BuildingDescription building =
          twin::DescribeScenarioBuilding(scenario, world_description);
      twin::Scenario defaulted = scenario;
      twin::ApplyBuildingDefaults(building, &defaulted);
      const twin::Scenario variant = twin::DrawScenarioVariant(defaulted, building, seed);
      std::string opened;
      for (const auto& door : variant.doors)
        if (!door.open_at.empty() && door.open_at.front() == 0.0)
          opened += (opened.empty() ? "" : ", ") + door.door;
      fmt::print("variant   start {}, goal {}, opened at the start: {}\n",
                 variant.start_place.empty() ? "(pose)" : variant.start_place,
                 variant.goal_place.empty() ? "(pose)" : variant.goal_place,
                 opened.empty() ? "none" : opened);
    }
  }
  twin::TwinConfig twin_config;
  o.crowd.ApplyTo(twin_config);
  twin::RunOptions options;
  options.duration = o.duration;
  // The trace only when something is made of it (recording it costs a few per cent of a run).
  options.record_trace = !o.trace.empty() || !o.png.empty() || !o.mp4.empty();
  if (!o.quiet && ::isatty(::fileno(stderr))) options.on_progress = ProgressBar;
  const auto started = std::chrono::steady_clock::now();
  std::unique_ptr<twin::TwinWorld> world_owner;
  std::unique_ptr<behavior::Executive> brain;
  twin::RunResult result;
  std::unique_ptr<BagRecorder> bag;
  if (!o.bag.empty()) {
    if (driver != "brain")
      throw CommandFailed("--bag records a brain run (the driver is " + driver + ")");
    bag = BagRecorder::Open(o.bag, o.overwrite);
  }
  for (const auto& [given, flag] :
       {std::pair{!o.btlog.empty(), "--btlog"}, std::pair{o.groot2_port.has_value(), "--groot2"}}) {
    if (given && driver != "brain")
      throw CommandFailed(
          fmt::format("{} shows the brain's tree (the driver is {})", flag, driver));
  }
  // Observers of the brain's tree; they go before the brain does (see the end of the run).
  std::unique_ptr<bt::FileLogger2> btlog;
  std::unique_ptr<bt::Groot2Publisher> groot2;
  if (driver == "brain") {
    BrainTrialOptions trial_options;
    trial_options.on_brain = [&](behavior::Executive& b) {
      if (!o.btlog.empty()) {
        // Groot2 shows the replay against the wall time the run started.
        const auto start_us = std::chrono::duration_cast<std::chrono::microseconds>(
            std::chrono::system_clock::now().time_since_epoch());
        btlog = std::make_unique<bt::FileLogger2>(b.tree(), b.tree_factory(), o.btlog,
                                                  start_us.count());
      }
      if (o.groot2_port) {
        groot2 = std::make_unique<bt::Groot2Publisher>(
            b.tree(), b.tree_factory(), bt::Groot2Options{*o.groot2_port, o.groot2_bind});
        fmt::print("groot2    serving the tree on {}:{} (publisher :{}); attach Groot2 there\n",
                   o.groot2_bind, groot2->port(), groot2->port() + 1);
        std::fflush(stdout);
      }
    };
    if (o.pace > 0.0) {
      // Holds the simulation to `pace` times real time, so that Groot2 can follow it.
      trial_options.after_step = [&, wall_start = std::chrono::steady_clock::now()](
                                     const twin::TwinWorld& w, const behavior::Executive& b) {
        if (bag) bag->AfterStep(w.now(), b);
        std::this_thread::sleep_until(
            wall_start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                             std::chrono::duration<double>(w.time() / o.pace)));
      };
    }
    if (bag) {
      trial_options.on_sense = [&](const SensorSnapshot& s) { bag->OnSense(s); };
      if (!trial_options.after_step) {
        trial_options.after_step = [&](const twin::TwinWorld& w, const behavior::Executive& b) {
          bag->AfterStep(w.now(), b);
        };
      }
    }
    trial_options.config.use_octomap = !o.no_octomap;
    trial_options.twin_config = twin_config;
    trial_options.config.perception.laser_people = o.laser_people;
    trial_options.run = options;
    // The video shows the running action, the planned path and, once a second, the costmap
    // (the map frame is W here: the brain starts from the twin's start pose).
    if (options.record_trace)
      trial_options.annotate = [next_costmap = 0.0](const twin::TwinWorld& world,
                                                    const behavior::Executive& b) mutable {
        twin::TraceAnnotation note;
        note.label = b.active_action();
        for (const Pose2& X : b.services().motion->path())
          note.path.push_back(X.translation());
        if (world.time() + 1e-9 >= next_costmap) {
          next_costmap = world.time() + kCostmapSnapshotPeriodSec;
          note.costmap = CostmapLayer(b.costmap());
        }
        return note;
      };
    BrainTrial trial = RunBrainTrial(scenario, world_description, seed, model, trial_options);
    world_owner = std::move(trial.world);
    brain = std::move(trial.brain);
    result = std::move(trial.result);
    if (groot2) {
      fmt::print("groot2    answered {} requests\n", groot2->requests_served());
      groot2.reset();
    }
    if (btlog) {
      btlog.reset();  // flushes
      fmt::print("btlog     {} (replay it in Groot2)\n", o.btlog);
    }
  } else {
    world_owner =
        std::make_unique<twin::TwinWorld>(scenario, world_description, seed, model, twin_config);
    twin::TwinRobot robot(world_owner.get());
    result = twin::RunScenario(robot, controller, options);
  }
  const twin::TwinWorld& world = *world_owner;
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (!o.quiet) {
    fmt::print("ran       {:.1f} s simulated in {:.2f} s ({:.0f}x real time), {} events\n",
               result.simulated_time, wall, result.simulated_time / std::max(wall, 1e-9),
               world.events().size());
    for (const auto& e : world.events()) {
      fmt::print("  {:7.2f}  {:<22} {:<14} {}\n", e.t, e.kind, e.subject, e.detail);
    }
    if (brain) {
      fmt::print("decisions ({}):\n", brain->decisions().size());
      for (const auto& d : brain->decisions())
        fmt::print("  {:7.2f}  {}\n", d.time, d.text);
    }
  }
  std::cout << twin::FormatVerdict(result.verdict);
  if (!o.trace.empty()) {
    result.trace->Write(o.trace);
    fmt::print("trace     {} ({} samples, hash {:016x})\n", o.trace, result.trace->sample_count(),
               result.trace->Hash());
  }
  if (!o.json.empty()) {
    std::ofstream out(o.json);
    out << twin::VerdictToJson(result.verdict) << "\n";
    if (!out) throw CommandFailed(fmt::format("cannot write '{}'", o.json));
    fmt::print("verdict   {}\n", o.json);
  }
  if (bag) {
    const std::size_t messages = bag->Close();
    fmt::print("bag       {} (rosbag2, sqlite3: {} messages)\n", o.bag, messages);
  }
  if (!o.png.empty() || !o.mp4.empty()) {
    // Render from the trace text itself, exactly as `egress render` would from the file.
    std::istringstream text(result.trace->ToJsonLines());
    const TraceFile trace = ParseTrace(text, "trace");
    if (!o.png.empty()) {
      WriteTracePng(trace, o.png);
      fmt::print("picture   {}\n", o.png);
    }
    if (!o.mp4.empty()) {
      WriteTraceVideo(trace, o.mp4);
      fmt::print("video     {}\n", o.mp4);
    }
  }
  if (!result.verdict.success) throw CommandFailed("");
}

}  // namespace

void AddSimCommand(CLI::App& app) {
  auto o = std::make_shared<SimOptions>();
  auto* sim_group =
      app.add_subcommand("sim", "Digital-twin runs: `sim run` (one scenario, judged), `sim batch`");
  sim_group->require_subcommand(1);
  auto* sim = sim_group->add_subcommand("run", "Run one twin scenario end to end and judge it");
  sim->add_option("scenario", o->scenario,
                  "scenario YAML (worlds/README.md), or an SDF world with --goal")
      ->required()
      ->check(CLI::ExistingFile);
  sim->add_option("--goal", o->goal,
                  "with a world file: where to go, a place of the building or x;y;yaw");
  sim->add_option("--start", o->start,
                  "with a world file: where the robot starts (default: the building's first "
                  "place)");
  sim->add_option("--time-limit", o->time_limit, "with a world file: time limit [s]")
      ->capture_default_str()
      ->check(FiniteIn(1e-3, 1e7));
  sim->add_option("--tree", o->tree, "with a world file: the mission tree (goal on {goal})")
      ->capture_default_str()
      ->check(CLI::ExistingFile);
  sim->add_option("--seed", o->seed, "seed (default: the scenario's)")
      ->check(CLI::Range(std::uint64_t{0}, twin::kMaxScenarioSeed));
  sim->add_option("--duration", o->duration,
                  "simulated seconds (default: the scenario's time limit)")
      ->check(FiniteIn(1e-3, 1e7));
  sim->add_option("--driver", o->driver,
                  "who drives the robot: auto (brain if the scenario has a mission, else idle) | "
                  "brain | idle | dead-reckoning")
      ->capture_default_str();
  sim->add_option("--trace", o->trace, "write the run's trace (JSON lines, 20 Hz)");
  sim->add_option("--json", o->json, "write the verdict as JSON");
  sim->add_option("--png", o->png, "draw the run (paths, final state) into this PNG");
  sim->add_option("--video,--mp4", o->mp4, "render the run to this top-down MP4");
  sim->add_option("--bag", o->bag,
                  "record the brain's run as a rosbag2 bag in this folder (sqlite3 .db3 + "
                  "metadata.yaml: /scan /odom /tf /map /plan /people /egress/status)");
  sim->add_option("--btlog", o->btlog,
                  "write the brain's tree transitions as a Groot2 .btlog (replay in Groot2)");
  sim->add_option("--groot2", o->groot2_port,
                  "serve the brain's tree to Groot2 live on this port and the next (0: the "
                  "first free pair from 1667)");
  sim->add_option("--groot2-bind", o->groot2_bind,
                  "interface the Groot2 server binds (default 127.0.0.1; '*' for all)");
  sim->add_option("--pace", o->pace,
                  "hold the run to this many times real time (e.g. 1 to watch it in Groot2)")
      ->check(CLI::NonNegativeNumber);
  o->crowd.AddTo(*sim);
  sim->add_flag("--overwrite", o->overwrite, "replace existing output files");
  sim->add_flag("-q,--quiet", o->quiet, "print only the verdict");
  sim->add_flag("--laser-people,!--camera-people-only", o->laser_people,
                "people from the base laser too, fused with the camera's (the default); "
                "--camera-people-only: the head camera's alone (the paper's brain)");
  sim->add_flag("--no-octomap", o->no_octomap,
                "disconnect the brain's 3D obstacle map (the base laser alone), for comparison");
  sim->callback([o] { RunSim(*o); });
  AddSimBatchCommand(*sim_group);

  auto render_path = std::make_shared<std::string>();
  auto render_out = std::make_shared<std::string>();
  auto render_overwrite = std::make_shared<bool>(false);
  auto* render =
      app.add_subcommand("render", "Render a recorded run (egress sim --trace) to PNG or MP4");
  render->add_option("trace", *render_path, "trace file (JSON lines)")
      ->required()
      ->check(CLI::ExistingFile);
  render
      ->add_option("--out", *render_out,
                   "output .png (last frame with paths) or .mp4 (the whole run)")
      ->required();
  render->add_flag("--overwrite", *render_overwrite, "replace an existing output file");
  render->callback([render_path, render_out, render_overwrite] {
    RefuseOverwrite(*render_out, *render_overwrite);
    const TraceFile trace = ReadTrace(*render_path);
    const std::string ext = std::filesystem::path(*render_out).extension().string();
    if (ext == ".png") {
      WriteTracePng(trace, *render_out);
    } else if (ext == ".mp4") {
      WriteTraceVideo(trace, *render_out);
    } else {
      throw CommandFailed(fmt::format("--out '{}': expected a .png or .mp4 file", *render_out));
    }
    fmt::print("{} samples ({:.1f} s) -> {}\n", trace.samples.size(),
               trace.samples.back()["t"].get<double>(), *render_out);
  });
}

}  // namespace egress::apps
