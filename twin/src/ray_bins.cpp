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
  if (nx_ > 0 && a.allFinite() && b.allFinite()) {
    const Eigen::Vector2d lo = origin_, hi = origin_ + cell_ * Eigen::Vector2d(nx_, ny_);
    const auto add_cells = [&](const Eigen::Vector2d& l, const Eigen::Vector2d& h) {
      if (h.x() < lo.x() || h.y() < lo.y() || l.x() > hi.x() || l.y() > hi.y()) return;
      const long x0 = CellX(l.x()), x1 = CellX(h.x()), y1 = CellY(h.y());
      for (long y = CellY(l.y()); y <= y1; ++y)
        for (long x = x0; x <= x1; ++x) {
          const auto& bin = bins_[std::size_t(y * nx_ + x)];
          out->insert(out->end(), bin.begin(), bin.end());
        }
    };
    const Eigen::Vector2d l = a.cwiseMin(b), h = a.cwiseMax(b);
    if ((h - l).maxCoeff() <= 3.0 * cell_) {
      add_cells(l, h);  // a short segment: its bounding box is at most 4 x 4 cells
    } else {
      // A long one in pieces no longer than a cell: each piece's bounding box covers at most
      // 2 x 2 cells, and together they cover every cell the segment touches.
      const int pieces = 1 + int(std::min(1e6, std::ceil((b - a).norm() / cell_)));
      Eigen::Vector2d p0 = a;
      for (int k = 1; k <= pieces; ++k) {
        const Eigen::Vector2d p1 =
            k == pieces ? b : Eigen::Vector2d(a + (b - a) * (double(k) / pieces));
        add_cells(p0.cwiseMin(p1), p0.cwiseMax(p1));
        p0 = p1;
      }
    }
  }
  std::sort(out->begin(), out->end());
  out->erase(std::unique(out->begin(), out->end()), out->end());
}

}  // namespace egress::twin::world_detail
