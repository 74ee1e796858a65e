#include "test_nodes.h"

#include <cstdlib>
#include <filesystem>

namespace egress::bt::testing {

std::string ReferenceDir() {
  const char* dir = std::getenv("EGRESS_REFERENCE_DIR");
  if (dir == nullptr || !std::filesystem::is_directory(dir)) return "";
  return dir;
}

}  // namespace egress::bt::testing
