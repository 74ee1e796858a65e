#include "escort_watch.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "task_node_support.h"

namespace egress::behavior::detail {

namespace {
// [m] Someone this near the doorway's centre, on the robot's side, stands by the door.
constexpr double kAtDoorwayM = 1.5;
// [m] Laser returns closer than this to one another are on one body (returns 0.25 degrees
// apart are centimetres apart on it; people in a group stand further apart than this).
constexpr double kSameBodyM = 0.15;
// [m] A laser return this near a mapped wall or leaf is the wall's, seen off, rather than a
// body's near side.
constexpr double kHuggingWallM = 0.3;

// p_M within `radius` [m] of the doorway's centre, on the robot's side of the door line (or
// less than kThroughM beyond it).
bool OnThisSideWithin(const DoorPass& pass, const Eigen::Vector2d& p_M, double radius) {
  const Eigen::Vector2d d = p_M - pass.centre;
  return d.dot(pass.n_M) > -kThroughM && d.norm() < radius;
}
}  // namespace

bool SeenWalking(const Belief& belief, const perception::TrackedPerson& person) {
  // Walking off, not a tracker's wobble: away from where they stood as well as fast, and seen so
  // now (a standing person's track that lost them at the edge of the laser's view, or behind
  // someone, coasts on a step's worth of wobble and walks off on its own).
  return person.v_MP.norm() > kMovingMps && (person.p_MP - person.p_MRest).norm() > kWalkedOffM &&
         ToSeconds(belief.now - person.last_seen) <= kSeenMovingWithinSec;
}

bool ApproachWatch::Update(const Belief& belief, const DoorPass& pass, double watch_radius) {
  bool closed = false;
  for (const auto& entry : belief.world.people) {
    const auto& person = entry.person;
    if (!OnThisSideWithin(pass, person.p_MP, watch_radius) || !SeenWalking(belief, person))
      continue;
    const double distance = (person.p_MP - pass.centre).norm();
    auto it = walks_.find(person.id);
    if (it == walks_.end() || ToSeconds(belief.now - it->second.last) > kStirGapSec)
      it = walks_.insert_or_assign(person.id, Walk{belief.now, distance}).first;
    Walk& walk = it->second;
    walk.last = belief.now;
    walk.farthest = std::max(walk.farthest, distance);
    closed = closed || walk.farthest - distance >= kComingCloserM;
  }
  // Walks over (or tracks gone) are forgotten: a track that walks again starts afresh.
  std::erase_if(walks_,
                [&](const auto& w) { return ToSeconds(belief.now - w.second.last) > kStirGapSec; });
  return closed;
}

Surroundings LookAround(const Belief& belief, const DoorPass& pass, double watch_radius,
                        double near_door) {
  const auto this_side = [&](const Eigen::Vector2d& p, double radius) {
    return OnThisSideWithin(pass, p, radius);
  };
  Surroundings s;
  for (const auto& entry : belief.world.people) {
    if (!this_side(entry.person.p_MP, watch_radius)) continue;
    s.near = true;
    const auto& person = entry.person;
    if (s.moving || !SeenWalking(belief, person)) continue;
    s.moving = true;
    s.person_moving = true;
    s.mover = StrCat("person ", person.id, " at ", PoseText({person.p_MP.x(), person.p_MP.y(), 0}),
                     ", ", std::round(person.v_MP.norm() * 10) / 10, " m/s");
  }
  // A leaf on the move is drawn in the costmap where the door estimate last put it, which lags
  // the leaf: its returns land off the map, and move (two wards seed 7: door_e's leaf, opening
  // towards the robot at its button, read as someone at the door after each press, and the hold
  // never ran out with everyone through). Returns where a moving leaf sweeps are its own; so are
  // those where a leaf not measured for a while sweeps, drawn where it was last seen (random
  // building seed 7: door_n1, last seen held open, was seen again shut 12 s later, and its
  // returns read as someone at the door each time the robot came back to its spot).
  const auto on_unsettled_leaf = [&](const Eigen::Vector2d& p) {
    for (const auto& d : belief.world.doors)
      if (d.state.observed &&
          (d.stale || d.state.motion == perception::DoorMotion::kOpening ||
           d.state.motion == perception::DoorMotion::kClosing) &&
          d.model.InSweep(p, kOffMapM))
        return true;
    return false;
  };
  for (const Eigen::Vector2d& p : belief.off_map_returns)
    s.near = s.near || (this_side(p, near_door) && !on_unsettled_leaf(p));
  for (const Eigen::Vector2d& p : belief.moving_returns) {
    if (s.moving || !this_side(p, near_door) || on_unsettled_leaf(p)) continue;
    s.moving = true;
    s.mover = StrCat("laser returns moving at ", PoseText({p.x(), p.y(), 0}));
  }
  return s;
}

AtTheDoorway ByTheDoorway(const Belief& belief, const DoorPass& pass, const Eigen::Vector2d& p_MS,
                          double radius, double person_radius) {
  const auto by_doorway = [&](const Eigen::Vector2d& p, double within) {
    return OnThisSideWithin(pass, p, within);
  };
  // Tracked people by the doorway.
  const auto& people = belief.world.people;
  std::vector<bool> by(people.size(), false);
  bool someone = false;
  for (std::size_t i = 0; i < people.size(); ++i) {
    by[i] = by_doorway(people[i].person.p_MP, kAtDoorwayM + person_radius);
    someone = someone || by[i];
  }
  // Only this side counts: those beyond the door line walk on away from it.
  const auto within = [&](const Eigen::Vector2d& p) {
    return (p - p_MS).norm() < radius && (p - pass.centre).dot(pass.n_M) > -kThroughM;
  };
  bool alone = true;
  for (std::size_t i = 0; i < people.size(); ++i)
    if (!by[i] && within(people[i].person.p_MP)) alone = false;
  // Returns off the map but hugging a wall or a door's leaf are not counted out there: seen
  // from metres away a jamb's edge lands beyond kOffMapM (the pose's yaw error times the range;
  // atrium seed 26: a jamb 4.7 m from the standoff, read as a group standing about, kept the
  // robot from the button while a resident waited at the door, until the time limit). The
  // near side of anyone standing against a wall is a body's depth off it.
  const perception::Costmap2D* costmap = belief.world.costmap;
  std::vector<Eigen::Vector2d> near;
  for (const Eigen::Vector2d& p : belief.off_map_returns)
    if (by_doorway(p, kAtDoorwayM) ||
        (within(p) && (costmap == nullptr || !costmap->IsNearMappedObstacle(p, kHuggingWallM))))
      near.push_back(p);
  std::vector<bool> linked(near.size(), false);
  std::vector<std::size_t> frontier;
  // Returns on the body of a tracked person by the doorway count with them (their outline
  // may reach further out).
  const auto on_someone_by = [&](const Eigen::Vector2d& p) {
    for (std::size_t i = 0; i < people.size(); ++i)
      if (by[i] && (p - people[i].person.p_MP).norm() < 2.0 * person_radius) return true;
    return false;
  };
  for (std::size_t i = 0; i < near.size(); ++i) {
    if (by_doorway(near[i], kAtDoorwayM)) {
      linked[i] = true;
      frontier.push_back(i);
    }
  }
  someone = someone || !frontier.empty();
  // Someone tracked stands about already: which returns are whose no longer matters (the flood
  // below is quadratic in the returns, and a crowd at the door gives hundreds).
  if (!alone) return {someone, false, false};
  for (std::size_t i = 0; i < near.size(); ++i) {
    if (!linked[i] && on_someone_by(near[i])) {
      linked[i] = true;
      frontier.push_back(i);
    }
  }
  // Returns binned in kSameBodyM cells: a return's body neighbours lie in the 3 x 3 cells round it.
  const auto cell_of = [](const Eigen::Vector2d& p) {
    return Eigen::Vector2i(static_cast<int>(std::floor(p.x() / kSameBodyM)),
                           static_cast<int>(std::floor(p.y() / kSameBodyM)));
  };
  const auto key_of = [](int cx, int cy) {  // unsigned: no shift of a negative number
    return (std::uint64_t{static_cast<std::uint32_t>(cx)} << 32) | static_cast<std::uint32_t>(cy);
  };
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells;
  for (std::size_t i = 0; i < near.size(); ++i) {
    const Eigen::Vector2i c = cell_of(near[i]);
    cells[key_of(c.x(), c.y())].push_back(i);
  }
  while (!frontier.empty()) {
    const std::size_t i = frontier.back();
    frontier.pop_back();
    const Eigen::Vector2i c = cell_of(near[i]);
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        const auto it = cells.find(key_of(c.x() + dx, c.y() + dy));
        if (it == cells.end()) continue;
        for (const std::size_t j : it->second) {
          if (linked[j] || (near[j] - near[i]).norm() >= kSameBodyM) continue;
          linked[j] = true;
          frontier.push_back(j);
        }
      }
    }
  }
  alone = alone && std::all_of(linked.begin(), linked.end(), [](bool b) { return b; });
  return {someone, alone, someone && alone};
}

bool WayClear(const Belief& belief, const Pose2& goal, double radius, double only_within,
              bool ahead_only) {
  const Eigen::Vector2d from = belief.X_MB.translation();
  Eigen::Vector2d a = from;
  const Eigen::Vector2d b = goal.translation();
  if (only_within >= 0.0 && (a - b).norm() > only_within)
    a = b + (a - b).normalized() * only_within;
  const auto near_way = [&](const Eigen::Vector2d& p) {
    if (ahead_only && (p - from).dot(b - from) <= 0.0 && (p - b).norm() >= radius) return false;
    return (p - ClosestPointOnSegment(p, a, b)).norm() < radius;
  };
  for (const auto& entry : belief.world.people)
    if (near_way(entry.person.p_MP)) return false;
  for (const Eigen::Vector2d& p : belief.off_map_returns)
    if (near_way(p)) return false;
  return true;
}

bool InTheLane(const DoorPass& pass, const Eigen::Vector2d& q, const TaskConfig& config) {
  const Eigen::Vector2d d = q - pass.centre;
  const double out = d.dot(pass.n_M);
  const Eigen::Vector2d t(-pass.n_M.y(), pass.n_M.x());
  const double lane = pass.width / 2 + config.footprint_radius + config.person_radius;
  return out > -(config.footprint_radius + kThroughM) && out < kLookOutM &&
         std::abs(d.dot(t)) < lane;
}

bool IntoADoorway(const TaskServices& task, const Eigen::Vector2d& at, const Eigen::Vector2d& q) {
  const double body = task.config.footprint_radius;
  for (const auto& door : task.map->doors) {
    // The normal towards the robot's side now: a step ending on the other side crosses.
    const DoorPass pass = CalcDoorPass(*task.map, door.id, Pose2{at.x(), at.y(), 0.0});
    const Eigen::Vector2d along(-pass.n_M.y(), pass.n_M.x());
    const double half = pass.width / 2 + body;
    const double from = (at - pass.centre).dot(pass.n_M), to = (q - pass.centre).dot(pass.n_M);
    if (std::abs(to) < kOffDoorwayM && std::abs((q - pass.centre).dot(along)) < half) return true;
    if (to < 0.0) {
      const Eigen::Vector2d cross = at + (q - at) * (from / (from - to));
      if (std::abs((cross - pass.centre).dot(along)) < half) return true;
    }
    if (door.InSweep(q, body + kLeafClearance)) return true;
  }
  return false;
}

bool SomeoneWalkingUpBehind(const TaskServices& task, const Eigen::Vector2d& way) {
  const Eigen::Vector2d at = task.belief->X_MB.translation();
  for (const auto& entry : task.belief->world.people) {
    const auto& person = entry.person;
    const Eigen::Vector2d d = person.p_MP - at;
    const double distance = d.norm();
    if (distance < 1e-6 || d.dot(way) >= 0.0) continue;  // ahead: the way's own yielding
    if (distance - task.config.footprint_radius - task.config.person_radius > kFollowerGapM)
      continue;
    if (person.v_MP.norm() < kWalkingMps || -person.v_MP.dot(d / distance) < kClosingMps) continue;
    return true;
  }
  return false;
}

}  // namespace egress::behavior::detail
