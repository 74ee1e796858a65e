#include "urdf_joint_tree.h"

#include <algorithm>
#include <map>
#include <set>
#include <vector>

#include <tinyxml2.h>

#include "egress/hsr_interface/error.h"

namespace egress {

std::string CanonicalRobotXml(const std::string& urdf_xml) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(urdf_xml.c_str(), urdf_xml.size()) != tinyxml2::XML_SUCCESS) return {};
  const tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  if (robot == nullptr) return {};
  tinyxml2::XMLPrinter printer;
  robot->Accept(&printer);
  return std::string(printer.CStr(),
                     std::size_t(printer.CStrSize() > 0 ? printer.CStrSize() - 1 : 0));
}

std::optional<std::string> FindJointTreeProblem(const std::string& urdf_xml,
                                                std::string_view root_link) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(urdf_xml.c_str(), urdf_xml.size()) != tinyxml2::XML_SUCCESS)
    return std::string(StrCat("XML error: ", doc.ErrorStr()));
  // The element urdfdom reads: the first top-level <robot>, not merely the first element (a
  // fuzzed file with a stray element before <robot> passed this check and leaked in urdfdom).
  const tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  if (robot == nullptr) return std::string("the document has no <robot> element.");
  std::set<std::string, std::less<>> links;
  for (const auto* link = robot->FirstChildElement("link"); link != nullptr;
       link = link->NextSiblingElement("link")) {
    if (const char* name = link->Attribute("name")) links.insert(name);
  }
  std::map<std::string, std::pair<std::string, std::string>> parent_of;  // child -> joint, parent
  for (const auto* joint = robot->FirstChildElement("joint"); joint != nullptr;
       joint = joint->NextSiblingElement("joint")) {
    const auto* parent = joint->FirstChildElement("parent");
    const auto* child = joint->FirstChildElement("child");
    const char* name = joint->Attribute("name");
    if (parent == nullptr || child == nullptr || name == nullptr) continue;  // urdfdom says
    const char* parent_link = parent->Attribute("link");
    const char* child_link = child->Attribute("link");
    if (parent_link == nullptr || child_link == nullptr) continue;
    // urdfdom fails on an undeclared link only after linking part of its tree, and leaks it.
    for (const char* link : {parent_link, child_link}) {
      if (!links.contains(link))
        return std::string(StrCat("joint '", name, "' (line ", joint->GetLineNum(),
                                  ") names link '", link, "', which the model does not declare."));
    }
    if (std::string_view(parent_link) == child_link)
      return std::string(StrCat("joint '", name, "' (line ", joint->GetLineNum(), ") has link '",
                                child_link, "' as both its parent and its child."));
    const auto [it, added] = parent_of.try_emplace(child_link, name, parent_link);
    if (!added)
      return std::string(StrCat("link '", child_link, "' is the child of two joints, '",
                                it->second.first, "' and '", name, "' (line ", joint->GetLineNum(),
                                "): a link has one parent."));
  }
  for (const auto& [start, unused] : parent_of) {
    std::vector<std::string> chain;  // joints walked from `start` towards the root
    for (auto it = parent_of.find(start); it != parent_of.end();
         it = parent_of.find(it->second.second)) {
      const auto seen = std::find(chain.begin(), chain.end(), it->second.first);
      if (seen != chain.end()) {
        std::string cycle;
        for (auto j = seen; j != chain.end(); ++j)
          cycle += "'" + *j + "' -> ";
        return std::string(StrCat("joints form a kinematic cycle: ", cycle, "'", *seen,
                                  "' (a robot model must be a tree rooted at '", root_link, "')."));
      }
      chain.push_back(it->second.first);
    }
  }
  return std::nullopt;
}

}  // namespace egress
