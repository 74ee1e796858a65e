// libFuzzer entry: egress::fuzz::MapServer (see fuzz_targets.h).
#include "fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return egress::fuzz::MapServer(data, size);
}
