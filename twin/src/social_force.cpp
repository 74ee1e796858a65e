#include "egress/twin/social_force.h"

#include "egress/hsr_interface/geometry.h"

#include <algorithm>
#include <cmath>
#include <map>

namespace egress::twin {
namespace {

// Beyond this centre distance another walker (or a disc) exerts no social force [m]; it is also
// the cell size of Step's neighbour grid, so that the 3 x 3 cells round a walker hold everyone
// within it. (At 6 m HM95's term is below 1e-8 of its contact value.)
constexpr double kSocialCutoffM = 6.0;
// Beyond this distance from its nearest point an obstacle exerts no force [m]; the cell size
// of Step's wall lists.
constexpr double kWallCutoffM = 3.0;

}  // namespace

Eigen::Vector2d ClosestPointOnSegment(const Eigen::Vector2d& p, const WallSegment& s) {
  return egress::ClosestPointOnSegment(p, s.a, s.b);
}

// HFV00 contact: compression along the normal and sliding friction along the tangent, only
// while the bodies overlap. Returns a force [N].
Eigen::Vector2d SocialForceModel::BodyForce(const Walker& w, const Eigen::Vector2d& other_p,
                                            const Eigen::Vector2d& other_v, double other_r) const {
  const Eigen::Vector2d d = w.position - other_p;
  const double dist = d.norm();
  const double overlap = w.radius + other_r - dist;
  if (overlap <= 0.0 || dist < 1e-9) return Eigen::Vector2d::Zero();
  const Eigen::Vector2d n = d / dist;
  const Eigen::Vector2d t(-n.y(), n.x());
  const double dv_t = (other_v - w.velocity).dot(t);
  return params_.body_compression * overlap * n + params_.sliding_friction * overlap * dv_t * t;
}

Eigen::Vector2d SocialForceModel::CalcAcceleration(std::size_t i,
                                                   const std::vector<Walker>& walkers,
                                                   const std::vector<DiscObstacle>& discs,
                                                   const std::vector<WallSegment>& walls) const {
  return CalcAccelerationAmong(i, walkers, Neighbours{}, discs, walls);
}

Eigen::Vector2d SocialForceModel::CalcAccelerationAmong(
    std::size_t i, const std::vector<Walker>& walkers, const Neighbours& near,
    const std::vector<DiscObstacle>& discs, const std::vector<WallSegment>& walls) const {
  const Walker& w = walkers[i];
  const auto& P = params_;
  Eigen::Vector2d desired = Eigen::Vector2d::Zero();
  const Eigen::Vector2d to_goal = w.target - w.position;
  if (w.desired_speed > 0.0 && to_goal.norm() > 1e-3) {
    // Slow down over the last half metre so walkers stop at their goal (not at via points).
    const double speed =
        w.final_target ? w.desired_speed * std::min(1.0, to_goal.norm() / 0.5) : w.desired_speed;
    desired = to_goal.normalized() * speed;
  }
  const double tau = w.relaxation_time > 0.0 ? w.relaxation_time : P.relaxation_time;
  Eigen::Vector2d a = P.drive_factor * (desired - w.velocity) / tau;
  const Eigen::Vector2d heading =
      w.velocity.norm() > 0.05 ? Eigen::Vector2d(w.velocity.normalized())
                               : (to_goal.norm() > 1e-3 ? Eigen::Vector2d(to_goal.normalized())
                                                        : Eigen::Vector2d::UnitX());
  const double cos_fov = std::cos(P.field_of_view_deg * M_PI / 360.0);
  auto weight = [&](const Eigen::Vector2d& force_dir) {
    // A force pointing along −heading comes from something ahead (in view).
    return -force_dir.dot(heading) >= cos_fov ? 1.0 : P.behind_weight;
  };
  auto social = [&](const Eigen::Vector2d& other_p, const Eigen::Vector2d& other_v, double strength,
                    double range) {
    // HM95 elliptical potential: b is the semi-minor axis of the ellipse through i with foci
    // at the other's position and its position one step (Δt) ahead.
    const Eigen::Vector2d r = w.position - other_p;
    const Eigen::Vector2d step = other_v * P.social_horizon;
    const double r_norm = r.norm();
    if (r_norm < 1e-6 || r_norm > kSocialCutoffM) return Eigen::Vector2d(Eigen::Vector2d::Zero());
    const double s = r_norm + (r - step).norm();
    const double b = 0.5 * std::sqrt(std::max(s * s - step.squaredNorm(), 1e-12));
    const Eigen::Vector2d n = r / r_norm;
    Eigen::Vector2d f = (strength / range) * std::exp(-b / range) * n;
    // Turn part of it to the walker's right when the other is ahead: people keep right.
    if (n.dot(heading) < 0.0)
      f += P.keep_right * f.norm() * Eigen::Vector2d(heading.y(), -heading.x());
    return Eigen::Vector2d(f * weight(f.normalized()));
  };
  const std::size_t others = near.walkers ? near.walkers->size() : walkers.size();
  for (std::size_t k = 0; k < others; ++k) {
    const std::size_t j = near.walkers ? (*near.walkers)[k] : k;
    if (j == i) continue;
    const Walker& o = walkers[j];
    // Social terms scale with the drive (their balance is what HM95 tuned); walls do not.
    a += social(o.position, o.velocity, P.drive_factor * P.social_strength, P.social_range);
    a += BodyForce(w, o.position, o.velocity, o.radius) / P.mass;
  }
  for (const auto& d : discs) {
    a += social(d.position, d.velocity, P.drive_factor * P.robot_strength, P.robot_range);
    a += BodyForce(w, d.position, d.velocity, d.radius) / P.mass;
  }
  // The nearest point of each obstacle (or of each loose segment) repels. Obstacles are summed
  // in the order of their first segment in `walls`, whichever segments are near.
  struct Nearest {
    std::size_t rank;
    int id;
    Eigen::Vector2d q;
  };
  thread_local std::vector<Nearest> nearest;
  nearest.clear();
  const std::size_t candidates = near.walls ? near.walls->size() : walls.size();
  for (std::size_t k = 0; k < candidates; ++k) {
    const std::size_t s = near.walls ? (*near.walls)[k] : k;
    const WallSegment& wall = walls[s];
    const Eigen::Vector2d q = ClosestPointOnSegment(w.position, wall);
    auto it = wall.obstacle < 0 ? nearest.end()
                                : std::find_if(nearest.begin(), nearest.end(), [&](const auto& e) {
                                    return e.id == wall.obstacle;
                                  });
    if (it == nearest.end()) {
      nearest.push_back({near.wall_rank ? (*near.wall_rank)[s] : s, wall.obstacle, q});
    } else if ((w.position - q).squaredNorm() < (w.position - it->q).squaredNorm()) {
      it->q = q;
    }
  }
  if (near.wall_rank)
    std::sort(nearest.begin(), nearest.end(),
              [](const Nearest& a, const Nearest& b) { return a.rank < b.rank; });
  for (const Nearest& e : nearest) {
    const Eigen::Vector2d r = w.position - e.q;
    const double dist = r.norm();
    if (dist < 1e-9 || dist > kWallCutoffM) continue;
    const Eigen::Vector2d n = r / dist;
    const double gap = dist - w.radius;
    Eigen::Vector2d f =
        w.wall_scale * (P.wall_strength / P.wall_range) * std::exp(-gap / P.wall_range) * n;
    if (gap < 0.0) {
      const Eigen::Vector2d t(-n.y(), n.x());
      f += (P.body_compression * -gap * n - P.sliding_friction * -gap * w.velocity.dot(t) * t) /
           P.mass;
    }
    a += f;
  }
  const double a_norm = a.norm();
  if (a_norm > P.max_acceleration) a *= P.max_acceleration / a_norm;
  return a;
}

void SocialForceModel::Step(std::vector<Walker>* walkers, const std::vector<DiscObstacle>& discs,
                            const std::vector<WallSegment>& walls, double dt) const {
  // A uniform grid of kSocialCutoffM cells (a cell list): each walker meets only the walkers
  // of the 3 x 3 cells round it, in ascending index as over the whole crowd, so the sums (and
  // the run) are the same as without the grid, in O(n) instead of O(n^2).
  const std::vector<Walker>& all = *walkers;
  std::vector<Eigen::Vector2d> accelerations(all.size());
  std::map<std::pair<long, long>, std::vector<std::size_t>> cells;
  const auto cell_of = [](const Eigen::Vector2d& p) {
    return std::pair<long, long>(long(std::floor(p.x() / kSocialCutoffM)),
                                 long(std::floor(p.y() / kSocialCutoffM)));
  };
  for (std::size_t i = 0; i < all.size(); ++i)
    cells[cell_of(all[i].position)].push_back(i);
  // Walls in cells of kWallCutoffM: each segment is listed in every cell its bounding box,
  // grown by the cutoff, overlaps, so a walker's own cell lists every segment within reach.
  const auto wall_cell_of = [](double x, double y) {
    return std::pair<long, long>(long(std::floor(x / kWallCutoffM)),
                                 long(std::floor(y / kWallCutoffM)));
  };
  std::map<std::pair<long, long>, std::vector<std::size_t>> wall_cells;
  std::vector<std::size_t> wall_rank(walls.size());
  std::map<int, std::size_t> first_of_obstacle;
  for (std::size_t s = 0; s < walls.size(); ++s) {
    const WallSegment& wall = walls[s];
    wall_rank[s] =
        wall.obstacle < 0 ? s : first_of_obstacle.emplace(wall.obstacle, s).first->second;
    const Eigen::Vector2d lo = wall.a.cwiseMin(wall.b).array() - kWallCutoffM;
    const Eigen::Vector2d hi = wall.a.cwiseMax(wall.b).array() + kWallCutoffM;
    if (!lo.allFinite() || !hi.allFinite()) continue;
    const auto [x0, y0] = wall_cell_of(lo.x(), lo.y());
    const auto [x1, y1] = wall_cell_of(hi.x(), hi.y());
    for (long cx = x0; cx <= x1; ++cx)
      for (long cy = y0; cy <= y1; ++cy)
        wall_cells[{cx, cy}].push_back(s);
  }
  const std::vector<std::size_t> no_walls;
  std::vector<std::size_t> near;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const auto [cx, cy] = cell_of(all[i].position);
    near.clear();
    for (long dx = -1; dx <= 1; ++dx) {
      for (long dy = -1; dy <= 1; ++dy) {
        const auto it = cells.find({cx + dx, cy + dy});
        if (it != cells.end()) near.insert(near.end(), it->second.begin(), it->second.end());
      }
    }
    std::sort(near.begin(), near.end());
    const auto walls_here = wall_cells.find(wall_cell_of(all[i].position.x(), all[i].position.y()));
    const Neighbours neighbours{
        &near, walls_here != wall_cells.end() ? &walls_here->second : &no_walls, &wall_rank};
    accelerations[i] = CalcAccelerationAmong(i, all, neighbours, discs, walls);
  }
  for (std::size_t i = 0; i < walkers->size(); ++i) {
    Walker& w = (*walkers)[i];
    w.velocity += accelerations[i] * dt;
    const double v_max = params_.max_speed_factor * std::max(w.desired_speed, 0.3);
    if (w.velocity.norm() > v_max) w.velocity *= v_max / w.velocity.norm();
    if (w.desired_speed == 0.0 && w.velocity.norm() < 0.02) w.velocity.setZero();
    w.position += w.velocity * dt;
  }
}

}  // namespace egress::twin
