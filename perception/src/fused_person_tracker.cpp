#include "egress/perception/fused_person_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "egress/hsr_interface/error.h"
#include "nearest_first_association.h"

namespace egress::perception {

void FusedPersonTrackerConfig::Validate() const {
  const auto positive = [](double v, const char* field) {
    ThrowUnless(std::isfinite(v) && v > 0.0, "FusedPersonTrackerConfig: ", field,
                " must be finite and > 0");
  };
  ThrowUnless(alpha > 0.0 && alpha <= 1.0, "FusedPersonTrackerConfig: alpha must be in (0, 1]");
  positive(gate_distance, "gate_distance");
  positive(drop_after_s, "drop_after_s");
  positive(drop_unseen_s, "drop_unseen_s");
  positive(max_latency_s, "max_latency_s");
  positive(min_velocity_dt, "min_velocity_dt");
  positive(reacquire_after_s, "reacquire_after_s");
  positive(reacquire_velocity_s, "reacquire_velocity_s");
  positive(forecast_dt, "forecast_dt");
  positive(confirm_window_s, "confirm_window_s");
  positive(static_radius, "static_radius");
  positive(max_person_speed, "max_person_speed");
  positive(edge_gate, "edge_gate");
  positive(static_after_s, "static_after_s");
  positive(static_gap_s, "static_gap_s");
  positive(static_forget_s, "static_forget_s");
  ThrowUnless(std::isfinite(camera_velocity_after_laser_s) && camera_velocity_after_laser_s >= 0.0,
              "FusedPersonTrackerConfig: camera_velocity_after_laser_s must be finite and >= 0");
  ThrowUnless(std::isfinite(confirm_motion) && confirm_motion >= 0.0,
              "FusedPersonTrackerConfig: confirm_motion must be finite and >= 0");
  ThrowUnless(confirm_laser_hits >= 1 && forecast_steps >= 0,
              "FusedPersonTrackerConfig: confirm_laser_hits >= 1 and forecast_steps >= 0");
}

FusedPersonTracker::FusedPersonTracker(FusedPersonTrackerConfig config)
    : config_(std::move(config)) {
  config_.Validate();
}

namespace {

// Whether a laser-only track's measurements since its confirm window began look like someone
// walking at `min_speed` or faster: the last three each stepping on from the one before (two
// table legs by turns: a jump to the other leg, then the same leg again), none back within
// `radius` of an earlier one the track had since gone 2 x `radius` away from (the first leg
// again). A slow walker's successive measurements lie within `radius` of each other, but
// never back after going farther.
bool WalksOn(const std::vector<std::pair<Time, Eigen::Vector2d>>& path, double min_speed,
             double radius) {
  const std::size_t n = path.size();
  if (n < 3) return false;
  for (std::size_t i = n - 2; i < n; ++i) {
    const double dt = ToSeconds(path[i].first - path[i - 1].first);
    if (dt <= 0.0 || (path[i].second - path[i - 1].second).norm() < min_speed * dt) return false;
  }
  const Eigen::Vector2d& now = path.back().second;
  for (std::size_t i = 0; i + 1 < n; ++i) {
    if ((path[i].second - now).norm() >= radius) continue;
    for (std::size_t j = i + 1; j + 1 < n; ++j) {
      if ((path[j].second - path[i].second).norm() >= 2.0 * radius) return false;
    }
  }
  return true;
}

}  // namespace

void FusedPersonTracker::Predict(Time stamp) {
  const double dt = ToSeconds(stamp - now_);
  for (FusedTrack& track : tracks_)
    track.person.p_MP += track.person.v_MP * dt;
  now_ = stamp;
}

std::vector<bool> FusedPersonTracker::UpdateSpots(
    const std::vector<PersonObservation>& observations, Time stamp) {
  std::erase_if(spots_, [&](const StaticSpot& spot) {
    return ToSeconds(stamp - spot.last_seen) >
           (spot.is_static ? config_.static_forget_s : config_.static_gap_s);
  });
  std::vector<bool> at_static(observations.size(), false);
  for (std::size_t k = 0; k < observations.size(); ++k) {
    const PersonObservation& o = observations[k];
    if (o.source != PersonSource::kLaser) continue;
    StaticSpot* nearest = nullptr;
    double nearest_distance = config_.static_radius;
    for (StaticSpot& spot : spots_) {
      const double d = (spot.p_M - o.p_MP).norm();
      if (d <= nearest_distance) {
        nearest = &spot;
        nearest_distance = d;
      }
    }
    if (!nearest) {
      spots_.push_back({o.p_MP, stamp, stamp, false});
      continue;
    }
    // A spot still here was seen within static_gap_s, or is static (UpdateSpots forgets the
    // others once unseen that long): its time since first_seen runs on.
    StaticSpot& spot = *nearest;
    spot.last_seen = std::max(spot.last_seen, stamp);
    spot.is_static =
        spot.is_static || ToSeconds(spot.last_seen - spot.first_seen) >= config_.static_after_s;
    at_static[k] = spot.is_static;
  }
  return at_static;
}

void FusedPersonTracker::Update(const std::vector<PersonObservation>& observations, Time stamp,
                                const std::function<bool(const Eigen::Vector2d&)>& covers) {
  for (const auto& o : observations)
    ThrowUnless(o.p_MP.allFinite(), "FusedPersonTracker: an observation is not finite");
  if (!started_) {
    now_ = stamp;
    started_ = true;
  }
  if (stamp > now_) Predict(stamp);
  const double lag = ToSeconds(now_ - stamp);
  ThrowUnless(lag <= config_.max_latency_s, "FusedPersonTracker: a frame ", lag,
              " s older than the tracks (more than max_latency_s = ", config_.max_latency_s, " s)");

  // Each track where it was when the frame was taken; nearest pairs first within the gate.
  std::vector<Eigen::Vector2d> then(tracks_.size());
  for (std::size_t t = 0; t < tracks_.size(); ++t)
    then[t] = tracks_[t].person.p_MP - tracks_[t].person.v_MP * lag;
  // A static spot's observation joins only people already confirmed.
  const std::vector<bool> at_static = UpdateSpots(observations, stamp);
  const double kNever = std::numeric_limits<double>::infinity();
  const internal::Association match =
      internal::AssociateNearestFirst(tracks_.size(), observations.size(), config_.gate_distance,
                                      [&](std::size_t t, std::size_t k) {
                                        if (at_static[k] && !tracks_[t].confirmed) return kNever;
                                        return (observations[k].p_MP - then[t]).norm();
                                      });
  const std::vector<bool>& used_t = match.track_matched;
  const std::vector<bool>& used_k = match.detection_matched;
  const double a = config_.alpha;
  for (const auto& [t, k] : match.pairs) {
    FusedTrack& track = tracks_[t];
    const PersonObservation& o = observations[k];
    if (o.at_edge && track.confirmed && (o.p_MP - then[t]).norm() > config_.edge_gate) {
      // Seen, but where exactly is unknown: alive, unmoved.
      track.person.misses = 0;
      track.last_measured = std::max(track.last_measured, stamp);
      track.person.last_seen = track.last_measured;
      continue;
    }
    auto& last = track.last_by_source[std::size_t(o.source)];
    // Faster than anyone walks since its last laser measurement: the track took something else
    // (the next table leg while the first was hidden), not a step; the jump is no motion.
    const bool jumped =
        o.source == PersonSource::kLaser && last && stamp > last->first &&
        (o.p_MP - last->second).norm() > config_.max_person_speed * ToSeconds(stamp - last->first);
    const bool reacquired = ToSeconds(stamp - track.last_measured) > config_.reacquire_after_s;
    const bool still = o.motion == PlaceMotion::kStill;
    if (reacquired) {
      // Coasted: the old velocity is kept until the new one is measured, not differenced across
      // the gap (from whoever the track followed before it).
      track.reacquired = FusedTrack::VelocityAnchor{stamp, o.p_MP, o.source};
      track.last_by_source = {};
    } else if (track.reacquired) {
      const FusedTrack::VelocityAnchor& anchor = *track.reacquired;
      const double dt = ToSeconds(stamp - anchor.stamp);
      if (o.source == anchor.source && dt >= config_.min_velocity_dt)
        track.person.v_MP =
            still ? Eigen::Vector2d::Zero() : Eigen::Vector2d((o.p_MP - anchor.p_MP) / dt);
      if (dt >= config_.reacquire_velocity_s) track.reacquired.reset();
    } else if (last && stamp > last->first) {
      const double dt = ToSeconds(stamp - last->first);
      const auto& by_laser = track.last_by_source[std::size_t(PersonSource::kLaser)];
      const bool laser_measures =
          o.source == PersonSource::kCamera && by_laser &&
          std::abs(ToSeconds(stamp - by_laser->first)) < config_.camera_velocity_after_laser_s;
      if (dt >= config_.min_velocity_dt && !laser_measures) {
        const Eigen::Vector2d step_v =
            still ? Eigen::Vector2d::Zero() : Eigen::Vector2d((o.p_MP - last->second) / dt);
        track.person.v_MP = a * step_v + (1.0 - a) * track.person.v_MP;
      }
    }
    if (!last || stamp >= last->first) last = std::make_pair(stamp, o.p_MP);
    // Fused where the person is now: the observation moved on by the (new) velocity; outright
    // after coasting, when the prediction is the guess.
    const double a_p = reacquired ? 1.0 : a;
    track.person.p_MP = a_p * (o.p_MP + track.person.v_MP * lag) + (1.0 - a_p) * track.person.p_MP;
    ++track.person.hits;
    track.person.misses = 0;
    track.last_measured = std::max(track.last_measured, stamp);
    track.person.last_seen = track.last_measured;
    if (o.source == PersonSource::kCamera) {
      ++track.camera_hits;
    } else {
      ++track.laser_hits;
    }
    if (jumped && !track.confirmed) {
      track.person.p_MP = o.p_MP;
      track.person.v_MP.setZero();
      track.p_MBirth = o.p_MP;
      track.birth = stamp;
      track.laser_path.clear();
    }
    if (o.source == PersonSource::kLaser && !track.confirmed)
      track.laser_path.emplace_back(stamp, o.p_MP);
    const bool moved = (track.person.p_MP - track.p_MBirth).norm() >= config_.confirm_motion;
    // O2 seed 2012: a track born on one table leg, then measured on the other 0.52 m off 0.4 s
    // later (a walker's pace) and there again, "moved" 0.35 m and held the robot at the door.
    const bool walks_on =
        o.source == PersonSource::kLaser &&
        WalksOn(track.laser_path, config_.confirm_motion / config_.confirm_window_s,
                config_.static_radius);
    track.confirmed = track.confirmed || track.camera_hits > 0 ||
                      (track.laser_hits >= config_.confirm_laser_hits && moved && walks_on);
    if (track.confirmed) {
      track.laser_path.clear();
      track.laser_path.shrink_to_fit();
    } else if (ToSeconds(stamp - track.birth) > config_.confirm_window_s) {
      track.p_MBirth = track.person.p_MP;  // a new window from here
      track.birth = stamp;
      // Its steps since the last laser measurement still count.
      track.laser_path.erase(track.laser_path.begin(), track.laser_path.end() - 1);
    }
  }

  // Drop tracks this sensor should have seen and has not for drop_after_s, and tracks no sensor
  // has measured for drop_unseen_s.
  std::vector<FusedTrack> kept;
  kept.reserve(tracks_.size());
  for (std::size_t t = 0; t < tracks_.size(); ++t) {
    FusedTrack& track = tracks_[t];
    if (!used_t[t]) {
      ++track.person.misses;
      const double unmeasured = ToSeconds(stamp - track.last_measured);
      const bool covered = !covers || covers(then[t]);
      if ((covered && unmeasured > config_.drop_after_s) ||
          ToSeconds(now_ - track.last_measured) > config_.drop_unseen_s) {
        continue;
      }
    }
    kept.push_back(std::move(track));
  }
  tracks_ = std::move(kept);

  for (std::size_t k = 0; k < observations.size(); ++k) {
    if (used_k[k] || at_static[k]) continue;
    FusedTrack track;
    track.person.id = next_id_++;
    track.person.p_MP = observations[k].p_MP;
    track.person.hits = 1;
    track.person.last_seen = stamp;
    track.p_MBirth = observations[k].p_MP;
    track.birth = stamp;
    track.last_measured = stamp;
    track.last_by_source[std::size_t(observations[k].source)] =
        std::make_pair(stamp, observations[k].p_MP);
    if (observations[k].source == PersonSource::kCamera) {
      track.camera_hits = 1;
      track.confirmed = true;
    } else {
      track.laser_hits = 1;
      track.laser_path.emplace_back(stamp, observations[k].p_MP);
    }
    tracks_.push_back(std::move(track));
  }
  for (FusedTrack& track : tracks_)
    UpdateRestPoint(track.person);
  Forecast();
}

void FusedPersonTracker::Forecast() {
  for (FusedTrack& track : tracks_) {
    track.person.forecast.clear();
    for (int s = 1; s <= config_.forecast_steps; ++s)
      track.person.forecast.push_back(track.person.p_MP +
                                      track.person.v_MP * (s * config_.forecast_dt));
  }
}

std::vector<TrackedPerson> FusedPersonTracker::ConfirmedPeople() const {
  std::vector<TrackedPerson> people;
  for (const FusedTrack& track : tracks_) {
    if (track.confirmed) people.push_back(track.person);
  }
  return people;
}

}  // namespace egress::perception
