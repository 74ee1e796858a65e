#include "egress/behavior/task_nodes.h"

#include <cmath>
#include <sstream>

#include "egress/hsr_interface/error.h"
#include "egress/perception/person_tracker.h"

namespace egress::behavior {

using bt::InputPort;
using bt::NodeConfig;
using bt::NodeStatus;
using bt::OutputPort;
using bt::PortsList;

void TaskConfig::Validate() const {
  ThrowUnless(footprint_radius > 0 && door_entry_distance > 0 && door_exit_distance > 0 &&
                  zone_depth > 0 && person_radius >= 0,
              "TaskConfig: distances must be positive");
  ThrowUnless(arm_tuck_time > 0 && press_reach_time > 0 && press_time > 0 && wave_hold_time >= 0,
              "TaskConfig: motion times must be positive");
  ik.Validate();
}

Pose2 ParsePose2(std::string_view text) {
  std::vector<double> values;
  std::stringstream in{std::string(text)};
  std::string part;
  while (std::getline(in, part, ';')) {
    try {
      std::size_t used = 0;
      values.push_back(std::stod(part, &used));
      if (part.find_first_not_of(" \t", used) != std::string::npos) throw std::invalid_argument("");
    } catch (const std::exception&) {
      throw InvalidArgument(StrCat("pose '", text, "': '", part, "' is not a number"));
    }
  }
  ThrowUnless(values.size() == 2 || values.size() == 3, "pose '", text,
              "': expected x;y;yaw (or x;y)");
  const Pose2 X{values[0], values[1], values.size() == 3 ? values[2] : 0.0};
  ThrowUnless(X.IsFinite(), "pose '", text, "': must be finite");
  return X;
}

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

namespace {

constexpr double kArmTolerance = 0.02;  // [rad or m] arm counts as at a pose

bool ArmAt(const ArmPose& a, const ArmPose& b) {
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (std::abs(a[i] - b[i]) > kArmTolerance) return false;
  }
  return true;
}

std::string PoseText(const Pose2& X) {
  return StrCat(std::round(X.x * 100) / 100, ", ", std::round(X.y * 100) / 100);
}

// Base for the nodes: access to the context and typed inputs that fail the node loudly.
template <typename Base>
class TaskNode : public Base {
 public:
  TaskNode(const std::string& name, NodeConfig config, TaskContext* context)
      : Base(name, std::move(config)), ctx_(*context) {}

 protected:
  template <typename T>
  T Input(std::string_view port) const {
    auto value = this->template GetInput<T>(port);
    if (!value) throw InvalidArgument(value.error());
    return *value;
  }
  std::string Door() const { return Input<std::string>("door"); }
  void Note(const std::string& text) const {
    ctx_.Note(StrCat(this->name().empty() ? this->registration_id() : this->name(), ": ", text));
  }
  TaskContext& ctx_;
};

// Starts a base motion along a planned path; RUNNING until it ends.
// Plans from the robot to `goal` on the costmap and starts following the path; `door_speed`
// runs every segment at the door speed (a door approach inside the hold window).
NodeStatus StartPath(TaskContext& ctx, const Pose2& goal, const std::string& what,
                     const std::function<void(const std::string&)>& note, bool door_speed = false) {
  planning::PlanResult plan = ctx.planner->Plan(ctx.X_MB, goal);
  if (plan.status == planning::PlanStatus::kStartInCollision) {
    // The robot stands where the costmap says it cannot (inflation around a leaf, a person seen
    // close by, an obstacle it brushed): step to the nearest free pose — never across an
    // obstacle cell — preferring the goal's direction, and plan from there.
    const Eigen::Vector2d towards = (goal.translation() - ctx.X_MB.translation()).normalized();
    const double heading = std::atan2(towards.y(), towards.x());
    const perception::Costmap2D& costmap = *ctx.world.costmap;
    bool escaped = false;
    for (double step = 0.05; step <= 0.6 && !escaped; step += 0.05) {
      for (int k = 0; k < 16 && !escaped; ++k) {
        // 0, +22.5°, -22.5°, +45°, ... around the goal's direction.
        const double a = heading + (k % 2 == 0 ? 1 : -1) * ((k + 1) / 2) * M_PI / 8;
        const Eigen::Vector2d d(std::cos(a), std::sin(a));
        const Eigen::Vector2d p = ctx.X_MB.translation() + d * step;
        const Pose2 escape{p.x(), p.y(), ctx.X_MB.yaw};
        if (!ctx.planner->IsValid(escape)) continue;
        bool crosses = false;
        for (double s = 0.02; s < step && !crosses; s += 0.02)
          crosses = costmap.CostAt(ctx.X_MB.translation() + d * s) >= perception::kLethalCost;
        if (crosses) continue;
        planning::PlanResult rest = ctx.planner->Plan(escape, goal);
        if (!rest.ok()) continue;
        rest.path.insert(rest.path.begin(), ctx.X_MB);
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
  const std::vector<bool> through(plan.path.size() > 0 ? plan.path.size() - 1 : 0, door_speed);
  if (plan.path.size() < 2 ||
      (plan.path.back().translation() - ctx.X_MB.translation()).norm() < 0.01) {
    return NodeStatus::kSuccess;  // already there
  }
  // The base is holonomic: turn from the start yaw to the goal yaw evenly along the path
  // rather than through the planner's intermediate headings.
  std::vector<Pose2> path = plan.path;
  path.front().yaw = ctx.X_MB.yaw;
  const double turn = std::remainder(goal.yaw - ctx.X_MB.yaw, 2 * M_PI);
  double travelled = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i) {
    travelled += (path[i].translation() - path[i - 1].translation()).norm();
    const double fraction = plan.length > 0 ? std::min(1.0, travelled / plan.length) : 1.0;
    path[i].yaw = ctx.X_MB.yaw + turn * fraction;
  }
  ctx.motion->FollowPath(path, through, ctx.motion->arm_target(), ctx.now);
  note(StrCat("driving to ", what, " (", PoseText(goal), ", ", std::round(plan.length * 100) / 100,
              " m)"));
  return NodeStatus::kRunning;
}

NodeStatus BaseMotionStatus(const TaskContext& ctx,
                            const std::function<void(const std::string&)>& note) {
  if (ctx.motion->base_failed()) {
    note("stopped: " + ctx.motion->base_failure());
    return NodeStatus::kFailure;
  }
  return ctx.motion->base_moving() ? NodeStatus::kRunning : NodeStatus::kSuccess;
}

// The arm motion under way: running while the joints travel, failure (with the joint that
// stopped short) when they did not arrive in time, success once they are at the target.
NodeStatus ArmMotionStatus(const TaskContext& ctx,
                           const std::function<void(const std::string&)>& note) {
  if (ctx.motion->arm_moving(ctx.now)) return NodeStatus::kRunning;
  if (ctx.motion->arm_failed()) {
    note(ctx.motion->arm_failure());
    return NodeStatus::kFailure;
  }
  return NodeStatus::kSuccess;
}

constexpr double kPathLookahead = 1.5;  // [m] of the path ahead checked against the costmap

// The next kPathLookahead metres of the path being followed cross lethal or inscribed cost.
bool IsPathAheadBlocked(const TaskContext& ctx) {
  const std::vector<Pose2>& path = ctx.motion->path();
  if (path.size() < 2) return false;
  // From the waypoint segment nearest the robot on.
  std::size_t next = 1;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i < path.size(); ++i) {
    const Eigen::Vector2d a = path[i - 1].translation(), b = path[i].translation();
    const Eigen::Vector2d ab = b - a;
    const double t =
        ab.squaredNorm() > 0
            ? std::clamp((ctx.X_MB.translation() - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0)
            : 0.0;
    const double d = (a + t * ab - ctx.X_MB.translation()).norm();
    if (d < best) {
      best = d;
      next = i;
    }
  }
  std::vector<Pose2> ahead{ctx.X_MB};
  double length = 0.0;
  for (std::size_t i = next; i < path.size() && length < kPathLookahead; ++i) {
    const Eigen::Vector2d step = path[i].translation() - ahead.back().translation();
    const double remaining = kPathLookahead - length;
    if (step.norm() > remaining) {
      const Eigen::Vector2d p = ahead.back().translation() + step.normalized() * remaining;
      ahead.push_back({p.x(), p.y(), path[i].yaw});
      break;
    }
    ahead.push_back(path[i]);
    length += step.norm();
  }
  if (ahead.size() < 2) return false;
  // Starting inside inflation (e.g. beside a door) is not a new blockage: test from the
  // first free pose on.
  return ctx.planner->IsValid(ctx.X_MB) && !ctx.planner->IsPathValid(ahead);
}

// BaseMotionStatus for a planned drive: when the path ahead becomes blocked on the costmap (an
// obstacle the map does not show, seen only once the robot is on its way), plan again to the
// same end pose instead of driving into it.
NodeStatus DriveStatus(TaskContext& ctx, const std::function<void(const std::string&)>& note,
                       bool door_speed = false) {
  if (ctx.motion->base_moving() && !ctx.motion->bug_active() && IsPathAheadBlocked(ctx)) {
    const Pose2 goal = ctx.motion->path().back();
    ctx.motion->StopBase();
    note("the path ahead is blocked: planning again");
    const NodeStatus s = StartPath(ctx, goal, "the same pose", note, door_speed);
    if (s != NodeStatus::kRunning) return s;
  }
  return BaseMotionStatus(ctx, note);
}

// ---- conditions

class IsPathClear final : public TaskNode<bt::ConditionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("door", "door whose zone must be free of people"),
            InputPort<double>("clear_for", 1.0, "seconds the zone must have been clear [s]")};
  }
  NodeStatus Tick() override {
    const std::string door = Door();
    // A standby retreat runs to its end before the robot resumes: stopping it half-way can
    // leave the robot in the doorway with the leaf about to close.
    if (ctx_.retreating) return last_ = NodeStatus::kFailure;
    if (IsDoorZoneOccupied(ctx_, door)) {
      if (last_ != NodeStatus::kFailure) Note("a person is in or entering the door zone");
      ctx_.zone_occupied_at[door] = ctx_.now;
      return last_ = NodeStatus::kFailure;
    }
    const auto it = ctx_.zone_occupied_at.find(door);
    if (it != ctx_.zone_occupied_at.end() &&
        ToSeconds(ctx_.now - it->second) < Input<double>("clear_for")) {
      return last_ = NodeStatus::kFailure;
    }
    if (last_ == NodeStatus::kFailure) Note("door zone clear");
    return last_ = NodeStatus::kSuccess;
  }

 private:
  NodeStatus last_{NodeStatus::kIdle};
};

constexpr double kDoorSeenRecentlySec = 0.5;  // [s] a door estimate this fresh is "now"
constexpr double kLeafClearance = 0.15;       // [m] kept between the footprint and a leaf's sweep
// [s] A low-energy ADA operator takes at least this long to open (ANSI A156.19: >= 3 s to the
// back check), and at most about the second: the hold window starts in between.
constexpr double kOperatorMinOpeningTime = 3.0;
constexpr double kOperatorOpeningTime = 4.0;
// [rad/s] The fastest a low-energy operator may close its door (A156.19: no less than 3 s from
// 90° to 10°).
constexpr double kOperatorMaxClosingRate = (80.0 * M_PI / 180.0) / 3.0;

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

}  // namespace

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

namespace {

class IsDoorOpen final : public TaskNode<bt::ConditionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("door", "door id"),
            InputPort<double>("margin", 0.1, "clearance beyond the footprint [m]")};
  }
  NodeStatus Tick() override {
    return DoorPassable(ctx_, Door(), Input<double>("margin")) ? NodeStatus::kSuccess
                                                               : NodeStatus::kFailure;
  }
};

class IsPersonHoldingDoor final : public TaskNode<bt::ConditionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() { return {InputPort<std::string>("door", "door id")}; }
  NodeStatus Tick() override {
    const std::string door = Door();
    for (const auto& entry : ctx_.world.people) {
      if (IsHoldingDoorAside(ctx_, entry, door) && DoorPassable(ctx_, door, 0.0)) {
        return NodeStatus::kSuccess;
      }
    }
    return NodeStatus::kFailure;
  }
};

class IsHoldingPayload final : public TaskNode<bt::ConditionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("payload", "", "payload class; empty: any")};
  }
  NodeStatus Tick() override {
    return ctx_.holding_object ? NodeStatus::kSuccess : NodeStatus::kFailure;
  }
};

// ---- actions

class ButtonType final : public TaskNode<bt::SyncActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("door", "door id"),
            OutputPort<std::string>("type", "push_button or proximity_plate")};
  }
  NodeStatus Tick() override {
    const MapActuator* actuator = ctx_.map->FindActuatorOf(Door(), ctx_.X_MB.translation());
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

// Plans and follows a path to `goal`. When the path ahead becomes blocked (an obstacle the map
// does not show), it plans again on the updated costmap; when the costmap has no way to the
// goal, it detours with the Bug2 local planner (round the obstacle's boundary by the laser).
// A goal someone stands on, or a detour that gives up, is planned again every `replan_period`
// for up to `patience` before the node fails.
class NavigateTo final : public TaskNode<bt::StatefulActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("goal", "goal pose x;y;yaw"),
            InputPort<double>("speed", 0.2, "cruise speed [m/s]"),
            InputPort<double>("patience", 15.0, "how long to keep re-planning a blocked goal [s]")};
  }
  NodeStatus OnStart() override {
    blocked_since_.reset();
    detour_tried_ = false;
    return Start();
  }
  NodeStatus OnRunning() override {
    if (blocked_since_) {
      if (ToSeconds(ctx_.now - last_try_) < kReplanPeriod) return NodeStatus::kRunning;
      return Start();
    }
    if (!ctx_.motion->bug_active() && IsPathAheadBlocked(ctx_)) {
      ctx_.motion->StopBase();
      Note("the path ahead is blocked: planning again");
      return Start();
    }
    const NodeStatus s = BaseMotionStatus(ctx_, [this](const std::string& t) { Note(t); });
    return s == NodeStatus::kFailure ? Blocked() : s;
  }
  void OnHalted() override { ctx_.motion->StopBase(); }

 private:
  static constexpr double kReplanPeriod = 0.5;  // [s]

  NodeStatus Start() {
    last_try_ = ctx_.now;
    const Pose2 goal = ParsePose2(Input<std::string>("goal"));
    // Quiet while re-planning: the first failure is noted, not every retry.
    const NodeStatus s = StartPath(ctx_, goal, "goal", [this](const std::string& t) {
      if (!blocked_since_) Note(t);
    });
    if (s != NodeStatus::kFailure) {
      if (blocked_since_) Note("the way is free again");
      blocked_since_.reset();
      return s;
    }
    // No path on the costmap, though the goal itself is free: round the obstacle by the laser.
    if (!detour_tried_ && ctx_.planner->IsValid(goal)) {
      detour_tried_ = true;
      planning::BugConfig bug;
      bug.speed = Input<double>("speed");
      bug.robot_radius = ctx_.config.footprint_radius;
      ctx_.motion->FollowBug(ctx_.X_MB, goal.translation(), bug, ctx_.now);
      Note("no path on the costmap: detouring round the obstacle (Bug2)");
      return NodeStatus::kRunning;
    }
    return Blocked();
  }
  NodeStatus Blocked() {
    if (!blocked_since_) {
      blocked_since_ = ctx_.now;
      last_try_ = ctx_.now;
      Note(StrCat("waiting up to ", Input<double>("patience"), " s for a way"));
    }
    if (ToSeconds(ctx_.now - *blocked_since_) > Input<double>("patience")) {
      Note("gave up: the goal stayed blocked");
      return NodeStatus::kFailure;
    }
    return NodeStatus::kRunning;
  }
  std::optional<Time> blocked_since_;
  Time last_try_{};
  bool detour_tried_{false};
};

class ApproachButton final : public TaskNode<bt::StatefulActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("door", "door whose actuator to stand off")};
  }
  NodeStatus OnStart() override {
    const std::string door = Door();
    const MapActuator* actuator = ctx_.map->FindActuatorOf(door, ctx_.X_MB.translation());
    if (actuator == nullptr) {
      Note("door has no actuator on this side");
      return NodeStatus::kFailure;
    }
    CalcApproachPass(ctx_, door);  // remember which side is "before" the door
    ButtonPlan plan;
    plan.actuator = actuator->id;
    plan.type = actuator->type;
    plan.targets = planning::MakeButtonTargets(actuator->p_M, actuator->n_M, actuator->type,
                                               ctx_.config.buttons);
    // Whole-body IK from the standoff with the arm tucked picks where the base stands.
    planning::IkConfig ik = ctx_.config.ik;
    ik.fingertip = actuator->type == planning::ButtonType::kPushButton;
    ik.use_base = true;
    WholeBodyVector q0 = WholeBodyVector::Zero();
    q0[kBaseX] = plan.targets.X_MB_standoff.x;
    q0[kBaseY] = plan.targets.X_MB_standoff.y;
    q0[kBaseYaw] = plan.targets.X_MB_standoff.yaw;
    q0 = WithArm(q0, kTuckedArm);
    const planning::IkResult solution =
        planning::DlsIkSolver(*ctx_.model, ik).Solve(plan.targets.approach, q0);
    plan.X_MB_standoff = solution.converged
                             ? Pose2{solution.q[kBaseX], solution.q[kBaseY], solution.q[kBaseYaw]}
                             : plan.targets.X_MB_standoff;
    if (solution.converged) plan.approach_arm = ArmOf(solution.q);
    if (!solution.converged) Note("whole-body IK did not converge; using the nominal standoff");
    ctx_.button_plans[door] = plan;
    return StartPath(ctx_, plan.X_MB_standoff, StrCat("the ", actuator->id, " standoff"),
                     [this](const std::string& s) { Note(s); });
  }
  NodeStatus OnRunning() override {
    return DriveStatus(ctx_, [this](const std::string& s) { Note(s); });
  }
  void OnHalted() override { ctx_.motion->StopBase(); }
};

// Arm-only IK at the current base pose (the base stays where it stopped). A solve that ends
// within `accept_error` of the target counts (0: only a converged one; DLS with the paper's
// damping creeps over the last millimetres, which a grasp does not need).
std::optional<ArmPose> SolveArm(const TaskContext& ctx, const Pose2& X_MB,
                                const planning::IkTarget& target, const ArmPose& from,
                                bool fingertip, double accept_error = 0.0) {
  planning::IkConfig ik = ctx.config.ik;
  ik.fingertip = fingertip;
  ik.use_base = false;
  WholeBodyVector q = WholeBodyVector::Zero();
  q[kBaseX] = X_MB.x;
  q[kBaseY] = X_MB.y;
  q[kBaseYaw] = X_MB.yaw;
  q = WithArm(q, from);
  const planning::DlsIkSolver solver(*ctx.model, ik);
  const auto good = [&](const planning::IkResult& r) {
    return r.converged || (r.position_error <= accept_error &&
                           r.orientation_error <= ctx.config.ik.orientation_tolerance);
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

// The base pose relative to the actuator's wall, corrected by the laser: the distance to the
// wall straight ahead, measured, against the distance the believed pose predicts. Pressing a
// 4 mm button stroke needs the wall's distance to a few millimetres; the localizer's estimate
// is good to a few centimetres. Along the wall nothing changes (the button is 10 cm wide).
Pose2 WallAlignedPose(const TaskContext& ctx, const MapActuator& actuator,
                      const std::function<void(const std::string&)>& note) {
  if (!ctx.scan) return ctx.X_MB;
  const Eigen::Vector2d n = actuator.n_M.head<2>().normalized();
  const Eigen::Vector2d t(-n.y(), n.x());
  const Eigen::Vector2d p_MWall = actuator.p_M.head<2>() - n * actuator.protrusion;
  const Pose2 X_ML = ctx.X_MB * ctx.X_BL;
  std::vector<double> distances;
  const LaserScan& scan = *ctx.scan;
  for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
    const double r = scan.ranges[i];
    if (!std::isfinite(r) || r < scan.range_min || r > 2.0) continue;
    const double a = scan.angle_min + double(i) * scan.angle_increment;
    const Eigen::Vector2d p_M = X_ML * Eigen::Vector2d(r * std::cos(a), r * std::sin(a));
    // Near the wall plane, within 0.4 m of the actuator along the wall.
    if (std::abs((p_M - p_MWall).dot(n)) > 0.15 || std::abs((p_M - p_MWall).dot(t)) > 0.4) continue;
    distances.push_back((X_ML.translation() - p_M).dot(n));
  }
  if (distances.size() < 5) return ctx.X_MB;
  auto middle = distances.begin() + std::ptrdiff_t(distances.size() / 2);
  std::nth_element(distances.begin(), middle, distances.end());
  const double expected = (X_ML.translation() - p_MWall).dot(n);
  const double error = *middle - expected;
  Pose2 corrected = ctx.X_MB;
  corrected.x += n.x() * error;
  corrected.y += n.y() * error;
  note(StrCat("wall ", std::round(*middle * 1000) / 1000, " m ahead by laser, ",
              std::round(error * 1000), " mm off the estimate"));
  return corrected;
}

// Presses (push button) or waves (proximity plate): one arm motion, RUNNING until it ends.
class ActuatorAction : public TaskNode<bt::StatefulActionNode> {
 public:
  ActuatorAction(const std::string& name, NodeConfig config, TaskContext* context,
                 planning::ButtonType type)
      : TaskNode(name, std::move(config), context), type_(type) {}
  NodeStatus OnStart() override {
    door_ = Door();
    const auto it = ctx_.button_plans.find(door_);
    if (it == ctx_.button_plans.end() || it->second.type != type_) {
      Note("no standoff for this actuator: ApproachButton must run first");
      return NodeStatus::kFailure;
    }
    alignments_ = 0;
    arm_started_ = false;
    return AlignOrOperate();
  }
  NodeStatus OnRunning() override {
    if (!arm_started_) {
      if (ctx_.motion->base_failed()) {
        Note("could not square up to the actuator: " + ctx_.motion->base_failure());
        return NodeStatus::kFailure;
      }
      if (ctx_.motion->base_moving()) return NodeStatus::kRunning;
      return AlignOrOperate();
    }
    if (const NodeStatus arm = ArmMotionStatus(ctx_, [this](const std::string& t) { Note(t); });
        arm != NodeStatus::kSuccess) {
      return arm;
    }
    // A press (or wave) restarts the operator's hold window of an open door.
    if (ctx_.door_open_since.count(door_) > 0) ctx_.door_open_since[door_] = ctx_.now;
    return NodeStatus::kSuccess;
  }
  void OnHalted() override { ctx_.motion->StopBase(); }  // the arm is tucked by whoever runs next

 private:
  static constexpr double kAlignTolerance = 0.01;  // [m] base off its standoff along the normal
  static constexpr int kMaxAlignments = 2;

  // The base squares up to the planned standoff (by the laser's wall distance) first, then the
  // arm presses or waves.
  NodeStatus AlignOrOperate() {
    const ButtonPlan& plan = ctx_.button_plans.at(door_);
    const MapActuator& actuator = *ctx_.map->FindActuator(plan.actuator);
    const Pose2 X_MB = WallAlignedPose(ctx_, actuator, [this](const std::string& t) { Note(t); });
    const Eigen::Vector2d n = actuator.n_M.head<2>().normalized();
    const double off = (X_MB.translation() - plan.X_MB_standoff.translation()).dot(n);
    if (std::abs(off) > kAlignTolerance && alignments_ < kMaxAlignments) {
      ++alignments_;
      const Pose2 target{ctx_.X_MB.x - n.x() * off, ctx_.X_MB.y - n.y() * off,
                         plan.X_MB_standoff.yaw};
      ctx_.motion->FollowPath({ctx_.X_MB, target}, {false}, ctx_.motion->arm_target(), ctx_.now);
      Note(StrCat("squaring up: ", std::round(off * 1000), " mm off the standoff"));
      return NodeStatus::kRunning;
    }
    return Operate(plan, X_MB);
  }

  NodeStatus Operate(const ButtonPlan& plan, const Pose2& X_MB) {
    const bool push = type_ == planning::ButtonType::kPushButton;
    // The hand reaches the actuator's approach pose then; the press or wave follows.
    ctx_.door_operated_at[door_] = ctx_.now + SecondsToDuration(ctx_.config.press_reach_time);
    const auto approach = SolveArm(ctx_, X_MB, plan.targets.approach, plan.approach_arm, push);
    if (!approach) {
      Note("the actuator is out of the arm's reach from here");
      return NodeStatus::kFailure;
    }
    const TaskConfig& c = ctx_.config;
    if (push) {
      planning::IkTarget press = plan.targets.press;
      press.approach_M.reset();  // the arm alone cannot also hold the approach axis exactly
      const auto pressed = SolveArm(ctx_, X_MB, press, *approach, true);
      if (!pressed) {
        Note("the press point is out of the arm's reach from here");
        return NodeStatus::kFailure;
      }
      ctx_.motion->MoveArm({{c.press_reach_time, *approach},
                            {c.press_reach_time + c.press_time, *pressed},
                            {c.press_reach_time + 2 * c.press_time, *approach}},
                           ctx_.now);
      Note("pressing the push button");
    } else {
      ctx_.motion->MoveArm(
          {{c.press_reach_time, *approach}, {c.press_reach_time + c.wave_hold_time, *approach}},
          ctx_.now);
      Note("waving at the proximity plate");
    }
    arm_started_ = true;
    return NodeStatus::kRunning;
  }

  planning::ButtonType type_;
  std::string door_;
  int alignments_{0};
  bool arm_started_{false};
};

class PressButton final : public ActuatorAction {
 public:
  PressButton(const std::string& name, NodeConfig config, TaskContext* context)
      : ActuatorAction(name, std::move(config), context, planning::ButtonType::kPushButton) {}
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("door", "door whose push button to press")};
  }
};

class WaveAtPlate final : public ActuatorAction {
 public:
  WaveAtPlate(const std::string& name, NodeConfig config, TaskContext* context)
      : ActuatorAction(name, std::move(config), context, planning::ButtonType::kProximityPlate) {}
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("door", "door whose proximity plate to wave at")};
  }
};

// Drives through a door in two legs: to the entry pose on the door's axis (the arm tucking on
// the way), where the laser sees through the opening; then, once the leaf leaves room for the
// footprint, through the doorway to the exit pose. Both legs run at the door speed: the ADA
// hold window is short.
class TraverseDoor final : public TaskNode<bt::StatefulActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("door", "door to drive through"),
            InputPort<double>("speed", 0.4, "speed through the doorway [m/s]"),
            InputPort<double>("wait_timeout", 8.0, "how long to wait for the leaf to open [s]")};
  }
  NodeStatus OnStart() override {
    door_ = Door();
    pass_ = CalcApproachPass(ctx_, door_);
    if (!ArmAt(ctx_.motion->arm_target(), kTuckedArm) || ctx_.motion->arm_moving(ctx_.now)) {
      ctx_.motion->MoveArm({{ctx_.config.arm_tuck_time, kTuckedArm}}, ctx_.now);
    }
    yaw_ = std::atan2(-pass_.n_M.y(), -pass_.n_M.x());  // facing through the door
    entry_distance_ = EntryDistance(ctx_, door_, pass_);
    const Eigen::Vector2d entry = pass_.centre + pass_.n_M * entry_distance_;
    const Eigen::Vector2d offset = ctx_.X_MB.translation() - pass_.centre;
    const double lateral = std::abs(offset.dot(Eigen::Vector2d(-pass_.n_M.y(), pass_.n_M.x())));
    phase_ = Phase::kWaiting;
    waiting_since_ = ctx_.now;
    if (lateral > 0.05 || offset.dot(pass_.n_M) > entry_distance_ + 0.05) {
      // Straight when the costmap allows (the usual case), else round what is in the way.
      const Pose2 X_MB_entry{entry.x(), entry.y(), yaw_};
      // On the side the leaf opens into, out beyond its sweep first, then across to the axis: a
      // straight line from beside the hinge (a button's standoff) would cut the opening leaf.
      std::vector<Pose2> line_up{ctx_.X_MB};
      const double out = offset.dot(pass_.n_M);
      if (entry_distance_ > ctx_.config.door_entry_distance && out < entry_distance_ - 0.05) {
        const Eigen::Vector2d p = ctx_.X_MB.translation() + pass_.n_M * (entry_distance_ - out);
        line_up.push_back({p.x(), p.y(), yaw_});
      }
      line_up.push_back(X_MB_entry);
      if (ctx_.planner->IsPathValid(line_up)) {
        ctx_.motion->FollowPath(line_up, std::vector<bool>(line_up.size() - 1, true), kTuckedArm,
                                ctx_.now);
        Note("lining up on the door's axis");
      } else {
        const NodeStatus s = StartPath(
            ctx_, X_MB_entry, "the door's axis", [this](const std::string& t) { Note(t); }, true);
        if (s != NodeStatus::kRunning) return s;
      }
      phase_ = Phase::kToEntry;
    }
    return OnRunning();
  }
  NodeStatus OnRunning() override {
    const auto note = [this](const std::string& t) { Note(t); };
    switch (phase_) {
      case Phase::kToEntry: {
        const NodeStatus s = DriveStatus(ctx_, note, true);
        if (s != NodeStatus::kSuccess) return s;
        phase_ = Phase::kWaiting;
        waiting_since_ = ctx_.now;
        [[fallthrough]];
      }
      case Phase::kWaiting: {
        if (const NodeStatus arm = ArmMotionStatus(ctx_, [this](const std::string& t) { Note(t); });
            arm != NodeStatus::kSuccess) {
          return arm;
        }
        if (!DoorPassable(ctx_, door_, 0.0)) {
          if (ToSeconds(ctx_.now - waiting_since_) > Input<double>("wait_timeout")) {
            Note("the door did not open in time");
            return NodeStatus::kFailure;
          }
          return NodeStatus::kRunning;  // the leaf is still opening
        }
        // Through the middle of the clear opening, between the latch jamb and the leaf.
        const Eigen::Vector2d centre = ClearOpeningCentre();
        const Eigen::Vector2d exit = centre - pass_.n_M * ExitDistance(ctx_, door_);
        const Eigen::Vector2d offset = ctx_.X_MB.translation() - centre;
        std::vector<Pose2> path{ctx_.X_MB};
        std::vector<bool> through;
        if (offset.dot(pass_.n_M) > 0.1) {  // square up on the opening's centre line first
          const Eigen::Vector2d in = centre + pass_.n_M * std::min(offset.dot(pass_.n_M), 0.4);
          path.push_back({in.x(), in.y(), yaw_});
          through.push_back(true);
        }
        path.push_back({exit.x(), exit.y(), yaw_});
        through.push_back(true);
        ctx_.motion->FollowPath(path, through, kTuckedArm, ctx_.now);
        Note(StrCat("door open: driving through at ", Input<double>("speed"), " m/s"));
        phase_ = Phase::kThrough;
        return NodeStatus::kRunning;
      }
      case Phase::kThrough: {
        const NodeStatus s = BaseMotionStatus(ctx_, note);
        if (s == NodeStatus::kSuccess) {
          Note("through the door");
          ctx_.door_approach_side.erase(door_);  // a later traversal may come the other way
        }
        return s;
      }
    }
    return NodeStatus::kFailure;
  }
  void OnHalted() override { ctx_.motion->StopBase(); }

 private:
  Eigen::Vector2d ClearOpeningCentre() const {
    const perception::DoorModel& door = *ctx_.map->FindDoor(door_);
    double angle = M_PI / 2;
    for (const auto& d : ctx_.world.doors) {
      if (d.model.id == door_ && d.state.observed) angle = std::min(d.state.angle, M_PI / 2);
    }
    constexpr double kLeafHalfThickness = 0.03;  // [m] with a margin
    const double w = door.width();
    const double clear_from = std::min(w, w * std::cos(angle) + kLeafHalfThickness);
    const Eigen::Vector2d along = (door.p_MLatch - door.p_MHinge) / w;
    return door.p_MHinge + along * (clear_from + w) / 2;
  }

  enum class Phase { kToEntry, kWaiting, kThrough };
  std::string door_;
  DoorPass pass_;
  double entry_distance_{0.0};
  double yaw_{0.0};
  Phase phase_{Phase::kWaiting};
  Time waiting_since_{};
};

class RetractToSafe final : public TaskNode<bt::StatefulActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<bool>("back_off", true, "also drive back to the last safe waypoint")};
  }
  NodeStatus OnStart() override {
    ctx_.motion->StopBase();
    if (!ArmAt(ctx_.motion->arm_target(), kTuckedArm) || ctx_.motion->arm_moving(ctx_.now)) {
      ctx_.motion->MoveArm({{ctx_.config.arm_tuck_time, kTuckedArm}}, ctx_.now);
      Note("tucking the arm");
    }
    if (Input<bool>("back_off") && ctx_.last_safe &&
        (ctx_.last_safe->translation() - ctx_.X_MB.translation()).norm() > 0.05) {
      // Out of a doorway straight back along the door's normal first (a diagonal line to the
      // safe waypoint would cut the jamb or the leaf), then to the waypoint.
      std::vector<Pose2> path{ctx_.X_MB};
      for (const auto& door : ctx_.map->doors) {
        const DoorPass pass = CalcKnownPass(ctx_, door.id);
        const Eigen::Vector2d offset = ctx_.X_MB.translation() - pass.centre;
        const double along = offset.dot(pass.n_M);
        const double lateral = std::abs(offset.dot(Eigen::Vector2d(-pass.n_M.y(), pass.n_M.x())));
        const double entry = EntryDistance(ctx_, door.id, pass);
        if (along < entry - 0.05 && along > -ExitDistance(ctx_, door.id) &&
            lateral < pass.width / 2 + 0.3) {
          const Eigen::Vector2d out = ctx_.X_MB.translation() + pass.n_M * (entry - along);
          path.push_back({out.x(), out.y(), ctx_.X_MB.yaw});
          break;
        }
      }
      if ((path.back().translation() - ctx_.last_safe->translation()).norm() > 0.05)
        path.push_back(*ctx_.last_safe);
      ctx_.motion->FollowPath(path, std::vector<bool>(path.size() - 1, false), kTuckedArm,
                              ctx_.now);
      ctx_.retreating = true;
      Note(StrCat("backing off to the last safe waypoint (", PoseText(*ctx_.last_safe), ")"));
    }
    return NodeStatus::kRunning;
  }
  NodeStatus OnRunning() override {
    if (ctx_.motion->base_failed()) ctx_.motion->StopBase();  // blocked: stay, arm tucked
    const bool busy = ctx_.motion->arm_moving(ctx_.now) || ctx_.motion->base_moving();
    if (!busy) ctx_.retreating = false;
    return busy ? NodeStatus::kRunning : NodeStatus::kSuccess;
  }
  void OnHalted() override {
    ctx_.motion->StopBase();
    ctx_.retreating = false;
  }
};

class WaitForClear final : public TaskNode<bt::StatefulActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("door", "door whose zone to watch"),
            InputPort<double>("timeout", 30.0, "give up after [s]")};
  }
  NodeStatus OnStart() override {
    started_ = ctx_.now;
    Note("waiting for the door zone to clear");
    return OnRunning();
  }
  NodeStatus OnRunning() override {
    if (!IsDoorZoneOccupied(ctx_, Door())) return NodeStatus::kSuccess;
    if (ToSeconds(ctx_.now - started_) > Input<double>("timeout")) {
      Note("gave up waiting");
      return NodeStatus::kFailure;
    }
    return NodeStatus::kRunning;
  }
  void OnHalted() override {}

 private:
  Time started_{};
};

// "x;y;z" → point. @throws InvalidArgument naming the text.
Eigen::Vector3d ParsePoint3(std::string_view text) {
  const Pose2 xy = ParsePose2(text);  // x;y;z parses as x;y;yaw
  return {xy.x, xy.y, xy.yaw};
}

// Waits (up to `timeout`) for the perception pipeline to confirm a payload of the class, and
// writes its position.
class DetectPayload final : public TaskNode<bt::StatefulActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("kind", "bottle or flashlight"),
            InputPort<double>("timeout", 4.0, "how long to look [s]"),
            OutputPort<std::string>("pose", "payload position x;y;z in the map")};
  }
  NodeStatus OnStart() override {
    started_ = ctx_.now;
    return OnRunning();
  }
  NodeStatus OnRunning() override {
    const std::string kind = Input<std::string>("kind");
    const perception::TrackedObject* best = nullptr;
    for (const auto& object : ctx_.world.payloads) {
      if (object.label != kind) continue;
      if (best == nullptr || (object.p_MO.head<2>() - ctx_.X_MB.translation()).norm() <
                                 (best->p_MO.head<2>() - ctx_.X_MB.translation()).norm()) {
        best = &object;
      }
    }
    if (best != nullptr) {
      this->SetOutput("pose", StrCat(best->p_MO.x(), ";", best->p_MO.y(), ";", best->p_MO.z()));
      Note(StrCat("found a ", kind, " at (", std::round(best->p_MO.x() * 100) / 100, ", ",
                  std::round(best->p_MO.y() * 100) / 100, ", ",
                  std::round(best->p_MO.z() * 100) / 100, ")"));
      return NodeStatus::kSuccess;
    }
    if (ToSeconds(ctx_.now - started_) > Input<double>("timeout")) {
      Note(StrCat("no ", kind, " in sight"));
      return NodeStatus::kFailure;
    }
    return NodeStatus::kRunning;
  }
  void OnHalted() override {}

 private:
  Time started_{};
};

constexpr double kGraspDepthInPalm = 0.07;  // grasp centre ahead of the palm [m]
constexpr double kPreGraspOffset = 0.12;    // pre-grasp / pre-place this far short [m]
constexpr double kHandError = 0.005;        // [m] a grasp or release this close is good

// The palm target that holds a grasp centre `p_M`, approached along the unit `approach_M`.
planning::IkTarget PalmTarget(const Eigen::Vector3d& p_M, const Eigen::Vector3d& approach_M) {
  return {p_M - approach_M * kGraspDepthInPalm, approach_M};
}

// Where the base stands, and the arm there, for the hand to hold a grasp centre `p_M`
// approached horizontally along `approach_M` (whole-body IK from 0.6 m short); nullopt if out
// of reach.
struct HandReach {
  Pose2 X_MB;
  ArmPose arm;
};
std::optional<HandReach> SolveHandReach(const TaskContext& ctx, const Eigen::Vector3d& p_M,
                                        const Eigen::Vector3d& approach_M) {
  static constexpr ArmPose kReachArm{0.2, -1.0, 0.0, -0.5, 0.0};
  const Eigen::Vector2d a = approach_M.head<2>();
  const Eigen::Vector2d base = p_M.head<2>() - a * 0.6;
  WholeBodyVector q0 = WholeBodyVector::Zero();
  q0[kBaseX] = base.x();
  q0[kBaseY] = base.y();
  q0[kBaseYaw] = std::atan2(a.y(), a.x());
  q0 = WithArm(q0, kReachArm);
  planning::IkConfig ik = ctx.config.ik;
  ik.fingertip = false;
  ik.use_base = true;
  const planning::IkResult r =
      planning::DlsIkSolver(*ctx.model, ik).Solve(PalmTarget(p_M, approach_M), q0);
  if (!r.converged) return std::nullopt;
  return HandReach{{r.q[kBaseX], r.q[kBaseY], r.q[kBaseYaw]}, ArmOf(r.q)};
}

// The unit horizontal direction from the robot to `p_M` (the robot's heading if it is there).
Eigen::Vector3d HorizontalApproach(const Pose2& X_MB, const Eigen::Vector3d& p_M) {
  Eigen::Vector2d a = p_M.head<2>() - X_MB.translation();
  if (a.norm() < 1e-6) a = Eigen::Vector2d(std::cos(X_MB.yaw), std::sin(X_MB.yaw));
  a.normalize();
  return {a.x(), a.y(), 0.0};
}

// How far a payload's centre stands above the surface it rests on [m]: a bottle upright, a
// flashlight lying; unknown kinds get a middle value.
double PayloadCentreHeight(std::string_view kind) {
  if (kind == perception::labels::kBottle) return 0.105;
  if (kind == perception::labels::kFlashlight) return 0.021;
  return 0.05;
}

// The highest depth point standing out of the surface the payload rests on (`surface_z`) in the
// corridor the hand sweeps horizontally towards a grasp centre `p_M` along `approach_M` (from
// the pre-grasp to just before the payload, within a hand's width of the line), or nullopt if
// there is none.
std::optional<double> ClutterTopBeforeGrasp(const TaskContext& ctx, const Eigen::Vector3d& p_M,
                                            const Eigen::Vector3d& approach_M,
                                            double payload_radius, double surface_z) {
  if (!ctx.depth) return std::nullopt;
  constexpr double kHandHalfWidth = 0.07;  // [m] fingers open, with a margin
  constexpr double kFlat = 0.02;           // [m] bumps lower than this are the surface
  const DepthImage& depth = *ctx.depth;
  const CameraIntrinsics& K = ctx.depth_intrinsics;
  const Eigen::Vector2d a = approach_M.head<2>().normalized();
  std::optional<double> top;
  for (int v = 0; v < depth.height; ++v) {
    for (int u = 0; u < depth.width; ++u) {
      if (!depth.IsValidAt(u, v)) continue;
      const double z = depth.At(u, v);
      const Eigen::Vector3d p =
          ctx.X_MC * Eigen::Vector3d((u + 0.5 - K.cx) / K.fx * z, (v + 0.5 - K.cy) / K.fy * z, z);
      const Eigen::Vector2d d = p.head<2>() - p_M.head<2>();
      const double along = d.dot(a);
      const double lateral = (d - along * a).norm();
      if (along > -(payload_radius + 0.01) || along < -(kPreGraspOffset + 0.1) ||
          lateral > kHandHalfWidth || p.z() < surface_z + kFlat) {
        continue;
      }
      top = top ? std::max(*top, p.z()) : p.z();
    }
  }
  return top;
}

// Grasps a payload seen at `pose`: the base goes where whole-body IK puts it (palm level,
// approaching horizontally from the robot's side), the arm reaches a pre-grasp 12 cm short, then
// the grasp, the gripper closes, and the arm lifts 10 cm. Success when the gripper holds it.
class GraspPayload final : public TaskNode<bt::StatefulActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("pose", "payload position x;y;z"),
            InputPort<std::string>("kind", "", "bottle or flashlight (how it stands)")};
  }
  NodeStatus OnStart() override {
    const Eigen::Vector3d p_seen = ParsePoint3(Input<std::string>("pose"));
    approach_ = HorizontalApproach(ctx_.X_MB, p_seen);
    // The camera sees the near surface; the centre is a radius further.
    centre_ = p_seen + approach_ * kPayloadRadius;
    // Something low in front of it (books, a box): grasp higher, so the hand passes above it.
    const double surface_z = centre_.z() - PayloadCentreHeight(Input<std::string>("kind"));
    if (const auto top = ClutterTopBeforeGrasp(ctx_, centre_, approach_, kPayloadRadius, surface_z);
        top && *top + kHandBelowGrasp > centre_.z()) {
      const double raised = std::min(*top + kHandBelowGrasp, centre_.z() + kMaxGraspRaise);
      Note(StrCat("something in front of it up to ", std::round(*top * 100) / 100, " m: grasping ",
                  std::round((raised - centre_.z()) * 100), " cm higher"));
      centre_.z() = raised;
    }
    const auto reach = SolveHandReach(ctx_, centre_, approach_);
    if (!reach) {
      Note("no whole-body reach for the grasp");
      return NodeStatus::kFailure;
    }
    grasp_arm_ = reach->arm;
    X_MB_grasp_ = reach->X_MB;
    GripperCommand open;
    open.mode = GripperCommand::Mode::kOpen;
    ctx_.motion->SetGripper(open);
    phase_ = Phase::kToBase;
    return StartPath(ctx_, X_MB_grasp_, "the grasp pose",
                     [this](const std::string& t) { Note(t); });
  }
  NodeStatus OnRunning() override {
    switch (phase_) {
      case Phase::kToBase: {
        const NodeStatus s = BaseMotionStatus(ctx_, [this](const std::string& t) { Note(t); });
        if (s != NodeStatus::kSuccess) return s;
        // Arm-only from where the base stopped.
        const auto grasp = SolveArm(ctx_, ctx_.X_MB, PalmTarget(centre_, approach_), grasp_arm_,
                                    false, kHandError);
        const auto pre =
            SolveArm(ctx_, ctx_.X_MB, PalmTarget(centre_ - approach_ * kPreGraspOffset, approach_),
                     grasp ? *grasp : grasp_arm_, false, kHandError);
        if (!grasp || !pre) {
          Note("the payload is out of the arm's reach from here");
          return NodeStatus::kFailure;
        }
        ctx_.motion->MoveArm({{2.0, *pre}, {3.5, *grasp}}, ctx_.now);
        lifted_ = *grasp;
        lifted_[0] += 0.10;  // arm_lift
        phase_ = Phase::kReach;
        Note("reaching for the payload");
        return NodeStatus::kRunning;
      }
      case Phase::kReach: {
        if (const NodeStatus arm = ArmMotionStatus(ctx_, [this](const std::string& t) { Note(t); });
            arm != NodeStatus::kSuccess) {
          return arm;
        }
        GripperCommand close;
        close.mode = GripperCommand::Mode::kGrasp;
        close.effort = 10.0;
        ctx_.motion->SetGripper(close);
        closing_since_ = ctx_.now;
        phase_ = Phase::kClose;
        return NodeStatus::kRunning;
      }
      case Phase::kClose: {
        if (ToSeconds(ctx_.now - closing_since_) < 1.5) return NodeStatus::kRunning;
        // Lift, then fold the arm over the base at that height: the hand rises on its arc,
        // clear of what the payload stood among (a straight tuck in joint space would lower
        // the lift while folding and drag the payload through it). The tuck that follows only
        // lowers the lift.
        ArmPose folded = kTuckedArm;
        folded[0] = lifted_[0];
        ctx_.motion->MoveArm({{1.0, lifted_}, {1.0 + ctx_.config.arm_tuck_time, folded}}, ctx_.now);
        phase_ = Phase::kLift;
        return NodeStatus::kRunning;
      }
      case Phase::kLift: {
        if (const NodeStatus arm = ArmMotionStatus(ctx_, [this](const std::string& t) { Note(t); });
            arm != NodeStatus::kSuccess) {
          return arm;
        }
        if (!ctx_.holding_object) {
          Note("the gripper closed on nothing");
          return NodeStatus::kFailure;
        }
        Note("holding the payload");
        return NodeStatus::kSuccess;
      }
    }
    return NodeStatus::kFailure;
  }
  void OnHalted() override { ctx_.motion->StopBase(); }

 private:
  static constexpr double kPayloadRadius = 0.03;   // [m] a bottle's, about
  static constexpr double kHandBelowGrasp = 0.06;  // [m] the hand's lowest point, with margin
  static constexpr double kMaxGraspRaise = 0.06;   // [m] still on the payload's body
  enum class Phase { kToBase, kReach, kClose, kLift };
  Phase phase_{Phase::kToBase};
  Eigen::Vector3d approach_{Eigen::Vector3d::UnitX()};
  Eigen::Vector3d centre_{Eigen::Vector3d::Zero()};
  ArmPose grasp_arm_{kTuckedArm}, lifted_{kTuckedArm};
  Pose2 X_MB_grasp_;
  Time closing_since_{};
};

// Lets go of the held payload where the hand takes it: the base goes where whole-body IK puts
// it, the arm carries the payload in from 12 cm short (and a little higher), waits until
// ReadyToRelease, opens the gripper, draws back and tucks. Success when the gripper is empty.
class ReleaseAction : public TaskNode<bt::StatefulActionNode> {
 public:
  using TaskNode::TaskNode;
  NodeStatus OnStart() override {
    if (!ctx_.holding_object) {
      Note("not holding a payload");
      return NodeStatus::kFailure;
    }
    const auto target = ReleaseTarget();
    if (!target) return NodeStatus::kFailure;
    centre_ = *target;
    approach_ = HorizontalApproach(ctx_.X_MB, centre_);
    approaches_ = 0;
    return DriveToReach();
  }
  NodeStatus OnRunning() override {
    switch (phase_) {
      case Phase::kToBase: {
        const NodeStatus s = BaseMotionStatus(ctx_, [this](const std::string& t) { Note(t); });
        if (s != NodeStatus::kSuccess) return s;
        const auto at = SolveArm(ctx_, ctx_.X_MB, PalmTarget(centre_, approach_), release_arm_,
                                 false, kHandError);
        const Eigen::Vector3d p_pre =
            centre_ - approach_ * kPreGraspOffset + Eigen::Vector3d(0, 0, kPreReleaseRise);
        const auto pre = SolveArm(ctx_, ctx_.X_MB, PalmTarget(p_pre, approach_),
                                  at ? *at : release_arm_, false, kHandError);
        if (!at || !pre) {
          // The base stopped a little off the planned pose: plan the reach again from here.
          Note("the release point is out of the arm's reach from here");
          return approaches_ < kMaxApproaches ? DriveToReach() : NodeStatus::kFailure;
        }
        pre_arm_ = *pre;
        ctx_.motion->MoveArm({{2.0, *pre}, {3.5, *at}}, ctx_.now);
        phase_ = Phase::kReach;
        waiting_since_ = ctx_.now;
        return NodeStatus::kRunning;
      }
      case Phase::kReach: {
        if (const NodeStatus arm = ArmMotionStatus(ctx_, [this](const std::string& t) { Note(t); });
            arm != NodeStatus::kSuccess) {
          return arm;
        }
        const Release release = ReadyToRelease(centre_);
        if (release == Release::kGiveUp) return NodeStatus::kFailure;  // still holding it
        if (release == Release::kWait) return NodeStatus::kRunning;
        GripperCommand open;
        open.mode = GripperCommand::Mode::kOpen;
        ctx_.motion->SetGripper(open);
        opened_at_ = ctx_.now;
        phase_ = Phase::kOpen;
        return NodeStatus::kRunning;
      }
      case Phase::kOpen: {
        if (ToSeconds(ctx_.now - opened_at_) < kOpenTime) return NodeStatus::kRunning;
        ctx_.motion->MoveArm({{1.5, pre_arm_}, {1.5 + ctx_.config.arm_tuck_time, kTuckedArm}},
                             ctx_.now);
        phase_ = Phase::kWithdraw;
        return NodeStatus::kRunning;
      }
      case Phase::kWithdraw: {
        if (const NodeStatus arm = ArmMotionStatus(ctx_, [this](const std::string& t) { Note(t); });
            arm != NodeStatus::kSuccess) {
          return arm;
        }
        if (ctx_.holding_object) {
          Note("the payload is still in the gripper");
          return NodeStatus::kFailure;
        }
        Note("let go of the payload");
        return NodeStatus::kSuccess;
      }
    }
    return NodeStatus::kFailure;
  }
  void OnHalted() override { ctx_.motion->StopBase(); }

 protected:
  // Where the payload's centre goes when released [m, M] (approached from where the robot is
  // now); nullopt (with a note) if there is none.
  virtual std::optional<Eigen::Vector3d> ReleaseTarget() = 0;
  enum class Release { kWait, kNow, kGiveUp };
  // Whether to let go now, the payload being held at `p_M_payload`.
  virtual Release ReadyToRelease(const Eigen::Vector3d& /*p_M_payload*/) { return Release::kNow; }
  Time waiting_since() const { return waiting_since_; }

 private:
  static constexpr double kPreReleaseRise = 0.05;  // [m] the payload comes in from above
  static constexpr int kMaxApproaches = 3;

  NodeStatus DriveToReach() {
    ++approaches_;
    const auto reach = SolveHandReach(ctx_, centre_, approach_);
    if (!reach) {
      Note("no whole-body reach for the release point");
      return NodeStatus::kFailure;
    }
    release_arm_ = reach->arm;
    phase_ = Phase::kToBase;
    const NodeStatus s =
        StartPath(ctx_, reach->X_MB, "the release pose", [this](const std::string& t) { Note(t); });
    return s == NodeStatus::kSuccess ? OnRunning() : s;  // already there: reach now
  }
  int approaches_{0};
  static constexpr double kOpenTime = 1.0;  // [s] for the fingers to open
  enum class Phase { kToBase, kReach, kOpen, kWithdraw };
  Phase phase_{Phase::kToBase};
  Eigen::Vector3d centre_{Eigen::Vector3d::Zero()};
  Eigen::Vector3d approach_{Eigen::Vector3d::UnitX()};
  ArmPose release_arm_{kTuckedArm}, pre_arm_{kTuckedArm};
  Time waiting_since_{}, opened_at_{};
};

// Places the held payload on a surface: `pose` is where its centre goes (the surface height
// plus half the payload's height plus a centimetre or so, which it drops).
class PlacePayload final : public ReleaseAction {
 public:
  using ReleaseAction::ReleaseAction;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("pose", "payload centre x;y;z in the map when let go [m]")};
  }

 private:
  std::optional<Eigen::Vector3d> ReleaseTarget() override {
    return ParsePoint3(Input<std::string>("pose"));
  }
};

// Hands the held payload to a responder standing near `pose`: the robot holds it out at
// hand height toward the nearest person tracked within `search_radius` of it and lets go once
// that person stands within `reach` of the payload (the twin has no hands: there the payload
// drops at the person's feet; on the robot a wrist-force pull would be the cue).
class HandOver final : public ReleaseAction {
 public:
  using ReleaseAction::ReleaseAction;
  static PortsList ProvidedPorts() {
    return {
        InputPort<std::string>("pose", "where the responder is expected x;y[;yaw]"),
        InputPort<double>("search_radius", 1.5, "person this close to pose is the recipient [m]"),
        InputPort<double>("hand_height", 0.9, "payload held out at this height [m]"),
        InputPort<double>("reach", 0.8, "recipient this close to the payload takes it [m]"),
        InputPort<double>("timeout", 20.0, "how long to hold it out [s]")};
  }

 private:
  std::optional<Eigen::Vector3d> ReleaseTarget() override {
    const Pose2 expected = ParsePose2(Input<std::string>("pose"));
    const auto* recipient = Recipient(expected.translation());
    if (recipient == nullptr) {
      Note("no responder in sight near " + PoseText(expected));
      return std::nullopt;
    }
    // Held out half-way between a comfortable standoff and the person.
    const Eigen::Vector2d p_MP = recipient->person.p_MP;
    Eigen::Vector2d to_robot = ctx_.X_MB.translation() - p_MP;
    if (to_robot.norm() < 1e-6) to_robot = Eigen::Vector2d::UnitX();
    const Eigen::Vector2d p = p_MP + to_robot.normalized() * kOfferDistance;
    const Eigen::Vector3d centre(p.x(), p.y(), Input<double>("hand_height"));
    Note(StrCat("holding it out to the responder at ", PoseText({p_MP.x(), p_MP.y(), 0.0})));
    return centre;
  }
  Release ReadyToRelease(const Eigen::Vector3d& p_M_payload) override {
    const Pose2 expected = ParsePose2(Input<std::string>("pose"));
    const auto* recipient = Recipient(expected.translation());
    if (recipient != nullptr &&
        (recipient->person.p_MP - p_M_payload.head<2>()).norm() < Input<double>("reach")) {
      Note(StrCat("the responder is within reach (at ",
                  PoseText({recipient->person.p_MP.x(), recipient->person.p_MP.y(), 0.0}),
                  "): letting go"));
      return Release::kNow;
    }
    if (ToSeconds(ctx_.now - waiting_since()) > Input<double>("timeout")) {
      Note("nobody took the payload in time");
      return Release::kGiveUp;
    }
    return Release::kWait;
  }
  const perception::TrackedPersonWithIntent* Recipient(const Eigen::Vector2d& expected) const {
    const perception::TrackedPersonWithIntent* best = nullptr;
    double best_distance = Input<double>("search_radius");
    for (const auto& entry : ctx_.world.people) {
      const double d = (entry.person.p_MP - expected).norm();
      if (d <= best_distance) {
        best = &entry;
        best_distance = d;
      }
    }
    return best;
  }
  static constexpr double kOfferDistance =
      0.3;  // [m] payload from the person (as tracked: its near side)
};

template <typename T>
void Register(bt::BehaviorTreeFactory& factory, const std::string& id, TaskContext* context) {
  bt::NodeManifest manifest;
  manifest.id = id;
  if constexpr (std::is_base_of_v<bt::ConditionNode, T>) {
    manifest.kind = bt::NodeKind::kCondition;
  } else {
    manifest.kind = bt::NodeKind::kAction;
  }
  manifest.ports = T::ProvidedPorts();
  factory.RegisterBuilder(std::move(manifest), [context](const std::string& name, NodeConfig c) {
    return std::make_unique<T>(name, std::move(c), context);
  });
}

}  // namespace

void RegisterTaskNodes(bt::BehaviorTreeFactory& factory, TaskContext* context) {
  ThrowUnless(context != nullptr && context->map != nullptr && context->model != nullptr &&
                  context->motion != nullptr && context->planner != nullptr,
              "RegisterTaskNodes: the context needs a map, a robot model, a motion executor and a "
              "planner");
  Register<IsPathClear>(factory, "IsPathClear", context);
  Register<IsDoorOpen>(factory, "IsDoorOpen", context);
  Register<IsPersonHoldingDoor>(factory, "IsPersonHoldingDoor", context);
  Register<IsHoldingPayload>(factory, "IsHoldingPayload", context);
  Register<ButtonType>(factory, "ButtonType", context);
  Register<NavigateTo>(factory, "NavigateTo", context);
  Register<ApproachButton>(factory, "ApproachButton", context);
  Register<PressButton>(factory, "PressButton", context);
  Register<WaveAtPlate>(factory, "WaveAtPlate", context);
  Register<TraverseDoor>(factory, "TraverseDoor", context);
  Register<RetractToSafe>(factory, "RetractToSafe", context);
  Register<WaitForClear>(factory, "WaitForClear", context);
  Register<DetectPayload>(factory, "DetectPayload", context);
  Register<GraspPayload>(factory, "GraspPayload", context);
  Register<PlacePayload>(factory, "PlacePayload", context);
  Register<HandOver>(factory, "HandOver", context);
}

}  // namespace egress::behavior
