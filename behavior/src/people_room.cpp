// People round the robot (task_node_support.h): their predicted ways (PeopleAround,
// ThroughDoorWays), the room they leave the robot at a spot and on its way there (PeopleRoom),
// what the base laser sees of them (IsInLaserSweep, IsInLaserSight, IsBlindWayClear), and the
// steps the robot takes out of their way (MakeWaySpot, StepAsideTo, HandClearOfWalls).

#include "task_node_support.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "egress/behavior/proxemics.h"
#include "egress/planning/trajectory.h"

namespace egress::behavior::detail {

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

namespace {

// The way `entry` may walk through the middle of a door's opening (ThroughDoorWays' rule; `zone`
// and `pass` are the door's), appended to `ways`.
void AppendThroughDoorWay(const TaskServices& task, const std::string& door,
                          const perception::DoorZone& zone, const DoorPass& pass,
                          const perception::TrackedPersonWithIntent& entry, double horizon,
                          std::vector<Occupant>& ways) {
  const perception::TrackedPerson& person = entry.person;
  const Eigen::Vector2d to_centre = pass.centre - person.p_MP;
  const double distance = to_centre.norm();
  if (distance < 1e-6 || IsHoldingDoorAside(task, entry, door)) return;
  const double towards = person.v_MP.dot(to_centre / distance);
  const bool far_side = -to_centre.dot(pass.n_M) < 0.0;
  // Out of the zone on the robot's side, only someone walking at the opening goes through it
  // (P1: walking up behind the robot at the button to the door it opened, tracked straight on,
  // they turned into the doorway and passed 0.65 m off the robot that had found no better
  // spot): to the far side.
  const bool inward = !far_side && !zone.Contains(person.p_MP);
  if (inward ? distance > kIntoDoorRadiusM || towards < PeopleRoom::kSidestepMinMps
             : distance > kThroughDoorRadiusM || towards < -PeopleRoom::kSidestepMinMps)
    return;
  const Eigen::Vector2d n_MOn = inward ? Eigen::Vector2d(-pass.n_M) : pass.n_M;
  const Eigen::Vector2d at = task.belief->X_MB.translation();
  const double step = PeopleRoom::kPeopleStepSec;
  const double speed = std::max(person.v_MP.norm(), kWalkingMps);
  // To the middle of the opening, then on along the normal (walls turning the way).
  const double t_centre = distance / speed;
  int k = 1;
  for (; k * step < t_centre && k * step <= horizon + 1e-9; ++k) {
    const Eigen::Vector2d p = person.p_MP + to_centre * (k * step / t_centre);
    if ((p - at).norm() < PeopleRoom::kPeopleLookM)
      ways.push_back({p, task.config.person_radius, k * step, to_centre / distance * speed});
  }
  if (k * step > horizon + 1e-9) return;
  // On through it along the normal at their speed, bent by the drift they have along the door
  // line (someone coming round the leaf towards the opening's middle, H12 and P5's runner,
  // walks on that way past it, not straight down the normal: the robot stepped aside to the
  // side they went).
  const Eigen::Vector2d along_door(-pass.n_M.y(), pass.n_M.x());
  const Eigen::Vector2d v_on =
      (n_MOn * speed + along_door * person.v_MP.dot(along_door)).normalized() * speed;
  const std::size_t first = ways.size();
  AppendPredictedWay(task, at, PeopleRoom::kPeopleLookM, horizon - t_centre, step, 0, pass.centre,
                     v_on, ways);
  for (std::size_t i = first; i < ways.size(); ++i)
    ways[i].t += t_centre;
}

// The door's zone and the robot's pass of it, for AppendThroughDoorWay.
std::pair<perception::DoorZone, DoorPass> ZoneAndPass(const TaskServices& task,
                                                      const std::string& door) {
  const perception::DoorModel* model = task.map->FindDoor(door);
  ThrowUnless(model != nullptr, "unknown door '", door, "' (not in the building map)");
  return {perception::DoorZone{*model, task.config.zone_depth, task.config.person_radius},
          CalcDoorPass(*task.map, door, task.belief->X_MB)};
}

}  // namespace

std::vector<Occupant> ThroughDoorWays(const TaskServices& task, const std::string& door,
                                      double horizon) {
  const auto [zone, pass] = ZoneAndPass(task, door);
  std::vector<Occupant> ways;
  for (const auto& entry : task.belief->world.people)
    AppendThroughDoorWay(task, door, zone, pass, entry, horizon, ways);
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
  // A way through a doorway's middle is where they must go: no room for stepping off it.
  const std::size_t through_first = predicted_.size();
  if (!hypotheses.through_door.empty()) {
    const std::vector<Occupant> through = ThroughDoorWays(task, hypotheses.through_door, horizon);
    predicted_.insert(predicted_.end(), through.begin(), through.end());
  }
  const std::size_t through_end = predicted_.size();
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
  for (std::size_t i = 0; i < predicted_.size(); ++i) {
    const Occupant& o = predicted_[i];
    const bool through = i >= through_first && i < through_end;
    std::pair<Eigen::Vector2d, Eigen::Vector2d> ends{o.p_M, o.p_M};
    const double speed = o.v_M.norm();
    const double reach =
        std::min(task.config.person_sidestep, task.config.person_sidestep_speed * o.t);
    if (sidestep && !through && o.radius > 0.0 && speed >= kSidestepMinMps && reach > 0.0) {
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
      if (IsWayHeldBack(corners)) continue;
      if (!task_.planner->IsPathValid({way.back(), candidate})) continue;
      best = candidate;
      beat = s;
    }
  }
  return best;
}

bool IsHeldBackByPace(const TaskServices& task, const Eigen::Vector2d& v_M,
                      const Eigen::Vector2d& p_MGoal) {
  if (task.proxemics == nullptr) return false;
  return ApproachSpeedScale(task.belief->X_MB, v_M, p_MGoal, task.belief->world.people,
                            task.config.footprint_radius, task.config.person_radius,
                            *task.proxemics) < ApproachPace::kHeldScale;
}

bool PeopleRoom::IsWayHeldBack(const std::vector<Eigen::Vector2d>& corners) const {
  // The first leg that goes anywhere: its direction is the velocity the pace is asked about.
  for (std::size_t i = 1; i < corners.size(); ++i) {
    const Eigen::Vector2d leg = corners[i] - corners[0];
    if (leg.norm() < 1e-3) continue;
    return IsHeldBackByPace(task_, leg.normalized() * task_.config.retreat_speed, corners.back());
  }
  return false;
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
    const TaskServices& task, const std::optional<Pose2>& goal, const std::string& through_door) {
  const Belief& belief = *task.belief;
  const Eigen::Vector2d at = belief.X_MB.translation();
  std::optional<std::pair<perception::DoorZone, DoorPass>> door;
  if (!through_door.empty()) door = ZoneAndPass(task, through_door);
  const double near = task.config.footprint_radius + task.config.comfort_distance;
  std::vector<std::pair<const perception::TrackedPerson*, double>> coming;
  std::vector<Occupant> way;
  for (const auto& entry : belief.world.people) {
    if (goal &&
        IsWhomTheRobotGoesTo(entry.person.p_MP, at, goal->translation(), kGoalPersonRadiusM))
      continue;
    if (const auto t_pass = OncomingPassTime(
            entry.person, at, task.config.footprint_radius, task.config.person_radius,
            task.config.comfort_distance, task.config.give_way_horizon, kWalkingMps)) {
      coming.emplace_back(&entry.person, *t_pass);
      continue;
    }
    // Walking, through the door: their speed may be read low (a track that has just set off
    // from standing and coasts out of the laser's view: P1, 0.46 m/s read for 1.3 m/s), and
    // the way through the opening's middle is at a walker's pace at least.
    if (!door || entry.person.v_MP.norm() < PeopleRoom::kSidestepMinMps) continue;
    way.clear();
    AppendThroughDoorWay(task, through_door, door->first, door->second, entry,
                         task.config.give_way_horizon, way);
    for (const Occupant& o : way)
      if ((o.p_M - at).norm() - o.radius < near) {
        coming.emplace_back(&entry.person, o.t);
        break;
      }
  }
  return coming;
}

std::optional<std::string> WhomToMakeWayFor(const TaskServices& task, const std::string& door) {
  if (!PeopleComing(task, std::nullopt).empty()) return "someone coming";
  if (door.empty()) return std::nullopt;
  const double horizon = 2.0 * task.config.give_way_horizon;  // as MakeWaySpot's
  if (RoomAt(ThroughDoorWays(task, door, horizon), task.belief->X_MB.translation()) <
      task.config.footprint_radius + task.config.comfort_distance)
    return "whoever comes through the doorway";
  return std::nullopt;
}

void StepAsideTo(const TaskServices& task, const Pose2& spot) {
  task.motion->FollowPath({task.belief->X_MB, spot}, {false}, task.motion->arm_target(),
                          task.belief->now, task.config.retreat_speed, /*brisk=*/true);
}

bool WayGiver::Begin(const TaskServices& task, const std::optional<Pose2>& goal, const NoteFn& note,
                     PeopleHypotheses hypotheses) {
  const auto coming = PeopleComing(task, goal, hypotheses.through_door);
  if (coming.empty()) return false;
  hypotheses_ = std::move(hypotheses);
  const perception::TrackedPerson& p = *coming.front().first;
  task.motion->StopBase();
  since_ = task.belief->now;
  until_ = task.belief->now;
  chosen_ = false;
  note(StrCat("making way: person ", p.id, " at (", PoseText({p.p_MP.x(), p.p_MP.y(), 0.0}), "), ",
              std::round(p.v_MP.norm() * 10) / 10, " m/s is coming"));
  return true;
}

NodeStatus WayGiver::Update(const TaskServices& task, const std::optional<Pose2>& goal,
                            double patience, const NoteFn& note) {
  const Time now = task.belief->now;
  if (!chosen_ && StoppedOrStopTimedOut(task, *since_)) {
    chosen_ = true;
    if (const auto spot = MakeWaySpot(task, kMakeWayMinGainM, hypotheses_)) {
      StepAsideTo(task, *spot);
      note(StrCat("stepping aside to (", PoseText(*spot), ")"));
    } else {
      note("standing still: no spot aside leaves more room");
    }
  }
  if (task.motion->base_failed()) task.motion->StopBase();  // blocked: stay where it is
  for (const auto& [person, t_pass] : PeopleComing(task, goal, hypotheses_.through_door))
    until_ = std::max(until_, now + SecondsToDuration(std::min(t_pass, kMaxPassSec)));
  const bool clear = ToSeconds(now - until_) >= task.config.give_way_clear_for;
  const bool waited = ToSeconds(now - *since_) > patience;
  if (!clear && !waited) return NodeStatus::kRunning;
  since_.reset();
  note(clear ? "nobody is coming any more: going on" : "made way long enough: going on");
  return NodeStatus::kSuccess;
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

}  // namespace egress::behavior::detail
