#include "scenario_faults.h"

#include <cmath>
#include <set>
#include <string>

namespace egress::twin {
namespace {

using Kind = FaultSpec::Kind;
constexpr Kind kKinds[] = {Kind::kLaserDropout, Kind::kCameraBlackout, Kind::kDetectorLatency,
                           Kind::kOdometrySlip, Kind::kKidnap,         Kind::kDoorClosesEarly,
                           Kind::kDoorRefuses,  Kind::kGraspSlip};
constexpr double kMaxFaultTimeS = 86400.0;
constexpr double kMaxKidnapM = 5.0;

}  // namespace

bool FaultSpec::Instantaneous() const {
  return kind == Kind::kKidnap || kind == Kind::kDoorClosesEarly || kind == Kind::kGraspSlip;
}

std::string_view ToString(FaultSpec::Kind kind) {
  switch (kind) {
    case Kind::kLaserDropout:
      return "laser_dropout";
    case Kind::kCameraBlackout:
      return "camera_blackout";
    case Kind::kDetectorLatency:
      return "detector_latency";
    case Kind::kOdometrySlip:
      return "odometry_slip";
    case Kind::kKidnap:
      return "kidnap";
    case Kind::kDoorClosesEarly:
      return "door_closes_early";
    case Kind::kDoorRefuses:
      return "door_refuses";
    case Kind::kGraspSlip:
      return "grasp_slip";
  }
  return "unknown";
}

std::vector<FaultSpec> ParseFaults(const FieldReader& r, const YAML::Node& node) {
  if (!node.IsSequence()) r.Fail(node, "faults", "expected a list of faults");
  std::vector<FaultSpec> out;
  for (std::size_t i = 0; i < node.size(); ++i) {
    const YAML::Node n = node[i];
    const std::string f = "faults[" + std::to_string(i) + "]";
    r.CheckKeys(n, f, {"kind", "start", "duration", "latency", "odometry_scale", "offset", "door"});
    FaultSpec fault;
    fault.line = n.Mark().line + 1;
    const std::string kind = r.String(r.Required(n, f, "kind"), f + ".kind");
    bool known = false;
    std::string names;
    for (Kind k : kKinds) {
      names += (names.empty() ? "" : ", ") + std::string(ToString(k));
      if (ToString(k) == kind) {
        fault.kind = k;
        known = true;
      }
    }
    if (!known)
      r.Fail(n["kind"], f + ".kind", "unknown fault '" + kind + "' (one of: " + names + ")");
    fault.start = r.ReadRange(r.Required(n, f, "start"), f + ".start");
    if (fault.start.min < 0 || fault.start.max > kMaxFaultTimeS)
      r.Fail(n["start"], f + ".start", "must lie in [0, 86400] s");
    const std::set<std::string> allowed = [&]() -> std::set<std::string> {
      switch (fault.kind) {
        case Kind::kDetectorLatency:
          return {"duration", "latency"};
        case Kind::kOdometrySlip:
          return {"duration", "odometry_scale"};
        case Kind::kKidnap:
          return {"offset"};
        case Kind::kDoorClosesEarly:
          return {"door"};
        case Kind::kDoorRefuses:
          return {"duration", "door"};
        case Kind::kGraspSlip:
          return {};
        default:
          return {"duration"};
      }
    }();
    for (const char* key : {"duration", "latency", "odometry_scale", "offset", "door"}) {
      if (n[key] && !allowed.count(key))
        r.Fail(n[key], f + "." + key, "does not apply to a " + kind + " fault");
      if (!n[key] && allowed.count(key) && std::string(key) != "latency" &&
          std::string(key) != "odometry_scale") {
        r.Required(n, f, key);  // names the missing field
      }
    }
    if (n["duration"]) {
      fault.duration = r.ReadRange(n["duration"], f + ".duration");
      if (fault.duration.min <= 0 || fault.duration.max > kMaxFaultTimeS)
        r.Fail(n["duration"], f + ".duration", "must lie in (0, 86400] s");
    }
    if (n["latency"]) {
      fault.latency_s = r.Positive(n["latency"], f + ".latency");
      if (fault.latency_s > 60) r.Fail(n["latency"], f + ".latency", "must be at most 60 s");
    }
    if (n["odometry_scale"]) {
      fault.odometry_scale = r.NonNegative(n["odometry_scale"], f + ".odometry_scale");
      if (fault.odometry_scale > 10)
        r.Fail(n["odometry_scale"], f + ".odometry_scale", "must be at most 10");
    }
    if (n["offset"]) {
      fault.offset = r.ReadPose2(n["offset"], f + ".offset");
      if (std::hypot(fault.offset.x, fault.offset.y) > kMaxKidnapM)
        r.Fail(n["offset"], f + ".offset", "a kidnap moves the robot at most 5 m");
    }
    if (n["door"]) fault.door = r.String(n["door"], f + ".door");
    out.push_back(fault);
  }
  return out;
}

}  // namespace egress::twin
