#pragma once
// Sub-commands of the `egress` program. Each Add*Command registers its CLI11 sub-command and the
// callback that runs it; a callback reports failure by throwing, and main() turns any exception
// into a one-line error and exit code 1.

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace egress::apps {

/// A sub-command failed; its message (if not empty) is printed by main(), which exits with 1.
/// An empty message means the command has reported the failure itself.
class CommandFailed : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A CLI11 check for a real number in [lo, hi] that also refuses NaN and infinity (CLI11's own
/// PositiveNumber and Range let NaN through: every comparison with it is false).
inline CLI::Validator FiniteIn(double lo, double hi) {
  const std::string range =
      "[" + CLI::detail::to_string(lo) + ", " + CLI::detail::to_string(hi) + "]";
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (text.empty() || end == nullptr || *end != '\0') return "'" + text + "' is not a number";
        if (!std::isfinite(v) || v < lo || v > hi)
          return "must be a finite number in " + range + ", not " + text;
        return {};
      },
      "FINITE in " + range);
}

/// Bounds of batch sizes on the command line: trials (or runs) per scenario and worker
/// processes.
inline constexpr int kMaxTrials = 1'000'000;
inline constexpr int kMaxJobs = 256;

/// --seed-base of a batch of `trials` trials: the last trial's seed (seed-base + trials - 1)
/// must be at most `max_seed` (the scenarios' own bound), not wrap past 2^64 to 0.
/// @throws CommandFailed naming --seed-base and both numbers.
inline void CheckSeedBase(std::uint64_t seed_base, int trials, std::uint64_t max_seed) {
  const std::uint64_t span = trials > 0 ? std::uint64_t(trials) - 1 : 0;
  if (seed_base > max_seed || max_seed - seed_base < span)
    throw CommandFailed("--seed-base " + std::to_string(seed_base) + " with " +
                        std::to_string(trials) + " trials: the last trial's seed must be at most " +
                        std::to_string(max_seed) + " (a scenario's largest seed)");
}

/// `egress --version`: the text printed (egress version, git revision, library versions).
std::string VersionText();

/// `egress model ...`: inspect the HSR robot model (joints, limits, forward kinematics).
void AddModelCommand(CLI::App& app);

/// `egress bt validate|trace`: check BehaviorTree.CPP v4 trees and run them with scripted
/// stand-in leaves.
void AddBtCommand(CLI::App& app);

/// `egress costmap MAP.yaml --out F.png`: render the door-aware costmap of a map.
void AddCostmapCommand(CLI::App& app);

/// `egress plan`: plan a base path through egress-navd or in-process, optionally as a PNG.
void AddPlanCommand(CLI::App& app);

/// `egress bench plan`: the planners over the planning suite, OMPL benchmark logs + CSV.
void AddBenchCommand(CLI::App& app);

/// `egress sim run SCENARIO` (one twin run, judged), `egress sim batch` (reserved) and
/// `egress render TRACE` (PNG/MP4).
void AddSimCommand(CLI::App& app);
/// `egress evac study SCENARIO`: evacuation time with no robot, the robot escorting, and every
/// door propped open, on the same seeds.
void AddEvacCommand(CLI::App& app);
/// `egress twin serve --ros2 SCENARIO` (the twin as a ROS 2 robot) and `egress robot --ros2`
/// (the brain against a robot over ROS 2).
void AddRos2Commands(CLI::App& app);
/// A sub-command reserved for a capability that is not built yet: it is listed in --help with
/// what it will do, and running it fails with a clear message.
void AddPlannedCommand(CLI::App& app, const std::string& name, const std::string& description,
                       const std::string& arrives_with);

}  // namespace egress::apps
