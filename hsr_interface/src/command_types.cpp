#include "egress/hsr_interface/command_types.h"

#include <set>

#include "check.h"

namespace egress {

using internal::CheckFinite;

void JointTrajectory::Validate() const {
  ThrowUnless(!joint_names.empty(), "Invalid JointTrajectory: joint_names must not be empty.");
  std::set<std::string_view> seen;
  for (const auto& name : joint_names) {
    ThrowUnless(!name.empty(), "Invalid JointTrajectory: a joint name is empty.");
    ThrowUnless(seen.insert(name).second, "Invalid JointTrajectory: joint '", name,
                "' appears twice.");
  }
  ThrowUnless(!points.empty(), "Invalid JointTrajectory: points must not be empty.");
  const std::size_t n = joint_names.size();
  for (std::size_t k = 0; k < points.size(); ++k) {
    const auto& point = points[k];
    ThrowUnless(point.positions.size() == n, "Invalid JointTrajectory: points[", k, "] has ",
                point.positions.size(), " positions for ", n, " joints.");
    ThrowUnless(point.velocities.empty() || point.velocities.size() == n,
                "Invalid JointTrajectory: points[", k, "] has ", point.velocities.size(),
                " velocities for ", n, " joints.");
    ThrowUnless(point.accelerations.empty() || point.accelerations.size() == n,
                "Invalid JointTrajectory: points[", k, "] has ", point.accelerations.size(),
                " accelerations for ", n, " joints.");
    for (std::size_t j = 0; j < n; ++j) {
      const auto field = [&](const char* what) {
        return StrCat("points[", k, "].", what, " of '", joint_names[j], "'");
      };
      CheckFinite(point.positions[j], "JointTrajectory", field("position"));
      if (!point.velocities.empty()) {
        CheckFinite(point.velocities[j], "JointTrajectory", field("velocity"));
      }
      if (!point.accelerations.empty()) {
        CheckFinite(point.accelerations[j], "JointTrajectory", field("acceleration"));
      }
    }
    ThrowUnless(point.time_from_start.count() >= 0, "Invalid JointTrajectory: points[", k,
                "].time_from_start must be >= 0.");
    if (k > 0) {
      ThrowUnless(point.time_from_start > points[k - 1].time_from_start,
                  "Invalid JointTrajectory: points[", k,
                  "].time_from_start must be later than points[", k - 1, "]'s.");
    }
  }
}

void HeadCommand::Validate() const {
  CheckFinite(pan, "HeadCommand", "pan");
  CheckFinite(tilt, "HeadCommand", "tilt");
}

void GripperCommand::Validate() const {
  CheckFinite(position, "GripperCommand", "position");
  CheckFinite(effort, "GripperCommand", "effort");
  ThrowUnless(effort >= 0.0, "Invalid GripperCommand: effort (", effort, ") must be >= 0.");
}

}  // namespace egress
