#include "ray_bins.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace egress::twin::world_detail {

void RayBins::Build(const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& boxes,
                    double cell) {
  cell_ = cell;
  per_metre_ = 1.0 / cell;
  box_count_ = boxes.size();
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

namespace {
// Which boxes a walk has yielded already, by walk number: a long walk meets a wall in many
// cells. Per thread, as the bins of a compiled model are shared by the runs of a study's
// threads.
struct Yielded {
  std::vector<std::uint32_t> walk_of;  // per box index: the last walk that yielded it
  std::uint32_t walk{0};
};
thread_local Yielded yielded;
}  // namespace

void RayBins::Query(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                    std::vector<int>* out) const {
  out->clear();
  Walk walk(*this, a, b);
  thread_local std::vector<int> cell;
  double t_beyond = 0.0;
  while (walk.Next(&cell, &t_beyond))
    out->insert(out->end(), cell.begin(), cell.end());
  std::sort(out->begin(), out->end());
}

RayBins::Walk::Walk(const RayBins& bins, const Eigen::Vector2d& a, const Eigen::Vector2d& b)
    : bins_(bins) {
  if (yielded.walk_of.size() < bins.box_count_) yielded.walk_of.resize(bins.box_count_, 0);
  if (++yielded.walk == 0) {  // wrapped: forget every mark
    std::fill(yielded.walk_of.begin(), yielded.walk_of.end(), 0);
    yielded.walk = 1;
  }
  walk_ = yielded.walk;
  gridded_ = bins.nx_ > 0 && a.allFinite() && b.allFinite();
  if (!gridded_) return;
  // The segment clipped to the grid's (closed) extent. Most segments lie inside it: t0 = 0 and
  // t1 = 1 exactly then, and the divisions of the clip (a fifth of a walk's set-up) are skipped.
  const Eigen::Array2d lo = bins.origin_.array(),
                       hi = lo + bins.cell_ * Eigen::Array2d(double(bins.nx_), double(bins.ny_));
  const Eigen::Vector2d d = b - a;
  const bool inside = (a.array() > lo).all() && (a.array() < hi).all() && (b.array() > lo).all() &&
                      (b.array() < hi).all();
  for (int i = 0; i < 2 && gridded_ && !inside; ++i) {
    if (d[i] == 0.0) {
      gridded_ = a[i] >= lo[i] && a[i] <= hi[i];
      continue;
    }
    double ta = (lo[i] - a[i]) / d[i], tb = (hi[i] - a[i]) / d[i];
    if (ta > tb) std::swap(ta, tb);
    t0_ = std::max(t0_, ta);
    t1_ = std::min(t1_, tb);
    gridded_ = t0_ <= t1_;
  }
  if (!gridded_) return;
  const Eigen::Vector2d p = a + t0_ * d, q = a + t1_ * d, e = q - p;
  // Amanatides & Woo's grid walk from p's cell to q's, in steps of one cell; t in [0, 1] on
  // p-q. The divisions of x and y go in pairs (one instruction for both, each rounded as alone).
  x_ = bins.CellX(p.x());
  y_ = bins.CellY(p.y());
  x_end_ = bins.CellX(q.x());
  y_end_ = bins.CellY(q.y());
  step_x_ = e.x() > 0 ? 1 : (e.x() < 0 ? -1 : 0);
  step_y_ = e.y() > 0 ? 1 : (e.y() < 0 ? -1 : 0);
  const Eigen::Array2d next_line =
      lo + Eigen::Array2d(double(x_ + (step_x_ > 0 ? 1 : 0)), double(y_ + (step_y_ > 0 ? 1 : 0))) *
               bins.cell_;
  const Eigen::Array2d first = (next_line - p.array()) / e.array();
  const Eigen::Array2d per_cell = bins.cell_ / e.array().abs();
  t_x_ = step_x_ != 0 ? first.x() : INFINITY;
  t_y_ = step_y_ != 0 ? first.y() : INFINITY;
  dt_x_ = step_x_ != 0 ? per_cell.x() : INFINITY;
  dt_y_ = step_y_ != 0 ? per_cell.y() : INFINITY;
  left_ = std::abs(x_end_ - x_) + std::abs(y_end_ - y_);
}

void RayBins::Walk::Add(long x, long y, std::vector<int>* out) const {
  if (x < 0 || y < 0 || x >= bins_.nx_ || y >= bins_.ny_) return;
  for (const int i : bins_.bins_[std::size_t(y * bins_.nx_ + x)]) {
    std::uint32_t& last = yielded.walk_of[std::size_t(i)];
    if (last == walk_) continue;
    last = walk_;
    out->push_back(i);
  }
}

bool RayBins::Walk::Next(std::vector<int>* boxes, double* t_beyond) {
  boxes->clear();
  switch (phase_) {
    case Phase::kDone:
      return false;
    case Phase::kStart:
      for (const int i : bins_.everywhere_) {
        yielded.walk_of[std::size_t(i)] = walk_;
        boxes->push_back(i);
      }
      if (!gridded_) {
        phase_ = Phase::kDone;
        *t_beyond = INFINITY;
        return true;
      }
      Add(x_, y_, boxes);
      phase_ = Phase::kWalking;
      break;
    case Phase::kWalking: {
      if (left_ <= 0 || (x_ == x_end_ && y_ == y_end_)) {
        phase_ = Phase::kDone;
        // Rounding may stop the walk a cell short of q's: q's cell always counts.
        if (x_ == x_end_ && y_ == y_end_) return false;
        Add(x_end_, y_end_, boxes);
        *t_beyond = INFINITY;
        return true;
      }
      // Where the walk passes a corner (both crossings at once, to rounding) the two cells
      // beside it are added too, so that no cell the segment touches is missed.
      constexpr double kCornerTol = 1e-9;  // crossings this close (in t) are one corner
      if (std::abs(t_x_ - t_y_) <= kCornerTol) {
        Add(x_ + step_x_, y_, boxes);
        Add(x_, y_ + step_y_, boxes);
        x_ += step_x_;
        y_ += step_y_;
        t_x_ += dt_x_;
        t_y_ += dt_y_;
        left_ -= 2;  // two cells' worth of the count
      } else if (t_x_ < t_y_) {
        x_ += step_x_;
        t_x_ += dt_x_;
        --left_;
      } else {
        y_ += step_y_;
        t_y_ += dt_y_;
        --left_;
      }
      Add(x_, y_, boxes);
      break;
    }
  }
  // The cells still to come start where the walk next crosses a cell line.
  if (x_ == x_end_ && y_ == y_end_) {
    *t_beyond = INFINITY;  // nothing is left
  } else if (left_ <= 0) {
    *t_beyond = t0_;  // q's cell, which rounding left out, may hold anything
  } else {
    *t_beyond = t0_ + std::min(t_x_, t_y_) * (t1_ - t0_);
  }
  return true;
}

}  // namespace egress::twin::world_detail
