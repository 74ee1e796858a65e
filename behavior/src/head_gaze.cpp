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
// [s] A glance kept on someone in the laser's blind sector is renewed by this much at a time.
constexpr double kGlanceRenewSec = 0.2;

// The unit normal of `door`'s line pointing to the side p_M is on.
Eigen::Vector2d NormalTowards(const perception::DoorModel& door, const Eigen::Vector2d& p_M) {
  const Eigen::Vector2d along = (door.p_MLatch - door.p_MHinge).normalized();
  const Eigen::Vector2d n(-along.y(), along.x());
  return n.dot(p_M - (door.p_MHinge + door.p_MLatch) / 2) < 0 ? Eigen::Vector2d(-n) : n;
}
}  // namespace

void HeadGazeConfig::Validate() const {
  ThrowUnless(camera_hfov_deg > 0 && camera_hfov_deg < 180,
              "HeadGazeConfig: camera_hfov_deg must be in (0, 180)");
  ThrowUnless(glance_range >= 0 && approach_speed >= 0 && glance_time >= 0 &&
                  glance_cooldown >= 0 && max_blind_glance >= 0 && door_look_range >= 0 &&
                  door_look_beyond >= 0 && approach_look_range >= 0,
              "HeadGazeConfig: ranges, speeds and times must be >= 0");
  ThrowUnless(door_open_fraction >= 0 && door_open_fraction <= 1,
              "HeadGazeConfig: door_open_fraction must be in [0, 1]");
  ThrowUnless(min_pan_deg <= 0 && min_pan_deg >= -360 && max_pan_deg >= 0 && max_pan_deg <= 360 &&
                  min_change_deg >= 0,
              "HeadGazeConfig: min_pan_deg must be in [-360, 0], max_pan_deg in [0, 360], "
              "min_change_deg >= 0");
  ThrowUnless(wall_ahead_range >= 0 && blind_look_pan_deg >= min_pan_deg &&
                  blind_look_pan_deg <= max_pan_deg,
              "HeadGazeConfig: wall_ahead_range must be >= 0, blind_look_pan_deg within "
              "[min_pan_deg, max_pan_deg]");
  ThrowUnless(max_tilt_down_deg >= 0 && max_tilt_down_deg <= 90 && max_tilt_up_deg >= 0 &&
                  max_tilt_up_deg <= 90,
              "HeadGazeConfig: max_tilt_down_deg and max_tilt_up_deg must be in [0, 90]");
}

HeadGaze::HeadGaze(HeadGazeConfig config) : config_(config) {
  config_.Validate();
}

double HeadGaze::PanTowards(const Pose2& X_MB, const Eigen::Vector2d& p_M, double looking) const {
  const Eigen::Vector2d d = p_M - X_MB.translation();
  const double bearing = std::remainder(std::atan2(d.y(), d.x()) - X_MB.yaw, 2 * M_PI);
  const double lo = config_.min_pan_deg * kDegToRad;
  const double hi = config_.max_pan_deg * kDegToRad;
  std::optional<double> best;
  for (const double pan : {bearing - 2 * M_PI, bearing, bearing + 2 * M_PI}) {
    if (pan < lo || pan > hi) continue;
    if (!best || std::abs(pan - looking) < std::abs(*best - looking)) best = pan;
  }
  if (best) return *best;
  // Out of reach: the limit nearer the bearing, round the circle.
  return std::abs(std::remainder(bearing - lo, 2 * M_PI)) <
                 std::abs(std::remainder(bearing - hi, 2 * M_PI))
             ? lo
             : hi;
}

double HeadGaze::TiltTowards(const Pose3& X_MC, const Eigen::Vector3d& p_M) const {
  const Eigen::Vector3d d = p_M - X_MC.translation();
  const double tilt = std::atan2(d.z(), std::max(d.head<2>().norm(), 1e-3));
  return std::clamp(tilt, -config_.max_tilt_down_deg * kDegToRad,
                    config_.max_tilt_up_deg * kDegToRad);
}

bool HeadGaze::WallAhead(const Belief& belief) const {
  if (!belief.scan || config_.wall_ahead_range <= 0) return false;
  const LaserScan& scan = *belief.scan;
  const double half_fov = config_.camera_hfov_deg * kDegToRad / 2;
  int returns = 0;
  for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
    const double bearing = std::remainder(scan.AngleAt(i) + belief.X_BL.yaw, 2 * M_PI);
    if (std::abs(bearing) > half_fov) continue;
    const double range = scan.ranges[i];
    if (std::isnan(range)) continue;  // an invalid beam says nothing
    // No return (open space) or a far one: there is something to see ahead.
    if (!(range < config_.wall_ahead_range && range <= scan.range_max)) return false;
    ++returns;
  }
  return returns > 0;
}

bool HeadGaze::InLaserBlindSector(const Belief& belief, const Eigen::Vector2d& p_M) const {
  if (!belief.scan || belief.scan->ranges.empty()) return false;
  const Eigen::Vector2d d = p_M - belief.X_MB.translation();
  const double bearing_L =
      std::remainder(std::atan2(d.y(), d.x()) - belief.X_MB.yaw - belief.X_BL.yaw, 2 * M_PI);
  return bearing_L < belief.scan->angle_min || bearing_L > belief.scan->angle_max();
}

std::optional<Eigen::Vector2d> HeadGaze::NearestBehind(const Belief& belief) const {
  std::optional<Eigen::Vector2d> nearest;
  double nearest_distance = config_.glance_range;
  for (const auto& entry : belief.world.people) {
    const double distance = (entry.person.p_MP - belief.X_MB.translation()).norm();
    if (distance < nearest_distance && InLaserBlindSector(belief, entry.person.p_MP)) {
      nearest_distance = distance;
      nearest = entry.person.p_MP;
    }
  }
  return nearest;
}

double HeadGaze::BehindPan(const Belief& belief, double looking) const {
  if (const auto person = NearestBehind(belief)) return PanTowards(belief.X_MB, *person, looking);
  const double fallback = config_.blind_look_pan_deg * kDegToRad;
  if (watch_behind_door_.empty() || !belief.scan || belief.scan->ranges.empty()) return fallback;
  const auto door = std::find_if(belief.world.doors.begin(), belief.world.doors.end(),
                                 [&](const auto& d) { return d.model.id == watch_behind_door_; });
  if (door == belief.world.doors.end()) return fallback;
  const Eigen::Vector2d at = belief.X_MB.translation();
  const Eigen::Vector2d centre = (door->model.p_MHinge + door->model.p_MLatch) / 2;
  const Eigen::Vector2d d =
      centre + NormalTowards(door->model, at) * config_.approach_look_range - at;
  // The blind sector in the base frame runs anticlockwise from the scan's last beam to its
  // first; a bearing the laser sees is brought to the nearer edge.
  const double yaw_L = belief.X_BL.yaw;
  const double from = belief.scan->angle_max() + yaw_L;
  const double width = 2 * M_PI - (belief.scan->angle_max() - belief.scan->angle_min);
  if (width <= 0) return fallback;
  double into = std::atan2(d.y(), d.x()) - belief.X_MB.yaw - from;
  into -= 2 * M_PI * std::floor(into / (2 * M_PI));  // in [0, 2 pi)
  if (into > width) into = into - width < 2 * M_PI - into ? width : 0.0;
  const double bearing = from + into;
  const Eigen::Vector2d towards(std::cos(belief.X_MB.yaw + bearing),
                                std::sin(belief.X_MB.yaw + bearing));
  return PanTowards(belief.X_MB, at + towards, looking);
}

void HeadGaze::ExpectOpening(const std::string& door, Time until) {
  expected_opening_[door] = until;
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
      if (entry.person.id != glance_id_) continue;
      pan = PanTowards(X_MB, entry.person.p_MP, looking);
      reason = GazeReason::kPerson;
      // Someone still coming in the laser's blind sector has only the camera: the glance goes
      // on, up to max_blind_glance, so their track keeps being measured (a track coasting on a
      // glance's first, still-converging velocity read a walker at 1.3 m/s as 0.5).
      const Eigen::Vector2d d = entry.person.p_MP - at;
      if (d.norm() > 1e-6 && -entry.person.v_MP.dot(d.normalized()) >= config_.approach_speed &&
          InLaserBlindSector(belief, entry.person.p_MP) &&
          ToSeconds(belief.now - glance_began_) < config_.max_blind_glance) {
        glance_until_ = std::max(glance_until_, belief.now + SecondsToDuration(kGlanceRenewSec));
        glance_ended_[glance_id_] = glance_until_;
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
      const double bearing = PanTowards(X_MB, person.p_MP, looking);
      // One in view needs no glance, but for one in the laser's blind sector: the camera
      // alone measures them, and a door opening ahead would take the head off them.
      if (std::abs(std::remainder(bearing - looking, 2 * M_PI)) < half_fov &&
          !InLaserBlindSector(belief, person.p_MP))
        continue;
      if (const auto it = glance_ended_.find(person.id);
          it != glance_ended_.end() && ToSeconds(belief.now - it->second) < config_.glance_cooldown)
        continue;
      nearest = distance;
      glance_id_ = person.id;
      pan = bearing;
      reason = GazeReason::kPerson;
    }
    if (glance_id_ >= 0) {
      glance_began_ = belief.now;
      glance_until_ = belief.now + SecondsToDuration(config_.glance_time);
      glance_ended_[glance_id_] = glance_until_;
    }
  }
  // 2. What the task asked for.
  if (!pan && requested_ && belief.now < requested_until_) {
    pan = PanTowards(X_MB, requested_->head<2>(), looking);
    tilt = TiltTowards(belief.X_MC, *requested_);
    reason = GazeReason::kTask;
  }
  // 3. Through the nearest door that is open or opening.
  if (!pan) {
    // Someone tracked in the laser's blind sector keeps the head behind until the door really
    // opens (P1: people waiting there set off as the robot presses), and while the robot is at
    // the actuator watching behind (rule 4), even then (P4 seed 2073: the head turned to the
    // opening door, and the one waiting behind set off unseen).
    const bool someone_behind = NearestBehind(belief).has_value();
    const bool keep_behind = someone_behind && belief.now < watch_behind_until_;
    double nearest = config_.door_look_range;
    // (Watched behind: no door is looked through.)
    for (const auto& door : belief.world.doors) {
      if (keep_behind) break;
      const auto expected = expected_opening_.find(door.model.id);
      const bool operated =
          expected != expected_opening_.end() && belief.now < expected->second && !someone_behind;
      if (!operated &&
          (!door.state.observed || door.state.open_fraction < config_.door_open_fraction))
        continue;
      const Eigen::Vector2d centre = (door.model.p_MHinge + door.model.p_MLatch) / 2;
      const double distance = (centre - at).norm();
      if (distance >= nearest) continue;
      // A door behind the robot (passed through, or beside it) is not where it is going.
      const Eigen::Vector2d to_centre = centre - at;
      const double bearing =
          std::remainder(std::atan2(to_centre.y(), to_centre.x()) - X_MB.yaw, 2 * M_PI);
      if (std::abs(bearing) > kDoorAheadRad) continue;
      nearest = distance;
      pan = PanTowards(X_MB, centre - NormalTowards(door.model, at) * config_.door_look_beyond,
                       looking);
      reason = GazeReason::kDoor;
    }
  }
  // 4. Behind, at an actuator with only a wall to see ahead.
  if (!pan && belief.now < watch_behind_until_ && WallAhead(belief)) {
    pan = BehindPan(belief, looking);
    reason = GazeReason::kBehind;
  }
  if (!pan) pan = 0.0;
  reason_ = reason;
  for (auto it = glance_ended_.begin(); it != glance_ended_.end();) {
    const bool stale = ToSeconds(belief.now - it->second) > config_.glance_cooldown;
    it = stale ? glance_ended_.erase(it) : std::next(it);
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
