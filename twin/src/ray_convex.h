#pragma once
/// @file
/// ConvexPolytope: a convex shape as the half-spaces n·x <= d that bound it, in the shape's own
/// frame, and where a ray segment crosses its surface (Cyrus–Beck clipping). The twin casts its
/// sensors' rays at the moving bodies (door leaves, people, payloads) this way: the same faces as
/// the triangle proxies Bullet would walk, without a BVH walk per body per ray.

#include <array>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace egress::twin::world_detail {

class ConvexPolytope {
 public:
  /// From a closed triangle surface (consecutive triples of vertices) enclosing the frame's
  /// origin: one half-space per distinct face plane, normals outward. Throws std::invalid_argument
  /// if the surface does not enclose the origin or has a degenerate (zero-area) triangle.
  static ConvexPolytope FromTriangles(const std::vector<Eigen::Vector3d>& vertices);

  /// A point where the segment crosses the surface: t in [0, 1] along it, and the face's unit
  /// normal turned to face the segment's start (as Bullet's triangle ray test reports it).
  struct Crossing {
    double t{0.0};
    Eigen::Vector3d normal{Eigen::Vector3d::Zero()};
  };

  /// The crossings of segment o + t·v, t in [0, 1] (both in this frame), in increasing t: the
  /// entry (where the segment starts outside), then the exit (where it ends outside). Returns
  /// how many of `out` are set (0-2). A segment grazing a face or an edge does not cross.
  int Cross(const Eigen::Vector3d& o, const Eigen::Vector3d& v, std::array<Crossing, 2>* out) const;

  std::size_t num_faces() const { return normals_.size(); }

 private:
  std::vector<Eigen::Vector3d> normals_;  // unit, outward
  std::vector<double> offsets_;           // d of n·x <= d, > 0 (the origin is inside)
};

}  // namespace egress::twin::world_detail
