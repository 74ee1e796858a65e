// Where the escort's robot steps to out of the residents' way (escort_room.h).

#include "escort_room.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "escort_watch.h"
#include "task_node_support.h"

namespace egress::behavior::detail {
namespace {

// [m] Someone (a laser return off the map, a tracked person) this near the robot's edge is too
// near: it makes room. Inside personal space (0.45-1.2 m), beyond a crowd's elbow room.
constexpr double kMakeRoomGapM = 0.35;
// [m] How far it looks round for room, and the steps it considers.
constexpr double kRoomLookM = 2.5;
constexpr double kRoomStepsM[] = {0.3, 0.6, 1.0};
constexpr int kRoomHeadings = 16;
// [s] Making room keeps clear of where people will be up to this far ahead (their positions at
// their velocity every kRoomHorizonStepSec; the tracker's own forecast is the first 0.8 s of
// these): about the time a 0.6 m step takes.
constexpr double kRoomHorizonSec = 2.0;
constexpr double kRoomHorizonStepSec = 0.2;
// [m] A step that gains less room than this is not worth taking.
constexpr double kRoomGainM = 0.1;
// [m] A step into the laser's blind sector keeps this clear of what it last saw there (school
// seed 5: the robot at the button stepped straight back among residents standing behind it).
constexpr double kBlindClearM = 0.25;
// [m] A step ends at least this much beyond the footprint from the building's walls.
constexpr double kRoomWallMarginM = 0.1;
// [m] Squeezing aside from an open door's way in: the longest step, the shortest worth taking,
// the step between tries, and the room kept from the wall beyond the footprint.
constexpr double kSqueezeMaxM = 0.4;
constexpr double kSqueezeMinM = 0.1;
constexpr double kSqueezeStepM = 0.05;
constexpr double kSqueezeWallMarginM = 0.04;

}  // namespace

bool InTheirWay(const TaskServices& task, const DoorPass& pass, const Eigen::Vector2d& at,
                const Eigen::Vector2d& q) {
  return InTheLane(pass, q, task.config) || (q - pass.centre).norm() < (at - pass.centre).norm() ||
         IntoADoorway(task, at, q);
}

std::optional<Pose2> FindRoom(const TaskServices& task, const DoorPass& pass,
                              const std::optional<Eigen::Vector2d>& stepping_to) {
  const Belief& belief = *task.belief;
  const Eigen::Vector2d at = belief.X_MB.translation();
  const perception::Costmap2D* costmap = belief.world.costmap;
  // A step planned from rest and begun moving runs past its end by about the braking distance
  // at the base's limit: the controller catches up with the lag it starts with (two wards seed
  // 53: a step begun at 0.45 m/s away from the corridor's wall ended 0.105 m past its end, on
  // the wall). Its end keeps that much more from the walls; and where braking alone takes the
  // robot up to a wall, no step begins: the motion under way brakes at its own end.
  const double speed = std::hypot(belief.V_B.vx, belief.V_B.vy);
  const double braking =
      speed * speed / (2.0 * task.motion->trajectory_config().max_base_acceleration);
  const double wall_clear = task.config.footprint_radius + kRoomWallMarginM + braking;
  if (costmap != nullptr && speed > kStoppedMps) {
    const Eigen::Vector2d v_M =
        Eigen::Rotation2Dd(belief.X_MB.yaw) * Eigen::Vector2d(belief.V_B.vx, belief.V_B.vy);
    if (costmap->IsNearMappedObstacle(at + v_M.normalized() * braking,
                                      task.config.footprint_radius + kRoomWallMarginM))
      return std::nullopt;
  }
  // A tracked person where they are and where they will be at their velocity up to
  // kRoomHorizonSec (someone walking at the robot is too near before they arrive, and a step
  // that keeps clear of them for only the tracker's 0.8 s forecast is a step along their path
  // — clinic seed 4, a resident pushed along the wall by the crowd caught up with the robot
  // stepping ahead of them).
  const std::vector<Occupant> near =
      PeopleAround(task, at, kRoomLookM, kRoomHorizonSec, kRoomHorizonStepSec);
  const auto room_at = [&](const Eigen::Vector2d& q) { return RoomAt(near, q); };
  if (room_at(stepping_to.value_or(at)) > task.config.footprint_radius + kMakeRoomGapM)
    return std::nullopt;
  // A step is worth the least room it leaves anyone: where it ends (at any time of the
  // horizon) and on the way there, the robot where the step has taken it when they are where
  // they are predicted (clinic seed 62: a step to a spot beyond a resident's way, chosen for
  // the room there, crossed in front of them).
  const PeopleRoom people(task, kRoomHorizonSec);
  const auto worth = [&](const Eigen::Vector2d& q) {
    return std::min(room_at(q), people.RoomOnTheWay({at, q}));
  };
  const double now = stepping_to ? worth(*stepping_to) : room_at(at);
  std::optional<Pose2> best;  // never in their way (InTheirWay)
  // Only a step predicted to leave them room: where every step still meets someone (a
  // resident pushed at 1.5 m/s into the corner it stood in), the robot keeps its course, which
  // they can see and avoid, rather than turn about into their way (atrium seed 32: a metre's
  // step chosen at a predicted -0.16 m reversed the robot into them).
  double best_room = std::max(now + kRoomGainM, 0.0);
  for (const double step : kRoomStepsM) {
    for (int k = 0; k < kRoomHeadings; ++k) {
      const double a = 2 * M_PI * k / kRoomHeadings;
      const Eigen::Vector2d q = at + step * Eigen::Vector2d(std::cos(a), std::sin(a));
      if (room_at(q) <= best_room || InTheirWay(task, pass, at, q)) continue;
      // Not up to a wall: a step's quintic settles up to a decimetre past its end (clinic
      // seed 62: a step to 2.5 cm from the corridor's wall touched it), and begun moving, the
      // braking distance more (wall_clear, above).
      if (costmap != nullptr && costmap->IsNearMappedObstacle(q, wall_clear)) continue;
      const double room = worth(q);
      if (room <= best_room || !IsBlindWayClear(task, belief.X_MB, at, q, kBlindClearM)) continue;
      const Pose2 candidate{q.x(), q.y(), belief.X_MB.yaw};
      // The straight step, not only where it ends: a free pose may lie beyond a wall; nor the
      // hand, out ahead of the footprint, into the wall the robot faces.
      if (!HandClearOfWalls(task, belief.X_MB, q) ||
          !task.planner->IsPathValid({belief.X_MB, candidate}))
        continue;
      best = candidate;
      best_room = room;
    }
  }
  return best;
}

std::optional<Pose2> SqueezeAsidePose(const TaskServices& task, const DoorPass& pass,
                                      const std::string& door) {
  const Belief& belief = *task.belief;
  const Eigen::Vector2d centre = ClearOpeningCentre(task, door);
  const Eigen::Vector2d at = belief.X_MB.translation();
  Eigen::Vector2d along(-pass.n_M.y(), pass.n_M.x());
  if (along.dot(at - centre) < 0.0) along = -along;
  const perception::Costmap2D* costmap = belief.world.costmap;
  for (double step = kSqueezeMaxM; step >= kSqueezeMinM - 1e-9; step -= kSqueezeStepM) {
    const Eigen::Vector2d q = at + along * step;
    if (costmap != nullptr &&
        costmap->IsNearMappedObstacle(q, task.config.footprint_radius + kSqueezeWallMarginM))
      continue;
    // Facing the way they come: the laser sees them and the doorway.
    const Pose2 to{q.x(), q.y(), LookYaw(pass, q)};
    if (task.planner->IsPathValid({belief.X_MB, to})) return to;
  }
  return std::nullopt;
}

}  // namespace egress::behavior::detail
