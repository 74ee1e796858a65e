#include "task_node_support.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace egress::behavior::detail {
namespace {

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
            InputPort<double>("timeout", 4.0, "how long to look before failing [s]"),
            OutputPort<std::string>("pose", "payload position x;y;z in the map")};
  }
  NodeStatus OnStart() override {
    started_ = belief_.now;
    return OnRunning();
  }
  NodeStatus OnRunning() override {
    const std::string kind = Input<std::string>("kind");
    const perception::TrackedObject* best = nullptr;
    for (const auto& object : belief_.world.payloads) {
      if (object.label != kind) continue;
      if (best == nullptr || (object.p_MO.head<2>() - belief_.X_MB.translation()).norm() <
                                 (best->p_MO.head<2>() - belief_.X_MB.translation()).norm()) {
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
    if (ToSeconds(belief_.now - started_) > Input<double>("timeout")) {
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
// approached along `approach_M` — horizontally, or straight down — by a robot coming from the
// horizontal direction `toward_M` (whole-body IK from 0.6 m short); nullopt if out of reach.
struct HandReach {
  Pose2 X_MB;
  ArmPose arm;
};
std::optional<HandReach> SolveHandReach(const TaskServices& task, const Eigen::Vector3d& p_M,
                                        const Eigen::Vector3d& approach_M,
                                        const Eigen::Vector3d& toward_M) {
  // Seeds: reaching forward (palm level), or from above (lift high, upper arm level, palm
  // down), so the solve lands on the posture whose hand comes in from that side.
  static constexpr ArmPose kReachArm{0.2, -1.0, 0.0, -0.5, 0.0};
  static constexpr ArmPose kReachFromAboveArm{0.5, -1.5707963267948966, 0.0, -1.5707963267948966,
                                              0.0};
  const bool from_above = approach_M.z() < -0.9;
  const Eigen::Vector2d a = toward_M.head<2>().normalized();
  const Eigen::Vector2d base = p_M.head<2>() - a * 0.6;
  WholeBodyVector q0 = WholeBodyVector::Zero();
  q0[kBaseX] = base.x();
  q0[kBaseY] = base.y();
  q0[kBaseYaw] = std::atan2(a.y(), a.x());
  q0 = WithArm(q0, from_above ? kReachFromAboveArm : kReachArm);
  planning::IkConfig ik = task.config.ik;
  ik.fingertip = false;
  ik.use_base = true;
  const planning::IkResult r =
      planning::DlsIkSolver(*task.model, ik).Solve(PalmTarget(p_M, approach_M), q0);
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

// Calls fn(p_MQ) for every valid pixel of the latest depth image, unprojected into M.
template <typename Fn>
void ForEachDepthPointInMap(const TaskServices& task, Fn&& fn) {
  const DepthImage& depth = *task.belief->depth;
  for (int v = 0; v < depth.height; ++v) {
    for (int u = 0; u < depth.width; ++u) {
      if (!depth.IsValidAt(u, v)) continue;
      fn(Eigen::Vector3d(task.belief->X_MC * task.belief->depth_intrinsics.Unproject(
                                                 u + 0.5, v + 0.5, depth.At(u, v))));
    }
  }
}

// The highest depth point standing out of the surface the payload rests on (`surface_z`) in the
// corridor the hand sweeps horizontally towards a grasp centre `p_M` along `approach_M` (from
// the pre-grasp to just before the payload, within a hand's width of the line), or nullopt if
// there is none.
std::optional<double> ClutterTopBeforeGrasp(const TaskServices& task, const Eigen::Vector3d& p_M,
                                            const Eigen::Vector3d& approach_M,
                                            double payload_radius, double surface_z) {
  if (!task.belief->depth) return std::nullopt;
  constexpr double kHandHalfWidth = 0.07;  // [m] fingers open, with a margin
  constexpr double kFlat = 0.02;           // [m] bumps lower than this are the surface
  const Eigen::Vector2d a = approach_M.head<2>().normalized();
  std::optional<double> top;
  ForEachDepthPointInMap(task, [&](const Eigen::Vector3d& p) {
    const Eigen::Vector2d d = p.head<2>() - p_M.head<2>();
    const double along = d.dot(a);
    const double lateral = (d - along * a).norm();
    if (along > -(payload_radius + 0.01) || along < -(kPreGraspOffset + 0.1) ||
        lateral > kHandHalfWidth || p.z() < surface_z + kFlat) {
      return;
    }
    top = top ? std::max(*top, p.z()) : p.z();
  });
  return top;
}

// The centre of a low payload lying on a surface at `surface_z`, from the depth points that
// stand out of the surface within `radius` of the estimate `p_M` (the centroid of what the
// camera sees of it, horizontally): a grasp from above has no slack along the approach, where
// the detection's single depth sample may be centimetres off. nullopt if too few points.
std::optional<Eigen::Vector3d> LowPayloadCentre(const TaskServices& task,
                                                const Eigen::Vector3d& p_M, double surface_z,
                                                double radius) {
  if (!task.belief->depth) return std::nullopt;
  constexpr double kAboveSurface = 0.01;  // [m] points lower than this are the surface
  constexpr int kMinPoints = 20;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  int n = 0;
  ForEachDepthPointInMap(task, [&](const Eigen::Vector3d& p) {
    if (p.z() < surface_z + kAboveSurface || p.z() > p_M.z() + radius ||
        (p.head<2>() - p_M.head<2>()).norm() > radius)
      return;
    sum += p.head<2>();
    ++n;
  });
  if (n < kMinPoints) return std::nullopt;
  const Eigen::Vector2d c = sum / n;
  return Eigen::Vector3d(c.x(), c.y(), p_M.z());
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
    gate_.Reset();
    const Eigen::Vector3d p_seen = ParsePoint3(Input<std::string>("pose"));
    approach_ = HorizontalApproach(belief_.X_MB, p_seen);
    // The camera sees the near surface; the centre is a radius further.
    centre_ = p_seen + approach_ * kPayloadRadius;
    // Something low in front of it (books, a box): grasp higher, so the hand passes above it.
    const double surface_z = centre_.z() - PayloadCentreHeight(Input<std::string>("kind"));
    surface_z_ = surface_z;
    if (const auto top =
            ClutterTopBeforeGrasp(task_, centre_, approach_, kPayloadRadius, surface_z);
        top && *top + kHandBelowGrasp > centre_.z()) {
      const double raised = std::min(*top + kHandBelowGrasp, centre_.z() + kMaxGraspRaise);
      Note(StrCat("something in front of it up to ", std::round(*top * 100) / 100, " m: grasping ",
                  std::round((raised - centre_.z()) * 100), " cm higher"));
      centre_.z() = raised;
    }
    // Too low to pass the hand in sideways without it brushing the surface (a lying
    // flashlight): from above, the palm's axis straight down.
    const Eigen::Vector3d toward = approach_;
    if (centre_.z() - surface_z < kHandBelowGrasp) {
      approach_ = -Eigen::Vector3d::UnitZ();
      Note(StrCat("its centre is ", std::round((centre_.z() - surface_z) * 100),
                  " cm above the surface: grasping from above"));
    }
    const auto reach = SolveHandReach(task_, centre_, approach_, toward);
    if (!reach) {
      Note("no whole-body reach for the grasp");
      return NodeStatus::kFailure;
    }
    grasp_arm_ = reach->arm;
    X_MB_grasp_ = reach->X_MB;
    GripperCommand open;
    open.mode = GripperCommand::Mode::kOpen;
    task_.motion->SetGripper(open);
    phase_ = Phase::kToBase;
    return StartPath(task_, X_MB_grasp_, "the grasp pose",
                     [this](const std::string& t) { Note(t); });
  }
  NodeStatus OnRunning() override {
    switch (phase_) {
      case Phase::kToBase: {
        const NodeStatus s = BaseMotionStatus(task_, [this](const std::string& t) { Note(t); });
        if (s != NodeStatus::kSuccess) return s;
        if (gate_.Check(task_, "grasping", EventNoter()) == NodeStatus::kRunning)
          return NodeStatus::kRunning;
        // From above there is no slack along the approach: look again from here, where the
        // pose estimate is the one the arm will use (it drifts on the way, by centimetres).
        if (approach_.z() < -0.9) RefreshLowPayloadCentre();
        // Arm-only from where the base stopped.
        const auto grasp = SolveArm(task_, belief_.X_MB, PalmTarget(centre_, approach_), grasp_arm_,
                                    false, kHandError);
        const auto pre = SolveArm(task_, belief_.X_MB,
                                  PalmTarget(centre_ - approach_ * kPreGraspOffset, approach_),
                                  grasp ? *grasp : grasp_arm_, false, kHandError);
        if (!grasp || !pre) {
          Note("the payload is out of the arm's reach from here");
          return NodeStatus::kFailure;
        }
        // From above: raise the lift first when the pre-grasp stands higher. The lift is the
        // arm's slowest joint, and swinging the arm out and down before it is up sweeps the
        // hand and forearm through the table the payload lies on. (A level reach keeps the
        // hand above the table top all the way.)
        ArmPose raised = task_.motion->arm_target();
        const double rise = (*pre)[0] - raised[0];
        const double lift_speed = task_.model->limits(kArmLift).velocity;
        double t = 0.0;
        std::vector<std::pair<double, ArmPose>> knots;
        if (approach_.z() < -0.9 && rise > kRaiseFirstAbove && lift_speed > 0.0) {
          raised[0] = (*pre)[0];
          t = rise / (kLiftSpeedShare * lift_speed);
          knots.emplace_back(t, raised);
        }
        knots.emplace_back(t + 2.0, *pre);
        knots.emplace_back(t + 3.5, *grasp);
        task_.motion->MoveArm(knots, belief_.now);
        lifted_ = *grasp;
        lifted_[0] = std::min(lifted_[0] + kLiftAfterGrasp,
                              task_.model->limits(kArmLift).upper);  // arm_lift
        phase_ = Phase::kReach;
        Note("reaching for the payload");
        return NodeStatus::kRunning;
      }
      case Phase::kReach: {
        if (const NodeStatus arm =
                ArmMotionStatus(task_, [this](const std::string& t) { Note(t); });
            arm != NodeStatus::kSuccess) {
          return arm;
        }
        GripperCommand close;
        close.mode = GripperCommand::Mode::kGrasp;
        close.effort = 10.0;
        task_.motion->SetGripper(close);
        closing_since_ = belief_.now;
        phase_ = Phase::kClose;
        return NodeStatus::kRunning;
      }
      case Phase::kClose: {
        if (ToSeconds(belief_.now - closing_since_) < 1.5) return NodeStatus::kRunning;
        // Lift, then fold the arm over the base at that height: the hand rises on its arc,
        // clear of what the payload stood among (a straight tuck in joint space would lower
        // the lift while folding and drag the payload through it). The tuck that follows only
        // lowers the lift.
        ArmPose folded = TuckedArm(*task_.model);
        folded[0] = lifted_[0];
        task_.motion->MoveArm({{1.0, lifted_}, {1.0 + task_.config.arm_tuck_time, folded}},
                              belief_.now);
        phase_ = Phase::kLift;
        return NodeStatus::kRunning;
      }
      case Phase::kLift: {
        if (const NodeStatus arm =
                ArmMotionStatus(task_, [this](const std::string& t) { Note(t); });
            arm != NodeStatus::kSuccess) {
          return arm;
        }
        if (!belief_.holding_object) {
          Note("the gripper closed on nothing");
          return NodeStatus::kFailure;
        }
        Note("holding the payload");
        return NodeStatus::kSuccess;
      }
    }
    return NodeStatus::kFailure;
  }
  void OnHalted() override { task_.motion->StopBase(); }

 private:
  // The tracked payload nearest the grasp centre (within kRefreshRadius), seen in the last
  // second, then its centre from the depth points around it.
  void RefreshLowPayloadCentre() {
    const std::string kind = Input<std::string>("kind");
    const perception::TrackedObject* best = nullptr;
    for (const auto& object : belief_.world.payloads) {
      if ((!kind.empty() && object.label != kind) ||
          ToSeconds(belief_.now - object.last_seen) > 1.0)
        continue;
      const double d = (object.p_MO.head<2>() - centre_.head<2>()).norm();
      if (d < kRefreshRadius &&
          (best == nullptr || d < (best->p_MO.head<2>() - centre_.head<2>()).norm()))
        best = &object;
    }
    Eigen::Vector3d centre = centre_;
    if (best != nullptr) centre.head<2>() = best->p_MO.head<2>();
    if (const auto refined = LowPayloadCentre(task_, centre, surface_z_, kLowPayloadSearch))
      centre = *refined;
    if ((centre - centre_).norm() > 0.005) {
      Note(StrCat("looked again: the payload is ", std::round((centre - centre_).norm() * 100),
                  " cm from where it was thought"));
    }
    centre_ = centre;
  }

  RelocalizeGate gate_;
  static constexpr double kRefreshRadius = 0.15;     // [m] the same payload, seen again
  static constexpr double kPayloadRadius = 0.03;     // [m] a bottle's, about
  static constexpr double kHandBelowGrasp = 0.06;    // [m] the hand's lowest point, with margin
  static constexpr double kMaxGraspRaise = 0.06;     // [m] still on the payload's body
  static constexpr double kLiftAfterGrasp = 0.10;    // [m] of arm lift, within its limit
  static constexpr double kLowPayloadSearch = 0.08;  // [m] around the estimate, from above
  static constexpr double kRaiseFirstAbove = 0.05;   // [m] a smaller rise goes with the reach
  static constexpr double kLiftSpeedShare = 0.8;     // of the lift's speed limit, when raising
  enum class Phase { kToBase, kReach, kClose, kLift };
  Phase phase_{Phase::kToBase};
  Eigen::Vector3d approach_{Eigen::Vector3d::UnitX()};
  Eigen::Vector3d centre_{Eigen::Vector3d::Zero()};
  double surface_z_{0.0};           // [m] what the payload rests on
  ArmPose grasp_arm_{}, lifted_{};  // set before use
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
    if (!belief_.holding_object) {
      Note("not holding a payload");
      return NodeStatus::kFailure;
    }
    const auto target = ReleaseTarget();
    if (!target) return NodeStatus::kFailure;
    centre_ = *target;
    approach_ = HorizontalApproach(belief_.X_MB, centre_);
    approaches_ = 0;
    return DriveToReach();
  }
  NodeStatus OnRunning() override {
    switch (phase_) {
      case Phase::kToBase: {
        const NodeStatus s = BaseMotionStatus(task_, [this](const std::string& t) { Note(t); });
        if (s != NodeStatus::kSuccess) return s;
        const auto at = SolveArm(task_, belief_.X_MB, PalmTarget(centre_, approach_), release_arm_,
                                 false, kHandError);
        const Eigen::Vector3d p_pre =
            centre_ - approach_ * kPreGraspOffset + Eigen::Vector3d(0, 0, kPreReleaseRise);
        const auto pre = SolveArm(task_, belief_.X_MB, PalmTarget(p_pre, approach_),
                                  at ? *at : release_arm_, false, kHandError);
        if (!at || !pre) {
          // The base stopped a little off the planned pose: plan the reach again from here.
          Note("the release point is out of the arm's reach from here");
          return approaches_ < kMaxApproaches ? DriveToReach() : NodeStatus::kFailure;
        }
        pre_arm_ = *pre;
        task_.motion->MoveArm({{2.0, *pre}, {3.5, *at}}, belief_.now);
        phase_ = Phase::kReach;
        waiting_since_ = belief_.now;
        return NodeStatus::kRunning;
      }
      case Phase::kReach: {
        if (const NodeStatus arm =
                ArmMotionStatus(task_, [this](const std::string& t) { Note(t); });
            arm != NodeStatus::kSuccess) {
          return arm;
        }
        const Release release = ReadyToRelease(centre_);
        if (release == Release::kGiveUp) return NodeStatus::kFailure;  // still holding it
        if (release == Release::kWait) return NodeStatus::kRunning;
        GripperCommand open;
        open.mode = GripperCommand::Mode::kOpen;
        task_.motion->SetGripper(open);
        opened_at_ = belief_.now;
        phase_ = Phase::kOpen;
        return NodeStatus::kRunning;
      }
      case Phase::kOpen: {
        if (ToSeconds(belief_.now - opened_at_) < kOpenTime) return NodeStatus::kRunning;
        task_.motion->MoveArm(
            {{1.5, pre_arm_}, {1.5 + task_.config.arm_tuck_time, TuckedArm(*task_.model)}},
            belief_.now);
        phase_ = Phase::kWithdraw;
        return NodeStatus::kRunning;
      }
      case Phase::kWithdraw: {
        if (const NodeStatus arm =
                ArmMotionStatus(task_, [this](const std::string& t) { Note(t); });
            arm != NodeStatus::kSuccess) {
          return arm;
        }
        if (belief_.holding_object) {
          Note("the payload is still in the gripper");
          return NodeStatus::kFailure;
        }
        Note("let go of the payload");
        return NodeStatus::kSuccess;
      }
    }
    return NodeStatus::kFailure;
  }
  void OnHalted() override { task_.motion->StopBase(); }

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
    const auto reach = SolveHandReach(task_, centre_, approach_, approach_);
    if (!reach) {
      Note("no whole-body reach for the release point");
      return NodeStatus::kFailure;
    }
    release_arm_ = reach->arm;
    phase_ = Phase::kToBase;
    const NodeStatus s = StartPath(task_, reach->X_MB, "the release pose",
                                   [this](const std::string& t) { Note(t); });
    return s == NodeStatus::kSuccess ? OnRunning() : s;  // already there: reach now
  }
  int approaches_{0};
  static constexpr double kOpenTime = 1.0;  // [s] for the fingers to open
  enum class Phase { kToBase, kReach, kOpen, kWithdraw };
  Phase phase_{Phase::kToBase};
  Eigen::Vector3d centre_{Eigen::Vector3d::Zero()};
  Eigen::Vector3d approach_{Eigen::Vector3d::UnitX()};
  ArmPose release_arm_{}, pre_arm_{};  // set before use
  Time waiting_since_{}, opened_at_{};
};

// Places the held payload on a surface: `pose` is where its centre goes (the surface height
// plus half the payload's height plus a centimetre or so, which it drops).
class PlacePayload final : public ReleaseAction {
 public:
  using ReleaseAction::ReleaseAction;
  static PortsList ProvidedPorts() {
    return {InputPort<std::string>("pose",
                                   "payload centre x;y;z in the map when let go [m]: the surface "
                                   "height plus half the payload's height plus a centimetre")};
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
    Eigen::Vector2d to_robot = belief_.X_MB.translation() - p_MP;
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
                  "): letting go"),
           DecisionEvent::kResponderInReach);
      return Release::kNow;
    }
    if (ToSeconds(belief_.now - waiting_since()) > Input<double>("timeout")) {
      Note("nobody took the payload in time");
      return Release::kGiveUp;
    }
    return Release::kWait;
  }
  const perception::TrackedPersonWithIntent* Recipient(const Eigen::Vector2d& expected) const {
    const perception::TrackedPersonWithIntent* best = nullptr;
    double best_distance = Input<double>("search_radius");
    for (const auto& entry : belief_.world.people) {
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

}  // namespace

void RegisterManipulationNodes(bt::BehaviorTreeFactory& factory, const TaskServices* services) {
  Register<DetectPayload>(factory, "DetectPayload", services);
  Register<GraspPayload>(factory, "GraspPayload", services);
  Register<PlacePayload>(factory, "PlacePayload", services);
  Register<HandOver>(factory, "HandOver", services);
}

}  // namespace egress::behavior::detail
