#pragma once
// `egress sim batch`'s tracking judge (issue 21): how often the brain reads someone who stands
// still as walking — each tracked person's velocity against the twin's ground truth. A track
// that walks off a standing person breaks off the robot's approaches ("someone coming") and
// sends it making room for nobody; the figure is split by whether the robot itself moves (from
// a moving base, occlusions and detections shift: README, stop 78).

#include <vector>

#include <Eigen/Core>

namespace egress::apps {

/// A tracked person (the brain's, in M) or a person (ground truth, in W): where, how fast. In the
/// twin the brain's map frame is the world frame.
struct PersonSample {
  Eigen::Vector2d p{Eigen::Vector2d::Zero()};  ///< [m]
  Eigen::Vector2d v{Eigen::Vector2d::Zero()};  ///< [m/s]
};

/// Track samples of people standing still, and how many of them read walking; with the robot
/// moving and with it still.
struct StandingReadWalking {
  int moving_samples{0};
  int moving_walking{0};
  int still_samples{0};
  int still_walking{0};
  StandingReadWalking& operator+=(const StandingReadWalking& o);
};

class StandingTrackJudge {
 public:
  /// [m] A track this near a person (ground truth) is taken for theirs.
  static constexpr double kMatchM = 0.5;
  /// [m/s] A person (ground truth) slower than this, for kStandingForSec [s] on end, stands still
  /// (a track's velocity takes a second or so to settle after someone stops: that is lag, not a
  /// walk read into a standing person).
  static constexpr double kStandingMps = 0.05;
  static constexpr double kStandingForSec = 1.0;
  /// [m/s] A track faster than this reads on the move: the escort's threshold for someone
  /// coming (behavior/src/escort_watch.h, kMovingMps), not the give-way's walking speed
  /// (kWalkingMps, 0.5 m/s).
  static constexpr double kOnTheMoveMps = 0.2;
  /// The robot moves when faster than this [m/s] or turning faster than kTurningRadPerSec.
  static constexpr double kRobotMovingMps = 0.05;
  static constexpr double kTurningRadPerSec = 0.1;

  /// One sample at `time` [s]: the robot's base speed [m/s] and yaw rate [rad/s] (ground truth),
  /// the brain's tracked people and the people (ground truth; the same person at the same index
  /// every step). Each track is matched to the nearest person within kMatchM; those matched to
  /// someone standing still are counted.
  void Step(double time, double robot_speed, double robot_yaw_rate,
            const std::vector<PersonSample>& tracks, const std::vector<PersonSample>& people);

  const StandingReadWalking& counts() const { return counts_; }

 private:
  StandingReadWalking counts_;
  std::vector<double> still_since_;  ///< per person: since when slower than kStandingMps [s]
};

}  // namespace egress::apps
