#include "fuzz_targets.h"

#include <exception>
#include <filesystem>
#include <string>

#include "egress/bt/blackboard.h"
#include "egress/bt/errors.h"
#include "egress/bt/factory.h"
#include "egress/bt/script.h"
#include "egress/hsr_interface/error.h"
#include "egress/hsr_interface/robot_model.h"
#include "egress/twin/scenario.h"
#include "egress/twin/sdf_world_loader.h"

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

const std::vector<NamedTarget>& AllTargets() {
  static const std::vector<NamedTarget> targets = {{"bt_script", BtScript},
                                                   {"bt_xml", BtXml},
                                                   {"scenario_yaml", ScenarioYaml},
                                                   {"sdf_world", SdfWorld},
                                                   {"urdf", Urdf}};
  return targets;
}

}  // namespace egress::fuzz
