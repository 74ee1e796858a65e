// The release's leaves, composed in behavior/trees/release.xml (subtrees PlacePayload and
// HandOver): PlanPlacement or PlanHandOver writes a ReleasePlan on the `release` port;
// DriveToRelease, ReachToRelease, WaitForRecipient, OpenGripper (manipulation_nodes.cpp) and
// WithdrawArm carry it out.

#include <cmath>

#include "manipulation_support.h"

namespace egress::behavior::detail {
namespace {

// A planning leaf's common start: the hand must hold something.
bool Holding(const Belief& belief, const std::function<void(const std::string&)>& note) {
  if (!belief.holding_object) note("not holding a payload");
  return belief.holding_object;
}

// Plans placing the held payload on a surface: `pose` is where its centre goes (the surface
// height plus half the payload's height plus a centimetre or so, which it drops), approached
// level from where the robot is.
class PlanPlacement final : public TaskNode<bt::SyncActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("pose",
                                   "payload centre x;y;z in the map when let go [m]: the surface "
                                   "height plus half the payload's height plus a centimetre"),
            PlanPort<ReleasePlan>(bt::PortDirection::kOutput)};
  }
  NodeStatus Tick() override {
    if (!Holding(belief_, [this](const std::string& t) { Note(t); })) return NodeStatus::kFailure;
    ReleasePlan plan;
    plan.p_MC = ParsePoint3(Input<std::string>("pose"));
    plan.approach_M = HorizontalApproach(belief_.X_MB, plan.p_MC);
    this->SetOutput("release", std::move(plan));
    return NodeStatus::kSuccess;
  }
};

// Where the responder is expected, and how near that a tracked person must be.
PortsList RecipientPorts() {
  return {
      InputPort<std::string>("pose", "where the responder is expected x;y[;yaw]"),
      InputPort<double>("search_radius", 1.5, "person this close to pose is the recipient [m]")};
}

// The tracked person nearest `expected` within `search_radius`, or null.
const perception::TrackedPersonWithIntent* Recipient(const Belief& belief,
                                                     const Eigen::Vector2d& expected,
                                                     double search_radius) {
  const perception::TrackedPersonWithIntent* best = nullptr;
  double best_distance = search_radius;
  for (const auto& entry : belief.world.people) {
    const double d = (entry.person.p_MP - expected).norm();
    if (d <= best_distance) {
      best = &entry;
      best_distance = d;
    }
  }
  return best;
}

// Plans handing the held payload to a responder standing near `pose`: held out at hand height
// toward the nearest person tracked within `search_radius` of it, half-way between a comfortable
// standoff and the person.
class PlanHandOver final : public TaskNode<bt::SyncActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    PortsList ports = RecipientPorts();
    ports.insert(InputPort<double>("hand_height", 0.9, "payload held out at this height [m]"));
    ports.insert(PlanPort<ReleasePlan>(bt::PortDirection::kOutput));
    return ports;
  }
  NodeStatus Tick() override {
    if (!Holding(belief_, [this](const std::string& t) { Note(t); })) return NodeStatus::kFailure;
    const Pose2 expected = ParsePose2(Input<std::string>("pose"));
    const auto* recipient =
        Recipient(belief_, expected.translation(), Input<double>("search_radius"));
    if (recipient == nullptr) {
      Note("no responder in sight near " + PoseText(expected));
      return NodeStatus::kFailure;
    }
    const Eigen::Vector2d p_MP = recipient->person.p_MP;
    Eigen::Vector2d to_robot = belief_.X_MB.translation() - p_MP;
    if (to_robot.norm() < 1e-6) to_robot = Eigen::Vector2d::UnitX();
    const Eigen::Vector2d p = p_MP + to_robot.normalized() * kOfferDistance;
    ReleasePlan plan;
    plan.p_MC = {p.x(), p.y(), Input<double>("hand_height")};
    plan.approach_M = HorizontalApproach(belief_.X_MB, plan.p_MC);
    plan.give = kOfferGive;
    Note(StrCat("holding it out to the responder at ", PoseText({p_MP.x(), p_MP.y(), 0.0})));
    this->SetOutput("release", std::move(plan));
    return NodeStatus::kSuccess;
  }

 private:
  static constexpr double kOfferDistance =
      0.3;  // [m] payload from the person (as tracked: its near side)
  // [m] ... or up to this much farther, where the base's pose for the nearer point is not free
  // (still within WaitForRecipient's 0.8 m reach of them).
  static constexpr double kOfferGive = 0.3;
};

using ReleaseLeaf = PlannedLeaf<ReleasePlan>;

// Drives the base to where whole-body IK puts it for the hand to hold the payload at the
// release point, and records the arm there in the plan.
class DriveToRelease final : public ReleaseLeaf {
 public:
  using PlannedLeaf::PlannedLeaf;
  static PortsList ProvidedPorts() { return {PlanPort<ReleasePlan>(bt::PortDirection::kInOut)}; }
  NodeStatus OnStart() override {
    std::optional<ReleasePlan> plan = Plan();
    if (!plan) return NodeStatus::kFailure;
    auto reach = SolveHandReach(task_, plan->p_MC, plan->approach_M, plan->approach_M);
    // Where the base's pose for the point is not free, the point comes back towards the robot
    // in kGiveStepM steps, as far as the plan's give allows.
    for (double back = kGiveStepM;
         reach && !task_.planner->IsValid(reach->X_MB) && back <= plan->give + 1e-9;
         back += kGiveStepM) {
      const Eigen::Vector3d p = plan->p_MC - plan->approach_M * back;
      auto nearer = SolveHandReach(task_, p, plan->approach_M, plan->approach_M);
      if (nearer && task_.planner->IsValid(nearer->X_MB)) {
        Note(StrCat("the base's pose for the release point is not free: holding it out ",
                    std::round(back * 100), " cm nearer the robot"));
        plan->p_MC = p;
        reach = nearer;
      }
    }
    if (!reach) {
      Note("no whole-body reach for the release point");
      return NodeStatus::kFailure;
    }
    plan->arm = reach->arm;
    this->SetOutput("release", *plan);
    const NodeStatus s = StartPath(task_, reach->X_MB, "the release pose", Noter());
    return s == NodeStatus::kSuccess ? OnRunning() : s;
  }
  NodeStatus OnRunning() override { return BaseMotionStatus(task_, Noter()); }
  void OnHalted() override { task_.motion->StopBase(); }

 private:
  static constexpr double kGiveStepM = 0.05;
};

// Carries the payload in from 12 cm short and 5 cm higher to the release point (arm-only IK
// from where the base stopped). Fails when the base stopped out of the arm's reach (a retry
// drives again).
class ReachToRelease final : public ReleaseLeaf {
 public:
  using PlannedLeaf::PlannedLeaf;
  static PortsList ProvidedPorts() { return {PlanPort<ReleasePlan>(bt::PortDirection::kInOut)}; }
  NodeStatus OnStart() override {
    std::optional<ReleasePlan> plan = Plan();
    if (!plan) return NodeStatus::kFailure;
    const auto at = SolveArm(task_, belief_.X_MB, PalmTarget(plan->p_MC, plan->approach_M),
                             plan->arm, false, kHandError);
    const Eigen::Vector3d p_pre =
        plan->p_MC - plan->approach_M * kPreGraspOffset + Eigen::Vector3d(0, 0, kPreReleaseRise);
    const auto pre = SolveArm(task_, belief_.X_MB, PalmTarget(p_pre, plan->approach_M),
                              at ? *at : plan->arm, false, kHandError);
    if (!at || !pre) {
      Note("the release point is out of the arm's reach from here");
      return NodeStatus::kFailure;
    }
    plan->pre_arm = *pre;
    this->SetOutput("release", *plan);
    task_.motion->MoveArm({{2.0, *pre}, {3.5, *at}}, belief_.now);
    return NodeStatus::kRunning;
  }
  NodeStatus OnRunning() override { return ArmMotionStatus(task_, Noter()); }
  void OnHalted() override {}

 private:
  static constexpr double kPreReleaseRise = 0.05;  // [m] the payload comes in from above
};

// Holds the payload out until the responder near `pose` stands within `reach` of it (the twin
// has no hands: there the payload drops at the person's feet; on the robot a wrist-force pull
// would be the cue); fails after `timeout`.
class WaitForRecipient final : public ReleaseLeaf {
 public:
  using PlannedLeaf::PlannedLeaf;
  static PortsList ProvidedPorts() {
    PortsList ports = RecipientPorts();
    ports.insert(
        InputPort<double>("reach", 0.8, "recipient this close to the payload takes it [m]"));
    ports.insert(InputPort<double>("timeout", 20.0, "how long to hold it out [s]"));
    ports.insert(PlanPort<ReleasePlan>(bt::PortDirection::kInput));
    return ports;
  }
  NodeStatus OnStart() override {
    started_ = belief_.now;
    return OnRunning();
  }
  NodeStatus OnRunning() override {
    std::optional<ReleasePlan> plan = Plan();
    if (!plan) return NodeStatus::kFailure;
    const Pose2 expected = ParsePose2(Input<std::string>("pose"));
    const auto* recipient =
        Recipient(belief_, expected.translation(), Input<double>("search_radius"));
    if (recipient != nullptr &&
        (recipient->person.p_MP - plan->p_MC.head<2>()).norm() < Input<double>("reach")) {
      Note(StrCat("the responder is within reach (at ",
                  PoseText({recipient->person.p_MP.x(), recipient->person.p_MP.y(), 0.0}),
                  "): letting go"),
           DecisionEvent::kResponderInReach);
      return NodeStatus::kSuccess;
    }
    if (ToSeconds(belief_.now - started_) > Input<double>("timeout")) {
      Note("nobody took the payload in time");
      return NodeStatus::kFailure;
    }
    return NodeStatus::kRunning;
  }
  void OnHalted() override {}

 private:
  Time started_{};
};

// Draws the hand back through the pre-release posture and tucks the arm. Success when the
// gripper is empty.
class WithdrawArm final : public ReleaseLeaf {
 public:
  using PlannedLeaf::PlannedLeaf;
  static PortsList ProvidedPorts() { return {PlanPort<ReleasePlan>(bt::PortDirection::kInput)}; }
  NodeStatus OnStart() override {
    const std::optional<ReleasePlan> plan = Plan();
    if (!plan) return NodeStatus::kFailure;
    task_.motion->MoveArm(
        {{1.5, plan->pre_arm}, {1.5 + task_.config.arm_tuck_time, TuckedArm(*task_.model)}},
        belief_.now);
    return NodeStatus::kRunning;
  }
  NodeStatus OnRunning() override {
    if (const NodeStatus arm = ArmMotionStatus(task_, Noter()); arm != NodeStatus::kSuccess) {
      return arm;
    }
    if (belief_.holding_object) {
      Note("the payload is still in the gripper");
      return NodeStatus::kFailure;
    }
    Note("let go of the payload");
    return NodeStatus::kSuccess;
  }
  void OnHalted() override {}
};

}  // namespace

void RegisterReleaseNodes(bt::BehaviorTreeFactory& factory, const TaskServices* services) {
  Register<PlanPlacement>(factory, "PlanPlacement", services);
  Register<PlanHandOver>(factory, "PlanHandOver", services);
  Register<DriveToRelease>(factory, "DriveToRelease", services);
  Register<ReachToRelease>(factory, "ReachToRelease", services);
  Register<WaitForRecipient>(factory, "WaitForRecipient", services);
  Register<WithdrawArm>(factory, "WithdrawArm", services);
}

}  // namespace egress::behavior::detail
