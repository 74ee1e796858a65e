#include "ray_convex.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace egress::twin::world_detail {

namespace {
constexpr double kSamePlaneTol = 1e-9;  // normals and offsets closer than this are one face
}  // namespace

ConvexPolytope ConvexPolytope::FromTriangles(const std::vector<Eigen::Vector3d>& vertices) {
  ConvexPolytope p;
  for (std::size_t i = 0; i + 2 < vertices.size(); i += 3) {
    const Eigen::Vector3d& a = vertices[i];
    Eigen::Vector3d n = (vertices[i + 1] - a).cross(vertices[i + 2] - a);
    const double area2 = n.norm();
    if (!(area2 > 1e-15)) {
      throw std::invalid_argument("ConvexPolytope: triangle " + std::to_string(i / 3) +
                                  " has no area");
    }
    n /= area2;
    double d = n.dot(a);
    if (d < 0.0) {  // wound the other way: turn the normal away from the origin
      n = -n;
      d = -d;
    }
    if (!(d > 0.0)) {
      throw std::invalid_argument("ConvexPolytope: the plane of triangle " + std::to_string(i / 3) +
                                  " passes through the origin");
    }
    bool known = false;
    for (std::size_t k = 0; k < p.normals_.size() && !known; ++k) {
      known =
          (p.normals_[k] - n).norm() < kSamePlaneTol && std::abs(p.offsets_[k] - d) < kSamePlaneTol;
    }
    if (!known) {
      p.normals_.push_back(n);
      p.offsets_.push_back(d);
    }
  }
  return p;
}

int ConvexPolytope::Cross(const Eigen::Vector3d& o, const Eigen::Vector3d& v,
                          std::array<Crossing, 2>* out) const {
  double t_in = -std::numeric_limits<double>::infinity();
  double t_out = std::numeric_limits<double>::infinity();
  int face_in = -1, face_out = -1;
  for (std::size_t k = 0; k < normals_.size(); ++k) {
    const double along = normals_[k].dot(v);
    const double gap = offsets_[k] - normals_[k].dot(o);  // > 0: o is inside this face
    if (along == 0.0) {
      if (gap <= 0.0) return 0;  // parallel to the face, outside (or on) it
      continue;
    }
    const double t = gap / along;
    if (along < 0.0) {
      if (t > t_in) {
        t_in = t;
        face_in = int(k);
      }
    } else if (t < t_out) {
      t_out = t;
      face_out = int(k);
    }
    if (t_in >= t_out) return 0;
  }
  int n = 0;
  if (face_in >= 0 && t_in > 0.0 && t_in < 1.0) {
    (*out)[std::size_t(n++)] = {t_in, normals_[std::size_t(face_in)]};
  }
  if (face_out >= 0 && t_out > 0.0 && t_out < 1.0) {
    (*out)[std::size_t(n++)] = {t_out, -normals_[std::size_t(face_out)]};
  }
  return n;
}

}  // namespace egress::twin::world_detail
