#include "twin_world_impl.h"

namespace egress::twin {

void TwinWorld::Impl::BuildRobot() {
  std::mt19937_64 rng(DeriveSeed(seed, 2));
  const auto& r = scenario.randomize;
  Pose2 start = scenario.robot_start;
  start.x += r.robot_dx.Sample(rng);
  start.y += r.robot_dy.Sample(rng);
  start.yaw = WrapAngle(start.yaw + r.robot_dyaw.Sample(rng));
  robot_radius = model->footprint_radius();
  // Arm at the robot description's tucked ("go") pose.
  const WholeBodyVector tucked = model->tucked_configuration();
  arm_q = {{"head_pan_joint", 0.0}, {"head_tilt_joint", 0.0}};
  for (int i = kArmLift; i < kNumWholeBodyJoints; ++i)
    arm_q[std::string(WholeBodyJointNames()[i])] = tucked[i];
  for (auto& [name, q] : arm_q) {
    const JointLimits lim = model->GetJointLimits(name);
    q = std::clamp(q, lim.lower, lim.upper);
  }
  // The trunk: the robot description's collision shapes of the links that move only with the
  // lift and the head, one compound the wheels drive. Above its base the HSR is a slim column,
  // so an overhang the base passes under meets the torso or the arm, as on the robot.
  const std::vector<std::pair<std::string, double>> joints(arm_q.begin(), arm_q.end());
  auto trunk_shape = std::make_unique<btCompoundShape>();
  const std::vector<PlacedShape> placed = model->CalcCollisionShapesInBase(joints);
  for (std::size_t i = 0; i < placed.size(); ++i) {
    if (!IsTrunkLink(placed[i].shape.link)) continue;
    auto child = MakeRobotShape(placed[i].shape);
    trunk_shape->addChildShape(ToBt(placed[i].X_BS), child.get());
    shapes.push_back(std::move(child));  // the compound does not own its children
    trunk_shape_index.push_back(i);
  }
  ThrowUnless(trunk_shape->getNumChildShapes() > 0, "TwinWorld: the robot description '",
              model->source(), "' has no collision shape on its base or torso links");
  trunk = trunk_shape.get();
  const int e = AddEntity(EntityKind::kRobotBase, "hsrb", -1);
  base = AddBody(std::move(trunk_shape), Pose3::FromPose2(start), config.robot_mass, kGBase,
                 kMaskBase, e);
  // The planar dynamics of a solid round base of the footprint (the wheels' torque limit assumes
  // it), whatever the compound's box-approximated inertia would be.
  btVector3 inertia;
  btCylinderShapeZ(btVector3(robot_radius, robot_radius, kRobotBodyHeight / 2))
      .calculateLocalInertia(config.robot_mass, inertia);
  base->setMassProps(config.robot_mass, inertia);
  base->updateInertiaTensor();
  base->setFlags(base->getFlags() | BT_DISABLE_WORLD_GRAVITY);
  base->setGravity(btVector3(0, 0, 0));
  base->setLinearFactor(btVector3(1, 1, 0));
  base->setAngularFactor(btVector3(0, 0, 1));
  base->setActivationState(DISABLE_DEACTIVATION);
  base->setFriction(0.0);
  // The hand: palm block and two fingers (fingers do not collide: grasps are decided
  // analytically, see UpdateGripper).
  auto palm_block = std::make_unique<btBoxShape>(btVector3(0.04, 0.035, 0.02));
  auto hand = std::make_unique<btCompoundShape>();
  hand->addChildShape(btTransform(btQuaternion::getIdentity(), btVector3(0, 0, -0.01)),
                      palm_block.get());
  shapes.push_back(std::move(palm_block));  // the compound does not own its children
  const int he = AddEntity(EntityKind::kRobotArm, "hsrb_hand", -1);
  hand_body = AddBody(std::move(hand), Pose3(), 0.0, kGArm, kMaskArm, he);
  MakeKinematic(hand_body);
  // The forearm: a capsule from the arm roll link's origin to the wrist flex link's, both on the
  // arm roll link, so of a fixed length. In the shipped model they coincide, and it is a ball at
  // the wrist: a fixed 0.2 m capsule there stood upright whatever the arm's pose, and reaching
  // level over something low (H5's books) its lower end, 0.19 m under the wrist, touched what
  // the arm cleared.
  const double forearm_length = (model->CalcLinkPoseInBase(kWristLink, joints).translation() -
                                 model->CalcLinkPoseInBase(kForearmLink, joints).translation())
                                    .norm();
  std::unique_ptr<btCollisionShape> forearm;
  if (forearm_length > 1e-6) {
    forearm = std::make_unique<btCapsuleShapeZ>(kForearmRadius, forearm_length);
  } else {
    forearm = std::make_unique<btSphereShape>(kForearmRadius);
  }
  const int fe = AddEntity(EntityKind::kRobotArm, "hsrb_forearm", -1);
  forearm_body = AddBody(std::move(forearm), Pose3(), 0.0, kGArm, kMaskArm, fe);
  MakeKinematic(forearm_body);
  // The upper arm: the arm flex link's own shapes, posed in W by its link frame.
  auto upper_arm = std::make_unique<btCompoundShape>();
  for (const CollisionShape& s : model->collision_shapes()) {
    if (s.link != kUpperArmLink) continue;
    auto child = MakeRobotShape(s);
    upper_arm->addChildShape(ToBt(s.X_LS), child.get());
    shapes.push_back(std::move(child));
  }
  if (upper_arm->getNumChildShapes() > 0) {
    const int ue = AddEntity(EntityKind::kRobotArm, "hsrb_upper_arm", -1);
    upper_arm_body = AddBody(std::move(upper_arm), Pose3(), 0.0, kGArm, kMaskArm, ue);
    MakeKinematic(upper_arm_body);
  }
  UpdateArmBodies();
}

void TwinWorld::Impl::BuildPayloads() {
  std::mt19937_64 rng(DeriveSeed(seed, 3));
  const double j = scenario.randomize.payload_xy;
  for (const auto& spec : scenario.payloads) {
    Payload p;
    p.spec = spec;
    Eigen::Vector3d xyz = spec.X_WP.translation();
    if (j > 0) {
      xyz.x() += std::uniform_real_distribution<double>(-j, j)(rng);
      xyz.y() += std::uniform_real_distribution<double>(-j, j)(rng);
    }
    std::unique_ptr<btCollisionShape> shape;
    double mass = 0.5;
    if (spec.kind == PayloadKind::kWaterBottle) {
      p.diameter = 0.066;
      shape = std::make_unique<btCylinderShapeZ>(btVector3(0.033, 0.033, 0.105));
    } else {
      p.diameter = 0.04;
      mass = 0.25;
      shape = std::make_unique<btCylinderShapeX>(btVector3(0.1, 0.02, 0.02));
    }
    const int e = AddEntity(EntityKind::kPayload, spec.name, int(payloads.size()));
    p.body = AddBody(std::move(shape), Pose3(spec.X_WP.rotation(), xyz), mass, kGPayload,
                     kMaskPayload, e);
    p.body->setFriction(0.8);
    p.body->setRollingFriction(0.01);
    payloads.push_back(std::move(p));
  }
  for (const Payload& p : payloads)
    CheckPayloadClear(p);
}

void TwinWorld::Impl::CheckPayloadClear(const Payload& p) const {
  struct Deepest : btCollisionWorld::ContactResultCallback {
    const Impl* impl{nullptr};
    const btCollisionObject* self{nullptr};
    double depth{0.0};
    int other{-1};
    btScalar addSingleResult(btManifoldPoint& pt, const btCollisionObjectWrapper* a, int,
                             int index_a, const btCollisionObjectWrapper* b, int,
                             int index_b) override {
      if (-pt.getDistance() > depth) {
        depth = -pt.getDistance();
        other = a->getCollisionObject() == self ? impl->EntityOf(b->getCollisionObject(), index_b)
                                                : impl->EntityOf(a->getCollisionObject(), index_a);
      }
      return 0;
    }
  } deepest;
  deepest.impl = this;
  deepest.self = p.body;
  deepest.m_collisionFilterGroup = kGPayload;
  deepest.m_collisionFilterMask = kGStatic | kGDoor | kGPayload;
  dynamics->contactTest(p.body, deepest);
  const Eigen::Vector3d p_WP = FromBt(p.body->getWorldTransform()).translation();
  ThrowUnless(deepest.depth <= kPayloadStartOverlapTolerance, "Invalid scenario '", scenario.name,
              "', payload '", p.spec.name, "': with seed ", seed, " it starts at (",
              std::round(p_WP.x() * 1e3) / 1e3, ", ", std::round(p_WP.y() * 1e3) / 1e3, ", ",
              std::round(p_WP.z() * 1e3) / 1e3, ") inside '",
              deepest.other >= 0 ? entities[std::size_t(deepest.other)].name : "?", "' (",
              std::lround(deepest.depth * 1000),
              " mm deep); move it or narrow "
              "randomize.payload_xy.");
}

void TwinWorld::Impl::UpdateRobot() {
  if (time - last_command_time > config.base_command_timeout) command = Twist2{};
  const double dv = config.base_max_linear_acceleration * dt;
  const double dw = config.base_max_angular_acceleration * dt;
  Eigen::Vector2d v_cmd(command.vx, command.vy);
  if (v_cmd.norm() > config.base_max_linear_speed)
    v_cmd *= config.base_max_linear_speed / v_cmd.norm();
  const double w_cmd =
      std::clamp(command.wz, -config.base_max_angular_speed, config.base_max_angular_speed);
  Eigen::Vector2d v(current.vx, current.vy);
  Eigen::Vector2d delta = v_cmd - v;
  if (delta.norm() > dv) delta *= dv / delta.norm();
  v += delta;
  current.vx = v.x();
  current.vy = v.y();
  current.wz += std::clamp(w_cmd - current.wz, -dw, dw);
  // The wheels push with at most base_max_force: the base tracks the velocity in free space
  // but stalls against walls, closed doors and people instead of shoving them.
  const Pose2 X_WB = RobotPose();
  const Eigen::Vector2d v_W = X_WB.rotation() * v;
  const btVector3 v_now = base->getLinearVelocity();
  Eigen::Vector2d force = config.robot_mass * (v_W - Eigen::Vector2d(v_now.x(), v_now.y())) / dt;
  if (force.norm() > config.base_max_force) force *= config.base_max_force / force.norm();
  base->applyCentralForce(btVector3(force.x(), force.y(), 0));
  const double inertia = 0.5 * config.robot_mass * robot_radius * robot_radius;
  const double torque =
      std::clamp(inertia * (current.wz - base->getAngularVelocity().z()) / dt,
                 -config.base_max_force * robot_radius, config.base_max_force * robot_radius);
  base->applyTorque(btVector3(0, 0, torque));

  // Arm trajectory: linear interpolation between knots, rate-limited by the joint limits.
  if (trajectory) {
    const double t = time - trajectory_start;
    const auto& pts = trajectory->points;
    for (std::size_t j = 0; j < trajectory->joint_names.size(); ++j) {
      const std::string& name = trajectory->joint_names[j];
      if (head_command && (name == "head_pan_joint" || name == "head_tilt_joint")) continue;
      double target = pts.back().positions[j];
      double prev_t = 0.0, prev_q = trajectory_q0[j];
      for (const auto& pt : pts) {
        const double pt_t = ToSeconds(pt.time_from_start);
        if (t <= pt_t) {
          const double s = pt_t > prev_t ? (t - prev_t) / (pt_t - prev_t) : 1.0;
          target = prev_q + std::clamp(s, 0.0, 1.0) * (pt.positions[j] - prev_q);
          break;
        }
        prev_t = pt_t;
        prev_q = pt.positions[j];
      }
      const JointLimits lim = model->GetJointLimits(name);
      double& q = arm_q[name];
      const double max_step = lim.velocity > 0 ? lim.velocity * dt : 1e9;
      q = std::clamp(q + std::clamp(target - q, -max_step, max_step), lim.lower, lim.upper);
    }
  }
  if (head_command) {
    for (const auto& [name, target] : {std::pair{"head_pan_joint", head_command->pan},
                                       {"head_tilt_joint", head_command->tilt}}) {
      const JointLimits lim = model->GetJointLimits(name);
      double& q = arm_q[name];
      const double max_step = lim.velocity > 0 ? lim.velocity * dt : 1e9;
      q = std::clamp(q + std::clamp(target - q, -max_step, max_step), lim.lower, lim.upper);
    }
  }
  UpdateGripper();
}

WholeBodyVector TwinWorld::Impl::Configuration() const {
  const Pose2 X_WB = RobotPose();
  WholeBodyVector q;
  q << X_WB.x, X_WB.y, X_WB.yaw, arm_q.at("arm_lift_joint"), arm_q.at("arm_flex_joint"),
      arm_q.at("arm_roll_joint"), arm_q.at("wrist_flex_joint"), arm_q.at("wrist_roll_joint");
  return q;
}

void TwinWorld::Impl::UpdateArmBodies() {
  const WholeBodyVector q = Configuration();
  palm = model->CalcPalmPose(q);
  fingertip = model->CalcFingertipPosition(q);
  const btTransform T = ToBt(palm);
  hand_body->getMotionState()->setWorldTransform(T);
  hand_body->setWorldTransform(T);
  // Forearm: a capsule from the arm roll link to the wrist, posed in W.
  const Pose3 X_WB = Pose3::FromPose2(RobotPose());
  const std::vector<std::pair<std::string, double>> joints(arm_q.begin(), arm_q.end());
  if (!(arm_pose_cache_valid && joints == arm_pose_cache_q)) {
    const Pose3 X_BR = model->CalcLinkPoseInBase(kForearmLink, joints);
    const Pose3 X_BW = model->CalcLinkPoseInBase(kWristLink, joints);
    X_BForearm_a = X_BR.translation();
    X_BForearm_b = X_BW.translation();
    X_BUpperArm = model->CalcLinkPoseInBase(kUpperArmLink, joints);
    const std::vector<PlacedShape> placed = model->CalcCollisionShapesInBase(joints);
    for (int c = 0; c < trunk->getNumChildShapes(); ++c)
      trunk->updateChildTransform(c, ToBt(placed[trunk_shape_index[std::size_t(c)]].X_BS),
                                  c + 1 == trunk->getNumChildShapes());
    arm_pose_cache_q = joints;
    arm_pose_cache_valid = true;
  }
  const Eigen::Vector3d a = X_WB * X_BForearm_a, b = X_WB * X_BForearm_b;
  const Eigen::Vector3d mid = (a + b) / 2;
  const Eigen::Vector3d dir =
      (b - a).norm() > 1e-6 ? Eigen::Vector3d((b - a).normalized()) : Eigen::Vector3d::UnitZ();
  const Eigen::Quaterniond rot = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), dir);
  const btTransform F = ToBt(Pose3(rot, mid));
  forearm_body->getMotionState()->setWorldTransform(F);
  forearm_body->setWorldTransform(F);
  if (upper_arm_body != nullptr) {
    const btTransform U = ToBt(X_WB * X_BUpperArm);
    upper_arm_body->getMotionState()->setWorldTransform(U);
    upper_arm_body->setWorldTransform(U);
  }
}

void TwinWorld::Impl::UpdateGripper() {
  double target = hand_q;
  switch (gripper_command.mode) {
    case GripperCommand::Mode::kOpen:
      target = kHandOpen;
      break;
    case GripperCommand::Mode::kGrasp:
      target = kHandTouching;
      break;
    case GripperCommand::Mode::kPosition:
      target = gripper_command.position;
      break;
  }
  if (held >= 0) {
    if (target > hand_q + 1e-3) {  // opening releases
      Release();
    } else {
      return;  // fingers rest on the payload
    }
  }
  const double before = hand_q;
  hand_q += std::clamp(target - hand_q, -kHandSpeed * dt, kHandSpeed * dt);
  if (gripper_command.mode == GripperCommand::Mode::kGrasp && hand_q < before) {
    // The closing fingers reach a payload's width: enclosed within tolerance → held.
    for (std::size_t i = 0; i < payloads.size(); ++i) {
      Payload& p = payloads[i];
      if (grasp_tried.count(int(i)) > 0) continue;
      const double w_before = HandWidth(before), w_now = HandWidth(hand_q);
      if (!(w_before > p.diameter && w_now <= p.diameter)) continue;
      const Pose3 X_WP = FromBt(p.body->getWorldTransform());
      const Eigen::Vector3d p_G = palm.Inverse() * X_WP.translation();
      const Eigen::Vector3d err(p_G.x(), p_G.y(), p_G.z() - kGraspDepthInPalm);
      // Closing direction is the palm's y axis; x is across the fingers; z the approach.
      const bool between = std::abs(err.x()) <= 0.03 && std::abs(err.z()) <= 0.04;
      if (between && std::abs(err.y()) <= config.grasp_tolerance) {
        p.held = true;
        p.X_GP = palm.Inverse() * X_WP;
        held = int(i);
        dynamics->removeRigidBody(p.body);
        MakeKinematic(p.body);
        // Held, it moves with the hand: not against the arm, nor the robot's own body (the
        // twin's body is one 1 m cylinder the tucked hand sits over; a kinematic payload
        // inside it would launch the base).
        dynamics->addRigidBody(p.body, kGPayload, kMaskPayload & ~kGArm & ~kGBase);
        hand_q = std::max(hand_q,
                          kHandTouching + (kHandOpen - kHandTouching) * p.diameter / kHandMaxWidth);
        AddEvent("grasp", p.spec.name, "held");
        return;
      }
      grasp_tried.insert(int(i));
      if (between && std::abs(err.y()) <= w_before / 2 + p.diameter / 2) {
        // A finger strikes it off-centre: it is pushed along the closing direction.
        const Eigen::Vector3d push_W = palm.rotation().col(1) * (err.y() > 0 ? 1.0 : -1.0);
        p.body->activate(true);
        p.body->applyCentralImpulse(ToBt(push_W * 0.3));
        AddEvent("grasp_failed", p.spec.name, "pushed");
      } else if ((X_WP.translation() - palm * Eigen::Vector3d(0, 0, kGraspDepthInPalm)).norm() <
                 0.25) {
        AddEvent("grasp_failed", p.spec.name, "missed");
      }
    }
  }
  if (gripper_command.mode != GripperCommand::Mode::kGrasp) grasp_tried.clear();
}

void TwinWorld::Impl::Release() {
  Payload& p = payloads[held];
  p.held = false;
  dynamics->removeRigidBody(p.body);
  p.body->setCollisionFlags(p.body->getCollisionFlags() & ~btCollisionObject::CF_KINEMATIC_OBJECT);
  p.body->setLinearVelocity(btVector3(0, 0, 0));
  p.body->setAngularVelocity(btVector3(0, 0, 0));
  p.body->forceActivationState(ACTIVE_TAG);
  dynamics->addRigidBody(p.body, kGPayload, kMaskPayload);
  AddEvent("release", p.spec.name);
  held = -1;
  grasp_tried.clear();
}

void TwinWorld::Impl::FollowHeldPayload() {
  if (held < 0) return;
  const btTransform T = ToBt(palm * payloads[held].X_GP);
  payloads[held].body->getMotionState()->setWorldTransform(T);
  payloads[held].body->setWorldTransform(T);
}

Pose2 TwinWorld::Impl::RobotPose() const {
  const btTransform& T = base->getWorldTransform();
  const btVector3 x = T.getBasis().getColumn(0);
  return {T.getOrigin().x(), T.getOrigin().y(), std::atan2(x.y(), x.x())};
}

Twist2 TwinWorld::Impl::RobotVelocity() const {
  const Pose2 X_WB = RobotPose();
  const btVector3 v = base->getLinearVelocity();
  const Eigen::Vector2d v_B = X_WB.rotation().transpose() * Eigen::Vector2d(v.x(), v.y());
  return {v_B.x(), v_B.y(), base->getAngularVelocity().z()};
}

}  // namespace egress::twin
