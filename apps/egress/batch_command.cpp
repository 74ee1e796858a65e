// `egress sim batch`: many seeded trials of twin scenarios, driven by the robot brain, in
// parallel worker processes, with a progress bar; then a table like the paper's Table I
// (success rate with a 95% Wilson interval, median time, closest person, failure reasons),
// CSV and JSON files, and the seed of every failed trial to replay it with `sim run`.
//
// Trial i of a scenario runs with seed `seed_base + i`; a trial is a pure function of its
// scenario file and seed, so the results do not depend on --jobs, and a batch can be split into
// shards (--shard I/N: work items I-1, I-1+N, ...) whose merged files (`sim merge`) equal one
// machine's. Every finished trial goes to DIR/journal.jsonl as it ends (batch_journal.h), so an
// interrupted batch continues with --resume; a worker that dies has its trial recorded as
// crashed (seed, signal, replay command) and the batch goes on.

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <numeric>
#include <ranges>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "batch.h"
#include "batch_journal.h"
#include "brain_trial.h"
#include "commands.h"
#include "egress/hsr_interface/error.h"
#include "egress/hsr_interface/text_file.h"
#include "egress/twin/scenario.h"
#include "egress/twin/sdf_world_loader.h"
#include "egress/twin/twin_run.h"
#include "study_stats.h"
#include "workers.h"

namespace egress::apps {
namespace {
// Below this base speed at the end of a run the robot stands still (a safe abort) [m/s].
constexpr double kStillSpeed = 0.05;
constexpr double kStopWithinS = 1.0;  // [s] for the base to stop after the brain gives up
constexpr double kNever = std::numeric_limits<double>::infinity();
constexpr double kEntryStillCountsS = 1.0;  // [s] see RunBrainTrial's preemption figure

// Whether the base laser sees `person` now: within its range and field of view, and the ray
// from the laser to the person's centre at laser height meets that person first.
bool InLaserView(const twin::TwinWorld& world, const twin::PersonState& person) {
  const twin::SensorConfig& sensors = world.scenario().sensors;
  const Pose3 X_WL = Pose3::FromPose2(world.robot_pose()) * world.robot_model().laser_pose();
  const Eigen::Vector3d p_WP(person.position.x(), person.position.y(), X_WL.translation().z());
  const Eigen::Vector3d p_LP = X_WL.Inverse() * p_WP;
  if (p_LP.head<2>().norm() > sensors.laser_range_max) return false;
  if (std::abs(std::atan2(p_LP.y(), p_LP.x())) > sensors.laser_fov_deg * M_PI / 360.0) return false;
  const twin::RayHit hit = world.CastRay(X_WL.translation(), p_WP, twin::GlassMode::kLaser,
                                         sensors.laser_glass_max_incidence_deg * M_PI / 180.0);
  return hit.hit && world.entity_kind(hit.entity) == twin::EntityKind::kPerson &&
         world.entity_name(hit.entity) == person.name;
}
}  // namespace

// A worker's compiled scenario: its trials come scenario by scenario, so it keeps the last one.
struct CompiledScenario {
  std::string path;
  std::shared_ptr<const twin::TwinModel> model;
};

TrialResult RunBrainTrial(const std::string& scenario_path, std::uint64_t seed,
                          CompiledScenario* compiled, bool laser_people) {
  const auto started = std::chrono::steady_clock::now();
  if (compiled->model == nullptr || compiled->path != scenario_path) {
    compiled->model.reset();  // a scenario that fails to load is not reused
    twin::Scenario loaded = twin::LoadScenario(scenario_path);
    twin::WorldDescription description = twin::LoadSdfWorld(loaded.world_file);
    compiled->model = std::make_shared<const twin::TwinModel>(
        std::move(loaded), std::move(description),
        std::make_shared<const RobotModel>(RobotModel::LoadDefault()));
    compiled->path = scenario_path;
  }
  const twin::Scenario& scenario = compiled->model->scenario();
  BrainTrialOptions options;
  options.run.record_trace = false;
  options.config.perception.laser_people = laser_people;
  // Ground truth for the preemption latency: when a person (not one holding the door) really
  // entered a door zone. Only this trial harness reads it; the brain sees sensors only.
  // Each time someone was really in a door zone: from when, until when (open while they are),
  // and whether the base laser could see them on entering.
  struct Occupied {
    double from{0.0}, until{kNever};
    bool seen{false};
  };
  std::vector<Occupied> occupied;
  bool inside_before = false;
  StandingTrackJudge standing;
  options.after_step = [&](const twin::TwinWorld& world, const behavior::Executive& brain) {
    {
      std::vector<PersonSample> tracks, people;
      for (const auto& entry : brain.belief().world.people)
        tracks.push_back({entry.person.p_MP, entry.person.v_MP});
      for (const auto& person : world.people())  // those out too: the same index every step
        people.push_back({person.position, person.velocity});
      const Twist2 V = world.robot_velocity();
      standing.Step(world.time(), std::hypot(V.vx, V.vy), V.wz, tracks, people);
    }
    bool inside = false, seen = false;
    for (const auto& door : brain.services().map->doors) {
      const perception::DoorZone zone{door, brain.services().config.zone_depth,
                                      brain.services().config.person_radius};
      for (const auto& person : world.people()) {
        if (person.started && person.phase != twin::PersonPhase::kHolding &&
            zone.Contains(person.position)) {
          inside = true;
          seen = seen || InLaserView(world, person);
        }
      }
    }
    if (inside && !inside_before) occupied.push_back({world.time(), kNever, seen});
    if (!inside && inside_before) occupied.back().until = world.time();
    inside_before = inside;
  };
  const BrainTrial trial = RunBrainTrial(compiled->model, seed, options);
  const twin::RunResult& run = trial.result;
  const behavior::Executive* brain = trial.brain.get();
  TrialResult r;
  r.scenario = scenario_path;
  r.name =
      scenario.name.empty() ? std::filesystem::path(scenario_path).stem().string() : scenario.name;
  r.seed = seed;
  r.success = run.verdict.success;
  for (const auto& p : run.verdict.predicates) {
    if (!p.passed) r.failed.push_back(p.name);
  }
  const twin::RunMetrics& m = run.verdict.metrics;
  r.time = m.time_to_goal.value_or(m.end_time);
  r.min_person_distance = m.min_person_distance;
  r.closest_robot_speed = m.closest_robot_speed;
  r.min_person_distance_in_sight = m.min_person_distance_in_sight;
  r.closest_in_sight_robot_speed = m.closest_in_sight_robot_speed;
  r.person_contacts = m.contacts.count("person") ? m.contacts.at("person") : 0;
  r.static_contacts = m.contacts.count("static") ? m.contacts.at("static") : 0;
  for (const auto& [door, n] : m.button_presses)
    r.presses += n;
  r.relocalizations = brain->relocalizations();
  r.standing_tracks = standing.counts();
  for (const auto& [known, commanded] : brain->preemptions()) {
    r.preemption_latencies.push_back(commanded - known);
    // The true entry of whoever was in a zone when this stop was commanded, or had left it
    // less than kEntryStillCountsS before (nobody: the stop came before anyone entered, from
    // the forecast or a person read as crossing; zero latency). An entry long over is not this
    // stop's (the old rule took the last entry whenever it was: up to 62 s "latencies").
    double total = 0.0;
    bool seen = true;  // a stop ahead of the entry: the laser's figure counts it too
    for (const Occupied& o : occupied) {
      if (o.from <= commanded + 1e-9 && commanded <= o.until + kEntryStillCountsS) {
        total = commanded - o.from;
        seen = o.seen;
      }
    }
    r.preemption_total_latencies.push_back(total);
    if (seen) r.preemption_laser_view_latencies.push_back(total);
  }
  // A safe abort: the brain gave up by itself, standing still, having touched no one.
  // The base was commanded to zero when the mission failed; it must come to rest within
  // kStopWithinS (its deceleration limit), touching no one.
  if (!r.success && brain->finished() && brain->status() != bt::NodeStatus::kSuccess) {
    trial.world->SetBaseVelocity(Twist2{});
    trial.world->StepFor(kStopWithinS);
    const Twist2 V = trial.world->robot_velocity();
    const bool still = std::hypot(V.vx, V.vy) < kStillSpeed;
    for (auto it = brain->decisions().rbegin(); it != brain->decisions().rend(); ++it) {
      const std::string& text = it->text;
      const bool halted = text.size() > 7 && text.compare(text.size() - 7, 7, " halted") == 0;
      // Where the head looks is no reason for giving up (it turns back ahead once the tree stops).
      const bool gaze = text.rfind("head: ", 0) == 0;
      if (text != "mission failed" && !halted && !gaze) {
        r.abort_reason = text;
        break;
      }
    }
    r.safe_abort = still && r.person_contacts == 0;
  }
  r.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return r;
}

namespace {

struct BatchOptions {
  std::vector<std::string> scenarios;
  int trials{10};
  int jobs{2};
  std::uint64_t seed_base{1};
  std::string out{"batch"};
  std::string shard{"1/1"};
  bool resume{false};
  bool overwrite{false};
  bool quiet{false};
  bool laser_people{egress::perception::PerceptionConfig{}.laser_people};  // the brain's default
};

// "I/N" with 1 <= I <= N.
std::pair<int, int> ParseShard(const std::string& text) {
  const auto slash = text.find('/');
  int index = 0, count = 0;
  try {
    std::size_t used_i = 0, used_n = 0;
    if (slash == std::string::npos) throw std::invalid_argument("");
    index = std::stoi(text.substr(0, slash), &used_i);
    count = std::stoi(text.substr(slash + 1), &used_n);
    if (used_i != slash || used_n != text.size() - slash - 1) throw std::invalid_argument("");
  } catch (const std::exception&) {
    index = 0;
  }
  if (index < 1 || count < index || count > 100000) {
    throw CommandFailed(fmt::format("--shard '{}': expected I/N with 1 <= I <= N", text));
  }
  return {index, count};
}

// The batch's plan as written in its journal and batch.json: what makes two runs the same batch.
// Brain settings other than the defaults are part of it (only when set, so that a journal of
// a default batch reads the same as before they existed).
nlohmann::json PlanJson(const std::vector<std::pair<std::string, int>>& scenarios,
                        std::uint64_t seed_base, std::pair<int, int> shard, bool laser_people) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& [file, trials] : scenarios)
    list.push_back({{"scenario", file}, {"trials", trials}});
  nlohmann::json plan = {
      {"scenarios", list}, {"seed_base", seed_base}, {"shard", {shard.first, shard.second}}};
  plan["brain"] = {{"laser_people", laser_people}};
  return plan;
}

// Every (scenario, seed) of the plan in order: scenario by scenario, seeds ascending.
std::vector<std::pair<std::string, std::uint64_t>> WorkList(const nlohmann::json& plan) {
  std::vector<std::pair<std::string, std::uint64_t>> work;
  const auto seed_base = plan.at("seed_base").get<std::uint64_t>();
  for (const auto& s : plan.at("scenarios")) {
    for (int i = 0; i < s.at("trials").get<int>(); ++i)
      work.emplace_back(s.at("scenario").get<std::string>(), seed_base + std::uint64_t(i));
  }
  return work;
}

// A worker's answer for one trial as a TrialResult (a crash or a throw keep scenario and seed).
TrialResult FromWorker(const nlohmann::json& r, const std::pair<std::string, std::uint64_t>& w) {
  if (r.contains("scenario")) return TrialFromJson(r);
  TrialResult t;
  t.scenario = w.first;
  t.name = std::filesystem::path(w.first).stem().string();
  t.seed = w.second;
  t.error = r.value("error", std::string("no result"));
  t.crashed = r.contains("crashed");
  return t;
}

// The table, the figures and the failed seeds on stdout; trials.csv and batch.json in `dir`.
void ReportBatch(const std::filesystem::path& dir, const nlohmann::json& plan,
                 const std::vector<TrialResult>& results, double wall, int jobs) {
  const std::vector<ScenarioSummary> summaries = Summarize(results);
  std::cout << FormatSummaryTable(summaries);
  const auto report = [&](const char* what, auto member) {
    std::vector<double> l;
    for (const auto& r : results)
      l.insert(l.end(), (r.*member).begin(), (r.*member).end());
    if (l.empty()) return;
    fmt::print("preemption, {}: {} events, median {:.3f} s, p90 {:.3f} s, max {:.3f} s\n", what,
               l.size(), CalcQuantile(l, 0.5), CalcQuantile(l, 0.9),
               *std::max_element(l.begin(), l.end()));
  };
  report("stack's share (person in the zone in the world model -> stop command)",
         &TrialResult::preemption_latencies);
  report("total (person really in the zone -> stop command, sensor latency included)",
         &TrialResult::preemption_total_latencies);
  report("total, the person in the base laser's view on entering",
         &TrialResult::preemption_laser_view_latencies);
  StandingReadWalking standing;
  for (const auto& r : results)
    standing += r.standing_tracks;
  const auto share = [](int k, int n) {
    return n == 0 ? std::string("-") : fmt::format("{:.1f} %", 100.0 * k / n);
  };
  if (standing.moving_samples + standing.still_samples > 0)
    fmt::print(
        "standing people read walking (tracks on someone standing, ground truth): {} of {} "
        "samples with the robot moving, {} of {} with it still\n",
        share(standing.moving_walking, standing.moving_samples), standing.moving_samples,
        share(standing.still_walking, standing.still_samples), standing.still_samples);
  fmt::print("wall time {:.1f} s for {} trials ({} jobs)\n", wall, results.size(), jobs);
  for (const auto& r : results) {
    if (r.success) continue;
    std::string why;
    for (const auto& f : r.failed)
      why += (why.empty() ? "" : ", ") + f;
    if (!r.error.empty()) why = r.error;
    fmt::print("  {}: {} seed {} ({})  replay: egress sim run {} --seed {}\n",
               r.crashed ? "CRASHED" : "failed", r.name, r.seed, why, r.scenario, r.seed);
  }
  std::filesystem::create_directories(dir);
  const auto csv_path = dir / "trials.csv";
  const auto json_path = dir / "batch.json";
  {
    std::ofstream csv(csv_path);
    csv << "scenario,name,seed,success,time_s,min_person_distance_m,closest_robot_speed_mps,"
           "closest_in_sight_m,closest_in_sight_robot_speed_mps,person_contacts,"
           "static_contacts,presses,relocalizations,failed,wall_s\n";
    for (const auto& r : results) {
      std::string failed;
      for (const auto& f : r.failed)
        failed += (failed.empty() ? "" : ";") + f;
      csv << fmt::format(
          "{},\"{}\",{},{},{:.2f},{},{:.3f},{},{:.3f},{},{},{},{},\"{}\",{:.2f}\n", r.scenario,
          r.name, r.seed, r.success ? 1 : 0, r.time,
          std::isfinite(r.min_person_distance) ? fmt::format("{:.3f}", r.min_person_distance) : "",
          r.closest_robot_speed,
          std::isfinite(r.min_person_distance_in_sight)
              ? fmt::format("{:.3f}", r.min_person_distance_in_sight)
              : "",
          r.closest_in_sight_robot_speed, r.person_contacts, r.static_contacts, r.presses,
          r.relocalizations, r.error.empty() ? failed : r.error, r.wall_time);
    }
    if (!csv) throw CommandFailed(fmt::format("cannot write '{}'", csv_path.string()));
  }
  nlohmann::json summary = nlohmann::json::array();
  for (const auto& s : summaries) {
    summary.push_back(
        {{"scenario", s.scenario},
         {"name", s.name},
         {"trials", s.trials},
         {"successes", s.successes},
         {"rate", double(s.successes) / std::max(1, s.trials)},
         {"wilson95", {s.rate.low, s.rate.high}},
         {"median_time", s.median_time ? nlohmann::json(*s.median_time) : nlohmann::json(nullptr)},
         {"closest_median_m", s.median_person_distance ? nlohmann::json(*s.median_person_distance)
                                                       : nlohmann::json(nullptr)},
         {"closest_p10_m",
          s.p10_person_distance ? nlohmann::json(*s.p10_person_distance) : nlohmann::json(nullptr)},
         {"closest_worst_m", std::isfinite(s.min_person_distance)
                                 ? nlohmann::json(s.min_person_distance)
                                 : nlohmann::json(nullptr)},
         {"closest_in_sight_median_m", s.median_person_distance_in_sight
                                           ? nlohmann::json(*s.median_person_distance_in_sight)
                                           : nlohmann::json(nullptr)},
         {"closest_in_sight_p10_m", s.p10_person_distance_in_sight
                                        ? nlohmann::json(*s.p10_person_distance_in_sight)
                                        : nlohmann::json(nullptr)},
         {"closest_in_sight_worst_m", std::isfinite(s.min_person_distance_in_sight)
                                          ? nlohmann::json(s.min_person_distance_in_sight)
                                          : nlohmann::json(nullptr)},
         {"close_approaches_moving", s.close_approaches_moving},
         {"person_contacts", s.person_contacts},
         {"static_contacts", s.static_contacts},
         {"trials_with_static_contacts", s.trials_with_static_contacts},
         {"trials_with_relocalizations", s.trials_with_relocalizations},
         {"safe_aborts", s.safe_aborts},
         {"success_or_safe_abort", double(s.successes + s.safe_aborts) / std::max(1, s.trials)},
         {"failure_reasons", s.failure_reasons},
         {"failed_seeds", s.failed_seeds}});
  }
  nlohmann::json trials = nlohmann::json::array();
  for (const auto& r : results)
    trials.push_back(ToJson(r));
  std::ofstream(json_path) << nlohmann::json{{"batch", plan},
                                             {"wall_s", wall},
                                             {"jobs", jobs},
                                             {"summary", summary},
                                             {"trials", trials}}
                                  .dump(2)
                           << "\n";
  fmt::print("wrote {} and {}\n", csv_path.string(), json_path.string());
}

void RunBatch(const BatchOptions& o) {
  if (o.trials < 1) throw CommandFailed("--trials must be at least 1");
  if (o.jobs < 1) throw CommandFailed("--jobs must be at least 1");
  if (o.resume && o.overwrite) throw CommandFailed("--resume and --overwrite exclude each other");
  const std::pair<int, int> shard = ParseShard(o.shard);
  const std::filesystem::path dir(o.out);
  if (!o.resume && !o.overwrite) {
    for (const auto& p : {dir / "trials.csv", dir / "batch.json"}) {
      if (std::filesystem::exists(p)) {
        throw CommandFailed(fmt::format(
            "'{}' exists; pass --overwrite to replace it (or --resume to continue)", p.string()));
      }
    }
  }
  // SCENARIO or SCENARIO:N (N trials of that one, e.g. the paper's protocol).
  std::vector<std::pair<std::string, int>> scenarios;
  for (const auto& arg : o.scenarios) {
    std::string file = arg;
    int trials = o.trials;
    if (const auto colon = arg.rfind(':');
        colon != std::string::npos && !std::filesystem::exists(arg)) {
      const std::string count = arg.substr(colon + 1);
      if (count.empty() || count.size() > 7 ||
          count.find_first_not_of("0123456789") != std::string::npos || std::stoll(count) < 1 ||
          std::stoll(count) > kMaxTrials) {
        throw CommandFailed(fmt::format("'{}': expected SCENARIO or SCENARIO:TRIALS", arg));
      }
      file = arg.substr(0, colon);
      trials = int(std::stoll(count));
    }
    if (!std::filesystem::exists(file))
      throw CommandFailed(fmt::format("'{}': no such scenario file", file));
    // Check every scenario (and its mission) before starting any worker.
    const twin::Scenario scenario = twin::LoadScenario(file);
    if (!scenario.mission) {
      throw CommandFailed(
          fmt::format("{}: no 'mission' section: sim batch runs the robot brain", file));
    }
    scenarios.emplace_back(file, trials);
  }
  CheckSeedBase(o.seed_base, std::ranges::max(scenarios | std::views::values),
                twin::kMaxScenarioSeed);
  const nlohmann::json plan = PlanJson(scenarios, o.seed_base, shard, o.laser_people);
  const bool laser_people = o.laser_people;
  const auto all = WorkList(plan);
  // This shard's work items, as indices into the whole batch's list.
  std::vector<std::size_t> mine;
  for (std::size_t k = std::size_t(shard.first - 1); k < all.size(); k += std::size_t(shard.second))
    mine.push_back(k);
  if (mine.empty()) throw CommandFailed(fmt::format("--shard {}: no trials fall in it", o.shard));
  std::map<std::size_t, nlohmann::json> finished;
  BatchJournal journal = o.resume ? BatchJournal::Resume(dir / "journal.jsonl", plan, &finished)
                                  : BatchJournal::Create(dir / "journal.jsonl", plan, o.overwrite);
  WorkerPoolOptions pool;
  pool.jobs = o.jobs;
  pool.progress = !o.quiet && ::isatty(::fileno(stderr));
  pool.skip.resize(mine.size());
  std::vector<TrialResult> results(mine.size());
  for (std::size_t k = 0; k < mine.size(); ++k) {
    if (const auto it = finished.find(mine[k]); it != finished.end()) {
      results[k] = TrialFromJson(it->second);
      pool.skip[k] = true;
    }
  }
  pool.on_result = [&](std::size_t k, const nlohmann::json& r) {
    results[k] = FromWorker(r, all[mine[k]]);
    journal.Append(mine[k], ToJson(results[k]));
  };
  const std::size_t to_run =
      mine.size() - std::size_t(std::count(pool.skip.begin(), pool.skip.end(), true));
  if (!o.quiet) {
    fmt::print("{} scenario(s), {} runs{}{} on {} worker process(es)\n", scenarios.size(),
               mine.size(),
               shard.second > 1 ? fmt::format(" (shard {} of {})", shard.first, shard.second) : "",
               o.resume ? fmt::format(", {} already in the journal", mine.size() - to_run) : "",
               std::min<std::size_t>(std::size_t(o.jobs), std::max<std::size_t>(1, to_run)));
  }
  const auto started = std::chrono::steady_clock::now();
  CompiledScenario compiled;  // each worker's own copy after the fork
  RunInWorkers(
      mine.size(),
      [&](std::size_t k) {
        const auto& [file, seed] = all[mine[k]];
        try {
          return ToJson(RunBrainTrial(file, seed, &compiled, laser_people));
        } catch (const std::exception& e) {
          TrialResult r = FromWorker({{"error", e.what()}}, all[mine[k]]);
          return ToJson(r);
        }
      },
      pool);
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  ReportBatch(dir, plan, results, wall, o.jobs);
}

// `sim merge DIR... --out OUT`: the shards of one batch into the files one machine would write.
struct MergeOptions {
  std::vector<std::string> shards;
  std::string out{"batch"};
  bool overwrite{false};
};

void RunMerge(const MergeOptions& o) {
  const std::filesystem::path out(o.out);
  for (const auto& p : {out / "trials.csv", out / "batch.json"}) {
    if (std::filesystem::exists(p) && !o.overwrite)
      throw CommandFailed(fmt::format("'{}' exists; pass --overwrite to replace it", p.string()));
  }
  nlohmann::json plan;
  std::map<int, nlohmann::json> by_shard;  // shard index -> its trials
  double wall = 0.0;
  int jobs = 0;
  for (const auto& dir : o.shards) {
    const auto path = std::filesystem::path(dir) / "batch.json";
    if (!std::filesystem::exists(path)) {
      throw CommandFailed(fmt::format(
          "'{}': no batch.json (the shard did not finish: continue it with --resume)", dir));
    }
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(ReadTextFile(path, "batch file"));
    } catch (const std::exception& e) {
      throw CommandFailed(fmt::format("{}: {}", path.string(), e.what()));
    }
    if (!j.contains("batch") || !j.contains("trials"))
      throw CommandFailed(fmt::format("{}: not a sim batch result", path.string()));
    nlohmann::json shard_plan = j.at("batch");
    const int index = shard_plan.at("shard").at(0).get<int>();
    shard_plan["shard"] = {1, shard_plan.at("shard").at(1).get<int>()};
    if (plan.is_null()) plan = shard_plan;
    if (shard_plan != plan) {
      throw CommandFailed(fmt::format(
          "{}: a shard of another batch (scenarios, trial counts, seed base or shard count "
          "differ from {})",
          path.string(), o.shards.front()));
    }
    if (!by_shard.emplace(index, j.at("trials")).second)
      throw CommandFailed(fmt::format("{}: shard {} is given twice", path.string(), index));
    wall = std::max(wall, j.value("wall_s", 0.0));
    jobs += j.value("jobs", 0);
  }
  const int count = plan.at("shard").at(1).get<int>();
  for (int i = 1; i <= count; ++i) {
    if (!by_shard.count(i)) throw CommandFailed(fmt::format("shard {} of {} is missing", i, count));
  }
  const auto all = WorkList(plan);
  std::vector<TrialResult> results;
  std::map<int, std::size_t> next;  // per shard: its next trial
  for (std::size_t k = 0; k < all.size(); ++k) {
    const int shard = int(k % std::size_t(count)) + 1;
    const nlohmann::json& trials = by_shard.at(shard);
    const std::size_t at = next[shard]++;
    if (at >= trials.size())
      throw CommandFailed(fmt::format("shard {} has fewer trials than its plan", shard));
    TrialResult r = TrialFromJson(trials.at(at));
    if (r.scenario != all[k].first || r.seed != all[k].second) {
      throw CommandFailed(fmt::format("shard {}: trial {} is {} seed {}, the plan says {} seed {}",
                                      shard, at, r.scenario, r.seed, all[k].first, all[k].second));
    }
    results.push_back(std::move(r));
  }
  plan["shard"] = {1, 1};
  ReportBatch(out, plan, results, wall, jobs);
}

}  // namespace

void AddSimBatchCommand(CLI::App& sim_group) {
  auto o = std::make_shared<BatchOptions>();
  auto* batch = sim_group.add_subcommand(
      "batch", "Run seeded trials of scenarios in parallel and print a success table");
  batch
      ->add_option("scenarios", o->scenarios,
                   "scenario YAML files with a mission; FILE:N runs N trials of that one")
      ->required();
  // Bounded: the batch holds a result per trial (2e9 trials allocated gigabytes before any ran).
  batch->add_option("--trials", o->trials, "trials per scenario")
      ->capture_default_str()
      ->check(CLI::Range(1, kMaxTrials));
  batch->add_option("--jobs,-j", o->jobs, "worker processes")
      ->capture_default_str()
      ->check(CLI::Range(1, kMaxJobs));
  batch->add_option("--seed-base", o->seed_base, "trial i runs with seed seed-base + i")
      ->capture_default_str();
  batch->add_option("--out", o->out, "directory for trials.csv, batch.json and journal.jsonl")
      ->capture_default_str();
  batch
      ->add_option("--shard", o->shard,
                   "I/N: run only work items I-1, I-1+N, ... (merge the shards with sim merge)")
      ->capture_default_str();
  batch->add_flag("--resume", o->resume,
                  "continue the interrupted batch in --out: run only trials not in its journal");
  batch->add_flag("--overwrite", o->overwrite, "replace existing result files");
  batch->add_flag("-q,--quiet", o->quiet, "no progress bar");
  batch->add_flag("--laser-people,!--camera-people-only", o->laser_people,
                  "people from the base laser too (the default), or the head camera's alone "
                  "(as sim run's)");
  batch->callback([o] { RunBatch(*o); });

  auto m = std::make_shared<MergeOptions>();
  auto* merge = sim_group.add_subcommand(
      "merge", "Merge the shards of a batch (sim batch --shard I/N) into one machine's files");
  merge->add_option("shards", m->shards, "the shards' --out directories")->required();
  merge->add_option("--out", m->out, "directory for the merged trials.csv and batch.json")
      ->capture_default_str();
  merge->add_flag("--overwrite", m->overwrite, "replace existing result files");
  merge->callback([m] { RunMerge(*m); });
}

}  // namespace egress::apps
