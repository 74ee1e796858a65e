#pragma once
/// @file
/// The two ADA actuator types, as contact logic independent of physics. A push button counts a
/// press when the fingertip travels the button's stroke with a force below the limit (a spring
/// cap that bottoms out: a jab that drives past the bottom in one step reads as over-force and
/// is refused). A proximity plate triggers when a hand point comes within its sensing range in
/// front of it (a plate on a wall does not sense a hand on the wall's other side).

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "egress/hsr_interface/geometry.h"

namespace egress::twin {

/// The box of a button or plate in W; its thinnest axis is the press direction.
struct ActuatorBox {
  Pose3 X_WA;            ///< Box centre frame A in W.
  Eigen::Vector3d size;  ///< Full extents [m].
  /// Index (0..2) of the thinnest axis of A.
  int PressAxis() const;
  /// Press direction's unit normal in W (along A's thinnest axis, sign arbitrary).
  Eigen::Vector3d NormalW() const;
};

class PushButton {
 public:
  enum class Result { kNone, kPressed, kOverForce };
  /// stroke [m] counts as a press; spring_force [N] at full stroke; max_force [N] refuses.
  PushButton(ActuatorBox box, double stroke, double spring_force, double max_force);

  /// Feeds the fingertip position in W for this step; reports a new press or refusal.
  Result Update(const Eigen::Vector3d& p_WF);

  double travel() const { return travel_; }  ///< Current cap travel [m].
  double force() const { return force_; }    ///< Current contact force [N].
  const ActuatorBox& box() const { return box_; }
  /// Travel at which the cap bottoms out [m].
  double bottom_travel() const { return 1.5 * stroke_; }

 private:
  double CalcForce(double travel) const;
  ActuatorBox box_;
  double stroke_, spring_force_, max_force_;
  int side_{0};  ///< Side of the face the fingertip approached from (+1/−1), 0 = unknown.
  double travel_{0.0};
  double force_{0.0};
  bool latched_{false};
};

class ProximityPlate {
 public:
  /// range [m]: hand-to-face distance that triggers. n_W: the outward normal of its face (unit,
  /// away from the wall it is mounted on); without it the plate senses all round.
  ProximityPlate(ActuatorBox box, double range, std::optional<Eigen::Vector3d> n_W = std::nullopt);
  /// Feeds hand points in W for this step; true on a new trigger (re-arms once all points are
  /// beyond 1.5 × range).
  bool Update(const std::vector<Eigen::Vector3d>& hand_points_W);
  /// Distance from a point to the plate's box [m] (0 inside); infinity behind the plate (past
  /// its back face, against its outward normal), where its wall hides the point.
  double DistanceTo(const Eigen::Vector3d& p_W) const;
  const ActuatorBox& box() const { return box_; }

 private:
  ActuatorBox box_;
  double range_;
  std::optional<Eigen::Vector3d> n_W_;
  bool armed_{true};
};

}  // namespace egress::twin
