#pragma once
// Internal to twin/src: the scenario file's `sensors:` section (scenario_sensors.cpp), read by
// the scenario parser (scenario.cpp).

#include <yaml-cpp/yaml.h>

#include "egress/twin/scenario.h"
#include "yaml_field_reader.h"

namespace egress::twin {

// Reads `sensors:` (laser, depth, odometry, detector) over the defaults in `c`; unknown keys and
// bad values are errors naming the field and line.
void ParseSensors(const FieldReader& r, const YAML::Node& node, SensorConfig* c);

}  // namespace egress::twin
