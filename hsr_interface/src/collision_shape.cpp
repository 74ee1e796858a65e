// CollisionShape's geometry (declared with the robot model whose links carry the shapes).
#include <cmath>

#include "egress/hsr_interface/robot_model.h"

namespace egress {

double CollisionShape::BoundingRadius() const {
  switch (kind) {
    case Kind::kBox:
      return size.norm() / 2;
    case Kind::kCylinder:
      return std::hypot(size.x(), size.z() / 2);
    case Kind::kSphere:
      return size.x();
  }
  return 0.0;
}

bool CollisionShape::Contains(const Eigen::Vector3d& p_SQ, double margin) const {
  switch (kind) {
    case Kind::kBox:
      return (p_SQ.cwiseAbs() - size / 2).maxCoeff() <= margin;
    case Kind::kCylinder:
      return p_SQ.head<2>().norm() <= size.x() + margin &&
             std::abs(p_SQ.z()) <= size.z() / 2 + margin;
    case Kind::kSphere:
      return p_SQ.norm() <= size.x() + margin;
  }
  return false;
}

}  // namespace egress
