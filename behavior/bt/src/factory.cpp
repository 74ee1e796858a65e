#include "factory_impl.h"

namespace egress::bt {

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
  return RegisterStandInsFromModelText(factory_detail::ReadTreeFile(path, "model file"),
                                       path.string());
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
  const std::string text = factory_detail::ReadTreeFile(path, "behavior tree file");
  std::error_code error;
  std::vector<std::filesystem::path> stack = {std::filesystem::weakly_canonical(path, error)};
  impl_->ReadDocument(text, path.string(), path.parent_path(), stack);
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
  impl_->files_read.clear();
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

  // A departure from BT.CPP, which applies a SubTree model's defaults only where a SubTree node
  // calls it: run as the main tree, a tree's modelled input ports with a literal default get it
  // where its blackboard has no entry, so a tree with an optional port runs the same on its own
  // as when called without that port. (A default naming an entry, {key}, has no parent to read.)
  if (auto model = impl_->subtree_models.find(main); model != impl_->subtree_models.end()) {
    for (const auto& [port, info] : model->second) {
      if (info.default_value && !BlackboardKeyOf(*info.default_value, port) &&
          !blackboard->Has(port))
        Impl::ApplySubTreePort(blackboard, port, *info.default_value);
    }
  }
  Impl::BuildState state{&tree, &options, {main}, {}, {}, {}};
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
