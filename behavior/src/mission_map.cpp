#include "egress/behavior/mission_map.h"

#include "egress/hsr_interface/error.h"

namespace egress::behavior {

const perception::DoorModel* MissionMap::FindDoor(const std::string& id) const {
  for (const auto& d : doors) {
    if (d.id == id) return &d;
  }
  return nullptr;
}

const MapActuator* MissionMap::FindActuatorOf(const std::string& door,
                                              const Eigen::Vector2d& p_M) const {
  const MapActuator* best = nullptr;
  double best_distance = 0.0;
  for (const auto& a : actuators) {
    const Eigen::Vector2d offset = p_M - a.p_M.head<2>();
    if (a.door != door || offset.dot(a.n_M.head<2>()) <= 0.0) continue;
    if (best == nullptr || offset.norm() < best_distance) {
      best = &a;
      best_distance = offset.norm();
    }
  }
  return best;
}

const MapActuator* MissionMap::FindActuator(const std::string& id) const {
  for (const auto& a : actuators) {
    if (a.id == id) return &a;
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
