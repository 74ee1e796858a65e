#include "egress/perception/scan_motion.h"

#include <algorithm>
#include <cmath>

#include "egress/hsr_interface/error.h"

namespace egress::perception {

void ScanMotionConfig::Validate() const {
  ThrowUnless(std::isfinite(window) && window > 0.0, "ScanMotionConfig: window must be > 0 (got ",
              window, ")");
  ThrowUnless(std::isfinite(step) && std::isfinite(reach) && step > 0.0 && step < reach,
              "ScanMotionConfig: need 0 < step < reach (got step ", step, ", reach ", reach, ")");
  ThrowUnless(std::isfinite(still_distance) && std::isfinite(still_angle) &&
                  still_distance >= 0.0 && still_angle >= 0.0,
              "ScanMotionConfig: still_distance and still_angle must be >= 0");
  ThrowUnless(std::isfinite(max_range) && max_range > 0.0,
              "ScanMotionConfig: max_range must be > 0 (got ", max_range, ")");
}

ScanMotion::ScanMotion(ScanMotionConfig config) : config_(config) {
  config_.Validate();
}

const std::vector<Eigen::Vector2d>& ScanMotion::Update(Time stamp, const Pose2& X_ML,
                                                       std::vector<Eigen::Vector2d> p_MR) {
  ThrowUnless(history_.empty() || stamp >= history_.back().stamp,
              "ScanMotion: a scan stamped before the last one");
  ThrowUnless(X_ML.IsFinite(), "ScanMotion: non-finite laser pose");
  // Seen from elsewhere, the earlier scans say nothing about motion: start again from here.
  if (!history_.empty()) {
    const Pose2& ref = history_.front().X_ML;
    if ((ref.translation() - X_ML.translation()).norm() > config_.still_distance ||
        std::abs(std::remainder(ref.yaw - X_ML.yaw, 2 * M_PI)) > config_.still_angle)
      history_.clear();
  }
  // The reference: the newest scan at least `window` old (older ones are dropped).
  while (history_.size() >= 2 && ToSeconds(stamp - history_[1].stamp) >= config_.window)
    history_.pop_front();
  moving_.clear();
  if (!history_.empty() && ToSeconds(stamp - history_.front().stamp) >= config_.window &&
      ToSeconds(stamp - history_.front().stamp) <= 3 * config_.window) {
    const std::vector<Eigen::Vector2d>& before = history_.front().p_MR;
    const double step2 = config_.step * config_.step;
    const double reach2 = config_.reach * config_.reach;
    const auto near = [](const std::vector<Eigen::Vector2d>& points, const Eigen::Vector2d& p,
                         double r2) {
      return std::any_of(points.begin(), points.end(),
                         [&](const Eigen::Vector2d& q) { return (p - q).squaredNorm() <= r2; });
    };
    // The earlier returns with no return near them now: where something left.
    std::vector<Eigen::Vector2d> left;
    for (const Eigen::Vector2d& q : before)
      if (!near(p_MR, q, step2)) left.push_back(q);
    const double range2 = config_.max_range * config_.max_range;
    for (const Eigen::Vector2d& p : p_MR)
      if ((p - X_ML.translation()).squaredNorm() <= range2 && !near(before, p, step2) &&
          near(left, p, reach2))
        moving_.push_back(p);
  }
  history_.push_back({stamp, X_ML, std::move(p_MR)});
  return moving_;
}

}  // namespace egress::perception
