// The scenario's injected faults in a run (FaultSpec): drawn per seed, the instantaneous ones
// fired here at their time; the window faults are read where they act (sensors in
// twin_robot.cpp, refused presses in twin_doors.cpp).

#include <cmath>
#include <random>

#include "egress/hsr_interface/error.h"
#include "scenario_poses.h"
#include "seeds.h"
#include "twin_world_impl.h"

namespace egress::twin {
namespace {
constexpr std::uint64_t kFaultStream = 7;
constexpr int kFootprintSamples = 8;  // points on the footprint's circle a kidnap must keep free
constexpr double kKidnapPathStepM = 0.02;  // below any wall's thickness
}  // namespace

void TwinWorld::Impl::DrawFaults() {
  std::mt19937_64 rng(DeriveSeed(seed, kFaultStream));
  for (const FaultSpec& spec : scenario.faults) {
    TwinWorld::DrawnFault f;
    f.spec = &spec;
    f.start = spec.start.Sample(rng);
    f.end = spec.Instantaneous() ? f.start : f.start + spec.duration.Sample(rng);
    if (!spec.door.empty()) {
      bool operated = false;
      for (const Door& d : doors)
        operated |= d.fixed->desc->name == spec.door && d.op.has_value();
      if (!operated) {
        throw LoadError(StrCat(scenario.source.string(), ":", spec.line, ": field 'faults': door '",
                               spec.door, "' has no operator to fail"));
      }
    }
    faults.push_back(f);
  }
}

bool TwinWorld::Impl::DoorRefusesAt(const Door& d, double t) const {
  for (const auto& f : faults) {
    if (f.spec->kind == FaultSpec::Kind::kDoorRefuses && f.spec->door == d.fixed->desc->name &&
        t >= f.start && t < f.end)
      return true;
  }
  return false;
}

void TwinWorld::Impl::ApplyFaults() {
  for (auto& f : faults) {
    if (f.fired || !f.spec->Instantaneous() || time < f.start) continue;
    f.fired = true;
    const std::string kind(ToString(f.spec->kind));
    switch (f.spec->kind) {
      case FaultSpec::Kind::kKidnap: {
        const Pose2 X_WB = RobotPose();
        const Pose2 target{X_WB.x + f.spec->offset.x, X_WB.y + f.spec->offset.y,
                           X_WB.yaw + f.spec->offset.yaw};
        // Only onto free floor reached without passing a wall (a kidnap fools localization; it
        // does not walk through walls): not into a model, a wall or a person.
        bool free = true;
        try {
          const double length = std::hypot(f.spec->offset.x, f.spec->offset.y);
          const int steps = int(std::ceil(length / kKidnapPathStepM));
          for (int k = 1; k <= steps; ++k) {
            const double u = double(k) / steps;
            CheckOnTheFloor(world, "kidnap", "offset", "",
                            {X_WB.x + u * f.spec->offset.x, X_WB.y + u * f.spec->offset.y, 0.0});
          }
          CheckOnTheFloor(world, "kidnap", "offset", "", target);
          for (int k = 0; k < kFootprintSamples; ++k) {
            const double a = 2.0 * M_PI * k / kFootprintSamples;
            CheckOnTheFloor(world, "kidnap", "offset", "",
                            {target.x + robot_radius * std::cos(a),
                             target.y + robot_radius * std::sin(a), target.yaw});
          }
        } catch (const LoadError&) {
          free = false;
        }
        for (const auto& p : people) {
          if (!p.state.out && (p.walker.position - Eigen::Vector2d(target.x, target.y)).norm() <
                                  robot_radius + p.walker.radius + 0.1)
            free = false;
        }
        if (!free) {
          AddEvent("fault_skipped", kind, "the spot is not free");
          break;
        }
        btTransform T = base->getWorldTransform();
        T.setOrigin(btVector3(target.x, target.y, T.getOrigin().z()));
        T.setRotation(btQuaternion(btVector3(0, 0, 1), target.yaw));
        base->setWorldTransform(T);
        base->setInterpolationWorldTransform(T);
        if (base->getMotionState() != nullptr) base->getMotionState()->setWorldTransform(T);
        AddEvent("fault", kind,
                 StrCat("moved by (", f.spec->offset.x, ", ", f.spec->offset.y, ", ",
                        f.spec->offset.yaw, ")"));
        break;
      }
      case FaultSpec::Kind::kDoorClosesEarly:
        for (Door& d : doors) {
          if (d.fixed->desc->name == f.spec->door && d.op) d.op->CloseNow();
        }
        AddEvent("fault", kind, f.spec->door);
        break;
      case FaultSpec::Kind::kGraspSlip:
        if (held >= 0) {
          AddEvent("fault", kind, payloads[std::size_t(held)].spec.name);
          Release();
        } else {
          AddEvent("fault_skipped", kind, "nothing held");
        }
        break;
      default:
        break;
    }
  }
}

const std::vector<TwinWorld::DrawnFault>& TwinWorld::faults() const {
  return impl_->faults;
}

const FaultSpec* TwinWorld::ActiveFault(FaultSpec::Kind kind, double t) const {
  for (const auto& f : impl_->faults) {
    if (f.spec->kind == kind && !f.spec->Instantaneous() && t >= f.start && t < f.end)
      return f.spec;
  }
  return nullptr;
}

}  // namespace egress::twin
