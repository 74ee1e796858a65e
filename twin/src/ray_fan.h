#pragma once
/// @file
/// RayFan: the boxes a fan of rays from one point may cross, binned once by their bearing from
/// that point, for a sensor's sweep (the laser's beams, the depth camera's pixels). A ray takes
/// its bearing's bin nearest first and stops once the next box lies beyond its closest hit so
/// far: the boxes that can matter, without RayBins' grid walk per ray. A superset, never a miss:
/// every box whose XY extent the ray's ground track touches is in the ray's bin.

#include <cstddef>
#include <span>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace egress::twin::world_detail {

class RayFan {
 public:
  /// A box in a bin: its index, and its least ground distance from the fan's origin [m].
  struct Entry {
    double near;
    int box;
  };

  /// The bins of the bearings round the origin (a quarter turn is kBins / 4 of them).
  static constexpr int kBins = 1024;

  /// Bins `boxes` (XY lower and upper corners in W) as seen from `origin` (XY in W), leaving out
  /// those wholly farther than `reach` [m]. A box that holds the origin, or is not finite, is in
  /// every bin (near 0).
  void Build(const Eigen::Vector2d& origin,
             const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& boxes, double reach);

  /// The bin of a ray from the origin along ground direction `d` (XY in W; any, zero included).
  /// The same for every fan: a ray's bin is found once for all the fans it is cast through.
  static long Bin(const Eigen::Vector2d& d);
  /// The boxes a ray in `bin` may cross, `near` ascending (ties by index).
  std::span<const Entry> Along(long bin) const;
  std::span<const Entry> Along(const Eigen::Vector2d& d) const { return Along(Bin(d)); }

  const Eigen::Vector2d& origin() const { return origin_; }

 private:
  Eigen::Vector2d origin_{Eigen::Vector2d::Zero()};
  std::vector<std::size_t> start_;  // kBins + 1: bin b is entries_[start_[b], start_[b + 1])
  std::vector<Entry> entries_;
};

}  // namespace egress::twin::world_detail
