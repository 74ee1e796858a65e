#include "egress/twin/actuators.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "egress/hsr_interface/error.h"

namespace egress::twin {
namespace {
// Stiffness of the bottomed-out cap [N/m]: 1 mm past the bottom adds 20 N.
constexpr double kBottomStiffness = 2.0e4;
}  // namespace

int ActuatorBox::PressAxis() const {
  int axis = 0;
  size.minCoeff(&axis);
  return axis;
}

Eigen::Vector3d ActuatorBox::NormalW() const {
  return X_WA.rotation().col(PressAxis());
}

PushButton::PushButton(ActuatorBox box, double stroke, double spring_force, double max_force)
    : box_(std::move(box)), stroke_(stroke), spring_force_(spring_force), max_force_(max_force) {
  ThrowUnless(stroke > 0 && spring_force > 0 && max_force > spring_force,
              "push button: need stroke > 0 and 0 < spring force < max force");
}

double PushButton::CalcForce(double travel) const {
  if (travel <= 0.0) return 0.0;
  const double bottom = bottom_travel();
  if (travel <= bottom) return spring_force_ * travel / stroke_;
  return spring_force_ * bottom / stroke_ + kBottomStiffness * (travel - bottom);
}

PushButton::Result PushButton::Update(const Eigen::Vector3d& p_WF) {
  const Eigen::Vector3d p_AF = box_.X_WA.rotation().transpose() * (p_WF - box_.X_WA.translation());
  const int k = box_.PressAxis();
  const Eigen::Vector3d half = box_.size / 2;
  bool over_face = true;
  for (int i = 0; i < 3; ++i) {
    if (i != k && std::abs(p_AF[i]) > half[i]) over_face = false;
  }
  // Travel: how far past the face on the side the finger came from. A finger that goes on
  // past the cap's centre pushes the cap further in (to the bottom, then into the wall behind);
  // it does not come out of the back: travel counts from that one face, not the nearer one.
  // Off the face (beside or above the cap, or anywhere else in the building) the finger is on
  // whichever side it is: a side kept from the robot's start behind the button's plane made
  // its first press from the front a 1.6 kN over-force (the clinic's door_e_button_north,
  // every press).
  const double s_k = p_AF[k];
  const bool in_front = side_ == 0 ? std::abs(s_k) >= half[k] : side_ * s_k >= half[k];
  if (std::abs(s_k) >= half[k] && (side_ == 0 || in_front || !over_face)) side_ = s_k >= 0 ? 1 : -1;
  if (!over_face || in_front || side_ == 0) {
    // Outside (or never seen outside: started inside the button): the cap is released.
    travel_ = 0.0;
    force_ = 0.0;
    latched_ = false;
    return Result::kNone;
  }
  const double depth = half[k] - side_ * s_k;
  travel_ = depth;
  force_ = CalcForce(depth);
  if (latched_) {
    if (travel_ < stroke_ / 2) latched_ = false;
    return Result::kNone;
  }
  if (travel_ >= stroke_) {
    latched_ = true;
    return force_ <= max_force_ ? Result::kPressed : Result::kOverForce;
  }
  return Result::kNone;
}

ProximityPlate::ProximityPlate(ActuatorBox box, double range, std::optional<Eigen::Vector3d> n_W)
    : box_(std::move(box)), range_(range), n_W_(std::move(n_W)) {
  ThrowUnless(range > 0, "proximity plate: range must be positive");
  ThrowUnless(!n_W_ || std::abs(n_W_->norm() - 1.0) < 1e-6,
              "proximity plate: its face normal must be a unit vector");
}

double ProximityPlate::DistanceTo(const Eigen::Vector3d& p_W) const {
  const Eigen::Vector3d p_AW = p_W - box_.X_WA.translation();
  if (n_W_) {
    // Behind the back face is the wall: its sensing field (capacitive or infrared) is in front.
    const double half = box_.size[box_.PressAxis()] / 2;
    if (n_W_->dot(p_AW) < -half) return std::numeric_limits<double>::infinity();
  }
  const Eigen::Vector3d p_A = box_.X_WA.rotation().transpose() * p_AW;
  const Eigen::Vector3d outside = (p_A.cwiseAbs() - box_.size / 2).cwiseMax(0.0);
  return outside.norm();
}

bool ProximityPlate::Update(const std::vector<Eigen::Vector3d>& hand_points_W) {
  double nearest = std::numeric_limits<double>::infinity();
  for (const auto& p : hand_points_W)
    nearest = std::min(nearest, DistanceTo(p));
  if (armed_ && nearest <= range_) {
    armed_ = false;
    return true;
  }
  if (!armed_ && nearest > 1.5 * range_) armed_ = true;
  return false;
}

}  // namespace egress::twin
