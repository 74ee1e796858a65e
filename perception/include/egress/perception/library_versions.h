#pragma once
/// @file
/// Libraries perception is built on (OpenCV, OctoMap), for `egress --version`. The world model,
/// localization, detection pipeline and trackers arrive with the perception issue; see
/// README.md, "Where each capability lives".

#include <vector>

#include "egress/hsr_interface/version.h"

namespace egress::perception {

std::vector<LibraryVersion> LibraryVersions();

}  // namespace egress::perception
