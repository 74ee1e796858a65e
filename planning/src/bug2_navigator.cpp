#include "egress/planning/bug2_navigator.h"

#include <cmath>
#include <limits>

#include "egress/hsr_interface/error.h"

namespace egress::planning {

void BugConfig::Validate() const {
  ThrowUnless(speed > 0.0 && robot_radius > 0.0 && lookahead > 0.0 && goal_tolerance > 0.0,
              "Invalid BugConfig: speed, robot_radius, lookahead and goal_tolerance must be > 0.");
  ThrowUnless(follow_distance > robot_radius, "Invalid BugConfig: follow_distance (",
              follow_distance, ") must exceed robot_radius (", robot_radius, ").");
  ThrowUnless(max_follow_length > 0.0 && person_stop_distance >= 0.0,
              "Invalid BugConfig: max_follow_length must be ",
              "> 0 and person_stop_distance >= 0.");
}

std::string_view ToString(BugMode mode) {
  switch (mode) {
    case BugMode::kMotionToGoal:
      return "motion_to_goal";
    case BugMode::kBoundaryFollowing:
      return "boundary_following";
    case BugMode::kReached:
      return "reached";
    case BugMode::kWaitingForPerson:
      return "waiting_for_person";
    case BugMode::kFailed:
      return "failed";
  }
  return "unknown";
}

namespace {
double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}
Eigen::Vector2d Ccw(const Eigen::Vector2d& v) {
  return {-v.y(), v.x()};
}
}  // namespace

Bug2Navigator::Bug2Navigator(const Eigen::Vector2d& p_MStart, const Eigen::Vector2d& p_MGoal,
                             BugConfig config)
    : start_(p_MStart), goal_(p_MGoal), config_(config) {
  ThrowUnless(p_MStart.allFinite() && p_MGoal.allFinite(),
              "Invalid Bug2 request: start and goal must be finite.");
  config_.Validate();
}

bool Bug2Navigator::Blocked(const Eigen::Vector2d& p, const Eigen::Vector2d& direction,
                            const std::vector<Eigen::Vector2d>& obstacles) const {
  const double half_width = config_.robot_radius + config_.safety_margin;
  const double reach =
      std::min(config_.lookahead + config_.robot_radius, (goal_ - p).norm() + config_.robot_radius);
  for (const auto& q : obstacles) {
    const Eigen::Vector2d d = q - p;
    const double ahead = d.dot(direction);
    if (ahead > 0.0 && ahead <= reach && std::abs(Cross(direction, d)) < half_width) return true;
  }
  return false;
}

BugCommand Bug2Navigator::Command(const Pose2& X_MB, const Eigen::Vector2d& v_M) const {
  BugCommand command;
  command.mode = mode_;
  const Eigen::Vector2d v_B = X_MB.rotation().transpose() * v_M;
  const double heading = v_M.norm() > 1e-9 ? std::atan2(v_M.y(), v_M.x()) : X_MB.yaw;
  command.V_B = {v_B.x(), v_B.y(), config_.turn_gain * WrapAngle(heading - X_MB.yaw)};
  return command;
}

BugCommand Bug2Navigator::Step(const Pose2& X_MB, const std::vector<Eigen::Vector2d>& p_MObstacles,
                               const std::vector<Eigen::Vector2d>& p_MPeople, double dt) {
  ThrowUnless(X_MB.IsFinite() && std::isfinite(dt) && dt >= 0.0,
              "Invalid Bug2 step: pose and dt must be finite.");
  const Eigen::Vector2d p = X_MB.translation();
  if (mode_ == BugMode::kReached || mode_ == BugMode::kFailed)
    return Command(X_MB, Eigen::Vector2d::Zero());
  const Eigen::Vector2d to_goal = goal_ - p;
  if (to_goal.norm() <= config_.goal_tolerance) {
    mode_ = BugMode::kReached;
    return Command(X_MB, Eigen::Vector2d::Zero());
  }
  // Never push into a person: stop while one is close and ahead of the intended motion.
  const Eigen::Vector2d goal_direction = to_goal.normalized();
  for (const auto& person : p_MPeople) {
    const Eigen::Vector2d d = person - p;
    if (d.norm() < config_.person_stop_distance && d.dot(goal_direction) > -0.2 * d.norm()) {
      BugCommand command = Command(X_MB, Eigen::Vector2d::Zero());
      command.mode = BugMode::kWaitingForPerson;
      command.reason = "a person is within the stop distance ahead";
      command.V_B = {};
      return command;
    }
  }
  const double mline_side = Cross(goal_ - start_, p - start_);
  if (mode_ == BugMode::kMotionToGoal) {
    if (!Blocked(p, goal_direction, p_MObstacles)) {
      last_mline_side_ = mline_side;
      return Command(X_MB, config_.speed * goal_direction);
    }
    mode_ = BugMode::kBoundaryFollowing;
    hit_point_ = p;
    hit_distance_ = to_goal.norm();
    followed_ = 0.0;
    last_mline_side_ = 0.0;
    // Follow on the side whose tangent turns less from the goal direction.
    const Eigen::Vector2d* nearest = nullptr;
    double best = std::numeric_limits<double>::infinity();
    for (const auto& q : p_MObstacles) {
      if ((q - p).norm() < best) {
        best = (q - p).norm();
        nearest = &q;
      }
    }
    const Eigen::Vector2d n =
        nearest ? Eigen::Vector2d((p - *nearest).normalized()) : -goal_direction;
    side_ = Ccw(n).dot(goal_direction) >= (-Ccw(n)).dot(goal_direction) ? 1.0 : -1.0;
  }
  // Boundary following.
  followed_ += config_.speed * dt;
  if (followed_ > config_.max_follow_length) {
    mode_ = BugMode::kFailed;
    BugCommand command = Command(X_MB, Eigen::Vector2d::Zero());
    command.reason = "the obstacle boundary is longer than max_follow_length; replan";
    return command;
  }
  if (followed_ > 1.0 && (p - hit_point_).norm() < config_.goal_tolerance * 2) {
    mode_ = BugMode::kFailed;
    BugCommand command = Command(X_MB, Eigen::Vector2d::Zero());
    command.reason =
        "walked around the obstacle back to where it was hit: the goal is enclosed; replan";
    return command;
  }
  // Leave the boundary on crossing the m-line closer to the goal, with the way ahead free.
  const bool crossed = last_mline_side_ != 0.0 && (mline_side > 0.0) != (last_mline_side_ > 0.0);
  last_mline_side_ = mline_side;
  if (crossed && to_goal.norm() < hit_distance_ - 0.05 &&
      !Blocked(p, goal_direction, p_MObstacles)) {
    mode_ = BugMode::kMotionToGoal;
    return Command(X_MB, config_.speed * goal_direction);
  }
  const Eigen::Vector2d* nearest = nullptr;
  double distance = std::numeric_limits<double>::infinity();
  for (const auto& q : p_MObstacles) {
    if ((q - p).norm() < distance) {
      distance = (q - p).norm();
      nearest = &q;
    }
  }
  if (nearest == nullptr || distance > config_.follow_distance + config_.lookahead) {
    // Lost the boundary (went round a corner): turn toward where it was, i.e. keep circling.
    mode_ = BugMode::kMotionToGoal;
    return Command(X_MB, config_.speed * goal_direction);
  }
  const Eigen::Vector2d n = (p - *nearest) / distance;  // away from the obstacle
  const Eigen::Vector2d tangent = side_ * Ccw(n);
  Eigen::Vector2d v =
      config_.speed * tangent + config_.follow_gain * (config_.follow_distance - distance) * n;
  if (v.norm() > config_.speed) v *= config_.speed / v.norm();
  return Command(X_MB, v);
}

}  // namespace egress::planning
