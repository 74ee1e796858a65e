// TreeNodesModel export (Groot2's palette) and the expanded tree XML (Groot2, .btlog).

#include <tinyxml2.h>

#include <set>

#include "builtin_nodes.h"
#include "egress/bt/factory.h"

namespace egress::bt {
namespace {

using tinyxml2::XMLDocument;
using tinyxml2::XMLElement;

std::string ToText(const XMLDocument& doc) {
  tinyxml2::XMLPrinter printer;
  doc.Print(&printer);
  return printer.CStr();
}

void AddModel(XMLDocument& doc, XMLElement* model, const NodeManifest& manifest) {
  XMLElement* element = doc.NewElement(std::string(ToString(manifest.kind)).c_str());
  element->SetAttribute("ID", manifest.id.c_str());
  for (const auto& [name, info] : manifest.ports) {
    const std::string tag = Cat(ToString(info.direction), "_port");
    XMLElement* port = doc.NewElement(tag.c_str());
    port->SetAttribute("name", name.c_str());
    if (!info.type_name.empty()) port->SetAttribute("type", info.type_name.c_str());
    if (info.default_value) port->SetAttribute("default", info.default_value->c_str());
    if (!info.description.empty()) port->SetText(info.description.c_str());
    element->InsertEndChild(port);
  }
  model->InsertEndChild(element);
}

const std::string& SubTreeId(const TreeNode& node) {
  return node.config().subtree_id;
}

class TreeWriter {
 public:
  explicit TreeWriter(XMLDocument& doc) : doc_(doc) {}

  // Writes `node` (and, for a SubTree, queues its body as a separate BehaviorTree).
  XMLElement* Write(const TreeNode& node) {
    const bool subtree = node.kind() == NodeKind::kSubTree;
    const std::string& id = subtree ? SubTreeId(node) : node.registration_id();
    XMLElement* e = doc_.NewElement(subtree ? "SubTree" : id.c_str());
    if (subtree) e->SetAttribute("ID", id.c_str());
    if (node.name() != id) e->SetAttribute("name", node.name().c_str());
    for (const auto& [port, text] : node.config().ports)
      e->SetAttribute(port.c_str(), text.c_str());
    for (int i = 0; i < kNumPreConditions; ++i) {
      if (node.config().pre[i])
        e->SetAttribute(std::string(PreConditionNames()[i]).c_str(),
                        node.config().pre[i]->source().c_str());
    }
    for (int i = 0; i < kNumPostConditions; ++i) {
      if (node.config().post[i])
        e->SetAttribute(std::string(PostConditionNames()[i]).c_str(),
                        node.config().post[i]->source().c_str());
    }
    e->SetAttribute("_uid", node.uid());
    if (subtree) {
      e->SetAttribute("_fullpath", node.path().c_str());
      if (!node.children().empty()) pending_.push_back(&node);
      return e;
    }
    ids_.insert(node.registration_id());
    for (const TreeNode* child : node.children())
      e->InsertEndChild(Write(*child));
    return e;
  }

  std::vector<const TreeNode*> TakePending() { return std::exchange(pending_, {}); }
  const std::set<std::string>& ids() const { return ids_; }

 private:
  XMLDocument& doc_;
  std::vector<const TreeNode*> pending_;
  std::set<std::string> ids_;
};

}  // namespace

std::string BehaviorTreeFactory::WriteTreeNodesModelXml(bool include_builtins) const {
  XMLDocument doc;
  XMLElement* root = doc.NewElement("root");
  root->SetAttribute("BTCPP_format", "4");
  doc.InsertEndChild(root);
  XMLElement* model = doc.NewElement("TreeNodesModel");
  root->InsertEndChild(model);
  for (const NodeManifest* manifest : Manifests()) {
    if (manifest->builtin && !include_builtins) continue;
    AddModel(doc, model, *manifest);
  }
  return ToText(doc);
}

std::string WriteTreeToXml(const Tree& tree, const BehaviorTreeFactory& factory) {
  XMLDocument doc;
  XMLElement* root = doc.NewElement("root");
  root->SetAttribute("BTCPP_format", "4");
  root->SetAttribute("main_tree_to_execute", tree.main_tree_id().c_str());
  doc.InsertEndChild(root);
  TreeWriter writer(doc);

  XMLElement* main = doc.NewElement("BehaviorTree");
  main->SetAttribute("ID", tree.main_tree_id().c_str());
  main->SetAttribute("_fullpath", "");
  main->InsertEndChild(writer.Write(tree.root()));
  root->InsertEndChild(main);
  for (auto pending = writer.TakePending(); !pending.empty(); pending = writer.TakePending()) {
    for (const TreeNode* subtree : pending) {
      XMLElement* body = doc.NewElement("BehaviorTree");
      body->SetAttribute("ID", SubTreeId(*subtree).c_str());
      body->SetAttribute("_fullpath", subtree->path().c_str());
      body->InsertEndChild(writer.Write(*subtree->children().front()));
      root->InsertEndChild(body);
    }
  }
  XMLElement* model = doc.NewElement("TreeNodesModel");
  for (const std::string& id : writer.ids()) {
    if (const NodeManifest* manifest = factory.FindManifest(id)) {
      AddModel(doc, model, *manifest);
    } else if (const NodeManifest* stand_in = tree.FindStandInManifest(id)) {
      AddModel(doc, model, *stand_in);  // what the loader inferred of a type it did not know
    }
  }
  root->InsertEndChild(model);
  return ToText(doc);
}

}  // namespace egress::bt
