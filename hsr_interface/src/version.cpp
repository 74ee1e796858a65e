#include "egress/hsr_interface/version.h"

#include <Eigen/Core>

#include "egress_revision.h"  // generated at build time: EGRESS_GIT_REVISION

#ifndef EGRESS_VERSION
#error "EGRESS_VERSION must be defined by the build"
#endif

namespace egress {

const char* Version() {
  return EGRESS_VERSION;
}
const char* GitRevision() {
  return EGRESS_GIT_REVISION;
}

std::string DottedVersion(int major, int minor, int patch) {
  return std::to_string(major) + "." + std::to_string(minor) + "." + std::to_string(patch);
}

std::vector<LibraryVersion> HsrInterfaceLibraryVersions() {
  return {
      {"Eigen", DottedVersion(EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION)},
      {"urdfdom", EGRESS_URDFDOM_VERSION},
  };
}

}  // namespace egress
