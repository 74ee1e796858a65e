#include "egress/perception/free_space_motion.h"

#include <cmath>

#include "egress/hsr_interface/error.h"
#include "egress/perception/door_estimation.h"

namespace egress::perception {

void FreeSpaceMotionConfig::Validate() const {
  const auto positive = [](double v, const char* field) {
    ThrowUnless(std::isfinite(v) && v > 0.0, "FreeSpaceMotionConfig: ", field,
                " must be finite and > 0 (got ", v, ")");
  };
  positive(baseline, "baseline");
  positive(margin, "margin");
  positive(max_range, "max_range");
  ThrowUnless(std::isfinite(leave_reach) && leave_reach >= 0.0,
              "FreeSpaceMotionConfig: leave_reach must be finite and >= 0 (got ", leave_reach, ")");
  ThrowUnless(beam_halo >= 0, "FreeSpaceMotionConfig: beam_halo must be >= 0 (got ", beam_halo,
              ")");
  ThrowUnless(min_moved_points >= 1 && min_judged_points >= 1,
              "FreeSpaceMotionConfig: min_moved_points and min_judged_points must be >= 1");
  ThrowUnless(std::isfinite(min_moved_share) && min_moved_share >= 0.0 && min_moved_share <= 1.0,
              "FreeSpaceMotionConfig: min_moved_share must be in [0, 1] (got ", min_moved_share,
              ")");
}

FreeSpaceMotion::FreeSpaceMotion(FreeSpaceMotionConfig config) : config_(config) {
  config_.Validate();
}

void FreeSpaceMotion::AddScan(const LaserScan& scan, const Pose2& X_ML) {
  scan.Validate();
  ThrowUnless(X_ML.IsFinite(), "FreeSpaceMotion: non-finite laser pose");
  ThrowUnless(history_.empty() || scan.stamp >= history_.back().scan.stamp,
              "FreeSpaceMotion: a scan stamped before the last one");
  if (u_L_.size() != scan.ranges.size() || u_angle_min_ != scan.angle_min ||
      u_angle_increment_ != scan.angle_increment) {
    u_L_ = BeamDirections(scan);  // a copy: held scans read them after other lasers' calls
    u_angle_min_ = scan.angle_min;
    u_angle_increment_ = scan.angle_increment;
    // Held scans of another geometry would read the new directions: start again.
    history_.clear();
  }
  const double c = std::cos(X_ML.yaw), sn = std::sin(X_ML.yaw);
  history_.push_back({scan, X_ML, (Eigen::Matrix2d() << c, -sn, sn, c).finished()});
  // Keep the newest scan at least `baseline` older than the latest, and what came after it.
  while (history_.size() >= 2 &&
         ToSeconds(history_.back().scan.stamp - history_[1].scan.stamp) >= config_.baseline)
    history_.pop_front();
}

template <typename Visit>
void FreeSpaceMotion::ForEachReturnNear(const Scan& s, const Eigen::Vector2d& p_C, double radius,
                                        Visit&& visit) const {
  const LaserScan& scan = s.scan;
  const Eigen::Vector2d p_L = s.R_ML.transpose() * (p_C - s.X_ML.translation());
  const double d = p_L.norm();
  if (d - radius > config_.max_range || scan.ranges.empty()) return;
  long first = 0, last = long(scan.ranges.size()) - 1;
  if (d > radius) {
    // The disc's bearings from the laser: its centre's, give or take asin(radius / d).
    const double centre = (std::atan2(p_L.y(), p_L.x()) - scan.angle_min) / scan.angle_increment;
    const double half = std::asin(radius / d) / scan.angle_increment;
    first = std::max(first, long(std::floor(centre - half)));
    last = std::min(last, long(std::ceil(centre + half)));
    // A disc straddling the scan's seam (behind the laser, where a 360-degree scan wraps) is
    // left to its near side: a 270-degree scan has no beams there.
  }
  const double radius2 = radius * radius;
  for (long i = first; i <= last; ++i) {
    const std::size_t k = std::size_t(i);
    if (!scan.IsValidReturn(k) || scan.ranges[k] > config_.max_range) continue;
    const Eigen::Vector2d q = s.X_ML.translation() + s.R_ML * (double(scan.ranges[k]) * u_L_[k]);
    if ((q - p_C).squaredNorm() <= radius2) visit(q);
  }
}

const FreeSpaceMotion::Scan* FreeSpaceMotion::Reference() const {
  if (history_.size() < 2) return nullptr;
  const Scan& oldest = history_.front();
  const double age = ToSeconds(history_.back().scan.stamp - oldest.scan.stamp);
  // Much older than the baseline (a gap in the scans): what moved then says little of now.
  if (age < config_.baseline || age > 3.0 * config_.baseline) return nullptr;
  return &oldest;
}

FreeSpaceMotion::Seen FreeSpaceMotion::SeenBy(const Scan& earlier,
                                              const Eigen::Vector2d& p_M) const {
  const LaserScan& scan = earlier.scan;
  const Eigen::Vector2d p_L = earlier.R_ML.transpose() * (p_M - earlier.X_ML.translation());
  const double r = p_L.norm();
  const double beam =
      std::round((std::atan2(p_L.y(), p_L.x()) - scan.angle_min) / scan.angle_increment);
  const long first = long(beam) - config_.beam_halo, last = long(beam) + config_.beam_halo;
  // Outside the earlier scan's view (its blind sector): not seen at all.
  if (scan.ranges.empty() || first < 0 || last >= long(scan.ranges.size())) return Seen::kHidden;
  bool all_through = true, any_surface = false;
  for (long i = first; i <= last; ++i) {
    const float range = scan.ranges[std::size_t(i)];
    double reach = 0.0;
    if (std::isinf(range) && range > 0.0f) {
      reach = scan.range_max;  // no return: free out to the laser's range
    } else if (scan.IsValidReturn(std::size_t(i))) {
      reach = range;
    } else {
      return Seen::kHidden;  // an invalid beam says nothing
    }
    all_through = all_through && reach > r + config_.margin;
    any_surface = any_surface || std::abs(reach - r) <= config_.margin;
  }
  if (all_through) return Seen::kThrough;
  return any_surface ? Seen::kSurface : Seen::kHidden;
}

PlaceMotion FreeSpaceMotion::Judge(const Eigen::Vector2d& p_M, double radius) const {
  ThrowUnless(p_M.allFinite() && std::isfinite(radius) && radius >= 0.0,
              "FreeSpaceMotion: a non-finite place or radius");
  const Scan* earlier = Reference();
  if (!earlier) return PlaceMotion::kUnknown;
  const Scan& latest = history_.back();
  int moved = 0, judged = 0;
  const auto count = [&](Seen seen) {
    if (seen == Seen::kHidden) return;
    ++judged;
    if (seen == Seen::kThrough) ++moved;
  };
  ForEachReturnNear(latest, p_M, radius,
                    [&](const Eigen::Vector2d& p) { count(SeenBy(*earlier, p)); });
  ForEachReturnNear(*earlier, p_M, radius + config_.leave_reach,
                    [&](const Eigen::Vector2d& q) { count(SeenBy(latest, q)); });
  if (moved >= config_.min_moved_points && moved >= config_.min_moved_share * judged)
    return PlaceMotion::kMoved;
  return judged >= config_.min_judged_points ? PlaceMotion::kStill : PlaceMotion::kUnknown;
}

}  // namespace egress::perception
