#pragma once
// The joints of a URDF form a tree, checked on its XML before urdfdom reads it: urdfdom lets a
// loop of joints cut off from the root through (walking up from one of its links never ends),
// and it leaks the model it half-built for a self-joint, a second parent or an undeclared link
// (shared pointers that own each other).

#include <optional>
#include <string>
#include <string_view>

namespace egress {

/// What keeps the joints of `urdf_xml` from forming a tree rooted at `root_link` (malformed XML,
/// a joint naming an undeclared link or the same link twice, a link with two parent joints, a
/// cycle, each named by joint and line), or nullopt.
std::optional<std::string> FindJointTreeProblem(const std::string& urdf_xml,
                                                std::string_view root_link);

/// The first top-level <robot> element of `urdf_xml` as tinyxml2 reads it, printed again (empty
/// if there is none or the XML is malformed). This is what urdfdom is given, so that it reads
/// the very document the checks above read: urdfdom parses with TinyXML 1, which reads malformed
/// XML differently (a fuzzed file passed the checks as one tree and reached urdfdom as another,
/// with a self-joint, which it leaked).
std::string CanonicalRobotXml(const std::string& urdf_xml);

}  // namespace egress
