#include "egress/hsr_interface/robot_state_types.h"

#include <cmath>
#include <set>

#include <Eigen/Eigenvalues>

#include "check.h"

namespace egress {

using internal::CheckFinite;

std::optional<double> JointState::Position(std::string_view name) const {
  for (std::size_t i = 0; i < names.size() && i < positions.size(); ++i) {
    if (names[i] == name) return positions[i];
  }
  return std::nullopt;
}

void JointState::Validate() const {
  ThrowUnless(positions.size() == names.size(), "Invalid JointState: ", positions.size(),
              " positions for ", names.size(), " names.");
  ThrowUnless(velocities.empty() || velocities.size() == names.size(),
              "Invalid JointState: ", velocities.size(), " velocities for ", names.size(),
              " names (must be empty or equal).");
  ThrowUnless(efforts.empty() || efforts.size() == names.size(),
              "Invalid JointState: ", efforts.size(), " efforts for ", names.size(),
              " names (must be empty or equal).");
  std::set<std::string_view> seen;
  for (std::size_t i = 0; i < names.size(); ++i) {
    ThrowUnless(!names[i].empty(), "Invalid JointState: names[", i, "] is empty.");
    ThrowUnless(seen.insert(names[i]).second, "Invalid JointState: joint '", names[i],
                "' appears twice.");
    CheckFinite(positions[i], "JointState", StrCat("position of '", names[i], "'"));
    if (!velocities.empty()) {
      CheckFinite(velocities[i], "JointState", StrCat("velocity of '", names[i], "'"));
    }
    if (!efforts.empty()) {
      CheckFinite(efforts[i], "JointState", StrCat("effort of '", names[i], "'"));
    }
  }
}

void Odometry::Validate() const {
  ThrowUnless(X_OB.IsFinite(), "Invalid Odometry: X_OB (", X_OB.x, ", ", X_OB.y, ", ", X_OB.yaw,
              ") must be finite.");
  ThrowUnless(V_B.IsFinite(), "Invalid Odometry: V_B (", V_B.vx, ", ", V_B.vy, ", ", V_B.wz,
              ") must be finite.");
  ThrowUnless(covariance.allFinite(), "Invalid Odometry: covariance must be finite.");
  ThrowUnless((covariance - covariance.transpose()).cwiseAbs().maxCoeff() < 1e-9,
              "Invalid Odometry: covariance must be symmetric.");
  const double min_eigenvalue =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance).eigenvalues().minCoeff();
  ThrowUnless(min_eigenvalue > -1e-12, "Invalid Odometry: covariance must be positive ",
              "semi-definite (smallest eigenvalue ", min_eigenvalue, ").");
}

void GripperState::Validate() const {
  CheckFinite(hand_motor_position, "GripperState", "hand_motor_position");
  CheckFinite(effort, "GripperState", "effort");
  ThrowUnless(effort >= 0.0, "Invalid GripperState: effort (", effort, ") must be >= 0.");
}

}  // namespace egress
