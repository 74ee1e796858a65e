#include "egress/perception/person_tracker.h"

#include <algorithm>
#include <cmath>

#include "egress/hsr_interface/error.h"
#include "nearest_first_association.h"

namespace egress::perception {

std::string_view ToString(PersonIntent intent) {
  switch (intent) {
    case PersonIntent::kUnknown:
      return "unknown";
    case PersonIntent::kStationary:
      return "stationary";
    case PersonIntent::kApproaching:
      return "approaching";
    case PersonIntent::kCrossing:
      return "crossing";
    case PersonIntent::kWalkingPast:
      return "walking_past";
    case PersonIntent::kHoldingDoor:
      return "holding_door";
  }
  return "unknown";
}

void PersonTrackerConfig::Validate() const {
  ThrowUnless(alpha > 0.0 && alpha <= 1.0, "Invalid PersonTrackerConfig: alpha (", alpha,
              ") must be in (0, 1].");
  ThrowUnless(gate_distance > 0.0, "Invalid PersonTrackerConfig: gate_distance must be > 0.");
  ThrowUnless(
      drop_misses >= 1 && forecast_steps >= 0 && forecast_dt > 0.0,
      "Invalid PersonTrackerConfig: drop_misses >= 1, forecast_steps >= 0, forecast_dt > 0.");
}

PersonTracker::PersonTracker(PersonTrackerConfig config) : config_(config) {
  config_.Validate();
}

void PersonTracker::Update(const std::vector<Eigen::Vector2d>& p_MDetections, Time stamp) {
  for (const auto& p : p_MDetections)
    ThrowUnless(p.allFinite(), "Invalid person position: must be finite.");
  ThrowUnless(!has_stamp_ || stamp >= last_stamp_, "Invalid person update: time went backwards.");
  const double dt = has_stamp_ ? ToSeconds(stamp - last_stamp_) : 0.0;
  last_stamp_ = stamp;
  has_stamp_ = true;
  // Predict, then associate each detection to the nearest predicted person within the gate.
  std::vector<Eigen::Vector2d> predicted;
  for (const TrackedPerson& person : people_)
    predicted.push_back(person.p_MP + person.v_MP * dt);
  const internal::Association match = internal::AssociateNearestFirst(
      people_.size(), p_MDetections.size(), config_.gate_distance,
      [&](std::size_t t, std::size_t k) { return (p_MDetections[k] - predicted[t]).norm(); });
  const std::vector<bool>& used_t = match.track_matched;
  const std::vector<bool>& used_k = match.detection_matched;
  const double a = config_.alpha;
  for (const auto& [t, k] : match.pairs) {
    TrackedPerson& person = people_[t];
    const Eigen::Vector2d previous = person.p_MP;
    // The paper's filter: exponential smoothing of position and of velocity (alpha = 0.3). The
    // velocity smooths what the detections say (this one against the track's last one), not the
    // smoothed positions: differencing those smooths twice (gain alpha² on the velocity's
    // error), and a person who has just set off read as a third of their speed for a second.
    person.p_MP = a * p_MDetections[k] + (1.0 - a) * (previous + person.v_MP * dt);
    const double measured_dt = ToSeconds(stamp - person.last_seen);
    if (measured_dt > 0.0) {
      person.v_MP =
          a * (p_MDetections[k] - person.p_MMeasured) / measured_dt + (1.0 - a) * person.v_MP;
    }
    person.p_MMeasured = p_MDetections[k];
    ++person.hits;
    person.misses = 0;
    person.last_seen = stamp;
  }
  for (std::size_t t = 0; t < people_.size(); ++t) {
    if (used_t[t]) continue;
    people_[t].p_MP += people_[t].v_MP * dt;  // coast on the last velocity
    ++people_[t].misses;
  }
  std::erase_if(people_, [&](const TrackedPerson& p) { return p.misses >= config_.drop_misses; });
  for (std::size_t k = 0; k < p_MDetections.size(); ++k) {
    if (used_k[k]) continue;
    TrackedPerson person;
    person.id = next_id_++;
    person.p_MP = p_MDetections[k];
    person.p_MMeasured = p_MDetections[k];
    person.hits = 1;
    person.last_seen = stamp;
    people_.push_back(person);
  }
  for (TrackedPerson& person : people_) {
    UpdateRestPoint(person);
    person.forecast.clear();
    for (int s = 1; s <= config_.forecast_steps; ++s) {
      person.forecast.push_back(person.p_MP + person.v_MP * (s * config_.forecast_dt));
    }
  }
}

namespace {
// (along, normal) coordinates of p in the door frame: along from hinge to latch.
Eigen::Vector2d DoorCoordinates(const DoorModel& door, const Eigen::Vector2d& p) {
  const Eigen::Vector2d along = (door.p_MLatch - door.p_MHinge) / door.width();
  const Eigen::Vector2d normal(-along.y(), along.x());
  const Eigen::Vector2d d = p - door.p_MHinge;
  return {d.dot(along), d.dot(normal)};
}
}  // namespace

bool DoorZone::Contains(const Eigen::Vector2d& p_MP) const {
  const Eigen::Vector2d c = DoorCoordinates(door, p_MP);
  const double dx = std::max({0.0, -c.x(), c.x() - door.width()});
  const double dy = std::max(0.0, std::abs(c.y()) - depth);
  return std::hypot(dx, dy) <= person_radius;
}

void UpdateRestPoint(TrackedPerson& person) {
  if (person.v_MP.norm() < kRestSpeedMps) person.p_MRest = person.p_MP;
}

PersonIntent ClassifyIntent(const TrackedPerson& person, const DoorZone& zone,
                            const DoorState& door, const IntentConfig& config) {
  const DoorModel& model = zone.door;
  const double speed = person.v_MP.norm();
  // Holding: still, beside an open leaf (at its edge, or at the hinge side pushing it).
  const Eigen::Vector2d tip = model.LeafTip(door.angle);
  const Eigen::Vector2d leaf = tip - model.p_MHinge;
  const double s =
      std::clamp((person.p_MP - model.p_MHinge).dot(leaf) / leaf.squaredNorm(), 0.0, 1.0);
  const double to_leaf = (person.p_MP - (model.p_MHinge + s * leaf)).norm();
  if (door.observed && door.open_fraction >= config.holding_min_open &&
      speed < config.stationary_speed * 2 && to_leaf <= config.holding_distance) {
    return PersonIntent::kHoldingDoor;
  }
  if (speed < config.stationary_speed) return PersonIntent::kStationary;
  const Eigen::Vector2d c = DoorCoordinates(model, person.p_MP);
  const Eigen::Vector2d along = (model.p_MLatch - model.p_MHinge) / model.width();
  const Eigen::Vector2d normal(-along.y(), along.x());
  const double v_normal = person.v_MP.dot(normal);
  if (std::abs(v_normal) < config.parallel_ratio * speed) {
    return zone.Contains(person.p_MP) ? PersonIntent::kCrossing : PersonIntent::kWalkingPast;
  }
  // Moving across the door line: where and when does the straight path cross it?
  const double time_to_line = -c.y() / v_normal;  // c.y() + v_normal * t = 0
  if (time_to_line >= 0.0) {
    const double along_at_crossing = c.x() + person.v_MP.dot(along) * time_to_line;
    const bool through_opening = along_at_crossing >= -zone.person_radius &&
                                 along_at_crossing <= model.width() + zone.person_radius;
    if (through_opening && time_to_line <= config.crossing_horizon) return PersonIntent::kCrossing;
    if (through_opening) return PersonIntent::kApproaching;
  } else if (zone.Contains(person.p_MP)) {
    return PersonIntent::kCrossing;  // already through the line, still in the zone
  }
  return PersonIntent::kWalkingPast;
}

std::vector<bool> ForecastZoneOccupancy(const std::vector<TrackedPerson>& people,
                                        const DoorZone& zone) {
  std::size_t steps = 0;
  for (const auto& person : people)
    steps = std::max(steps, person.forecast.size());
  std::vector<bool> occupied(steps + 1, false);
  for (const auto& person : people) {
    if (zone.Contains(person.p_MP)) occupied[0] = true;
    for (std::size_t s = 0; s < person.forecast.size(); ++s) {
      if (zone.Contains(person.forecast[s])) occupied[s + 1] = true;
    }
  }
  return occupied;
}

}  // namespace egress::perception
