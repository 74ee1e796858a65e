// Peer driver (NOT part of egress): runs a tree in BehaviorTree.CPP 4.10 with stand-in leaves
// driven by an egress trace script, printing the btcpp status stream.
#include <behaviortree_cpp/bt_factory.h>
#include <behaviortree_cpp/loggers/abstract_logger.h>
#include <tinyxml2.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>
#include <iostream>
#include <map>
#include <set>

using namespace BT;
struct Script {
  NodeStatus def = NodeStatus::SUCCESS;
  std::vector<std::map<std::string, NodeStatus>> ticks;
  std::vector<std::vector<std::pair<std::string, std::string>>> bb;
  std::vector<std::pair<std::string, std::string>> bb0;
};
static Script g_script;
static std::set<std::string> g_conditions;
static std::size_t g_tick = 0;
static NodeStatus Outcome(const TreeNode& n) {
  if (g_script.ticks.empty()) return g_script.def;
  const auto& m = g_script.ticks[std::min(g_tick, g_script.ticks.size()) - 1];
  for (const std::string& k : {n.fullPath(), n.name(), n.registrationName()}) {
    auto it = m.find(k);
    if (it != m.end()) return it->second;
  }
  return g_script.def;
}
class StandInAction : public StatefulActionNode {
 public:
  StandInAction(const std::string& n, const NodeConfig& c) : StatefulActionNode(n, c) {}
  NodeStatus onStart() override { return Outcome(*this); }
  NodeStatus onRunning() override { return Outcome(*this); }
  void onHalted() override {
    std::cout << "halt " << fullPath() << " " << registrationName() << "\n";
  }
};
class StandInCondition : public ConditionNode {
 public:
  StandInCondition(const std::string& n, const NodeConfig& c) : ConditionNode(n, c) {}
  NodeStatus tick() override { return Outcome(*this); }
};
class Printer : public StatusChangeLogger {
 public:
  Printer(const Tree& t) : StatusChangeLogger(t.rootNode()) {}
  void callback(Duration, const TreeNode& n, NodeStatus prev, NodeStatus st) override {
    std::cout << "status " << n.fullPath() << " " << n.registrationName() << " " << toStr(prev)
              << " -> " << toStr(st) << "\n";
  }
  void flush() override {}
};
static void SetBB(Blackboard& bb, const std::string& k, const std::string& v) {
  try {
    size_t pos;
    long long i = std::stoll(v, &pos);
    if (pos == v.size()) {
      bb.set(k, int(i));
      return;
    }
  } catch (...) {
  }
  try {
    size_t pos;
    double d = std::stod(v, &pos);
    if (pos == v.size()) {
      bb.set(k, d);
      return;
    }
  } catch (...) {
  }
  if (v == "true" || v == "false") {
    bb.set(k, v == "true");
    return;
  }
  bb.set(k, v);
}
static NodeStatus Parse(const std::string& s) {
  if (s == "SUCCESS") return NodeStatus::SUCCESS;
  if (s == "FAILURE") return NodeStatus::FAILURE;
  if (s == "RUNNING") return NodeStatus::RUNNING;
  if (s == "SKIPPED") return NodeStatus::SKIPPED;
  throw std::runtime_error("bad outcome " + s);
}
int main(int argc, char** argv) {
  if (argc < 4) {
    std::cerr << "peer TREE SCRIPT TICKS\n";
    return 2;
  }
  YAML::Node y = YAML::LoadFile(argv[2]);
  if (y["default"]) g_script.def = Parse(y["default"].as<std::string>());
  if (y["blackboard"])
    for (auto e : y["blackboard"])
      g_script.bb0.emplace_back(e.first.as<std::string>(), e.second.as<std::string>());
  if (y["ticks"])
    for (auto t : y["ticks"]) {
      std::map<std::string, NodeStatus> m;
      std::vector<std::pair<std::string, std::string>> b;
      if (t["outcomes"])
        for (auto e : t["outcomes"])
          m[e.first.as<std::string>()] = Parse(e.second.as<std::string>());
      if (t["blackboard"])
        for (auto e : t["blackboard"])
          b.emplace_back(e.first.as<std::string>(), e.second.as<std::string>());
      g_script.ticks.push_back(m);
      g_script.bb.push_back(b);
    }
  BehaviorTreeFactory factory;
  // Stand-ins: unknown leaf elements (bare or <Action ID>/<Condition ID>), ports from attributes.
  tinyxml2::XMLDocument doc;
  doc.LoadFile(argv[1]);
  std::map<std::string, std::pair<bool, std::set<std::string>>> unknown;
  std::function<void(tinyxml2::XMLElement*)> walk = [&](tinyxml2::XMLElement* e) {
    for (auto* c = e; c; c = c->NextSiblingElement()) {
      std::string n = c->Name();
      bool cond = n == "Condition" || g_conditions.count(n);
      std::string id = (n == "Action" || n == "Condition") ? c->Attribute("ID") : n;
      if (!c->FirstChildElement() && n != "SubTree" && !factory.builders().count(id)) {
        auto& u = unknown[id];
        u.first = cond;
        for (auto* a = c->FirstAttribute(); a; a = a->Next()) {
          std::string an = a->Name();
          if (an != "ID" && an != "name" && an[0] != '_') u.second.insert(an);
        }
      }
      if (c->FirstChildElement()) walk(c->FirstChildElement());
    }
  };
  if (auto* m = doc.RootElement()->FirstChildElement("TreeNodesModel"))
    for (auto* c = m->FirstChildElement("Condition"); c; c = c->NextSiblingElement("Condition"))
      g_conditions.insert(c->Attribute("ID"));
  for (auto* bt = doc.RootElement()->FirstChildElement("BehaviorTree"); bt;
       bt = bt->NextSiblingElement("BehaviorTree"))
    walk(bt->FirstChildElement());
  for (auto& [id, u] : unknown) {
    PortsList ports;
    for (auto& p : u.second)
      ports.insert(InputPort<std::string>(p));
    if (u.first) {
      factory.registerBuilder(TreeNodeManifest{NodeType::CONDITION, id, ports, {}},
                              [](const std::string& n, const NodeConfig& c) {
                                return std::make_unique<StandInCondition>(n, c);
                              });
    } else {
      factory.registerBuilder(TreeNodeManifest{NodeType::ACTION, id, ports, {}},
                              [](const std::string& n, const NodeConfig& c) {
                                return std::make_unique<StandInAction>(n, c);
                              });
    }
  }
  auto tree = factory.createTreeFromFile(argv[1]);
  for (auto& [k, v] : g_script.bb0)
    SetBB(*tree.rootBlackboard(), k, v);
  Printer printer(tree);
  const int ticks = std::atoi(argv[3]);
  for (int i = 1; i <= ticks; ++i) {
    g_tick = i;
    if (!g_script.bb.empty())
      for (auto& [k, v] : g_script.bb[std::min<size_t>(i, g_script.bb.size()) - 1])
        if (size_t(i) <= g_script.bb.size()) SetBB(*tree.rootBlackboard(), k, v);
    NodeStatus st;
    try {
      st = tree.tickOnce();
    } catch (const std::exception& e) {
      std::cout << "error " << e.what() << "\n";
      return 0;
    }
    std::cout << "tick " << i << " -> " << toStr(st) << "\n";
  }
  std::cout.flush();
  _exit(0);
}
