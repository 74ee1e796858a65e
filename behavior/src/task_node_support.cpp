#include "task_node_support.h"

#include <cstdio>

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

#include "egress/behavior/proxemics.h"
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
                                bool fingertip, double accept_error) {
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
  if (!good(r) && target.approach_M) {
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

namespace {
// A predicted way meeting a wall turns along it in steps of kWallTurnRad, up to kMaxWallTurns.
constexpr double kWallTurnRad = 15.0 * M_PI / 180.0;
constexpr int kMaxWallTurns = 6;
}  // namespace

void AppendPredictedWay(const TaskServices& task, const Eigen::Vector2d& at, double look,
                        double horizon, double step, int first_step, Eigen::Vector2d p_MP,
                        Eigen::Vector2d v_MP, std::vector<Occupant>& near) {
  const perception::Costmap2D* costmap = task.belief->world.costmap;
  const double wall_gap = 0.5 * task.config.person_radius;
  const auto walkable = [&](const Eigen::Vector2d& p) {
    return !costmap || !costmap->IsNearMappedObstacle(p, wall_gap);
  };
  const Eigen::Vector2d v_MStart = v_MP;
  for (int k = 0; step > 0 ? k * step <= horizon + 1e-9 : k == 0; ++k) {
    if (k > 0) {
      // Nobody walks through a wall: a way predicted into one (a velocity a few degrees askew
      // along a corridor, over seconds) turns along it, by the least turn that is free. Never
      // back the way they came (more than kMaxWallTurns from where they walk now): at a dead
      // end, or a wall straight ahead, they stop there (P2's group, walking to the corridor's
      // end, was predicted back along the wall onto the robot's spot aside).
      bool free = walkable(p_MP + v_MP * step);
      for (int turn = 1; !free && turn <= kMaxWallTurns; ++turn) {
        for (const double sign : {1.0, -1.0}) {
          const Eigen::Vector2d v = Eigen::Rotation2Dd(sign * turn * kWallTurnRad) * v_MP;
          if (v.dot(v_MStart) >= -1e-9 && walkable(p_MP + v * step)) {
            v_MP = v;
            free = true;
            break;
          }
        }
      }
      if (!free) v_MP.setZero();
      p_MP += v_MP * step;
    }
    if (k >= first_step && (p_MP - at).norm() < look)
      near.push_back({p_MP, task.config.person_radius, k * step, v_MP});
    if (step <= 0) break;
  }
}

std::vector<Occupant> PeopleAround(const TaskServices& task, const Eigen::Vector2d& at, double look,
                                   double horizon, double step) {
  std::vector<Occupant> near;
  for (const Eigen::Vector2d& p : task.belief->off_map_returns)
    if ((p - at).norm() < look) near.push_back({p, 0.0});
  for (const auto& entry : task.belief->world.people)
    AppendPredictedWay(task, at, look, horizon, step, 0, entry.person.p_MP, entry.person.v_MP,
                       near);
  return near;
}

std::vector<Occupant> ThroughDoorWays(const TaskServices& task, const std::string& door,
                                      double horizon) {
  const perception::DoorModel* model = task.map->FindDoor(door);
  ThrowUnless(model != nullptr, "unknown door '", door, "' (not in the building map)");
  const perception::DoorZone zone{*model, task.config.zone_depth, task.config.person_radius};
  const DoorPass pass = CalcDoorPass(*task.map, door, task.belief->X_MB);
  const Eigen::Vector2d at = task.belief->X_MB.translation();
  const double step = PeopleRoom::kPeopleStepSec;
  std::vector<Occupant> ways;
  for (const auto& entry : task.belief->world.people) {
    const perception::TrackedPerson& person = entry.person;
    const Eigen::Vector2d to_centre = pass.centre - person.p_MP;
    const double distance = to_centre.norm();
    const bool far_side = -to_centre.dot(pass.n_M) < 0.0;
    if (distance > kThroughDoorRadiusM || !(far_side || zone.Contains(person.p_MP)) ||
        IsHoldingDoorAside(task, entry, door) ||
        (distance > 1e-6 && person.v_MP.dot(to_centre / distance) < -PeopleRoom::kSidestepMinMps))
      continue;
    const double speed = std::max(person.v_MP.norm(), kWalkingMps);
    // To the middle of the opening, then on along the normal (walls turning the way).
    const double t_centre = distance / speed;
    int k = 1;
    for (; k * step < t_centre && k * step <= horizon + 1e-9; ++k) {
      const Eigen::Vector2d p = person.p_MP + to_centre * (k * step / t_centre);
      if ((p - at).norm() < PeopleRoom::kPeopleLookM)
        ways.push_back({p, task.config.person_radius, k * step, to_centre / distance * speed});
    }
    if (k * step > horizon + 1e-9) continue;
    const std::size_t first = ways.size();
    AppendPredictedWay(task, at, PeopleRoom::kPeopleLookM, horizon - t_centre, step, 0, pass.centre,
                       pass.n_M * speed, ways);
    for (std::size_t i = first; i < ways.size(); ++i)
      ways[i].t += t_centre;
  }
  return ways;
}

double RoomAt(const std::vector<Occupant>& near, const Eigen::Vector2d& q) {
  double room = std::numeric_limits<double>::infinity();
  for (const Occupant& o : near)
    room = std::min(room, (o.p_M - q).norm() - o.radius);
  return room;
}

PeopleRoom::PeopleRoom(const TaskServices& task, double horizon, PeopleHypotheses hypotheses)
    : task_(task),
      at_(task.belief->X_MB.translation()),
      predicted_(PeopleAround(task, at_, kPeopleLookM, horizon, kPeopleStepSec)),
      now_(PeopleAround(task, at_, kPeopleLookM, 0.0, 0.0)) {
  const bool sidestep = hypotheses.sidestep;
  if (!hypotheses.through_door.empty()) {
    const std::vector<Occupant> through = ThroughDoorWays(task, hypotheses.through_door, horizon);
    predicted_.insert(predicted_.end(), through.begin(), through.end());
  }
  if (hypotheses.head_on) {
    for (const auto& entry : task.belief->world.people) {
      const Eigen::Vector2d to_robot = at_ - entry.person.p_MP;
      const double speed = entry.person.v_MP.norm(), distance = to_robot.norm();
      if (distance >= kHeadOnRadiusM || distance < 1e-6 || speed < kSidestepMinMps ||
          entry.person.v_MP.dot(to_robot) <= 0.0)
        continue;
      // Their place now is already predicted: the way from the first step on.
      AppendPredictedWay(task, at_, kPeopleLookM, horizon, kPeopleStepSec, 1, entry.person.p_MP,
                         to_robot * (speed / distance), predicted_);
    }
  }
  const perception::Costmap2D* costmap = task.belief->world.costmap;
  const double body = task.config.person_radius;
  for (const Occupant& o : predicted_) {
    std::pair<Eigen::Vector2d, Eigen::Vector2d> ends{o.p_M, o.p_M};
    const double speed = o.v_M.norm();
    const double reach =
        std::min(task.config.person_sidestep, task.config.person_sidestep_speed * o.t);
    if (sidestep && o.radius > 0.0 && speed >= kSidestepMinMps && reach > 0.0) {
      const Eigen::Vector2d across = Eigen::Vector2d(-o.v_M.y(), o.v_M.x()) / speed;
      // As far to each side as the walls leave the body room.
      const auto side = [&](double sign) {
        Eigen::Vector2d end = o.p_M;
        for (double s = kSidestepSampleM; s <= reach + 1e-9; s += kSidestepSampleM) {
          const Eigen::Vector2d p = o.p_M + sign * s * across;
          if (costmap && costmap->IsNearMappedObstacle(p, body)) break;
          end = p;
        }
        return end;
      };
      ends = {side(1.0), side(-1.0)};
    }
    sidesteps_.push_back(ends);
  }
}

double PeopleRoom::RoomFrom(std::size_t i, const Eigen::Vector2d& p_MB) const {
  // The farthest point of the sidestep segment from the base is one of its ends.
  const auto& [a, b] = sidesteps_[i];
  return std::max((a - p_MB).norm(), (b - p_MB).norm()) - predicted_[i].radius;
}

double PeopleRoom::Predicted(const Eigen::Vector2d& q) const {
  double room = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < predicted_.size(); ++i)
    room = std::min(room, RoomFrom(i, q));
  return room;
}

double PeopleRoom::RoomOnTheWay(const std::vector<Eigen::Vector2d>& corners) const {
  planning::TrajectoryConfig timing = task_.motion->trajectory_config();
  timing.nominal_speed = task_.config.retreat_speed;
  // Each leg's start time and its progress 0 -> 1, as the trajectory will time it.
  std::vector<double> starts{0.0};
  std::vector<planning::SegmentTimeScaling> legs;
  for (std::size_t i = 0; i + 1 < corners.size(); ++i) {
    const double length = (corners[i + 1] - corners[i]).norm();
    legs.emplace_back(length, planning::SegmentDuration(length, false, timing), timing);
    starts.push_back(starts.back() + legs.back().duration());
  }
  const auto base_at = [&](double t) -> Eigen::Vector2d {
    for (std::size_t i = 0; i < legs.size(); ++i)
      if (t < starts[i + 1])
        return corners[i] + (corners[i + 1] - corners[i]) * legs[i].Progress(t - starts[i]);
    return corners.back();
  };
  double room = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < predicted_.size(); ++i) {
    const Occupant& o = predicted_[i];
    // A scan return off the map stands where it is: compared with the spot.
    const Eigen::Vector2d p_MB = o.radius > 0.0 ? base_at(o.t) : corners.back();
    room = std::min(room, RoomFrom(i, p_MB));
  }
  return room;
}

double PeopleRoom::Score(const std::vector<Eigen::Vector2d>& corners) const {
  const double comfortable = task_.config.footprint_radius + task_.config.comfort_distance;
  const Eigen::Vector2d& q = corners.back();
  const double at_spot = std::min(Predicted(q), comfortable);
  return std::min(at_spot, RoomOnTheWay(corners)) + kSpotRoomTieBreak * at_spot -
         kWayCostPerM * (q - at_).norm();
}

bool IsInLaserSweep(const TaskServices& task, const Pose2& X_MB, const Eigen::Vector2d& p_M) {
  const Belief& belief = *task.belief;
  if (!belief.scan || (p_M - X_MB.translation()).norm() <= task.config.footprint_radius)
    return true;
  const Eigen::Vector2d p_L = (X_MB * belief.X_BL).Inverse() * p_M;
  const double bearing = std::atan2(p_L.y(), p_L.x());
  return bearing >= belief.scan->angle_min + PeopleRoom::kSweepMarginRad &&
         bearing <= belief.scan->angle_max() - PeopleRoom::kSweepMarginRad;
}

bool IsInLaserSight(const TaskServices& task, const Pose2& X_MB, const Eigen::Vector2d& p_M) {
  if (!IsInLaserSweep(task, X_MB, p_M)) return false;
  const perception::Costmap2D* costmap = task.belief->world.costmap;
  if (costmap == nullptr) return true;
  // Sampled finer than a wall is thick; a cell's half-diagonal catches the corners between.
  constexpr double kSightSampleM = 0.05;
  const Eigen::Vector2d p_ML = (X_MB * task.belief->X_BL).translation();
  const double length = (p_M - p_ML).norm() - kSightShortM;
  if (length <= 0.0) return true;
  const Eigen::Vector2d u = (p_M - p_ML).normalized();
  const double half_cell = 0.5 * std::sqrt(2.0) * costmap->geometry().resolution;
  for (double s = 0.0; s <= length; s += kSightSampleM)
    if (costmap->IsNearMappedObstacle(p_ML + s * u, half_cell)) return false;
  return true;
}

std::optional<Eigen::Vector2d> NearestOnGrid(
    const Eigen::Vector2d& p_MFrom, const Eigen::Vector2d& along, double max_along,
    const Eigen::Vector2d& out, double max_out, double step, double min_distance,
    const std::function<bool(const Eigen::Vector2d&)>& ok) {
  std::vector<Eigen::Vector2d> offsets;
  for (int i = 0; i * step <= max_along + 1e-9; ++i)
    for (int j = 0; j * step <= max_out + 1e-9; ++j)
      offsets.push_back(along * i * step + out * j * step);
  std::stable_sort(offsets.begin(), offsets.end(),
                   [](const auto& l, const auto& r) { return l.norm() < r.norm(); });
  for (const auto& offset : offsets) {
    if (offset.norm() < min_distance - 1e-9) continue;
    if (ok(p_MFrom + offset)) return p_MFrom + offset;
  }
  return std::nullopt;
}

bool IsBlindWayClear(const TaskServices& task, const Pose2& X_MB, const Eigen::Vector2d& p_MFrom,
                     const Eigen::Vector2d& p_MTo, double clearance) {
  const perception::Costmap2D* costmap = task.belief->world.costmap;
  if (costmap == nullptr) return true;
  constexpr double kSampleM = 0.15;  // the way is checked this often
  const int steps = std::max(1, int(std::ceil((p_MTo - p_MFrom).norm() / kSampleM)));
  for (int k = 1; k <= steps; ++k) {
    const Eigen::Vector2d p = p_MFrom + (p_MTo - p_MFrom) * (double(k) / steps);
    if (!IsInLaserSweep(task, X_MB, p) &&
        costmap->IsNearUnmappedMark(p, task.config.footprint_radius + clearance, kOffMapM))
      return false;
  }
  return true;
}

bool PeopleRoom::IsSeenFrom(const Pose2& X_MB, const Eigen::Vector2d& p) const {
  // Where the base just drove, facing that way: nobody stood there as it passed.
  for (const auto& [t, p_MB] : task_.belief->swept_p_MB)
    if ((p - p_MB).norm() <= task_.config.footprint_radius) return true;
  return IsInLaserSweep(task_, X_MB, p);
}

bool PeopleRoom::AllAlong(const std::vector<Eigen::Vector2d>& corners,
                          const std::function<bool(const Eigen::Vector2d&)>& f) const {
  for (std::size_t i = 0; i + 1 < corners.size(); ++i) {
    const double length = (corners[i + 1] - corners[i]).norm();
    const int steps = std::max(1, int(std::ceil(length / kPathSampleM)));
    for (int k = 1; k <= steps; ++k)
      if (!f(corners[i] + (corners[i + 1] - corners[i]) * (double(k) / steps))) return false;
  }
  return true;
}

bool PeopleRoom::IsWayClear(const std::vector<Eigen::Vector2d>& corners) const {
  const double passable = task_.config.footprint_radius + kPassMarginM;
  const Pose2& X_MB = task_.belief->X_MB;
  return AllAlong(corners, [&](const Eigen::Vector2d& p) {
    return RoomAt(now_, p) >= passable && IsSeenFrom(X_MB, p);
  });
}

std::optional<double> PeopleRoom::YawSeeing(const std::vector<Eigen::Vector2d>& corners) const {
  if (!task_.belief->scan) return std::nullopt;
  Pose2 X_MB = task_.belief->X_MB;
  const double yaw = X_MB.yaw;
  for (double turn = 0.0; turn <= M_PI + 1e-9; turn += kLookTurnStepRad) {
    for (const double sign : {1.0, -1.0}) {
      X_MB.yaw = yaw + sign * turn;
      if (AllAlong(corners, [&](const Eigen::Vector2d& p) { return IsSeenFrom(X_MB, p); }))
        return X_MB.yaw;
    }
  }
  return std::nullopt;
}

std::optional<Pose2> PeopleRoom::BestSpotAround(const std::vector<Pose2>& way, double beat) const {
  std::vector<Eigen::Vector2d> corners;
  for (const Pose2& p : way)
    corners.push_back(p.translation());
  corners.push_back(Eigen::Vector2d::Zero());
  const double yaw = task_.belief->X_MB.yaw;
  std::optional<Pose2> best;
  for (const double radius : kSpotRadiiM) {
    for (int k = 0; k < kSpotHeadings; ++k) {
      const double a = 2 * M_PI * k / kSpotHeadings;
      const Eigen::Vector2d q = at_ + radius * Eigen::Vector2d(std::cos(a), std::sin(a));
      corners.back() = q;
      const double s = Score(corners);
      // Nor through a doorway: its leaf may close meanwhile (two wards seed 5 met door_d's).
      if (s <= beat || IsInAnyDoorZone(task_, q) ||
          PassesThroughAnyDoorway(task_, way.back().translation(), q) || !IsWayClear(corners))
        continue;
      const perception::Costmap2D* costmap = task_.belief->world.costmap;
      if (costmap != nullptr &&
          costmap->IsNearMappedObstacle(q, task_.config.footprint_radius + kSpotWallClearanceM))
        continue;
      const Pose2 candidate{q.x(), q.y(), yaw};
      if (!HandClearOfWalls(task_, way.back(), q)) continue;
      if (!task_.planner->IsPathValid({way.back(), candidate})) continue;
      best = candidate;
      beat = s;
    }
  }
  return best;
}

bool StoppedOrStopTimedOut(const TaskServices& task, Time since) {
  const Belief& belief = *task.belief;
  return std::hypot(belief.V_B.vx, belief.V_B.vy) <= kStoppedMps ||
         ToSeconds(belief.now - since) >= kStopWithinSec;
}

std::optional<Pose2> MakeWaySpot(const TaskServices& task, double min_gain,
                                 PeopleHypotheses hypotheses,
                                 const std::optional<Eigen::Vector2d>& stepping_to) {
  hypotheses.sidestep = true;
  const PeopleRoom room(task, 2.0 * task.config.give_way_horizon, std::move(hypotheses));
  const Pose2& X_MB = task.belief->X_MB;
  std::vector<Eigen::Vector2d> staying{X_MB.translation()};
  if (stepping_to) staying.push_back(*stepping_to);
  return room.BestSpotAround({X_MB}, room.Score(staying) + min_gain);
}

std::vector<std::pair<const perception::TrackedPerson*, double>> PeopleComing(
    const TaskServices& task, const std::optional<Pose2>& goal) {
  const Belief& belief = *task.belief;
  const Eigen::Vector2d at = belief.X_MB.translation();
  std::vector<std::pair<const perception::TrackedPerson*, double>> coming;
  for (const auto& entry : belief.world.people) {
    if (goal &&
        IsWhomTheRobotGoesTo(entry.person.p_MP, at, goal->translation(), kGoalPersonRadiusM))
      continue;
    if (const auto t_pass = OncomingPassTime(
            entry.person, at, task.config.footprint_radius, task.config.person_radius,
            task.config.comfort_distance, task.config.give_way_horizon, kWalkingMps))
      coming.emplace_back(&entry.person, *t_pass);
  }
  return coming;
}

void StepAsideTo(const TaskServices& task, const Pose2& spot) {
  task.motion->FollowPath({task.belief->X_MB, spot}, {false}, task.motion->arm_target(),
                          task.belief->now, task.config.retreat_speed, /*brisk=*/true);
}

bool HandClearOfWalls(const TaskServices& task, const Pose2& from, const Eigen::Vector2d& to) {
  const perception::Costmap2D* costmap = task.belief->world.costmap;
  if (costmap == nullptr || task.model == nullptr || task.motion == nullptr) return true;
  // The hand's offset from the base in M, with the arm where it is going now and tucked: a step
  // tucks it on the way (an operation broken off leaves it out at the actuator), and the base,
  // setting off briskly, may be all the way there before the arm is in.
  const auto hand_offset = [&](const ArmPose& arm) -> Eigen::Vector2d {
    WholeBodyVector q = WithArm(WholeBodyVector::Zero(), arm);
    q[kBaseYaw] = from.yaw;
    return task.model->CalcPalmPose(q).translation().head<2>();
  };
  const Eigen::Vector2d out = hand_offset(task.motion->arm_target());
  const Eigen::Vector2d tucked = hand_offset(TuckedArm(*task.model));
  if (costmap->IsNearMappedObstacle(from.translation() + out, kHandWallClearanceM)) return true;
  constexpr double kSampleM = 0.05;
  const Eigen::Vector2d way = to - from.translation();
  const int steps = std::max(1, int(std::ceil(way.norm() / kSampleM)));
  for (int k = 1; k <= steps; ++k) {
    const Eigen::Vector2d p_MB = from.translation() + way * (double(k) / steps);
    if (costmap->IsNearMappedObstacle(p_MB + out, kHandWallClearanceM) ||
        costmap->IsNearMappedObstacle(p_MB + tucked, kHandWallClearanceM))
      return false;
  }
  return true;
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
