#include "track_judge.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace egress::apps {

StandingReadWalking& StandingReadWalking::operator+=(const StandingReadWalking& o) {
  moving_samples += o.moving_samples;
  moving_walking += o.moving_walking;
  still_samples += o.still_samples;
  still_walking += o.still_walking;
  return *this;
}

void StandingTrackJudge::Step(double time, double robot_speed, double robot_yaw_rate,
                              const std::vector<PersonSample>& tracks,
                              const std::vector<PersonSample>& people) {
  still_since_.resize(people.size(), time);
  for (std::size_t i = 0; i < people.size(); ++i)
    if (people[i].v.norm() >= kStandingMps)
      still_since_[i] = std::numeric_limits<double>::max();
    else
      still_since_[i] = std::min(still_since_[i], time);
  const bool moving = robot_speed > kRobotMovingMps || std::abs(robot_yaw_rate) > kTurningRadPerSec;
  for (const PersonSample& track : tracks) {
    std::size_t nearest = people.size();
    double nearest_distance = kMatchM;
    for (std::size_t i = 0; i < people.size(); ++i) {
      const double d = (people[i].p - track.p).norm();
      if (d < nearest_distance) {
        nearest = i;
        nearest_distance = d;
      }
    }
    if (nearest == people.size() || time - still_since_[nearest] < kStandingForSec) continue;
    const bool walking = track.v.norm() > kOnTheMoveMps;
    (moving ? counts_.moving_samples : counts_.still_samples) += 1;
    if (walking) (moving ? counts_.moving_walking : counts_.still_walking) += 1;
  }
}

}  // namespace egress::apps
