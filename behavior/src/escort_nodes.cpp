// The escort's task nodes (behavior/trees/evacuation_escort.xml): HoldForResidents keeps a door
// open for the people being evacuated, from a spot beside the door out of their way;
// IsNobodyComing (escort_guard.cpp) breaks an operation off when they come.

#include "escort_room.h"
#include "escort_watch.h"
#include "task_node_support.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "egress/behavior/head_gaze.h"
#include "egress/perception/door_estimation.h"

namespace egress::behavior::detail {
namespace {

// [rad] Facing the people's way in within this, the robot does not turn again.
constexpr double kFacingToleranceRad = 20.0 * M_PI / 180.0;
// [rad] Waiting, the robot turns only as far as brings the people's way in within this of
// ahead: the laser (270 deg) sees it with 45 deg to spare and the head turns the camera to it,
// while the turn from the actuator and back stays short.
constexpr double kWatchWithinRad = M_PI / 2;
// [m] The robot this near its wait spot is there.
constexpr double kAtSpotM = 0.15;
// [m] This near the actuator's standoff after an operation, the robot has not left it.
constexpr double kStillAtActuatorM = 0.3;
// An operation asked for that did not happen is not asked for again sooner than this [s].
constexpr double kOperateRetrySec = 3.0;
// [s] The head's look at the residents' way in lasts this long unless renewed (each tick).
constexpr double kLookRequestSec = 0.5;
// [m] The robot goes to its wait spot only with nobody this near it (or the way there).
constexpr double kSpotClearM = 1.0;
// [m] For residents waiting at the door, the robot goes to the actuator with nobody this near
// its standoff: its footprint (0.215 m) and a hand's breadth. Someone waiting who cannot
// operate the door leaves a person's room before the actuator for whoever can, not more (clinic
// seed 13: a wheelchair user's side 0.36 m from the standoff; with 0.5 m the robot watched them
// wait from its spot aside until the time limit).
constexpr double kStandoffFreeM = 0.33;
// Someone walking up behind (LettingFollowersPass, SomeoneWalkingUpBehind): it drives on
// kLetPassClearSec after the last one, or after kLetPassMaxSec [s]; once stopped it stands aside
// where kAsideGainM more room is (MakeWaySpot).
constexpr double kLetPassClearSec = 1.5, kLetPassMaxSec = 15.0;
constexpr double kAsideGainM = 0.1;
// The search for a wait spot beside the lane when none is free along the wall: this far out from
// the wall at most, on a grid of this step [m].
constexpr double kSpotSearchOutM = 1.0;
constexpr double kSpotSearchStepM = 0.1;

// HoldForResidents: the watch between operations while the robot keeps a door open for the
// residents being evacuated. Until anyone comes it waits at the actuator's standoff and
// operates it every `every` seconds (inside the operator's hold window), so the door stands open
// when the first of them arrives. Once someone comes — moves near the door on the robot's side:
// laser returns off the map within `near_door` of the doorway that moved, or a tracked person
// within `watch_radius` walking — it steps aside out of their flow, to `spot` (which it works out:
// `aside` metres beyond the standoff along the wall, away from the doorway: the way in, and the
// crowd funnelling into it, and the pocket behind a leaf that opens towards them, are on the
// doorway's side), faces the way they come and watches; it goes back to the actuator only when an
// operation is due and nobody is within `keep_clear` of the standoff or of its way there (a gap in
// the flow) — it never walks into the queue to reach a button: the residents there can press it.
// Until people came to a door it held (the evacuation under way), it does not go to the actuator
// with people standing within `reach` of it, other than someone waiting by the doorway: a group
// yet to set off may as it operates, and it would have to drive back through them. Once under
// way, people found standing at a door with someone by its doorway are waiting for it, and it
// opens it for them once per hold window, waiting aside in between (never at the actuator: they
// may be behind it, and its standoff may be before the doorway), and not again for nobody once
// they are through. Right after an operation, the door open and someone near (or those it opened
// for), still at the actuator in their way in, it first steps sideways along the door line away
// from the opening, up to the wall (the way between the open leaf's edge and the robot is theirs).
// SUCCESS: operate now. FAILURE: the hold is over — someone came (or it opened for someone
// waiting) and nobody (moving or not; a resident who cannot open the door waits still) has been
// near for `clear_for` seconds of watching, or nobody at all was near for `wait_for` (they went
// ahead, or are elsewhere), or it has held `max_hold`. RUNNING: watching.
class HoldForResidents final : public TaskNode<bt::StatefulActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("door", "door held open for the residents"),
            VisitPort(bt::PortDirection::kInput),
            InputPort<bool>("door_speed", false,
                            "drive to the spot beside the door (or the actuator) at the door "
                            "speed (TrajectoryConfig::door_speed): residents the robot let out "
                            "are ahead of it"),
            OutputPort<std::string>("spot", "where the robot waits beside the door (x;y;yaw)",
                                    "{hold_spot}"),
            InputPort<double>("aside", 1.5,
                              "the wait spot, beyond the actuator's standoff along the wall away "
                              "from the doorway [m]"),
            InputPort<double>("every", 6.0,
                              "operate again this long after the last operation, inside the "
                              "operator's hold window (for residents left waiting at the door: "
                              "once per hold window, waiting aside between) [s]"),
            InputPort<double>("near_door", 5.0,
                              "a laser return off the map this close to the doorway, on the "
                              "robot's side, is someone near (coming, if it moves) [m]"),
            InputPort<double>("watch_radius", 6.0,
                              "a tracked person this close to the doorway, on the robot's side, "
                              "is coming [m]"),
            InputPort<double>("keep_clear", 3.5,
                              "go to (or wait at) the actuator only with nobody this close to its "
                              "standoff or to the way there [m]"),
            InputPort<double>("reach", 6.0,
                              "until people came to a door it held, people standing this close "
                              "to the standoff on its side (others than those waiting by the "
                              "doorway) may set off while the robot operates the actuator: it "
                              "does not go [m]"),
            InputPort<double>("clear_for", 5.0,
                              "the hold is over when nobody has been near for this long [s]"),
            InputPort<double>("wait_for", 20.0,
                              "the hold is over when nobody at all has been near for this long "
                              "(they went ahead, or are elsewhere) [s]"),
            InputPort<double>("max_hold", 600.0, "the longest the robot holds one door [s]"),
            InputPort<bool>("under_way", false,
                            "the evacuation is known to be under way (the robot let residents "
                            "out of a room): whoever stands at the door waits for it")};
  }

  NodeStatus OnStart() override {
    const std::string door = Door();
    if (door != door_) {
      door_ = door;
      ResetHold();
    }
    // Once people came, the time it was not watching (operating) does not count as clear: at
    // the actuator, facing the wall, someone still coming may be behind it. Before anyone came,
    // time spent operating between two looks that found nobody about counts as nobody about:
    // it operates every `every` seconds and watches only in between, and the wait_for clock ran
    // at a fifth of its speed (office seed 1: door_b held 100 s for a group already out).
    if (came_ || !nobody_at_last_watch_) last_tick_.reset();
    stuck_since_.reset();
    drive_failing_ = false;
    // Counted wherever the robot faces now, at the actuator facing its wall (the watch below
    // counts only time with the way in inside the laser's sweep): else only the few seconds it
    // watched between operations did (atrium seed 5: nobody came to the north door, everyone was
    // past it, and the robot pressed its button every 14 s for 130 s; arriving at the clinic's
    // door_e after its residents had gone out, it pressed every 13 s until the time limit). If
    // the first look back finds someone near, the watch resets it.
    if (last_tick_) {
      unseen_ += ToSeconds(belief_.now - *last_tick_);
      last_tick_ = belief_.now;
    }
    if (!started_) {
      started_ = belief_.now;
      if (!PlanSpot()) return NodeStatus::kFailure;
    }
    return OnRunning();
  }

  NodeStatus OnRunning() override {
    // Residents the sweep let out come to the route's doors after the robot: one waiting at a
    // door that stood open before them is waiting for it, not a group yet to set off (the
    // clinic, one wheelchair user in room A, seed 6: let out by the sweep, they waited at door_e
    // and the robot stood short of it until max_hold).
    if (Input<bool>("under_way")) under_way_ = true;
    const DoorPass pass = CalcDoorPass(*task_.map, door_, standoff_);
    const double held = ToSeconds(belief_.now - *started_);
    const Surroundings around =
        LookAround(belief_, pass, Input<double>("watch_radius"), Input<double>("near_door"));
    // Came: on the move for kComingForSec on end — not a stir in a group standing about (a
    // track hopping between neighbours as they hide one another reads as a walk for a few
    // tenths of a second: two wards seed 16, 4.9 s into a hold, a minute before the alarm; the
    // robot then took the group for residents waiting at the door and went to press for them).
    if (around.moving) {
      if (!moving_since_ || !last_moving_ || ToSeconds(belief_.now - *last_moving_) > kStirGapSec)
        moving_since_ = belief_.now;
    }
    // And a tracked person among them nearer the doorway by kComingCloserM (ApproachWatch): a
    // standing person's track creeps, now and then for seconds on end, but stays by them.
    const bool closing = approach_.Update(belief_, pass, Input<double>("watch_radius"));
    if (around.moving && !came_ && ToSeconds(belief_.now - *moving_since_) >= kComingForSec &&
        (closing || !around.person_moving)) {
      Note(StrCat("residents coming (", around.mover, "): stepping aside"));
      came_ = true;
      under_way_ = true;
    }
    if (around.moving) last_moving_ = belief_.now;
    if (around.moving && ToSeconds(belief_.now - *moving_since_) >= kComingForSec) walked_ = true;
    // Clear time counts only while the way in is in the laser's sweep: stepping aside with its
    // back to the door, the robot sees nobody there (two-wards seed 17: a resident waiting at
    // door_e, behind it, was "everyone through" after clear_for). The operation just done was
    // counted in OnStart. Nor while the way in is beyond where the laser knows people: driving
    // to a door 17 m away, it saw nobody there for want of range. Nor while something of the map
    // stands between: stepped aside behind the office's table, the robot saw nobody at door_a
    // for 5 s while a wheelchair user waited there, and left them behind (office seed 5).
    const Eigen::Vector2d way_in = WayIn(pass);
    if (around.near) {
      unseen_ = 0.0;
    } else if (last_tick_ && IsInLaserSight(task_, belief_.X_MB, way_in) &&
               (way_in - belief_.X_MB.translation()).norm() <= belief_.people_range) {
      unseen_ += ToSeconds(belief_.now - *last_tick_);
    }
    last_tick_ = belief_.now;
    nobody_at_last_watch_ = !around.near;
    if (held > Input<double>("max_hold"))
      return Release(StrCat("held for ", std::round(held), " s"));
    // Over only on a look at the way in (the point the watch below turns to, in the laser's
    // sweep): the time counted while it operated ends facing the actuator's wall, the way in
    // behind it (random building seed 10: released "nobody about" on the first tick after a
    // press, with eight residents 3-4 m behind it walking to the door).
    const bool looking = IsInLaserSweep(task_, belief_.X_MB, WatchPoint(pass));
    if (!came_ && unseen_ > Input<double>("wait_for") && looking) return Release("nobody about");
    // ... as once it has opened for someone waiting: they go through when it opens, and may not
    // be seen to come (kComingForSec on end) as the robot turns from the actuator.
    if ((came_ || opened_for_waiting_) && unseen_ > Input<double>("clear_for") && looking)
      return Release("everyone is through");
    // The door open for those waiting or anyone near, and the robot still at the actuator in
    // their way in: first of all it steps sideways out of the way through, up to the wall (a drive
    // to its spot may stall beside them, as the drive slows for whoever is near). Standing at the
    // standoff, it is what they cannot pass (two wards seed 54, clinic seed 19: door_e's leaf
    // opens towards them, its free edge 0.55 m from the robot at the standoff on the wall where
    // its button is, and a wheelchair needs 0.66 m). With its way to the spot taken, it stays
    // there while the door stands open, for a hold window at most (it may have shut unseen).
    const bool door_open = belief_.door_open_since.count(door_) > 0;
    if ((opened_for_waiting_ || around.near) && door_open && !squeezed_ &&
        (standoff_.translation() - belief_.X_MB.translation()).norm() <= kStillAtActuatorM &&
        InTheLane(pass, belief_.X_MB.translation(), task_.config)) {
      if (const std::optional<Pose2> to = SqueezeAsidePose(task_, pass, door_)) {
        task_.motion->FollowPath({belief_.X_MB, *to}, {true}, TuckedArm(*task_.model), belief_.now);
        Note(StrCat("in the way in to the open door: squeezing aside to ", PoseText(*to)));
        squeezed_ = true;
        squeezed_at_ = belief_.now;
        return NodeStatus::kRunning;
      }
    }
    if (squeezed_ && door_open &&
        ToSeconds(belief_.now - squeezed_at_) < task_.config.door_hold_window &&
        (task_.motion->base_moving() ||
         !WayClear(belief_, spot_, kStandoffFreeM, kSpotClearM, /*ahead_only=*/true)))
      return NodeStatus::kRunning;
    // Someone too near: the robot steps away from them first, whatever it was doing (a crowd
    // funnelling into the doorway spreads along the wall it waits by). A step under way is
    // re-aimed when someone now comes at where it ends (clinic seed 4: a resident skirting the
    // crowd walked 2 m at the robot during a 3 s step it took for others, and into it).
    if (!task_.motion->base_moving()) making_room_ = false;
    // Not sooner than kReAimAfterSec into a step: each starts from rest, and re-aimed every
    // tick the robot hardly moved (clinic seed 124).
    const bool may_step = !making_room_ || ToSeconds(belief_.now - room_since_) >= kReAimAfterSec;
    if (const std::optional<Pose2> room =
            may_step ? FindRoom(task_, pass, making_room_ ? std::optional(room_to_) : std::nullopt)
                     : std::nullopt) {
      // At the door speed (the quickest the trajectories go): a resident walks at 1 m/s. The arm
      // tucks on the way: an operation broken off leaves it out at the actuator, and stepping
      // with it out dragged the hand along the wall (atrium west seeds 5 and 36).
      task_.motion->FollowPath({belief_.X_MB, *room}, {true}, TuckedArm(*task_.model), belief_.now,
                               std::nullopt, /*brisk=*/true);
      making_room_ = true;
      room_to_ = room->translation();
      room_since_ = belief_.now;
      Note(StrCat("making room: stepping to ", PoseText(*room)));
      return NodeStatus::kRunning;
    }
    if (!task_.motion->base_moving() && !letting_pass_since_) driving_to_.reset();
    // Its spot taken on the way: it stops short (the drive's slowing spares whoever stands at
    // its goal: two wards seed 10, it crept on into a resident waiting beside the spot). Not in
    // the residents' way in: stopped there, between the actuator and its spot, it held up a
    // wheelchair user at door_e through two hold windows (the leaf opening towards them left
    // 0.6 m between its edge and the robot; clinic seed 19), and the drive's slowing and the
    // guard spare whoever it nears on its way out.
    if (driving_to_ && !letting_pass_since_ && task_.motion->base_moving() &&
        (*driving_to_ - belief_.X_MB.translation()).norm() > kAtSpotM &&
        !InTheLane(pass, belief_.X_MB.translation(), task_.config) &&
        !WayClear(belief_, {driving_to_->x(), driving_to_->y(), 0.0}, drive_clear_, 0.0)) {
      task_.motion->StopBase();
      driving_to_.reset();
      Note("the spot is taken: stopping short");
    }
    if (LettingFollowersPass(pass)) return NodeStatus::kRunning;
    if (task_.motion->base_moving()) return NodeStatus::kRunning;  // turning, or stepping aside
    // An operation broken off (someone came) leaves the arm out: tucked before the base moves.
    if (!ArmAt(task_.motion->arm_target(), TuckedArm(*task_.model))) {
      task_.motion->MoveArm({{task_.config.arm_tuck_time, TuckedArm(*task_.model)}}, belief_.now);
      Note("tucking the arm");
    }
    if (task_.motion->arm_moving(belief_.now)) return NodeStatus::kRunning;
    if (task_.motion->base_failed()) task_.motion->StopBase();  // blocked: watch from here
    // The actuator is reached only with nobody on the move near the door, and nobody, moving or
    // standing, within keep_clear of the standoff or the way there: people standing that close
    // may set off while the robot is at the actuator, beside the doorway they make for (and it
    // takes the robot seconds to get out of their way).
    // Once they came and have all stood still for a while, whoever is left waits for the door
    // (someone who cannot open it): the robot opens it for them, with only the standoff itself
    // free (kStandoffFreeM); the way there is the planner's, round them, and the reactive guard's
    // (IsNobodyComing). Asking the last metre of the straight line to be clear as well kept it
    // away for good where the one waiting stands beside the standoff in a 2 m corridor (clinic
    // seeds 13, 60; two wards seeds 12, 17: a resident left behind).
    const bool all_waiting =
        came_ && last_moving_ && ToSeconds(belief_.now - *last_moving_) > kStillForSec;
    // Someone who cannot open the door may be waiting right at it before the robot arrives, and
    // never move while it watches: nobody near has moved since the hold began, and someone
    // stands by the doorway. (Not anyone still within the watch radius: residents standing in
    // the room when the alarm sounds set off as the robot reaches the actuator among them.)
    // Only they: with others standing further out near the actuator, this is a group that has
    // not set off yet (office seed 21: its front row stood 1.4 m from the doorway; the robot,
    // its back to them to press the button, was walked into when they set off — the laser's
    // blind sector is behind it).
    // And not once the door has stood open before them while they stayed: someone waiting for
    // it goes through when it opens; a group yet to set off stays (and its back rows may be
    // hidden behind the front one).
    const auto open_since = belief_.door_open_since.find(door_);
    if (open_since != belief_.door_open_since.end() &&
        ToSeconds(belief_.now - open_since->second) > kStillForSec)
      stood_open_ = true;
    // Found waiting: still for kStillForSec (not since the hold began: a stir nearby, too short
    // to be people coming, is no reason to leave someone waiting — two wards seed 7), with
    // someone by the doorway. Before the evacuation is under way, only those by the doorway
    // near the actuator: a group standing about has its front row there too (office seed 19: a
    // grid of twelve 1 m apart, its corner 1.8 m from door_a), and a group that stayed while the
    // door stood open before it is not waiting for it. Once under way (people came to a door
    // this robot held), whoever stands at the next door is waiting: with someone by its
    // doorway, however many stand further out (office seed 14: a queue of two at door_b, the
    // second 1.9 m from the doorway), or anyone within `reach` of the standoff (clinic seed 37: a
    // wheelchair user 2.4 m from door_e's doorway, across the lane to the actuator they made
    // way for), and even if they stayed while it stood open (clinic seed 19: a wheelchair user
    // held up at door_e by the robot through two windows).
    const AtTheDoorway at_door = ByTheDoorway(belief_, pass, standoff_.translation(),
                                              Input<double>("reach"), task_.config.person_radius);
    const bool found_waiting =
        !came_ && !around.moving && (!stood_open_ || under_way_) &&
        (!last_moving_ || ToSeconds(belief_.now - *last_moving_) > kStillForSec) &&
        ToSeconds(belief_.now - *started_) > kStillForSec &&
        (under_way_ ? at_door.someone || !at_door.alone : at_door.only);
    // Before the evacuation is under way, not with people standing within `reach` who have yet
    // to set off: they may at any moment, and an operation keeps the robot at the actuator,
    // beside their way in, for ~10 s (a walker's 10 m). Going every `every` seconds while a
    // group stood 3.5-4 m from the standoff, the robot was at the button when the alarm set them
    // off about half the time, and drove back to its spot through them (two wards seeds 3, 16,
    // 22; atrium seeds 23, 38: walked into). Only someone waiting by the doorway
    // (found_waiting), or nobody near: then it opens ahead of whoever comes.
    const bool group_within_reach = !came_ && !under_way_ && !at_door.alone;
    const bool actuator_clear =
        !around.moving && (!group_within_reach || found_waiting) &&
        (found_waiting || all_waiting ? WayClear(belief_, standoff_, kStandoffFreeM, 0.0)
                                      : WayClear(belief_, standoff_, Input<double>("keep_clear")));
    // For those waiting, once per hold window, not every `every` seconds: between operations
    // the robot waits aside, out of their way in (at `every`, the press itself and the tuck
    // after it kept the robot at the actuator, beside the way in, for good: clinic seed 13).
    const double every = found_waiting || all_waiting
                             ? std::max(Input<double>("every"), task_.config.door_hold_window)
                             : Input<double>("every");
    // Having opened for someone waiting, and nobody about any more before anyone came: they went
    // through, and there is nobody to open it for (clinic escort seed 26: the robot pressed door_e
    // twice more after the wheelchair user it had opened for went through, and reached the exit
    // door, where they waited, after the time limit). Not once people came: residents still
    // coming from beyond its watch then find the door shut (two wards, 20 of 50 trials slower).
    // Nor, once people came, while the clear clock runs with nobody near: the hold either runs
    // out or someone comes within clear_for. Due on arrival at its spot after a drive longer than
    // `every`, the operation fell due before the clear time had run, and the robot pressed for
    // nobody once per round trip until the time limit (random building seeds 7, 12).
    const bool clock_running = came_ && unseen_ > 0.0 && !around.near;
    const bool for_someone = (came_ || !opened_for_waiting_ || around.near) && !clock_running;
    // Boxed in at the actuator (not on its way to its spot for kStillForSec), with someone near
    // who walked in this hold (on the move kComingForSec on end: came, or milled about the door)
    // and all still for kStillForSec since, someone by the doorway: they wait at the shut door,
    // and the robot stands where they would operate it. It operates from where it stands, once
    // per hold window (random building seed 8: the group came while it pressed, the press was
    // broken off, and nine residents and the robot waited at the exit door for 340 s, the group
    // within `reach` keeping it from pressing). Not for a group yet to set off, however it stirs
    // (seed 28: a stir of theirs let it reach for the button among them as they set off).
    const bool boxed_in =
        (standoff_.translation() - belief_.X_MB.translation()).norm() <= kAtSpotM && stuck_since_ &&
        ToSeconds(belief_.now - *stuck_since_) >= kStillForSec && at_door.someone && walked_ &&
        ToSeconds(belief_.now - *last_moving_) > kStillForSec && !clock_running;
    if (!OperationJustFailed() &&
        ((OperateDue(every) && actuator_clear && for_someone) ||
         (boxed_in &&
          OperateDue(std::max(Input<double>("every"), task_.config.door_hold_window))))) {
      operate_asked_at_ = belief_.now;
      squeezed_ = false;
      if (found_waiting || all_waiting || boxed_in) opened_for_waiting_ = true;
      return NodeStatus::kSuccess;
    }
    // Not at the actuator with anyone near, moving or not: its standoff is beside the doorway's
    // way in, and with the leaf open towards them a wide resident waiting there cannot get
    // between the leaf and the robot (clinic seed 13: a wheelchair user waited through 80 s of
    // the robot's presses, the robot at the button between presses, until the time limit).
    // Nor once it has opened for someone waiting: they may be where the laser does not see,
    // behind it as it faces the actuator (clinic escort seed 26: at door_e, whose standoff is
    // before the doorway, the robot waited there after the press, and the resident it had
    // opened for could not pass it while the door stood open).
    // And not where the standoff is the residents' way in (a spot found only beside the lane):
    // waiting there, it was what the first of them, setting off, walked into on their way to the
    // actuator (random building seed 31).
    const Pose2& wait_at =
        came_ || around.near || !actuator_clear || opened_for_waiting_ || spot_beside_lane_
            ? spot_
            : standoff_;
    // Only the spot and the last kSpotClearM of the way there: from far back, the straight line
    // to it passes people it will never meet on its path (clinic: a resident waiting at door_e
    // kept the robot 14 m back from its spot, and the door shut, until max_hold). On the way, the
    // navigation yields to people as everywhere.
    // Past those waiting (standing still), the robot's room is enough: the planner keeps it
    // off them (a metre kept it at the actuator beside a wheelchair user it had opened for).
    const double spot_clear = found_waiting || all_waiting ? kStandoffFreeM : kSpotClearM;
    // Nor to set off from their way in: staying there holds up whoever is near more than driving
    // out past them (clinic escort seed 26: a resident 0.8 m from the way to the spot kept the
    // robot before door_e's doorway, and so themselves behind it, through two openings). Out of
    // the lane it stops short as ever if the spot is taken.
    const double set_off_clear =
        InTheLane(pass, belief_.X_MB.translation(), task_.config) ? kStandoffFreeM : spot_clear;
    const bool may_plan =
        !drive_failing_ || ToSeconds(belief_.now - drive_failed_at_) >= kReplanNoPathSec;
    if ((wait_at.translation() - belief_.X_MB.translation()).norm() > kAtSpotM && may_plan &&
        WayClear(belief_, wait_at, set_off_clear, kSpotClearM, /*ahead_only=*/true)) {
      // Square to the way it drives, turning to watch at the spot (below): the laser sees both
      // ahead and back along the way. From the last door the way there runs away from where the
      // residents come: facing them the robot drove backwards, the blind sector leading, into a
      // resident queued on its way (two-wards seed 12, 14 m along the corridor); facing the way
      // it drove, a resident who came up behind it was not seen until they walked into it
      // (two-wards seed 3).
      Pose2 goal = wait_at;
      goal.yaw = LookYaw(pass, wait_at.translation());
      std::vector<std::string> notes;
      const bool set_off =
          StartPath(
              task_, goal, &wait_at == &spot_ ? "the spot beside the door" : "the actuator",
              [&notes](const std::string& t) { notes.push_back(t); }, Input<bool>("door_speed"),
              PathHeading::kAcrossTravel) == NodeStatus::kRunning;
      // Why it cannot go, noted once while that lasts (every tick filled the log: seed 8).
      if (set_off || !drive_failing_)
        for (const std::string& t : notes)
          Note(t);
      drive_failing_ = !set_off;
      if (!set_off) drive_failed_at_ = belief_.now;
      if (set_off) {
        driving_to_ = goal.translation();
        drive_clear_ = spot_clear;
        stuck_since_.reset();
        return NodeStatus::kRunning;
      }
    }
    // Not where it waits, and not driving there (its way taken, or no path).
    if ((wait_at.translation() - belief_.X_MB.translation()).norm() <= kAtSpotM)
      stuck_since_.reset();
    else if (!stuck_since_)
      stuck_since_ = belief_.now;
    // Waiting, at the actuator as aside, face the way the residents come: the camera sees only
    // ahead, and the laser's blind sector is behind (facing the wall at the actuator, it is the
    // room: office seeds 20, 24, 31, 33 — a group it did not see stood behind it, set off and
    // walked into it).
    // Only as far as brings that way within kWatchWithinRad of ahead: at the actuator the
    // robot faces the wall and the residents' way in is behind it; a whole turn there and back
    // took ~5 s each way (lab: back at the button after the door had shut, as the residents set
    // off). The head looks the rest of the way.
    // With no path to where it would wait, it looks there (marks of someone long gone, behind
    // it, only a ray clears: seed 8's spot stayed "in collision" 340 s in the blind sector).
    // Else both the watch point and the way in, where the clear time is counted: near the watch
    // point, the way in may lie well off its bearing (two wards seed 56: a step to make room
    // ended 0.4 m from door_e's watch point, which it faced 90 deg off ahead; the way in was
    // 129 deg off, past the laser's sweep, the clear time never ran, and the robot held door_e
    // until the time limit while the last resident waited at the exit door).
    {
      const auto bearing = [&](const Eigen::Vector2d& p_M) {
        const Eigen::Vector2d to = p_M - belief_.X_MB.translation();
        return std::remainder(std::atan2(to.y(), to.x()) - belief_.X_MB.yaw, 2 * M_PI);
      };
      const bool look_at_spot =
          drive_failing_ && !IsInLaserSweep(task_, belief_.X_MB, wait_at.translation());
      const double turn =
          look_at_spot ? WatchTurn(bearing(wait_at.translation()), bearing(wait_at.translation()),
                                   kWatchWithinRad)
                       : WatchTurn(bearing(WatchPoint(pass)), bearing(way_in), kWatchWithinRad);
      const double yaw = belief_.X_MB.yaw + turn;
      if (task_.gaze != nullptr) {
        const Eigen::Vector2d p = WatchPoint(pass);
        task_.gaze->RequestLook({p.x(), p.y(), belief_.X_MC.translation().z()},
                                belief_.now + SecondsToDuration(kLookRequestSec));
      }
      if (std::abs(std::remainder(yaw - belief_.X_MB.yaw, 2 * M_PI)) > kFacingToleranceRad) {
        task_.motion->FollowPath({belief_.X_MB, Pose2{belief_.X_MB.x, belief_.X_MB.y, yaw}},
                                 {false}, task_.motion->arm_target(), belief_.now);
      }
    }
    return NodeStatus::kRunning;
  }

  void OnHalted() override {
    task_.motion->StopBase();
    making_room_ = false;
    driving_to_.reset();
    letting_pass_since_.reset();
  }

 private:
  // Someone walking up behind its drive (residents walk faster; two wards seed 3): it stops,
  // stands where people leave it the most room (PeopleRoom, as NavigateTo's give-way) but never
  // in the way in, nearer the doorway or in one (lab seed 14), and drives on kLetPassClearSec
  // after the last. True: letting them pass.
  bool LettingFollowersPass(const DoorPass& pass) {
    const Eigen::Vector2d at = belief_.X_MB.translation();
    if (driving_to_ && (*driving_to_ - at).norm() > kAtSpotM &&
        SomeoneWalkingUpBehind(task_, (*driving_to_ - at).normalized())) {
      follower_seen_ = belief_.now;
      if (!letting_pass_since_) {
        letting_pass_since_ = belief_.now;
        aside_chosen_ = false;
        task_.motion->StopBase();
        Note("someone walking up behind: letting them pass");
      }
    }
    if (!letting_pass_since_) return false;
    if (ToSeconds(belief_.now - follower_seen_) >= kLetPassClearSec ||
        ToSeconds(belief_.now - *letting_pass_since_) >= kLetPassMaxSec) {
      Note("nobody walking up behind: driving on");
      letting_pass_since_.reset();
      driving_to_.reset();
      return false;
    }
    if (!aside_chosen_ && StoppedOrStopTimedOut(task_, *letting_pass_since_)) {
      aside_chosen_ = true;
      const auto aside = MakeWaySpot(task_, kAsideGainM);
      if (aside && !InTheirWay(task_, pass, at, aside->translation())) {
        StepAsideTo(task_, *aside);
        Note(StrCat("stepping aside to ", PoseText(*aside)));
      }
    }
    if (task_.motion->base_failed()) task_.motion->StopBase();  // blocked: stay where it is
    return true;
  }

  void ResetHold() {
    started_.reset();
    operate_asked_at_.reset();
    last_tick_.reset();
    nobody_at_last_watch_ = false;
    came_ = false;
    walked_ = false;
    approach_.Reset();
    last_moving_.reset();
    moving_since_.reset();
    unseen_ = 0.0;
    stood_open_ = false;
    opened_for_waiting_ = false;
    squeezed_ = false;
  }

  NodeStatus Release(const std::string& why) {
    Note(StrCat("releasing ", door_, ": ", why));
    ResetHold();
    return NodeStatus::kFailure;
  }

  // The actuator on the robot's side, its standoff, and the wait spot beside it; written to
  // `spot`. False (noted) when the door has no actuator on this side.
  bool PlanSpot() {
    const MapActuator* actuator = task_.map->FindActuatorOf(door_, belief_.X_MB.translation());
    if (actuator == nullptr) {
      Note("door has no actuator on this side");
      return false;
    }
    standoff_ = planning::MakeButtonTargets(actuator->p_M, actuator->n_M, actuator->type,
                                            task_.config.buttons)
                    .X_MB_standoff;
    const DoorPass pass = CalcDoorPass(*task_.map, door_, standoff_);
    const Eigen::Vector2d n = actuator->n_M.head<2>().normalized();
    Eigen::Vector2d t(-n.y(), n.x());
    if (t.dot(standoff_.translation() - pass.centre) < 0.0) t = -t;  // away from the doorway
    const double aside = Input<double>("aside");
    spot_ = standoff_;
    bool found = aside <= 0.0;
    // Nearer spots if the far one is blocked (a corner, furniture); the standoff itself last.
    for (const double f : {1.0, 0.75, 0.5, 0.25}) {
      if (found) break;
      const Eigen::Vector2d p = standoff_.translation() + t * aside * f;
      const Pose2 candidate{p.x(), p.y(), standoff_.yaw};
      // Reached along the wall from the standoff: a free pose past a corner may be in the next
      // room.
      if (!task_.planner->IsPathValid({standoff_, candidate})) continue;
      spot_ = candidate;
      found = true;
    }
    spot_beside_lane_ = !found && SpotBesideTheLane(pass, t, n, aside);
    if (spot_beside_lane_)
      Note(StrCat("no free spot along the wall: waiting beside the lane at ", PoseText(spot_)));
    found = found || spot_beside_lane_;
    if (!found) Note("no free spot beside the actuator: waiting at its standoff");
    this->SetOutput("spot", PosePortText(spot_));
    return true;
  }

  // No spot along the wall (a corner within a footprint of the standoff): the standoff lies in
  // the residents' way in, where the crowd funnelling to the door pressed the standing robot into
  // the corner (random building seed 31). The nearest spot, along the wall and out from it, beside
  // the lane, clear of the leaves, and leaving a resident room to stand at the actuator between
  // it and the standoff, reached straight from the standoff; written to spot_.
  bool SpotBesideTheLane(const DoorPass& pass, const Eigen::Vector2d& along,
                         const Eigen::Vector2d& out, double aside) {
    const auto p = NearestOnGrid(
        standoff_.translation(), along, aside, out, kSpotSearchOutM, kSpotSearchStepM,
        task_.config.footprint_radius + 2 * task_.config.person_radius,
        [&](const Eigen::Vector2d& q) {
          return !InTheLane(pass, q, task_.config) &&
                 !IntoADoorway(task_, standoff_.translation(), q) &&
                 task_.planner->IsPathValid({standoff_, {q.x(), q.y(), standoff_.yaw}});
        });
    if (p) spot_ = {p->x(), p->y(), standoff_.yaw};
    return p.has_value();
  }

  // The operation asked for less than kOperateRetrySec ago did not happen (the approach found
  // no free standoff: someone waiting by the actuator, in reach of the arm from nowhere the
  // base may stand): asked again at once, it failed again every tick for 340 s (two-wards
  // seed 17).
  bool OperationJustFailed() const {
    if (!operate_asked_at_ || ToSeconds(belief_.now - *operate_asked_at_) >= kOperateRetrySec)
      return false;
    const std::optional<DoorVisit> visit = Shared<DoorVisit>("visit");
    return !visit || visit->door != door_ || !visit->operated_at ||
           *visit->operated_at < *operate_asked_at_;
  }

  // Whether to operate the actuator now: not yet in this hold, the door seen shut or shutting,
  // or `every` seconds since the last operation.
  bool OperateDue(double every) const {
    const std::optional<DoorVisit> visit = Shared<DoorVisit>("visit");
    if (!visit || visit->door != door_ || !visit->operated_at || *visit->operated_at < *started_)
      return true;  // not operated in this hold yet
    for (const auto& d : belief_.world.doors) {
      if (d.model.id != door_) continue;
      if (d.state.observed && (d.state.motion == perception::DoorMotion::kClosing ||
                               d.state.motion == perception::DoorMotion::kClosed))
        return true;
    }
    return ToSeconds(belief_.now - *visit->operated_at) >= every;
  }

  std::string door_;
  Pose2 standoff_;
  Pose2 spot_;
  std::optional<Time> started_;           // when this hold began
  std::optional<Time> operate_asked_at_;  // when it last returned SUCCESS: operate now
  std::optional<Time> last_tick_;         // the previous tick of an unbroken watch
  bool nobody_at_last_watch_{false};      // nobody was near at the last tick of the watch
  bool came_{false};                      // someone came during this hold
  bool walked_{false};     // someone near was on the move kComingForSec on end in this hold
  bool under_way_{false};  // someone came during any hold so far
  std::optional<Time> last_moving_;    // when someone near was last seen on the move
  std::optional<Time> moving_since_;   // since when, with no gap over kStirGapSec
  ApproachWatch approach_;             // who walks up to the doorway, for came_
  double unseen_{0.0};                 // [s] of watching since anyone was near
  bool making_room_{false};            // stepping away from someone too near
  Eigen::Vector2d room_to_{0.0, 0.0};  // where that step ends
  Time room_since_{};                  // when it began
  bool stood_open_{false};  // the door stood open kStillForSec in this hold with nobody moving
  bool opened_for_waiting_{false};  // it operated for someone found waiting, in this hold
  bool squeezed_{false};  // stepped aside from the open door's way in since the last operation
  Time squeezed_at_{};    // when
  bool spot_beside_lane_{false};  // no spot along the wall: spot_ is SpotBesideTheLane's
  std::optional<Eigen::Vector2d> driving_to_;  // where a drive of this node's under way goes
  double drive_clear_{0.0};  // [m] the room round its end that drive set off with (WayClear)
  std::optional<Time> stuck_since_;         // since when it is not on its way to where it waits
  bool drive_failing_{false};               // its last try to drive there found no path
  Time drive_failed_at_{};                  // when (planned again kReplanNoPathSec after)
  std::optional<Time> letting_pass_since_;  // stopped for someone walking up behind
  Time follower_seen_{};                    // when someone last walked up behind
  bool aside_chosen_{false};                // the spot aside, while letting them pass
};

}  // namespace

void RegisterEscortNodes(bt::BehaviorTreeFactory& factory, const TaskServices* services) {
  Register<HoldForResidents>(factory, "HoldForResidents", services);
  RegisterEscortGuard(factory, services);
}

}  // namespace egress::behavior::detail
