#include "twin_world_impl.h"

#include <limits>

namespace egress::twin {

void TwinWorld::Impl::BuildDoors() {
  std::mt19937_64 rng(DeriveSeed(seed, 1));
  const double hold_override = scenario.randomize.hold_open_s.Sample(rng);
  for (std::size_t i = 0; i < world.doors.size(); ++i) {
    const DoorDescription& d = world.doors[i];
    Door door;
    door.fixed = &fixed.doors[i];
    door.spec = door.fixed->spec;
    if (door.spec && scenario.randomize.hold_open_s.max > 0.0) {
      door.spec->timing.hold_open_s = hold_override;
    }
    const bool glass = door.spec && door.spec->glass;
    const int e = AddEntity(EntityKind::kDoor, d.name, int(i), glass);
    door.leaf = AddBody(std::make_unique<btBoxShape>(ToBt(d.leaf_size / 2)), d.X_WL, d.mass, kGDoor,
                        kMaskDoor, e);
    door.leaf->setFlags(door.leaf->getFlags() | BT_DISABLE_WORLD_GRAVITY);
    door.leaf->setGravity(btVector3(0, 0, 0));
    door.leaf->setActivationState(DISABLE_DEACTIVATION);
    door.leaf->setFriction(0.3);
    const Eigen::Vector3d pivot_L = d.X_WL.rotation().transpose() * (d.p_WH - d.X_WL.translation());
    const Eigen::Vector3d axis_L = d.X_WL.rotation().transpose() * d.axis_W;
    auto hinge = std::make_unique<btHingeConstraint>(*door.leaf, ToBt(pivot_L), ToBt(axis_L));
    // Which sign of Bullet's hinge angle opens the door: probe with a small opening.
    const btTransform closed = ToBt(d.X_WL);
    const btTransform probe = ToBt(d.CalcLeafPose(0.1));
    const btTransform fixed = hinge->getBFrame();
    const double a0 = hinge->getHingeAngle(closed * hinge->getAFrame(), fixed);
    const double a1 = hinge->getHingeAngle(probe * hinge->getAFrame(), fixed);
    // Bullet's hinge angle is in [-pi, pi]: a leaf closed near pi reads the probe's 0.1 rad
    // opening across the wrap (a0 3.075, a1 -3.108: a door turned 86 degrees in a random
    // building opened the wrong way, into its jamb, and never opened).
    door.motor_sign = std::remainder(a1 - a0, 2 * M_PI) > 0.0 ? 1.0 : -1.0;
    if (door.motor_sign > 0)
      hinge->setLimit(a0, a0 + d.max_open_angle, 0.9, 0.3, 0.5);
    else
      hinge->setLimit(a0 - d.max_open_angle, a0, 0.9, 0.3, 0.5);
    door.hinge = hinge.get();
    dynamics->addConstraint(hinge.get(), true);
    constraints.push_back(std::move(hinge));
    if (door.spec) {
      door.op.emplace(door.spec->timing, d.max_open_angle);
      for (const auto& actuator : door.spec->actuators) {
        const ShapeDescription& a = *world.ShapesOfModel(actuator).front();
        ActuatorBox box{a.X_WS, a.box_size};
        if (door.spec->kind == OperatorKind::kPushButton) {
          door.buttons.emplace_back(box, door.spec->button_stroke, door.spec->button_spring_force,
                                    door.spec->button_max_force);
        } else if (door.spec->kind == OperatorKind::kProximityPlate) {
          // Its facing as the building reads it (away from the wall it is mounted on).
          const BuildingActuator* facing = twin_model->building().FindActuator(actuator);
          door.plates.emplace_back(box, door.spec->proximity_range,
                                   facing != nullptr ? std::optional(facing->n_W) : std::nullopt);
        }
      }
    }
    doors.push_back(std::move(door));
  }
}

void TwinWorld::Impl::UpdateActuators() {
  const std::vector<Eigen::Vector3d> hand_points = {fingertip, palm.translation()};
  for (std::size_t i = 0; i < doors.size(); ++i) {
    Door& d = doors[i];
    const std::string* triggered = nullptr;  // the actuator that opened the door this step
    for (std::size_t k = 0; k < d.buttons.size(); ++k) {
      const auto result = d.buttons[k].Update(fingertip);
      if (result == PushButton::Result::kPressed) {
        triggered = &d.spec->actuators[k];
      } else if (result == PushButton::Result::kOverForce) {
        AddEvent("button_overforce", d.fixed->desc->name, StrCat(d.buttons[k].force(), " N"));
      }
    }
    for (std::size_t k = 0; k < d.plates.size(); ++k) {
      if (d.plates[k].Update(hand_points)) triggered = &d.spec->actuators[k];
    }
    if (d.spec && d.next_open_at < d.spec->open_at.size() &&
        time >= d.spec->open_at[d.next_open_at]) {
      ++d.next_open_at;
      if (DoorRefusesAt(d, time)) {
        AddEvent("fault_refused_press", d.fixed->desc->name, "scheduled");
      } else {
        AddEvent("door_triggered", d.fixed->desc->name, "scheduled");
        d.op->Trigger(time);
      }
    }
    if (triggered != nullptr && DoorRefusesAt(d, time)) {
      AddEvent("fault_refused_press", d.fixed->desc->name, *triggered);
      triggered = nullptr;
    }
    if (triggered != nullptr) {
      ++d.presses;
      AddEvent("button_pressed", d.fixed->desc->name, *triggered);
      d.op->Trigger(time);
    }
  }
}

double TwinWorld::Impl::MeasureDoorAngle(const Door& d) const {
  const Eigen::Matrix3d R =
      FromBt(d.leaf->getWorldTransform()).rotation() * d.fixed->desc->X_WL.rotation().transpose();
  const double about_axis =
      std::atan2(R(1, 0), R(0, 0)) * (d.fixed->desc->axis_W.z() > 0 ? 1.0 : -1.0);
  return std::max(0.0, d.fixed->desc->open_sign * about_axis);
}

bool TwinWorld::Impl::LeafSwingsIntoSomeone(const Door& d) const {
  const Eigen::Vector2d hinge = d.fixed->desc->p_WH.head<2>();
  const Eigen::Vector2d edge = FreeEdge(d);
  const double omega_z = d.leaf->getAngularVelocity().z();  // about W's z [rad/s]
  if (std::abs(omega_z) < 1e-9) return false;
  for (const auto& p : people) {
    if (p.state.out) continue;
    const Eigen::Vector2d q = egress::ClosestPointOnSegment(p.walker.position, hinge, edge);
    const Eigen::Vector2d from_leaf = p.walker.position - q;
    if (from_leaf.norm() > p.walker.radius + kLeafTouchMarginM) continue;
    // The leaf's point q moves at omega x (q - hinge): into the person, or away.
    const Eigen::Vector2d r = q - hinge;
    const Eigen::Vector2d v_q = omega_z * Eigen::Vector2d(-r.y(), r.x());
    if (v_q.dot(from_leaf) > 0.0) return true;
  }
  return false;
}

void TwinWorld::Impl::UpdateDoors() {
  for (std::size_t i = 0; i < doors.size(); ++i) {
    Door& d = doors[i];
    d.angle = MeasureDoorAngle(d);
    const double stall_impulse = (d.spec ? d.spec->timing.stall_force : 67.0) * d.fixed->reach * dt;
    if (d.op) {
      const double rate = d.op->Update(time, d.angle);
      d.hinge->enableAngularMotor(true, d.motor_sign * rate, stall_impulse);
      if (d.op->phase() != d.last_phase) {
        AddEvent(StrCat("door_", ToString(d.op->phase())), d.fixed->desc->name);
        d.last_phase = d.op->phase();
      }
    } else {
      // A manual door with a closer: gently back to closed (≥ 5 s from 90° to 12°).
      const double closer_rate = d.angle > AdaDoorOperator::kClosedAngle ? -0.25 : 0.0;
      d.hinge->enableAngularMotor(true, d.motor_sign * closer_rate, 15.0 * d.fixed->reach * dt);
    }
    const btVector3 axis = ToBt(d.fixed->desc->axis_W * d.fixed->desc->open_sign);
    if (LeafSwingsIntoSomeone(d)) {
      // People are not in the leaves' collisions (kMaskDoor): the social forces keep them off a
      // leaf, and a crowd leaning on an open leaf would otherwise shove it shut. A leaf that
      // swings into someone stops there (they stand their ground; an operator stops on an
      // obstruction).
      d.leaf->setAngularVelocity(btVector3(0, 0, 0));
      d.hinge->enableAngularMotor(true, 0.0, kLeafBrakeTorqueNm * dt);
    }
    const double omega = d.leaf->getAngularVelocity().dot(axis);
    btVector3 torque = -d.fixed->desc->damping * omega * axis;
    // People holding this door push it towards their hold angle.
    for (const auto& p : people) {
      if (p.state.phase != PersonPhase::kHolding || p.door != int(i)) continue;
      const double max_torque = config.person_hold_force * d.fixed->reach;
      const double tau =
          std::clamp(1000.0 * (p.hold_angle - d.angle) - 100.0 * omega, -max_torque, max_torque);
      torque += tau * axis;
    }
    d.leaf->applyTorque(torque);
    const double open_threshold = config.door_crossed_open_angle_deg * kDegToRad;
    if (!d.reported_open && d.angle >= open_threshold) {
      d.reported_open = true;
      d.reported_closed = false;
      AddEvent("door_opened", d.fixed->desc->name);
    } else if (!d.reported_closed && d.angle <= AdaDoorOperator::kClosedAngle) {
      d.reported_closed = true;
      d.reported_open = false;
      AddEvent("door_closed", d.fixed->desc->name);
    }
  }
}

Eigen::Vector2d TwinWorld::Impl::FreeEdge(const Door& d) const {
  const auto k = std::size_t(&d - doors.data());
  if (free_edges.size() != doors.size())
    free_edges.assign(doors.size(),
                      {std::numeric_limits<double>::quiet_NaN(), Eigen::Vector2d::Zero()});
  auto& [angle, edge] = free_edges[k];
  if (!(angle == d.angle)) {
    edge = d.fixed->desc->CalcFreeEdge(d.angle).head<2>();
    angle = d.angle;
  }
  return edge;
}

}  // namespace egress::twin
