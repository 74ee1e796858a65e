#pragma once
/// @file
/// Bug2Navigator: local avoidance of an unexpected static obstacle (the paper's S7). Heads
/// straight for the goal along the m-line; when the laser shows an obstacle in the robot's
/// corridor ahead, follows its boundary at a fixed distance (on the side that turns less from
/// the goal) until it crosses the m-line closer to the goal than where it left it and the way
/// ahead is free. Gives up (kFailed: replan) when the boundary walk grows too long or loops.
/// Never drives toward a person: with one within person_stop_distance ahead it stops.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "egress/hsr_interface/geometry.h"

namespace egress::planning {

struct BugConfig {
  double speed{0.2};                 ///< [m/s]
  double robot_radius{0.215};        ///< [m]
  double safety_margin{0.1};         ///< Corridor half-width = radius + margin [m].
  double lookahead{0.6};             ///< How far ahead counts as blocked [m].
  double follow_distance{0.45};      ///< Robot centre to obstacle while following [m].
  double follow_gain{2.0};           ///< Correction toward follow_distance [1/s].
  double goal_tolerance{0.05};       ///< [m]
  double person_stop_distance{1.0};  ///< [m]
  double max_follow_length{15.0};    ///< Boundary walk before giving up [m].
  double turn_gain{1.5};             ///< Yaw toward the motion direction [1/s].
  void Validate() const;
};

enum class BugMode { kMotionToGoal, kBoundaryFollowing, kReached, kWaitingForPerson, kFailed };
std::string_view ToString(BugMode mode);

struct BugCommand {
  Twist2 V_B;  ///< Base velocity in the base frame.
  BugMode mode{BugMode::kMotionToGoal};
  std::string reason;  ///< For kFailed and kWaitingForPerson.
};

class Bug2Navigator {
 public:
  /// The m-line runs from `p_MStart` to `p_MGoal`. @throws InvalidArgument for non-finite input.
  Bug2Navigator(const Eigen::Vector2d& p_MStart, const Eigen::Vector2d& p_MGoal,
                BugConfig config = {});
  /// One step: the robot pose, the laser's obstacle points and tracked people (all in M), and
  /// the time since the previous step [s].
  BugCommand Step(const Pose2& X_MB, const std::vector<Eigen::Vector2d>& p_MObstacles,
                  const std::vector<Eigen::Vector2d>& p_MPeople, double dt);
  BugMode mode() const { return mode_; }

 private:
  bool Blocked(const Eigen::Vector2d& p, const Eigen::Vector2d& direction,
               const std::vector<Eigen::Vector2d>& obstacles) const;
  BugCommand Command(const Pose2& X_MB, const Eigen::Vector2d& v_M) const;

  Eigen::Vector2d start_, goal_;
  BugConfig config_;
  BugMode mode_{BugMode::kMotionToGoal};
  Eigen::Vector2d hit_point_{Eigen::Vector2d::Zero()};
  double hit_distance_{0.0};
  double followed_{0.0};
  double side_{1.0};  // +1: obstacle on the left
  double last_mline_side_{0.0};
};

}  // namespace egress::planning
