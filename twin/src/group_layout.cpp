#include "group_layout.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

#include "egress/hsr_interface/error.h"

namespace egress::twin::world_detail {
namespace {

bool CrossesAny(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                const std::vector<WallSegment>& barriers) {
  return std::any_of(barriers.begin(), barriers.end(),
                     [&](const WallSegment& w) { return SegmentsCross(a, b, w.a, w.b); });
}

}  // namespace

int GroupLayout::Columns(int count) {
  return int(std::ceil(std::sqrt(double(count))));
}

Eigen::Vector2d GroupLayout::GridUnit(int k, int count) {
  const int columns = Columns(count);
  return Eigen::Vector2d((k % columns) - (columns - 1) / 2.0, (k / columns) - (columns - 1) / 2.0);
}

GroupLayout::GroupLayout(const Eigen::Vector2d& p_WS,
                         const std::vector<Eigen::Vector2d>& grid_places, double spacing,
                         const std::vector<WallSegment>& barriers,
                         const std::vector<WallSegment>& keep_off)
    : p_WS_(p_WS), count_(int(grid_places.size())) {
  ThrowUnless(count_ >= 1 && std::isfinite(spacing) && spacing > 0.0 && p_WS.allFinite(),
              "GroupLayout: needs a member, a finite spacing > 0 and a finite start");
  columns_ = Columns(count_);
  lo_ = -kGroupLayoutExtraRings;
  side_ = columns_ + 2 * kGroupLayoutExtraRings;
  const double c = (columns_ - 1) / 2.0;
  nodes_.resize(std::size_t(side_ * side_));
  for (int j = lo_; j < lo_ + side_; ++j) {
    for (int i = lo_; i < lo_ + side_; ++i) {
      Node& n = At(i, j);
      n.i = i;
      n.j = j;
      n.someones_grid_place = i >= 0 && j >= 0 && i < columns_ && j * columns_ + i < count_;
      n.p_W = n.someones_grid_place ? grid_places[std::size_t(j * columns_ + i)]
                                    : p_WS + Eigen::Vector2d(i - c, j - c) * spacing;
      n.clearance = n.keep_off = std::numeric_limits<double>::infinity();
      for (const WallSegment& w : barriers)
        n.clearance = std::min(n.clearance, (n.p_W - ClosestPointOnSegment(n.p_W, w)).norm());
      for (const WallSegment& w : keep_off)
        n.keep_off = std::min(n.keep_off, (n.p_W - ClosestPointOnSegment(n.p_W, w)).norm());
    }
  }
  // The places the start reaches: those it sees, and from them on by grid steps that cross no
  // barrier (round a pillar, along an L-shaped room).
  std::deque<Node*> open;
  for (Node& n : nodes_) {
    if (!CrossesAny(p_WS, n.p_W, barriers) && !CrossesAny(p_WS, n.p_W, keep_off)) {
      n.reached = true;
      open.push_back(&n);
    }
  }
  while (!open.empty()) {
    const Node& n = *open.front();
    open.pop_front();
    constexpr int kSteps[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
    for (const auto& step : kSteps) {
      const int i = n.i + step[0], j = n.j + step[1];
      if (i < lo_ || j < lo_ || i >= lo_ + side_ || j >= lo_ + side_) continue;
      Node& next = At(i, j);
      if (next.reached || CrossesAny(n.p_W, next.p_W, barriers) ||
          CrossesAny(n.p_W, next.p_W, keep_off))
        continue;
      next.reached = true;
      open.push_back(&next);
    }
  }
}

std::optional<Eigen::Vector2d> GroupLayout::Place(int k, double radius) {
  ThrowUnless(k >= 0 && k < count_, "GroupLayout: member ", k, " of a group of ", count_);
  Node& own = At(k % columns_, k / columns_);
  // A grid place on the start's side counts even where the body touches a wall (the walls'
  // force moves it clear in the first steps, as it always has); one beyond or in a wall does not.
  if (own.reached && !own.taken && own.clearance > 0.0 && own.keep_off >= radius) {
    own.taken = true;
    return own.p_W;
  }
  Node* best = nullptr;
  double best_distance = std::numeric_limits<double>::infinity();
  for (Node& n : nodes_) {  // row by row, column by column: the first of equals wins
    if (n.someones_grid_place || !n.reached || n.taken ||
        std::min(n.clearance, n.keep_off) < radius)
      continue;
    const double d = (n.p_W - p_WS_).norm();
    if (d < best_distance - 1e-9) {
      best = &n;
      best_distance = d;
    }
  }
  if (!best) return std::nullopt;
  best->taken = true;
  return best->p_W;
}

}  // namespace egress::twin::world_detail
