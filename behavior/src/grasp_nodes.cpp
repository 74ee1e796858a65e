// The grasp's leaves, composed in behavior/trees/grasp.xml (subtree GraspPayload): PlanGrasp
// writes a GraspPlan on the `grasp` port; DriveToGrasp, ReachForPayload, CloseGripper
// (manipulation_nodes.cpp) and LiftPayload carry it out, each one phase a tree (and Groot2) can
// show.

#include <algorithm>
#include <cmath>

#include "manipulation_support.h"

namespace egress::behavior::detail {
namespace {

using GraspLeaf = PlannedLeaf<GraspPlan>;

// Plans a grasp of the payload seen at `pose`: its centre (the camera sees the near surface; the
// centre is a radius further), the approach (horizontal from the robot's side; straight down
// when the payload lies too low for the hand to pass beside it; raised over something low in
// front of it) and where the base stands for it (whole-body IK).
class PlanGrasp final : public TaskNode<bt::SyncActionNode> {
 public:
  using TaskNode::TaskNode;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("pose", "payload position x;y;z"),
            InputPort<std::string>("kind", "", "bottle or flashlight (how it stands)"),
            PlanPort<GraspPlan>(bt::PortDirection::kOutput)};
  }
  NodeStatus Tick() override {
    GraspPlan plan;
    plan.kind = Input<std::string>("kind");
    const Eigen::Vector3d p_seen = ParsePoint3(Input<std::string>("pose"));
    plan.approach_M = HorizontalApproach(belief_.X_MB, p_seen);
    plan.p_MC = p_seen + plan.approach_M * kPayloadRadius;
    plan.surface_z = plan.p_MC.z() - PayloadCentreHeight(plan.kind);
    // Something low in front of it (books, a box): grasp higher, so the hand passes above it.
    const std::optional<ClutterBeforeGrasp> clutter =
        FindClutterBeforeGrasp(task_, plan.p_MC, plan.approach_M, kPayloadRadius, plan.surface_z);
    if (clutter && clutter->top_z + kHandBelowGrasp > plan.p_MC.z()) {
      const double raised =
          std::min(clutter->top_z + kHandBelowGrasp, plan.p_MC.z() + kMaxGraspRaise);
      Note(StrCat("something in front of it up to ", std::round(clutter->top_z * 100) / 100,
                  " m: grasping ", std::round((raised - plan.p_MC.z()) * 100), " cm higher"));
      plan.p_MC.z() = raised;
    }
    // Too low to pass the hand in sideways without it brushing the surface (a lying
    // flashlight): from above, the palm's axis straight down.
    const Eigen::Vector3d toward = plan.approach_M;
    if (plan.p_MC.z() - plan.surface_z < kHandBelowGrasp) {
      plan.approach_M = -Eigen::Vector3d::UnitZ();
      Note(StrCat("its centre is ", std::round((plan.p_MC.z() - plan.surface_z) * 100),
                  " cm above the surface: grasping from above"));
    }
    // Level, the pre-grasp in front of the clutter: the arm swings up into the pre-grasp from
    // below, and 12 cm short of the payload its hand came up through the books' near edge
    // (H5: 24 of 100 seeds touched them).
    if (clutter && plan.approach_M.z() > -0.9) {
      plan.pre_offset = std::max(kPreGraspOffset, clutter->reach + kPreGraspBeforeClutter);
    }
    const auto reach = SolveHandReach(task_, plan.p_MC, plan.approach_M, toward);
    if (!reach) {
      Note("no whole-body reach for the grasp");
      return NodeStatus::kFailure;
    }
    plan.X_MB = reach->X_MB;
    plan.arm = reach->arm;
    this->SetOutput("grasp", std::move(plan));
    return NodeStatus::kSuccess;
  }

 private:
  static constexpr double kPayloadRadius = 0.03;   // [m] a bottle's, about
  static constexpr double kHandBelowGrasp = 0.06;  // [m] the hand's lowest point, with margin
  static constexpr double kMaxGraspRaise = 0.06;   // [m] still on the payload's body
  // [m] the pre-grasp's centre before the clutter's near face: the fingertips reach ~3 cm
  // beyond the grasp centre.
  static constexpr double kPreGraspBeforeClutter = 0.06;
};

// Opens the gripper and drives the base to the grasp's pose; there, waits for a precise pose
// (RelocalizeGate) before the arm moves.
class DriveToGrasp final : public GraspLeaf {
 public:
  using PlannedLeaf::PlannedLeaf;
  static PortsList ProvidedPorts() { return {PlanPort<GraspPlan>(bt::PortDirection::kInput)}; }
  NodeStatus OnStart() override {
    gate_.Reset();
    const std::optional<GraspPlan> plan = Plan();
    if (!plan) return NodeStatus::kFailure;
    GripperCommand open;
    open.mode = GripperCommand::Mode::kOpen;
    task_.motion->SetGripper(open);
    p_MC_ = plan->p_MC;
    LookAt(p_MC_);  // the payload in view on the way, so that the reach finds it seen afresh
    const NodeStatus s = StartPath(task_, plan->X_MB, "the grasp pose", Noter());
    return s == NodeStatus::kSuccess ? OnRunning() : s;
  }
  NodeStatus OnRunning() override {
    LookAt(p_MC_);
    const NodeStatus s = BaseMotionStatus(task_, Noter());
    if (s != NodeStatus::kSuccess) return s;
    return gate_.Check(task_, "grasping", EventNoter());
  }
  void OnHalted() override { task_.motion->StopBase(); }

 private:
  RelocalizeGate gate_;
  Eigen::Vector3d p_MC_{Eigen::Vector3d::Zero()};
};

// Swings the arm from where the base stopped to a pre-grasp 12 cm short of the payload (further
// in front of clutter: GraspPlan::pre_offset, then in along a straight line), then to the grasp
// (arm-only IK). From above it first looks again (the pose estimate drifts on the way,
// and from above there is no slack along the approach) and raises the lift before the arm swings
// out and down. Writes the arm at the grasp back to the plan.
class ReachForPayload final : public GraspLeaf {
 public:
  using PlannedLeaf::PlannedLeaf;
  static PortsList ProvidedPorts() { return {PlanPort<GraspPlan>(bt::PortDirection::kInOut)}; }
  NodeStatus OnStart() override {
    std::optional<GraspPlan> plan = Plan();
    if (!plan) return NodeStatus::kFailure;
    const bool from_above = plan->approach_M.z() < -0.9;
    if (from_above) RefreshLowPayloadCentre(&*plan);
    const auto grasp = SolveArm(task_, belief_.X_MB, PalmTarget(plan->p_MC, plan->approach_M),
                                plan->arm, false, kHandError);
    const auto pre =
        SolveArm(task_, belief_.X_MB,
                 PalmTarget(plan->p_MC - plan->approach_M * plan->pre_offset, plan->approach_M),
                 grasp ? *grasp : plan->arm, false, kHandError);
    // From a pre-grasp further back (before clutter), the hand goes in along the straight line:
    // knots kStraightStepM apart (joint-space between two far poses, it may sag onto the clutter).
    std::vector<ArmPose> way_in;
    const int steps = int(std::ceil(plan->pre_offset / kStraightStepM - 1e-9));
    if (grasp && pre && plan->pre_offset > kPreGraspOffset) {
      ArmPose seed = *pre;
      for (int i = 1; i < steps && grasp; ++i) {
        const double back = plan->pre_offset * (1.0 - double(i) / steps);
        const auto at = SolveArm(task_, belief_.X_MB,
                                 PalmTarget(plan->p_MC - plan->approach_M * back, plan->approach_M),
                                 seed, false, kHandError);
        if (!at) {
          way_in.clear();
          break;
        }
        way_in.push_back(*at);
        seed = *at;
      }
    }
    if (!grasp || !pre) {
      Note("the payload is out of the arm's reach from here");
      return NodeStatus::kFailure;
    }
    // From above: raise the lift first when the pre-grasp stands higher. The lift is the arm's
    // slowest joint, and swinging the arm out and down before it is up sweeps the hand and
    // forearm through the table the payload lies on. (A level reach keeps the hand above the
    // table top all the way.)
    ArmPose raised = task_.motion->arm_target();
    const double rise = (*pre)[0] - raised[0];
    const double lift_speed = task_.model->limits(kArmLift).velocity;
    double t = 0.0;
    std::vector<std::pair<double, ArmPose>> knots;
    if (from_above && rise > kRaiseFirstAbove && lift_speed > 0.0) {
      raised[0] = (*pre)[0];
      t = rise / (kLiftSpeedShare * lift_speed);
      knots.emplace_back(t, raised);
    }
    knots.emplace_back(t + 2.0, *pre);
    // At the default's pace: 1.5 s for the last 12 cm.
    const double way_in_time = kWayInSec * std::max(1.0, plan->pre_offset / kPreGraspOffset);
    for (std::size_t i = 0; i < way_in.size(); ++i)
      knots.emplace_back(t + 2.0 + way_in_time * double(i + 1) / double(way_in.size() + 1),
                         way_in[i]);
    knots.emplace_back(t + 2.0 + way_in_time, *grasp);
    task_.motion->MoveArm(knots, belief_.now);
    plan->arm = *grasp;
    p_MC_ = plan->p_MC;
    this->SetOutput("grasp", *plan);
    Note("reaching for the payload");
    LookAt(p_MC_);
    return NodeStatus::kRunning;
  }
  NodeStatus OnRunning() override {
    LookAt(p_MC_);
    return ArmMotionStatus(task_, Noter());
  }
  void OnHalted() override {}

 private:
  // The tracked payload nearest the grasp centre (within kRefreshRadius), seen in the last
  // second, then its centre from the depth points around it.
  void RefreshLowPayloadCentre(GraspPlan* plan) {
    const perception::TrackedObject* best = nullptr;
    for (const auto& object : belief_.world.payloads) {
      if ((!plan->kind.empty() && object.label != plan->kind) ||
          ToSeconds(belief_.now - object.last_seen) > 1.0)
        continue;
      const double d = (object.p_MO.head<2>() - plan->p_MC.head<2>()).norm();
      if (d < kRefreshRadius &&
          (best == nullptr || d < (best->p_MO.head<2>() - plan->p_MC.head<2>()).norm()))
        best = &object;
    }
    Eigen::Vector3d centre = plan->p_MC;
    if (best != nullptr) centre.head<2>() = best->p_MO.head<2>();
    if (const auto refined = LowPayloadCentre(task_, centre, plan->surface_z, kLowPayloadSearch))
      centre = *refined;
    if ((centre - plan->p_MC).norm() > 0.005) {
      Note(StrCat("looked again: the payload is ", std::round((centre - plan->p_MC).norm() * 100),
                  " cm from where it was thought"));
    }
    plan->p_MC = centre;
  }
  Eigen::Vector3d p_MC_{Eigen::Vector3d::Zero()};
  static constexpr double kRefreshRadius = 0.15;     // [m] the same payload, seen again
  static constexpr double kLowPayloadSearch = 0.08;  // [m] around the estimate, from above
  static constexpr double kRaiseFirstAbove = 0.05;   // [m] a smaller rise goes with the reach
  static constexpr double kLiftSpeedShare = 0.8;     // of the lift's speed limit, when raising
  static constexpr double kWayInSec = 1.5;           // [s] pre-grasp to grasp, for kPreGraspOffset
  static constexpr double kStraightStepM = 0.06;     // [m] knots on the way in from further back
};

// Lifts the hand 10 cm, then folds the arm over the base at that height: the hand rises on its
// arc, clear of what the payload stood among (a straight tuck in joint space would lower the
// lift while folding and drag the payload through it; the tuck that follows only lowers the
// lift). Success when the gripper still holds the payload.
class LiftPayload final : public GraspLeaf {
 public:
  using PlannedLeaf::PlannedLeaf;
  static PortsList ProvidedPorts() { return {PlanPort<GraspPlan>(bt::PortDirection::kInput)}; }
  NodeStatus OnStart() override {
    const std::optional<GraspPlan> plan = Plan();
    if (!plan) return NodeStatus::kFailure;
    ArmPose lifted = plan->arm;
    lifted[0] = std::min(lifted[0] + kLiftAfterGrasp, task_.model->limits(kArmLift).upper);
    ArmPose folded = TuckedArm(*task_.model);
    folded[0] = lifted[0];
    task_.motion->MoveArm({{1.0, lifted}, {1.0 + task_.config.arm_tuck_time, folded}}, belief_.now);
    return NodeStatus::kRunning;
  }
  NodeStatus OnRunning() override {
    if (const NodeStatus arm = ArmMotionStatus(task_, Noter()); arm != NodeStatus::kSuccess) {
      return arm;
    }
    if (!belief_.holding_object) {
      Note("the gripper closed on nothing");
      return NodeStatus::kFailure;
    }
    Note("holding the payload");
    return NodeStatus::kSuccess;
  }
  void OnHalted() override {}

 private:
  static constexpr double kLiftAfterGrasp = 0.10;  // [m] of arm lift, within its limit
};

}  // namespace

void RegisterGraspNodes(bt::BehaviorTreeFactory& factory, const TaskServices* services) {
  Register<PlanGrasp>(factory, "PlanGrasp", services);
  Register<DriveToGrasp>(factory, "DriveToGrasp", services);
  Register<ReachForPayload>(factory, "ReachForPayload", services);
  Register<LiftPayload>(factory, "LiftPayload", services);
}

}  // namespace egress::behavior::detail
