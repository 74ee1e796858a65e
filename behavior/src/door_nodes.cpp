#include "task_node_support.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "egress/perception/door_estimation.h"

namespace egress::behavior::detail {
namespace {

// Other standoffs when the whole-body one is blocked: (shift along the wall [m], turn [rad]),
// nearest first. Every one is turned: shifted along the wall square to it, the arm reaches the
// button sideways, at a slant where at all (room A seed 6: from 20 cm along, the hand touched
// the wall beside door_a's button). Until stop 108 the list began with such shifts (5, 10 and
// 20 cm either way); stop 108's study (504 trials: 0 obstacle contacts, 16 of the 21 trials it
// changed quicker) ran without them.
constexpr std::pair<double, double> kStandoffSeeds[] = {
    {0.0, 0.3},   {0.0, -0.3},  {-0.1, 0.3}, {0.1, -0.3}, {-0.1, -0.3}, {0.1, 0.3},
    {-0.15, 0.6}, {0.15, -0.6}, {-0.2, 0.6}, {0.2, -0.6}, {-0.25, 0.9}, {0.25, -0.9}};

// With those, the base stands this far out from the wall (in: negative) [m], first square on.
constexpr double kStandoffOutOffsets[] = {0.0, 0.05, -0.05, 0.1};

// A standoff relative to the whole-body one: along the wall [m], turned [rad], out from it [m].
struct StandoffOffset {
  double shift{0.0};
  double turn{0.0};
  double out{0.0};
  bool operator==(const StandoffOffset&) const = default;
};

// Where a standoff from which the arm holds the approach axis is looked for: each seed, then
// turned the other way, each at kStandoffOutOffsets, nearest seed first; each once (the seeds
// hold many of each other's mirror images, and a standoff that failed fails again).
const std::vector<StandoffOffset>& SquareOnStandoffs() {
  static const std::vector<StandoffOffset> offsets = [] {
    std::vector<StandoffOffset> all;
    for (const auto& [shift, turn] : kStandoffSeeds) {
      for (const double signed_turn : {turn, -turn}) {
        for (const double out : kStandoffOutOffsets) {
          const StandoffOffset o{shift, signed_turn, out};
          if (std::find(all.begin(), all.end(), o) == all.end()) all.push_back(o);
        }
      }
    }
    return all;
  }();
  return offsets;
}

// An actuator the camera sees farther than this from where the map has it is another one [m].
constexpr double kActuatorMatchDistance = 0.15;

// Points along the press stroke the arm is solved for (pre-press to press): the fingertip
// stays on the button's normal instead of a joint-space curve.
constexpr int kPressStrokeKnots = 4;

class ButtonType final : public TaskNode<bt::SyncActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("door", "door id"),
            OutputPort<std::string>(
                "type", "push_button or proximity_plate: sets the end-effector travel")};
  }
  NodeStatus Tick() override {
    const MapActuator* actuator = task_.map->FindActuatorOf(Door(), belief_.X_MB.translation());
    if (actuator == nullptr) {
      Note("door has no actuator on this side");
      return NodeStatus::kFailure;
    }
    this->SetOutput("type", std::string(actuator->type == planning::ButtonType::kPushButton
                                            ? "push_button"
                                            : "proximity_plate"));
    return NodeStatus::kSuccess;
  }
};

std::pair<std::string, bt::PortInfo> HeadGazePort();

class ApproachButton final : public TaskNode<bt::StatefulActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("door", "door whose actuator to stand off (base facing it)"),
            VisitPort(bt::PortDirection::kInOut), HeadGazePort(),
            InputPort<bool>("door_speed", false,
                            "drive to the standoff at the door speed (TrajectoryConfig::"
                            "door_speed): a resident already waits at the door, or the escort, "
                            "behind the group, goes to open a door nobody is near")};
  }
  NodeStatus OnStart() override {
    DoorVisit visit = Visit();
    const std::string door = visit.door;
    const MapActuator* actuator = task_.map->FindActuatorOf(door, belief_.X_MB.translation());
    if (actuator == nullptr) {
      Note("door has no actuator on this side");
      return NodeStatus::kFailure;
    }
    CalcApproachPass(task_, visit);  // remember which side is "before" the door
    ButtonPlan plan;
    plan.actuator = actuator->id;
    plan.type = actuator->type;
    plan.targets = planning::MakeButtonTargets(actuator->p_M, actuator->n_M, actuator->type,
                                               task_.config.buttons);
    // Whole-body IK from the standoff with the arm tucked picks where the base stands.
    planning::IkConfig ik = task_.config.ik;
    ik.fingertip = actuator->type == planning::ButtonType::kPushButton;
    ik.use_base = true;
    // Where the base stands: whole-body IK from the nominal standoff with the arm tucked. If
    // that base pose is in collision (an actuator in a corner, beside a jamb or a side wall),
    // the base stands shifted along the wall and turned, nearest first, the arm alone reaching
    // (whole-body IK from a shifted seed slides the base back to the same spot).
    WholeBodyVector q0 = WholeBodyVector::Zero();
    q0[kBaseX] = plan.targets.X_MB_standoff.x;
    q0[kBaseY] = plan.targets.X_MB_standoff.y;
    q0[kBaseYaw] = plan.targets.X_MB_standoff.yaw;
    q0 = WithArm(q0, TuckedArm(*task_.model));
    const planning::IkResult solution =
        planning::DlsIkSolver(*task_.model, ik).Solve(plan.targets.approach, q0);
    plan.X_MB_standoff = solution.converged
                             ? Pose2{solution.q[kBaseX], solution.q[kBaseY], solution.q[kBaseYaw]}
                             : plan.targets.X_MB_standoff;
    plan.approach_arm = solution.converged ? ArmOf(solution.q) : TuckedArm(*task_.model);
    if (!task_.planner->IsValid(plan.X_MB_standoff)) {
      const Eigen::Vector2d n = actuator->n_M.head<2>().normalized();
      const Eigen::Vector2d t(-n.y(), n.x());
      // First a standoff from which the arm holds the button's approach axis; then, failing
      // that, the seeds with the arm reaching at a slant (room A seed 6: from 20 cm along the
      // wall, square to it, the arm reached sideways to door_a's button and the hand touched the
      // wall beside it).
      const auto stand_at = [&](const StandoffOffset& o, bool square) {
        const Eigen::Vector2d p = plan.X_MB_standoff.translation() + t * o.shift + n * o.out;
        const Pose2 base{p.x(), p.y(), plan.X_MB_standoff.yaw + o.turn};
        if (!task_.planner->IsValid(base)) return false;
        const auto arm = SolveArm(task_, base, plan.targets.approach, plan.approach_arm,
                                  ik.fingertip, 0.0, /*allow_slant=*/!square);
        if (!arm) return false;
        Note(StrCat("the standoff is blocked: standing ", std::round(o.shift * 100),
                    " cm along the wall, ", std::round(o.out * 100), " cm out, turned ",
                    std::round(o.turn * 180 / M_PI), " deg",
                    square ? "" : ", pressing at a slant"));
        plan.X_MB_standoff = base;
        plan.approach_arm = *arm;
        return true;
      };
      const auto& square_on = SquareOnStandoffs();
      bool found = std::any_of(square_on.begin(), square_on.end(),
                               [&](const StandoffOffset& o) { return stand_at(o, true); });
      for (const auto& [shift, turn] : kStandoffSeeds) {
        if (found) break;
        found = stand_at({shift, turn, 0.0}, false);
      }
      if (!found) {
        if (LookAgainAt(visit, plan.X_MB_standoff)) return NodeStatus::kRunning;
        Note(StrCat("no free standoff from which the arm reaches ", actuator->id));
        return NodeStatus::kFailure;
      }
    }
    if (!solution.converged) Note("whole-body IK did not converge; using the nominal standoff");
    visit.button_plan = plan;
    Remember(visit);
    return StartPath(
        task_, plan.X_MB_standoff, StrCat("the ", actuator->id, " standoff"),
        [this](const std::string& s) { Note(s); }, Input<bool>("door_speed"));
  }
  NodeStatus OnRunning() override {
    const auto note = [this](const std::string& s) { Note(s); };
    if (Input<bool>("head_gaze")) WatchBehind();
    if (looking_until_) {
      if (const NodeStatus s = BaseMotionStatus(task_, note); s != NodeStatus::kSuccess) return s;
      if (belief_.now < *looking_until_) return NodeStatus::kRunning;
      looking_until_.reset();
      return OnStart();  // planned again on what it sees now
    }
    return DriveStatus(task_, note);
  }
  void OnHalted() override {
    looking_until_.reset();
    task_.motion->StopBase();
  }

 private:
  // The standoff found blocked may be blocked only by what the costmap and the 3D map last saw
  // there: people who have since walked on, out of the laser's and the camera's view (office
  // escort seed 54: residents marked round door_a's button as they crowded through; the robot,
  // stepped back out of their way with the button behind it, found no free standoff for 180 s
  // and two residents waited at the next door to the time limit). It turns to face the
  // standoff, the head on it, and plans again after kLookDwellSec; at most once per
  // kLookAgainSec for a door.
  bool LookAgainAt(DoorVisit& visit, const Pose2& standoff) {
    if (visit.standoff_looked_at &&
        ToSeconds(belief_.now - *visit.standoff_looked_at) < kLookAgainSec)
      return false;
    visit.standoff_looked_at = belief_.now;
    Remember(visit);
    const Eigen::Vector2d d = standoff.translation() - belief_.X_MB.translation();
    const double yaw = d.norm() > kFacingMinM ? std::atan2(d.y(), d.x()) : belief_.X_MB.yaw;
    task_.motion->FollowPath({belief_.X_MB, {belief_.X_MB.x, belief_.X_MB.y, yaw}}, {false},
                             task_.motion->arm_target(), belief_.now);
    looking_until_ = belief_.now + SecondsToDuration(kLookDwellSec);
    if (task_.gaze) {
      task_.gaze->RequestLook({standoff.x, standoff.y, belief_.X_MC.translation().z()},
                              *looking_until_ + SecondsToDuration(kLookTurnAllowanceSec));
    }
    Note("the standoff looks blocked: turning to look at it again");
    return true;
  }

  static constexpr double kLookAgainSec = 10.0;  ///< [s]
  static constexpr double kLookDwellSec = 1.0;   ///< [s] from the turn's start, at least
  /// [s] The head's request outlasts the dwell by this: the turn may take longer.
  static constexpr double kLookTurnAllowanceSec = 3.0;
  static constexpr double kFacingMinM = 0.05;  ///< nearer, the base keeps its heading [m]
  std::optional<Time> looking_until_;
};

// The base pose relative to the actuator's wall, corrected by the laser: the distance to the
// wall straight ahead, measured, against the distance the believed pose predicts. Pressing a
// 4 mm button stroke needs the wall's distance to a few millimetres; the localizer's estimate
// is good to a few centimetres. Along the wall nothing changes (the button is 10 cm wide).
Pose2 WallAlignedPose(const TaskServices& task, const MapActuator& actuator,
                      const std::function<void(const std::string&)>& note) {
  if (!task.belief->scan) return task.belief->X_MB;
  const Eigen::Vector2d n = actuator.n_M.head<2>().normalized();
  const Eigen::Vector2d t(-n.y(), n.x());
  const Eigen::Vector2d p_MWall = actuator.p_M.head<2>() - n * actuator.protrusion;
  const Pose2 X_ML = task.belief->X_MB * task.belief->X_BL;
  std::vector<double> distances;
  const LaserScan& scan = *task.belief->scan;
  const std::vector<Eigen::Vector2d>& u_L = perception::BeamDirections(scan);
  const Eigen::Matrix2d R_ML = X_ML.rotation();
  for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
    const double r = scan.ranges[i];
    if (!std::isfinite(r) || r < scan.range_min || r > 2.0) continue;
    const Eigen::Vector2d p_M = R_ML * (r * u_L[i]) + X_ML.translation();
    // Near the wall plane, within 0.4 m of the actuator along the wall.
    if (std::abs((p_M - p_MWall).dot(n)) > 0.15 || std::abs((p_M - p_MWall).dot(t)) > 0.4) continue;
    distances.push_back((X_ML.translation() - p_M).dot(n));
  }
  Pose2 corrected = task.belief->X_MB;
  if (distances.size() >= 5) {
    auto middle = distances.begin() + std::ptrdiff_t(distances.size() / 2);
    std::nth_element(distances.begin(), middle, distances.end());
    const double expected = (X_ML.translation() - p_MWall).dot(n);
    const double error = *middle - expected;
    corrected.x += n.x() * error;
    corrected.y += n.y() * error;
    note(StrCat("wall ", std::round(*middle * 1000) / 1000, " m ahead by laser, ",
                std::round(error * 1000), " mm off the estimate"));
  }
  // Along the wall the laser has nothing to measure (a long wall looks the same everywhere:
  // after 15 m of corridor the estimate was 5 cm off there, half the button). The head camera's
  // detection of the actuator itself has: placed in M from the believed pose, it is off its
  // mapped position by that pose's own error.
  const perception::TrackedObject* seen = nullptr;
  double nearest = kActuatorMatchDistance;
  for (const auto& object : task.belief->world.buttons) {
    const double d = (object.p_MO.head<2>() - actuator.p_M.head<2>()).norm();
    if (d < nearest) {
      nearest = d;
      seen = &object;
    }
  }
  if (seen != nullptr) {
    const double along = (seen->p_MO.head<2>() - actuator.p_M.head<2>()).dot(t);
    corrected.x -= t.x() * along;
    corrected.y -= t.y() * along;
    note(StrCat("actuator seen ", std::round(along * 1000), " mm along the wall from the map"));
  }
  return corrected;
}

// The actuator nodes' `head_gaze` port: whether they turn the head (HeadGaze::WatchBehind while
// at the actuator, HeadGaze::ExpectOpening while operating it).
std::pair<std::string, bt::PortInfo> HeadGazePort() {
  return InputPort<bool>("head_gaze", true,
                         "at the actuator the head watches the laser's blind sector behind the "
                         "robot, and looks through the door while the arm opens it; false: the "
                         "tree looks by itself (EvacuationEscort's hold)");
}

// The actuator nodes' `to_pass` port (ActuatorAction::PressWaitsUntil).
std::pair<std::string, bt::PortInfo> ToPassPort() {
  return InputPort<bool>("to_pass", true,
                         "the robot operates the door to pass it itself: a press that would only "
                         "restart a hold window too short to line up and pass waits for the door "
                         "to close; false to hold it open for others (EvacuationEscort)");
}

// Presses (push button) or waves (proximity plate): one arm motion, RUNNING until it ends.
class ActuatorAction : public TaskNode<bt::StatefulActionNode> {
 public:
  ActuatorAction(const std::string& name, NodeConfig config, const TaskServices* services,
                 planning::ButtonType type)
      : TaskNode(name, std::move(config), services), type_(type) {}
  NodeStatus OnStart() override {
    const DoorVisit visit = Visit();
    if (!visit.button_plan || visit.button_plan->type != type_) {
      Note("no standoff for this actuator: ApproachButton must run first");
      return NodeStatus::kFailure;
    }
    plan_ = *visit.button_plan;
    head_gaze_ = Input<bool>("head_gaze");
    if (head_gaze_) WatchBehind();
    alignments_ = 0;
    arm_started_ = false;
    waiting_out_ = false;
    gate_.Reset();
    return AlignOrOperate();
  }
  NodeStatus OnRunning() override {
    if (head_gaze_) WatchBehind();
    if (!arm_started_) {
      if (task_.motion->base_failed()) {
        Note("could not square up to the actuator: " + task_.motion->base_failure());
        return NodeStatus::kFailure;
      }
      if (task_.motion->base_moving()) return NodeStatus::kRunning;
      return AlignOrOperate();
    }
    // The arm is on its way to open the door: the head turns to look through it.
    if (task_.gaze != nullptr && head_gaze_)
      task_.gaze->ExpectOpening(Door(), belief_.now + SecondsToDuration(kLookRequestSec));
    // Seen shut after the arm set off (a closing leaf that closed during the stroke): this press
    // opens the door afresh, it restarts no window (H1 seed 2006: timed as a restart, the window
    // ended 0.8 s before the real one, and the robot waited at the open door until it shut).
    if (const perception::TrackedDoor* door = FindTrackedDoor(belief_.world, Door());
        door != nullptr && door->state.observed && door->state.stamp >= arm_set_off_ &&
        door->state.motion == perception::DoorMotion::kClosed) {
      shut_since_set_off_ = true;
    }
    if (const NodeStatus arm = ArmMotionStatus(task_, [this](const std::string& t) { Note(t); });
        arm != NodeStatus::kSuccess) {
      return arm;
    }
    // A press (or wave) restarts the operator's hold window of an open door — from the moment
    // the hand reached the actuator, not from now: the stroke and the way back take another
    // second or more, and a window timed from here would end that much before the robot thinks.
    // Unless the door was last seen closed when the arm set off, it is taken to have been open:
    // from the actuator the leaf is often out of view, and a restarted window is the shorter one
    // (a door held open when the estimate last read it opening closed 10 s after a second press,
    // not 14).
    if (DoorVisit visit = Visit();
        !shut_since_set_off_ &&
        (belief_.door_open_since.count(Door()) > 0 || !closed_before_press_) && visit.operated_at) {
      visit.window_restarted_at = visit.operated_at;
      Remember(visit);
    }
    return NodeStatus::kSuccess;
  }
  void OnHalted() override { task_.motion->StopBase(); }  // the arm is tucked by whoever runs next

 private:
  RelocalizeGate gate_;
  bool head_gaze_{true};                           // the `head_gaze` port, read at the start
  static constexpr double kAlignTolerance = 0.01;  // [m] base off its standoff
  static constexpr int kMaxAlignments = 2;

  // The base squares up to the planned standoff (by the laser's wall distance) first, then the
  // arm presses or waves.
  NodeStatus AlignOrOperate() {
    if (OwnOpeningLeavesTimeToPass()) {
      Note(
          "the door is opening from the robot's own press, and its window leaves time to line up "
          "and pass: not pressing again");
      return NodeStatus::kSuccess;
    }
    if (const auto until = PressWaitsUntil(); until && belief_.now < *until) {
      if (!waiting_out_) {
        Note(
            StrCat("the door may still stand open from the last press, and a press now would "
                   "restart a hold window too short to line up and pass: waiting ",
                   std::round(ToSeconds(*until - belief_.now) * 10) / 10, " s for it to close"));
      }
      waiting_out_ = true;
      return NodeStatus::kRunning;
    }
    if (gate_.Check(task_, "operating the actuator", EventNoter()) == NodeStatus::kRunning)
      return NodeStatus::kRunning;
    const ButtonPlan& plan = plan_;
    const MapActuator& actuator = *task_.map->FindActuator(plan.actuator);
    const Pose2 X_MB = WallAlignedPose(task_, actuator, [this](const std::string& t) { Note(t); });
    // Off the standoff, in M, by the corrected pose: along the wall's normal (the laser) and
    // along the wall (the camera's sighting of the actuator).
    const Eigen::Vector2d off = X_MB.translation() - plan.X_MB_standoff.translation();
    if (off.norm() > kAlignTolerance && alignments_ < kMaxAlignments) {
      ++alignments_;
      const Pose2 target{belief_.X_MB.x - off.x(), belief_.X_MB.y - off.y(),
                         plan.X_MB_standoff.yaw};
      task_.motion->FollowPath({belief_.X_MB, target}, {false}, task_.motion->arm_target(),
                               belief_.now);
      Note(StrCat("squaring up: ", std::round(off.norm() * 1000), " mm off the standoff"));
      return NodeStatus::kRunning;
    }
    return Operate(plan, X_MB);
  }

  NodeStatus Operate(const ButtonPlan& plan, const Pose2& X_MB) {
    const bool push = type_ == planning::ButtonType::kPushButton;
    const TaskConfig& c = task_.config;
    // A proximity plate senses a hand coming into its field: a wave from an arm left out (at the
    // plate since the last wave, while the robot waited out a window) first takes the hand away
    // (office seed 1: a wave from the hand held at door_b's plate did not open it, and the robot
    // drove at the shut door).
    const double withdraw = !push && !ArmAt(task_.motion->arm_target(), TuckedArm(*task_.model))
                                ? c.arm_tuck_time
                                : 0.0;
    // The hand reaches the actuator's approach pose then; the press or wave follows.
    DoorVisit visit = Visit();
    visit.operated_at = belief_.now + SecondsToDuration(withdraw + c.press_reach_time);
    visit.window_restarted_at.reset();  // an earlier press's restart says nothing of this one
    Remember(visit);
    const perception::TrackedDoor* door = FindTrackedDoor(belief_.world, Door());
    closed_before_press_ = waiting_out_ || door == nullptr || !door->state.observed ||
                           door->state.motion == perception::DoorMotion::kClosed;
    arm_set_off_ = belief_.now;
    shut_since_set_off_ = false;
    const auto approach = SolveArm(task_, X_MB, plan.targets.approach, plan.approach_arm, push);
    if (!approach) {
      Note("the actuator is out of the arm's reach from here");
      return NodeStatus::kFailure;
    }
    if (push) {
      planning::IkTarget press = plan.targets.press;
      press.approach_M.reset();  // the arm alone cannot also hold the approach axis exactly
      const auto stroke = SolveArmLine(task_, X_MB, plan.targets.approach, press, *approach, true,
                                       kPressStrokeKnots);
      if (!stroke) {
        Note("the press point is out of the arm's reach from here");
        return NodeStatus::kFailure;
      }
      // In along the button's normal, out the same way.
      std::vector<std::pair<double, ArmPose>> knots{{c.press_reach_time, *approach}};
      const double dt = c.press_time / kPressStrokeKnots;
      for (int i = 0; i < kPressStrokeKnots; ++i)
        knots.emplace_back(c.press_reach_time + (i + 1) * dt, (*stroke)[std::size_t(i)]);
      for (int i = kPressStrokeKnots - 2; i >= -1; --i)
        knots.emplace_back(knots.back().first + dt, i >= 0 ? (*stroke)[std::size_t(i)] : *approach);
      task_.motion->MoveArm(knots, belief_.now);
      Note("pressing the push button");
    } else {
      std::vector<std::pair<double, ArmPose>> knots;
      if (withdraw > 0.0) knots.emplace_back(withdraw, TuckedArm(*task_.model));
      knots.emplace_back(withdraw + c.press_reach_time, *approach);
      knots.emplace_back(withdraw + c.press_reach_time + c.wave_hold_time, *approach);
      task_.motion->MoveArm(knots, belief_.now);
      Note("waving at the proximity plate");
    }
    arm_started_ = true;
    return NodeStatus::kRunning;
  }

  // A press restarts an open door's hold window (it ends a window after the press), where a press
  // on a shut door has the opening time as well. When the opening of the robot's own last press
  // may not be over (the door not seen shut since) and a restarted window would not leave time to
  // finish the stroke, line up and drive clear of the leaf, the press waits until that opening
  // has surely ended; nullopt: no need to wait.
  std::optional<Time> PressWaitsUntil() const {
    const DoorVisit visit = Visit();
    if (!visit.operated_at || !Input<bool>("to_pass")) return std::nullopt;
    const perception::TrackedDoor* door = FindTrackedDoor(belief_.world, Door());
    if (door != nullptr && door->state.motion == perception::DoorMotion::kClosed &&
        door->state.stamp > *visit.operated_at) {
      return std::nullopt;
    }
    const TaskConfig& c = task_.config;
    const DoorPass pass = CalcKnownPass(task_, Door(), &visit);
    const double after_hand =
        type_ == planning::ButtonType::kPushButton ? 2 * c.press_time : c.wave_hold_time;
    const double needed = after_hand + LineUpTime(visit) +
                          (EntryDistance(task_, Door(), pass) + ExitDistance(task_, Door())) /
                              task_.motion->trajectory_config().door_speed;
    if (needed <= c.door_hold_window) return std::nullopt;
    const Time window_from = visit.window_restarted_at
                                 ? *visit.window_restarted_at
                                 : *visit.operated_at + SecondsToDuration(kOperatorOpeningTime);
    return window_from + SecondsToDuration(c.door_hold_window + kOperatorClosingTime);
  }

  // From the standoff to the entry pose on the door's axis (TraverseDoor's way there, turns
  // included), and the stop there with a margin [s]. The straight line's length alone, without
  // the way out round a leaf opening towards the standoff and the quarter turn, read 3.5 s for
  // the 6.5 s it took: the door then closed before the robot was through (two wards seed 7).
  double LineUpTime(const DoorVisit& visit) const {
    const DoorPass pass = CalcKnownPass(task_, Door(), &visit);
    constexpr double kSettleSec = 1.0;
    return DoorPathDuration(task_, LineUpPath(task_, Door(), pass, plan_.X_MB_standoff)) +
           kSettleSec;
  }

  // The robot operated this door moments ago (a hold's last press, before the traversal), the
  // door has been seen opening or open since, and that opening's window still leaves time to line
  // up and drive clear: a press now would only restart the window (or, too short, wait it out).
  bool OwnOpeningLeavesTimeToPass() const {
    const DoorVisit visit = Visit();
    if (!visit.operated_at || !Input<bool>("to_pass") ||
        ToSeconds(belief_.now - *visit.operated_at) >
            kOperatorOpeningTime + task_.config.door_hold_window) {
      return false;
    }
    const perception::TrackedDoor* door = FindTrackedDoor(belief_.world, Door());
    if (door == nullptr || !door->state.observed || door->state.stamp <= *visit.operated_at)
      return false;
    const auto motion = door->state.motion;
    if (motion != perception::DoorMotion::kOpening && motion != perception::DoorMotion::kOpen &&
        motion != perception::DoorMotion::kHeldOpen) {
      return false;
    }
    return DoorWindowLeavesTime(task_, Door(), &visit, LineUpTime(visit));
  }

  planning::ButtonType type_;
  ButtonPlan plan_;  // from the visit, at the start
  int alignments_{0};
  bool arm_started_{false};
  bool closed_before_press_{true};  // the door read closed when the arm set off (Operate)
  Time arm_set_off_{};              // when the arm set off to press or wave (Operate)
  bool shut_since_set_off_{false};  // the door read closed (a fresh estimate) since then
  bool waiting_out_{false};         // waited for the last press's opening to end (PressWaitsUntil)
};

class PressButton final : public ActuatorAction {
 public:
  PressButton(const std::string& name, NodeConfig config, const TaskServices* services)
      : ActuatorAction(name, std::move(config), services, planning::ButtonType::kPushButton) {}
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>(
                "door", "door whose push button to press (fingertip past the face by the stroke)"),
            ToPassPort(), HeadGazePort(), VisitPort(bt::PortDirection::kInOut)};
  }
};

class WaveAtPlate final : public ActuatorAction {
 public:
  WaveAtPlate(const std::string& name, NodeConfig config, const TaskServices* services)
      : ActuatorAction(name, std::move(config), services, planning::ButtonType::kProximityPlate) {}
  static PortsList ProvidedPorts() {
    return {
        InputPort<std::string>(
            "door", "door whose proximity plate to wave at (palm within its range, no contact)"),
        ToPassPort(), HeadGazePort(), VisitPort(bt::PortDirection::kInOut)};
  }
};

}  // namespace

void RegisterDoorNodes(bt::BehaviorTreeFactory& factory, const TaskServices* services) {
  Register<ButtonType>(factory, "ButtonType", services);
  Register<ApproachButton>(factory, "ApproachButton", services);
  Register<PressButton>(factory, "PressButton", services);
  Register<WaveAtPlate>(factory, "WaveAtPlate", services);
  RegisterTraverseDoor(factory, services);
}

}  // namespace egress::behavior::detail
