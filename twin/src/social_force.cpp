#include "egress/twin/social_force.h"

#include "egress/hsr_interface/error.h"
#include "egress/hsr_interface/geometry.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <map>

namespace egress::twin {
namespace {

// A social term is dropped where it is below this fraction of its value at contact (b = 0): past
// b = σ ln(1 / fraction), 2.1 m for HM95's σ = 0.3 m. Dropping the far terms is what lets a
// walker meet only the walkers near it.
constexpr double kSocialNegligibleFraction = 1e-3;
// Two bodies closer than this may touch [m] (a wheelchair and a pushed one: well under 1 m).
constexpr double kMaxBodyReachM = 1.0;

// The ellipse's semi-minor axis b beyond which a social term of range σ is dropped [m].
double NegligibleBeyond(double range) {
  return range * std::log(1.0 / kSocialNegligibleFraction);
}

}  // namespace

Eigen::Vector2d ClosestPointOnSegment(const Eigen::Vector2d& p, const WallSegment& s) {
  return egress::ClosestPointOnSegment(p, s.a, s.b);
}

bool SegmentsCross(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                   const Eigen::Vector2d& d) {
  const auto cross = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) {
    return u.x() * v.y() - u.y() * v.x();
  };
  const double d1 = cross(b - a, c - a), d2 = cross(b - a, d - a);
  const double d3 = cross(d - c, a - c), d4 = cross(d - c, b - c);
  return d1 * d2 <= 0.0 && d3 * d4 <= 0.0;
}

// HFV00 contact: compression along the normal and sliding friction along the tangent, only
// while the bodies overlap. Returns a force [N].
Eigen::Vector2d SocialForceModel::BodyForce(const Walker& w, const Eigen::Vector2d& other_p,
                                            const Eigen::Vector2d& other_v, double other_r) const {
  const Eigen::Vector2d d = w.position - other_p;
  const double reach = w.radius + other_r;
  if (d.squaredNorm() >= reach * reach) return Eigen::Vector2d::Zero();  // apart: no sqrt
  const double dist = d.norm();
  const double overlap = reach - dist;
  if (overlap <= 0.0 || dist < 1e-9) return Eigen::Vector2d::Zero();
  const Eigen::Vector2d n = d / dist;
  const Eigen::Vector2d t(-n.y(), n.x());
  const double dv_t = (other_v - w.velocity).dot(t);
  return params_.body_compression * overlap * n + params_.sliding_friction * overlap * dv_t * t;
}

SocialForceModel::Reach SocialForceModel::WalkerReach(const Walker& o) const {
  // The ellipse of the cutoff, semi-minor axis b_max with foci at o and one step ahead, lies
  // within sqrt(b_max² + (step / 2)²) of its centre. A hair more than that, so rounding never
  // drops a term the sum over everyone keeps.
  const Eigen::Vector2d step = o.velocity * params_.social_horizon;
  const double b_max = NegligibleBeyond(params_.social_range);
  const double radius = std::sqrt(b_max * b_max + 0.25 * step.squaredNorm());
  return {o.position + 0.5 * step, radius * (1.0 + 1e-9) + 1e-9};
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
  return ClampAcceleration(CalcTermsAmong(i, walkers, near, discs, walls, Terms::kAll,
                                          CalcDriveAcceleration(walkers[i])));
}

Eigen::Vector2d SocialForceModel::ClampAcceleration(const Eigen::Vector2d& a) const {
  const double a_norm = a.norm();
  return a_norm > params_.max_acceleration
             ? Eigen::Vector2d(a * (params_.max_acceleration / a_norm))
             : a;
}

Eigen::Vector2d SocialForceModel::CalcDriveAcceleration(const Walker& w) const {
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
  return P.drive_factor * (desired - w.velocity) / tau;
}

Eigen::Vector2d SocialForceModel::CalcTermsAmong(std::size_t i, const std::vector<Walker>& walkers,
                                                 const Neighbours& near,
                                                 const std::vector<DiscObstacle>& discs,
                                                 const std::vector<WallSegment>& walls, Terms terms,
                                                 Eigen::Vector2d a) const {
  const Walker& w = walkers[i];
  const auto& P = params_;
  const bool social_terms = terms != Terms::kContact;
  const bool contact_terms = terms != Terms::kSocial;
  const Eigen::Vector2d to_goal = w.target - w.position;
  const Eigen::Vector2d heading =
      w.velocity.norm() > 0.05 ? Eigen::Vector2d(w.velocity.normalized())
                               : (to_goal.norm() > 1e-3 ? Eigen::Vector2d(to_goal.normalized())
                                                        : Eigen::Vector2d::UnitX());
  const double cos_fov = cos_half_fov_;
  const double cos_fov_squared = cos_fov * cos_fov;
  auto weight = [&](const Eigen::Vector2d& force) {
    // A force pointing along −heading comes from something ahead (in view): −f·h ≥ cos·|f|,
    // compared squared, without the square root (its latency was a fifth of the pair terms'
    // time), by the signs of both sides.
    const double ahead = -force.dot(heading);
    const double ahead_squared = ahead * ahead;
    const double bound_squared = cos_fov_squared * force.squaredNorm();
    const bool in_view = cos_fov >= 0.0 ? ahead >= 0.0 && ahead_squared >= bound_squared
                                        : ahead >= 0.0 || ahead_squared <= bound_squared;
    return in_view ? 1.0 : P.behind_weight;
  };
  auto social = [&](const Eigen::Vector2d& other_p, const Eigen::Vector2d& other_v, double strength,
                    double range) {
    // HM95 elliptical potential: b is the semi-minor axis of the ellipse through i with foci
    // at the other's position and its position one step (Δt) ahead.
    const Eigen::Vector2d r = w.position - other_p;
    const Eigen::Vector2d step = other_v * P.social_horizon;
    const double r_norm = r.norm();
    if (r_norm < 1e-6) return Eigen::Vector2d(Eigen::Vector2d::Zero());
    const double s = r_norm + (r - step).norm();
    const double b = 0.5 * std::sqrt(std::max(s * s - step.squaredNorm(), 1e-12));
    if (b > NegligibleBeyond(range)) return Eigen::Vector2d(Eigen::Vector2d::Zero());
    const Eigen::Vector2d n = r / r_norm;
    Eigen::Vector2d f = (strength / range) * std::exp(-b / range) * n;
    // Turn part of it to the walker's right when the other is ahead: people keep right.
    if (n.dot(heading) < 0.0)
      f += P.keep_right * f.norm() * Eigen::Vector2d(heading.y(), -heading.x());
    return Eigen::Vector2d(f * weight(f));
  };
  const std::size_t others = near.walkers ? near.walkers->size() : walkers.size();
  for (std::size_t k = 0; k < others; ++k) {
    const std::size_t j = near.walkers ? (*near.walkers)[k] : k;
    if (j == i) continue;
    const Walker& o = walkers[j];
    // Beyond its reach (and touching distance) another walker does nothing: no square roots.
    bool social_near = false;
    if (social_terms) {
      const Reach reach = near.reach ? (*near.reach)[j] : WalkerReach(o);
      social_near = (w.position - reach.social_centre).squaredNorm() <=
                    reach.social_radius * reach.social_radius;
    }
    if (!social_near && (w.position - o.position).squaredNorm() > kMaxBodyReachM * kMaxBodyReachM)
      continue;
    // Social terms scale with the drive (their balance is what HM95 tuned); walls do not.
    if (social_near)
      a += social(o.position, o.velocity, P.drive_factor * P.social_strength, P.social_range);
    if (contact_terms) a += BodyForce(w, o.position, o.velocity, o.radius) / P.mass;
  }
  for (const auto& d : discs) {
    if (social_terms)
      a += social(d.position, d.velocity, P.drive_factor * P.robot_strength, P.robot_range);
    if (contact_terms) a += BodyForce(w, d.position, d.velocity, d.radius) / P.mass;
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
  // Beyond this no segment counts (the wall cutoff; contact alone: the body's radius). In a
  // cell's list (by rank: an obstacle's fixed segments together, its rank whichever of them
  // comes first) a segment whose bounding box lies farther is skipped unmeasured: its nearest
  // point would be farther still, so it could neither be its obstacle's nearest that counts nor
  // count itself (the margin keeps the box's rounding on the safe side).
  constexpr double kSkipMarginM = 1e-9;
  // Beyond this from its nearest point an obstacle exerts no force (its term is negligible).
  const double wall_cutoff = w.radius + NegligibleBeyond(P.wall_range);
  const double reach = (social_terms ? wall_cutoff : w.radius) + kSkipMarginM;
  const double reach_squared = reach * reach;
  for (std::size_t k = 0; k < candidates; ++k) {
    const std::size_t s = near.walls ? (*near.walls)[k] : k;
    const bool fixed = s < walls.size();
    const WallSegment& wall = fixed ? walls[s] : (*near.moving)[s - walls.size()];
    const bool listed_by_rank = fixed && near.walls && near.wall_rank;
    if (listed_by_rank && (wall.a.cwiseMin(wall.b) - w.position)
                                  .cwiseMax(w.position - wall.a.cwiseMax(wall.b))
                                  .cwiseMax(0.0)
                                  .squaredNorm() > reach_squared)
      continue;
    const Eigen::Vector2d q = ClosestPointOnSegment(w.position, wall);
    // Contact alone: only an obstacle the body overlaps pushes, from its nearest point, which
    // is then among the segments it overlaps.
    if (!social_terms && (w.position - q).squaredNorm() >= w.radius * w.radius) continue;
    // In a cell's list, an obstacle's entry, if any, is the last one made.
    auto it = wall.obstacle < 0 ? nearest.end()
              : listed_by_rank
                  ? (!nearest.empty() && nearest.back().id == wall.obstacle ? nearest.end() - 1
                                                                            : nearest.end())
                  : std::find_if(nearest.begin(), nearest.end(),
                                 [&](const auto& e) { return e.id == wall.obstacle; });
    if (it == nearest.end()) {
      const bool ranked = near.wall_rank && s < near.wall_rank->size();
      nearest.push_back({ranked ? (*near.wall_rank)[s] : s, wall.obstacle, q});
    } else if ((w.position - q).squaredNorm() < (w.position - it->q).squaredNorm()) {
      it->q = q;
    }
  }
  // WallCells lists a cell's segments by rank already (few sums need the sort).
  const auto by_rank = [](const Nearest& a, const Nearest& b) { return a.rank < b.rank; };
  if (near.wall_rank && !std::is_sorted(nearest.begin(), nearest.end(), by_rank))
    std::sort(nearest.begin(), nearest.end(), by_rank);
  for (const Nearest& e : nearest) {
    const Eigen::Vector2d r = w.position - e.q;
    const double dist = r.norm();
    if (dist < 1e-9 || dist > wall_cutoff) continue;
    const Eigen::Vector2d n = r / dist;
    const double gap = dist - w.radius;
    Eigen::Vector2d f = Eigen::Vector2d::Zero();
    if (social_terms)
      f = w.wall_scale * (P.wall_strength / P.wall_range) * std::exp(-gap / P.wall_range) * n;
    if (contact_terms && gap < 0.0) {
      const Eigen::Vector2d t(-n.y(), n.x());
      f += (P.body_compression * -gap * n - P.sliding_friction * -gap * w.velocity.dot(t) * t) /
           P.mass;
    }
    a += f;
  }
  return a;
}

namespace {
// The cells of WallCells [m]: smaller than the reach, so that a walker's cell lists few walls
// beyond it.
constexpr double kWallCellM = 1.0;
std::pair<long, long> WallCellOf(double x, double y) {
  return {long(std::floor(x / kWallCellM)), long(std::floor(y / kWallCellM))};
}
}  // namespace

double SocialForceModel::WallReach() const {
  return kMaxBodyReachM + NegligibleBeyond(params_.wall_range);
}

WallCells::WallCells(std::vector<WallSegment> walls, double reach)
    : walls_(std::move(walls)), reach_(reach) {
  ThrowUnless(std::isfinite(reach) && reach > 0.0, "WallCells: the reach must be positive (got ",
              reach, " m)");
  // Each segment is listed in every cell its bounding box, grown by the reach, overlaps, so a
  // walker's own cell lists every segment within reach.
  rank_.resize(walls_.size());
  std::map<int, std::size_t> first_of_obstacle;
  for (std::size_t s = 0; s < walls_.size(); ++s) {
    const WallSegment& wall = walls_[s];
    rank_[s] = wall.obstacle < 0 ? s : first_of_obstacle.emplace(wall.obstacle, s).first->second;
    const Eigen::Vector2d lo = wall.a.cwiseMin(wall.b).array() - reach_;
    const Eigen::Vector2d hi = wall.a.cwiseMax(wall.b).array() + reach_;
    if (!lo.allFinite() || !hi.allFinite()) continue;
    const auto [x0, y0] = WallCellOf(lo.x(), lo.y());
    const auto [x1, y1] = WallCellOf(hi.x(), hi.y());
    for (long cx = x0; cx <= x1; ++cx)
      for (long cy = y0; cy <= y1; ++cy)
        cells_[{cx, cy}].push_back(s);
    // The same within touching distance: the segments a body in the cell may press against.
    const Eigen::Vector2d touch_lo = wall.a.cwiseMin(wall.b).array() - kMaxBodyReachM;
    const Eigen::Vector2d touch_hi = wall.a.cwiseMax(wall.b).array() + kMaxBodyReachM;
    const auto [tx0, ty0] = WallCellOf(touch_lo.x(), touch_lo.y());
    const auto [tx1, ty1] = WallCellOf(touch_hi.x(), touch_hi.y());
    for (long cx = tx0; cx <= tx1; ++cx)
      for (long cy = ty0; cy <= ty1; ++cy)
        touching_cells_[{cx, cy}].push_back(s);
  }
  // Each cell's segments by rank (an obstacle's together, in index order): a walker's nearest
  // points come out in the order they are summed in, without sorting them.
  const auto by_rank = [&](std::size_t a, std::size_t b) {
    return std::pair(rank_[a], a) < std::pair(rank_[b], b);
  };
  for (auto* cells : {&cells_, &touching_cells_})
    for (auto& [cell, segments] : *cells)
      std::sort(segments.begin(), segments.end(), by_rank);
}

const std::vector<std::size_t>& WallCells::NearTouching(const Eigen::Vector2d& p) const {
  const auto it = touching_cells_.find(WallCellOf(p.x(), p.y()));
  return it != touching_cells_.end() ? it->second : none_;
}

const std::vector<std::size_t>& WallCells::Near(const Eigen::Vector2d& p) const {
  const auto it = cells_.find(WallCellOf(p.x(), p.y()));
  return it != cells_.end() ? it->second : none_;
}

void SocialForceModel::Step(std::vector<Walker>* walkers, const std::vector<DiscObstacle>& discs,
                            const std::vector<WallSegment>& walls, double dt) const {
  Step(walkers, discs, WallCells(walls, WallReach()), {}, dt);
}

void SocialForceModel::Step(std::vector<Walker>* walkers, const std::vector<DiscObstacle>& discs,
                            const WallCells& fixed, const std::vector<WallSegment>& moving,
                            double dt) const {
  Integrate(walkers, CalcAccelerations(*walkers, discs, fixed, moving), dt, discs);
}

std::vector<Eigen::Vector2d> SocialForceModel::CalcAccelerations(
    const std::vector<Walker>& all, const std::vector<DiscObstacle>& discs, const WallCells& fixed,
    const std::vector<WallSegment>& moving) const {
  return SumTerms(all, discs, fixed, moving, Terms::kAll, nullptr);
}

std::vector<Eigen::Vector2d> SocialForceModel::CalcSocialAccelerations(
    const std::vector<Walker>& all, const std::vector<DiscObstacle>& discs, const WallCells& fixed,
    const std::vector<WallSegment>& moving) const {
  return SumTerms(all, discs, fixed, moving, Terms::kSocial, nullptr);
}

std::vector<Eigen::Vector2d> SocialForceModel::CalcAccelerationsWithSocial(
    const std::vector<Eigen::Vector2d>& social, const std::vector<Walker>& all,
    const std::vector<DiscObstacle>& discs, const WallCells& fixed,
    const std::vector<WallSegment>& moving) const {
  ThrowUnless(social.size() == all.size(), "SocialForceModel: ", social.size(),
              " social accelerations for ", all.size(), " walkers");
  return SumTerms(all, discs, fixed, moving, Terms::kContact, &social);
}

std::vector<Eigen::Vector2d> SocialForceModel::SumTerms(
    const std::vector<Walker>& all, const std::vector<DiscObstacle>& discs, const WallCells& fixed,
    const std::vector<WallSegment>& moving, Terms terms,
    const std::vector<Eigen::Vector2d>* social) const {
  // A uniform grid over the walkers: each cell lists, in ascending index, every walker whose
  // reach (the box round its social circle and touching distance) overlaps the cell, so a walker
  // meets only those that may reach it, in the order of the whole crowd: the sums (and the run) are
  // the same as without the grid, in O(n) instead of O(n^2).
  ThrowUnless(fixed.reach() >= WallReach() - 1e-9, "SocialForceModel: the walls are binned for ",
              fixed.reach(), " m, but reach ", WallReach(), " m with wall_range ",
              params_.wall_range, " m (build WallCells with WallReach())");
  std::vector<Eigen::Vector2d> accelerations(all.size(), Eigen::Vector2d::Zero());
  const bool contact_only = terms == Terms::kContact;
  std::vector<Reach> reach(all.size());
  for (std::size_t j = 0; j < all.size(); ++j)
    reach[j] = contact_only ? Reach{all[j].position, 0.0} : WalkerReach(all[j]);
  // The grid spans the walkers' bounding box (a crowd spans tens of metres at most). Walkers that
  // are not finite, or a box too large to hold densely, make it one cell (everyone meets
  // everyone in it, as without the grid).
  constexpr double kCellM = kMaxBodyReachM;
  constexpr double kMaxGridCells = 1 << 20;
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  bool finite = true;
  for (std::size_t j = 0; j < all.size(); ++j) {
    finite = finite && all[j].position.allFinite() && reach[j].social_centre.allFinite() &&
             std::isfinite(reach[j].social_radius);
    lo = lo.cwiseMin(all[j].position);
    hi = hi.cwiseMax(all[j].position);
  }
  const double span_x = (hi.x() - lo.x()) / kCellM + 1.0, span_y = (hi.y() - lo.y()) / kCellM + 1.0;
  const bool dense = finite && !all.empty() && span_x * span_y < kMaxGridCells;
  const long nx = dense ? long(span_x) + 1 : 1, ny = dense ? long(span_y) + 1 : 1;
  const auto cell_x = [&](double x) {
    return dense ? std::clamp(long(std::floor((x - lo.x()) / kCellM)), 0L, nx - 1) : 0L;
  };
  const auto cell_y = [&](double y) {
    return dense ? std::clamp(long(std::floor((y - lo.y()) / kCellM)), 0L, ny - 1) : 0L;
  };
  // Each walker's reach as a block of cells [x0, x1] x [y0, y1]; then the lists by counting sort.
  thread_local std::vector<std::array<long, 4>> blocks;
  thread_local std::vector<std::size_t> start, fill, members;
  blocks.resize(all.size());
  start.assign(std::size_t(nx * ny) + 1, 0);
  for (std::size_t j = 0; j < all.size(); ++j) {
    const Eigen::Vector2d& p = all[j].position;
    // The box round both: the social circle and touching distance (contact alone: the latter).
    const Eigen::Vector2d& c = reach[j].social_centre;
    const double r = reach[j].social_radius;
    blocks[j] = {cell_x(std::min(c.x() - r, p.x() - kMaxBodyReachM)),
                 cell_x(std::max(c.x() + r, p.x() + kMaxBodyReachM)),
                 cell_y(std::min(c.y() - r, p.y() - kMaxBodyReachM)),
                 cell_y(std::max(c.y() + r, p.y() + kMaxBodyReachM))};
    const auto& [x0, x1, y0, y1] = blocks[j];
    for (long y = y0; y <= y1; ++y)
      for (long x = x0; x <= x1; ++x)
        ++start[std::size_t(y * nx + x) + 1];
  }
  for (std::size_t c = 1; c < start.size(); ++c)
    start[c] += start[c - 1];
  fill.assign(start.begin(), start.end() - 1);
  members.resize(start.back());
  for (std::size_t j = 0; j < all.size(); ++j) {
    const auto& [x0, x1, y0, y1] = blocks[j];
    for (long y = y0; y <= y1; ++y)
      for (long x = x0; x <= x1; ++x)
        members[fill[std::size_t(y * nx + x)]++] = j;
  }
  // The fixed walls, then the moving ones (few: every walker meets each).
  const std::vector<WallSegment>& walls = fixed.walls();
  std::vector<std::size_t> near_walls, near;
  for (std::size_t i = 0; i < all.size(); ++i) {
    // A held walker's sum would be thrown away, but for its social terms alone: held between
    // sums, they are what it sets off with if its hold ends before the next sum.
    if (all[i].held && terms != Terms::kSocial) continue;  // zero
    const Eigen::Vector2d& p = all[i].position;
    const std::size_t c = std::size_t(cell_y(p.y()) * nx + cell_x(p.x()));
    near.assign(members.begin() + long(start[c]), members.begin() + long(start[c + 1]));
    const std::vector<std::size_t>& fixed_near =
        terms == Terms::kContact ? fixed.NearTouching(p) : fixed.Near(p);
    near_walls.assign(fixed_near.begin(), fixed_near.end());
    for (std::size_t k = 0; k < moving.size(); ++k)
      near_walls.push_back(walls.size() + k);
    const Neighbours neighbours{&near, &near_walls, &fixed.rank(), contact_only ? nullptr : &reach,
                                &moving};
    switch (terms) {
      case Terms::kAll:
        accelerations[i] = CalcAccelerationAmong(i, all, neighbours, discs, walls);
        break;
      case Terms::kSocial:
        accelerations[i] =
            CalcTermsAmong(i, all, neighbours, discs, walls, terms, Eigen::Vector2d::Zero());
        break;
      case Terms::kContact:
        accelerations[i] = ClampAcceleration(CalcTermsAmong(
            i, all, neighbours, discs, walls, terms, CalcDriveAcceleration(all[i]) + (*social)[i]));
        break;
    }
  }
  return accelerations;
}

Eigen::Vector2d SocialForceModel::CapApproach(const Walker& w, const DiscObstacle& d) const {
  // The cap is the speed one can brake from over the gap left (from afar it is above any
  // walker's top speed: the social terms keep walkers off the disc there).
  const Eigen::Vector2d to_disc = d.position - w.position;
  const double dist = to_disc.norm();
  if (dist < 1e-9) return w.velocity;
  const Eigen::Vector2d n = to_disc / dist;
  const double gap = std::max(dist - w.radius - d.radius - params_.disc_keep_gap, 0.0);
  const double cap = std::sqrt(2.0 * params_.disc_braking_deceleration * gap);
  const double own = w.velocity.dot(n);  // the walker's own speed towards the disc
  const double excess = std::min((w.velocity - d.velocity).dot(n) - cap, own);
  // Only the walker's approach is taken away: it is not made to back off a disc coming at it.
  return excess > 0.0 ? Eigen::Vector2d(w.velocity - excess * n) : w.velocity;
}

void SocialForceModel::Integrate(std::vector<Walker>* walkers,
                                 const std::vector<Eigen::Vector2d>& accelerations, double dt,
                                 const std::vector<DiscObstacle>& discs) const {
  for (std::size_t i = 0; i < walkers->size(); ++i) {
    Walker& w = (*walkers)[i];
    if (w.held) continue;
    w.velocity += accelerations[i] * dt;
    const double v_max = params_.max_speed_factor * std::max(w.desired_speed, 0.3);
    if (w.velocity.norm() > v_max) w.velocity *= v_max / w.velocity.norm();
    for (const DiscObstacle& d : discs)
      w.velocity = CapApproach(w, d);
    if (w.desired_speed == 0.0 && w.velocity.norm() < 0.02) w.velocity.setZero();
    w.position += w.velocity * dt;
  }
}

}  // namespace egress::twin
