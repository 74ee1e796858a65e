#pragma once
/// @file
/// Batch trials of twin scenarios driven by the robot brain (`egress sim batch`): one trial's
/// result, per-scenario summaries with a Wilson score interval, and the table like the paper's
/// Table I.

#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace egress::apps {

/// A binomial proportion's confidence interval (Wilson score), in [0, 1].
struct WilsonInterval {
  double low{0.0};
  double high{1.0};
};
/// z = 1.96 gives the 95% interval. @throws InvalidArgument unless 0 <= successes <= trials.
WilsonInterval CalcWilsonInterval(int successes, int trials, double z = 1.96);

struct TrialResult {
  std::string scenario;  ///< The scenario file as given.
  std::string name;      ///< Its name.
  std::uint64_t seed{0};
  bool success{false};
  std::vector<std::string> failed;  ///< Names of the failed predicates.
  double time{0.0};                 ///< Time to goal, else the run's end [s].
  double min_person_distance{std::numeric_limits<double>::infinity()};  ///< [m]
  int person_contacts{0};
  int static_contacts{0};  ///< The robot touching walls or furniture (not a failure; a bump).
  int presses{0};
  int relocalizations{0};  ///< Precise acts that waited for an uncertain pose to settle.
  std::vector<double> preemption_latencies;        ///< [s] person seen in the zone -> stop.
  std::vector<double> preemption_total_latencies;  ///< [s] person in the zone (truth) -> stop.
  double wall_time{0.0};                           ///< [s]
  std::string error;                               ///< The run threw this.
  bool crashed{false};  ///< The worker process died running it (`error` says how).
  /// Not a success, but the brain gave up by itself (its mission failed or it halted) with
  /// the robot standing still and no person touched: a safe abort, for the reason given.
  bool safe_abort{false};
  std::string abort_reason;  ///< The brain's last note before it gave up.
};

/// One trial in this process. @throws like `egress sim run` for a bad scenario.
TrialResult RunBrainTrial(const std::string& scenario_path, std::uint64_t seed);

struct ScenarioSummary {
  std::string scenario;
  std::string name;
  int trials{0};
  int successes{0};
  WilsonInterval rate;
  std::optional<double> median_time;  ///< Of the successful trials [s].
  double min_person_distance{std::numeric_limits<double>::infinity()};
  int person_contacts{0};
  int static_contacts{0};
  int trials_with_static_contacts{0};
  int trials_with_relocalizations{0};
  int safe_aborts{0};  ///< Trials that were not successes but safe aborts.
  std::map<std::string, int> failure_reasons;
  std::vector<std::uint64_t> failed_seeds;
  std::vector<double> times;
};

/// Per scenario, in the order first seen.
std::vector<ScenarioSummary> Summarize(const std::vector<TrialResult>& trials);
std::string FormatSummaryTable(const std::vector<ScenarioSummary>& summaries);

/// Adds `batch` and `merge` under the `sim` command group.
void AddSimBatchCommand(CLI::App& sim_group);

}  // namespace egress::apps
