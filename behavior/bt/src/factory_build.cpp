#include "factory_impl.h"

namespace egress::bt {

TreeNode* BehaviorTreeFactory::Impl::AddNode(BuildState& state, std::unique_ptr<TreeNode> node) {
  TreeNode* raw = node.get();
  state.tree->nodes_.push_back(std::move(node));
  return raw;
}

NodeConfig BehaviorTreeFactory::Impl::BaseConfig(BuildState& state,
                                                 const Blackboard::Ptr& blackboard,
                                                 std::string registration_id) {
  NodeConfig config;
  config.blackboard = blackboard;
  config.registration_id = std::move(registration_id);
  config.uid = static_cast<std::uint16_t>(state.tree->nodes_.size() + 1);
  config.context = state.tree->context_.get();
  if (state.tree->nodes_.size() + 1 > 65535)
    throw LogicError("a tree may have at most 65535 nodes");
  return config;
}

bool BehaviorTreeFactory::Impl::ReadConditionAttribute(NodeConfig& config,
                                                       std::string_view attribute,
                                                       const char* value,
                                                       std::string_view context) {
  const auto parse = [&](std::shared_ptr<const Script>& slot) {
    try {
      slot = Script::Parse(value);
    } catch (const LogicError& e) {
      throw LogicError(Cat(context, ": ", attribute, ": ", e.what()));
    }
  };
  for (int i = 0; i < kNumPreConditions; ++i) {
    if (attribute == PreConditionNames()[i]) {
      parse(config.pre[i]);
      return true;
    }
  }
  for (int i = 0; i < kNumPostConditions; ++i) {
    if (attribute == PostConditionNames()[i]) {
      parse(config.post[i]);
      return true;
    }
  }
  return false;
}

std::string BehaviorTreeFactory::Impl::DescribeNode(const std::string& where, std::string_view id,
                                                    std::string_view name) {
  return name == id ? Cat(where, "node '", id, "'") : Cat(where, "node '", name, "' (", id, ")");
}

TreeNode* BehaviorTreeFactory::Impl::Build(const XMLElement* e, const Blackboard::Ptr& blackboard,
                                           const std::string& prefix,
                                           const TreeDefinition& definition, BuildState& state) {
  const std::string where = Where(definition.file, e);
  const std::string_view tag = e->Name();
  if (tag == "SubTree") return BuildSubTree(e, blackboard, prefix, definition, state);

  std::string id;
  std::optional<NodeKind> explicit_kind = ExplicitKind(tag);
  if (explicit_kind) {
    const char* attr = e->Attribute("ID");
    if (attr == nullptr)
      throw LogicError(Cat(where, "<", tag, "> needs an ID attribute naming the node type"));
    id = attr;
  } else {
    if (e->Attribute("ID") != nullptr) {
      throw LogicError(Cat(where, "<", tag, " ID=\"", e->Attribute("ID"), "\">: the compact form <",
                           tag, "> must not have an ID attribute"));
    }
    id = std::string(tag);
  }
  const char* name_attr = e->Attribute("name");
  const std::string name = name_attr != nullptr ? name_attr : id;
  const int children = ChildElementCount(e);

  // Resolve the node type.
  auto registration = registrations.find(id);
  std::shared_ptr<const NodeManifest> manifest;
  NodeBuilder builder;
  if (registration != registrations.end()) {
    manifest = registration->second.manifest;
    builder = registration->second.builder;
  } else if (state.options->stand_in_unknown_nodes) {
    auto stand_in = std::make_shared<NodeManifest>();
    stand_in->id = id;
    stand_in->kind =
        explicit_kind
            ? *explicit_kind
            : (children == 0 ? NodeKind::kAction
                             : (children == 1 ? NodeKind::kDecorator : NodeKind::kControl));
    stand_in->stand_in = true;
    manifest = stand_in;
    const NodeKind kind = stand_in->kind;
    builder = [kind](const std::string& n, NodeConfig c) {
      return internal::MakeStandIn(kind, n, std::move(c));
    };
    auto& ids = state.tree->stand_in_ids_;
    if (std::find(ids.begin(), ids.end(), id) == ids.end()) ids.push_back(id);
    // For the tree's model (Groot2, .btlog): the kind, and every port any instance sets
    // (taken as input ports: a stand-in has no declaration to say otherwise).
    auto& models = state.tree->stand_in_manifests_;
    auto model =
        std::find_if(models.begin(), models.end(), [&](const auto& m) { return m->id == id; });
    if (model == models.end()) model = models.insert(models.end(), stand_in);
    auto widened = std::make_shared<NodeManifest>(**model);
    for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a != nullptr; a = a->Next()) {
      const std::string_view attribute = a->Name();
      if (attribute == "ID" || attribute == "name" || attribute.starts_with("_")) continue;
      if (!widened->ports.contains(attribute)) {
        PortInfo port;
        port.type_name = "Any";
        widened->ports.emplace(std::string(attribute), std::move(port));
      }
    }
    *model = std::move(widened);
  } else {
    std::string hint;
    for (const auto& [known, r] : registrations) {
      if (known.size() == id.size() &&
          std::equal(known.begin(), known.end(), id.begin(),
                     [](char a, char b) { return std::tolower(a) == std::tolower(b); })) {
        hint = Cat(" (did you mean '", known, "'? node IDs are case-sensitive)");
      }
    }
    throw LogicError(
        Cat(where, "unknown node type '", id, "' in BehaviorTree '", definition.id, "'", hint,
            "; register it with the factory, or load with stand-ins for unknown nodes"));
  }
  const NodeManifest& m = *manifest;
  if (!m.stand_in) state.manifests_used.insert(manifest.get());
  state.tree->keep_alive_.push_back(manifest);
  const std::string what = DescribeNode(where, id, name);

  // Child count.
  const auto count_error = [&](const std::string& expected) {
    throw LogicError(
        Cat(what, " has ", children, " children; a ", ToString(m.kind), " ", expected));
  };
  if ((m.kind == NodeKind::kAction || m.kind == NodeKind::kCondition) && children != 0) {
    count_error("has none");
  }
  if (m.kind == NodeKind::kDecorator && children != 1) count_error("has exactly one");
  if (m.kind == NodeKind::kControl && children < 1) count_error("has at least one");
  if ((id == "IfThenElse" || id == "WhileDoElse") && (children < 2 || children > 3)) {
    throw LogicError(
        Cat(what, " has ", children, " children; it takes 2 or 3 (condition, then, else)"));
  }
  if (id.starts_with("Switch") && m.builtin) {
    const int cases = std::stoi(id.substr(6));
    if (children != cases + 1) {
      throw LogicError(Cat(what, " has ", children, " children; ", id, " takes ", cases + 1,
                           " (one per case, then the default)"));
    }
  }

  NodeConfig config = BaseConfig(state, blackboard, id);
  config.file = state.File(definition.file);
  config.line = e->GetLineNum();
  config.manifest_ports = m.stand_in ? nullptr : &m.ports;
  if (m.stand_in && !m.ports.empty()) config.manifest_ports = &m.ports;
  config.path = prefix + name;
  if (name == id) config.path += Cat("::", config.uid);

  for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a != nullptr; a = a->Next()) {
    const std::string_view attribute = a->Name();
    if (attribute == "ID" || attribute == "name") continue;
    if (ReadConditionAttribute(config, attribute, a->Value(), what)) continue;
    if (attribute.starts_with("_")) continue;  // UI metadata (_description, _uid, …)
    if (!m.stand_in || !m.ports.empty()) {
      if (!m.ports.contains(attribute)) {
        std::vector<std::string> declared;
        for (const auto& [port, info] : m.ports)
          declared.push_back(port);
        if (m.stand_in) {
          // A model-based stand-in: the model may be older than the tree; accept with a warning.
          Warn(Cat(what, ": port '", attribute, "' is not in the TreeNodesModel of '", id, "'"));
        } else {
          throw LogicError(
              Cat(what, ": port '", attribute, "' is not declared by '", id,
                  "' (its ports: ", declared.empty() ? std::string("none") : Join(declared), ")"));
        }
      }
    }
    config.ports[std::string(attribute)] = a->Value();
  }
  CheckPorts(m, config, blackboard, what);

  std::unique_ptr<TreeNode> node;
  try {
    node = builder(name, std::move(config));
  } catch (const std::exception& e2) {
    throw LogicError(Cat(what, ": ", e2.what()));
  }
  TreeNode* raw = AddNode(state, std::move(node));
  for (const XMLElement* c = e->FirstChildElement(); c != nullptr; c = c->NextSiblingElement()) {
    TreeNode* child = Build(c, blackboard, prefix, definition, state);
    if (auto* control = dynamic_cast<ControlNode*>(raw)) {
      control->AddChild(child);
    } else if (auto* decorator = dynamic_cast<DecoratorNode*>(raw)) {
      decorator->SetChild(child);
    } else {
      throw LogicError(Cat(what, ": its builder made a leaf, but the element has children"));
    }
  }
  return raw;
}

void BehaviorTreeFactory::Impl::CheckPorts(const NodeManifest& m, const NodeConfig& config,
                                           const Blackboard::Ptr& blackboard,
                                           const std::string& what) {
  for (const auto& [port, info] : m.ports) {
    auto set = config.ports.find(port);
    if (set == config.ports.end()) {
      if (info.required && !m.stand_in) {
        throw LogicError(Cat(what, ": missing required port '", port, "'",
                             info.description.empty() ? "" : Cat(" (", info.description, ")")));
      }
      if (info.default_value) {
        if (auto key = BlackboardKeyOf(*info.default_value, port))
          DeclareType(blackboard, *key, info, what, port);
      }
      continue;
    }
    const std::string& text = set->second;
    if (auto key = BlackboardKeyOf(text, port)) {
      DeclareType(blackboard, *key, info, what, port);
      continue;
    }
    if (info.direction == PortDirection::kOutput) {
      throw LogicError(Cat(what, ": output port '", port,
                           "' must be a blackboard reference like {key}, not '", text, "'"));
    }
    if (info.script) {
      try {
        Script::Parse(text);
      } catch (const LogicError& e) {
        throw LogicError(Cat(what, ": port '", port, "': ", e.what()));
      }
    } else if (info.IsStronglyTyped() && info.parse && !IsEnumName(text)) {
      try {
        info.parse(text, types.get());
      } catch (const std::exception& e) {
        throw LogicError(Cat(what, ": port '", port, "' value '", text, "' cannot be converted to ",
                             info.type_name, ": ", e.what()));
      }
    }
  }
}

void BehaviorTreeFactory::Impl::DeclareType(const Blackboard::Ptr& blackboard,
                                            const std::string& key, const PortInfo& info,
                                            const std::string& what, const std::string& port) {
  try {
    blackboard->DeclareType(key, info);
  } catch (const LogicError& e) {
    throw LogicError(Cat(what, ": port '", port, "': ", e.what()));
  }
}

TreeNode* BehaviorTreeFactory::Impl::BuildSubTree(const XMLElement* e,
                                                  const Blackboard::Ptr& parent,
                                                  const std::string& prefix,
                                                  const TreeDefinition& definition,
                                                  BuildState& state) {
  const std::string where = Where(definition.file, e);
  const char* id_attr = e->Attribute("ID");
  if (id_attr == nullptr)
    throw LogicError(Cat(where, "<SubTree> needs an ID attribute naming the BehaviorTree"));
  const std::string id = id_attr;
  const char* name_attr = e->Attribute("name");
  const std::string name = name_attr != nullptr ? name_attr : id;
  if (ChildElementCount(e) != 0)
    throw LogicError(Cat(where, "<SubTree ID=\"", id, "\"> must not have children"));

  auto found = trees.find(id);
  if (found == trees.end()) {
    if (!state.options->stub_missing_subtrees) {
      throw LogicError(Cat(where, "SubTree '", id, "' is not defined (known trees: ",
                           Join(tree_order), "); include its file, or load with stub subtrees"));
    }
    auto& stubs = state.tree->stubbed_subtrees_;
    if (std::find(stubs.begin(), stubs.end(), id) == stubs.end()) stubs.push_back(id);
    NodeConfig config = BaseConfig(state, parent, id);
    config.path = prefix + name + (name_attr == nullptr ? Cat("::", config.uid) : "");
    return AddNode(state, internal::MakeStandIn(NodeKind::kAction, name, std::move(config)));
  }
  if (std::find(state.subtree_stack.begin(), state.subtree_stack.end(), id) !=
      state.subtree_stack.end()) {
    std::string cycle;
    for (const auto& s : state.subtree_stack)
      cycle += s + " -> ";
    throw LogicError(Cat(where, "recursive SubTree: ", cycle, id));
  }
  if (int(state.subtree_stack.size()) >= kMaxSubTreeDepth) {
    throw LogicError(Cat(where, "SubTrees nest deeper than ", kMaxSubTreeDepth));
  }

  // As in BT.CPP: the node's registration ID is "SubTree"; its path gets "::uid" when its name
  // is the subtree's ID, and the subtree's nodes live under its name, or "ID::uid" unnamed.
  NodeConfig config = BaseConfig(state, parent, "SubTree");
  config.subtree_id = id;
  config.file = state.File(definition.file);
  config.line = e->GetLineNum();
  config.path = prefix + name;
  if (name == id) config.path += Cat("::", config.uid);
  const std::string subtree_prefix =
      prefix + (name_attr != nullptr ? name : Cat(id, "::", config.uid)) + "/";
  if (!state.paths.insert(config.path).second) {
    throw LogicError(Cat(where, "Duplicate SubTree path '", config.path,
                         "': give sibling SubTrees distinct name attributes"));
  }
  auto child_blackboard = Blackboard::Create(parent);
  child_blackboard->SetTypeRegistry(types.get());
  state.tree->blackboards_.push_back(child_blackboard);

  const std::string subtree_what = Cat(where, "SubTree '", id, "'");
  bool auto_remap = false;
  std::set<std::string> given;
  for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a != nullptr; a = a->Next()) {
    const std::string attribute = a->Name();
    if (attribute == "ID" || attribute == "name") continue;
    if (ReadConditionAttribute(config, attribute, a->Value(), subtree_what))
      continue;  // parent scope
    if (attribute == "_autoremap") {
      auto_remap = ParseBoolAttribute(a->Value());
      continue;
    }
    if (attribute.starts_with("_")) continue;
    given.insert(attribute);
    config.ports[attribute] = a->Value();
    ApplySubTreePort(child_blackboard, attribute, a->Value());
  }
  child_blackboard->SetAutoRemap(auto_remap);
  if (auto model = subtree_models.find(id); model != subtree_models.end()) {
    for (const auto& [port, info] : model->second) {
      if (given.contains(port)) continue;
      if (info.default_value) {
        ApplySubTreePort(child_blackboard, port, *info.default_value);
      } else if (!auto_remap) {
        throw LogicError(
            Cat(where, "SubTree '", id, "' port '", port,
                "' is declared in its TreeNodesModel without a default and is not remapped here"));
      }
    }
  }

  auto node = std::make_unique<internal::SubTreeNode>(name, std::move(config), id);
  TreeNode* raw = AddNode(state, std::move(node));
  state.subtree_stack.push_back(id);
  const XMLElement* body = found->second.element->FirstChildElement();
  TreeNode* root = Build(body, child_blackboard, subtree_prefix, found->second, state);
  state.subtree_stack.pop_back();
  static_cast<internal::SubTreeNode*>(raw)->SetChild(root);
  return raw;
}

void BehaviorTreeFactory::Impl::ApplySubTreePort(const Blackboard::Ptr& child,
                                                 const std::string& port,
                                                 const std::string& value) {
  if (auto key = BlackboardKeyOf(value, port)) {
    child->AddRemap(port, *key);
    return;
  }
  try {
    child->Set(port, ParseInteger(value));
    return;
  } catch (const RuntimeError&) {
  }
  try {
    child->Set(port, ParseReal(value));
    return;
  } catch (const RuntimeError&) {
  }
  child->Set(port, value);
}

std::string BehaviorTreeFactory::Impl::ChooseMainTree(std::string_view requested) const {
  if (!requested.empty()) {
    if (!trees.contains(requested)) {
      throw LogicError(Cat("no BehaviorTree '", requested,
                           "' is registered (known trees: ", Join(tree_order), ")"));
    }
    return std::string(requested);
  }
  if (main_tree_to_execute) {
    if (!trees.contains(*main_tree_to_execute)) {
      throw LogicError(Cat("main_tree_to_execute names '", *main_tree_to_execute,
                           "', which is not defined (known trees: ", Join(tree_order), ")"));
    }
    return *main_tree_to_execute;
  }
  if (trees.size() == 1) return trees.begin()->first;
  if (trees.empty()) {
    throw LogicError(files_read.empty()
                         ? std::string("no BehaviorTree is registered (no tree file was read)")
                         : Cat(Join(files_read), ": no <BehaviorTree> in ",
                               files_read.size() == 1 ? "this file" : "these files",
                               " (a TreeNodesModel alone declares node types; it is not a tree)"));
  }
  std::vector<std::string> where;
  for (const std::string& id : tree_order) {
    const TreeDefinition& tree = trees.at(id);
    where.push_back(Cat(id, " at ", tree.file, ":", tree.element->GetLineNum()));
  }
  throw LogicError(Cat("[main_tree_to_execute] was not specified and there are several trees (",
                       Join(where), "); name the tree to run (--tree ID)"));
}

}  // namespace egress::bt
