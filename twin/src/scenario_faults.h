#pragma once
// Internal to twin/src: the scenario file's `faults:` section (scenario_faults.cpp), read by the
// scenario parser (scenario.cpp).

#include <yaml-cpp/yaml.h>

#include <vector>

#include "egress/twin/scenario.h"
#include "yaml_field_reader.h"

namespace egress::twin {

// Reads `faults:`, a list of {kind, start, duration, ...}; unknown kinds or keys and bad values
// are errors naming the field and line.
std::vector<FaultSpec> ParseFaults(const FieldReader& r, const YAML::Node& node);

}  // namespace egress::twin
