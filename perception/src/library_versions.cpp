#include "egress/perception/library_versions.h"

#include <opencv2/core/utility.hpp>

namespace egress::perception {

std::vector<LibraryVersion> LibraryVersions() {
  return {
      {"OpenCV", cv::getVersionString()},
      {"OctoMap", EGRESS_OCTOMAP_VERSION},
  };
}

}  // namespace egress::perception
