// `egress bt validate` and `egress bt trace`: load and check BehaviorTree.CPP v4 trees, and run
// them without a robot, their unknown leaves driven by a per-tick script of outcomes.

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <set>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "egress/behavior/task_nodes.h"
#include "egress/bt/factory.h"
#include "egress/bt/loggers.h"

namespace egress::apps {
namespace {

namespace bt = egress::bt;

struct BtOptions {
  std::string tree_file;
  std::string tree_id;
  std::vector<std::string> models;
  std::string script_file;
  std::string btlog;
  bool json{false};
  std::string format{"text"};
  std::uint64_t ticks{0};  ///< 0: until the root completes or the script's max_ticks
};

void RegisterModels(bt::BehaviorTreeFactory& factory, const BtOptions& options) {
  for (const auto& model : options.models)
    factory.RegisterStandInsFromModelFile(model);
}

int RunValidate(const BtOptions& options) {
  // A strict load first; if it fails, a tolerant one lists everything unknown at once.
  std::string strict_error;
  {
    bt::BehaviorTreeFactory factory;
    RegisterModels(factory, options);
    try {
      bt::Tree tree = factory.CreateTreeFromFile(options.tree_file, options.tree_id);
      for (const auto& warning : factory.warnings())
        fmt::print("warning: {}\n", warning);
      std::set<std::string> subtrees;
      for (const auto& node : tree.nodes()) {
        if (node->kind() == bt::NodeKind::kSubTree) subtrees.insert(node->config().subtree_id);
      }
      fmt::print("OK: {} loads: tree '{}', {} nodes, {} subtree types\n", options.tree_file,
                 tree.main_tree_id(), tree.nodes().size(), subtrees.size());
      return 0;
    } catch (const bt::LogicError& e) {
      strict_error = e.what();
    }
  }
  bt::BehaviorTreeFactory factory;
  RegisterModels(factory, options);
  try {
    bt::Tree tree =
        factory.CreateTreeFromFile(options.tree_file, options.tree_id, nullptr, {true, true});
    for (const auto& warning : factory.warnings())
      fmt::print("warning: {}\n", warning);
    fmt::print("error: {}\n", strict_error);
    if (!tree.stand_in_node_ids().empty()) {
      fmt::print("unknown node types ({}): {}\n", tree.stand_in_node_ids().size(),
                 fmt::join(tree.stand_in_node_ids(), ", "));
    }
    if (!tree.stubbed_subtree_ids().empty()) {
      fmt::print("undefined subtrees ({}): {}\n", tree.stubbed_subtree_ids().size(),
                 fmt::join(tree.stubbed_subtree_ids(), ", "));
    }
    fmt::print(
        "hint: register the node types in egress, pass their TreeNodesModel with --model, or "
        "include "
        "the files that define the subtrees\n");
  } catch (const bt::LogicError& e) {
    fmt::print("error: {}\n", e.what());
  }
  return 1;
}

// ---- trace

struct TickScript {
  std::map<std::string, bt::NodeStatus> outcomes;
  std::vector<std::pair<std::string, YAML::Node>> blackboard;
};

struct TraceScript {
  std::string tree;
  std::int64_t tick_period_ms{100};
  std::uint64_t max_ticks{100};
  bt::NodeStatus default_outcome{bt::NodeStatus::kSuccess};
  std::vector<std::pair<std::string, YAML::Node>> blackboard;
  std::vector<TickScript> ticks;
};

[[noreturn]] void ScriptError(const std::string& file, const YAML::Node& node,
                              const std::string& what) {
  throw std::runtime_error(fmt::format("{}:{}: {}", file, node.Mark().line + 1, what));
}

bt::NodeStatus ParseOutcome(const std::string& file, const YAML::Node& node,
                            const std::string& field) {
  const auto status = bt::ParseNodeStatus(node.as<std::string>());
  if (!status || *status == bt::NodeStatus::kIdle) {
    ScriptError(file, node,
                fmt::format("{}: '{}' is not an outcome (RUNNING, SUCCESS, FAILURE, SKIPPED)",
                            field, node.as<std::string>()));
  }
  return *status;
}

void CheckKeys(const std::string& file, const YAML::Node& map, const std::set<std::string>& allowed,
               const std::string& where) {
  if (!map.IsMap()) ScriptError(file, map, fmt::format("{} must be a mapping", where));
  for (const auto& entry : map) {
    const std::string key = entry.first.as<std::string>();
    if (!allowed.contains(key)) {
      ScriptError(file, entry.first,
                  fmt::format("unknown field '{}' in {} (allowed: {})", key, where,
                              fmt::join(allowed, ", ")));
    }
  }
}

std::vector<std::pair<std::string, YAML::Node>> ReadBlackboard(const std::string& file,
                                                               const YAML::Node& node) {
  if (!node.IsMap()) ScriptError(file, node, "blackboard must be a mapping of key: value");
  std::vector<std::pair<std::string, YAML::Node>> out;
  for (const auto& entry : node)
    out.emplace_back(entry.first.as<std::string>(), entry.second);
  return out;
}

TraceScript ReadTraceScript(const std::string& file) {
  if (!std::filesystem::is_regular_file(file))
    throw std::runtime_error(fmt::format("script '{}' does not exist", file));
  YAML::Node root;
  try {
    root = YAML::LoadFile(file);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(
        fmt::format("{}:{}: malformed YAML: {}", file, e.mark.line + 1, e.msg));
  }
  TraceScript script;
  CheckKeys(file, root, {"tree", "tick_period_ms", "max_ticks", "default", "blackboard", "ticks"},
            "the script");
  try {
    if (root["tree"]) script.tree = root["tree"].as<std::string>();
    if (root["tick_period_ms"]) script.tick_period_ms = root["tick_period_ms"].as<std::int64_t>();
    if (root["max_ticks"]) script.max_ticks = root["max_ticks"].as<std::uint64_t>();
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(fmt::format("{}:{}: {}", file, e.mark.line + 1, e.msg));
  }
  if (script.tick_period_ms < 0)
    ScriptError(file, root["tick_period_ms"], "tick_period_ms must be >= 0");
  if (root["default"]) script.default_outcome = ParseOutcome(file, root["default"], "default");
  if (root["blackboard"]) script.blackboard = ReadBlackboard(file, root["blackboard"]);
  if (root["ticks"]) {
    if (!root["ticks"].IsSequence()) ScriptError(file, root["ticks"], "ticks must be a list");
    for (const auto& tick : root["ticks"]) {
      CheckKeys(file, tick, {"outcomes", "blackboard"}, "a tick");
      TickScript t;
      if (tick["outcomes"]) {
        if (!tick["outcomes"].IsMap())
          ScriptError(file, tick["outcomes"], "outcomes must be a mapping node: OUTCOME");
        for (const auto& entry : tick["outcomes"]) {
          t.outcomes[entry.first.as<std::string>()] = ParseOutcome(
              file, entry.second, "outcome of '" + entry.first.as<std::string>() + "'");
        }
      }
      if (tick["blackboard"]) t.blackboard = ReadBlackboard(file, tick["blackboard"]);
      script.ticks.push_back(std::move(t));
    }
  }
  return script;
}

bt::Any ToAny(const YAML::Node& value) {
  const std::string text = value.as<std::string>();
  try {
    return bt::Any(bt::ParseInteger(text));
  } catch (const bt::RuntimeError&) {
  }
  try {
    return bt::Any(bt::ParseReal(text));
  } catch (const bt::RuntimeError&) {
  }
  if (text == "true" || text == "false") return bt::Any(text == "true");
  return bt::Any(text);
}

/// Every blackboard of the tree (the main tree's, then each SubTree instance's by its path),
/// key -> {type, value}, as Groot2's blackboard view shows them.
nlohmann::json BlackboardJson(const bt::Tree& tree) {
  nlohmann::json out = nlohmann::json::object();
  const auto dump = [](const bt::Blackboard& blackboard) {
    nlohmann::json entries = nlohmann::json::object();
    for (const std::string& key : blackboard.LocalKeys()) {
      const std::optional<bt::Any> value = blackboard.GetAny(key);
      if (!value || value->empty()) {
        entries[key] = {{"type", blackboard.DeclaredTypeName(key)}, {"value", nullptr}};
        continue;
      }
      entries[key] = {{"type", bt::TypeName(value->type())}, {"value", value->ToString()}};
    }
    return entries;
  };
  out[""] = dump(*tree.root_blackboard());
  for (const auto& node : tree.nodes()) {
    if (node->kind() == bt::NodeKind::kSubTree && !node->children().empty())
      out[node->path()] = dump(*node->children().front()->config().blackboard);
  }
  return out;
}

int RunTrace(const BtOptions& options) {
  const TraceScript script = ReadTraceScript(options.script_file);
  const std::string format = options.json ? "json" : options.format;
  bt::BehaviorTreeFactory factory;
  RegisterModels(factory, options);
  const std::string tree_id = !options.tree_id.empty() ? options.tree_id : script.tree;
  bt::Tree tree = factory.CreateTreeFromFile(options.tree_file, tree_id, nullptr, {true, true});
  auto clock = std::make_shared<bt::ManualClock>();
  tree.SetClock(clock);
  for (const auto& [key, value] : script.blackboard)
    tree.root_blackboard()->Set(key, ToAny(value));

  // Outcome keys name a node by path, instance name or type ID; each must match something.
  std::set<std::string> names;
  for (const auto& node : tree.nodes()) {
    names.insert(node->path());
    names.insert(node->name());
    names.insert(node->registration_id());
  }
  for (std::size_t i = 0; i < script.ticks.size(); ++i) {
    for (const auto& [key, outcome] : script.ticks[i].outcomes) {
      if (!names.contains(key)) {
        throw std::runtime_error(
            fmt::format("{}: tick {}: no node is named '{}' (by path, name or ID)",
                        options.script_file, i + 1, key));
      }
    }
  }

  // Outcomes are per tick number: every instance of a leaf returns that tick's value, and
  // after the script's last tick its outcomes go on.
  const TickScript* current = nullptr;
  tree.SetStandInDriver([&](const bt::TreeNode& node) {
    if (current != nullptr) {
      for (const std::string* key : {&node.path(), &node.name(), &node.registration_id()}) {
        if (auto it = current->outcomes.find(*key); it != current->outcomes.end())
          return it->second;
      }
    }
    return script.default_outcome;
  });

  const std::set<std::string> stand_ins(tree.stand_in_node_ids().begin(),
                                        tree.stand_in_node_ids().end());
  nlohmann::json json_ticks = nlohmann::json::array();
  nlohmann::json* json_tick = nullptr;
  const int observer = tree.AddStatusObserver([&](bt::Duration, const bt::TreeNode& node,
                                                  bt::NodeStatus previous, bt::NodeStatus status) {
    if (format == "json") {
      (*json_tick)["transitions"].push_back(
          {{"node", node.path()}, {"from", bt::ToString(previous)}, {"to", bt::ToString(status)}});
    } else if (format == "btcpp") {
      // A stand-in action going from RUNNING to IDLE was halted (BT.CPP's onHalted() prints
      // first, then the status change).
      if (previous == bt::NodeStatus::kRunning && status == bt::NodeStatus::kIdle &&
          node.children().empty() && stand_ins.contains(node.registration_id())) {
        fmt::print("halt {} {}\n", node.path(), node.registration_id());
      }
      fmt::print("status {} {} {} -> {}\n", node.path(), node.registration_id(),
                 bt::ToString(previous), bt::ToString(status));
    } else {
      fmt::print("  {:<48} {:>7} -> {}\n", node.path(), bt::ToString(previous),
                 bt::ToString(status));
    }
  });
  std::unique_ptr<bt::FileLogger2> btlog;
  if (!options.btlog.empty())
    btlog = std::make_unique<bt::FileLogger2>(tree, factory, options.btlog);

  if (format == "text") {
    if (!tree.stand_in_node_ids().empty()) {
      fmt::print("stand-ins: {}\n", fmt::join(tree.stand_in_node_ids(), ", "));
    }
    if (!tree.stubbed_subtree_ids().empty()) {
      fmt::print("stub subtrees: {}\n", fmt::join(tree.stubbed_subtree_ids(), ", "));
    }
  }
  // --ticks N runs exactly N ticks (a completed root starts over); else until the root
  // completes or max_ticks.
  const std::uint64_t limit = options.ticks != 0 ? options.ticks : script.max_ticks;
  bt::NodeStatus result = bt::NodeStatus::kRunning;
  std::uint64_t tick = 0;
  while (tick < limit) {
    if (!script.ticks.empty()) {
      current = &script.ticks[std::min<std::size_t>(tick, script.ticks.size() - 1)];
      if (tick < script.ticks.size()) {
        for (const auto& [key, value] : current->blackboard)
          tree.root_blackboard()->Set(key, ToAny(value));
      }
    }
    ++tick;
    const std::int64_t time_ms = script.tick_period_ms * std::int64_t(tick - 1);
    if (format == "json") {
      json_ticks.push_back(
          {{"tick", tick}, {"time_ms", time_ms}, {"transitions", nlohmann::json::array()}});
      json_tick = &json_ticks.back();
    } else if (format == "text") {
      fmt::print("tick {} (t = {} ms)\n", tick, time_ms);
    }
    try {
      result = tree.TickOnce();
    } catch (...) {
      tree.RemoveStatusObserver(observer);  // the halt on destruction is not traced
      std::fflush(stdout);
      throw;
    }
    if (format == "json") {
      (*json_tick)["result"] = bt::ToString(result);
      (*json_tick)["blackboard"] = BlackboardJson(tree);
    } else if (format == "btcpp") {
      fmt::print("tick {} -> {}\n", tick, bt::ToString(result));
    }
    if (result != bt::NodeStatus::kRunning && options.ticks == 0) break;
    clock->Advance(std::chrono::milliseconds(script.tick_period_ms));
  }
  tree.RemoveStatusObserver(observer);  // the tree's halt on destruction is not traced
  if (format == "json") {
    std::cout << nlohmann::json{{"tree", tree.main_tree_id()},
                                {"result", bt::ToString(result)},
                                {"ticks", json_ticks}}
                     .dump(2)
              << "\n";
  } else if (format == "text") {
    fmt::print("result: {} after {} tick{}{}\n", bt::ToString(result), tick, tick == 1 ? "" : "s",
               result == bt::NodeStatus::kRunning ? " (max_ticks reached)" : "");
  }
  std::fflush(stdout);
  return 0;
}

}  // namespace

void AddBtCommand(CLI::App& app) {
  auto options = std::make_shared<BtOptions>();
  auto* bt_app = app.add_subcommand("bt", "Check and trace BehaviorTree.CPP v4 trees");
  bt_app->require_subcommand(1);
  auto* validate = bt_app->add_subcommand(
      "validate",
      "Load a tree, report errors (file:line) and list unknown node types and subtrees");
  auto* trace = bt_app->add_subcommand(
      "trace",
      "Run a tree whose unknown leaves follow a per-tick script; print every status transition");
  for (auto* command : {validate, trace}) {
    command->add_option("TREE", options->tree_file, "BehaviorTree.CPP v4 XML file")
        ->required()
        ->check(CLI::ExistingFile);
    command->add_option("--tree", options->tree_id,
                        "ID of the tree to run (default: main_tree_to_execute or the only tree)");
    command
        ->add_option("--model", options->models, "TreeNodesModel XML whose nodes become stand-ins")
        ->check(CLI::ExistingFile);
  }
  trace
      ->add_option("--script", options->script_file,
                   "YAML script of outcomes per tick (see README)")
      ->required();
  trace->add_option("--btlog", options->btlog, "also write a Groot2 .btlog of the run");
  trace->add_flag("--json", options->json,
                  "print the trace as JSON, with every blackboard after each tick");
  trace
      ->add_option("--format", options->format,
                   "text (default), json, or btcpp: BehaviorTree.CPP's status-change stream "
                   "('status PATH ID PREV -> NEW', 'halt PATH ID', 'tick N -> STATUS')")
      ->check(CLI::IsMember({"text", "json", "btcpp"}));
  trace
      ->add_option("--ticks", options->ticks,
                   "run exactly N ticks, whatever the root returns (default: until it "
                   "completes, at most the script's max_ticks)")
      ->check(CLI::PositiveNumber);
  auto* model = bt_app->add_subcommand(
      "model",
      "Print the TreeNodesModel of egress's task nodes (Groot2's palette), from their "
      "registrations");
  auto model_out = std::make_shared<std::string>();
  auto model_overwrite = std::make_shared<bool>(false);
  model->add_option("--out", *model_out, "write it to this file instead of printing it");
  model->add_flag("--overwrite", *model_overwrite, "replace an existing --out file");
  model->callback([model_out, model_overwrite] {
    const std::string xml = behavior::TaskNodesModelXml();
    if (model_out->empty()) {
      std::cout << xml;
      return;
    }
    if (std::filesystem::exists(*model_out) && !*model_overwrite)
      throw CommandFailed(*model_out + " exists (pass --overwrite to replace it)");
    std::ofstream out(*model_out);
    out << xml;
    if (!out) throw CommandFailed("cannot write '" + *model_out + "'");
  });
  validate->callback([options] {
    if (RunValidate(*options) != 0) throw CommandFailed("");
  });
  trace->callback([options] { RunTrace(*options); });
}

}  // namespace egress::apps
