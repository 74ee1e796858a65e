#include "egress/perception/door_estimation.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <random>

#include <Eigen/Eigenvalues>

#include "egress/hsr_interface/error.h"

namespace egress::perception {

double DoorModel::closed_yaw() const {
  const Eigen::Vector2d d = p_MLatch - p_MHinge;
  return std::atan2(d.y(), d.x());
}

Eigen::Vector2d DoorModel::LeafTip(double angle) const {
  const double yaw = closed_yaw() + swing_sign * angle;
  return p_MHinge + width() * Eigen::Vector2d(std::cos(yaw), std::sin(yaw));
}

bool DoorModel::InSweep(const Eigen::Vector2d& p_MQ, double margin) const {
  const Eigen::Vector2d offset = p_MQ - p_MHinge;
  return offset.norm() <= width() + margin && offset.dot(SwingSide()) > -margin;
}

bool DoorModel::InLeafReach(const Eigen::Vector2d& p_MQ, double margin) const {
  const Eigen::Vector2d offset = p_MQ - p_MHinge;
  const double r = offset.norm();
  if (r > width() + margin) return false;
  if (r <= margin) return true;
  // The angle from the closed leaf towards the swing side, and the angle `margin` spans at r.
  const Eigen::Vector2d along = (p_MLatch - p_MHinge).normalized();
  const double angle = std::atan2(offset.dot(SwingSide()), offset.dot(along));
  const double slack = std::asin(margin / r);
  return angle >= -slack && angle <= max_open_angle + slack;
}

bool DoorModel::OnDoorLine(const Eigen::Vector2d& p_MQ, double margin) const {
  const Eigen::Vector2d along = (p_MLatch - p_MHinge).normalized();
  const Eigen::Vector2d offset = p_MQ - p_MHinge;
  const double s = offset.dot(along);
  return s >= 0.0 && s <= width() &&
         std::abs(along.x() * offset.y() - along.y() * offset.x()) <= margin;
}

Eigen::Vector2d DoorModel::SwingSide() const {
  const Eigen::Vector2d along = (p_MLatch - p_MHinge).normalized();
  return swing_sign * Eigen::Vector2d(-along.y(), along.x());
}

double DoorModel::ClearanceWidth(double angle) const {
  const double a = std::clamp(angle, 0.0, std::numbers::pi / 2);
  return width() * (1.0 - std::cos(a));
}

void DoorModel::Validate() const {
  ThrowUnless(p_MHinge.allFinite() && p_MLatch.allFinite() && width() > 0.05, "Invalid door '", id,
              "': jambs must be finite and at least 5 cm apart.");
  ThrowUnless(swing_sign == 1.0 || swing_sign == -1.0, "Invalid door '", id,
              "': swing_sign must be +1 or -1.");
  ThrowUnless(max_open_angle > 0.0 && max_open_angle <= std::numbers::pi, "Invalid door '", id,
              "': max_open_angle must be in (0, pi].");
}

std::optional<LineFit> FitLineRansac(const std::vector<Eigen::Vector2d>& points,
                                     const LineFitConfig& config) {
  if (points.size() < std::max<std::size_t>(2, config.min_inliers)) return std::nullopt;
  std::mt19937_64 random(config.seed);
  std::uniform_int_distribution<std::size_t> pick(0, points.size() - 1);
  std::vector<std::size_t> best;
  for (int it = 0; it < config.iterations; ++it) {
    const std::size_t i = pick(random), j = pick(random);
    const Eigen::Vector2d d = points[j] - points[i];
    if (i == j || d.norm() < 1e-6) continue;
    const Eigen::Vector2d normal = Eigen::Vector2d(-d.y(), d.x()).normalized();
    std::vector<std::size_t> inliers;
    for (std::size_t k = 0; k < points.size(); ++k) {
      if (std::abs((points[k] - points[i]).dot(normal)) <= config.inlier_distance)
        inliers.push_back(k);
    }
    if (inliers.size() > best.size()) best = std::move(inliers);
  }
  if (best.size() < config.min_inliers) return std::nullopt;
  // Least squares on the inliers: the principal direction of their scatter.
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (std::size_t k : best)
    mean += points[k];
  mean /= double(best.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (std::size_t k : best)
    scatter += (points[k] - mean) * (points[k] - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(scatter);
  LineFit fit;
  fit.p_M = mean;
  fit.direction = eigen.eigenvectors().col(1).normalized();
  fit.inliers = best.size();
  const Eigen::Vector2d normal(-fit.direction.y(), fit.direction.x());
  double sum = 0.0;
  for (std::size_t k : best)
    sum += std::pow((points[k] - mean).dot(normal), 2);
  fit.rms = std::sqrt(sum / double(best.size()));
  return fit;
}

std::pair<double, double> BoxBearingsInLaser(const PixelBox& box,
                                             const CameraIntrinsics& intrinsics,
                                             const Pose3& X_LC) {
  intrinsics.Validate();
  ThrowUnless(X_LC.IsFinite(), "Invalid camera pose X_LC: must be finite.");
  const double v = (box.v_min + box.v_max) / 2;
  const auto bearing = [&](double u) {
    const Eigen::Vector3d ray_C((u - intrinsics.cx) / intrinsics.fx,
                                (v - intrinsics.cy) / intrinsics.fy, 1.0);
    const Eigen::Vector3d ray_L = X_LC.rotation() * ray_C;
    return std::atan2(ray_L.y(), ray_L.x());
  };
  const double a = bearing(box.u_min), b = bearing(box.u_max);
  return {std::min(a, b), std::max(a, b)};
}

std::vector<Eigen::Vector2d> ScanPointsInBearings(const LaserScan& scan, const Pose2& X_ML,
                                                  double bearing_min, double bearing_max) {
  scan.Validate();
  ThrowUnless(X_ML.IsFinite(), "Invalid laser pose X_ML: must be finite.");
  const std::vector<Eigen::Vector2d>& u_L = BeamDirections(scan);
  const Eigen::Matrix2d R_ML = X_ML.rotation();
  const Eigen::Vector2d p_ML = X_ML.translation();
  std::vector<Eigen::Vector2d> points;
  points.reserve(scan.ranges.size());
  for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
    const double angle = scan.AngleAt(i);
    if (angle < bearing_min || angle > bearing_max || !scan.IsValidReturn(i)) continue;
    points.push_back(R_ML * (scan.ranges[i] * u_L[i]) + p_ML);
  }
  return points;
}

const std::vector<Eigen::Vector2d>& BeamDirections(const LaserScan& scan) {
  struct Cache {
    double angle_min{0.0}, angle_increment{0.0};
    std::vector<Eigen::Vector2d> u_L;
  };
  thread_local Cache cache;
  // Compared bit for bit: a scan of another shape (NaN angles included) is computed afresh.
  if (cache.u_L.size() != scan.ranges.size() ||
      std::memcmp(&cache.angle_min, &scan.angle_min, sizeof(double)) != 0 ||
      std::memcmp(&cache.angle_increment, &scan.angle_increment, sizeof(double)) != 0) {
    cache.angle_min = scan.angle_min;
    cache.angle_increment = scan.angle_increment;
    cache.u_L.clear();
    cache.u_L.reserve(scan.ranges.size());
    for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
      const double angle = scan.AngleAt(i);
      cache.u_L.emplace_back(std::cos(angle), std::sin(angle));
    }
  }
  return cache.u_L;
}

std::vector<Eigen::Vector2d> ScanPoints(const LaserScan& scan, const Pose2& X_ML) {
  return ScanPointsInBearings(scan, X_ML, -std::numeric_limits<double>::infinity(),
                              std::numeric_limits<double>::infinity());
}

std::optional<DoorAngleMeasurement> MeasureDoorAngle(const DoorModel& door,
                                                     const std::vector<Eigen::Vector2d>& p_MPoints,
                                                     std::size_t min_support) {
  door.Validate();
  constexpr double kMargin = 10.0 * std::numbers::pi / 180.0;
  const double w = door.width();
  // A leaf is a segment from the hinge: its points share a polar angle and spread along the
  // radius. Anything else in the sector (a person in the doorway, a leg, a bag) shares an angle
  // over a short radial stretch only. Vote per angle bin, keep the bin (with its neighbours)
  // whose points reach furthest along the radius, and take the median angle there.
  constexpr double kBin = 3.0 * std::numbers::pi / 180.0;
  struct Vote {
    double phi, r;
  };
  std::vector<Vote> votes;
  for (const auto& p : p_MPoints) {
    if (!p.allFinite()) continue;
    const Eigen::Vector2d d = p - door.p_MHinge;
    const double r = d.norm();
    if (r < 0.15 * w || r > 0.95 * w) continue;
    const double phi = door.swing_sign * WrapAngle(std::atan2(d.y(), d.x()) - door.closed_yaw());
    if (phi < -kMargin || phi > door.max_open_angle + kMargin) continue;
    votes.push_back({phi, r});
  }
  if (votes.size() < std::max<std::size_t>(1, min_support)) return std::nullopt;
  const int bins = int(std::ceil((door.max_open_angle + 2 * kMargin) / kBin)) + 1;
  std::vector<double> r_min(std::size_t(bins), 1e9), r_max(std::size_t(bins), -1e9);
  std::vector<int> count(std::size_t(bins), 0);
  const auto bin_of = [&](double phi) {
    return std::clamp(int((phi + kMargin) / kBin), 0, bins - 1);
  };
  for (const Vote& v : votes) {
    const auto b = std::size_t(bin_of(v.phi));
    r_min[b] = std::min(r_min[b], v.r);
    r_max[b] = std::max(r_max[b], v.r);
    ++count[b];
  }
  int best = -1;
  double best_extent = -1.0;
  for (int b = 0; b < bins; ++b) {
    double lo = 1e9, hi = -1e9;
    int n = 0;
    for (int k = std::max(0, b - 1); k <= std::min(bins - 1, b + 1); ++k) {
      if (count[std::size_t(k)] == 0) continue;
      lo = std::min(lo, r_min[std::size_t(k)]);
      hi = std::max(hi, r_max[std::size_t(k)]);
      n += count[std::size_t(k)];
    }
    if (n == 0) continue;
    const double extent = hi - lo + 1e-3 * n;  // ties: more points
    if (extent > best_extent) {
      best_extent = extent;
      best = b;
    }
  }
  // A leaf seen over less than a quarter of its width is not told from a person's outline.
  if (best < 0 || best_extent < 0.25 * w) return std::nullopt;
  std::vector<double> chosen;
  for (const Vote& v : votes) {
    if (std::abs(bin_of(v.phi) - best) <= 1) chosen.push_back(v.phi);
  }
  if (chosen.size() < std::max<std::size_t>(1, min_support)) return std::nullopt;
  auto middle = chosen.begin() + std::ptrdiff_t(chosen.size() / 2);
  std::nth_element(chosen.begin(), middle, chosen.end());
  return DoorAngleMeasurement{std::clamp(*middle, 0.0, door.max_open_angle), chosen.size()};
}

std::optional<double> DoorAngleFromLine(const DoorModel& door, const LineFit& line,
                                        double hinge_tolerance) {
  door.Validate();
  const Eigen::Vector2d from_hinge = line.p_M - door.p_MHinge;
  const double off_line =
      std::abs(from_hinge.x() * line.direction.y() - from_hinge.y() * line.direction.x());
  const double w = door.width();
  if (off_line > hinge_tolerance || from_hinge.norm() > 1.2 * w || from_hinge.norm() < w / 8)
    return std::nullopt;
  // The line's direction is ambiguous by pi; take the orientation pointing away from the hinge.
  Eigen::Vector2d direction = line.direction;
  if (from_hinge.dot(direction) < 0.0) direction = -direction;
  const double phi =
      door.swing_sign * WrapAngle(std::atan2(direction.y(), direction.x()) - door.closed_yaw());
  constexpr double kMargin = 10.0 * std::numbers::pi / 180.0;
  if (phi < -kMargin || phi > door.max_open_angle + kMargin) return std::nullopt;
  return std::clamp(phi, 0.0, door.max_open_angle);
}

std::optional<double> DoorAngleFromBearings(const DoorModel& door, const Pose2& X_MV,
                                            std::optional<double> lo, std::optional<double> hi,
                                            double max_error) {
  door.Validate();
  ThrowUnless(X_MV.IsFinite(), "Invalid viewpoint X_MV: must be finite.");
  if (!lo && !hi) return std::nullopt;
  const Pose2 X_VM = X_MV.Inverse();
  const auto bearing = [&](const Eigen::Vector2d& p_M) {
    const Eigen::Vector2d p_V = X_VM * p_M;
    return std::atan2(p_V.y(), p_V.x());
  };
  const double hinge = bearing(door.p_MHinge);
  constexpr double kStep = std::numbers::pi / 180.0;
  // One box edge within this of the hinge's bearing is the hinge's own: any angle with the free
  // edge on the cut side explains it (a few degrees: detector noise, the leaf's thickness).
  constexpr double kHingeEdgeMargin = 6.0 * std::numbers::pi / 180.0;  // [rad]
  std::vector<std::pair<double, double>> errors;                       // (angle, error)
  std::optional<double> best;
  double best_error = std::numeric_limits<double>::infinity();
  bool best_tip_is_lo = false;
  for (double angle = 0.0; angle <= door.max_open_angle + 1e-9; angle += kStep) {
    const double tip = bearing(door.LeafTip(angle));
    double error = 0.0;
    if (lo) error += std::abs(*lo - std::min(tip, hinge));
    if (hi) error += std::abs(*hi - std::max(tip, hinge));
    errors.emplace_back(angle, error);
    if (error < best_error) {
      best_error = error;
      best = angle;
      best_tip_is_lo = tip < hinge;
    }
  }
  // Seen from some places a leaf projects alike at quite different angles (near its plane,
  // or close to the swing side): then the box says nothing.
  constexpr double kAmbiguity = 0.05;                             // [rad]
  constexpr double kMaxSpread = 10.0 * std::numbers::pi / 180.0;  // [rad]
  for (const auto& [angle, error] : errors) {
    if (best && error <= best_error + kAmbiguity && std::abs(angle - *best) > kMaxSpread)
      return std::nullopt;
  }
  if (!best || best_error > max_error) return std::nullopt;
  if (lo && hi) return best;
  const double edge = lo ? *lo : *hi;
  if (std::abs(edge - hinge) < kHingeEdgeMargin || best_tip_is_lo != lo.has_value())
    return std::nullopt;
  return best;
}

std::string_view ToString(DoorMotion motion) {
  switch (motion) {
    case DoorMotion::kUnknown:
      return "unknown";
    case DoorMotion::kClosed:
      return "closed";
    case DoorMotion::kOpening:
      return "opening";
    case DoorMotion::kOpen:
      return "open";
    case DoorMotion::kHeldOpen:
      return "held_open";
    case DoorMotion::kClosing:
      return "closing";
  }
  return "unknown";
}

DoorStateTracker::DoorStateTracker(DoorModel door, DoorStateConfig config)
    : door_(std::move(door)), config_(config) {
  door_.Validate();
  ThrowUnless(config_.smoothing > 0.0 && config_.smoothing <= 1.0,
              "Invalid DoorStateConfig: smoothing must be in (0, 1].");
  ThrowUnless(config_.stale_after > 0.0,
              "Invalid DoorStateConfig: stale_after must be positive [s].");
}

bool DoorStateTracker::IsStaleAt(Time now) const {
  return state_.observed && ToSeconds(now - state_.stamp) > config_.stale_after;
}

void DoorStateTracker::Update(double angle, Time stamp) {
  ThrowUnless(std::isfinite(angle), "Invalid door angle for '", door_.id, "': must be finite.");
  angle = std::clamp(angle, 0.0, door_.max_open_angle);
  if (state_.observed)
    ThrowUnless(stamp >= state_.stamp, "Invalid door measurement for '", door_.id,
                "': time went backwards.");
  if (!state_.observed || IsStaleAt(stamp)) {
    state_.angle = angle;
    state_.rate = 0.0;
    state_.steady_for = 0.0;
  } else {
    const double dt = ToSeconds(stamp - state_.stamp);
    const double previous = state_.angle;
    state_.angle += config_.smoothing * (angle - state_.angle);
    if (dt > 0.0) state_.rate += config_.smoothing * ((state_.angle - previous) / dt - state_.rate);
    state_.steady_for = std::abs(state_.rate) < config_.motion_rate ? state_.steady_for + dt : 0.0;
  }
  state_.observed = true;
  state_.stamp = stamp;
  state_.open_fraction = std::clamp(state_.angle / door_.max_open_angle, 0.0, 1.0);
  state_.clearance_width = door_.ClearanceWidth(state_.angle);
  if (state_.rate > config_.motion_rate) {
    state_.motion = DoorMotion::kOpening;
  } else if (state_.rate < -config_.motion_rate) {
    state_.motion = DoorMotion::kClosing;
  } else if (state_.angle < config_.closed_angle) {
    state_.motion = DoorMotion::kClosed;
  } else {
    state_.motion =
        state_.steady_for >= config_.held_after ? DoorMotion::kHeldOpen : DoorMotion::kOpen;
  }
}

}  // namespace egress::perception
