#include "egress/behavior/mission_map.h"

#include "egress/hsr_interface/error.h"

namespace egress::behavior {

const perception::DoorModel* MissionMap::FindDoor(const std::string& id) const {
  for (const auto& d : doors) {
    if (d.id == id) return &d;
  }
  return nullptr;
}

const MapActuator* MissionMap::FindActuatorOf(const std::string& door) const {
  for (const auto& a : actuators) {
    if (a.door == door) return &a;
  }
  return nullptr;
}

void MissionMap::Validate() const {
  for (const auto& d : doors) {
    d.Validate();
    bool found = false;
    for (const auto& w : doorways)
      found = found || w.id == d.id;
    ThrowUnless(found, "building map: door '", d.id, "' has no doorway");
  }
  for (const auto& a : actuators) {
    ThrowUnless(FindDoor(a.door) != nullptr, "building map: actuator '", a.id,
                "' operates unknown door '", a.door, "'");
    ThrowUnless(a.p_M.allFinite() && a.n_M.allFinite() && std::abs(a.n_M.norm() - 1.0) < 1e-6,
                "building map: actuator '", a.id, "': non-finite pose or a non-unit normal");
  }
}

}  // namespace egress::behavior
