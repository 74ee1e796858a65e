#pragma once
// `egress evac study`'s doorway judge (issue 17: the robot never stands in a doorway while a
// resident is within 2 m of it, on either side): how long the robot was in a doorway with a
// resident near, and how much of that it stood there.

#include <vector>

#include <Eigen/Core>

#include "egress/twin/scenario_judge.h"

namespace egress::apps {

/// A resident this near the robot while it is in a doorway counts as held up by it [m].
inline constexpr double kDoorwayBlockRadiusM = 2.0;
/// The robot is in a doorway within this of the door line (and within its jambs) [m].
inline constexpr double kInDoorwayM = 0.5;

class DoorwayBlockJudge {
 public:
  /// The building's doorways (W).
  explicit DoorwayBlockJudge(std::vector<twin::DoorwayFrame> doorways);

  /// One period of `dt` [s] ending now: the robot's base at p_WB (ground truth, W) moving at
  /// `speed` [m/s], and the residents still in the building at p_WR.
  void Step(double dt, const Eigen::Vector2d& p_WB, double speed,
            const std::vector<Eigen::Vector2d>& p_WR);

  /// Whether p_WB is in one of the doorways.
  bool InDoorway(const Eigen::Vector2d& p_WB) const;

  /// Time [s] the robot was in a doorway, at any speed, with a resident within
  /// kDoorwayBlockRadiusM (the strict figure: a drive through counts).
  double in_doorway_s() const { return in_doorway_s_; }
  /// The part of it the robot stood there: slower than ScenarioJudge::kWaitSpeed.
  double standing_s() const { return standing_s_; }

 private:
  std::vector<twin::DoorwayFrame> doorways_;
  double in_doorway_s_{0.0};
  double standing_s_{0.0};
};

}  // namespace egress::apps
