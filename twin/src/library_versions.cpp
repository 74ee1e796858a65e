#include "egress/twin/library_versions.h"

#include <LinearMath/btScalar.h>
#include <assimp/version.h>

namespace egress::twin {

std::vector<LibraryVersion> LibraryVersions() {
  const int bullet = btGetVersion();  // e.g. 324 for 3.24
  return {
      {"Bullet", std::to_string(bullet / 100) + "." + std::to_string(bullet % 100) +
                     (sizeof(btScalar) == 8 ? " (double precision)" : " (single precision)")},
      {"sdformat", EGRESS_SDFORMAT_VERSION},
      {"assimp",
       DottedVersion(int(aiGetVersionMajor()), int(aiGetVersionMinor()), int(aiGetVersionPatch()))},
      {"yaml-cpp", EGRESS_YAML_CPP_VERSION},
  };
}

}  // namespace egress::twin
