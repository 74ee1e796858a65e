#include "fuzz_targets.h"

#include <unistd.h>

#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include "egress/bt/blackboard.h"
#include "egress/bt/errors.h"
#include "egress/bt/factory.h"
#include "egress/bt/script.h"
#include "egress/hsr_interface/error.h"
#include "egress/hsr_interface/robot_model.h"
#include "egress/hsr_interface/text_file.h"
#include "egress/perception/occupancy_grid.h"
#include "egress/twin/scenario.h"
#include "egress/twin/sdf_world_loader.h"
#include "navigation_server.h"

namespace egress::fuzz {
namespace {

std::string Text(const std::uint8_t* data, std::size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

// Ticks of a fuzzed tree: enough to reach its nodes' running paths, few enough to stay fast
// (a tree that waits on a timer just stays RUNNING: the injected clock does not advance).
constexpr int kTicks = 8;

}  // namespace

int BtScript(const std::uint8_t* data, std::size_t size) {
  try {
    const auto script = bt::Script::Parse(Text(data, size));
    auto board = bt::Blackboard::Create();
    const bt::ScriptEnums enums{{"OPEN", 1}, {"CLOSED", 0}};
    script->Evaluate({board.get(), &enums});
  } catch (const bt::LogicError&) {
  } catch (const bt::RuntimeError&) {
  }
  return 0;
}

int BtXml(const std::uint8_t* data, std::size_t size) {
  try {
    bt::BehaviorTreeFactory factory;
    const std::string xml = Text(data, size);
    factory.RegisterStandInsFromModelText(xml, "fuzz.xml");
    bt::Tree tree = factory.CreateTreeFromText(xml);
    for (int i = 0; i < kTicks; ++i)
      tree.TickOnce();
    tree.HaltTree();
  } catch (const bt::LogicError&) {
  } catch (const bt::RuntimeError&) {
  }
  return 0;
}

int ScenarioYaml(const std::uint8_t* data, std::size_t size) {
  try {
    twin::LoadScenarioFromString(Text(data, size), "fuzz.yaml",
                                 std::filesystem::path(EGRESS_SOURCE_DIR) / "worlds/lab");
  } catch (const LoadError&) {
  }
  return 0;
}

int SdfWorld(const std::uint8_t* data, std::size_t size) {
  try {
    twin::LoadSdfWorldFromString(Text(data, size), "fuzz.sdf",
                                 std::filesystem::path(EGRESS_SOURCE_DIR) / "worlds/lab");
  } catch (const LoadError&) {
  }
  return 0;
}

int Urdf(const std::uint8_t* data, std::size_t size) {
  try {
    RobotModel::LoadFromString(Text(data, size), "fuzz.urdf");
  } catch (const LoadError&) {
  }
  return 0;
}

int MapServer(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("egress_fuzz_map_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string text = Text(data, size);
  const std::size_t nul = text.find('\0');
  std::ofstream(dir / "map.yaml", std::ios::binary | std::ios::trunc) << text.substr(0, nul);
  std::ofstream(dir / "map.pgm", std::ios::binary | std::ios::trunc)
      << (nul == std::string::npos ? std::string() : text.substr(nul + 1));
  try {
    const ScopedReadRoot root(dir);
    perception::OccupancyGrid::LoadMapServerYaml(dir / "map.yaml", 1'000'000);
  } catch (const LoadError&) {
  } catch (const InvalidArgument&) {
  }
  return 0;
}

int NavdRequests(const std::uint8_t* data, std::size_t size) {
  navd::NavigationServerConfig config;
  config.max_map_cells = 1'000'000;
  config.max_cached_cells = 2'000'000;
  config.max_worlds = 4;
  config.max_time_budget_s = 0.05;  // a planner may run; not for long
  navd::NavigationHandlers handlers(config);
  const auto& rpcs = navd::NavigationHandlers::Rpcs();
  std::size_t at = 0;
  while (at + 3 <= size) {
    const std::string& rpc = rpcs[data[at] % rpcs.size()];
    const std::size_t length = std::size_t(data[at + 1]) | (std::size_t(data[at + 2]) << 8);
    at += 3;
    const std::size_t n = std::min(length, size - at);
    handlers.Call(rpc, std::string_view(reinterpret_cast<const char*>(data + at), n));
    at += n;
  }
  return 0;
}

const std::vector<NamedTarget>& AllTargets() {
  static const std::vector<NamedTarget> targets = {
      {"bt_script", BtScript},        {"bt_xml", BtXml}, {"scenario_yaml", ScenarioYaml},
      {"sdf_world", SdfWorld},        {"urdf", Urdf},    {"map_server", MapServer},
      {"navd_requests", NavdRequests}};
  return targets;
}

}  // namespace egress::fuzz
