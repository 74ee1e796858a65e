#pragma once
// Internal to behavior/bt/src: BehaviorTreeFactory's state (BehaviorTreeFactory::Impl) and the
// helpers its parts share. Reading XML documents (factory_read.cpp), building trees from them
// (factory_build.cpp), and the public API (factory.cpp).

#include "egress/bt/factory.h"

#include <tinyxml2.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "builtin_nodes.h"

namespace egress::bt {
namespace factory_detail {

using tinyxml2::XMLDocument;
using tinyxml2::XMLElement;

constexpr int kMaxSubTreeDepth = 256;
// The largest tree file read [bytes] (a FIFO, a device or a huge file is an error, not an
// unbounded read). egress::bt stands alone, so this is its own reader.
constexpr std::size_t kMaxTreeFileBytes = std::size_t{16} << 20;

// The whole of `path`, a regular file of at most kMaxTreeFileBytes. `what` names it in errors
// ("behavior tree file", "included file"), `where` prefixes them (the including element).
// @throws LogicError.
std::string ReadTreeFile(const std::filesystem::path& path, std::string_view what,
                         const std::string& where = "");
constexpr std::string_view kExplicitTags[] = {"Action", "Condition", "Control", "Decorator"};

inline std::optional<NodeKind> ExplicitKind(std::string_view tag) {
  if (tag == "Action") return NodeKind::kAction;
  if (tag == "Condition") return NodeKind::kCondition;
  if (tag == "Control") return NodeKind::kControl;
  if (tag == "Decorator") return NodeKind::kDecorator;
  if (tag == "SubTree") return NodeKind::kSubTree;
  return std::nullopt;
}

// Characters BT.CPP >= 4.8.4 forbids in IDs and port names.
inline bool HasForbiddenCharacter(std::string_view name, bool allow_space) {
  for (char c : name) {
    if (c == ' ' && allow_space) continue;
    if (static_cast<unsigned char>(c) < 0x20 ||
        std::string_view(" <>&\"'/\\:*?|.").find(c) != std::string_view::npos) {
      return true;
    }
  }
  return false;
}

inline bool ParseBoolAttribute(const char* value) {
  const std::string_view v = value == nullptr ? "" : value;
  return v == "true" || v == "1" || v == "True" || v == "TRUE";
}

inline int ChildElementCount(const XMLElement* element) {
  int n = 0;
  for (auto* c = element->FirstChildElement(); c != nullptr; c = c->NextSiblingElement())
    ++n;
  return n;
}

inline std::string Join(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& item : items)
    out += (out.empty() ? "" : ", ") + item;
  return out;
}

}  // namespace factory_detail
using namespace factory_detail;

struct BehaviorTreeFactory::Impl {
  struct Registration {
    std::shared_ptr<const NodeManifest> manifest;
    NodeBuilder builder;
  };
  struct TreeDefinition {
    std::string id;
    const XMLElement* element{nullptr};  // the <BehaviorTree>
    std::string file;
  };

  std::map<std::string, Registration, std::less<>> registrations;
  std::shared_ptr<TypeRegistry> types = std::make_shared<TypeRegistry>();
  std::shared_ptr<ScriptEnums> enums = std::make_shared<ScriptEnums>();
  std::vector<std::shared_ptr<XMLDocument>> documents;
  std::map<std::string, TreeDefinition, std::less<>> trees;
  std::vector<std::string> tree_order;
  std::vector<std::string> files_read;  ///< Every document read since the last clear (errors).
  std::map<std::string, PortsList, std::less<>> subtree_models;
  std::optional<std::string> main_tree_to_execute;
  bool first_document{true};
  std::vector<std::string> warnings;

  void Warn(std::string message) { warnings.push_back(std::move(message)); }

  static std::string Where(const std::string& file, const XMLElement* e);

  // ---- reading documents

  void ReadDocument(const std::string& xml, const std::string& file,
                    const std::filesystem::path& base_dir,
                    std::vector<std::filesystem::path>& include_stack);

  void ReadInclude(const XMLElement* e, const std::string& file,
                   const std::filesystem::path& base_dir,
                   std::vector<std::filesystem::path>& include_stack);

  void ReadTreeDefinition(const XMLElement* e, const std::string& file, int tree_count,
                          int& unnamed);

  static PortsList ReadModelPorts(const XMLElement* model, const std::string& file);

  void ReadSubTreeModels(const XMLElement* model, const std::string& file);

  // ---- instantiation

  struct BuildState {
    Tree* tree;
    const LoadOptions* options;
    std::vector<std::string> subtree_stack;
    std::set<std::string> paths;
    std::set<const NodeManifest*> manifests_used;
    // The name of each tree file, shared by its nodes' NodeConfig::file.
    std::map<std::string, std::shared_ptr<const std::string>, std::less<>> files;
    std::shared_ptr<const std::string> File(const std::string& name) {
      auto& file = files[name];
      if (!file) file = std::make_shared<const std::string>(name);
      return file;
    }
  };

  TreeNode* AddNode(BuildState& state, std::unique_ptr<TreeNode> node);

  NodeConfig BaseConfig(BuildState& state, const Blackboard::Ptr& blackboard,
                        std::string registration_id);

  // Reads _failureIf … _onHalted into the config; returns true if the attribute was one. An
  // error reads "<context>: <attribute>: ..." (context: file, line and node).
  static bool ReadConditionAttribute(NodeConfig& config, std::string_view attribute,
                                     const char* value, std::string_view context);

  std::string DescribeNode(const std::string& where, std::string_view id, std::string_view name);

  TreeNode* Build(const XMLElement* e, const Blackboard::Ptr& blackboard, const std::string& prefix,
                  const TreeDefinition& definition, BuildState& state);

  void CheckPorts(const NodeManifest& m, const NodeConfig& config,
                  const Blackboard::Ptr& blackboard, const std::string& what);

  bool IsEnumName(const std::string& text) const { return enums->contains(text); }

  static void DeclareType(const Blackboard::Ptr& blackboard, const std::string& key,
                          const PortInfo& info, const std::string& what, const std::string& port);

  TreeNode* BuildSubTree(const XMLElement* e, const Blackboard::Ptr& parent,
                         const std::string& prefix, const TreeDefinition& definition,
                         BuildState& state);

  // `{key}` remaps into the parent; a literal is written into the subtree's blackboard (as an
  // integer or double when it parses fully as one, else as a string; BT.CPP 4.9.1+).
  static void ApplySubTreePort(const Blackboard::Ptr& child, const std::string& port,
                               const std::string& value);

  std::string ChooseMainTree(std::string_view requested) const;
};

}  // namespace egress::bt
