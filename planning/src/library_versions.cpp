#include "egress/planning/library_versions.h"

#include <fcl/config.h>
#include <ompl/config.h>

namespace egress::planning {

std::vector<LibraryVersion> LibraryVersions() {
  return {
      // ompl/config.h's OMPL_VERSION is empty in Debian's build; the numeric parts are right.
      {"OMPL", DottedVersion(OMPL_MAJOR_VERSION, OMPL_MINOR_VERSION, OMPL_PATCH_VERSION)},
      {"FCL", FCL_VERSION},
  };
}

}  // namespace egress::planning
