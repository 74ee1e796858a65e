#pragma once
/// @file
/// A pool of forked worker processes for independent seeded runs (`sim batch`, `evac study`).
/// The parent hands items out one at a time (so a slow item does not hold up a fixed share),
/// collects each result as one JSON line, draws a progress bar and returns the results in item
/// order — so results do not depend on the number of workers. A worker that dies while running
/// an item (a signal, an exit) has that item reported as crashed and is replaced; the other
/// items go on.

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace egress::apps {

struct WorkerPoolOptions {
  int jobs{1};
  bool progress{false};
  std::string what{"trials"};  ///< Names the items on the progress bar.
  /// Items not to run (already done, e.g. read from a journal); their results stay null and
  /// they count as done on the progress bar. Empty: run all.
  std::vector<bool> skip;
  /// Called in the parent as each result arrives, in completion order (a journal appends it).
  std::function<void(std::size_t, const nlohmann::json&)> on_result;
};

/// The result a worker's death leaves for the item it was running:
/// {"crashed": {"signal": S} or {"exit_code": C}, "error": "worker died: ..."}.
nlohmann::json CrashedResult(int wait_status);

/// Runs items 0..count-1 (minus options.skip) in min(jobs, items) worker processes;
/// `run_one(i)` returns item i's result (a throw becomes {"error": what}). Workers die with the
/// parent. @throws CommandFailed when a worker cannot be started.
std::vector<nlohmann::json> RunInWorkers(std::size_t count,
                                         const std::function<nlohmann::json(std::size_t)>& run_one,
                                         const WorkerPoolOptions& options);

/// The same with default options but jobs, progress and `what`.
std::vector<nlohmann::json> RunInWorkers(std::size_t count, int jobs, bool progress,
                                         const std::function<nlohmann::json(std::size_t)>& run_one,
                                         const std::string& what = "trials");

}  // namespace egress::apps
