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

}  // namespace egress
