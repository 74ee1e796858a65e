#pragma once
/// @file
/// Libraries the twin is built on (Bullet, sdformat, assimp, yaml-cpp), for `egress --version`.
/// The twin itself (SDF worlds, ADA doors, people, the HSR body, simulated sensors) arrives with
/// the digital-twin issue; see README.md, "Where each capability lives".

#include <vector>

#include "egress/hsr_interface/version.h"

namespace egress::twin {

/// Versions as reported by the libraries at run time where they can tell (Bullet, assimp), else
/// as found at configure time.
std::vector<LibraryVersion> LibraryVersions();

}  // namespace egress::twin
