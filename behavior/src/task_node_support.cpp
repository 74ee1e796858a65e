#include "task_node_support.h"

#include <cstdio>

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

#include "egress/planning/trajectory.h"

namespace egress::behavior::detail {

bool ArmAt(const ArmPose& a, const ArmPose& b) {
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (std::abs(a[i] - b[i]) > kArmTolerance) return false;
  }
  return true;
}

std::string PoseText(const Pose2& X) {
  return StrCat(std::round(X.x * 100) / 100, ", ", std::round(X.y * 100) / 100);
}

std::string PosePortText(const Pose2& X) {
  char buffer[96];  // %.17g: reads back to the same doubles
  std::snprintf(buffer, sizeof(buffer), "%.17g;%.17g;%.17g", X.x, X.y, X.yaw);
  return buffer;
}

double BlindTravel(const TaskServices& task, const std::vector<Pose2>& path) {
  // Where the footprint's leading edge will be a little ahead: the space the base drives into.
  const double look = task.config.footprint_radius + kBlindLookAheadM;
  double blind = 0.0;
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    const Eigen::Vector2d d = path[i + 1].translation() - path[i].translation();
    const double length = d.norm();
    if (length < 0.01) continue;
    const Eigen::Vector2d ahead = d / length * look;
    // The heading turns evenly along a segment: seen at both ends, the way is seen along it.
    if (!IsInLaserSweep(task, path[i], path[i].translation() + ahead) ||
        !IsInLaserSweep(task, {path[i + 1].x, path[i + 1].y, path[i + 1].yaw},
                        path[i + 1].translation() + ahead))
      blind += length;
  }
  return blind;
}

void FaceTravel(std::vector<Pose2>* path, double goal_yaw) {
  std::vector<Pose2>& p = *path;
  std::vector<Pose2> faced{p.front()};
  double yaw = p.front().yaw;
  for (std::size_t i = 0; i + 1 < p.size(); ++i) {
    const Eigen::Vector2d d = p[i + 1].translation() - p[i].translation();
    if (d.norm() < 0.01) continue;  // an escape step's end: the next segment's way
    const double travel = std::atan2(d.y(), d.x());
    // Turned on the spot where the way turns much, else the turn spread along the segment.
    if (std::abs(std::remainder(travel - yaw, 2 * M_PI)) > kFaceTravelTurnFirstRad)
      faced.push_back({p[i].x, p[i].y, yaw + std::remainder(travel - yaw, 2 * M_PI)});
    yaw = faced.back().yaw + std::remainder(travel - faced.back().yaw, 2 * M_PI);
    faced.push_back({p[i + 1].x, p[i + 1].y, yaw});
  }
  // At the goal, to its heading on the spot.
  if (std::abs(std::remainder(goal_yaw - yaw, 2 * M_PI)) > 1e-3)
    faced.push_back({p.back().x, p.back().y, yaw + std::remainder(goal_yaw - yaw, 2 * M_PI)});
  p = std::move(faced);
}

// Starts a base motion along a planned path; RUNNING until it ends.
// Plans from the robot to `goal` on the costmap and starts following the path; `door_speed`
// runs every segment at the door speed (a door approach inside the hold window).
NodeStatus StartPath(const TaskServices& task, const Pose2& goal, const std::string& what,
                     const std::function<void(const std::string&)>& note, bool door_speed,
                     PathHeading heading) {
  planning::PlanResult plan = task.planner->Plan(task.belief->X_MB, goal);
  if (plan.status == planning::PlanStatus::kStartInCollision) {
    // The robot stands where the costmap says it cannot (inflation around a leaf, a person seen
    // close by, an obstacle it brushed): step to the nearest free pose — never across an
    // obstacle cell — preferring the goal's direction, and plan from there.
    const Eigen::Vector2d towards =
        (goal.translation() - task.belief->X_MB.translation()).normalized();
    const double heading = std::atan2(towards.y(), towards.x());
    const perception::Costmap2D& costmap = *task.belief->world.costmap;
    bool escaped = false;
    for (double step = 0.05; step <= 0.6 && !escaped; step += 0.05) {
      for (int k = 0; k < 16 && !escaped; ++k) {
        // 0, +22.5°, -22.5°, +45°, ... around the goal's direction.
        const double a = heading + (k % 2 == 0 ? 1 : -1) * ((k + 1) / 2) * M_PI / 8;
        const Eigen::Vector2d d(std::cos(a), std::sin(a));
        const Eigen::Vector2d p = task.belief->X_MB.translation() + d * step;
        const Pose2 escape{p.x(), p.y(), task.belief->X_MB.yaw};
        if (!task.planner->IsValid(escape)) continue;
        bool crosses = false;
        for (double s = 0.02; s < step && !crosses; s += 0.02)
          crosses =
              costmap.CostAt(task.belief->X_MB.translation() + d * s) >= perception::kLethalCost;
        if (crosses) continue;
        planning::PlanResult rest = task.planner->Plan(escape, goal);
        if (!rest.ok()) continue;
        rest.path.insert(rest.path.begin(), task.belief->X_MB);
        rest.length += step;
        plan = rest;
        escaped = true;
      }
    }
  }
  if (!plan.ok()) {
    note(StrCat("no path to ", what, " (", PoseText(goal), "): ", plan.message));
    return NodeStatus::kFailure;
  }
  if (plan.path.size() < 2 ||
      (plan.path.back().translation() - task.belief->X_MB.translation()).norm() < 0.01) {
    return NodeStatus::kSuccess;  // already there
  }
  std::vector<Pose2> path = plan.path;
  path.front().yaw = task.belief->X_MB.yaw;
  if ((heading == PathHeading::kAlongTravel || heading == PathHeading::kAcrossTravel) &&
      plan.length >= kFaceTravelBeyondM) {
    // Each waypoint faces along the segment that starts there (the last, along the one that
    // ends there), or square to it: the robot turns into each segment on the one before.
    double offset = 0.0;  // [rad] from the way of travel
    const auto segment_yaw = [&](std::size_t i) {
      const Eigen::Vector2d d = path[i + 1].translation() - path[i].translation();
      return std::atan2(d.y(), d.x()) + offset;
    };
    // Segments too short to have a direction (an escape step's end) take the next one's.
    std::size_t first = 0;
    while (first + 2 < path.size() &&
           (path[first + 1].translation() - path[first].translation()).norm() < 0.01)
      ++first;
    if (heading == PathHeading::kAcrossTravel)
      offset = std::remainder(task.belief->X_MB.yaw - segment_yaw(first), 2 * M_PI) >= 0.0
                   ? M_PI / 2
                   : -M_PI / 2;
    const double first_yaw = segment_yaw(first);
    for (std::size_t i = 1; i + 1 < path.size(); ++i)
      path[i].yaw = i <= first ? first_yaw : segment_yaw(i);
    path.back().yaw = segment_yaw(path.size() - 2);
    if (std::abs(std::remainder(first_yaw - task.belief->X_MB.yaw, 2 * M_PI)) >
        kFaceTravelTurnFirstRad) {
      Pose2 turned = task.belief->X_MB;
      turned.yaw = first_yaw;
      path.insert(path.begin() + 1, turned);
    }
  } else {
    // The base is holonomic: turn from the start yaw to the goal yaw evenly along the path
    // rather than through the planner's intermediate headings.
    const double turn = std::remainder(goal.yaw - task.belief->X_MB.yaw, 2 * M_PI);
    double travelled = 0.0;
    for (std::size_t i = 1; i < path.size(); ++i) {
      travelled += (path[i].translation() - path[i - 1].translation()).norm();
      const double fraction = plan.length > 0 ? std::min(1.0, travelled / plan.length) : 1.0;
      path[i].yaw = task.belief->X_MB.yaw + turn * fraction;
    }
  }
  if (BlindTravel(task, path) > kBlindTravelToleranceM) FaceTravel(&path, goal.yaw);
  const std::vector<bool> through(path.size() - 1, door_speed);
  task.motion->FollowPath(path, through, task.motion->arm_target(), task.belief->now);
  note(StrCat("driving to ", what, " (", PoseText(goal), ", ", std::round(plan.length * 100) / 100,
              " m)"));
  return NodeStatus::kRunning;
}

NodeStatus BaseMotionStatus(const TaskServices& task,
                            const std::function<void(const std::string&)>& note) {
  if (task.motion->base_failed()) {
    note("stopped: " + task.motion->base_failure());
    return NodeStatus::kFailure;
  }
  return task.motion->base_moving() ? NodeStatus::kRunning : NodeStatus::kSuccess;
}

// The arm motion under way: running while the joints travel, failure (with the joint that
// stopped short) when they did not arrive in time, success once they are at the target.
NodeStatus ArmMotionStatus(const TaskServices& task,
                           const std::function<void(const std::string&)>& note) {
  if (task.motion->arm_moving(task.belief->now)) return NodeStatus::kRunning;
  if (task.motion->arm_failed()) {
    note(task.motion->arm_failure());
    return NodeStatus::kFailure;
  }
  return NodeStatus::kSuccess;
}

// The next kPathLookahead metres of the path being followed cross lethal or inscribed cost.
bool IsPathAheadBlocked(const TaskServices& task) {
  const std::vector<Pose2>& path = task.motion->path();
  if (path.size() < 2) return false;
  // From the waypoint segment nearest the robot on.
  std::size_t next = 1;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i < path.size(); ++i) {
    const Eigen::Vector2d a = path[i - 1].translation(), b = path[i].translation();
    const Eigen::Vector2d ab = b - a;
    const double t =
        ab.squaredNorm() > 0
            ? std::clamp((task.belief->X_MB.translation() - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0)
            : 0.0;
    const double d = (a + t * ab - task.belief->X_MB.translation()).norm();
    if (d < best) {
      best = d;
      next = i;
    }
  }
  std::vector<Pose2> ahead{task.belief->X_MB};
  double length = 0.0;
  std::size_t last = next;  // the waypoint that ends the last segment looked along
  for (std::size_t i = next; i < path.size() && length < kPathLookahead; ++i) {
    last = i;
    const Eigen::Vector2d step = path[i].translation() - ahead.back().translation();
    const double remaining = kPathLookahead - length;
    if (step.norm() > remaining) {
      // A point along the segment turned as far as the motion along it turns there (the
      // planner's interpolation): the body is not round.
      const double f = remaining / step.norm();
      const Pose2& from = ahead.back();
      const Eigen::Vector2d p = from.translation() + step * f;
      ahead.push_back({p.x(), p.y(), from.yaw + f * WrapAngle(path[i].yaw - from.yaw)});
      break;
    }
    ahead.push_back(path[i]);
    length += step.norm();
  }
  if (ahead.size() < 2) return false;
  const planning::BasePlanner& planner = *task.planner;
  // Starting inside inflation (e.g. beside a door) is not a new blockage: test from the
  // first free pose on.
  if (!planner.IsValid(task.belief->X_MB) || planner.IsPathValid(ahead)) return false;
  // From where the robot is to the path: a plan from here goes round what blocks it.
  if (!planner.IsPathValid({task.belief->X_MB, path[next]})) return true;
  // Further on, only what blocks the planned segments themselves, whole, as the planner checks
  // them: a piece of one is sampled at other points and can meet a sliver of inscribed cost that
  // the planner's samples step over, and a plan from here would be the same path again (the
  // school of worlds/tools/make_school.py: 442 plans at a corridor's inner corner, the robot
  // standing).
  return last > next && !planner.IsPathValid(std::vector<Pose2>(path.begin() + long(next),
                                                                path.begin() + long(last) + 1));
}

// BaseMotionStatus for a planned drive: when the path ahead becomes blocked on the costmap (an
// obstacle the map does not show, seen only once the robot is on its way), plan again to the
// same end pose instead of driving into it.
NodeStatus DriveStatus(const TaskServices& task,
                       const std::function<void(const std::string&)>& note, bool door_speed) {
  if (task.motion->base_moving() && !task.motion->bug_active() && IsPathAheadBlocked(task)) {
    const Pose2 goal = task.motion->path().back();
    task.motion->StopBase();
    note("the path ahead is blocked: planning again");
    const NodeStatus s = StartPath(task, goal, "the same pose", note, door_speed);
    if (s != NodeStatus::kRunning) return s;
  }
  return BaseMotionStatus(task, note);
}

// Arm-only IK at the current base pose (the base stays where it stopped). A solve that ends
// within `accept_error` of the target counts (0: only a converged one; DLS with the paper's
// damping creeps over the last millimetres, which a grasp does not need).
std::optional<ArmPose> SolveArm(const TaskServices& task, const Pose2& X_MB,
                                const planning::IkTarget& target, const ArmPose& from,
                                bool fingertip, double accept_error, bool allow_slant) {
  planning::IkConfig ik = task.config.ik;
  ik.fingertip = fingertip;
  ik.use_base = false;
  WholeBodyVector q = WholeBodyVector::Zero();
  q[kBaseX] = X_MB.x;
  q[kBaseY] = X_MB.y;
  q[kBaseYaw] = X_MB.yaw;
  q = WithArm(q, from);
  const planning::DlsIkSolver solver(*task.model, ik);
  const auto good = [&](const planning::IkResult& r) {
    return r.converged || (r.position_error <= accept_error &&
                           r.orientation_error <= task.config.ik.orientation_tolerance);
  };
  planning::IkResult r = solver.Solve(target, q);
  if (!good(r) && target.approach_M && allow_slant) {
    // With the base a little off its planned pose the arm alone may not hold the approach
    // axis too: the position is what presses.
    planning::IkTarget position_only = target;
    position_only.approach_M.reset();
    r = solver.Solve(position_only, q);
  }
  if (!good(r)) return std::nullopt;
  return ArmOf(r.q);
}

std::optional<std::vector<ArmPose>> SolveArmLine(const TaskServices& task, const Pose2& X_MB,
                                                 const planning::IkTarget& from_target,
                                                 const planning::IkTarget& to_target,
                                                 const ArmPose& from, bool fingertip, int steps) {
  ThrowUnless(steps >= 1, "SolveArmLine: steps (", steps, ") must be >= 1.");
  std::vector<ArmPose> knots;
  ArmPose seed = from;
  for (int i = 1; i <= steps; ++i) {
    planning::IkTarget point = to_target;
    const double f = double(i) / steps;
    point.p_MT = (1.0 - f) * from_target.p_MT + f * to_target.p_MT;
    const auto arm = SolveArm(task, X_MB, point, seed, fingertip);
    if (!arm) return std::nullopt;
    knots.push_back(*arm);
    seed = *arm;
  }
  return knots;
}

double PositionSigma(const TaskServices& task) {
  const Eigen::Matrix2d C = task.belief->world.X_MB_covariance.topLeftCorner<2, 2>();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(C);
  return std::sqrt(std::max(0.0, eigen.eigenvalues().maxCoeff()));
}

NodeStatus RelocalizeGate::Check(const TaskServices& task, const std::string& act,
                                 const EventNoteFn& note, std::optional<double> act_limit) {
  // Checked every tick of an act: after a wait that timed out, a new one each tick the act was
  // still not under way took 3 s at a time until the door's window had gone (random building
  // seed 12: three waits, "the door did not open in time", and again each press to 400 s).
  if (gave_up_) return NodeStatus::kSuccess;
  const double sigma = PositionSigma(task);
  const double limit = act_limit.value_or(task.config.precise_pose_sigma);
  if (!waiting_since_) {
    if (sigma <= limit) return NodeStatus::kSuccess;
    waiting_since_ = task.belief->now;
    task.motion->StopBase();
    note(StrCat("the pose is uncertain (", std::round(sigma * 1000), " mm): re-localizing before ",
                act),
         DecisionEvent::kRelocalizing);
    return NodeStatus::kRunning;
  }
  if (sigma <= limit) {
    note(StrCat("re-localized (", std::round(sigma * 1000), " mm)"), DecisionEvent::kNote);
    waiting_since_.reset();
    return NodeStatus::kSuccess;
  }
  if (ToSeconds(task.belief->now - *waiting_since_) < task.config.relocalize_timeout)
    return NodeStatus::kRunning;
  note(StrCat("the pose stayed uncertain (", std::round(sigma * 1000), " mm): ", act, " anyway"),
       DecisionEvent::kNote);
  waiting_since_.reset();
  gave_up_ = true;
  return NodeStatus::kSuccess;
}

}  // namespace egress::behavior::detail
