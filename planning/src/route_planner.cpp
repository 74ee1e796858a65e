#include "egress/planning/route_planner.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

#include "egress/hsr_interface/error.h"

namespace egress::planning {
namespace {

constexpr float kFar = 1e6f;
// Length of a diagonal step in cells (std::hypot(1, 1) gives this same double).
const double kSqrt2 = std::sqrt(2.0);

bool SegmentsCross(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                   const Eigen::Vector2d& d) {
  const auto cross = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) {
    return u.x() * v.y() - u.y() * v.x();
  };
  const double d1 = cross(d - c, a - c), d2 = cross(d - c, b - c);
  const double d3 = cross(b - a, c - a), d4 = cross(b - a, d - a);
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0)) && d1 != 0 && d3 != d4;
}

}  // namespace

void RoutePlannerConfig::Validate() const {
  const auto positive = [](double v, const char* name) {
    ThrowUnless(std::isfinite(v) && v > 0, "route planner: ", name, " must be positive, got ", v);
  };
  positive(clearance, "clearance");
  positive(comfort_distance, "comfort_distance");
  positive(approach_distance, "approach_distance");
  positive(exit_distance, "exit_distance");
  positive(near_door_distance, "near_door_distance");
  ThrowUnless(std::isfinite(wall_cost) && wall_cost >= 0, "route planner: wall_cost must be >= 0");
  ThrowUnless(std::isfinite(sweep_margin) && sweep_margin >= 0,
              "route planner: sweep_margin must be >= 0");
  ThrowUnless(std::isfinite(snap_distance) && snap_distance >= 0,
              "route planner: snap_distance must be >= 0");
}

RoutePlanner::RoutePlanner(const perception::OccupancyGrid& grid,
                           std::vector<perception::Doorway> doors, RoutePlannerConfig config)
    : grid_(grid), doors_(std::move(doors)), config_(config) {
  config_.Validate();
  const perception::GridGeometry& g = grid_.geometry();
  ThrowUnless(g.width > 0 && g.height > 0, "route planner: the map is empty");
  for (const auto& d : doors_) {
    ThrowUnless(d.width() > 1e-3 && d.p_MHinge.allFinite() && d.p_MLatch.allFinite(),
                "route planner: door '", d.id, "' has coincident or non-finite jambs");
  }
  // Distance to the nearest occupied (or unknown) cell: nearest-site propagation in two
  // raster passes (8-neighbour), exact to within a fraction of a cell for maps like these.
  const int w = g.width, h = g.height;
  std::vector<Eigen::Vector2i> site(g.size(), Eigen::Vector2i(-1, -1));
  distance_.assign(g.size(), kFar);
  for (int iy = 0; iy < h; ++iy) {
    for (int ix = 0; ix < w; ++ix) {
      if (grid_.at(ix, iy) != perception::kFreeCost) {
        site[g.Index(ix, iy)] = {ix, iy};
        distance_[g.Index(ix, iy)] = 0.0f;
      }
    }
  }
  const auto relax = [&](int ix, int iy, int nx, int ny) {
    if (!g.Contains(nx, ny)) return;
    const Eigen::Vector2i s = site[g.Index(nx, ny)];
    if (s.x() < 0) return;
    // sqrt of the exact integer square, not std::hypot: correctly rounded and a tenth of the
    // cost (the transform was a tenth of `sim run`'s start-up); the same floats on our grids.
    const int dx = ix - s.x(), dy = iy - s.y();
    const float d = float(std::sqrt(double(dx * dx + dy * dy)) * g.resolution);
    if (d < distance_[g.Index(ix, iy)]) {
      distance_[g.Index(ix, iy)] = d;
      site[g.Index(ix, iy)] = s;
    }
  };
  for (int pass = 0; pass < 2; ++pass) {
    for (int iy = 0; iy < h; ++iy) {
      for (int ix = 0; ix < w; ++ix) {
        relax(ix, iy, ix - 1, iy);
        relax(ix, iy, ix, iy - 1);
        relax(ix, iy, ix - 1, iy - 1);
        relax(ix, iy, ix + 1, iy - 1);
      }
      for (int ix = w - 1; ix >= 0; --ix)
        relax(ix, iy, ix + 1, iy);
    }
    for (int iy = h - 1; iy >= 0; --iy) {
      for (int ix = w - 1; ix >= 0; --ix) {
        relax(ix, iy, ix + 1, iy);
        relax(ix, iy, ix, iy + 1);
        relax(ix, iy, ix + 1, iy + 1);
        relax(ix, iy, ix - 1, iy + 1);
      }
      for (int ix = 0; ix < w; ++ix)
        relax(ix, iy, ix - 1, iy);
    }
  }
}

double RoutePlanner::ClearanceAt(const Eigen::Vector2d& p_M) const {
  const auto cell = grid_.geometry().CellOf(p_M);
  if (!cell) return double(kFar);
  return distance_[grid_.geometry().Index(cell->x(), cell->y())];
}

RouteResult RoutePlanner::Plan(const Pose2& X_MB_start, const Pose2& X_MB_goal,
                               const std::set<std::string>& avoid) const {
  RouteResult result;
  if (!X_MB_start.IsFinite() || !X_MB_goal.IsFinite()) {
    result.message = "the start or the goal is not a finite pose";
    return result;
  }
  for (const auto& id : avoid) {
    const bool known = std::any_of(doors_.begin(), doors_.end(),
                                   [&](const perception::Doorway& d) { return d.id == id; });
    if (!known) {
      result.message = StrCat("cannot avoid door '", id, "': the map has no such door");
      return result;
    }
  }
  const perception::GridGeometry& g = grid_.geometry();
  // Cells a route may use: clear of walls, and not in the opening of an avoided door.
  std::vector<std::uint8_t> blocked(g.size(), 0);
  for (std::size_t i = 0; i < g.size(); ++i)
    blocked[i] = distance_[i] < float(config_.clearance) ? 1 : 0;
  for (const auto& d : doors_) {
    if (avoid.count(d.id) == 0) continue;
    const int steps = int(std::ceil(d.width() / (g.resolution / 4))) + 1;
    for (int k = 0; k <= steps; ++k) {
      const Eigen::Vector2d p = d.p_MHinge + (d.p_MLatch - d.p_MHinge) * (double(k) / steps);
      if (const auto c = g.CellOf(p)) {
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx)
            if (g.Contains(c->x() + dx, c->y() + dy))
              blocked[g.Index(c->x() + dx, c->y() + dy)] = 1;
      }
    }
  }
  // A start or goal near a wall moves to the nearest route cell within snap_distance.
  const auto snap = [&](const Eigen::Vector2d& p, const char* what, Eigen::Vector2i* out) -> bool {
    const auto cell = g.CellOf(p);
    if (!cell) {
      result.message = StrCat("the ", what, " (", p.x(), ", ", p.y(), ") is outside the map");
      return false;
    }
    if (distance_[g.Index(cell->x(), cell->y())] <= 0.0f) {
      result.message = StrCat("the ", what, " (", p.x(), ", ", p.y(), ") is inside a wall");
      return false;
    }
    if (!blocked[g.Index(cell->x(), cell->y())]) {
      *out = *cell;
      return true;
    }
    const int r = int(std::ceil(config_.snap_distance / g.resolution));
    double best = std::numeric_limits<double>::infinity();
    for (int dy = -r; dy <= r; ++dy) {
      for (int dx = -r; dx <= r; ++dx) {
        const int x = cell->x() + dx, y = cell->y() + dy;
        if (!g.Contains(x, y) || blocked[g.Index(x, y)]) continue;
        const double d = (g.CellCenter(x, y) - p).norm();
        if (d <= config_.snap_distance + g.resolution / 2 && d < best) {
          best = d;
          *out = {x, y};
        }
      }
    }
    if (!std::isfinite(best)) {
      result.message =
          StrCat("the ", what, " (", p.x(), ", ", p.y(),
                 ") is against a wall: no free space within ", config_.snap_distance, " m");
      return false;
    }
    return true;
  };
  Eigen::Vector2i start, goal;
  if (!snap(X_MB_start.translation(), "start", &start) ||
      !snap(X_MB_goal.translation(), "goal", &goal)) {
    return result;
  }
  // A* over 8-neighbour cells; step cost grows near walls (comfort), the heuristic is the
  // straight-line distance (admissible: every step costs at least its length).
  const std::size_t n = g.size();
  std::vector<double> cost(n, std::numeric_limits<double>::infinity());
  std::vector<std::int64_t> parent(n, -1);
  using Entry = std::pair<double, std::size_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> open;
  const std::size_t s = g.Index(start.x(), start.y()), t = g.Index(goal.x(), goal.y());
  const auto heuristic = [&](int x, int y) {
    return std::hypot(x - goal.x(), y - goal.y()) * g.resolution;
  };
  cost[s] = 0.0;
  open.push({heuristic(start.x(), start.y()), s});
  while (!open.empty()) {
    const auto [f, i] = open.top();
    open.pop();
    if (i == t) break;
    const int x = int(i % std::size_t(g.width)), y = int(i / std::size_t(g.width));
    if (f - heuristic(x, y) > cost[i] + 1e-9) continue;  // stale entry
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if (dx == 0 && dy == 0) continue;
        const int nx = x + dx, ny = y + dy;
        if (!g.Contains(nx, ny)) continue;
        const std::size_t j = g.Index(nx, ny);
        if (blocked[j]) continue;
        const double penalty = 1.0 + config_.wall_cost * std::max(0.0, config_.comfort_distance -
                                                                           double(distance_[j]));
        const double c = cost[i] + (dx != 0 && dy != 0 ? kSqrt2 : 1.0) * g.resolution * penalty;
        if (c < cost[j]) {
          cost[j] = c;
          parent[j] = std::int64_t(i);
          open.push({c + heuristic(nx, ny), j});
        }
      }
    }
  }
  if (!std::isfinite(cost[t])) {
    result.message = StrCat("no route from (", X_MB_start.x, ", ", X_MB_start.y, ") to (",
                            X_MB_goal.x, ", ", X_MB_goal.y, ")");
    if (!avoid.empty()) {
      std::string list;
      for (const auto& id : avoid)
        list += (list.empty() ? "" : ", ") + id;
      result.message += StrCat(" avoiding door(s) ", list);
    }
    return result;
  }
  std::vector<Eigen::Vector2d> raw;
  for (std::int64_t i = std::int64_t(t); i >= 0; i = parent[std::size_t(i)]) {
    raw.push_back(g.CellCenter(int(std::size_t(i) % std::size_t(g.width)),
                               int(std::size_t(i) / std::size_t(g.width))));
  }
  std::reverse(raw.begin(), raw.end());
  raw.front() = X_MB_start.translation();
  raw.back() = X_MB_goal.translation();
  if (start != *g.CellOf(X_MB_start.translation()))
    raw.front() = g.CellCenter(start.x(), start.y());
  if (goal != *g.CellOf(X_MB_goal.translation())) raw.back() = g.CellCenter(goal.x(), goal.y());

  Route route;
  route.X_MB_goal = {raw.back().x(), raw.back().y(), X_MB_goal.yaw};
  // Doors crossed, in order, with their approach and exit poses.
  double along = 0.0;
  for (std::size_t k = 1; k < raw.size(); ++k) {
    along += (raw[k] - raw[k - 1]).norm();
    for (const auto& d : doors_) {
      if (!SegmentsCross(raw[k - 1], raw[k], d.p_MHinge, d.p_MLatch)) continue;
      const Eigen::Vector2d dir = (d.p_MLatch - d.p_MHinge).normalized();
      const Eigen::Vector2d left(-dir.y(), dir.x());
      const Eigen::Vector2d centre = (d.p_MHinge + d.p_MLatch) / 2;
      // n: the door's normal towards the side the route comes from.
      const Eigen::Vector2d n =
          (raw[k - 1] - centre).dot(left) >= 0 ? left : Eigen::Vector2d(-left);
      RouteLeg leg;
      leg.door = d.id;
      leg.distance_along = along;
      leg.opens_towards_robot = (d.swing_sign * left).dot(n) > 0;
      const double depth = leg.opens_towards_robot ? std::max(config_.approach_distance,
                                                              d.width() + config_.sweep_margin)
                                                   : config_.approach_distance;
      Eigen::Vector2d approach = centre + n * depth;
      if (ClearanceAt(approach) < config_.clearance) {
        // No room straight before the door (a corridor corner): the last route point before
        // the door at that depth, or the farthest one there is.
        approach = raw[k - 1];
        for (std::size_t m = k; m-- > 0;) {
          if ((raw[m] - centre).dot(n) > (approach - centre).dot(n)) approach = raw[m];
          if ((raw[m] - centre).dot(n) >= depth) break;
        }
      }
      const Eigen::Vector2d facing = centre - approach;
      leg.X_MB_approach = {approach.x(), approach.y(), std::atan2(facing.y(), facing.x())};
      Eigen::Vector2d exit = centre - n * config_.exit_distance;
      if (ClearanceAt(exit) < config_.clearance) {
        exit = raw[k];
        for (std::size_t m = k; m < raw.size(); ++m) {
          if ((centre - raw[m]).dot(n) > (centre - exit).dot(n)) exit = raw[m];
          if ((centre - raw[m]).dot(n) >= config_.exit_distance) break;
        }
      }
      leg.X_MB_exit = {exit.x(), exit.y(), std::atan2(-n.y(), -n.x())};
      route.legs.push_back(leg);
    }
  }
  route.length = along;
  // String-pull: keep a point only where the straight line past it would leave clear cells.
  const auto clear_line = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    const int steps = int(std::ceil((b - a).norm() / (g.resolution / 2))) + 1;
    for (int k = 0; k <= steps; ++k) {
      const auto c = g.CellOf(a + (b - a) * (double(k) / steps));
      if (!c || blocked[g.Index(c->x(), c->y())]) return false;
    }
    return true;
  };
  route.path.push_back(raw.front());
  std::size_t anchor = 0;
  for (std::size_t k = 2; k < raw.size(); ++k) {
    if (!clear_line(raw[anchor], raw[k])) {
      anchor = k - 1;
      route.path.push_back(raw[anchor]);
    }
  }
  if (raw.size() > 1) route.path.push_back(raw.back());
  result.route = std::move(route);
  return result;
}

}  // namespace egress::planning
