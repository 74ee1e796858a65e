#include "egress/behavior/head_gaze.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "egress/hsr_interface/error.h"

namespace egress::behavior {
namespace {
constexpr double kDegToRad = M_PI / 180.0;
// [rad] A door whose centre is within this of the robot's heading is ahead of it.
constexpr double kDoorAheadRad = M_PI / 2;
}  // namespace

void HeadGazeConfig::Validate() const {
  ThrowUnless(camera_hfov_deg > 0 && camera_hfov_deg < 180,
              "HeadGazeConfig: camera_hfov_deg must be in (0, 180)");
  ThrowUnless(glance_range >= 0 && approach_speed >= 0 && glance_time >= 0 &&
                  glance_cooldown >= 0 && door_look_range >= 0 && door_look_beyond >= 0,
              "HeadGazeConfig: ranges, speeds and times must be >= 0");
  ThrowUnless(door_open_fraction >= 0 && door_open_fraction <= 1,
              "HeadGazeConfig: door_open_fraction must be in [0, 1]");
  ThrowUnless(max_pan_deg >= 0 && max_pan_deg <= 180 && min_change_deg >= 0,
              "HeadGazeConfig: max_pan_deg must be in [0, 180], min_change_deg >= 0");
  ThrowUnless(max_tilt_down_deg >= 0 && max_tilt_down_deg <= 90 && max_tilt_up_deg >= 0 &&
                  max_tilt_up_deg <= 90,
              "HeadGazeConfig: max_tilt_down_deg and max_tilt_up_deg must be in [0, 90]");
}

HeadGaze::HeadGaze(HeadGazeConfig config) : config_(config) {
  config_.Validate();
}

double HeadGaze::PanTowards(const Pose2& X_MB, const Eigen::Vector2d& p_M) const {
  const Eigen::Vector2d d = p_M - X_MB.translation();
  const double bearing = std::remainder(std::atan2(d.y(), d.x()) - X_MB.yaw, 2 * M_PI);
  const double limit = config_.max_pan_deg * kDegToRad;
  return std::clamp(bearing, -limit, limit);
}

double HeadGaze::TiltTowards(const Pose3& X_MC, const Eigen::Vector3d& p_M) const {
  const Eigen::Vector3d d = p_M - X_MC.translation();
  const double tilt = std::atan2(d.z(), std::max(d.head<2>().norm(), 1e-3));
  return std::clamp(tilt, -config_.max_tilt_down_deg * kDegToRad,
                    config_.max_tilt_up_deg * kDegToRad);
}

void HeadGaze::RequestLook(const Eigen::Vector3d& p_M, Time until) {
  ThrowUnless(p_M.allFinite(), "HeadGaze::RequestLook: the point must be finite");
  requested_ = p_M;
  requested_until_ = until;
}

std::optional<HeadCommand> HeadGaze::Update(const Belief& belief, std::optional<double> pan_now) {
  if (!config_.enabled) return std::nullopt;
  const Pose2& X_MB = belief.X_MB;
  const Eigen::Vector2d at = X_MB.translation();
  const double half_fov = config_.camera_hfov_deg * kDegToRad / 2;
  const double looking = pan_now.value_or(commanded_pan_);

  std::optional<double> pan;
  double tilt = 0.0;
  GazeReason reason = GazeReason::kAhead;
  // 1. A glance under way goes on while its person is still tracked.
  if (glance_id_ >= 0 && belief.now < glance_until_) {
    for (const auto& entry : belief.world.people) {
      if (entry.person.id == glance_id_) {
        pan = PanTowards(X_MB, entry.person.p_MP);
        reason = GazeReason::kPerson;
      }
    }
  }
  if (!pan) {
    glance_id_ = -1;
    // The nearest person coming towards the robot from outside the camera's view.
    double nearest = config_.glance_range;
    for (const auto& entry : belief.world.people) {
      const auto& person = entry.person;
      const Eigen::Vector2d d = person.p_MP - at;
      const double distance = d.norm();
      if (distance >= nearest || distance < 1e-6) continue;
      const double closing = -person.v_MP.dot(d / distance);
      if (closing < config_.approach_speed) continue;
      const double bearing = PanTowards(X_MB, person.p_MP);
      if (std::abs(std::remainder(bearing - looking, 2 * M_PI)) < half_fov) continue;
      if (const auto it = glanced_at_.find(person.id);
          it != glanced_at_.end() &&
          ToSeconds(belief.now - it->second) < config_.glance_time + config_.glance_cooldown)
        continue;
      nearest = distance;
      glance_id_ = person.id;
      pan = bearing;
      reason = GazeReason::kPerson;
    }
    if (glance_id_ >= 0) {
      glanced_at_[glance_id_] = belief.now;
      glance_until_ = belief.now + SecondsToDuration(config_.glance_time);
    }
  }
  // 2. What the task asked for.
  if (!pan && requested_ && belief.now < requested_until_) {
    pan = PanTowards(X_MB, requested_->head<2>());
    tilt = TiltTowards(belief.X_MC, *requested_);
    reason = GazeReason::kTask;
  }
  // 3. Through the nearest door that is open or opening.
  if (!pan) {
    double nearest = config_.door_look_range;
    for (const auto& door : belief.world.doors) {
      if (!door.state.observed || door.state.open_fraction < config_.door_open_fraction) continue;
      const Eigen::Vector2d centre = (door.model.p_MHinge + door.model.p_MLatch) / 2;
      const double distance = (centre - at).norm();
      if (distance >= nearest) continue;
      // A door behind the robot (passed through, or beside it) is not where it is going.
      const Eigen::Vector2d to_centre = centre - at;
      const double bearing =
          std::remainder(std::atan2(to_centre.y(), to_centre.x()) - X_MB.yaw, 2 * M_PI);
      if (std::abs(bearing) > kDoorAheadRad) continue;
      const Eigen::Vector2d along = (door.model.p_MLatch - door.model.p_MHinge).normalized();
      Eigen::Vector2d n(-along.y(), along.x());
      if (n.dot(at - centre) < 0) n = -n;  // towards the robot's side
      nearest = distance;
      pan = PanTowards(X_MB, centre - n * config_.door_look_beyond);
      reason = GazeReason::kDoor;
    }
  }
  if (!pan) pan = 0.0;
  reason_ = reason;
  for (auto it = glanced_at_.begin(); it != glanced_at_.end();) {
    const bool stale =
        ToSeconds(belief.now - it->second) > config_.glance_time + config_.glance_cooldown;
    it = stale ? glanced_at_.erase(it) : std::next(it);
  }
  const double min_change = config_.min_change_deg * kDegToRad;
  if (sent_ && std::abs(*pan - commanded_pan_) < min_change &&
      std::abs(tilt - commanded_tilt_) < min_change)
    return std::nullopt;
  sent_ = true;
  commanded_pan_ = *pan;
  commanded_tilt_ = tilt;
  return HeadCommand{*pan, tilt};
}

}  // namespace egress::behavior
