// The grid searches of base_planner.h: the shortest and the cheapest 8-connected path over the
// costmap's free cells (reachability, the doors on the way, the narrow-passage seed).

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

#include "egress/hsr_interface/error.h"
#include "egress/planning/base_planner.h"

namespace egress::planning {

using perception::kInscribedCost;
using perception::kUnknownCost;

namespace {

// Whether `source` and `target` lie in one component of the passable cells, 8-connected with
// no corner cutting. A diagonal step needs both cells beside it passable, so the straight
// steps alone join the same cells: two breadth-first floods over the 4 neighbours, one from
// each end, a cell at a time in turn, until they meet (joined) or either runs out (not).
// The search below would explore the whole of the start's side before it found no path; a
// goal shut off by a queue of people (the crowd bench: the robot asks every tick for a standoff
// beyond them, ~8 ms a time) costs here at most twice the smaller side, at a fraction of the
// search's cost per cell. Only the verdict is used: the search's path is unchanged.
template <class Passable>
bool Connected(const perception::GridGeometry& g, const Passable& passable, std::size_t source,
               std::size_t target) {
  if (source == target) return true;
  // Per cell of the grid framed by a blocked border (no bounds checks in the floods): 0 blocked,
  // 1 passable and unseen, 2 reached from the source, 3 from the target.
  constexpr std::uint8_t kFree = 1, kFromSource = 2, kFromTarget = 3;
  const std::size_t width = std::size_t(g.width), w = width + 2;
  std::vector<std::uint8_t> state(w * (std::size_t(g.height) + 2), 0);
  for (int iy = 0; iy < g.height; ++iy) {
    std::uint8_t* row = &state[(std::size_t(iy) + 1) * w + 1];
    const std::size_t first = g.Index(0, iy);
    for (std::size_t ix = 0; ix < width; ++ix)
      row[ix] = passable(first + ix) ? kFree : 0;
  }
  const auto framed = [&](std::size_t i) { return (i / width + 1) * w + i % width + 1; };
  const std::size_t steps[4] = {1, std::size_t(-1), w, std::size_t(0) - w};  // wrap-around adds
  std::vector<std::size_t> queue[2];
  std::size_t head[2] = {0, 0};
  queue[0].reserve(4096);
  queue[1].reserve(4096);
  queue[0].push_back(framed(source));
  queue[1].push_back(framed(target));
  state[queue[0][0]] = kFromSource;
  state[queue[1][0]] = kFromTarget;
  for (int turn = 0;; turn ^= 1) {
    auto& q = queue[turn];
    if (head[turn] == q.size()) return false;
    const std::size_t index = q[head[turn]++];
    const std::uint8_t mine = turn == 0 ? kFromSource : kFromTarget;
    for (const std::size_t step : steps) {
      const std::size_t next = index + step;
      const std::uint8_t s = state[next];
      if (s == kFree) {
        state[next] = mine;
        q.push_back(next);
      } else if (s != 0 && s != mine) {
        return true;  // the other flood's
      }
    }
  }
}

}  // namespace

std::optional<double> GridShortestPathLength(const perception::Costmap2D& costmap,
                                             const Eigen::Vector2d& start,
                                             const Eigen::Vector2d& goal, bool allow_unknown) {
  const auto path = GridShortestPath(costmap, start, goal, allow_unknown);
  if (!path) return std::nullopt;
  double length = 0.0;
  for (std::size_t i = 1; i < path->size(); ++i)
    length += ((*path)[i] - (*path)[i - 1]).norm();
  return length;
}

std::optional<std::vector<Eigen::Vector2d>> GridShortestPath(const perception::Costmap2D& costmap,
                                                             const Eigen::Vector2d& start,
                                                             const Eigen::Vector2d& goal,
                                                             bool allow_unknown) {
  return GridCheapestPath(costmap, start, goal, GridStepCosts{}, allow_unknown);
}

std::vector<std::uint8_t> DoorwayCells(const perception::GridGeometry& geometry,
                                       const std::vector<PlannerDoor>& doors, double depth,
                                       double widen) {
  std::vector<std::uint8_t> doorway(geometry.size(), 0);
  for (const auto& door : doors) {
    const Eigen::Vector2d centre = 0.5 * (door.p_MA + door.p_MB);
    const Eigen::Vector2d along = (door.p_MB - door.p_MA).normalized();
    const Eigen::Vector2d normal(-along.y(), along.x());
    const double half_width = 0.5 * (door.p_MB - door.p_MA).norm() + widen;
    // The band's bounding box in cells, then each cell centre tested in the door's frame.
    const Eigen::Vector2d extent = half_width * along.cwiseAbs() + depth * normal.cwiseAbs() +
                                   Eigen::Vector2d::Constant(geometry.resolution);
    const Eigen::Vector2d lo = (centre - extent - geometry.origin) / geometry.resolution;
    const Eigen::Vector2d hi = (centre + extent - geometry.origin) / geometry.resolution;
    const int x0 = std::max(0, int(std::floor(lo.x()))), y0 = std::max(0, int(std::floor(lo.y())));
    const int x1 = std::min(geometry.width - 1, int(std::ceil(hi.x())));
    const int y1 = std::min(geometry.height - 1, int(std::ceil(hi.y())));
    for (int iy = y0; iy <= y1; ++iy) {
      for (int ix = x0; ix <= x1; ++ix) {
        const Eigen::Vector2d rel = geometry.CellCenter(ix, iy) - centre;
        if (std::abs(rel.dot(along)) <= half_width && std::abs(rel.dot(normal)) <= depth)
          doorway[geometry.Index(ix, iy)] = 1;
      }
    }
  }
  return doorway;
}

std::optional<std::vector<Eigen::Vector2d>> GridCheapestPath(const perception::Costmap2D& costmap,
                                                             const Eigen::Vector2d& start,
                                                             const Eigen::Vector2d& goal,
                                                             const GridStepCosts& costs,
                                                             bool allow_unknown) {
  ThrowUnless(std::isfinite(costs.close_weight) && costs.close_weight >= 0.0,
              "GridCheapestPath: close_weight must be finite and >= 0, got ", costs.close_weight);
  ThrowUnless(std::isfinite(costs.personal_space_weight) && costs.personal_space_weight >= 0.0,
              "GridCheapestPath: personal_space_weight must be finite and >= 0, got ",
              costs.personal_space_weight);
  ThrowUnless(std::isfinite(costs.doorway_weight) && costs.doorway_weight >= 0.0,
              "GridCheapestPath: doorway_weight must be finite and >= 0, got ",
              costs.doorway_weight);
  ThrowUnless(costs.doorway == nullptr || costs.doorway->size() == costmap.geometry().size(),
              "GridCheapestPath: the doorway cells (", costs.doorway ? costs.doorway->size() : 0,
              ") do not match the costmap (", costmap.geometry().size(), " cells)");
  const float penalty = 1.0f + float(costs.close_weight);
  const float per_doorway = costs.doorway ? float(costs.doorway_weight) : 0.0f;
  const float per_personal =
      float(costs.personal_space_weight) / float(perception::kPersonalSpacePeakCost);
  const auto& personal = costmap.personal_space_costs();
  const auto& g = costmap.geometry();
  const auto s = g.CellOf(start), t = g.CellOf(goal);
  if (!s || !t) return std::nullopt;
  const auto passable = [&](std::size_t i) {
    const std::uint8_t c = costmap.costs()[i];
    return c == kUnknownCost ? allow_unknown : c < kInscribedCost;
  };
  const std::size_t source = g.Index(s->x(), s->y()), target = g.Index(t->x(), t->y());
  if (!passable(source) || !passable(target)) return std::nullopt;
  if (!Connected(g, passable, source, target)) return std::nullopt;
  std::vector<float> distance(g.size(), std::numeric_limits<float>::infinity());
  std::vector<std::uint32_t> parent(g.size(), std::numeric_limits<std::uint32_t>::max());
  using Item = std::pair<float, std::uint32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
  distance[source] = 0.0f;
  open.push({0.0f, std::uint32_t(source)});
  constexpr float kDiagonal = 1.41421356f;
  while (!open.empty()) {
    const auto [d, index] = open.top();
    open.pop();
    if (d > distance[index]) continue;
    if (index == target) break;
    const int ix = int(index % std::uint32_t(g.width)), iy = int(index / std::uint32_t(g.width));
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if ((dx == 0 && dy == 0) || !g.Contains(ix + dx, iy + dy)) continue;
        const std::size_t next = g.Index(ix + dx, iy + dy);
        if (!passable(next)) continue;
        // No corner cutting: a diagonal step needs both cells beside it free.
        if (dx != 0 && dy != 0 &&
            (!passable(g.Index(ix + dx, iy)) || !passable(g.Index(ix, iy + dy))))
          continue;
        const std::uint8_t c = costmap.costs()[next];
        const float factor = (c != kUnknownCost && c >= costs.close_cost ? penalty : 1.0f) +
                             per_personal * float(personal[next]) +
                             (per_doorway > 0.0f && (*costs.doorway)[next] ? per_doorway : 0.0f);
        const float nd = d + ((dx != 0 && dy != 0) ? kDiagonal : 1.0f) * factor;
        if (nd < distance[next]) {
          distance[next] = nd;
          parent[next] = index;
          open.push({nd, std::uint32_t(next)});
        }
      }
    }
  }
  if (!std::isfinite(distance[target])) return std::nullopt;
  std::vector<Eigen::Vector2d> path;
  for (std::size_t i = target;; i = parent[i]) {
    path.push_back(g.CellCenter(int(i % std::size_t(g.width)), int(i / std::size_t(g.width))));
    if (i == source) break;
  }
  std::reverse(path.begin(), path.end());
  return path;
}

}  // namespace egress::planning
