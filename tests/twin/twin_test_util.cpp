// The one twin-test file that holds this checkout's worlds/ path (EGRESS_WORLDS_DIR): the
// other test files then compile the same in any checkout (ccache shares them).

#include "twin_test_util.h"

namespace egress::twin::testing {

std::filesystem::path WorldsDir() {
  return EGRESS_WORLDS_DIR;
}

}  // namespace egress::twin::testing
