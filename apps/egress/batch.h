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
#include <nlohmann/json.hpp>

#include "track_judge.h"

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
  double closest_robot_speed{0.0};  ///< The robot's speed at that closest moment [m/s].
  /// The closest approach to a person in sight (RunMetrics::min_person_distance_in_sight) [m].
  double min_person_distance_in_sight{std::numeric_limits<double>::infinity()};
  double closest_in_sight_robot_speed{0.0};  ///< The robot's speed then [m/s].
  int person_contacts{0};
  int static_contacts{0};  ///< The robot touching walls or furniture (not a failure; a bump).
  int presses{0};
  int relocalizations{0};  ///< Precise acts that waited for an uncertain pose to settle.
  std::vector<double> preemption_latencies;        ///< [s] person seen in the zone -> stop.
  std::vector<double> preemption_total_latencies;  ///< [s] person in the zone (truth) -> stop.
  /// The total latencies of the events whose person was in the base laser's view on entering.
  std::vector<double> preemption_laser_view_latencies;
  /// Track samples of people standing still, and those read as walking (StandingTrackJudge).
  StandingReadWalking standing_tracks;
  double wall_time{0.0};  ///< [s]
  std::string error;      ///< The run threw this.
  bool crashed{false};    ///< The worker process died running it (`error` says how).
  /// Not a success, but the brain gave up by itself (its mission failed or it halted) with
  /// the robot standing still and no person touched: a safe abort, for the reason given.
  bool safe_abort{false};
  std::string abort_reason;  ///< The brain's last note before it gave up.
};

/// A closest approach under this is too close [m] (issue 21's bar), unless the robot stood
/// (slower than ScenarioJudge::kWaitSpeed).
inline constexpr double kCloseApproach = 0.3;

struct ScenarioSummary {
  std::string scenario;
  std::string name;
  int trials{0};
  int successes{0};
  WilsonInterval rate;
  std::optional<double> median_time;  ///< Of the successful trials [s].
  double min_person_distance{std::numeric_limits<double>::infinity()};  ///< The worst trial's.
  std::optional<double> median_person_distance;  ///< Over the trials that met a person [m].
  std::optional<double> p10_person_distance;     ///< Their 10th percentile [m].
  /// Trials whose closest approach was under kCloseApproach with the robot moving (it came
  /// to the person, rather than the person to a standing robot).
  int close_approaches_moving{0};
  std::vector<double> person_distances;  ///< Per trial that met a person [m].
  /// The same for people in sight (TrialResult::min_person_distance_in_sight).
  double min_person_distance_in_sight{std::numeric_limits<double>::infinity()};
  std::optional<double> median_person_distance_in_sight;
  std::optional<double> p10_person_distance_in_sight;
  std::vector<double> person_distances_in_sight;
  int person_contacts{0};
  int static_contacts{0};
  int trials_with_static_contacts{0};
  int trials_with_relocalizations{0};
  int safe_aborts{0};  ///< Trials that were not successes but safe aborts.
  std::map<std::string, int> failure_reasons;
  std::vector<std::uint64_t> failed_seeds;
  std::vector<double> times;
};

/// A trial's result as a line of the journal and of batch.json, and back (fields a batch of an
/// earlier stop did not write take their defaults).
nlohmann::json ToJson(const TrialResult& r);
TrialResult TrialFromJson(const nlohmann::json& j);

/// Per scenario, in the order first seen.
std::vector<ScenarioSummary> Summarize(const std::vector<TrialResult>& trials);
std::string FormatSummaryTable(const std::vector<ScenarioSummary>& summaries);

/// Adds `batch` and `merge` under the `sim` command group.
void AddSimBatchCommand(CLI::App& sim_group);

}  // namespace egress::apps
