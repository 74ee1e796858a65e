#include "egress/perception/costmap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "egress/hsr_interface/error.h"

namespace egress::perception {

void CostmapConfig::Validate() const {
  ThrowUnless(std::isfinite(robot_radius) && robot_radius > 0.0,
              "Invalid CostmapConfig: robot_radius (", robot_radius, ") must be > 0.");
  ThrowUnless(std::isfinite(inflation_radius) && inflation_radius >= robot_radius,
              "Invalid CostmapConfig: inflation_radius (", inflation_radius,
              ") must be >= robot_radius (", robot_radius, ").");
  ThrowUnless(std::isfinite(cost_scaling_factor) && cost_scaling_factor > 0.0,
              "Invalid CostmapConfig: cost_scaling_factor (", cost_scaling_factor,
              ") must be > 0.");
  ThrowUnless(obstacle_max_range > 0.0 && raytrace_max_range > 0.0,
              "Invalid CostmapConfig: obstacle_max_range and raytrace_max_range must be > 0.");
  ThrowUnless(unseen_mark_lifetime >= 0.0, "Invalid CostmapConfig: unseen_mark_lifetime (",
              unseen_mark_lifetime, ") must be >= 0.");
}

namespace {
constexpr int kLookupSubdivisions = 8;

// Squared Euclidean distance [cells²] from each cell to the nearest cell where `is_site` holds,
// exactly (Felzenszwalb and Huttenlocher's lower envelope of parabolas, by columns then rows,
// in integers); kNoSite where there is none.
constexpr std::uint32_t kNoSite = std::numeric_limits<std::uint32_t>::max();
template <typename IsSite>
std::vector<std::uint32_t> SquaredDistanceToSites(int width, int height, IsSite&& is_site) {
  constexpr std::int64_t kFar = std::int64_t(1) << 40;
  const std::size_t w = std::size_t(width), h = std::size_t(height);
  std::vector<std::int64_t> column(w * h);
  // 1D transform of f over n samples into d (v: parabola apexes, z: boundaries, as ratios).
  std::vector<std::int64_t> f(std::max(w, h)), d(std::max(w, h));
  std::vector<std::size_t> v(std::max(w, h));
  std::vector<double> z(std::max(w, h) + 1);
  const auto transform = [&](std::size_t n) {
    // Where the parabolas of q and p (q > p) cross: exact enough, their numerator and
    // denominator being integers far below 2^53.
    const auto meet = [&](std::size_t q, std::size_t p) {
      return double((f[q] + std::int64_t(q * q)) - (f[p] + std::int64_t(p * p))) /
             double(2 * (std::int64_t(q) - std::int64_t(p)));
    };
    constexpr double kInf = std::numeric_limits<double>::infinity();
    std::ptrdiff_t k = -1;  // the envelope's last parabola (none yet)
    for (std::size_t q = 0; q < n; ++q) {
      if (f[q] >= kFar) continue;  // not a site
      if (k < 0) {
        k = 0;
        v[0] = q;
        z[0] = -kInf;
        z[1] = kInf;
        continue;
      }
      double s = meet(q, v[std::size_t(k)]);
      while (s <= z[std::size_t(k)]) {  // z[0] = -inf ends it
        --k;
        s = meet(q, v[std::size_t(k)]);
      }
      ++k;
      v[std::size_t(k)] = q;
      z[std::size_t(k)] = s;
      z[std::size_t(k) + 1] = kInf;
    }
    if (k < 0) {
      std::fill(d.begin(), d.begin() + std::ptrdiff_t(n), kFar);
      return;
    }
    std::size_t e = 0;
    for (std::size_t q = 0; q < n; ++q) {
      while (z[e + 1] < double(q))
        ++e;
      const std::int64_t dq = std::int64_t(q) - std::int64_t(v[e]);
      d[q] = dq * dq + f[v[e]];
    }
  };
  for (std::size_t x = 0; x < w; ++x) {
    for (std::size_t y = 0; y < h; ++y)
      f[y] = is_site(x + y * w) ? 0 : kFar;
    transform(h);
    for (std::size_t y = 0; y < h; ++y)
      column[x + y * w] = d[y];
  }
  std::vector<std::uint32_t> out(w * h);
  for (std::size_t y = 0; y < h; ++y) {
    for (std::size_t x = 0; x < w; ++x)
      f[x] = column[x + y * w];
    transform(w);
    for (std::size_t x = 0; x < w; ++x)
      out[x + y * w] = d[x] >= std::int64_t(kNoSite) ? kNoSite : std::uint32_t(d[x]);  // kFar too
  }
  return out;
}

constexpr double kMaxInflationCells = 1000.0;
constexpr double kMaxDoorwayWidthM = 10.0;
}  // namespace

Costmap2D::Costmap2D(const OccupancyGrid& static_map, CostmapConfig config)
    : config_(config), geometry_(static_map.geometry()), static_(static_map.cells()) {
  config_.Validate();
  geometry_.Validate();
  // The inflation kernel spans inflation_radius / resolution cells each way: bounded, so that
  // a tiny resolution (1e-20 m, found by fuzzing navd) is an error, not a kernel of 1e20 cells.
  ThrowUnless(config_.inflation_radius / geometry_.resolution <= kMaxInflationCells,
              "Costmap: the inflation radius (", config_.inflation_radius, " m) spans more than ",
              kMaxInflationCells, " cells of ", geometry_.resolution, " m");
  static_lethal_d2_ = SquaredDistanceToSites(
      geometry_.width, geometry_.height, [&](std::size_t i) { return static_[i] == kLethalCost; });
  obstacle_.assign(geometry_.size(), kFreeCost);
  marked_at_.assign(geometry_.size(), 0.0);
  in_marked_.assign(geometry_.size(), 0);
  projection_.assign(geometry_.size(), kFreeCost);
  leaves_.assign(geometry_.size(), kFreeCost);
  doorway_zone_.assign(geometry_.size(), 0);
  personal_space_.assign(geometry_.size(), kFreeCost);
  master_.assign(geometry_.size(), kFreeCost);
  const int max_cells =
      static_cast<int>(std::ceil(config_.inflation_radius / geometry_.resolution)) + 2;
  inflation_lookup_.resize(std::size_t(max_cells * kLookupSubdivisions + 1));
  for (std::size_t i = 0; i < inflation_lookup_.size(); ++i) {
    inflation_lookup_[i] = InflatedCost(double(i) / kLookupSubdivisions * geometry_.resolution);
  }
  RecomputeWindow(0, 0, geometry_.width - 1, geometry_.height - 1);
}

std::uint8_t Costmap2D::InflatedCost(double distance) const {
  if (distance <= 1e-9) return kLethalCost;
  if (distance <= config_.robot_radius) return kInscribedCost;
  if (distance > config_.inflation_radius) return kFreeCost;
  const double factor = std::exp(-config_.cost_scaling_factor * (distance - config_.robot_radius));
  return static_cast<std::uint8_t>((kInscribedCost - 1) * factor);
}

void Costmap2D::UpdateWithScan(const LaserScan& scan, const Pose2& X_ML) {
  scan.Validate();
  ThrowUnless(X_ML.IsFinite(), "Invalid laser pose X_ML: must be finite.");
  const Eigen::Vector2d p_MO = X_ML.translation();
  const double res = geometry_.resolution;
  int x0 = geometry_.width, y0 = geometry_.height, x1 = -1, y1 = -1;
  const auto touch = [&](int ix, int iy) {
    x0 = std::min(x0, ix);
    y0 = std::min(y0, iy);
    x1 = std::max(x1, ix);
    y1 = std::max(y1, iy);
  };
  const auto origin_cell = geometry_.CellOf(p_MO);
  if (!origin_cell) return;  // the sensor is off the map: nothing to trace from
  // All rays clear first, then all returns mark (as Nav2 does): otherwise a neighbouring beam
  // with no return would clear the cell a hit has just marked.
  std::vector<Eigen::Vector2i> marks;
  for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
    const float r = scan.ranges[i];
    if (std::isnan(r) || r < scan.range_min) continue;  // invalid beam
    const bool hit = std::isfinite(r) && r <= scan.range_max;
    const double clear_range =
        std::min<double>(hit ? r : scan.range_max, config_.raytrace_max_range);
    const double angle = X_ML.yaw + scan.AngleAt(i);
    const Eigen::Vector2d direction(std::cos(angle), std::sin(angle));
    // Clear with a DDA walk through the cells the ray crosses, stopping before the hit cell.
    const Eigen::Vector2d end = p_MO + clear_range * direction;
    const auto hit_cell = hit ? geometry_.CellOf(p_MO + double(r) * direction) : std::nullopt;
    Eigen::Vector2d local = (p_MO - geometry_.origin) / res;
    int ix = origin_cell->x(), iy = origin_cell->y();
    const int step_x = direction.x() > 0 ? 1 : -1, step_y = direction.y() > 0 ? 1 : -1;
    const double inv_x = direction.x() != 0 ? std::abs(1.0 / direction.x()) : 1e30;
    const double inv_y = direction.y() != 0 ? std::abs(1.0 / direction.y()) : 1e30;
    double t_x = (direction.x() > 0 ? (ix + 1 - local.x()) : (local.x() - ix)) * inv_x;
    double t_y = (direction.y() > 0 ? (iy + 1 - local.y()) : (local.y() - iy)) * inv_y;
    const double t_end = (end - p_MO).norm() / res;
    while (geometry_.Contains(ix, iy)) {
      if (hit_cell && ix == hit_cell->x() && iy == hit_cell->y()) break;
      // Only a cell that changes dirties the window: re-clearing free space costs nothing later.
      if (std::uint8_t& cell = obstacle_[geometry_.Index(ix, iy)]; cell != kFreeCost) {
        cell = kFreeCost;
        touch(ix, iy);
      }
      if (std::min(t_x, t_y) > t_end) break;
      if (t_x < t_y) {
        ix += step_x;
        t_x += inv_x;
      } else {
        iy += step_y;
        t_y += inv_y;
      }
    }
    if (hit_cell && r <= config_.obstacle_max_range) marks.push_back(*hit_cell);
  }
  const double now = ToSeconds(scan.stamp);
  for (const Eigen::Vector2i& cell : marks) {
    const std::size_t index = geometry_.Index(cell.x(), cell.y());
    if (std::uint8_t& value = obstacle_[index]; value != kLethalCost) {
      value = kLethalCost;
      touch(cell.x(), cell.y());
    }
    if (!in_marked_[index]) marked_.push_back(index);
    in_marked_[index] = 1;
    marked_at_[index] = now;
  }
  ForgetUnseenMarks(now, p_MO, touch);
  if (x1 >= x0) RecomputeWindow(x0, y0, x1, y1);
}

template <typename Touch>
void Costmap2D::ForgetUnseenMarks(double now, const Eigen::Vector2d& p_MO, Touch&& touch) {
  // Drops the cells the rays have cleared and forgets the stale ones out of their reach.
  const double reach = config_.raytrace_max_range;
  std::erase_if(marked_, [&](std::size_t index) {
    std::uint8_t& value = obstacle_[index];
    if (value == kLethalCost) {
      if (now - marked_at_[index] <= config_.unseen_mark_lifetime) return false;
      const int ix = int(index % std::size_t(geometry_.width));
      const int iy = int(index / std::size_t(geometry_.width));
      if ((geometry_.CellCenter(ix, iy) - p_MO).norm() <= reach) return false;  // a ray's job
      value = kFreeCost;  // stale and out of every ray's reach
      touch(ix, iy);
    }
    in_marked_[index] = 0;
    return true;
  });
}

void Costmap2D::SetProjectedObstacles(const std::vector<Eigen::Vector2d>& p_MObstacles) {
  int x0 = geometry_.width, y0 = geometry_.height, x1 = -1, y1 = -1;
  const auto touch = [&](const Eigen::Vector2i& c) {
    x0 = std::min(x0, c.x());
    y0 = std::min(y0, c.y());
    x1 = std::max(x1, c.x());
    y1 = std::max(y1, c.y());
  };
  for (const auto& c : projected_cells_) {
    projection_[geometry_.Index(c.x(), c.y())] = kFreeCost;
    touch(c);
  }
  projected_cells_.clear();
  for (const auto& p : p_MObstacles) {
    if (auto c = geometry_.CellOf(p)) {
      projection_[geometry_.Index(c->x(), c->y())] = kLethalCost;
      projected_cells_.push_back(*c);
      touch(*c);
    }
  }
  if (x1 >= x0) RecomputeWindow(x0, y0, x1, y1);
}

void Costmap2D::SetPersonalSpaces(const std::vector<PersonalSpace>& spaces) {
  for (std::size_t k = 0; k < spaces.size(); ++k) {
    const PersonalSpace& s = spaces[k];
    // The message only for a bad space: this runs for every space ten times a second.
    const char* bad = nullptr;
    if (!s.p_MP.allFinite()) {
      bad = "the centre must be finite";
    } else if (!(std::isfinite(s.inner) && s.inner >= 0.0)) {
      bad = "inner must be >= 0";
    } else if (!(std::isfinite(s.outer) && s.outer > s.inner)) {
      bad = "outer must exceed inner";
    } else if (!(s.outer <= kMaxPersonalSpaceM)) {
      bad = "outer is beyond kMaxPersonalSpaceM (5 m)";
    } else if (!(s.weight > 0.0 && s.weight <= 1.0)) {
      bad = "the weight must be in (0, 1]";
    }
    ThrowUnless(bad == nullptr, "Invalid personal space ", k, ": ", bad ? bad : "", " (centre ",
                s.p_MP.x(), ", ", s.p_MP.y(), ", inner ", s.inner, ", outer ", s.outer, ", weight ",
                s.weight, ").");
  }
  personal_spaces_ = spaces;
  personal_space_painted_ = false;
}

void Costmap2D::PaintPersonalSpaces() const {
  if (personal_space_painted_) return;
  personal_space_painted_ = true;
  for (const std::size_t i : personal_space_cells_)
    personal_space_[i] = kFreeCost;
  personal_space_cells_.clear();
  const double res = geometry_.resolution;
  const std::vector<PersonalSpace>& spaces = personal_spaces_;
  for (std::size_t k = 0; k < spaces.size(); ++k) {
    const PersonalSpace& s = spaces[k];
    // A space another one covers (the same centre and radii, no lower weight: a standing
    // person's predicted positions) adds nothing: its cost is no higher in any cell.
    const bool covered = std::any_of(spaces.begin(), spaces.begin() + long(k), [&](const auto& o) {
      return o.p_MP == s.p_MP && o.inner == s.inner && o.outer == s.outer && o.weight >= s.weight;
    });
    if (covered) continue;
    const int n = int(std::ceil(s.outer / res));
    // A person just off the map still reaches into it: cells from the unclamped position.
    const Eigen::Vector2d local = (s.p_MP - geometry_.origin) / res;
    if (local.x() < -n - 1 || local.y() < -n - 1 || local.x() > geometry_.width + n + 1 ||
        local.y() > geometry_.height + n + 1)
      continue;
    const int cx = int(std::floor(local.x())), cy = int(std::floor(local.y()));
    const double inner2 = s.inner * s.inner, outer2 = s.outer * s.outer;
    const double peak = kPersonalSpacePeakCost * s.weight;
    for (int iy = std::max(0, cy - n); iy <= std::min(geometry_.height - 1, cy + n); ++iy) {
      const double dy = (iy + 0.5) * res + geometry_.origin.y() - s.p_MP.y();
      if (dy * dy >= outer2) continue;
      // Only the row's cells the circle spans (and one more each side for rounding); the
      // distance test below decides each.
      const int half = int(std::ceil(std::sqrt(outer2 - dy * dy) / res)) + 1;
      const int x0 = std::max({0, cx - n, cx - half});
      const int x1 = std::min({geometry_.width - 1, cx + n, cx + half});
      for (int ix = x0; ix <= x1; ++ix) {
        const double dx = (ix + 0.5) * res + geometry_.origin.x() - s.p_MP.x();
        const double d2 = dx * dx + dy * dy;
        if (d2 >= outer2) continue;
        // The square root only in the fading ring.
        const double f = d2 <= inner2 ? 1.0 : (s.outer - std::sqrt(d2)) / (s.outer - s.inner);
        const auto cost = static_cast<std::uint8_t>(peak * f + 0.5);
        if (cost == kFreeCost) continue;
        std::uint8_t& cell = personal_space_[geometry_.Index(ix, iy)];
        if (cell == kFreeCost) personal_space_cells_.push_back(geometry_.Index(ix, iy));
        cell = std::max(cell, cost);
      }
    }
  }
}

const std::vector<std::uint8_t>& Costmap2D::personal_space_costs() const {
  PaintPersonalSpaces();
  return personal_space_;
}

std::uint8_t Costmap2D::PersonalSpaceCostAt(const Eigen::Vector2d& p_MQ) const {
  PaintPersonalSpaces();
  const auto cell = geometry_.CellOf(p_MQ);
  return cell ? personal_space_[geometry_.Index(cell->x(), cell->y())] : kFreeCost;
}

bool Costmap2D::IsNearSensedObstacle(const Eigen::Vector2d& p_MQ, double radius) const {
  return IsNearLethal(p_MQ, radius, {&static_, &obstacle_, &leaves_});
}

bool Costmap2D::IsNearMappedObstacle(const Eigen::Vector2d& p_MQ, double radius) const {
  return IsNearLethal(p_MQ, radius, {&static_, &leaves_});
}

bool Costmap2D::IsNearUnmappedMark(const Eigen::Vector2d& p_MQ, double radius,
                                   double off_map) const {
  const auto c = geometry_.CellOf(p_MQ);
  if (!c || !(radius >= 0.0)) return false;
  const int n = int(std::ceil(radius / geometry_.resolution));
  const double r2 = std::pow(radius / geometry_.resolution, 2);
  for (int dy = -n; dy <= n; ++dy) {
    for (int dx = -n; dx <= n; ++dx) {
      const int x = c->x() + dx, y = c->y() + dy;
      if (dx * dx + dy * dy > r2 || !geometry_.Contains(x, y) ||
          obstacle_[geometry_.Index(x, y)] != kLethalCost)
        continue;
      if (!IsNearMappedObstacle(geometry_.CellCenter(x, y), off_map)) return true;
    }
  }
  return false;
}

bool Costmap2D::IsNearLethal(const Eigen::Vector2d& p_MQ, double radius,
                             std::initializer_list<const std::vector<std::uint8_t>*> layers) const {
  const auto c = geometry_.CellOf(p_MQ);
  if (!c) return false;
  const int n = int(std::ceil(radius / geometry_.resolution));
  if (n < 0) return false;
  const double r2 = std::pow(radius / geometry_.resolution, 2);
  // The map's lethal cells by their distance transform; the other layers (which change with
  // every scan) by a search.
  std::array<const std::vector<std::uint8_t>*, 4> searched{};
  std::size_t count = 0;
  const auto near_a_leaf = [&] {
    return std::any_of(leaf_cell_boxes_.begin(), leaf_cell_boxes_.end(), [&](const auto& box) {
      return c->x() + n >= box[0] && c->y() + n >= box[1] && c->x() - n <= box[2] &&
             c->y() - n <= box[3];
    });
  };
  for (const auto* layer : layers) {
    if (layer == &static_) {
      if (double(static_lethal_d2_[geometry_.Index(c->x(), c->y())]) <= r2) return true;
    } else if (layer == &leaves_ && !near_a_leaf()) {
      continue;  // no leaf within reach
    } else {
      ThrowUnless(count < searched.size(), "Costmap: IsNearLethal takes at most ", searched.size(),
                  " layers besides the map's");
      searched[count++] = layer;
    }
  }
  if (count == 0) return false;
  // Nearest first, ring by ring out from its own cell: most points asked about are a wall's
  // laser returns, in or beside a lethal cell.
  const auto lethal = [&](int dx, int dy) {
    const int x = c->x() + dx, y = c->y() + dy;
    if (dx * dx + dy * dy > r2 || x < 0 || y < 0 || x >= geometry_.width || y >= geometry_.height)
      return false;
    const std::size_t i = geometry_.Index(x, y);
    for (std::size_t k = 0; k < count; ++k)
      if ((*searched[k])[i] == kLethalCost) return true;
    return false;
  };
  if (lethal(0, 0)) return true;
  for (int k = 1; k <= n; ++k) {
    for (int dy = -k; dy <= k; ++dy) {
      const int step = dy == -k || dy == k ? 1 : 2 * k;  // the ring's rows, else its two ends
      for (int dx = -k; dx <= k; dx += step)
        if (lethal(dx, dy)) return true;
    }
  }
  return false;
}

void Costmap2D::ClearObstacles() {
  std::fill(obstacle_.begin(), obstacle_.end(), kFreeCost);
  for (const std::size_t index : marked_)
    in_marked_[index] = 0;
  marked_.clear();
  RecomputeWindow(0, 0, geometry_.width - 1, geometry_.height - 1);
}

void Costmap2D::AddDoorway(const Doorway& doorway) {
  ThrowUnless(!doorways_.contains(doorway.id), "Invalid doorway: id '", doorway.id,
              "' exists already.");
  ThrowUnless(
      doorway.p_MHinge.allFinite() && doorway.p_MLatch.allFinite() && doorway.width() > 1e-3,
      "Invalid doorway '", doorway.id, "': jambs must be finite and distinct.");
  // A doorway wider than any door (a 1e9 m one, found by fuzzing navd) would be walked cell by
  // cell for ever when its leaf is marked.
  ThrowUnless(doorway.width() <= kMaxDoorwayWidthM, "Invalid doorway '", doorway.id,
              "': its jambs are ", doorway.width(), " m apart (at most ", kMaxDoorwayWidthM,
              " m).");
  ThrowUnless(doorway.threshold_depth >= 0.0 && doorway.threshold_depth <= kMaxDoorwayWidthM,
              "Invalid doorway '", doorway.id, "': threshold_depth must be in [0, ",
              kMaxDoorwayWidthM, "] m.");
  doorways_[doorway.id] = doorway;
  // The threshold zone: the rectangle between the jambs, threshold_depth to each side.
  const Eigen::Vector2d along = (doorway.p_MLatch - doorway.p_MHinge) / doorway.width();
  const Eigen::Vector2d normal(-along.y(), along.x());
  int x0 = geometry_.width, y0 = geometry_.height, x1 = -1, y1 = -1;
  for (int iy = 0; iy < geometry_.height; ++iy) {
    for (int ix = 0; ix < geometry_.width; ++ix) {
      const Eigen::Vector2d d = geometry_.CellCenter(ix, iy) - doorway.p_MHinge;
      const double s = d.dot(along), n = d.dot(normal);
      if (s > 0.0 && s < doorway.width() && std::abs(n) <= doorway.threshold_depth) {
        doorway_zone_[geometry_.Index(ix, iy)] = 1;
        x0 = std::min(x0, ix);
        y0 = std::min(y0, iy);
        x1 = std::max(x1, ix);
        y1 = std::max(y1, iy);
      }
    }
  }
  if (x1 >= x0) RecomputeWindow(x0, y0, x1, y1);
}

void Costmap2D::MarkLeaf(const Doorway& doorway, double angle, std::uint8_t value) {
  const Eigen::Vector2d closed = doorway.p_MLatch - doorway.p_MHinge;
  const double yaw = std::atan2(closed.y(), closed.x()) + doorway.swing_sign * angle;
  const Eigen::Vector2d direction(std::cos(yaw), std::sin(yaw));
  const double step = geometry_.resolution / 3.0;
  for (double s = 0.0; s <= doorway.width(); s += step) {
    if (auto c = geometry_.CellOf(doorway.p_MHinge + s * direction))
      leaves_[geometry_.Index(c->x(), c->y())] = value;
  }
}

void Costmap2D::SetDoorLeafAngle(const std::string& id, std::optional<double> angle) {
  auto it = doorways_.find(id);
  ThrowUnless(it != doorways_.end(), "Unknown doorway '", id, "'.");
  ThrowUnless(!angle || std::isfinite(*angle), "Invalid leaf angle for doorway '", id,
              "': must be finite.");
  const Doorway& doorway = it->second;
  if (auto previous = leaf_angles_.find(id); previous != leaf_angles_.end()) {
    MarkLeaf(doorway, previous->second, kFreeCost);
    leaf_angles_.erase(previous);
  }
  if (angle) {
    MarkLeaf(doorway, *angle, kLethalCost);
    leaf_angles_[id] = *angle;
  }
  // Other leaves may share cells with the one removed: mark them again.
  leaf_cell_boxes_.clear();
  for (const auto& [other, other_angle] : leaf_angles_) {
    const Doorway& marked = doorways_.at(other);
    MarkLeaf(marked, other_angle, kLethalCost);
    const Eigen::Vector2d r = Eigen::Vector2d::Constant(marked.width());
    const Eigen::Vector2d lo = (marked.p_MHinge - r - geometry_.origin) / geometry_.resolution;
    const Eigen::Vector2d hi = (marked.p_MHinge + r - geometry_.origin) / geometry_.resolution;
    // A cell more each way, for the rounding of MarkLeaf's steps along the leaf.
    const auto cell = [](double x) { return int(std::clamp(std::floor(x), -1e9, 1e9)); };
    leaf_cell_boxes_.push_back(
        {cell(lo.x()) - 1, cell(lo.y()) - 1, cell(hi.x()) + 1, cell(hi.y()) + 1});
  }
  const double reach = doorway.width();
  const auto lo = geometry_.CellOf(doorway.p_MHinge - Eigen::Vector2d(reach, reach));
  const auto hi = geometry_.CellOf(doorway.p_MHinge + Eigen::Vector2d(reach, reach));
  RecomputeWindow(lo ? lo->x() : 0, lo ? lo->y() : 0, hi ? hi->x() : geometry_.width - 1,
                  hi ? hi->y() : geometry_.height - 1);
}

void Costmap2D::RecomputeWindow(int x0, int y0, int x1, int y1) {
  // Cells within the inflation radius of the window may change; obstacles within the radius of
  // those cells affect them.
  const int margin =
      static_cast<int>(std::ceil(config_.inflation_radius / geometry_.resolution)) + 1;
  const cv::Rect full(0, 0, geometry_.width, geometry_.height);
  const cv::Rect affected =
      cv::Rect(x0 - margin, y0 - margin, x1 - x0 + 1 + 2 * margin, y1 - y0 + 1 + 2 * margin) & full;
  const cv::Rect source = cv::Rect(affected.x - margin, affected.y - margin,
                                   affected.width + 2 * margin, affected.height + 2 * margin) &
                          full;
  // Distance transform input: 0 at lethal cells, 255 elsewhere.
  cv::Mat free_mask(source.height, source.width, CV_8UC1);
  bool any_lethal = false;
  for (int r = 0; r < source.height; ++r) {
    auto* row = free_mask.ptr<std::uint8_t>(r);
    for (int c = 0; c < source.width; ++c) {
      const std::size_t i = geometry_.Index(source.x + c, source.y + r);
      const bool lethal = static_[i] == kLethalCost || obstacle_[i] == kLethalCost ||
                          projection_[i] == kLethalCost || leaves_[i] == kLethalCost;
      row[c] = lethal ? 0 : 255;
      any_lethal = any_lethal || lethal;
    }
  }
  cv::Mat distance;
  // The 5x5 mask is within 2% of the exact distance and several times faster.
  if (any_lethal) cv::distanceTransform(free_mask, distance, cv::DIST_L2, cv::DIST_MASK_5, CV_32F);
  for (int r = affected.y; r < affected.y + affected.height; ++r) {
    for (int c = affected.x; c < affected.x + affected.width; ++c) {
      const std::size_t i = geometry_.Index(c, r);
      std::uint8_t cost = kFreeCost;
      if (any_lethal) {
        const float cells = distance.at<float>(r - source.y, c - source.x);
        const std::size_t k = static_cast<std::size_t>(cells * kLookupSubdivisions + 0.5f);
        cost = k < inflation_lookup_.size() ? inflation_lookup_[k] : kFreeCost;
        // A known doorway keeps only lethal and inscribed: inflation never seals its threshold.
        if (doorway_zone_[i] != 0 && cost < kInscribedCost) cost = kFreeCost;
      }
      if (cost == kFreeCost && static_[i] == kUnknownCost) cost = kUnknownCost;
      master_[i] = cost;
    }
  }
}

std::uint8_t Costmap2D::CostAt(const Eigen::Vector2d& p_MQ) const {
  const auto cell = geometry_.CellOf(p_MQ);
  return cell ? master_[geometry_.Index(cell->x(), cell->y())] : kUnknownCost;
}

std::uint8_t Costmap2D::FootprintCost(const Pose2& X_MB) const {
  ThrowUnless(X_MB.IsFinite(), "Invalid pose X_MB: must be finite.");
  const Eigen::Vector2d c = X_MB.translation();
  const double r = config_.robot_radius;
  const auto lo = geometry_.CellOf(c - Eigen::Vector2d(r, r));
  const auto hi = geometry_.CellOf(c + Eigen::Vector2d(r, r));
  if (!lo || !hi) return kUnknownCost;
  for (int iy = lo->y(); iy <= hi->y(); ++iy) {
    for (int ix = lo->x(); ix <= hi->x(); ++ix) {
      // Inside the footprint only obstacles matter (inscribed cells there are expected).
      if ((geometry_.CellCenter(ix, iy) - c).norm() <= r &&
          master_[geometry_.Index(ix, iy)] == kLethalCost) {
        return kLethalCost;
      }
    }
  }
  return CostAt(c);
}

cv::Mat Costmap2D::ToImage() const {
  PaintPersonalSpaces();
  cv::Mat image(geometry_.height, geometry_.width, CV_8UC1);
  for (int iy = 0; iy < geometry_.height; ++iy) {
    for (int ix = 0; ix < geometry_.width; ++ix) {
      const std::size_t i = geometry_.Index(ix, iy);
      image.at<std::uint8_t>(geometry_.height - 1 - iy, ix) =
          master_[i] < kInscribedCost ? std::max(master_[i], personal_space_[i]) : master_[i];
    }
  }
  return image;
}

}  // namespace egress::perception
