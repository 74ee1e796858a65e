#include "egress/twin/mobility.h"

namespace egress::twin {

const std::vector<MobilityClass>& MobilityClasses() {
  // Speeds: Boyce, Shields & Silcock 1999 (see the header), mean ± 1 s.d.: no disability
  // 1.24 ± 0.25, walking stick 0.81 ± 0.38 (floored at 0.45), walking frame / rollator
  // 0.57 ± 0.29 (floored at 0.3), manual wheelchair 0.69 ± 0.35 (floored at 0.35).
  static const std::vector<MobilityClass> classes = {
      {"walker", {0.99, 1.49}, 0.23, 1.0, {1.0, 2.0}},
      {"cane", {0.45, 1.19}, 0.25, 1.0, {2.0, 4.0}},
      // Letting go of the frame to reach the actuator, then taking hold of it again.
      {"frame", {0.30, 0.86}, 0.30, 1.0, {4.0, 8.0}},
      // Self-propelled: manoeuvring alongside an actuator in a queue is not always possible.
      {"wheelchair", {0.35, 1.04}, 0.33, 0.5, {5.0, 10.0}},
      // Pushed by a helper (assumption: the helper's pace, slowed to 1.0 m/s ± 0.2; no Boyce
      // figure); the helper presses.
      {"wheelchair_pushed", {0.8, 1.2}, 0.35, 1.0, {2.0, 4.0}},
  };
  return classes;
}

const MobilityClass* FindMobilityClass(std::string_view name) {
  for (const auto& c : MobilityClasses()) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

std::string MobilityClassNames() {
  std::string names;
  for (const auto& c : MobilityClasses())
    names += (names.empty() ? "" : ", ") + c.name;
  return names;
}

}  // namespace egress::twin
