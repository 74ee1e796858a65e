#pragma once
/// @file
/// BehaviorTreeFactory: registers node types (built-in and the application's), reads
/// BehaviorTree.CPP v4 XML and instantiates trees.
///
/// Format accepted (see README "Behavior trees"): `<root BTCPP_format="4">` (a missing attribute
/// is a warning), several `<BehaviorTree ID>`, `<include path>` relative to the including file,
/// one `<TreeNodesModel>` per file (its SubTree port models give subtree interfaces and
/// defaults), compact (`<Sequence>`) and explicit (`<Control ID="Sequence">`) node syntax,
/// `SubTree` with remapping and `_autoremap`, pre/post-condition scripts, and UI attributes
/// starting with `_` (ignored). Tree IDs with spaces are accepted with a warning.
///
/// Every load error is a LogicError whose message starts with "file:line:" and names the
/// element and what is wrong.

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "egress/bt/tree.h"
#include "egress/bt/tree_node.h"

namespace egress::bt {

/// Creates a node instance from its name and configuration.
using NodeBuilder =
    std::function<std::unique_ptr<TreeNode>(const std::string& name, NodeConfig config)>;

/// What the factory knows about a node type.
struct NodeManifest {
  std::string id;
  NodeKind kind{NodeKind::kAction};
  PortsList ports;
  std::string description;
  bool builtin{false};
  /// A stand-in: registered from a TreeNodesModel or by RegisterStandIn; ticks through the
  /// tree's stand-in driver.
  bool stand_in{false};
};

/// How tolerant loading is.
struct LoadOptions {
  /// Unknown node IDs become stand-ins (kind from the explicit syntax, else from the number of
  /// children) that accept any port, instead of a load error.
  bool stand_in_unknown_nodes{false};
  /// A SubTree whose BehaviorTree is not defined becomes a stand-in action.
  bool stub_missing_subtrees{false};
};

class BehaviorTreeFactory {
 public:
  /// A factory with every built-in node type registered.
  BehaviorTreeFactory();
  ~BehaviorTreeFactory();
  BehaviorTreeFactory(const BehaviorTreeFactory&) = delete;
  BehaviorTreeFactory& operator=(const BehaviorTreeFactory&) = delete;

  // ---- node types

  /// Registers a node type. @throws LogicError if the ID is registered already or invalid.
  void RegisterBuilder(NodeManifest manifest, NodeBuilder builder);
  /// Registers T, constructible as T(name, config), with ports from `T::ProvidedPorts()` if it
  /// declares them. The kind follows T's base class.
  template <typename T>
  void RegisterNodeType(const std::string& id, std::string description = {});
  /// A synchronous action or a condition from a function.
  void RegisterSimpleAction(const std::string& id, SimpleLeafNode::Function function,
                            PortsList ports = {});
  void RegisterSimpleCondition(const std::string& id, SimpleLeafNode::Function function,
                               PortsList ports = {});
  /// A stand-in node type (see NodeManifest::stand_in).
  void RegisterStandIn(const std::string& id, NodeKind kind, PortsList ports = {});
  /// Registers a stand-in for every Action/Condition/Control/Decorator model in the file's
  /// TreeNodesModel that is not registered yet. Returns the IDs registered.
  std::vector<std::string> RegisterStandInsFromModelFile(const std::filesystem::path& path);
  std::vector<std::string> RegisterStandInsFromModelText(const std::string& xml,
                                                         const std::string& source_name);
  /// A converter from string for a user type used by ports.
  template <typename T>
  void RegisterConverter(std::function<T(std::string_view)> converter);
  /// An enum constant usable in scripts and as the value of integer ports.
  void RegisterScriptingEnum(const std::string& name, std::int64_t value);

  const NodeManifest* FindManifest(std::string_view id) const;
  /// All registered node types, sorted by ID.
  std::vector<const NodeManifest*> Manifests() const;

  // ---- trees

  /// Reads the BehaviorTree definitions (and includes) of a file for later CreateTree calls.
  void RegisterTreesFromFile(const std::filesystem::path& path);
  /// Same for XML text; `source_name` appears in error messages, includes resolve against the
  /// working directory.
  void RegisterTreesFromText(const std::string& xml, const std::string& source_name = "<text>");
  /// IDs of the registered BehaviorTrees, in the order they were read.
  std::vector<std::string> RegisteredTreeIds() const;
  /// Forgets all registered BehaviorTrees (node types stay).
  void ClearRegisteredTrees();

  /// Instantiates a tree: `tree_id`, else the first document's main_tree_to_execute, else the
  /// only registered tree. `blackboard` becomes the root blackboard (a new one if null).
  Tree CreateTree(std::string_view tree_id = {}, Blackboard::Ptr blackboard = nullptr,
                  const LoadOptions& options = {});
  Tree CreateTreeFromFile(const std::filesystem::path& path, std::string_view tree_id = {},
                          Blackboard::Ptr blackboard = nullptr, const LoadOptions& options = {});
  Tree CreateTreeFromText(const std::string& xml, std::string_view tree_id = {},
                          Blackboard::Ptr blackboard = nullptr, const LoadOptions& options = {});

  /// `<root BTCPP_format="4"><TreeNodesModel>…` of the registered node types, for Groot2's
  /// palette. Built-in types are included on request.
  std::string WriteTreeNodesModelXml(bool include_builtins = false) const;

  /// Warnings met while loading (missing BTCPP_format, spaces in IDs, …).
  const std::vector<std::string>& warnings() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  void RegisterConverterImpl(std::type_index type, std::string name,
                             TypeRegistry::Converter converter);
};

/// The tree as BehaviorTree.CPP's WriteTreeToXML writes it: every SubTree instance expanded into
/// its own `<BehaviorTree ID=… _fullpath=…>`, every node with `_uid` (and `_fullpath`), plus a
/// TreeNodesModel of the node types used. This is what Groot2 and .btlog files expect.
std::string WriteTreeToXml(const Tree& tree, const BehaviorTreeFactory& factory);

// ---- template implementations

namespace internal {
template <typename T, typename = void>
struct HasProvidedPorts : std::false_type {};
template <typename T>
struct HasProvidedPorts<T, std::void_t<decltype(T::ProvidedPorts())>> : std::true_type {};
}  // namespace internal

template <typename T>
void BehaviorTreeFactory::RegisterNodeType(const std::string& id, std::string description) {
  static_assert(std::is_base_of_v<TreeNode, T>, "T must derive from egress::bt::TreeNode");
  static_assert(!std::is_abstract_v<T>,
                "T is abstract: implement Tick() (or OnStart/OnRunning/OnHalted)");
  static_assert(std::is_constructible_v<T, const std::string&, NodeConfig>,
                "T needs a constructor T(const std::string& name, egress::bt::NodeConfig config)");
  NodeManifest manifest;
  manifest.id = id;
  manifest.description = std::move(description);
  if constexpr (std::is_base_of_v<ConditionNode, T>) {
    manifest.kind = NodeKind::kCondition;
  } else if constexpr (std::is_base_of_v<ControlNode, T>) {
    manifest.kind = NodeKind::kControl;
  } else if constexpr (std::is_base_of_v<DecoratorNode, T>) {
    manifest.kind = NodeKind::kDecorator;
  } else {
    manifest.kind = NodeKind::kAction;
  }
  if constexpr (internal::HasProvidedPorts<T>::value) manifest.ports = T::ProvidedPorts();
  RegisterBuilder(std::move(manifest), [](const std::string& name, NodeConfig config) {
    return std::make_unique<T>(name, std::move(config));
  });
}

template <typename T>
void BehaviorTreeFactory::RegisterConverter(std::function<T(std::string_view)> converter) {
  RegisterConverterImpl(typeid(T), TypeName(typeid(T)),
                        [converter = std::move(converter)](std::string_view text) -> std::any {
                          return converter(text);
                        });
}

}  // namespace egress::bt
