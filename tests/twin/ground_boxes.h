#pragma once
// Shared helpers of the ray bin tests (ray_bins_test.cpp, ray_fan_test.cpp): XY boxes on the
// ground and where a segment's ground track meets them, exhaustively.

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/Core>

namespace egress::twin::world_detail {

using Box = std::pair<Eigen::Vector2d, Eigen::Vector2d>;

// Where the segment a-b first touches the box, in t on a-b; infinity where it does not.
inline double EntryAlong(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Box& box) {
  double t0 = 0.0, t1 = 1.0;
  const Eigen::Vector2d d = b - a;
  for (int i = 0; i < 2; ++i) {
    if (std::abs(d[i]) < 1e-15) {
      if (a[i] < box.first[i] || a[i] > box.second[i]) return INFINITY;
      continue;
    }
    double ta = (box.first[i] - a[i]) / d[i], tb = (box.second[i] - a[i]) / d[i];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return INFINITY;
  }
  return t0;
}

// Whether the segment a-b touches the box (closed intervals).
inline bool SegmentTouchesBox(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Box& box) {
  return std::isfinite(EntryAlong(a, b, box));
}

}  // namespace egress::twin::world_detail
