#include "people/person_behavior.h"
#include "twin_world_impl.h"

namespace egress::twin {

std::string_view ToString(EntityKind kind) {
  switch (kind) {
    case EntityKind::kStatic:
      return "static";
    case EntityKind::kFloor:
      return "floor";
    case EntityKind::kDoor:
      return "door";
    case EntityKind::kRobotBase:
      return "robot_base";
    case EntityKind::kRobotArm:
      return "robot_arm";
    case EntityKind::kPerson:
      return "person";
    case EntityKind::kPayload:
      return "payload";
  }
  return "unknown";
}

TwinWorld::Impl::Impl(std::shared_ptr<const TwinModel> twin_model_in, std::uint64_t seed_in)
    : twin_model(std::move(twin_model_in)),
      fixed(twin_model->compiled()),
      scenario(twin_model->scenario()),
      world(twin_model->world()),
      seed(seed_in),
      model(twin_model->robot_model()),
      config(twin_model->config()),
      dt(twin_model->step_size()),
      crowd_every(std::uint64_t(std::lround(config.physics_rate_hz / config.crowd_rate_hz))),
      crowd_dt(double(crowd_every) * dt) {
  entities = fixed.entities;
  collision_config = std::make_unique<btDefaultCollisionConfiguration>();
  dispatcher = std::make_unique<btCollisionDispatcher>(collision_config.get());
  broadphase = std::make_unique<btDbvtBroadphase>();
  solver = std::make_unique<btSequentialImpulseConstraintSolver>();
  dynamics = std::make_unique<btDiscreteDynamicsWorld>(dispatcher.get(), broadphase.get(),
                                                       solver.get(), collision_config.get());
  dynamics->setGravity(btVector3(0, 0, -9.81));
  BuildStatics();
  BuildDoors();
  BuildRobot();
  BuildPayloads();
  BuildPeople();
  BuildRayProxies();
  SyncRayProxies();
  DrawFaults();
}

TwinWorld::Impl::~Impl() {
  for (auto& c : constraints)
    dynamics->removeConstraint(c.get());
  for (auto& b : bodies)
    dynamics->removeRigidBody(b.get());
}

int TwinWorld::Impl::AddEntity(EntityKind kind, std::string name, int index, bool glass) {
  entities.push_back({kind, std::move(name), index, glass});
  return int(entities.size()) - 1;
}

btRigidBody* TwinWorld::Impl::AddBody(std::unique_ptr<btCollisionShape> shape, const Pose3& X_W,
                                      double mass, int group, int mask, int entity) {
  btRigidBody* body = AddBodyWithShape(shape.get(), X_W, mass, group, mask, entity);
  shapes.push_back(std::move(shape));
  return body;
}

btRigidBody* TwinWorld::Impl::AddBodyWithShape(btCollisionShape* shape, const Pose3& X_W,
                                               double mass, int group, int mask, int entity) {
  btVector3 inertia(0, 0, 0);
  if (mass > 0) shape->calculateLocalInertia(mass, inertia);
  auto state = std::make_unique<btDefaultMotionState>(ToBt(X_W));
  btRigidBody::btRigidBodyConstructionInfo info(mass, state.get(), shape, inertia);
  auto body = std::make_unique<btRigidBody>(info);
  body->setUserIndex(entity);
  dynamics->addRigidBody(body.get(), group, mask);
  btRigidBody* raw = body.get();
  states.push_back(std::move(state));
  bodies.push_back(std::move(body));
  return raw;
}

void TwinWorld::Impl::MakeKinematic(btRigidBody* body) {
  body->setCollisionFlags(body->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
  body->setActivationState(DISABLE_DEACTIVATION);
}

int TwinWorld::Impl::EntityOf(const btCollisionObject* object, int triangle) const {
  const int e = object->getUserIndex();
  if (e != kMergedStatic) return e;
  return triangle >= 0 && std::size_t(triangle) < fixed.static_triangle_entity.size()
             ? fixed.static_triangle_entity[std::size_t(triangle)]
             : -1;
}

void TwinWorld::Impl::AddEvent(const std::string& kind, const std::string& subject,
                               const std::string& detail) {
  events.push_back({time, kind, subject, detail});
  fired_events.emplace(kind + ":" + subject, time);  // keeps the first
}

void TwinWorld::Impl::RecordContacts() {
  std::set<std::pair<int, int>> now_touching;
  const int n = dispatcher->getNumManifolds();
  for (int m = 0; m < n; ++m) {
    const btPersistentManifold* mf = dispatcher->getManifoldByIndexInternal(m);
    for (int c = 0; c < mf->getNumContacts(); ++c) {
      const btManifoldPoint& pt = mf->getContactPoint(c);
      if (pt.getDistance() >= 1e-3) continue;
      int a = EntityOf(mf->getBody0(), pt.m_index0), b = EntityOf(mf->getBody1(), pt.m_index1);
      if (a < 0 || b < 0) continue;
      if (a > b) std::swap(a, b);
      now_touching.insert({a, b});
    }
  }
  // Kinematic–kinematic and kinematic–static pairs make no manifolds: test the arm directly.
  if (step % 8 == 0) {
    struct Collector : btCollisionWorld::ContactResultCallback {
      const Impl* impl{nullptr};
      std::set<int> hits;
      btScalar addSingleResult(btManifoldPoint& pt, const btCollisionObjectWrapper* a, int,
                               int index_a, const btCollisionObjectWrapper* b, int,
                               int index_b) override {
        if (pt.getDistance() < 0) {
          hits.insert(impl->EntityOf(a->getCollisionObject(), index_a));
          hits.insert(impl->EntityOf(b->getCollisionObject(), index_b));
        }
        return 0;
      }
    };
    // What the hand holds is part of the robot's outline while carried.
    std::vector<btRigidBody*> parts{hand_body, forearm_body};
    if (upper_arm_body != nullptr) parts.push_back(upper_arm_body);
    if (held >= 0) parts.push_back(payloads[held].body);
    for (btRigidBody* arm : parts) {
      Collector collector;
      collector.impl = this;
      collector.m_collisionFilterGroup = kGArm;
      collector.m_collisionFilterMask = kGStatic | kGPerson;
      dynamics->contactTest(arm, collector);
      for (int other : collector.hits) {
        if (other < 0 || other == arm->getUserIndex()) continue;
        int a = arm->getUserIndex(), b = other;
        if (a > b) std::swap(a, b);
        arm_touching.insert({a, b});
      }
    }
    arm_touching_now = arm_touching;
    arm_touching.clear();
  }
  for (const auto& pr : arm_touching_now)
    now_touching.insert(pr);
  for (const auto& [a, b] : now_touching) {
    if (touching.count({a, b})) continue;
    const Entity& ea = entities[a];
    const Entity& eb = entities[b];
    const auto carried = [&](const Entity& e) {
      return e.kind == EntityKind::kPayload && payloads[e.index].held;
    };
    const auto robot = [&](const Entity& e) {
      return e.kind == EntityKind::kRobotBase || e.kind == EntityKind::kRobotArm || carried(e);
    };
    const bool robot_a = robot(ea);
    if (robot_a == robot(eb)) continue;  // only robot–world contacts are recorded
    const Entity& other = robot_a ? eb : ea;
    const Entity& part = robot_a ? ea : eb;
    if (other.kind == EntityKind::kFloor) continue;
    // A carried payload touching furniture is not a bump of the robot's body (it is how a
    // payload is set down), but it names what it touched.
    const std::string kind = carried(part) && other.kind == EntityKind::kStatic
                                 ? std::string("carried")
                                 : std::string(ToString(other.kind));
    AddEvent("contact", other.name, StrCat(kind, " by ", part.name));
  }
  touching = std::move(now_touching);
}

void TwinWorld::Impl::StepOnce() {
  ApplyFaults();
  if (step % crowd_every == 0) {
    UpdatePeople();
  } else {
    CarryPeople();
  }
  UpdateRobot();
  UpdateArmBodies();
  FollowHeldPayload();
  UpdateActuators();
  UpdateDoors();
  WakeNearPeople();
  dynamics->stepSimulation(dt, 1, dt);
  ++step;
  time = double(step) * dt;
  UpdateArmBodies();
  FollowHeldPayload();
  RecordContacts();
  states_stale = true;       // TwinWorld::people() copies them when asked
  ray_proxies_stale = true;  // re-posed before the next ray cast (sensors run at 5-40 Hz)
}

void TwinWorld::Impl::CarryPeople() {
  for (auto& p : people) {
    if (!p.state.started || p.state.out) continue;
    p.walker.position += p.walker.velocity * dt;
    p.state.position = p.walker.position;
    PlacePersonBody(p);
  }
}

void TwinWorld::Impl::PlacePersonBody(Person& p) {
  const btTransform T(btQuaternion::getIdentity(),
                      btVector3(p.walker.position.x(), p.walker.position.y(), kPersonHeight / 2));
  p.body_before = p.body->getWorldTransform();
  p.body_placed_step = step;
  p.body->setWorldTransform(T);  // no motion state (BuildPeople)
}

void TwinWorld::Impl::WakeNearPeople() {
  // TwinConfig::person_body_awake_reach: nobody closes its margin over the arm's reach and a
  // body's size in one step.
  const double reach = config.person_body_awake_reach;
  const btVector3& p_WB = base->getWorldTransform().getOrigin();
  for (Person& p : people) {
    const btVector3& p_WP = p.body->getWorldTransform().getOrigin();
    const auto near = [&](const btVector3& q) {
      const btVector3 d = q - p_WP;
      return d.x() * d.x() + d.y() * d.y() < reach * reach;
    };
    bool awake = near(p_WB);
    for (const Payload& payload : payloads)
      awake = awake || near(payload.body->getWorldTransform().getOrigin());
    if (awake == !p.body_asleep) continue;
    if (awake) {
      // As if it had been awake: Bullet derives its velocity over this step from where it was
      // before this step's placing (or where it stands, if not placed this step). Its bounds are
      // kept up to date asleep too (Bullet updates every body's by default), so that Bullet's
      // broadphase, and the order it finds contacts in, is the same as with it awake.
      p.body->setInterpolationWorldTransform(
          p.body_placed_step == step ? p.body_before : p.body->getWorldTransform());
      p.body->forceActivationState(DISABLE_DEACTIVATION);
    } else {
      p.body->forceActivationState(ISLAND_SLEEPING);
    }
    p.body_asleep = !awake;
  }
}

TwinWorld::TwinWorld(std::shared_ptr<const TwinModel> model, std::uint64_t seed) {
  ThrowUnless(model != nullptr, "TwinWorld: the twin model is null");
  impl_ = std::make_unique<Impl>(std::move(model), seed);
}

TwinWorld::TwinWorld(const Scenario& scenario, const WorldDescription& world, std::uint64_t seed,
                     std::shared_ptr<const RobotModel> robot_model, TwinConfig config)
    : TwinWorld(std::make_shared<const TwinModel>(scenario, world, std::move(robot_model), config),
                seed) {}

TwinWorld::~TwinWorld() = default;

void TwinWorld::Step() {
  impl_->StepOnce();
}

void TwinWorld::StepFor(double seconds) {
  const std::uint64_t target = impl_->step + std::uint64_t(std::ceil(seconds / impl_->dt - 1e-9));
  while (impl_->step < target)
    impl_->StepOnce();
}

double TwinWorld::time() const {
  return impl_->time;
}
Time TwinWorld::now() const {
  return SecondsToDuration(impl_->time);
}
double TwinWorld::step_size() const {
  return impl_->dt;
}
std::uint64_t TwinWorld::step_count() const {
  return impl_->step;
}

void TwinWorld::SetBaseVelocity(const Twist2& V_B) {
  ThrowUnless(V_B.IsFinite(), "base velocity: non-finite twist");
  impl_->command = V_B;
  impl_->last_command_time = impl_->time;
}

void TwinWorld::SetArmTrajectory(const JointTrajectory& trajectory) {
  trajectory.Validate();
  ThrowUnless(!trajectory.points.empty(), "arm trajectory: no points");
  std::vector<double> q0;
  for (const auto& name : trajectory.joint_names) {
    const auto it = impl_->arm_q.find(name);
    if (it == impl_->arm_q.end()) {
      throw InvalidArgument(
          StrCat("arm trajectory: unknown joint '", name,
                 "' (the twin's arm and head joints: arm_lift_joint, arm_flex_joint, "
                 "arm_roll_joint, wrist_flex_joint, wrist_roll_joint, head_pan_joint, "
                 "head_tilt_joint; the base is commanded by velocity)"));
    }
    q0.push_back(it->second);
  }
  for (const auto& name : trajectory.joint_names) {
    if (name == "head_pan_joint" || name == "head_tilt_joint") impl_->head_command.reset();
  }
  impl_->trajectory = trajectory;
  impl_->trajectory_q0 = std::move(q0);
  impl_->trajectory_start =
      trajectory.start.count() == 0 ? impl_->time : ToSeconds(trajectory.start);
}

void TwinWorld::SetHeadCommand(const HeadCommand& command) {
  command.Validate();
  impl_->head_command = command;
}

void TwinWorld::SetGripperCommand(const GripperCommand& command) {
  command.Validate();
  impl_->gripper_command = command;
}

Pose2 TwinWorld::robot_pose() const {
  return impl_->RobotPose();
}
Twist2 TwinWorld::robot_velocity() const {
  return impl_->RobotVelocity();
}
WholeBodyVector TwinWorld::robot_configuration() const {
  return impl_->Configuration();
}

double TwinWorld::arm_joint(std::string_view name) const {
  if (name == "hand_motor_joint") return impl_->hand_q;
  const auto it = impl_->arm_q.find(std::string(name));
  if (it == impl_->arm_q.end()) throw InvalidArgument(StrCat("unknown joint '", name, "'"));
  return it->second;
}

std::vector<std::pair<std::string, double>> TwinWorld::joint_positions() const {
  std::vector<std::pair<std::string, double>> out(impl_->arm_q.begin(), impl_->arm_q.end());
  out.emplace_back("hand_motor_joint", impl_->hand_q);
  return out;
}

double TwinWorld::hand_motor_position() const {
  return impl_->hand_q;
}
double TwinWorld::gripper_effort() const {
  // The fingers squeeze what they hold with the commanded force; closed on nothing, or open,
  // the motor rests.
  return impl_->held >= 0 ? std::max(impl_->gripper_command.effort, 1.0) : 0.0;
}
std::optional<std::string> TwinWorld::held_payload() const {
  if (impl_->held < 0) return std::nullopt;
  return impl_->payloads[impl_->held].spec.name;
}
Eigen::Vector3d TwinWorld::fingertip_position() const {
  return impl_->fingertip;
}
Pose3 TwinWorld::palm_pose() const {
  return impl_->palm;
}
Pose3 TwinWorld::head_camera_pose() const {
  const HeadConfiguration head{impl_->arm_q.at("head_pan_joint"),
                               impl_->arm_q.at("head_tilt_joint")};
  return Pose3::FromPose2(robot_pose()) *
         impl_->model->CalcHeadCameraPose(impl_->arm_q.at("arm_lift_joint"), head);
}
const RobotModel& TwinWorld::robot_model() const {
  return *impl_->model;
}
double TwinWorld::robot_radius() const {
  return impl_->robot_radius;
}

std::size_t TwinWorld::door_count() const {
  return impl_->doors.size();
}
const DoorDescription& TwinWorld::door(std::size_t i) const {
  return *impl_->doors.at(i).fixed->desc;
}
double TwinWorld::door_angle(std::size_t i) const {
  return impl_->MeasureDoorAngle(impl_->doors.at(i));
}
DoorPhase TwinWorld::door_phase(std::size_t i) const {
  const auto& d = impl_->doors.at(i);
  return d.op ? d.op->phase() : DoorPhase::kClosed;
}
bool TwinWorld::door_is_glass(std::size_t i) const {
  const auto& d = impl_->doors.at(i);
  return d.spec && d.spec->glass;
}
int TwinWorld::FindDoorIndex(const std::string& name) const {
  return impl_->FindDoor(name);
}
int TwinWorld::button_presses(std::size_t i) const {
  return impl_->doors.at(i).presses;
}

#if defined(__GLIBCXX__) && defined(__x86_64__)
// people() copies PersonState field by field: a field added to it must be copied there too.
static_assert(sizeof(PersonState) == 192, "PersonState changed: copy the new field in people()");
#endif

const std::vector<PersonState>& TwinWorld::people() const {
  if (impl_->states_stale) {
    // Asked for every step (the judge): the text fields, which seldom change, are compared
    // before they are copied.
    const auto copy_text = [](const std::string& from, std::string* to) {
      if (*to != from) *to = from;
    };
    for (std::size_t i = 0; i < impl_->people.size(); ++i) {
      const PersonState& from = impl_->people[i].state;
      PersonState& to = impl_->states_cache[i];
      copy_text(from.name, &to.name);
      to.behavior = from.behavior;
      to.position = from.position;
      to.velocity = from.velocity;
      to.radius = from.radius;
      to.started = from.started;
      to.phase = from.phase;
      copy_text(from.mobility, &to.mobility);
      to.arrived_at = from.arrived_at;
      to.doors_operated = from.doors_operated;
      to.can_operate = from.can_operate;
      copy_text(from.waiting_for, &to.waiting_for);
      to.out = from.out;
    }
    impl_->states_stale = false;
  }
  return impl_->states_cache;
}

Pose3 TwinWorld::payload_pose(const std::string& name) const {
  for (const auto& p : impl_->payloads) {
    if (p.spec.name == name) return FromBt(p.body->getWorldTransform());
  }
  throw InvalidArgument(StrCat("no payload '", name, "'"));
}

std::vector<std::string> TwinWorld::payload_names() const {
  std::vector<std::string> out;
  for (const auto& p : impl_->payloads)
    out.push_back(p.spec.name);
  return out;
}

const std::vector<TwinEvent>& TwinWorld::events() const {
  return impl_->events;
}

std::vector<DetectableObject> TwinWorld::DetectableObjects() const {
  std::vector<DetectableObject> out;
  const auto& I = *impl_;
  for (std::size_t i = 0; i < I.doors.size(); ++i) {
    const auto& d = I.doors[i];
    out.push_back({door_is_glass(i) ? "glass_door" : "door", d.fixed->desc->name,
                   FromBt(d.leaf->getWorldTransform()), d.fixed->desc->leaf_size / 2,
                   d.leaf->getUserIndex()});
    if (!d.spec) continue;
    for (const auto& actuator : d.spec->actuators) {
      const ShapeDescription& a = *I.world.ShapesOfModel(actuator).front();
      int entity = -1;
      for (std::size_t e = 0; e < I.entities.size(); ++e) {
        if (I.entities[e].name == a.model && I.entities[e].kind == EntityKind::kStatic)
          entity = int(e);
      }
      out.push_back({d.spec->kind == OperatorKind::kPushButton ? "push_button" : "proximity_plate",
                     a.model, a.X_WS, a.box_size / 2, entity});
    }
  }
  for (const auto& p : I.people) {
    if (p.state.out) continue;  // left the scene
    out.push_back(
        {"person", p.state.name,
         Pose3(Eigen::Vector3d(p.state.position.x(), p.state.position.y(), kPersonHeight / 2)),
         Eigen::Vector3d(p.state.radius, p.state.radius, kPersonHeight / 2),
         p.body->getUserIndex()});
  }
  for (const auto& p : I.payloads) {
    const Eigen::Vector3d half = p.spec.kind == PayloadKind::kWaterBottle
                                     ? Eigen::Vector3d(0.033, 0.033, 0.105)
                                     : Eigen::Vector3d(0.1, 0.02, 0.02);
    out.push_back({p.spec.kind == PayloadKind::kWaterBottle ? "bottle" : "flashlight", p.spec.name,
                   FromBt(p.body->getWorldTransform()), half, p.body->getUserIndex()});
  }
  return out;
}

}  // namespace egress::twin
