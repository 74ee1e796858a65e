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
  const int side = SideOfDoor(door, p_M);
  if (side == 0) return nullptr;
  const MapActuator* best = nullptr;
  double best_distance = 0.0;
  for (const auto& a : actuators) {
    if (a.door != door) continue;
    // Its side: where it stands; an actuator on the door line itself (on a jamb) by its facing.
    int actuator_side = SideOfDoor(door, a.p_M.head<2>());
    if (actuator_side == 0) {
      const Eigen::Vector2d towards = a.p_M.head<2>() + a.n_M.head<2>() * 0.01;
      actuator_side = SideOfDoor(door, towards);
    }
    if (actuator_side != side) continue;
    const double distance = (p_M - a.p_M.head<2>()).norm();
    if (best == nullptr || distance < best_distance) {
      best = &a;
      best_distance = distance;
    }
  }
  return best;
}

int MissionMap::SideOfDoor(const std::string& door, const Eigen::Vector2d& p_M) const {
  const perception::DoorModel* d = FindDoor(door);
  if (d == nullptr) return 0;
  const double s = (p_M - d->p_MHinge).dot(d->SwingSide());
  return s > 1e-3 ? 1 : (s < -1e-3 ? -1 : 0);
}

const MapPlace* MissionMap::FindPlace(const std::string& name) const {
  for (const auto& p : places) {
    if (p.name == name) return &p;
  }
  return nullptr;
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
  for (const auto& p : places)
    ThrowUnless(p.X_MP.IsFinite(), "building map: place '", p.name, "' has a non-finite pose");
}

}  // namespace egress::behavior
