#include "egress/twin/world_description.h"

#include <cmath>

#include <Eigen/Geometry>

namespace egress::twin {
namespace {

Eigen::Vector3d HorizontalDirection(const Eigen::Vector3d& v) {
  Eigen::Vector3d d(v.x(), v.y(), 0.0);
  return d.norm() > 1e-9 ? Eigen::Vector3d(d.normalized()) : Eigen::Vector3d::UnitX();
}

}  // namespace

void ShapeDescription::CalcWorldBounds(Eigen::Vector3d* lower, Eigen::Vector3d* upper) const {
  Eigen::Vector3d half = Eigen::Vector3d::Zero();
  switch (kind) {
    case ShapeKind::kBox:
      half = box_size / 2;
      break;
    case ShapeKind::kCylinder:
      half = {radius, radius, length / 2};
      break;
    case ShapeKind::kSphere:
      half = Eigen::Vector3d::Constant(radius);
      break;
    case ShapeKind::kPlane:
      half = {plane_size.x() / 2, plane_size.y() / 2, 0.0};
      break;
    case ShapeKind::kMesh: {
      *lower = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
      *upper = -*lower;
      for (const auto& v : mesh->vertices) {
        const Eigen::Vector3d p = X_WS * v;
        *lower = lower->cwiseMin(p);
        *upper = upper->cwiseMax(p);
      }
      return;
    }
  }
  // Half extents of the rotated box: |R| * half.
  const Eigen::Vector3d extent = X_WS.rotation().cwiseAbs() * half;
  *lower = X_WS.translation() - extent;
  *upper = X_WS.translation() + extent;
}

double DoorDescription::LeafReach() const {
  const Eigen::Vector3d to_centre = X_WL.translation() - p_WH;
  const Eigen::Vector3d dir = HorizontalDirection(to_centre);
  // Half the leaf's extent along the hinge-to-centre direction.
  const Eigen::Vector3d half_extent = X_WL.rotation().cwiseAbs() * (leaf_size / 2);
  return dir.dot(to_centre) + std::abs(dir.x()) * half_extent.x() +
         std::abs(dir.y()) * half_extent.y();
}

Pose3 DoorDescription::CalcLeafPose(double angle) const {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(open_sign * angle, axis_W).toRotationMatrix();
  return Pose3::FromTrustedParts(R * X_WL.rotation(), p_WH + R * (X_WL.translation() - p_WH));
}

Eigen::Vector3d DoorDescription::CalcFreeEdge(double angle) const {
  const Pose3 X_WL_now = CalcLeafPose(angle);
  const Eigen::Vector3d dir = HorizontalDirection(X_WL_now.translation() - p_WH);
  return Eigen::Vector3d(p_WH.x(), p_WH.y(), X_WL_now.translation().z()) + dir * LeafReach();
}

std::optional<FloorFootprint> CalcFloorFootprint(const ShapeDescription& s, double z_min,
                                                 double z_max) {
  if (s.kind == ShapeKind::kPlane) return std::nullopt;
  Eigen::Vector3d lo, hi;
  s.CalcWorldBounds(&lo, &hi);
  if (hi.z() < z_min || lo.z() > z_max) return std::nullopt;
  FloorFootprint f;
  f.model = s.model;
  const bool upright = std::abs(s.X_WS.rotation()(2, 2)) > 0.999;
  if (upright && (s.kind == ShapeKind::kBox || s.kind == ShapeKind::kCylinder)) {
    const Eigen::Vector3d x_axis = s.X_WS.rotation().col(0);
    f.X_WF = {s.X_WS.translation().x(), s.X_WS.translation().y(),
              std::atan2(x_axis.y(), x_axis.x())};
    f.size = s.kind == ShapeKind::kBox ? Eigen::Vector2d(s.box_size.head<2>())
                                       : Eigen::Vector2d::Constant(2 * s.radius);
  } else {
    f.X_WF = {(lo.x() + hi.x()) / 2, (lo.y() + hi.y()) / 2, 0.0};
    f.size = (hi - lo).head<2>();
  }
  return f;
}

std::vector<FloorFootprint> CalcFloorFootprints(const WorldDescription& world, double z_min,
                                                double z_max) {
  std::vector<FloorFootprint> out;
  for (const auto& s : world.shapes) {
    if (auto f = CalcFloorFootprint(s, z_min, z_max)) out.push_back(std::move(*f));
  }
  return out;
}

std::vector<const ShapeDescription*> WorldDescription::ShapesOfModel(
    const std::string& model) const {
  std::vector<const ShapeDescription*> out;
  for (const auto& s : shapes) {
    if (s.model == model) out.push_back(&s);
  }
  return out;
}

const DoorDescription* WorldDescription::FindDoor(const std::string& model) const {
  for (const auto& d : doors) {
    if (d.name == model) return &d;
  }
  return nullptr;
}

}  // namespace egress::twin
