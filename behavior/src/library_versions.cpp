#include "egress/behavior/library_versions.h"

#include <tinyxml2.h>

namespace egress::behavior {

std::vector<LibraryVersion> LibraryVersions() {
  return {{"tinyxml2",
           DottedVersion(TIXML2_MAJOR_VERSION, TIXML2_MINOR_VERSION, TIXML2_PATCH_VERSION)}};
}

}  // namespace egress::behavior
