#pragma once
/// @file
/// Libraries planning is built on (OMPL, FCL), for `egress --version`. Base planning, local
/// avoidance, IK, trajectories and tracking control arrive with the planning issue; see
/// README.md, "Where each capability lives".

#include <vector>

#include "egress/hsr_interface/version.h"

namespace egress::planning {

std::vector<LibraryVersion> LibraryVersions();

}  // namespace egress::planning
