#pragma once
/// @file
/// Proxemics: how close the robot lets itself come to people. Personal space is 0.45-1.2 m
/// (Hall); the robot slows its paths when it heads towards someone within `slow_gap` of its
/// edge (where they are, or will be within `horizon` at their velocity), down to a stop at
/// `stop_gap`. Moving away from someone, or past them with room (`pass_gap`), is never slowed:
/// a retreat must be quick.
/// Held back for `patience_s` by people who stand still (a resident waiting at the door the
/// robot goes to open, beside the only way to its button: they will not move until it opens),
/// the robot edges past them at a crawl instead of waiting for good (ApproachPace).
/// Gaps are surface to surface, as the judge measures them.

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "egress/hsr_interface/geometry.h"
#include "egress/perception/door_estimation.h"
#include "egress/perception/world_state.h"

namespace egress::behavior {

struct ProxemicsConfig {
  bool slow_near_people{true};  ///< False: paths keep their planned pace whoever is near.
  double slow_gap{1.2};         ///< Slowing starts this near [m] (personal space's edge).
  double stop_gap{0.45};        ///< ... and reaches a standstill this near [m].
  double horizon{1.0};          ///< People's positions this far ahead count too [s].
  double cone_deg{60.0};        ///< Within this of the way the robot goes, it goes to them.
  /// Someone ahead of abeam whom the robot's straight way would pass nearer than this [m] is
  /// slowed for as if it went to them: going by at a hand's breadth is no way past anyone.
  double pass_gap{0.2};
  /// Someone this near where the path ends, and no nearer the robot than the end, is whom the
  /// robot goes to (a hand-over, a responder): not slowed for [m].
  double goal_radius{1.5};
  /// The costmap's proxemic layer, which the base planner weighs (paths round people): each
  /// tracked person's personal space, full from stop_gap beyond both bodies and fading out at
  /// slow_gap, where they are and where they are predicted every space_step up to
  /// space_horizon, a prediction counting less the further ahead it is. False: no layer.
  bool personal_space_layer{true};
  double space_horizon{2.0};  ///< [s]
  double space_step{0.5};     ///< [s]
  /// Held back this long [s] by people standing still, the robot edges past them: towards them
  /// or going by them, it slows from stop_gap and stops at squeeze_gap. 0: it waits for them
  /// however long.
  double patience_s{5.0};
  double squeeze_gap{0.2};      ///< [m], below stop_gap
  double standing_speed{0.25};  ///< Tracked people slower than this stand still [m/s].
  /// Within this of a door's line, between its jambs (grown by the footprint), the base is in
  /// the doorway [m]. Going out of it, the pace holds the robot to no less than a crawl
  /// (ApproachPace::kHeldScale) unless someone is within squeeze_gap ahead: stopped there for a
  /// passer-by, it would stand in the way of everyone who comes through the door (two wards seed
  /// 24: stopped 0.46 m past door_d's line for a resident walking the corridor). 0: no floor.
  double doorway_depth{0.6};
  /// @throws InvalidArgument naming the field.
  void Validate() const;
};

/// Whether a person at p_MP is whom the robot at p_MB goes to, its path ending at p_MGoal: within
/// `goal_radius` [m] of the end and no nearer the robot than the end (the path stops short of
/// them). Someone near the end but on the robot's side of it is in its way.
bool IsWhomTheRobotGoesTo(const Eigen::Vector2d& p_MP, const Eigen::Vector2d& p_MB,
                          const Eigen::Vector2d& p_MGoal, double goal_radius);

/// Whether the straight way from p_MB to p_MGoal goes by p_MP within `reach` [m] (centre to
/// centre) on the way, not at its ends: someone it passes, whom it does not go to.
bool IsPassedOnTheWay(const Eigen::Vector2d& p_MP, const Eigen::Vector2d& p_MB,
                      const Eigen::Vector2d& p_MGoal, double reach);

/// The fraction of its planned pace the robot may go at (in [0, 1]) heading along v_M from
/// X_MB to p_MGoal (where its path ends, if it has one), with `people` around (whom the robot
/// goes to excepted: IsWhomTheRobotGoesTo, standing still, and not passed within `pass_gap` on
/// the way there, IsPassedOnTheWay). Radii: the
/// robot's footprint and a person's [m].
/// `squeeze`: people standing still (slower than `standing_speed`) slow it from `stop_gap` to a
/// stop at `squeeze_gap` instead, heading at them or going by them (anywhere ahead of abeam),
/// where they stand (ApproachPace, once patience is spent).
double ApproachSpeedScale(const Pose2& X_MB, const Eigen::Vector2d& v_M,
                          const std::optional<Eigen::Vector2d>& p_MGoal,
                          const std::vector<perception::TrackedPersonWithIntent>& people,
                          double robot_radius, double person_radius, const ProxemicsConfig& config,
                          bool squeeze = false);

/// Whether a robot at X_MB going along v_M is in one of `doors`' doorways (within
/// `doorway_depth` of its door line, and between its jambs grown by `robot_radius` [m]) and going
/// out of it (away from the door line). Unlike DoorModel::OnDoorLine (a point between the
/// jambs), a footprint that still overlaps the opening counts.
bool IsLeavingDoorway(const Pose2& X_MB, const Eigen::Vector2d& v_M,
                      const std::vector<perception::DoorModel>& doors, double doorway_depth,
                      double robot_radius);

/// The robot's pace near people over time: ApproachSpeedScale, and patience. While the robot
/// is held to a crawl (below kHeldScale) by people who stand still, for `patience_s` in a row,
/// it edges past them (ApproachSpeedScale with `squeeze`) until it is no longer held. Without
/// it a resident waiting at a door, beside the way to its button, and the robot waiting for
/// them to move, waited for each other to the time limit (two wards seed 33: 340 s).
class ApproachPace {
 public:
  /// A scale below this holds the robot to a crawl (a fifth of its pace).
  static constexpr double kHeldScale = 0.2;
  /// Held again after this long with no path [s], the robot's patience starts afresh.
  static constexpr double kHeldGapSec = 1.0;

  explicit ApproachPace(ProxemicsConfig config);
  /// The scale at `now_s` [s] (monotonic across calls); arguments as ApproachSpeedScale's.
  /// `leaving_doorway` (IsLeavingDoorway): the scale is at least a crawl (kHeldScale), slowed
  /// from stop_gap to a stop at squeeze_gap for anyone ahead (ProxemicsConfig::doorway_depth).
  double Update(double now_s, const Pose2& X_MB, const Eigen::Vector2d& v_M,
                const std::optional<Eigen::Vector2d>& p_MGoal,
                const std::vector<perception::TrackedPersonWithIntent>& people, double robot_radius,
                double person_radius, bool leaving_doorway = false);
  /// Whether it edges past people standing still (as of the last Update with a pace planned).
  bool squeezing() const { return squeezing_; }

 private:
  ProxemicsConfig config_;
  std::optional<double> held_since_;  // [s] held by people standing still since
  double last_held_s_{0.0};           // [s] when last held so
  bool squeezing_{false};
};

/// Whether `person` walks (faster than `walking_speed` [m/s]) towards a robot standing at
/// p_MB and, going straight on at their velocity, will pass within `gap` of its edge (surface
/// to surface) within `horizon` [s]: someone the robot should make way for. Then the time from
/// now at which they pass nearest [s] (may exceed the horizon); else nullopt. Radii [m].
std::optional<double> OncomingPassTime(const perception::TrackedPerson& person,
                                       const Eigen::Vector2d& p_MB, double robot_radius,
                                       double person_radius, double gap, double horizon,
                                       double walking_speed);

}  // namespace egress::behavior
