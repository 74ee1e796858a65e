#include "egress/bt/factory.h"

#include <tinyxml2.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "builtin_nodes.h"

namespace egress::bt {
namespace {

using tinyxml2::XMLDocument;
using tinyxml2::XMLElement;

constexpr int kMaxSubTreeDepth = 256;
constexpr std::string_view kExplicitTags[] = {"Action", "Condition", "Control", "Decorator"};

std::optional<NodeKind> ExplicitKind(std::string_view tag) {
  if (tag == "Action") return NodeKind::kAction;
  if (tag == "Condition") return NodeKind::kCondition;
  if (tag == "Control") return NodeKind::kControl;
  if (tag == "Decorator") return NodeKind::kDecorator;
  if (tag == "SubTree") return NodeKind::kSubTree;
  return std::nullopt;
}

// Characters BT.CPP >= 4.8.4 forbids in IDs and port names.
bool HasForbiddenCharacter(std::string_view name, bool allow_space) {
  for (char c : name) {
    if (c == ' ' && allow_space) continue;
    if (static_cast<unsigned char>(c) < 0x20 ||
        std::string_view(" <>&\"'/\\:*?|.").find(c) != std::string_view::npos) {
      return true;
    }
  }
  return false;
}

bool ParseBoolAttribute(const char* value) {
  const std::string_view v = value == nullptr ? "" : value;
  return v == "true" || v == "1" || v == "True" || v == "TRUE";
}

int ChildElementCount(const XMLElement* element) {
  int n = 0;
  for (auto* c = element->FirstChildElement(); c != nullptr; c = c->NextSiblingElement())
    ++n;
  return n;
}

std::string Join(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& item : items)
    out += (out.empty() ? "" : ", ") + item;
  return out;
}

}  // namespace

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
  std::map<std::string, PortsList, std::less<>> subtree_models;
  std::optional<std::string> main_tree_to_execute;
  bool first_document{true};
  std::vector<std::string> warnings;

  void Warn(std::string message) { warnings.push_back(std::move(message)); }

  static std::string Where(const std::string& file, const XMLElement* e) {
    return Cat(file, ":", e->GetLineNum(), ": ");
  }

  // ---- reading documents

  void ReadDocument(const std::string& xml, const std::string& file,
                    const std::filesystem::path& base_dir,
                    std::vector<std::filesystem::path>& include_stack) {
    auto doc = std::make_shared<XMLDocument>();
    if (doc->Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS) {
      throw LogicError(Cat(file, ":", doc->ErrorLineNum(), ": malformed XML: ", doc->ErrorStr()));
    }
    const XMLElement* root = doc->RootElement();
    if (root == nullptr) throw LogicError(Cat(file, ": the document has no element"));
    if (std::string_view(root->Name()) != "root") {
      throw LogicError(Cat(Where(file, root), "the document element must be <root>, found <",
                           root->Name(), ">"));
    }
    const char* format = root->Attribute("BTCPP_format");
    if (format == nullptr) {
      Warn(Cat(file,
               ": <root> has no BTCPP_format attribute; reading it as BehaviorTree.CPP version 4 "
               "(a version 3 file may not load correctly)"));
    } else if (std::string_view(format) != "4") {
      throw LogicError(Cat(Where(file, root), "BTCPP_format=\"", format,
                           "\" is not supported; only version 4 trees load"));
    }
    if (first_document) {
      if (const char* main = root->Attribute("main_tree_to_execute")) main_tree_to_execute = main;
      first_document = false;
    }
    documents.push_back(doc);

    bool seen_model = false;
    int unnamed = 0;
    const int tree_count = [&] {
      int n = 0;
      for (auto* e = root->FirstChildElement("BehaviorTree"); e != nullptr;
           e = e->NextSiblingElement("BehaviorTree"))
        ++n;
      return n;
    }();
    for (const XMLElement* e = root->FirstChildElement(); e != nullptr;
         e = e->NextSiblingElement()) {
      const std::string_view tag = e->Name();
      if (tag == "include") {
        ReadInclude(e, file, base_dir, include_stack);
      } else if (tag == "BehaviorTree") {
        ReadTreeDefinition(e, file, tree_count, unnamed);
      } else if (tag == "TreeNodesModel") {
        if (seen_model)
          throw LogicError(
              Cat(Where(file, e), "a second <TreeNodesModel>; a file may have only one"));
        seen_model = true;
        ReadSubTreeModels(e, file);
      } else {
        throw LogicError(Cat(Where(file, e), "unexpected element <", tag,
                             "> under <root> (expected BehaviorTree, include or TreeNodesModel)"));
      }
    }
  }

  void ReadInclude(const XMLElement* e, const std::string& file,
                   const std::filesystem::path& base_dir,
                   std::vector<std::filesystem::path>& include_stack) {
    if (e->Attribute("ros_pkg") != nullptr) {
      throw LogicError(Cat(Where(file, e),
                           "<include ros_pkg=…> needs ROS package paths, which egress does not "
                           "resolve; use a path relative to this file"));
    }
    const char* path_attr = e->Attribute("path");
    if (path_attr == nullptr)
      throw LogicError(Cat(Where(file, e), "<include> needs a path attribute"));
    std::filesystem::path path = path_attr;
    if (path.is_relative()) path = base_dir / path;
    std::error_code error;
    const auto canonical = std::filesystem::weakly_canonical(path, error);
    if (std::find(include_stack.begin(), include_stack.end(), canonical) != include_stack.end()) {
      throw LogicError(
          Cat(Where(file, e), "<include path=\"", path_attr, "\"> includes itself (a cycle)"));
    }
    std::ifstream in(path);
    if (!in)
      throw LogicError(Cat(Where(file, e), "included file '", path.string(), "' cannot be read"));
    std::stringstream text;
    text << in.rdbuf();
    include_stack.push_back(canonical);
    ReadDocument(text.str(), path.string(), path.parent_path(), include_stack);
    include_stack.pop_back();
  }

  void ReadTreeDefinition(const XMLElement* e, const std::string& file, int tree_count,
                          int& unnamed) {
    std::string id;
    if (const char* attr = e->Attribute("ID")) {
      id = attr;
    } else if (tree_count == 1) {
      id = Cat("BehaviorTree_", unnamed++);
    } else {
      throw LogicError(
          Cat(Where(file, e), "<BehaviorTree> needs an ID when a file holds several trees"));
    }
    if (id.empty()) throw LogicError(Cat(Where(file, e), "<BehaviorTree> has an empty ID"));
    if (HasForbiddenCharacter(id, /*allow_space=*/true)) {
      throw LogicError(
          Cat(Where(file, e), "BehaviorTree ID '", id, "' contains a forbidden character"));
    }
    if (id.find(' ') != std::string::npos) {
      Warn(Cat(Where(file, e), "BehaviorTree ID '", id,
               "' contains spaces; BehaviorTree.CPP >= 4.8.4 rejects it"));
    }
    if (registrations.contains(id)) {
      throw LogicError(
          Cat(Where(file, e), "BehaviorTree ID '", id, "' is the name of a registered node type"));
    }
    if (auto it = trees.find(id); it != trees.end()) {
      throw LogicError(Cat(Where(file, e), "BehaviorTree '", id, "' is defined twice (also in ",
                           it->second.file, ":", it->second.element->GetLineNum(), ")"));
    }
    const int children = ChildElementCount(e);
    if (children != 1) {
      throw LogicError(Cat(Where(file, e), "BehaviorTree '", id,
                           "' must have exactly one root node, has ", children));
    }
    trees[id] = {id, e, file};
    tree_order.push_back(id);
  }

  static PortsList ReadModelPorts(const XMLElement* model, const std::string& file) {
    PortsList ports;
    for (const XMLElement* p = model->FirstChildElement(); p != nullptr;
         p = p->NextSiblingElement()) {
      const std::string_view tag = p->Name();
      PortInfo info;
      if (tag == "input_port") {
        info.direction = PortDirection::kInput;
      } else if (tag == "output_port") {
        info.direction = PortDirection::kOutput;
      } else if (tag == "inout_port") {
        info.direction = PortDirection::kInOut;
      } else {
        continue;  // MetadataFields and others are Groot2 metadata
      }
      const char* name = p->Attribute("name");
      if (name == nullptr)
        throw LogicError(Cat(Where(file, p), "<", tag, "> needs a name attribute"));
      if (const char* type = p->Attribute("type")) info.type_name = type;  // informational only
      if (const char* def = p->Attribute("default")) info.default_value = def;
      if (const char* text = p->GetText()) info.description = text;
      info.parse = [](std::string_view text, const TypeRegistry*) {
        return Any(std::string(text));
      };
      ports[name] = std::move(info);
    }
    return ports;
  }

  void ReadSubTreeModels(const XMLElement* model, const std::string& file) {
    for (const XMLElement* m = model->FirstChildElement(); m != nullptr;
         m = m->NextSiblingElement()) {
      if (std::string_view(m->Name()) != "SubTree") continue;
      const char* id = m->Attribute("ID");
      if (id == nullptr) throw LogicError(Cat(Where(file, m), "<SubTree> model needs an ID"));
      subtree_models[id] = ReadModelPorts(m, file);
    }
  }

  // ---- instantiation

  struct BuildState {
    Tree* tree;
    const LoadOptions* options;
    std::vector<std::string> subtree_stack;
    std::set<std::string> paths;
    std::set<const NodeManifest*> manifests_used;
  };

  TreeNode* AddNode(BuildState& state, std::unique_ptr<TreeNode> node) {
    TreeNode* raw = node.get();
    state.tree->nodes_.push_back(std::move(node));
    return raw;
  }

  NodeConfig BaseConfig(BuildState& state, const Blackboard::Ptr& blackboard,
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

  // Reads _failureIf … _onHalted into the config; returns true if the attribute was one.
  static bool ReadConditionAttribute(NodeConfig& config, std::string_view attribute,
                                     const char* value, const std::string& where) {
    const auto parse = [&](std::shared_ptr<const Script>& slot) {
      try {
        slot = Script::Parse(value);
      } catch (const LogicError& e) {
        throw LogicError(Cat(where, attribute, ": ", e.what()));
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

  std::string DescribeNode(const std::string& where, std::string_view id, std::string_view name) {
    return name == id ? Cat(where, "node '", id, "'") : Cat(where, "node '", name, "' (", id, ")");
  }

  TreeNode* Build(const XMLElement* e, const Blackboard::Ptr& blackboard, const std::string& prefix,
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
        throw LogicError(Cat(where, "<", tag, " ID=\"", e->Attribute("ID"),
                             "\">: the compact form <", tag, "> must not have an ID attribute"));
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
    config.manifest_ports = m.stand_in ? nullptr : &m.ports;
    if (m.stand_in && !m.ports.empty()) config.manifest_ports = &m.ports;
    config.path = prefix + name;
    if (name == id) config.path += Cat("::", config.uid);

    for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a != nullptr; a = a->Next()) {
      const std::string_view attribute = a->Name();
      if (attribute == "ID" || attribute == "name") continue;
      if (ReadConditionAttribute(config, attribute, a->Value(), where)) continue;
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
            throw LogicError(Cat(
                what, ": port '", attribute, "' is not declared by '", id,
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

  void CheckPorts(const NodeManifest& m, const NodeConfig& config,
                  const Blackboard::Ptr& blackboard, const std::string& what) {
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
          throw LogicError(Cat(what, ": port '", port, "' value '", text,
                               "' cannot be converted to ", info.type_name, ": ", e.what()));
        }
      }
    }
  }

  bool IsEnumName(const std::string& text) const { return enums->contains(text); }

  static void DeclareType(const Blackboard::Ptr& blackboard, const std::string& key,
                          const PortInfo& info, const std::string& what, const std::string& port) {
    try {
      blackboard->DeclareType(key, info);
    } catch (const LogicError& e) {
      throw LogicError(Cat(what, ": port '", port, "': ", e.what()));
    }
  }

  TreeNode* BuildSubTree(const XMLElement* e, const Blackboard::Ptr& parent,
                         const std::string& prefix, const TreeDefinition& definition,
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

    NodeConfig config = BaseConfig(state, parent, id);
    config.path = prefix + name;
    if (name_attr == nullptr) config.path += Cat("::", config.uid);
    if (!state.paths.insert(config.path).second) {
      throw LogicError(Cat(where, "Duplicate SubTree path '", config.path,
                           "': give sibling SubTrees distinct name attributes"));
    }
    auto child_blackboard = Blackboard::Create(parent);
    child_blackboard->SetTypeRegistry(types.get());
    state.tree->blackboards_.push_back(child_blackboard);

    bool auto_remap = false;
    std::set<std::string> given;
    for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a != nullptr; a = a->Next()) {
      const std::string attribute = a->Name();
      if (attribute == "ID" || attribute == "name") continue;
      if (ReadConditionAttribute(config, attribute, a->Value(), where)) continue;  // parent scope
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
          throw LogicError(Cat(
              where, "SubTree '", id, "' port '", port,
              "' is declared in its TreeNodesModel without a default and is not remapped here"));
        }
      }
    }

    auto node = std::make_unique<internal::SubTreeNode>(name, std::move(config), id);
    TreeNode* raw = AddNode(state, std::move(node));
    state.subtree_stack.push_back(id);
    const XMLElement* body = found->second.element->FirstChildElement();
    TreeNode* root = Build(body, child_blackboard, raw->path() + "/", found->second, state);
    state.subtree_stack.pop_back();
    static_cast<internal::SubTreeNode*>(raw)->SetChild(root);
    return raw;
  }

  // `{key}` remaps into the parent; a literal is written into the subtree's blackboard (as an
  // integer or double when it parses fully as one, else as a string; BT.CPP 4.9.1+).
  static void ApplySubTreePort(const Blackboard::Ptr& child, const std::string& port,
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

  std::string ChooseMainTree(std::string_view requested) const {
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
    if (trees.empty()) throw LogicError("no BehaviorTree is registered");
    throw LogicError(Cat("[main_tree_to_execute] was not specified and there are several trees (",
                         Join(tree_order), "); name the tree to run"));
  }
};

BehaviorTreeFactory::BehaviorTreeFactory() : impl_(std::make_unique<Impl>()) {
  internal::RegisterBuiltinNodes(*this);
}
BehaviorTreeFactory::~BehaviorTreeFactory() = default;

void BehaviorTreeFactory::RegisterBuilder(NodeManifest manifest, NodeBuilder builder) {
  if (manifest.id.empty()) throw LogicError("a node type needs a non-empty ID");
  if (HasForbiddenCharacter(manifest.id, false)) {
    throw LogicError(Cat("node type ID '", manifest.id, "' contains a forbidden character"));
  }
  if (manifest.id == "SubTree" || manifest.id == "root" || manifest.id == "Root") {
    throw LogicError(Cat("node type ID '", manifest.id, "' is reserved"));
  }
  if (impl_->registrations.contains(manifest.id)) {
    throw LogicError(Cat("node type '", manifest.id, "' is registered already"));
  }
  for (const auto& [port, info] : manifest.ports) {
    if (port.empty() || HasForbiddenCharacter(port, false) ||
        std::isdigit(static_cast<unsigned char>(port[0]))) {
      throw LogicError(Cat("node type '", manifest.id, "': invalid port name '", port, "'"));
    }
  }
  const std::string id = manifest.id;
  impl_->registrations[id] = {std::make_shared<const NodeManifest>(std::move(manifest)),
                              std::move(builder)};
}

void BehaviorTreeFactory::RegisterSimpleAction(const std::string& id,
                                               SimpleLeafNode::Function function, PortsList ports) {
  RegisterBuilder({id, NodeKind::kAction, std::move(ports), "", false},
                  [function](const std::string& name, NodeConfig config) {
                    return std::make_unique<SimpleLeafNode>(name, std::move(config),
                                                            NodeKind::kAction, function);
                  });
}

void BehaviorTreeFactory::RegisterSimpleCondition(const std::string& id,
                                                  SimpleLeafNode::Function function,
                                                  PortsList ports) {
  RegisterBuilder({id, NodeKind::kCondition, std::move(ports), "", false},
                  [function](const std::string& name, NodeConfig config) {
                    return std::make_unique<SimpleLeafNode>(name, std::move(config),
                                                            NodeKind::kCondition, function);
                  });
}

void BehaviorTreeFactory::RegisterStandIn(const std::string& id, NodeKind kind, PortsList ports) {
  NodeManifest manifest{id, kind, std::move(ports), "stand-in", false, true};
  RegisterBuilder(std::move(manifest), [kind](const std::string& name, NodeConfig config) {
    return internal::MakeStandIn(kind, name, std::move(config));
  });
}

std::vector<std::string> BehaviorTreeFactory::RegisterStandInsFromModelFile(
    const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw LogicError(Cat("model file '", path.string(), "' cannot be read"));
  std::stringstream text;
  text << in.rdbuf();
  return RegisterStandInsFromModelText(text.str(), path.string());
}

std::vector<std::string> BehaviorTreeFactory::RegisterStandInsFromModelText(
    const std::string& xml, const std::string& source_name) {
  XMLDocument doc;
  if (doc.Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS) {
    throw LogicError(
        Cat(source_name, ":", doc.ErrorLineNum(), ": malformed XML: ", doc.ErrorStr()));
  }
  const XMLElement* root = doc.RootElement();
  const XMLElement* model = root == nullptr ? nullptr : root->FirstChildElement("TreeNodesModel");
  if (model == nullptr) throw LogicError(Cat(source_name, ": no <root><TreeNodesModel> found"));
  std::vector<std::string> registered;
  for (const XMLElement* m = model->FirstChildElement(); m != nullptr;
       m = m->NextSiblingElement()) {
    const auto kind = ExplicitKind(m->Name());
    if (!kind || *kind == NodeKind::kSubTree) continue;
    const char* id = m->Attribute("ID");
    if (id == nullptr)
      throw LogicError(Cat(Impl::Where(source_name, m), "<", m->Name(), "> model needs an ID"));
    if (impl_->registrations.contains(id)) continue;
    RegisterStandIn(id, *kind, Impl::ReadModelPorts(m, source_name));
    registered.push_back(id);
  }
  return registered;
}

void BehaviorTreeFactory::RegisterConverterImpl(std::type_index type, std::string name,
                                                TypeRegistry::Converter converter) {
  impl_->types->Register(type, std::move(name), std::move(converter));
}

void BehaviorTreeFactory::RegisterScriptingEnum(const std::string& name, std::int64_t value) {
  if (name.empty() || !(std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_')) {
    throw LogicError(Cat("scripting enum name '", name, "' is not an identifier"));
  }
  (*impl_->enums)[name] = value;
}

const NodeManifest* BehaviorTreeFactory::FindManifest(std::string_view id) const {
  auto it = impl_->registrations.find(id);
  return it == impl_->registrations.end() ? nullptr : it->second.manifest.get();
}

std::vector<const NodeManifest*> BehaviorTreeFactory::Manifests() const {
  std::vector<const NodeManifest*> out;
  for (const auto& [id, registration] : impl_->registrations)
    out.push_back(registration.manifest.get());
  return out;
}

void BehaviorTreeFactory::RegisterTreesFromFile(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in)
    throw LogicError(
        Cat("behavior tree file '", path.string(), "' does not exist or cannot be read"));
  std::stringstream text;
  text << in.rdbuf();
  std::error_code error;
  std::vector<std::filesystem::path> stack = {std::filesystem::weakly_canonical(path, error)};
  impl_->ReadDocument(text.str(), path.string(), path.parent_path(), stack);
}

void BehaviorTreeFactory::RegisterTreesFromText(const std::string& xml,
                                                const std::string& source_name) {
  std::vector<std::filesystem::path> stack;
  impl_->ReadDocument(xml, source_name, std::filesystem::current_path(), stack);
}

std::vector<std::string> BehaviorTreeFactory::RegisteredTreeIds() const {
  return impl_->tree_order;
}

void BehaviorTreeFactory::ClearRegisteredTrees() {
  impl_->trees.clear();
  impl_->tree_order.clear();
  impl_->subtree_models.clear();
  impl_->documents.clear();
  impl_->main_tree_to_execute.reset();
  impl_->first_document = true;
}

Tree BehaviorTreeFactory::CreateTree(std::string_view tree_id, Blackboard::Ptr blackboard,
                                     const LoadOptions& options) {
  const std::string main = impl_->ChooseMainTree(tree_id);
  Tree tree;
  tree.main_tree_id_ = main;
  tree.context_->types = impl_->types.get();
  tree.context_->enums = impl_->enums.get();
  tree.keep_alive_.push_back(impl_->types);
  tree.keep_alive_.push_back(std::make_shared<ScriptEnums>(*impl_->enums));
  tree.context_->enums = static_cast<const ScriptEnums*>(tree.keep_alive_.back().get());
  for (const auto& doc : impl_->documents)
    tree.keep_alive_.push_back(doc);
  if (!blackboard) blackboard = Blackboard::Create();
  blackboard->SetTypeRegistry(impl_->types.get());
  tree.blackboards_.push_back(blackboard);

  Impl::BuildState state{&tree, &options, {main}, {}, {}};
  const auto& definition = impl_->trees.at(main);
  impl_->Build(definition.element->FirstChildElement(), blackboard, "", definition, state);
  return tree;
}

Tree BehaviorTreeFactory::CreateTreeFromFile(const std::filesystem::path& path,
                                             std::string_view tree_id, Blackboard::Ptr blackboard,
                                             const LoadOptions& options) {
  RegisterTreesFromFile(path);
  return CreateTree(tree_id, std::move(blackboard), options);
}

Tree BehaviorTreeFactory::CreateTreeFromText(const std::string& xml, std::string_view tree_id,
                                             Blackboard::Ptr blackboard,
                                             const LoadOptions& options) {
  RegisterTreesFromText(xml);
  return CreateTree(tree_id, std::move(blackboard), options);
}

const std::vector<std::string>& BehaviorTreeFactory::warnings() const {
  return impl_->warnings;
}

}  // namespace egress::bt
