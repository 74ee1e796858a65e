#include "factory_impl.h"

namespace egress::bt {

std::string factory_detail::ReadTreeFile(const std::filesystem::path& path, std::string_view what,
                                         const std::string& where) {
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (!std::filesystem::exists(status))
    throw LogicError(Cat(where, what, " '", path.string(), "' does not exist"));
  if (!std::filesystem::is_regular_file(status))
    throw LogicError(Cat(where, what, " '", path.string(), "' is not a regular file"));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw LogicError(Cat(where, what, " '", path.string(), "' cannot be read"));
  std::string text;
  char buffer[1 << 16];
  while (in && text.size() <= kMaxTreeFileBytes) {
    in.read(buffer, sizeof(buffer));
    text.append(buffer, std::size_t(in.gcount()));
  }
  if (text.size() > kMaxTreeFileBytes)
    throw LogicError(Cat(where, what, " '", path.string(), "' is larger than ", kMaxTreeFileBytes,
                         " bytes, the most egress reads"));
  if (in.bad()) throw LogicError(Cat(where, what, " '", path.string(), "' cannot be read"));
  return text;
}

std::string BehaviorTreeFactory::Impl::Where(const std::string& file, const XMLElement* e) {
  return Cat(file, ":", e->GetLineNum(), ": ");
}

void BehaviorTreeFactory::Impl::ReadDocument(const std::string& xml, const std::string& file,
                                             const std::filesystem::path& base_dir,
                                             std::vector<std::filesystem::path>& include_stack) {
  auto doc = std::make_shared<XMLDocument>();
  if (doc->Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS) {
    throw LogicError(Cat(file, ":", doc->ErrorLineNum(), ": malformed XML: ", doc->ErrorStr()));
  }
  const XMLElement* root = doc->RootElement();
  if (root == nullptr) throw LogicError(Cat(file, ": the document has no element"));
  if (std::string_view(root->Name()) != "root") {
    throw LogicError(
        Cat(Where(file, root), "the document element must be <root>, found <", root->Name(), ">"));
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
  files_read.push_back(file);

  bool seen_model = false;
  int unnamed = 0;
  const int tree_count = [&] {
    int n = 0;
    for (auto* e = root->FirstChildElement("BehaviorTree"); e != nullptr;
         e = e->NextSiblingElement("BehaviorTree"))
      ++n;
    return n;
  }();
  for (const XMLElement* e = root->FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
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

void BehaviorTreeFactory::Impl::ReadInclude(const XMLElement* e, const std::string& file,
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
  const std::string text = ReadTreeFile(path, "included file", Where(file, e));
  include_stack.push_back(canonical);
  ReadDocument(text, path.string(), path.parent_path(), include_stack);
  include_stack.pop_back();
}

void BehaviorTreeFactory::Impl::ReadTreeDefinition(const XMLElement* e, const std::string& file,
                                                   int tree_count, int& unnamed) {
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

PortsList BehaviorTreeFactory::Impl::ReadModelPorts(const XMLElement* model,
                                                    const std::string& file) {
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
    info.parse = [](std::string_view text, const TypeRegistry*) { return Any(std::string(text)); };
    ports[name] = std::move(info);
  }
  return ports;
}

void BehaviorTreeFactory::Impl::ReadSubTreeModels(const XMLElement* model,
                                                  const std::string& file) {
  for (const XMLElement* m = model->FirstChildElement(); m != nullptr;
       m = m->NextSiblingElement()) {
    if (std::string_view(m->Name()) != "SubTree") continue;
    const char* id = m->Attribute("ID");
    if (id == nullptr) throw LogicError(Cat(Where(file, m), "<SubTree> model needs an ID"));
    subtree_models[id] = ReadModelPorts(m, file);
  }
}

}  // namespace egress::bt
