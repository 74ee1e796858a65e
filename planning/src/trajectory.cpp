#include "egress/planning/trajectory.h"

#include <algorithm>
#include <cmath>

#include "egress/hsr_interface/error.h"

namespace egress::planning {
namespace {

// Peak speed / average speed of a rest-to-rest quintic.
constexpr double kQuinticPeakFactor = 1.875;
// Peak acceleration of a rest-to-rest quintic over L in T, as a multiple of L / T² (10 / √3).
constexpr double kQuinticPeakAccelFactor = 5.773502691896258;

}  // namespace

QuinticPolynomial::QuinticPolynomial(double q0, double v0, double a0, double q1, double v1,
                                     double a1, double duration)
    : duration_(duration) {
  ThrowUnless(std::isfinite(q0) && std::isfinite(v0) && std::isfinite(a0) && std::isfinite(q1) &&
                  std::isfinite(v1) && std::isfinite(a1),
              "Invalid quintic: boundary values must be finite.");
  ThrowUnless(duration > 0.0 && std::isfinite(duration), "Invalid quintic: duration (", duration,
              ") must be > 0.");
  const double T = duration, T2 = T * T, T3 = T2 * T, T4 = T3 * T, T5 = T4 * T;
  const double h = q1 - q0;
  c_ = {q0,
        v0,
        a0 / 2.0,
        (20 * h - (8 * v1 + 12 * v0) * T - (3 * a0 - a1) * T2) / (2 * T3),
        (-30 * h + (14 * v1 + 16 * v0) * T + (3 * a0 - 2 * a1) * T2) / (2 * T4),
        (12 * h - 6 * (v1 + v0) * T + (a1 - a0) * T2) / (2 * T5)};
}

double QuinticPolynomial::Position(double t) const {
  t = std::clamp(t, 0.0, duration_);
  return c_[0] + t * (c_[1] + t * (c_[2] + t * (c_[3] + t * (c_[4] + t * c_[5]))));
}

double QuinticPolynomial::Velocity(double t) const {
  t = std::clamp(t, 0.0, duration_);
  return c_[1] + t * (2 * c_[2] + t * (3 * c_[3] + t * (4 * c_[4] + t * 5 * c_[5])));
}

double QuinticPolynomial::Acceleration(double t) const {
  t = std::clamp(t, 0.0, duration_);
  return 2 * c_[2] + t * (6 * c_[3] + t * (12 * c_[4] + t * 20 * c_[5]));
}

void TrajectoryConfig::Validate() const {
  ThrowUnless(nominal_speed > 0.0 && door_speed > 0.0,
              "Invalid TrajectoryConfig: speeds must be > 0.");
  ThrowUnless(min_duration > 0.0, "Invalid TrajectoryConfig: min_duration must be > 0.");
  ThrowUnless(max_yaw_rate > 0.0, "Invalid TrajectoryConfig: max_yaw_rate must be > 0.");
  ThrowUnless(std::isfinite(max_base_acceleration) && max_base_acceleration > 0.0,
              "Invalid TrajectoryConfig: max_base_acceleration must be finite and > 0 (got ",
              max_base_acceleration, ").");
}

double SegmentDuration(double base_distance, bool through_door, const TrajectoryConfig& config) {
  ThrowUnless(std::isfinite(base_distance) && base_distance >= 0.0,
              "Invalid segment: base distance (", base_distance, ") must be finite and >= 0.");
  const double paper =
      std::max(base_distance / (through_door ? config.door_speed : config.nominal_speed),
               config.min_duration);
  // Accelerating half the way and braking the other half at the base's limit.
  return std::max(paper, 2.0 * std::sqrt(base_distance / config.max_base_acceleration));
}

SegmentTimeScaling::SegmentTimeScaling(double base_distance, double duration,
                                       const TrajectoryConfig& config)
    : duration_(duration) {
  config.Validate();
  ThrowUnless(std::isfinite(base_distance) && base_distance >= 0.0,
              "Invalid segment: base distance (", base_distance, ") must be finite and >= 0.");
  ThrowUnless(std::isfinite(duration) && duration > 0.0, "Invalid segment: duration (", duration,
              ") must be finite and > 0.");
  const double a = config.max_base_acceleration, L = base_distance, T = duration;
  // A hair of tolerance: the quintic exactly at the limit stays the quintic.
  if (L <= 0.0 || (!config.brisk && kQuinticPeakAccelFactor * L / (T * T) <= a * (1.0 + 1e-9)))
    return;
  // t_a (T - t_a) = L / a: the smaller root (the larger would brake before it coasts).
  const double discriminant = std::max(0.0, T * T - 4.0 * L / a);
  const double accel_time = 0.5 * (T - std::sqrt(discriminant));
  if (accel_time <= 0.0) return;  // brisk, over a distance too small to tell from none
  accel_time_ = accel_time;
  accel_ = 1.0 / (accel_time_ * (T - accel_time_));
}

double SegmentTimeScaling::Progress(double t) const {
  const double T = duration_;
  t = std::clamp(t, 0.0, T);
  if (quintic()) {
    const double u = t / T;
    return u * u * u * (10.0 + u * (-15.0 + 6.0 * u));
  }
  const double ta = accel_time_;
  if (t < ta) return 0.5 * accel_ * t * t;
  if (t > T - ta) return 1.0 - 0.5 * accel_ * (T - t) * (T - t);
  return 0.5 * accel_ * ta * ta + accel_ * ta * (t - ta);
}

double SegmentTimeScaling::Rate(double t) const {
  const double T = duration_;
  t = std::clamp(t, 0.0, T);
  if (quintic()) {
    const double u = t / T;
    return 30.0 * u * u * (1.0 - u) * (1.0 - u) / T;
  }
  const double ta = accel_time_;
  if (t < ta) return accel_ * t;
  if (t > T - ta) return accel_ * (T - t);
  return accel_ * ta;
}

double SegmentTimeScaling::Acceleration(double t) const {
  const double T = duration_;
  t = std::clamp(t, 0.0, T);
  if (quintic()) {
    const double u = t / T;
    return 60.0 * u * (1.0 - u) * (1.0 - 2.0 * u) / (T * T);
  }
  const double ta = accel_time_;
  if (t < ta) return accel_;
  if (t > T - ta) return -accel_;
  return 0.0;
}

double SegmentTimeScaling::peak_rate() const {
  return quintic() ? kQuinticPeakFactor / duration_ : accel_ * accel_time_;
}

double SegmentDuration(double base_distance, double base_turn, bool through_door,
                       const TrajectoryConfig& config) {
  ThrowUnless(std::isfinite(base_turn), "Invalid segment: base turn (", base_turn,
              ") must be finite.");
  // The base turns no faster than the tracking controller can follow.
  return std::max(SegmentDuration(base_distance, through_door, config),
                  kQuinticPeakFactor * std::abs(base_turn) / config.max_yaw_rate);
}

WholeBodyTrajectory WholeBodyTrajectory::Plan(const std::vector<WholeBodyVector>& waypoints,
                                              const RobotModel& model,
                                              const TrajectoryConfig& config,
                                              const std::vector<bool>& through_door) {
  config.Validate();
  ThrowUnless(waypoints.size() >= 2, "Invalid trajectory: needs at least 2 waypoints, got ",
              waypoints.size(), ".");
  ThrowUnless(through_door.empty() || through_door.size() == waypoints.size() - 1,
              "Invalid trajectory: through_door ", "has ", through_door.size(), " entries for ",
              waypoints.size() - 1, " segments.");
  WholeBodyTrajectory trajectory;
  WholeBodyVector previous = waypoints[0];
  ThrowUnless(previous.allFinite(), "Invalid trajectory: waypoint 0 is not finite.");
  double time = 0.0;
  for (std::size_t s = 1; s < waypoints.size(); ++s) {
    ThrowUnless(waypoints[s].allFinite(), "Invalid trajectory: waypoint ", s, " is not finite.");
    WholeBodyVector next = waypoints[s];
    next[kBaseYaw] =
        previous[kBaseYaw] + WrapAngle(next[kBaseYaw] - previous[kBaseYaw]);  // the short way
    const double distance =
        std::hypot(next[kBaseX] - previous[kBaseX], next[kBaseY] - previous[kBaseY]);
    double T = SegmentDuration(distance, next[kBaseYaw] - previous[kBaseYaw],
                               !through_door.empty() && through_door[s - 1], config);
    for (int j = kArmLift; j < kNumWholeBodyJoints; ++j) {
      const double limit = model.limits(WholeBodyJoint(j)).velocity;
      if (limit > 0.0)
        T = std::max(T, kQuinticPeakFactor * std::abs(next[j] - previous[j]) / limit);
    }
    // The coasting profile peaks up to 2/T (not 1.875/T): stretched until no joint and no turn
    // is faster than its limit (each pass lowers the peak; a longer T may be a quintic again).
    SegmentTimeScaling timing(distance, T, config);
    for (int pass = 0; pass < 8 && !timing.quintic(); ++pass) {
      double ratio =
          timing.peak_rate() * std::abs(next[kBaseYaw] - previous[kBaseYaw]) / config.max_yaw_rate;
      for (int j = kArmLift; j < kNumWholeBodyJoints; ++j) {
        const double limit = model.limits(WholeBodyJoint(j)).velocity;
        if (limit > 0.0)
          ratio = std::max(ratio, timing.peak_rate() * std::abs(next[j] - previous[j]) / limit);
      }
      if (ratio <= 1.0 + 1e-9) break;
      T *= ratio;
      timing = SegmentTimeScaling(distance, T, config);
    }
    trajectory.segments_.push_back({previous, next, timing});
    time += timing.duration();
    trajectory.end_times_.push_back(time);
    previous = next;
  }
  return trajectory;
}

double WholeBodyTrajectory::segment_duration(std::size_t i) const {
  ThrowUnless(i < segments_.size(), "Invalid segment index ", i, ".");
  return segments_[i].timing.duration();
}

TrajectorySample WholeBodyTrajectory::Sample(double t) const {
  ThrowUnless(std::isfinite(t), "Invalid trajectory time: must be finite.");
  std::size_t s = std::lower_bound(end_times_.begin(), end_times_.end(), t) - end_times_.begin();
  if (s >= segments_.size()) s = segments_.size() - 1;
  const double start = s == 0 ? 0.0 : end_times_[s - 1];
  const Segment& segment = segments_[s];
  const WholeBodyVector delta = segment.to - segment.from;
  TrajectorySample sample;
  sample.q = segment.from + delta * segment.timing.Progress(t - start);
  sample.qd = delta * segment.timing.Rate(t - start);
  sample.qdd = delta * segment.timing.Acceleration(t - start);
  sample.q[kBaseYaw] = WrapAngle(sample.q[kBaseYaw]);
  return sample;
}

}  // namespace egress::planning
