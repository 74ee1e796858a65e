#pragma once
/// @file
/// A pool of forked worker processes for independent seeded runs (`sim batch`, `evac study`):
/// worker j runs items j, j + J, ... and reports each as one JSON line on its pipe; the parent
/// collects them, draws a progress bar and returns them in item order — so results do not depend
/// on the number of workers.

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace egress::apps {

/// Runs `count` items in min(jobs, count) worker processes; `run_one(i)` returns item i's result
/// (a throw becomes {"error": what}). `what` names the items on the progress bar ("trials").
/// @throws CommandFailed when a worker cannot be started or dies before reporting all its items.
std::vector<nlohmann::json> RunInWorkers(std::size_t count, int jobs, bool progress,
                                         const std::function<nlohmann::json(std::size_t)>& run_one,
                                         const std::string& what = "trials");

}  // namespace egress::apps
