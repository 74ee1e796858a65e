#include "ray_bins.h"

#include <algorithm>
#include <cmath>

namespace egress::twin::world_detail {

long RayBins::CellX(double x) const {
  return std::clamp(long(std::floor((x - origin_.x()) / cell_)), 0L, nx_ - 1);
}
long RayBins::CellY(double y) const {
  return std::clamp(long(std::floor((y - origin_.y()) / cell_)), 0L, ny_ - 1);
}

void RayBins::Build(const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& boxes,
                    double cell) {
  cell_ = cell;
  everywhere_.clear();
  bins_.clear();
  nx_ = ny_ = 0;
  std::vector<int> binned;
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(INFINITY), hi = -lo;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const auto& [a, b] = boxes[i];
    const Eigen::Vector2d size = (b - a) / cell;
    if (!a.allFinite() || !b.allFinite() || size.x() * size.y() > double(kMaxCellsPerBox) ||
        size.maxCoeff() > double(kMaxCellsPerBox)) {
      everywhere_.push_back(int(i));
      continue;
    }
    binned.push_back(int(i));
    lo = lo.cwiseMin(a);
    hi = hi.cwiseMax(b);
  }
  if (binned.empty()) return;
  origin_ = lo;
  nx_ = long(std::floor((hi.x() - lo.x()) / cell)) + 1;
  ny_ = long(std::floor((hi.y() - lo.y()) / cell)) + 1;
  bins_.resize(std::size_t(nx_ * ny_));
  for (int i : binned) {
    const auto& [a, b] = boxes[std::size_t(i)];
    for (long y = CellY(a.y()); y <= CellY(b.y()); ++y)
      for (long x = CellX(a.x()); x <= CellX(b.x()); ++x)
        bins_[std::size_t(y * nx_ + x)].push_back(i);
  }
}

void RayBins::Query(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                    std::vector<int>* out) const {
  out->assign(everywhere_.begin(), everywhere_.end());
  if (nx_ > 0 && a.allFinite() && b.allFinite()) WalkCells(a, b, out);
  std::sort(out->begin(), out->end());
  out->erase(std::unique(out->begin(), out->end()), out->end());
}

void RayBins::WalkCells(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                        std::vector<int>* out) const {
  // The segment clipped to the grid's (closed) extent.
  const Eigen::Vector2d lo = origin_, hi = origin_ + cell_ * Eigen::Vector2d(nx_, ny_);
  const Eigen::Vector2d d = b - a;
  double t0 = 0.0, t1 = 1.0;
  for (int i = 0; i < 2; ++i) {
    if (d[i] == 0.0) {
      if (a[i] < lo[i] || a[i] > hi[i]) return;
      continue;
    }
    double ta = (lo[i] - a[i]) / d[i], tb = (hi[i] - a[i]) / d[i];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return;
  }
  const Eigen::Vector2d p = a + t0 * d, q = a + t1 * d, e = q - p;
  const auto add = [&](long x, long y) {
    if (x < 0 || y < 0 || x >= nx_ || y >= ny_) return;
    const auto& bin = bins_[std::size_t(y * nx_ + x)];
    out->insert(out->end(), bin.begin(), bin.end());
  };
  // Amanatides & Woo's grid walk from p's cell to q's, in steps of one cell; t in [0, 1] on
  // p-q. Where the walk passes a corner (both crossings at once, to rounding) the two cells
  // beside it are added too, so that no cell the segment touches is missed.
  long x = CellX(p.x()), y = CellY(p.y());
  const long x_end = CellX(q.x()), y_end = CellY(q.y());
  const long step_x = e.x() > 0 ? 1 : (e.x() < 0 ? -1 : 0);
  const long step_y = e.y() > 0 ? 1 : (e.y() < 0 ? -1 : 0);
  const auto first_crossing = [&](long c, long step, double start, double extent, double origin) {
    if (step == 0) return double(INFINITY);
    return (origin + double(c + (step > 0 ? 1 : 0)) * cell_ - start) / extent;
  };
  double t_x = first_crossing(x, step_x, p.x(), e.x(), origin_.x());
  double t_y = first_crossing(y, step_y, p.y(), e.y(), origin_.y());
  const double dt_x = step_x != 0 ? cell_ / std::abs(e.x()) : INFINITY;
  const double dt_y = step_y != 0 ? cell_ / std::abs(e.y()) : INFINITY;
  constexpr double kCornerTol = 1e-9;  // crossings this close (in t) are one corner
  add(x, y);
  for (long left = std::abs(x_end - x) + std::abs(y_end - y); left > 0; --left) {
    if (std::abs(t_x - t_y) <= kCornerTol) {
      add(x + step_x, y);
      add(x, y + step_y);
      x += step_x;
      y += step_y;
      t_x += dt_x;
      t_y += dt_y;
      --left;  // two cells' worth of the count
    } else if (t_x < t_y) {
      x += step_x;
      t_x += dt_x;
    } else {
      y += step_y;
      t_y += dt_y;
    }
    add(x, y);
    if (x == x_end && y == y_end) break;
  }
  // Rounding may stop the walk a cell short of q's: q's cell always counts.
  if (x != x_end || y != y_end) add(x_end, y_end);
}

}  // namespace egress::twin::world_detail
