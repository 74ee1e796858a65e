#pragma once
/// @file
/// Libraries behavior is built on (tinyxml2 for BehaviorTree.CPP v4 XML), for `egress
/// --version`. The behavior-tree engine (behavior/bt/), the task nodes, trees and executive
/// arrive with their issues; see README.md, "Where each capability lives".

#include <vector>

#include "egress/hsr_interface/version.h"

namespace egress::behavior {

std::vector<LibraryVersion> LibraryVersions();

}  // namespace egress::behavior
