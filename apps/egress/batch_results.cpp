// `egress sim batch`'s results (batch.h): one trial's result to and from JSON (the journal's and
// batch.json's lines), the per-scenario summaries with their Wilson intervals, and the table.

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "batch.h"
#include "egress/hsr_interface/error.h"
#include "egress/twin/scenario_judge.h"
#include "study_stats.h"

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
          {"preemption_laser_view_latencies", r.preemption_laser_view_latencies},
          {"closest_robot_speed", r.closest_robot_speed},
          {"min_person_distance_in_sight", std::isfinite(r.min_person_distance_in_sight)
                                               ? nlohmann::json(r.min_person_distance_in_sight)
                                               : nlohmann::json(nullptr)},
          {"closest_in_sight_robot_speed", r.closest_in_sight_robot_speed},
          {"standing_tracks",
           {{"robot_moving",
             {{"samples", r.standing_tracks.moving_samples},
              {"walking", r.standing_tracks.moving_walking}}},
            {"robot_still",
             {{"samples", r.standing_tracks.still_samples},
              {"walking", r.standing_tracks.still_walking}}}}},
          {"wall_time", r.wall_time},
          {"error", r.error},
          {"crashed", r.crashed},
          {"safe_abort", r.safe_abort},
          {"abort_reason", r.abort_reason}};
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
  r.preemption_laser_view_latencies =
      j.value("preemption_laser_view_latencies", std::vector<double>());
  r.closest_robot_speed = j.value("closest_robot_speed", 0.0);
  // A journal of an earlier stop has no figure in sight: unknown, as for nobody met.
  if (const auto it = j.find("min_person_distance_in_sight"); it != j.end() && !it->is_null())
    r.min_person_distance_in_sight = it->get<double>();
  r.closest_in_sight_robot_speed = j.value("closest_in_sight_robot_speed", 0.0);
  if (j.contains("standing_tracks")) {
    const auto& s = j.at("standing_tracks");
    r.standing_tracks = {s.at("robot_moving").at("samples").get<int>(),
                         s.at("robot_moving").at("walking").get<int>(),
                         s.at("robot_still").at("samples").get<int>(),
                         s.at("robot_still").at("walking").get<int>()};
  }
  r.wall_time = j.at("wall_time").get<double>();
  r.error = j.at("error").get<std::string>();
  r.crashed = j.value("crashed", false);
  r.safe_abort = j.value("safe_abort", false);
  r.abort_reason = j.value("abort_reason", std::string());
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
    s.safe_aborts += t.safe_abort ? 1 : 0;
    s.min_person_distance = std::min(s.min_person_distance, t.min_person_distance);
    if (std::isfinite(t.min_person_distance)) {
      s.person_distances.push_back(t.min_person_distance);
      if (t.min_person_distance < kCloseApproach &&
          t.closest_robot_speed >= twin::ScenarioJudge::kWaitSpeed)
        ++s.close_approaches_moving;
    }
    s.min_person_distance_in_sight =
        std::min(s.min_person_distance_in_sight, t.min_person_distance_in_sight);
    if (std::isfinite(t.min_person_distance_in_sight))
      s.person_distances_in_sight.push_back(t.min_person_distance_in_sight);
    if (t.success) s.times.push_back(t.time);
    if (!t.success) s.failed_seeds.push_back(t.seed);
    if (t.safe_abort) {
      ++s.failure_reasons["safe abort: " + t.abort_reason];
    } else {
      for (const auto& f : t.failed)
        ++s.failure_reasons[f];
    }
    if (!t.error.empty()) ++s.failure_reasons["error: " + t.error];
  }
  for (ScenarioSummary& s : out) {
    s.rate = CalcWilsonInterval(s.successes, s.trials);
    if (!s.times.empty()) s.median_time = CalcQuantile(s.times, 0.5);
    if (!s.person_distances.empty()) {
      s.median_person_distance = CalcQuantile(s.person_distances, 0.5);
      s.p10_person_distance = CalcQuantile(s.person_distances, 0.1);
    }
    if (!s.person_distances_in_sight.empty()) {
      s.median_person_distance_in_sight = CalcQuantile(s.person_distances_in_sight, 0.5);
      s.p10_person_distance_in_sight = CalcQuantile(s.person_distances_in_sight, 0.1);
    }
  }
  return out;
}

std::string FormatSummaryTable(const std::vector<ScenarioSummary>& summaries) {
  std::ostringstream out;
  out << fmt::format("{:<28} {:>6} {:>5} {:>7}  {:<15} {:>5} {:>8} {:>16} {:>16} {:>8} {:>6}  {}\n",
                     "scenario", "trials", "ok", "rate", "95% Wilson", "safe", "median",
                     "closest med/worst", "in sight", "contacts", "bumps", "failure reasons");
  int trials = 0, successes = 0;
  for (const ScenarioSummary& s : summaries) {
    std::string reasons;
    for (const auto& [reason, n] : s.failure_reasons)
      reasons += fmt::format("{}{} x{}", reasons.empty() ? "" : ", ", reason, n);
    out << fmt::format(
        "{:<28} {:>6} {:>5} {:>6.1f}%  [{:>5.1f}, {:>5.1f}] {:>5} {:>7} {:>16} {:>16} {:>8} {:>6}  "
        "{}\n",
        s.name.substr(0, 28), s.trials, s.successes, 100.0 * s.successes / std::max(1, s.trials),
        100 * s.rate.low, 100 * s.rate.high, s.successes + s.safe_aborts,
        s.median_time ? fmt::format("{:.1f} s", *s.median_time) : "-",
        s.median_person_distance
            ? fmt::format("{:.2f}/{:.2f} m{}", *s.median_person_distance, s.min_person_distance,
                          s.close_approaches_moving > 0 ? "*" : "")
            : "-",
        s.median_person_distance_in_sight
            ? fmt::format("{:.2f}/{:.2f} m", *s.median_person_distance_in_sight,
                          s.min_person_distance_in_sight)
            : "-",
        s.person_contacts, s.trials_with_static_contacts, reasons.empty() ? "-" : reasons);
    trials += s.trials;
    successes += s.successes;
  }
  const WilsonInterval all = CalcWilsonInterval(successes, trials);
  out << fmt::format("{:<28} {:>6} {:>5} {:>6.1f}%  [{:>5.1f}, {:>5.1f}]\n", "total", trials,
                     successes, 100.0 * successes / std::max(1, trials), 100 * all.low,
                     100 * all.high);
  if (std::any_of(summaries.begin(), summaries.end(),
                  [](const ScenarioSummary& s) { return s.close_approaches_moving > 0; })) {
    out << fmt::format("* a trial came under {:.1f} m with the robot moving\n", kCloseApproach);
  }
  return out.str();
}

}  // namespace egress::apps
