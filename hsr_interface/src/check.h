#pragma once
// Field checks shared by the Validate() methods of hsr_interface's message types.

#include <cmath>
#include <string_view>

#include "egress/hsr_interface/error.h"

namespace egress::internal {

inline void CheckFinite(double value, std::string_view type, std::string_view field) {
  ThrowUnless(std::isfinite(value), "Invalid ", type, ": ", field, " (", value,
              ") must be finite.");
}

}  // namespace egress::internal
