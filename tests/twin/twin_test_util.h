#pragma once
// Shared helpers of the twin tests: where the worlds are, and a world built from scenario text.

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "egress/hsr_interface/robot_model.h"
#include "egress/twin/scenario.h"
#include "egress/twin/sdf_world_loader.h"
#include "egress/twin/twin_world.h"

namespace egress::twin::testing {

/// egress's worlds/ folder (defined in twin_test_util.cpp, the one file that holds the path).
std::filesystem::path WorldsDir();

/// The reference folder (../shared/reference through EGRESS_REFERENCE_DIR), or empty.
inline std::filesystem::path ReferenceDir() {
  const char* env = std::getenv("EGRESS_REFERENCE_DIR");
  if (env == nullptr || !std::filesystem::exists(env)) return {};
  return env;
}

inline std::shared_ptr<const RobotModel> Hsr() {
  static const auto model = std::make_shared<const RobotModel>(RobotModel::LoadDefault());
  return model;
}

/// A scenario in `world_dir` (relative world paths resolve there) and its world.
struct Loaded {
  Scenario scenario;
  WorldDescription world;
};

inline Loaded LoadText(const std::string& yaml, const std::filesystem::path& dir) {
  Loaded out;
  out.scenario = LoadScenarioFromString(yaml, "test.yaml", dir);
  out.world = LoadSdfWorld(out.scenario.world_file);
  return out;
}

/// How many events of `kind` (about `subject`, if given) the world has raised.
inline int CountEvents(const TwinWorld& w, const std::string& kind,
                       const std::string& subject = "") {
  int n = 0;
  for (const auto& e : w.events())
    n += e.kind == kind && (subject.empty() || e.subject == subject) ? 1 : 0;
  return n;
}

}  // namespace egress::twin::testing
