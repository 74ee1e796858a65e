// TraverseDoor, the door node that drives through the doorway (door_nodes.cpp has the others:
// finding, approaching and operating the actuator).

#include "task_node_support.h"

#include <cmath>
#include <optional>

namespace egress::behavior::detail {
namespace {

// Drives through a door in two legs: to the entry pose on the door's axis (the arm tucking on
// the way), where the laser sees through the opening; then, once the leaf leaves room for the
// footprint, through the doorway to the exit pose. Both legs run at the door speed (the ADA
// hold window is short), but for the slide from the lane's edge, as slowly as the window leaves
// time for, down to the nominal speed (slide_speed_). Coming from beside the lane to a door that
// opens away, the first leg stops at the lane's edge until the leaf is open and the robot has
// looked through the opening (TaskConfig::door_peek_time): whoever waited on the far side is seen
// setting off before the robot stands in their way.
class TraverseDoor final : public TaskNode<bt::StatefulActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("door", "door to drive through"),
            InputPort<double>("wait_timeout", 8.0,
                              "how long to wait for the leaf to open before failing [s]"),
            VisitPort(bt::PortDirection::kInOut)};
  }
  NodeStatus OnStart() override {
    gate_.Reset();
    DoorVisit visit = Visit();
    door_ = visit.door;
    pass_ = CalcApproachPass(task_, visit);
    Remember(visit);
    if (!ArmAt(task_.motion->arm_target(), TuckedArm(*task_.model)) ||
        task_.motion->arm_moving(belief_.now)) {
      task_.motion->MoveArm({{task_.config.arm_tuck_time, TuckedArm(*task_.model)}}, belief_.now);
    }
    yaw_ = std::atan2(-pass_.n_M.y(), -pass_.n_M.x());  // facing through the door
    entry_distance_ = EntryDistance(task_, door_, pass_);
    const Eigen::Vector2d offset = belief_.X_MB.translation() - pass_.centre;
    const double lateral = std::abs(offset.dot(Eigen::Vector2d(-pass_.n_M.y(), pass_.n_M.x())));
    phase_ = Phase::kWaiting;
    waiting_since_ = belief_.now;
    passage_wait_over_ = false;
    aside_for_passage_ = false;
    peek_side_.reset();
    give_way_.Reset();
    if (lateral > 0.05 || offset.dot(pass_.n_M) > entry_distance_ + 0.05) {
      // Out of the way of anyone walking up to the door first: the line-up crosses the
      // approach to the doorway (P1: someone walking up behind the robot at the button to go
      // through met it driving to the lane's edge, 0.38 m off).
      if (WatchSomeoneForTheDoor()) return OnRunning();
      if (GiveWayIfComing()) return NodeStatus::kRunning;
      if (const NodeStatus s = StartLineUp(); s != NodeStatus::kRunning) return s;
    }
    return OnRunning();
  }
  NodeStatus OnRunning() override {
    const auto note = [this](const std::string& t) { Note(t); };
    switch (phase_) {
      case Phase::kGivingWay: {
        if (give_way_.Update(task_, std::nullopt, Input<double>("wait_timeout"), note) ==
            NodeStatus::kRunning)
          return NodeStatus::kRunning;
        if (aside_for_passage_) {
          // Still waiting for the passage beside the lane (kPeeking lines up once it is quiet).
          phase_ = Phase::kPeeking;
          waiting_since_ = belief_.now;
          return NodeStatus::kRunning;
        }
        return StartLineUp();
      }
      case Phase::kWatchingWaiter: {
        const std::optional<ForTheDoor> someone = SomeoneForTheDoor();
        if (someone) {
          LookAt({someone->p_M.x(), someone->p_M.y(), belief_.X_MC.translation().z()});
          StandClearOfTheWayIn(someone->p_M);
        }
        // The step clear of their way is a way made for them already: it ends first.
        if (task_.motion->base_moving()) return NodeStatus::kRunning;
        if (GiveWayIfComing()) return NodeStatus::kRunning;
        if (someone && ToSeconds(belief_.now - waiting_since_) < task_.config.near_waiter_time)
          return NodeStatus::kRunning;
        Note(someone ? "they stay where they are: lining up"
                     : "nobody for the door now: lining up");
        return StartLineUp();
      }
      case Phase::kToPeek: {
        if (GiveWayIfComing()) return NodeStatus::kRunning;
        const NodeStatus s = DriveStatus(task_, note, true);
        if (s != NodeStatus::kSuccess) return s;
        phase_ = Phase::kPeeking;
        waiting_since_ = belief_.now;
        [[fallthrough]];
      }
      case Phase::kPeeking: {
        if (GiveWayIfComing()) return NodeStatus::kRunning;
        if (const NodeStatus arm = ArmMotionStatus(task_, note); arm != NodeStatus::kSuccess)
          return arm;
        const Eigen::Vector2d entry = EntryPoint();
        const double slide = (entry - belief_.X_MB.translation()).norm();
        // The slide turns the base back square to the door (TaskConfig::door_peek_turn_deg).
        const double turn = std::remainder(yaw_ - belief_.X_MB.yaw, 2 * M_PI);
        const double slide_time =
            planning::SegmentDuration(slide, turn, true, task_.motion->trajectory_config());
        const double slow_slide_time =
            planning::SegmentDuration(slide, turn, false, task_.motion->trajectory_config());
        const double looked = ToSeconds(belief_.now - waiting_since_);
        // From beside the lane the leaf is often behind the jamb: its clearance is checked
        // again on the axis, where it is in view.
        const DoorVisit visit = Visit();
        const auto window_leaves = [&](double t) {
          return LeafSeenNow() ? DoorPassable(task_, door_, 0.0, &visit, t)
                               : DoorWindowLeavesTime(task_, door_, &visit, t);
        };
        const bool window_leaves_time = window_leaves(slide_time);
        // Stepped back here for people passing the doorway: until they have passed.
        if (aside_for_passage_ &&
            PassageBusy(slide_time +
                        DoorPathDuration(task_, {Pose2{entry.x(), entry.y(), yaw_}, ExitPose()})))
          return NodeStatus::kRunning;
        if (looked < task_.config.door_peek_time || LeafOpening() || !window_leaves_time) {
          if (looked > Input<double>("wait_timeout")) {
            Note("the door did not open in time");
            return NodeStatus::kFailure;
          }
          return NodeStatus::kRunning;
        }
        slide_speed_ = SlideSpeed(slide, slide_time, slow_slide_time, window_leaves);
        if (const NodeStatus s = StartLineUp(); s != NodeStatus::kRunning) return s;
        return NodeStatus::kRunning;
      }
      case Phase::kToEntry: {
        const NodeStatus s = DriveStatus(task_, note, true);
        if (s != NodeStatus::kSuccess) return s;
        phase_ = Phase::kWaiting;
        waiting_since_ = belief_.now;
        [[fallthrough]];
      }
      case Phase::kWaiting: {
        if (gate_.Check(task_, "driving through the door", EventNoter(),
                        DoorPassPoseSigma(task_, door_)) == NodeStatus::kRunning)
          return NodeStatus::kRunning;
        if (const NodeStatus arm =
                ArmMotionStatus(task_, [this](const std::string& t) { Note(t); });
            arm != NodeStatus::kSuccess) {
          return arm;
        }
        if (const DoorVisit visit = Visit(); !DoorPassable(task_, door_, 0.0, &visit)) {
          if (ToSeconds(belief_.now - waiting_since_) > Input<double>("wait_timeout")) {
            Note("the door did not open in time");
            return NodeStatus::kFailure;
          }
          BackOutOfTheSweep();
          return NodeStatus::kRunning;  // the leaf is still opening
        }
        // Through the middle of the clear opening, between the latch jamb and the leaf.
        const Eigen::Vector2d centre = ClearOpeningCentre(task_, door_);
        const Eigen::Vector2d offset = belief_.X_MB.translation() - centre;
        std::vector<Pose2> path{belief_.X_MB};
        std::vector<bool> through;
        // Squared up on the opening's centre line first, by a step sideways where the robot
        // stands: every waypoint is a stop, and one in the doorway (as 0.4 m before the line
        // was) stands there a second beside whoever walks past (two wards seed 35).
        const Eigen::Vector2d in = centre + pass_.n_M * offset.dot(pass_.n_M);
        if (offset.dot(pass_.n_M) > 0.1 &&
            (in - belief_.X_MB.translation()).norm() > kSquareUpTolerance) {
          path.push_back({in.x(), in.y(), yaw_});
          through.push_back(true);
        }
        // From an entry beyond the sweep of a leaf that opens towards it, the laser sees little of
        // the far side, and the pass would be at speed by the time it crosses the commit distance:
        // someone coming into view there found the base sliding into the doorway (two wards seed
        // 35). The pass stops first at the ordinary entry distance, out of the doorway, and sets
        // off from there: the view is wider, and the commit distance crossed slowly.
        const double look = task_.config.door_entry_distance;
        if (offset.dot(pass_.n_M) > look + kLookThroughMinStep) {
          const Eigen::Vector2d p = centre + pass_.n_M * look;
          path.push_back({p.x(), p.y(), yaw_});
          through.push_back(true);
        }
        path.push_back(ExitPose());
        through.push_back(true);
        if (PassageBusy(DoorPathDuration(task_, path))) {
          if (!BackOutOfTheSweep()) WaitBesideTheLane();
          return NodeStatus::kRunning;
        }
        task_.motion->FollowPath(path, through, TuckedArm(*task_.model), belief_.now);
        Note(StrCat("door open: driving through at ", task_.motion->trajectory_config().door_speed,
                    " m/s"));
        phase_ = Phase::kThrough;
        return NodeStatus::kRunning;
      }
      case Phase::kThrough: {
        // Someone come into view who will pass the doorway beside the robot: it stops short of
        // the doorway and waits at the entry again, if it is still far enough out to stop there.
        const double along = (belief_.X_MB.translation() - pass_.centre).dot(pass_.n_M);
        if (task_.config.passage_clearance > 0.0 && !passage_wait_over_ &&
            along > kPassageCommitDistance && task_.motion->base_moving() &&
            IsPassageBusy(task_, door_, DoorPathDuration(task_, task_.motion->path()))) {
          task_.motion->StopBase();
          Note("stopping short of the doorway: someone will pass it beside the robot");
          phase_ = Phase::kWaiting;
          waiting_since_ = belief_.now;
          return NodeStatus::kRunning;
        }
        const NodeStatus s = BaseMotionStatus(task_, note);
        if (s == NodeStatus::kSuccess) {
          Note("through the door");
          DoorVisit visit = Visit();
          visit.approach_side.reset();  // a later traversal may come the other way
          Remember(visit);
        }
        return s;
      }
    }
    return NodeStatus::kFailure;
  }
  void OnHalted() override {
    // A step out of someone's way goes on: halted as they enter the door zone, the standby
    // after it (RetractToSafe) lets it end (P1 seed 2000: stopped 0.3 s into a step along the
    // wall, the robot stood at the button as the walker passed 0.69 m off). The executive stops
    // the base when it halts the whole tree.
    if (!task_.motion->stepping_out_of_way()) task_.motion->StopBase();
    give_way_.Reset();
  }

 private:
  RelocalizeGate gate_;

  // Drives to the entry pose on the door's axis (phase kToEntry), or first to the lane's edge
  // (phase kToPeek, PeekPose).
  NodeStatus StartLineUp() {
    if (const auto peek = PeekPose()) {
      // Only when the hold window leaves time for the stop as well (a press that restarted the
      // window of an open door leaves 10 s, about what the direct line-up and the pass take).
      const std::vector<Pose2> path{belief_.X_MB, *peek};
      if (const DoorVisit visit = Visit();
          DoorWindowLeavesTime(task_, door_, &visit, PeekLead(*peek)) &&
          task_.planner->IsPathValid(path)) {
        task_.motion->FollowPath(path, {true}, TuckedArm(*task_.model), belief_.now);
        Note("to the lane's edge, to look through the door before lining up");
        phase_ = Phase::kToPeek;
        peek_side_ = LateralOf(peek->translation()) > 0.0 ? 1.0 : -1.0;
        return NodeStatus::kRunning;
      }
    }
    const Eigen::Vector2d entry = EntryPoint();
    // Straight when the costmap allows (the usual case), else round what is in the way.
    const Pose2 X_MB_entry{entry.x(), entry.y(), yaw_};
    const std::vector<Pose2> line_up = LineUpPath(task_, door_, pass_, belief_.X_MB);
    if (task_.planner->IsPathValid(line_up)) {
      const std::optional<double> slide_speed =
          phase_ == Phase::kPeeking ? slide_speed_ : std::nullopt;
      task_.motion->FollowPath(line_up, std::vector<bool>(line_up.size() - 1, !slide_speed),
                               TuckedArm(*task_.model), belief_.now, slide_speed);
      Note("lining up on the door's axis");
    } else {
      const NodeStatus s = StartPath(
          task_, X_MB_entry, "the door's axis", [this](const std::string& t) { Note(t); }, true);
      if (s != NodeStatus::kRunning) return s;
    }
    phase_ = Phase::kToEntry;
    return NodeStatus::kRunning;
  }

  // How long the line-up by the lane's edge takes to the entry: to `peek`, the look through
  // (TaskConfig::door_peek_time) and the slide, at the door speed [s].
  double PeekLead(const Pose2& peek) const {
    const auto& trajectory = task_.motion->trajectory_config();
    const double turn = std::remainder(peek.yaw - belief_.X_MB.yaw, 2 * M_PI);
    const double turn_back = std::remainder(yaw_ - peek.yaw, 2 * M_PI);
    return planning::SegmentDuration((peek.translation() - belief_.X_MB.translation()).norm(), turn,
                                     true, trajectory) +
           task_.config.door_peek_time +
           planning::SegmentDuration((EntryPoint() - peek.translation()).norm(), turn_back, true,
                                     trajectory);
  }

  // Where the robot stops to look through the door before lining up: on the entry line, just
  // clear of the lane through the opening on the robot's side, turned door_peek_turn_deg from
  // facing through the door towards the lane (TaskConfig::door_peek_turn_deg). Only for a door
  // that opens away (one that opens towards the robot stands its leaf between the lane's edge
  // and the far side) and a robot beside the lane, farther out than that.
  std::optional<Pose2> PeekPose() const {
    if (task_.config.door_peek_time <= 0.0) return std::nullopt;
    const perception::DoorModel& door = *task_.map->FindDoor(door_);
    if (pass_.n_M.dot(door.SwingSide()) > 0.0) return std::nullopt;
    constexpr double kMinSlide = 0.15;  // [m] nearer than this, straight onto the axis
    const double lateral = LateralOf(belief_.X_MB.translation());
    if (std::abs(lateral) < LaneEdgeLateral() + kMinSlide) return std::nullopt;
    return LaneEdgePose(lateral > 0.0 ? 1.0 : -1.0);
  }

  // How far from the door's axis the footprint clears the lane through the opening [m].
  double LaneEdgeLateral() const {
    constexpr double kEdgeClearance = 0.05;  // [m] between the footprint and the lane
    return task_.map->FindDoor(door_)->width() / 2 + task_.config.footprint_radius + kEdgeClearance;
  }
  // Where p_M is across the door's axis (along the door line) [m].
  double LateralOf(const Eigen::Vector2d& p_M) const {
    return (p_M - pass_.centre).dot(Eigen::Vector2d(-pass_.n_M.y(), pass_.n_M.x()));
  }
  // PeekPose's spot on the `side` (+1 or -1, LateralOf's sign) of the lane.
  Pose2 LaneEdgePose(double side) const {
    const Eigen::Vector2d along(-pass_.n_M.y(), pass_.n_M.x());
    const Eigen::Vector2d p = EntryPoint() + along * (side * LaneEdgeLateral());
    const double turn = task_.config.door_peek_turn_deg * M_PI / 180.0;
    const Eigen::Vector2d facing = -pass_.n_M * std::cos(turn) - along * (side * std::sin(turn));
    return Pose2{p.x(), p.y(), std::atan2(facing.y(), facing.x())};
  }
  // Beyond the door, through the middle of the clear opening, facing on.
  Pose2 ExitPose() const {
    const Eigen::Vector2d exit =
        ClearOpeningCentre(task_, door_) - pass_.n_M * ExitDistance(task_, door_);
    return Pose2{exit.x(), exit.y(), yaw_};
  }

  // Waiting at the entry for people passing the doorway, the robot stands in front of the
  // opening: anyone near it on the far side may turn through it, and walks at the robot (H12,
  // P5 with their delays: someone from behind the leaf came through at the robot lined up on the
  // axis, stopped there for a passer-by, and squeezed past it at 5 cm). Come from the lane's
  // edge (PeekPose), it steps back there to wait, once per visit, and lines up again when they
  // have passed (phase kPeeking).
  void WaitBesideTheLane() {
    if (aside_for_passage_ || !peek_side_ || task_.motion->base_moving()) return;
    if (std::abs(LateralOf(belief_.X_MB.translation())) > 0.5 * LaneEdgeLateral()) return;
    const Pose2 aside = LaneEdgePose(*peek_side_);
    const std::vector<Pose2> path{belief_.X_MB, aside};
    if (!task_.planner->IsPathValid(path)) return;
    task_.motion->FollowPath(path, {true}, TuckedArm(*task_.model), belief_.now);
    Note("waiting beside the lane: someone by the doorway may come through it");
    aside_for_passage_ = true;
    phase_ = Phase::kToPeek;
  }

  // Waiting (for the leaf, or for people passing the doorway) nearer a leaf that opens towards
  // the robot than the entry, in its sweep, the robot backs out to the entry first: stopped short
  // of the doorway there for a stream of residents, it stood while the window ran out, and the
  // leaf closed onto it (two wards seed 17, five strikes). True if it set off.
  bool BackOutOfTheSweep() {
    constexpr double kInSweepToleranceM = 0.05;
    if (task_.motion->base_moving() ||
        pass_.n_M.dot(task_.map->FindDoor(door_)->SwingSide()) <= 0.0 ||
        (belief_.X_MB.translation() - pass_.centre).dot(pass_.n_M) >
            entry_distance_ - kInSweepToleranceM)
      return false;
    const Eigen::Vector2d entry = EntryPoint();
    const std::vector<Pose2> path{belief_.X_MB, {entry.x(), entry.y(), yaw_}};
    if (!task_.planner->IsPathValid(path)) return false;
    task_.motion->FollowPath(path, {true}, TuckedArm(*task_.model), belief_.now);
    Note("backing out of the leaf's sweep to the entry to wait there");
    phase_ = Phase::kToEntry;
    return true;
  }

  // Whether the robot waits at the entry for people to pass the doorway (IsPassageClear over the
  // pass's `duration` [s]), at most TaskConfig::passage_max_wait from the visit's first such
  // wait.
  bool PassageBusy(double duration) {
    if (task_.config.passage_clearance <= 0.0 ||
        IsPassageClear(task_, door_, duration, task_.config.passage_quiet_time))
      return false;
    DoorVisit visit = Visit();
    if (!visit.passage_wait_began) {
      visit.passage_wait_began = belief_.now;
      Remember(visit);
      Note("waiting at the entry: people would pass the doorway beside the robot");
    }
    if (ToSeconds(belief_.now - *visit.passage_wait_began) < task_.config.passage_max_wait)
      return true;
    Note("people still pass the doorway after the longest wait: going");
    passage_wait_over_ = true;  // and not stopping short for them on the way in
    return false;
  }

  // Off the opening's centre line by no more than this, the robot drives straight through [m].
  static constexpr double kSquareUpTolerance = 0.02;
  // Nearer the door line than this, a passage turned busy no longer stops the drive through: the
  // base takes ~0.15 m to stop from the door speed, which would leave it standing in the doorway
  // beside the passer-by (the reactive door-zone check still halts it for anyone entering the
  // zone) [m].
  static constexpr double kPassageCommitDistance = 0.65;
  // The slide from the lane's edge (after the look through, PeekPose) onto the door's axis runs
  // as slowly as the hold window leaves time for, down to the nominal speed (SlideSpeed): it
  // crosses the lane in front of the opening, whose far side the robot may not see (behind the
  // leaf), and a rest-to-rest quintic at the door speed peaks at 1.875 x 0.4 m/s, from which the
  // base needs ~0.35 m to stop (H12 seed 2093: someone stepping out from behind the leaf at
  // 2 m/s met the robot still sliding towards their way as it braked, 0.14 m off; at half the
  // speed it is still by the lane's edge when they come). Its speed when slower than the door
  // speed (nullopt: at the door speed) [m/s].
  std::optional<double> slide_speed_;
  // The slowest slide, no slower than the nominal speed, that the window leaves time for with
  // kSlowSlideSpareTime to spare; nullopt for the door speed. `slide` [m] takes `fast_time` [s]
  // at the door speed, `slow_time` at the nominal speed; `window_leaves(t)`: whether the window
  // leaves time for the pass after a slide of t seconds.
  template <class WindowLeaves>
  std::optional<double> SlideSpeed(double slide, double fast_time, double slow_time,
                                   const WindowLeaves& window_leaves) const {
    if (slow_time <= fast_time || !window_leaves(fast_time + kSlowSlideSpareTime))
      return std::nullopt;
    double t = slow_time;
    if (!window_leaves(slow_time + kSlowSlideSpareTime)) {
      // The window's end is a threshold in the slide's time: halve the bracket [fast, slow].
      double lo = fast_time, hi = slow_time;
      for (int i = 0; i < 12; ++i) {
        const double mid = 0.5 * (lo + hi);
        (window_leaves(mid + kSlowSlideSpareTime) ? lo : hi) = mid;
      }
      t = lo;
    }
    // (fast_time is no shorter than the trajectory's min_duration: SegmentDuration.)
    if (t <= fast_time + 1e-3) return std::nullopt;
    return slide / t;
  }
  // What the window must leave beyond the slide's trajectory for a slide slower than the door
  // speed [s]: the line-up ends a little after its trajectory (in-process 0.05 s; over DDS, with
  // odometry a step or two late, 0.5 s and more), and an entry reached with the window spent is
  // a failed pass and a second press (S1 across two processes: 24 s later than in-process).
  static constexpr double kSlowSlideSpareTime = 1.0;
  // Farther out than the ordinary entry distance by more than this, the pass stops there first
  // to look through (nearer, it sets off slowly enough as it is) [m].
  static constexpr double kLookThroughMinStep = 0.2;

  // The entry pose's position: on the door's axis, entry_distance_ before the door line.
  Eigen::Vector2d EntryPoint() const { return pass_.centre + pass_.n_M * entry_distance_; }

  const perception::TrackedDoor* Estimate() const { return FindTrackedDoor(belief_.world, door_); }
  bool LeafSeenNow() const {
    const auto* d = Estimate();
    return d != nullptr && ToSeconds(belief_.now - d->state.stamp) <= kDoorSeenRecentlySec;
  }
  // The leaf may still be swinging open: it hides part of the far side, and people there wait for
  // it. Out of view, it had the operator's opening time since the robot's own press (or since it
  // was last seen opening).
  bool LeafOpening() const {
    const auto* d = Estimate();
    if (d == nullptr) return false;
    const DoorVisit visit = Visit();
    if (LeafSeenNow()) return d->state.motion == perception::DoorMotion::kOpening;
    if (visit.operated_at)
      return ToSeconds(belief_.now - *visit.operated_at) < kOperatorOpeningTime;
    return d->state.motion == perception::DoorMotion::kOpening &&
           ToSeconds(belief_.now - d->state.stamp) < kOperatorOpeningTime;
  }

  // Someone on the robot's side of the door, within TaskConfig::near_waiter_radius of the
  // doorway's centre and not holding the door aside, who is for the door: standing in front of
  // the doorway (within the lane's edges, LaneEdgeLateral), or walking towards the opening
  // (within kForTheDoorRad of straight at its middle). The nearest, and whether they walk.
  // Someone standing off to the side is not waiting for the door (S2, P5: a walker who has
  // crossed stands at their goal beside the approach).
  struct ForTheDoor {
    Eigen::Vector2d p_M;
    bool walking{false};
  };
  std::optional<ForTheDoor> SomeoneForTheDoor() const {
    std::optional<ForTheDoor> nearest;
    double nearest_distance = task_.config.near_waiter_radius;
    for (const auto& entry : belief_.world.people) {
      const Eigen::Vector2d& p = entry.person.p_MP;
      const Eigen::Vector2d& v = entry.person.v_MP;
      const Eigen::Vector2d to_middle = pass_.centre - p;
      const double distance = to_middle.norm();
      if (distance >= nearest_distance || -to_middle.dot(pass_.n_M) <= 0.0 ||
          IsHoldingDoorAside(task_, entry, door_))
        continue;
      const bool walking = v.norm() >= kWalkingMps;
      if (walking ? v.dot(to_middle) < std::cos(kForTheDoorRad) * v.norm() * distance
                  : std::abs(LateralOf(p)) > LaneEdgeLateral())
        continue;
      nearest_distance = distance;
      nearest = ForTheDoor{p, walking};
    }
    return nearest;
  }
  // [rad] Walking within this of straight at the opening's middle is walking to the door.
  static constexpr double kForTheDoorRad = M_PI / 4;
  // Watching someone for the door (kWatchingWaiter), the robot steps along
  // the door line away from the lane, once, far enough that their straight way in would pass it
  // comfort_distance off, by at most kMaxStandClearM: a robot at the button's standoff is
  // 0.6-0.7 m from their way (P4). Their way in runs from where they stand to the opening's
  // side nearer the robot, a body's radius in from the jamb: walkers do not keep to the middle
  // (P4 seed 2073 passed 0.13 m on the robot's side of it).
  void StandClearOfTheWayIn(const Eigen::Vector2d& waiter) {
    if (stood_clear_ || task_.motion->base_moving()) return;
    stood_clear_ = true;
    const Eigen::Vector2d at = belief_.X_MB.translation();
    const Eigen::Vector2d away =
        Eigen::Vector2d(-pass_.n_M.y(), pass_.n_M.x()) * (LateralOf(at) > 0.0 ? 1.0 : -1.0);
    const double comfortable =
        task_.config.footprint_radius + task_.config.person_radius + task_.config.comfort_distance;
    const double in_from_middle =
        std::max(task_.map->FindDoor(door_)->width() / 2 - task_.config.person_radius, 0.0);
    const Eigen::Vector2d way_in = pass_.centre + away * in_from_middle;
    const auto room = [&](const Eigen::Vector2d& q) {
      return (ClosestPointOnSegment(q, waiter, way_in) - q).norm();
    };
    if (room(at) >= comfortable) return;
    // The nearest shift that leaves them comfortable room, else the one that leaves the most; no
    // step that gains less than kMakeWayMinGainM (someone walking up from the far side of the
    // robot has their way in across the step: P1's walker from behind the button).
    const perception::Costmap2D* costmap = belief_.world.costmap;
    std::optional<Pose2> spot;
    double best_room = room(at) + kMakeWayMinGainM;
    constexpr double kStepM = 0.05;
    for (double shift = kStepM; shift <= kMaxStandClearM + 1e-9; shift += kStepM) {
      const Eigen::Vector2d q = at + away * shift;
      const Pose2 candidate{q.x(), q.y(), belief_.X_MB.yaw};
      if ((costmap != nullptr &&
           costmap->IsNearMappedObstacle(
               q, task_.config.footprint_radius + PeopleRoom::kSpotWallClearanceM)) ||
          !task_.planner->IsPathValid({belief_.X_MB, candidate}))
        break;
      if (room(q) < best_room) continue;
      best_room = room(q);
      spot = candidate;
      if (best_room >= comfortable) break;
    }
    if (!spot) return;
    StepAsideTo(task_, *spot);
    Note(StrCat("standing clear of their way in: to (", PoseText(*spot), ")"));
  }
  // [m] The farthest StandClearOfTheWayIn steps.
  static constexpr double kMaxStandClearM = 0.6;

  // Starts watching someone for the door (phase kWatchingWaiter, SomeoneForTheDoor) if there is
  // one: someone walking up, at once (making way for them ends the window's chance as much as
  // the watch); someone standing, if the hold window leaves time for the watch, the direct
  // line-up and the pass after it (the look through from the lane's edge comes after only if the
  // window still leaves time for it).
  bool WatchSomeoneForTheDoor() {
    if (task_.config.near_waiter_time <= 0.0) return false;
    const std::optional<ForTheDoor> someone = SomeoneForTheDoor();
    if (!someone) return false;
    const DoorVisit visit = Visit();
    const double line_up = DoorPathDuration(task_, LineUpPath(task_, door_, pass_, belief_.X_MB));
    if (!someone->walking &&
        !DoorWindowLeavesTime(task_, door_, &visit, task_.config.near_waiter_time + line_up))
      return false;
    Note(StrCat("someone ", someone->walking ? "walks up to" : "stands by", " the door at (",
                PoseText({someone->p_M.x(), someone->p_M.y(), 0.0}),
                "): watching whether they go through first"));
    phase_ = Phase::kWatchingWaiter;
    waiting_since_ = belief_.now;
    stood_clear_ = false;
    return true;
  }

  // Starts making way (phase kGivingWay) if someone is coming (TaskConfig::give_way).
  // Whoever walks up may be going through the door (ThroughDoorWays).
  bool GiveWayIfComing() {
    if (!task_.config.give_way ||
        !give_way_.Begin(task_, std::nullopt, [this](const std::string& t) { Note(t); },
                         {.through_door = door_}))
      return false;
    phase_ = Phase::kGivingWay;
    return true;
  }

  // kGivingWay: making way for people walking up before the line-up (WayGiver);
  // kWatchingWaiter: watching someone for the door before it (WatchSomeoneForTheDoor).
  enum class Phase { kWatchingWaiter, kGivingWay, kToPeek, kPeeking, kToEntry, kWaiting, kThrough };
  WayGiver give_way_;
  std::string door_;
  DoorPass pass_;
  double entry_distance_{0.0};
  double yaw_{0.0};
  Phase phase_{Phase::kWaiting};
  Time waiting_since_{};
  bool passage_wait_over_{false};    // waited the longest for them: going regardless
  bool aside_for_passage_{false};    // stepped back to the lane's edge to wait for them
  bool stood_clear_{false};          // StandClearOfTheWayIn has had its one go
  std::optional<double> peek_side_;  // the side of the lane it looked through from (+1/-1)
};

}  // namespace

void RegisterTraverseDoor(bt::BehaviorTreeFactory& factory, const TaskServices* services) {
  Register<TraverseDoor>(factory, "TraverseDoor", services);
}

}  // namespace egress::behavior::detail
