#include "egress/behavior/door_rules.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "egress/hsr_interface/error.h"
#include "egress/hsr_interface/geometry.h"
#include "egress/perception/person_tracker.h"
#include "task_node_support.h"

namespace egress::behavior {
namespace {
// [m/s] Someone moving off from a doorway faster than this is not coming through it.
constexpr double kWalkingAwayMps = 0.2;
// [m] A door's zone reaches this far beside its opening, for where the robot stands.
constexpr double kZoneBesideOpeningM = 0.5;
}  // namespace

DoorPass CalcDoorPass(const MissionMap& map, const std::string& door, const Pose2& X_MB) {
  const perception::DoorModel* model = map.FindDoor(door);
  ThrowUnless(model != nullptr, "unknown door '", door, "' (not in the building map)");
  DoorPass pass;
  pass.centre = (model->p_MHinge + model->p_MLatch) / 2;
  const Eigen::Vector2d along = (model->p_MLatch - model->p_MHinge).normalized();
  Eigen::Vector2d n(-along.y(), along.x());
  if (n.dot(X_MB.translation() - pass.centre) < 0) n = -n;
  pass.n_M = n;
  pass.width = model->width();
  return pass;
}

DoorPass CalcKnownPass(const TaskServices& task, const std::string& door, const DoorVisit* visit) {
  DoorPass pass = CalcDoorPass(*task.map, door, task.belief->X_MB);
  if (visit != nullptr && visit->door == door && visit->approach_side) {
    pass.n_M = *visit->approach_side;
  }
  return pass;
}

DoorPass CalcApproachPass(const TaskServices& task, DoorVisit& visit) {
  const DoorPass pass = CalcKnownPass(task, visit.door, &visit);
  if (!visit.approach_side) visit.approach_side = pass.n_M;
  return pass;
}

bool IsHoldingDoorAside(const TaskServices& task, const perception::TrackedPersonWithIntent& entry,
                        const std::string& door) {
  if (entry.intent != perception::PersonIntent::kHoldingDoor || entry.door_id != door) return false;
  const DoorPass pass = CalcDoorPass(*task.map, door, task.belief->X_MB);
  const Eigen::Vector2d along(-pass.n_M.y(), pass.n_M.x());
  const double lateral = std::abs((entry.person.p_MP - pass.centre).dot(along));
  return lateral >= task.config.footprint_radius + task.config.person_radius;
}

bool IsInAnyDoorZone(const TaskServices& task, const Eigen::Vector2d& p_MB) {
  for (const auto& door : task.map->doors) {
    const DoorPass pass = CalcDoorPass(*task.map, door.id, Pose2{p_MB.x(), p_MB.y(), 0.0});
    const Eigen::Vector2d offset = p_MB - pass.centre;
    const double along = offset.dot(pass.n_M);
    const double lateral = std::abs(offset.dot(Eigen::Vector2d(-pass.n_M.y(), pass.n_M.x())));
    if (along < task.config.zone_depth && lateral < pass.width / 2 + kZoneBesideOpeningM)
      return true;
    // Nor where a closing leaf can reach: a retreat to it meets the leaf.
    if (door.InSweep(p_MB, task.config.footprint_radius + detail::kLeafClearance)) return true;
  }
  return false;
}

bool PassesThroughAnyDoorway(const TaskServices& task, const Eigen::Vector2d& p_MFrom,
                             const Eigen::Vector2d& p_MTo) {
  const auto cross = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) {
    return u.x() * v.y() - u.y() * v.x();
  };
  const Eigen::Vector2d way = p_MTo - p_MFrom;
  for (const auto& door : task.map->doors) {
    const Eigen::Vector2d line = door.p_MLatch - door.p_MHinge;
    const double from_side = cross(line, p_MFrom - door.p_MHinge);
    const double to_side = cross(line, p_MTo - door.p_MHinge);
    if (from_side * to_side > 0.0) continue;  // both on one side of the door line
    // And the crossing between the jambs: the hinge and latch on either side of the way.
    if (cross(way, door.p_MHinge - p_MFrom) * cross(way, door.p_MLatch - p_MFrom) <= 0.0)
      return true;
  }
  return false;
}

bool IsDoorZoneOccupied(const TaskServices& task, const std::string& door) {
  const perception::DoorModel* model = task.map->FindDoor(door);
  ThrowUnless(model != nullptr, "unknown door '", door, "' (not in the building map)");
  perception::DoorZone zone{*model, task.config.zone_depth, task.config.person_radius};
  // A door that opened moments ago: who waited on its far side for it has the right of way.
  bool just_opened = false;
  if (const auto it = task.belief->door_open_since.find(door);
      it != task.belief->door_open_since.end()) {
    just_opened = ToSeconds(task.belief->now - it->second) < task.config.right_of_way_time;
  }
  const DoorPass pass = CalcDoorPass(*task.map, door, task.belief->X_MB);
  for (const auto& entry : task.belief->world.people) {
    // Someone holding this door open is why the robot may pass, not a reason to wait.
    if (IsHoldingDoorAside(task, entry, door)) continue;
    if (zone.Contains(entry.person.p_MP)) return true;
    if (task.config.yield_to_crossing && entry.door_id == door &&
        entry.intent == perception::PersonIntent::kCrossing)
      return true;
    if (just_opened) {
      const Eigen::Vector2d from_centre = entry.person.p_MP - pass.centre;
      const bool far_side = from_centre.dot(pass.n_M) < 0.0;
      const bool walking_away = entry.person.v_MP.dot(from_centre.normalized()) > kWalkingAwayMps;
      if (far_side && from_centre.norm() < task.config.right_of_way_radius && !walking_away)
        return true;
    }
    for (const auto& p : entry.person.forecast) {
      if (zone.Contains(p)) return true;
    }
  }
  return false;
}

bool IsPassageBusy(const TaskServices& task, const std::string& door, double horizon) {
  const DoorPass pass = CalcDoorPass(*task.map, door, task.belief->X_MB);
  for (const auto& entry : task.belief->world.people) {
    if (IsHoldingDoorAside(task, entry, door)) continue;
    const Eigen::Vector2d& p = entry.person.p_MP;
    // Someone standing stays where they are: a standing track's jitter (kWalkingMps) over the
    // horizon of a pass reached the opening from metres away (S2 seed 2005: a crosser standing
    // 2.9 m off at 0.15 m/s "would pass" over 6.5 s, and the robot waited at the entry until
    // the door shut).
    const Eigen::Vector2d later = entry.person.v_MP.norm() < detail::kWalkingMps
                                      ? p
                                      : p + entry.person.v_MP * std::max(horizon, 0.0);
    if ((ClosestPointOnSegment(pass.centre, p, later) - pass.centre).norm() <
        task.config.passage_clearance)
      return true;
  }
  return false;
}

bool IsPassageClear(const TaskServices& task, const std::string& door, double horizon,
                    double quiet_for) {
  if (IsPassageBusy(task, door, horizon)) return false;
  const auto it = task.belief->passage_used_at.find(door);
  return it == task.belief->passage_used_at.end() ||
         ToSeconds(task.belief->now - it->second) >= quiet_for;
}

bool IsDoorZoneClearFor(const TaskServices& task, const std::string& door, double clear_for) {
  if (IsDoorZoneOccupied(task, door)) return false;
  const auto it = task.belief->zone_occupied_at.find(door);
  return it == task.belief->zone_occupied_at.end() ||
         ToSeconds(task.belief->now - it->second) >= clear_for;
}

std::optional<double> DoorClearance(const TaskServices& task, const std::string& door) {
  for (const auto& d : task.belief->world.doors) {
    if (d.model.id == door) {
      if (!d.state.observed) return std::nullopt;
      return d.state.clearance_width;
    }
  }
  throw InvalidArgument(StrCat("unknown door '", door, "' (not in the building map)"));
}

namespace detail {

const perception::TrackedDoor* FindTrackedDoor(const perception::WorldState& world,
                                               const std::string& door) {
  for (const auto& d : world.doors) {
    if (d.model.id == door) return &d;
  }
  return nullptr;
}

// Far enough past the door line that the closing leaf cannot reach the footprint.
double ExitDistance(const TaskServices& task, const std::string& door) {
  const double w = task.map->FindDoor(door)->width();
  return std::max(task.config.door_exit_distance,
                  w + task.config.footprint_radius + kLeafClearance);
}

// Half a leaf's thickness, with a margin: how far an open leaf stands into its doorway [m].
constexpr double kLeafHalfThickness = 0.03;

Eigen::Vector2d ClearOpeningCentre(const TaskServices& task, const std::string& door_id) {
  const perception::DoorModel& door = *task.map->FindDoor(door_id);
  double angle = M_PI / 2;
  for (const auto& d : task.belief->world.doors) {
    if (d.model.id == door_id && d.state.observed) angle = std::min(d.state.angle, M_PI / 2);
  }
  const double w = door.width();
  const double clear_from = std::min(w, w * std::cos(angle) + kLeafHalfThickness);
  const Eigen::Vector2d along = (door.p_MLatch - door.p_MHinge) / w;
  return door.p_MHinge + along * (clear_from + w) / 2;
}

double DoorPassPoseSigma(const TaskServices& task, const std::string& door) {
  constexpr double kSigmas = 3.0;
  const double clear = task.map->FindDoor(door)->width() - kLeafHalfThickness;
  const double margin = (clear - 2.0 * task.config.footprint_radius) / 2.0;
  return std::max(task.config.precise_pose_sigma, margin / kSigmas);
}

// How far before the door line the robot lines up and waits: on the side the leaf opens into,
// beyond its sweep (the opening leaf would strike a robot waiting closer).
double EntryDistance(const TaskServices& task, const std::string& door, const DoorPass& pass) {
  const perception::DoorModel& model = *task.map->FindDoor(door);
  if (pass.n_M.dot(model.SwingSide()) <= 0.0) return task.config.door_entry_distance;
  return std::max(task.config.door_entry_distance, ExitDistance(task, door));
}

std::vector<Pose2> LineUpPath(const TaskServices& task, const std::string& door,
                              const DoorPass& pass, const Pose2& X_MB_from) {
  const double entry_distance = EntryDistance(task, door, pass);
  const double yaw = std::atan2(-pass.n_M.y(), -pass.n_M.x());  // facing through the door
  const Eigen::Vector2d entry = pass.centre + pass.n_M * entry_distance;
  std::vector<Pose2> path{X_MB_from};
  const double out = (X_MB_from.translation() - pass.centre).dot(pass.n_M);
  if (entry_distance > task.config.door_entry_distance && out < entry_distance - 0.05) {
    const Eigen::Vector2d p = X_MB_from.translation() + pass.n_M * (entry_distance - out);
    path.push_back({p.x(), p.y(), yaw});
  }
  path.push_back({entry.x(), entry.y(), yaw});
  return path;
}

double DoorPathDuration(const TaskServices& task, const std::vector<Pose2>& path) {
  double total = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i)
    total += planning::SegmentDuration((path[i].translation() - path[i - 1].translation()).norm(),
                                       WrapAngle(path[i].yaw - path[i - 1].yaw), true,
                                       task.motion->trajectory_config());
  return total;
}

}  // namespace detail

using namespace detail;

bool DoorWindowLeavesTime(const TaskServices& task, const std::string& door, const DoorVisit* visit,
                          double lead_time) {
  if (visit != nullptr && visit->door != door) visit = nullptr;
  bool held_by_person = false;
  for (const auto& entry : task.belief->world.people) {
    held_by_person = held_by_person || IsHoldingDoorAside(task, entry, door);
  }
  for (const auto& d : task.belief->world.doors) {
    if (d.model.id != door) continue;
    if (d.state.motion == perception::DoorMotion::kClosing) return false;
    if (held_by_person) continue;
    const double window = task.config.door_hold_window;
    // Opened by our own press or wave and not seen opening right after it (a glass leaf may be
    // seen open only seconds later): the window runs from the press plus the shortest opening
    // time at the latest.
    const bool pressed = visit != nullptr && visit->operated_at.has_value();
    const Time operated = pressed ? *visit->operated_at : Time{};
    const double since_press =
        pressed ? ToSeconds(task.belief->now - operated) : std::numeric_limits<double>::infinity();
    const bool ours = since_press < window + task.config.door_hold_margin + kOperatorOpeningTime;
    // An opening the robot did not see begin (first seen already open, e.g. a glass leaf out of
    // the camera's view while it swung) may have begun a whole window ago: it is timed as one
    // that may close now, whatever its motion reads.
    const bool witnessed = task.belief->door_opening_witnessed.count(door) > 0;
    if (!ours && witnessed && d.state.motion != perception::DoorMotion::kHeldOpen) continue;
    // How long it has been open in this opening (not the estimate's steady time, which a
    // person passing in front of the leaf resets); a press on the open door restarted it.
    std::optional<Time> since;
    if (const auto it = task.belief->door_open_since.find(door);
        it != task.belief->door_open_since.end()) {
      since = it->second;
      if (visit != nullptr && visit->window_restarted_at)
        since = std::max(*since, *visit->window_restarted_at);
    }
    double open_for = since ? ToSeconds(task.belief->now - *since) : 0.0;
    // Still open well past an operator's window: someone or something out of sight holds it —
    // if it is seen so now. An estimate not refreshed for a while (the leaf out of the laser's
    // view from a button's standoff) says only what the door was.
    const bool seen_now = ToSeconds(task.belief->now - d.state.stamp) <= kDoorSeenRecentlySec;
    if (!ours && seen_now && open_for > window + task.config.door_hold_margin) continue;
    if (ours && (!since || ToSeconds(*since - operated) > kOperatorOpeningTime)) {
      open_for = std::max(open_for, since_press - kOperatorMinOpeningTime);
    }
    if (!ours && !witnessed) open_for = std::max(open_for, window);
    // A press that found the door open restarted the window then, however late the opening was
    // first seen (from beside the actuator the leaf is often out of view until the robot lines
    // up): the window is at least that old.
    if (visit != nullptr && visit->window_restarted_at)
      open_for = std::max(open_for, ToSeconds(task.belief->now - *visit->window_restarted_at));
    const DoorPass pass = CalcKnownPass(task, door, visit);
    // From here to beyond the leaf's sweep on the far side (less if already past the line); a
    // leaf that opens towards the robot closes away from it: just past the line is clear.
    const bool opens_towards_robot = pass.n_M.dot(task.map->FindDoor(door)->SwingSide()) > 0.0;
    const double beyond = opens_towards_robot ? task.config.footprint_radius + kLeafClearance
                                              : ExitDistance(task, door);
    const double to_clear =
        std::max(0.0, (task.belief->X_MB.translation() - pass.centre).dot(pass.n_M) + beyond);
    const double needed = to_clear / task.motion->trajectory_config().door_speed;
    // A leaf that opens towards the robot closes across the robot's side of the line, reaching
    // the lane through the clear opening only once it has swung down to the lane's edge: time the
    // robot still has after the window ends, at the fastest closing an operator may have.
    double grace = 0.0;
    if (opens_towards_robot) {
      const double w = task.map->FindDoor(door)->width();
      const double lane_edge =
          w * (1.0 + std::cos(d.state.angle)) / 2 - task.config.footprint_radius;
      const double hit_angle =
          std::atan2(task.config.footprint_radius + kLeafClearance, std::max(lane_edge, 1e-3));
      grace = std::max(0.0, d.state.angle - hit_angle) / kOperatorMaxClosingRate;
    }
    if (open_for + lead_time + needed > window + grace) return false;
  }
  return true;
}

bool DoorPassable(const TaskServices& task, const std::string& door, double margin,
                  const DoorVisit* visit, double lead_time) {
  const auto clearance = DoorClearance(task, door);
  if (!clearance || *clearance < 2 * task.config.footprint_radius + margin) return false;
  return DoorWindowLeavesTime(task, door, visit, lead_time);
}

}  // namespace egress::behavior
