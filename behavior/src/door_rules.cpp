#include "egress/behavior/door_rules.h"

#include <cmath>
#include <limits>

#include "egress/hsr_interface/error.h"
#include "egress/perception/person_tracker.h"
#include "task_node_support.h"

namespace egress::behavior {

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

DoorPass CalcKnownPass(const TaskContext& context, const std::string& door) {
  DoorPass pass = CalcDoorPass(*context.map, door, context.X_MB);
  if (const auto side = context.door_approach_side.find(door);
      side != context.door_approach_side.end()) {
    pass.n_M = side->second;
  }
  return pass;
}

DoorPass CalcApproachPass(TaskContext& context, const std::string& door) {
  const DoorPass pass = CalcKnownPass(context, door);
  context.door_approach_side.try_emplace(door, pass.n_M);
  return pass;
}

bool IsHoldingDoorAside(const TaskContext& context,
                        const perception::TrackedPersonWithIntent& entry, const std::string& door) {
  if (entry.intent != perception::PersonIntent::kHoldingDoor || entry.door_id != door) return false;
  const DoorPass pass = CalcDoorPass(*context.map, door, context.X_MB);
  const Eigen::Vector2d along(-pass.n_M.y(), pass.n_M.x());
  const double lateral = std::abs((entry.person.p_MP - pass.centre).dot(along));
  return lateral >= context.config.footprint_radius + context.config.person_radius;
}

bool IsDoorZoneOccupied(const TaskContext& context, const std::string& door) {
  const perception::DoorModel* model = context.map->FindDoor(door);
  ThrowUnless(model != nullptr, "unknown door '", door, "' (not in the building map)");
  perception::DoorZone zone{*model, context.config.zone_depth, context.config.person_radius};
  for (const auto& entry : context.world.people) {
    // Someone holding this door open is why the robot may pass, not a reason to wait.
    if (IsHoldingDoorAside(context, entry, door)) continue;
    if (zone.Contains(entry.person.p_MP)) return true;
    for (const auto& p : entry.person.forecast) {
      if (zone.Contains(p)) return true;
    }
  }
  return false;
}

std::optional<double> DoorClearance(const TaskContext& context, const std::string& door) {
  for (const auto& d : context.world.doors) {
    if (d.model.id == door) {
      if (!d.state.observed) return std::nullopt;
      return d.state.clearance_width;
    }
  }
  throw InvalidArgument(StrCat("unknown door '", door, "' (not in the building map)"));
}

namespace detail {

// Far enough past the door line that the closing leaf cannot reach the footprint.
double ExitDistance(const TaskContext& ctx, const std::string& door) {
  const double w = ctx.map->FindDoor(door)->width();
  return std::max(ctx.config.door_exit_distance, w + ctx.config.footprint_radius + kLeafClearance);
}

// How far before the door line the robot lines up and waits: on the side the leaf opens into,
// beyond its sweep (the opening leaf would strike a robot waiting closer).
double EntryDistance(const TaskContext& ctx, const std::string& door, const DoorPass& pass) {
  const perception::DoorModel& model = *ctx.map->FindDoor(door);
  if (pass.n_M.dot(model.SwingSide()) <= 0.0) return ctx.config.door_entry_distance;
  return std::max(ctx.config.door_entry_distance, ExitDistance(ctx, door));
}

}  // namespace detail

using namespace detail;

bool DoorPassable(const TaskContext& ctx, const std::string& door, double margin) {
  const auto clearance = DoorClearance(ctx, door);
  if (!clearance || *clearance < 2 * ctx.config.footprint_radius + margin) return false;
  bool held_by_person = false;
  for (const auto& entry : ctx.world.people) {
    held_by_person = held_by_person || IsHoldingDoorAside(ctx, entry, door);
  }
  for (const auto& d : ctx.world.doors) {
    if (d.model.id != door) continue;
    if (d.state.motion == perception::DoorMotion::kClosing) return false;
    if (held_by_person) continue;
    const double window = ctx.config.door_hold_window;
    // Opened by our own press or wave and not seen opening right after it (a glass leaf may be
    // seen open only seconds later): the window runs from the press plus the shortest opening
    // time at the latest.
    const auto operated = ctx.door_operated_at.find(door);
    const double since_press = operated != ctx.door_operated_at.end()
                                   ? ToSeconds(ctx.now - operated->second)
                                   : std::numeric_limits<double>::infinity();
    const bool ours = since_press < window + ctx.config.door_hold_margin + kOperatorOpeningTime;
    if (!ours && d.state.motion != perception::DoorMotion::kHeldOpen) continue;
    // How long it has been open in this opening (not the estimate's steady time, which a
    // person passing in front of the leaf resets).
    const auto since = ctx.door_open_since.find(door);
    double open_for = since != ctx.door_open_since.end() ? ToSeconds(ctx.now - since->second) : 0.0;
    // Still open well past an operator's window: someone or something out of sight holds it —
    // if it is seen so now. An estimate not refreshed for a while (the leaf out of the laser's
    // view from a button's standoff) says only what the door was.
    const bool seen_now = ToSeconds(ctx.now - d.state.stamp) <= kDoorSeenRecentlySec;
    if (!ours && seen_now && open_for > window + ctx.config.door_hold_margin) continue;
    if (ours && (since == ctx.door_open_since.end() ||
                 ToSeconds(since->second - operated->second) > kOperatorOpeningTime)) {
      open_for = std::max(open_for, since_press - kOperatorMinOpeningTime);
    }
    const DoorPass pass = CalcKnownPass(ctx, door);
    // From here to beyond the leaf's sweep on the far side (less if already past the line); a
    // leaf that opens towards the robot closes away from it: just past the line is clear.
    const bool opens_towards_robot = pass.n_M.dot(ctx.map->FindDoor(door)->SwingSide()) > 0.0;
    const double beyond = opens_towards_robot ? ctx.config.footprint_radius + kLeafClearance
                                              : ExitDistance(ctx, door);
    const double to_clear =
        std::max(0.0, (ctx.X_MB.translation() - pass.centre).dot(pass.n_M) + beyond);
    const double needed = to_clear / ctx.motion->trajectory_config().door_speed;
    // A leaf that opens towards the robot closes across the robot's side of the line, reaching
    // the lane through the clear opening only once it has swung down to the lane's edge: time the
    // robot still has after the window ends, at the fastest closing an operator may have.
    double grace = 0.0;
    if (opens_towards_robot) {
      const double w = ctx.map->FindDoor(door)->width();
      const double lane_edge =
          w * (1.0 + std::cos(d.state.angle)) / 2 - ctx.config.footprint_radius;
      const double hit_angle =
          std::atan2(ctx.config.footprint_radius + kLeafClearance, std::max(lane_edge, 1e-3));
      grace = std::max(0.0, d.state.angle - hit_angle) / kOperatorMaxClosingRate;
    }
    if (open_for + needed > window + grace) return false;
  }
  return true;
}

}  // namespace egress::behavior
