// `egress sim batch`: many seeded trials of twin scenarios, driven by the robot brain, in
// parallel worker processes, with a progress bar; then a table like the paper's Table I
// (success rate with a 95% Wilson interval, median time, closest person, failure reasons),
// CSV and JSON files, and the seed of every failed trial to replay it with `sim run`.
//
// Trial i of a scenario runs with seed `seed_base + i`; a trial is a pure function of its
// scenario file and seed, so the results do not depend on --jobs, and a batch can be split into
// shards (--first) whose merged files equal one machine's.

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "batch.h"
#include "brain_trial.h"
#include "commands.h"
#include "egress/hsr_interface/error.h"
#include "egress/twin/sdf_world_loader.h"
#include "egress/twin/twin_run.h"
#include "workers.h"

namespace egress::apps {

WilsonInterval CalcWilsonInterval(int successes, int trials, double z) {
  ThrowUnless(trials >= 0 && successes >= 0 && successes <= trials,
              "Wilson interval: need 0 <= successes <= trials");
  if (trials == 0) return {0.0, 1.0};
  const double n = trials;
  const double p = successes / n;
  const double denominator = 1.0 + z * z / n;
  const double centre = (p + z * z / (2 * n)) / denominator;
  const double half = z * std::sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denominator;
  return {std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

// A worker's compiled scenario: its trials come scenario by scenario, so it keeps the last one.
struct CompiledScenario {
  std::string path;
  std::shared_ptr<const twin::TwinModel> model;
};

TrialResult RunBrainTrial(const std::string& scenario_path, std::uint64_t seed,
                          CompiledScenario* compiled) {
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
  // Ground truth for the preemption latency: when a person (not one holding the door) really
  // entered a door zone. Only this trial harness reads it; the brain sees sensors only.
  std::vector<double> entered_at;
  bool inside_before = false;
  options.after_step = [&](const twin::TwinWorld& world, const behavior::Executive& brain) {
    bool inside = false;
    for (const auto& door : brain.services().map->doors) {
      const perception::DoorZone zone{door, brain.services().config.zone_depth,
                                      brain.services().config.person_radius};
      for (const auto& person : world.people()) {
        if (person.started && person.phase != twin::PersonPhase::kHolding &&
            zone.Contains(person.position))
          inside = true;
      }
    }
    if (inside && !inside_before) entered_at.push_back(world.time());
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
  r.person_contacts = m.contacts.count("person") ? m.contacts.at("person") : 0;
  r.static_contacts = m.contacts.count("static") ? m.contacts.at("static") : 0;
  for (const auto& [door, n] : m.button_presses)
    r.presses += n;
  r.relocalizations = brain->relocalizations();
  for (const auto& [known, commanded] : brain->preemptions()) {
    r.preemption_latencies.push_back(commanded - known);
    // The person's true entry before this stop (none: the forecast saw them coming).
    double entered = -1.0;
    for (double t : entered_at) {
      if (t <= commanded + 1e-9) entered = t;
    }
    r.preemption_total_latencies.push_back(entered >= 0 ? std::max(0.0, commanded - entered) : 0.0);
  }
  r.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return r;
}

nlohmann::json ToJson(const TrialResult& r) {
  return {{"scenario", r.scenario},
          {"name", r.name},
          {"seed", r.seed},
          {"success", r.success},
          {"failed", r.failed},
          {"time", r.time},
          {"min_person_distance", std::isfinite(r.min_person_distance)
                                      ? nlohmann::json(r.min_person_distance)
                                      : nlohmann::json(nullptr)},
          {"person_contacts", r.person_contacts},
          {"static_contacts", r.static_contacts},
          {"presses", r.presses},
          {"relocalizations", r.relocalizations},
          {"preemption_latencies", r.preemption_latencies},
          {"preemption_total_latencies", r.preemption_total_latencies},
          {"wall_time", r.wall_time},
          {"error", r.error}};
}

TrialResult TrialFromJson(const nlohmann::json& j) {
  TrialResult r;
  r.scenario = j.at("scenario").get<std::string>();
  r.name = j.at("name").get<std::string>();
  r.seed = j.at("seed").get<std::uint64_t>();
  r.success = j.at("success").get<bool>();
  r.failed = j.at("failed").get<std::vector<std::string>>();
  r.time = j.at("time").get<double>();
  r.min_person_distance = j.at("min_person_distance").is_null()
                              ? std::numeric_limits<double>::infinity()
                              : j.at("min_person_distance").get<double>();
  r.person_contacts = j.at("person_contacts").get<int>();
  r.static_contacts = j.at("static_contacts").get<int>();
  r.presses = j.at("presses").get<int>();
  r.relocalizations = j.value("relocalizations", 0);
  r.preemption_latencies = j.at("preemption_latencies").get<std::vector<double>>();
  r.preemption_total_latencies = j.at("preemption_total_latencies").get<std::vector<double>>();
  r.wall_time = j.at("wall_time").get<double>();
  r.error = j.at("error").get<std::string>();
  return r;
}

std::vector<ScenarioSummary> Summarize(const std::vector<TrialResult>& trials) {
  std::vector<ScenarioSummary> out;
  std::map<std::string, std::size_t> index;
  for (const TrialResult& t : trials) {
    auto [it, inserted] = index.try_emplace(t.scenario, out.size());
    if (inserted) {
      ScenarioSummary fresh;
      fresh.scenario = t.scenario;
      fresh.name = t.name;
      out.push_back(std::move(fresh));
    }
    ScenarioSummary& s = out[it->second];
    ++s.trials;
    s.successes += t.success ? 1 : 0;
    s.person_contacts += t.person_contacts;
    s.static_contacts += t.static_contacts;
    s.trials_with_static_contacts += t.static_contacts > 0 ? 1 : 0;
    s.trials_with_relocalizations += t.relocalizations > 0 ? 1 : 0;
    s.min_person_distance = std::min(s.min_person_distance, t.min_person_distance);
    if (t.success) s.times.push_back(t.time);
    if (!t.success) s.failed_seeds.push_back(t.seed);
    for (const auto& f : t.failed)
      ++s.failure_reasons[f];
    if (!t.error.empty()) ++s.failure_reasons["error: " + t.error];
  }
  for (ScenarioSummary& s : out) {
    s.rate = CalcWilsonInterval(s.successes, s.trials);
    if (!s.times.empty()) {
      std::vector<double> t = s.times;
      std::nth_element(t.begin(), t.begin() + std::ptrdiff_t(t.size() / 2), t.end());
      s.median_time = t[t.size() / 2];
    }
  }
  return out;
}

std::string FormatSummaryTable(const std::vector<ScenarioSummary>& summaries) {
  std::ostringstream out;
  out << fmt::format("{:<28} {:>6} {:>5} {:>7}  {:<15} {:>8} {:>9} {:>8} {:>6}  {}\n", "scenario",
                     "trials", "ok", "rate", "95% Wilson", "median", "closest", "contacts", "bumps",
                     "failure reasons");
  int trials = 0, successes = 0;
  for (const ScenarioSummary& s : summaries) {
    std::string reasons;
    for (const auto& [reason, n] : s.failure_reasons)
      reasons += fmt::format("{}{} x{}", reasons.empty() ? "" : ", ", reason, n);
    out << fmt::format(
        "{:<28} {:>6} {:>5} {:>6.1f}%  [{:>5.1f}, {:>5.1f}] {:>7} {:>9} {:>8} {:>6}  {}\n",
        s.name.substr(0, 28), s.trials, s.successes, 100.0 * s.successes / std::max(1, s.trials),
        100 * s.rate.low, 100 * s.rate.high,
        s.median_time ? fmt::format("{:.1f} s", *s.median_time) : "-",
        std::isfinite(s.min_person_distance) ? fmt::format("{:.2f} m", s.min_person_distance) : "-",
        s.person_contacts, s.trials_with_static_contacts, reasons.empty() ? "-" : reasons);
    trials += s.trials;
    successes += s.successes;
  }
  const WilsonInterval all = CalcWilsonInterval(successes, trials);
  out << fmt::format("{:<28} {:>6} {:>5} {:>6.1f}%  [{:>5.1f}, {:>5.1f}]\n", "total", trials,
                     successes, 100.0 * successes / std::max(1, trials), 100 * all.low,
                     100 * all.high);
  return out.str();
}

namespace {

struct BatchOptions {
  std::vector<std::string> scenarios;
  int trials{10};
  int jobs{2};
  std::uint64_t seed_base{1};
  std::string out{"batch"};
  bool overwrite{false};
  bool quiet{false};
};

// The trials in worker processes (workers.h), in the order of the work list.
std::vector<TrialResult> RunTrialsInWorkers(
    const std::vector<std::pair<std::string, std::uint64_t>>& work, int jobs, bool progress) {
  CompiledScenario compiled;  // each worker's own copy after the fork
  const std::vector<nlohmann::json> lines =
      RunInWorkers(work.size(), jobs, progress, [&](std::size_t k) {
        TrialResult r;
        try {
          r = RunBrainTrial(work[k].first, work[k].second, &compiled);
        } catch (const std::exception& e) {
          r.scenario = work[k].first;
          r.name = std::filesystem::path(work[k].first).stem().string();
          r.seed = work[k].second;
          r.error = e.what();
        }
        return ToJson(r);
      });
  std::vector<TrialResult> results;
  for (const auto& line : lines)
    results.push_back(TrialFromJson(line));
  return results;
}

void RunBatch(const BatchOptions& o) {
  if (o.trials < 1) throw CommandFailed("--trials must be at least 1");
  if (o.jobs < 1) throw CommandFailed("--jobs must be at least 1");
  const std::filesystem::path dir(o.out);
  const auto csv_path = dir / "trials.csv";
  const auto json_path = dir / "batch.json";
  for (const auto& p : {csv_path, json_path}) {
    if (std::filesystem::exists(p) && !o.overwrite) {
      throw CommandFailed(fmt::format("'{}' exists; pass --overwrite to replace it", p.string()));
    }
  }
  // Check every scenario (and its mission) before starting any worker.
  // SCENARIO or SCENARIO:N (N trials of that one, e.g. the paper's protocol).
  std::vector<std::pair<std::string, int>> plan;
  for (const auto& arg : o.scenarios) {
    std::string file = arg;
    int trials = o.trials;
    if (const auto colon = arg.rfind(':');
        colon != std::string::npos && !std::filesystem::exists(arg)) {
      const std::string count = arg.substr(colon + 1);
      if (count.empty() || count.find_first_not_of("0123456789") != std::string::npos ||
          std::stoll(count) < 1 || std::stoll(count) > 1000000) {
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
    plan.emplace_back(file, trials);
  }
  std::vector<std::pair<std::string, std::uint64_t>> work;
  for (const auto& [file, trials] : plan) {
    for (int i = 0; i < trials; ++i)
      work.emplace_back(file, o.seed_base + std::uint64_t(i));
  }
  if (!o.quiet) {
    fmt::print("{} scenario(s), {} runs on {} worker process(es)\n", plan.size(), work.size(),
               std::min<std::size_t>(std::size_t(o.jobs), work.size()));
  }
  const auto started = std::chrono::steady_clock::now();
  const std::vector<TrialResult> results =
      RunTrialsInWorkers(work, o.jobs, !o.quiet && ::isatty(::fileno(stderr)));
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  const std::vector<ScenarioSummary> summaries = Summarize(results);
  std::cout << FormatSummaryTable(summaries);
  const auto report = [&](const char* what, auto member) {
    std::vector<double> l;
    for (const auto& r : results)
      l.insert(l.end(), (r.*member).begin(), (r.*member).end());
    if (l.empty()) return;
    std::sort(l.begin(), l.end());
    const auto q = [&](double f) { return l[std::min(l.size() - 1, std::size_t(f * l.size()))]; };
    fmt::print("preemption, {}: {} events, median {:.3f} s, p90 {:.3f} s, max {:.3f} s\n", what,
               l.size(), q(0.5), q(0.9), l.back());
  };
  report("stack's share (person in the zone in the world model -> stop command)",
         &TrialResult::preemption_latencies);
  report("total (person really in the zone -> stop command, sensor latency included)",
         &TrialResult::preemption_total_latencies);
  fmt::print("wall time {:.1f} s for {} trials ({} jobs)\n", wall, results.size(), o.jobs);
  for (const auto& r : results) {
    if (r.success) continue;
    std::string why;
    for (const auto& f : r.failed)
      why += (why.empty() ? "" : ", ") + f;
    if (!r.error.empty()) why = r.error;
    fmt::print("  failed: {} seed {} ({})  replay: egress sim run {} --seed {}\n", r.name, r.seed,
               why, r.scenario, r.seed);
  }
  std::filesystem::create_directories(dir);
  {
    std::ofstream csv(csv_path);
    csv << "scenario,name,seed,success,time_s,min_person_distance_m,person_contacts,"
           "static_contacts,presses,relocalizations,failed,wall_s\n";
    for (const auto& r : results) {
      std::string failed;
      for (const auto& f : r.failed)
        failed += (failed.empty() ? "" : ";") + f;
      csv << fmt::format(
          "{},\"{}\",{},{},{:.2f},{},{},{},{},{},\"{}\",{:.2f}\n", r.scenario, r.name, r.seed,
          r.success ? 1 : 0, r.time,
          std::isfinite(r.min_person_distance) ? fmt::format("{:.3f}", r.min_person_distance) : "",
          r.person_contacts, r.static_contacts, r.presses, r.relocalizations,
          r.error.empty() ? failed : r.error, r.wall_time);
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
         {"person_contacts", s.person_contacts},
         {"static_contacts", s.static_contacts},
         {"trials_with_static_contacts", s.trials_with_static_contacts},
         {"trials_with_relocalizations", s.trials_with_relocalizations},
         {"failure_reasons", s.failure_reasons},
         {"failed_seeds", s.failed_seeds}});
  }
  nlohmann::json trials = nlohmann::json::array();
  for (const auto& r : results)
    trials.push_back(ToJson(r));
  std::ofstream(json_path) << nlohmann::json{{"wall_s", wall},
                                             {"jobs", o.jobs},
                                             {"summary", summary},
                                             {"trials", trials}}
                                  .dump(2)
                           << "\n";
  fmt::print("wrote {} and {}\n", csv_path.string(), json_path.string());
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
  batch->add_option("--out", o->out, "directory for trials.csv and batch.json")
      ->capture_default_str();
  batch->add_flag("--overwrite", o->overwrite, "replace existing result files");
  batch->add_flag("-q,--quiet", o->quiet, "no progress bar");
  batch->callback([o] { RunBatch(*o); });
}

}  // namespace egress::apps
