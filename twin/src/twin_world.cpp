#include "egress/twin/twin_world.h"

#include <BulletCollision/NarrowPhaseCollision/btRaycastCallback.h>
#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <set>

#include "egress/hsr_interface/error.h"
#include "egress/twin/actuators.h"
#include "egress/twin/social_force.h"
#include "seeds.h"

namespace egress::twin {
namespace {

// Collision groups. Pairs collide when each one's group is in the other's mask.
enum Group : int {
  kGStatic = 1 << 0,
  kGFloor = 1 << 1,
  kGDoor = 1 << 2,
  kGBase = 1 << 3,
  kGArm = 1 << 4,
  kGPerson = 1 << 5,
  kGPayload = 1 << 6,
};
constexpr int kMaskStatic = kGBase | kGArm | kGPerson | kGPayload;
constexpr int kMaskFloor = kGPayload;
constexpr int kMaskDoor = kGBase | kGArm | kGPerson | kGPayload;
constexpr int kMaskBase = kGStatic | kGDoor | kGPerson | kGPayload;
constexpr int kMaskArm = kGStatic | kGDoor | kGPerson | kGPayload;
constexpr double kStuckSec =
    2.0;  // [s] a walker that wants to move but has not, this long, is stuck
constexpr double kKeepRight = 0.2;  // [m] off the doorway axis, clear of a 0.9 m door's jambs
constexpr int kMaskPerson = kGStatic | kGDoor | kGBase | kGArm | kGPayload;
constexpr int kMaskPayload = kGStatic | kGFloor | kGDoor | kGBase | kGArm | kGPerson | kGPayload;

constexpr double kPersonHeight = 1.7;       // [m]
constexpr double kRobotBodyHeight = 1.0;    // base + torso cylinder [m]
constexpr double kHandOpen = 1.24;          // hand_motor_joint fully open [rad]
constexpr double kHandTouching = -0.3;      // fingertips meet [rad]
constexpr double kHandMaxWidth = 0.135;     // finger gap when fully open [m]
constexpr double kHandSpeed = 1.0;          // [rad/s] (URDF limit)
constexpr double kGraspDepthInPalm = 0.07;  // grasp centre along the palm's approach z [m]
constexpr double kDegToRad = M_PI / 180.0;
// A payload may start this deep in what it stands on (contact margins), no deeper [m].
constexpr double kPayloadStartOverlapTolerance = 0.002;

btVector3 ToBt(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}
Eigen::Vector3d FromBt(const btVector3& v) {
  return {v.x(), v.y(), v.z()};
}

btTransform ToBt(const Pose3& X) {
  const Eigen::Quaterniond q = X.quaternion();
  return btTransform(btQuaternion(q.x(), q.y(), q.z(), q.w()), ToBt(X.translation()));
}

Pose3 FromBt(const btTransform& T) {
  const btQuaternion q = T.getRotation();
  return Pose3(Eigen::Quaterniond(q.w(), q.x(), q.y(), q.z()).normalized(), FromBt(T.getOrigin()));
}

double HandWidth(double hand_q) {
  return kHandMaxWidth *
         std::clamp((hand_q - kHandTouching) / (kHandOpen - kHandTouching), 0.0, 1.0);
}

// Outline segments of a static shape on the floor (for the people's wall forces).
void AppendFootprint(const ShapeDescription& s, int obstacle, std::vector<WallSegment>* out) {
  const auto f = CalcFloorFootprint(s, 0.1, 1.8);  // at body height
  if (!f) return;
  const Eigen::Vector2d h = f->size / 2;
  const Eigen::Vector2d corners[4] = {
      f->X_WF * Eigen::Vector2d(-h.x(), -h.y()), f->X_WF * Eigen::Vector2d(h.x(), -h.y()),
      f->X_WF * Eigen::Vector2d(h.x(), h.y()), f->X_WF * Eigen::Vector2d(-h.x(), h.y())};
  for (int i = 0; i < 4; ++i)
    out->push_back({corners[i], corners[(i + 1) % 4], obstacle});
}

// Appends quad a-b-c-d (counter-clockwise seen from outside) as two triangles.
void AppendQuad(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                const Eigen::Vector3d& d, btTriangleMesh* mesh) {
  mesh->addTriangle(ToBt(a), ToBt(b), ToBt(c));
  mesh->addTriangle(ToBt(a), ToBt(c), ToBt(d));
}

// Appends a static box's, plane's or mesh's triangles, in W, to `mesh`; false for other kinds.
bool AppendTriangles(const ShapeDescription& s, btTriangleMesh* mesh) {
  if (s.kind == ShapeKind::kBox) {
    const Eigen::Vector3d h = s.box_size / 2;
    auto corner = [&](int i) {
      return Eigen::Vector3d(s.X_WS * Eigen::Vector3d((i & 1) ? h.x() : -h.x(),
                                                      (i & 2) ? h.y() : -h.y(),
                                                      (i & 4) ? h.z() : -h.z()));
    };
    static constexpr int kFaces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                                         {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    for (const auto& f : kFaces)
      AppendQuad(corner(f[0]), corner(f[1]), corner(f[2]), corner(f[3]), mesh);
    return true;
  }
  if (s.kind == ShapeKind::kPlane) {
    // A finite quad (100 m square when the file gives no size) in the plane's frame.
    const double hx = s.plane_size.x() > 0 ? s.plane_size.x() / 2 : 50.0;
    const double hy = s.plane_size.y() > 0 ? s.plane_size.y() / 2 : 50.0;
    AppendQuad(s.X_WS * Eigen::Vector3d(-hx, -hy, 0), s.X_WS * Eigen::Vector3d(hx, -hy, 0),
               s.X_WS * Eigen::Vector3d(hx, hy, 0), s.X_WS * Eigen::Vector3d(-hx, hy, 0), mesh);
    return true;
  }
  if (s.kind == ShapeKind::kMesh) {
    for (const auto& t : s.mesh->triangles) {
      mesh->addTriangle(ToBt(s.X_WS * s.mesh->vertices[t[0]]),
                        ToBt(s.X_WS * s.mesh->vertices[t[1]]),
                        ToBt(s.X_WS * s.mesh->vertices[t[2]]));
    }
    return true;
  }
  return false;
}

// The convex static shapes; boxes, planes and meshes go into the merged triangle mesh
// (AppendTriangles) instead.
std::unique_ptr<btCollisionShape> MakeConvexShape(const ShapeDescription& s) {
  if (s.kind == ShapeKind::kSphere) return std::make_unique<btSphereShape>(s.radius);
  return std::make_unique<btCylinderShapeZ>(btVector3(s.radius, s.radius, s.length / 2));
}

}  // namespace

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

struct TwinWorld::Impl {
  struct Entity {
    EntityKind kind;
    std::string name;
    int index;  // into doors_/people_/payloads_ where that applies
    bool glass{false};
  };

  struct Door {
    const DoorDescription* desc{nullptr};
    std::optional<DoorOperatorSpec> spec;
    std::optional<AdaDoorOperator> op;
    std::vector<PushButton> buttons;     // one per push-button actuator, in spec order
    std::vector<ProximityPlate> plates;  // one per proximity-plate actuator, in spec order
    std::size_t next_open_at{0};
    btRigidBody* leaf{nullptr};
    btHingeConstraint* hinge{nullptr};
    double motor_sign{1.0};
    double reach{0.0};
    double angle{0.0};
    int presses{0};
    bool reported_open{false};
    bool reported_closed{true};
    DoorPhase last_phase{DoorPhase::kClosed};
    Eigen::Vector2d centre{Eigen::Vector2d::Zero()};  // doorway centre in the plane
    Eigen::Vector2d normal{Eigen::Vector2d::Zero()};  // doorway plane normal
    Eigen::Vector2d along{Eigen::Vector2d::Zero()};   // hinge → latch direction (closed)
  };

  struct Person {
    PersonState state;
    Walker walker;
    TriggerSpec trigger;
    double trigger_delay{0.0};
    double speed{1.3};
    std::vector<Eigen::Vector2d> route;  // waypoints still to go
    int door{-1};
    int wait_before_waypoint{-1};  // route index (counted from the start) of the doorway centre
    int reached{0};                // waypoints reached so far
    double stuck_for{0.0};         // [s] wanting to walk but not moving
    bool realigned{false};         // stepped back onto the door's axis once
    double hold_angle{0.0};
    double hold_duration{0.0};
    double hold_started{-1.0};
    double wait_started{-1.0};
    btRigidBody* body{nullptr};
  };

  struct Payload {
    PayloadSpec spec;
    btRigidBody* body{nullptr};
    double diameter{0.0};
    bool held{false};
    Pose3 X_GP;  // pose in the palm while held
  };

  Impl(const Scenario& s, const WorldDescription& w, std::uint64_t seed_in,
       std::shared_ptr<const RobotModel> model_in, TwinConfig cfg)
      : scenario(s),
        world(w),
        seed(seed_in),
        model(std::move(model_in)),
        config(cfg),
        dt(1.0 / cfg.physics_rate_hz) {
    ThrowUnless(model != nullptr, "TwinWorld: robot model is null");
    ThrowUnless(cfg.physics_rate_hz >= 60.0, "TwinWorld: physics_rate_hz must be at least 60");
    scenario.ValidateAgainst(world);
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
  }

  ~Impl() {
    for (auto& c : constraints)
      dynamics->removeConstraint(c.get());
    for (auto& b : bodies)
      dynamics->removeRigidBody(b.get());
  }

  int AddEntity(EntityKind kind, std::string name, int index, bool glass = false) {
    entities.push_back({kind, std::move(name), index, glass});
    return int(entities.size()) - 1;
  }

  btRigidBody* AddBody(std::unique_ptr<btCollisionShape> shape, const Pose3& X_W, double mass,
                       int group, int mask, int entity) {
    btVector3 inertia(0, 0, 0);
    if (mass > 0) shape->calculateLocalInertia(mass, inertia);
    auto state = std::make_unique<btDefaultMotionState>(ToBt(X_W));
    btRigidBody::btRigidBodyConstructionInfo info(mass, state.get(), shape.get(), inertia);
    auto body = std::make_unique<btRigidBody>(info);
    body->setUserIndex(entity);
    dynamics->addRigidBody(body.get(), group, mask);
    btRigidBody* raw = body.get();
    shapes.push_back(std::move(shape));
    states.push_back(std::move(state));
    bodies.push_back(std::move(body));
    return raw;
  }

  void MakeKinematic(btRigidBody* body) {
    body->setCollisionFlags(body->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
    body->setActivationState(DISABLE_DEACTIVATION);
  }

  // Static boxes, planes and meshes become one triangle mesh (one BVH for contacts); the entity
  // of each triangle is kept so rays and contacts still name the model they touch. Rays test
  // boxes and planes analytically (a slab test is far cheaper than a BVH walk over their
  // triangles) and only the meshes' triangles through their own BVH.
  void BuildStatics() {
    bool has_floor = false;
    auto merged = std::make_unique<btTriangleMesh>(true, false);
    auto ray_mesh = std::make_unique<btTriangleMesh>(true, false);
    auto add = [&](const ShapeDescription& s) {
      const bool floor = s.kind == ShapeKind::kPlane;
      has_floor = has_floor || floor;
      const int e = AddEntity(floor ? EntityKind::kFloor : EntityKind::kStatic, s.model, -1);
      if (!floor) AppendFootprint(s, e, &walls);
      if (AppendTriangles(s, merged.get())) {
        static_triangle_entity.resize(std::size_t(merged->getNumTriangles()), e);
        if (s.kind == ShapeKind::kBox || s.kind == ShapeKind::kPlane) {
          RayBox box;
          box.R_SW = s.X_WS.rotation().transpose();
          box.p_WS = s.X_WS.translation();
          box.half = s.kind == ShapeKind::kBox
                         ? Eigen::Vector3d(s.box_size / 2)
                         : Eigen::Vector3d(s.plane_size.x() > 0 ? s.plane_size.x() / 2 : 50.0,
                                           s.plane_size.y() > 0 ? s.plane_size.y() / 2 : 50.0, 0.0);
          box.entity = e;
          ray_boxes.push_back(box);
        } else {
          AppendTriangles(s, ray_mesh.get());
          ray_triangle_entity.resize(std::size_t(ray_mesh->getNumTriangles()), e);
        }
        return;
      }
      ray_targets.push_back(AddBody(MakeConvexShape(s), s.X_WS, 0.0, floor ? kGFloor : kGStatic,
                                    floor ? kMaskFloor : kMaskStatic, e));
    };
    for (const auto& s : world.shapes)
      add(s);
    for (const auto& s : scenario.obstacles)
      add(s);
    if (!has_floor) {
      ShapeDescription ground;
      ground.model = "ground_plane";
      ground.kind = ShapeKind::kPlane;
      add(ground);
    }
    if (merged->getNumTriangles() > 0) {
      auto shape = std::make_unique<btBvhTriangleMeshShape>(merged.get(), true);
      static_mesh_shape = shape.get();
      meshes.push_back(std::move(merged));
      static_mesh_body =
          AddBody(std::move(shape), Pose3(), 0.0, kGStatic, kMaskStatic, kMergedStatic);
    }
    if (ray_mesh->getNumTriangles() > 0) {
      auto shape = std::make_unique<btBvhTriangleMeshShape>(ray_mesh.get(), true);
      ray_mesh_shape = shape.get();
      meshes.push_back(std::move(ray_mesh));
      shapes.push_back(std::move(shape));
    }
  }

  // A collision object outside the dynamics world with a triangle version of `source`'s shape,
  // for ray casts only; it follows `source` (SyncRayProxies).
  void AddRayProxy(const btCollisionObject* source, const std::vector<btVector3>& triangles_local) {
    auto mesh = std::make_unique<btTriangleMesh>(true, false);
    for (std::size_t i = 0; i + 2 < triangles_local.size(); i += 3) {
      mesh->addTriangle(triangles_local[i], triangles_local[i + 1], triangles_local[i + 2]);
    }
    auto shape = std::make_unique<btBvhTriangleMeshShape>(mesh.get(), true);
    auto proxy = std::make_unique<btCollisionObject>();
    proxy->setCollisionShape(shape.get());
    proxy->setUserIndex(source->getUserIndex());
    proxy->setWorldTransform(source->getWorldTransform());
    ray_targets.push_back(proxy.get());
    ray_proxies.push_back({std::move(proxy), source});
    meshes.push_back(std::move(mesh));
    shapes.push_back(std::move(shape));
  }

  static std::vector<btVector3> BoxTriangles(const btVector3& h) {
    auto corner = [&](int i) {
      return btVector3((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(),
                       (i & 4) ? h.z() : -h.z());
    };
    static constexpr int kFaces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                                         {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    std::vector<btVector3> t;
    for (const auto& f : kFaces) {
      for (int k : {f[0], f[1], f[2], f[0], f[2], f[3]})
        t.push_back(corner(k));
    }
    return t;
  }

  // A 16-sided prism along `axis` (0 = x, 2 = z) circumscribing a cylinder or capsule.
  static std::vector<btVector3> PrismTriangles(double radius, double half_length, int axis) {
    constexpr int kSides = 16;
    const double r = radius / std::cos(M_PI / kSides);
    auto point = [&](int k, double h) {
      const double a = 2 * M_PI * k / kSides;
      const double u = r * std::cos(a), v = r * std::sin(a);
      return axis == 0 ? btVector3(h, u, v) : btVector3(u, v, h);
    };
    std::vector<btVector3> t;
    const btVector3 top = axis == 0 ? btVector3(half_length, 0, 0) : btVector3(0, 0, half_length);
    for (int k = 0; k < kSides; ++k) {
      const btVector3 a0 = point(k, -half_length), a1 = point(k + 1, -half_length);
      const btVector3 b0 = point(k, half_length), b1 = point(k + 1, half_length);
      for (const auto& p : {a0, a1, b1, a0, b1, b0, top, b0, b1, -top, a1, a0})
        t.push_back(p);
    }
    return t;
  }

  void BuildRayProxies() {
    for (const auto& d : doors)
      AddRayProxy(d.leaf, BoxTriangles(ToBt(d.desc->leaf_size / 2)));
    for (const auto& p : people)
      AddRayProxy(p.body, PrismTriangles(p.state.radius, kPersonHeight / 2, 2));
    for (const auto& p : payloads) {
      AddRayProxy(p.body, p.spec.kind == PayloadKind::kWaterBottle ? PrismTriangles(0.033, 0.105, 2)
                                                                   : PrismTriangles(0.02, 0.1, 0));
    }
  }

  // Const because ray casts are: the proxies are a cache of the bodies' poses.
  void SyncRayProxies() const {
    ray_proxies_stale = false;
    for (auto& [proxy, source] : ray_proxies)
      proxy->setWorldTransform(source->getWorldTransform());
    ray_target_aabbs.resize(ray_targets.size());
    for (std::size_t i = 0; i < ray_targets.size(); ++i) {
      ray_targets[i]->getCollisionShape()->getAabb(ray_targets[i]->getWorldTransform(),
                                                   ray_target_aabbs[i].first,
                                                   ray_target_aabbs[i].second);
    }
  }

  // The entity of a collision object; for the merged static mesh, of its triangle.
  int EntityOf(const btCollisionObject* object, int triangle) const {
    const int e = object->getUserIndex();
    if (e != kMergedStatic) return e;
    return triangle >= 0 && std::size_t(triangle) < static_triangle_entity.size()
               ? static_triangle_entity[std::size_t(triangle)]
               : -1;
  }

  void BuildDoors() {
    std::mt19937_64 rng(DeriveSeed(seed, 1));
    const double hold_override = scenario.randomize.hold_open_s.Sample(rng);
    for (std::size_t i = 0; i < world.doors.size(); ++i) {
      const DoorDescription& d = world.doors[i];
      Door door;
      door.desc = &d;
      for (const auto& spec : scenario.doors) {
        if (spec.door == d.name) door.spec = spec;
      }
      if (door.spec && scenario.randomize.hold_open_s.max > 0.0) {
        door.spec->timing.hold_open_s = hold_override;
      }
      const bool glass = door.spec && door.spec->glass;
      const int e = AddEntity(EntityKind::kDoor, d.name, int(i), glass);
      door.leaf = AddBody(std::make_unique<btBoxShape>(ToBt(d.leaf_size / 2)), d.X_WL, d.mass,
                          kGDoor, kMaskDoor, e);
      door.leaf->setFlags(door.leaf->getFlags() | BT_DISABLE_WORLD_GRAVITY);
      door.leaf->setGravity(btVector3(0, 0, 0));
      door.leaf->setActivationState(DISABLE_DEACTIVATION);
      door.leaf->setFriction(0.3);
      const Eigen::Vector3d pivot_L =
          d.X_WL.rotation().transpose() * (d.p_WH - d.X_WL.translation());
      const Eigen::Vector3d axis_L = d.X_WL.rotation().transpose() * d.axis_W;
      auto hinge = std::make_unique<btHingeConstraint>(*door.leaf, ToBt(pivot_L), ToBt(axis_L));
      // Which sign of Bullet's hinge angle opens the door: probe with a small opening.
      const btTransform closed = ToBt(d.X_WL);
      const btTransform probe = ToBt(d.CalcLeafPose(0.1));
      const btTransform fixed = hinge->getBFrame();
      const double a0 = hinge->getHingeAngle(closed * hinge->getAFrame(), fixed);
      const double a1 = hinge->getHingeAngle(probe * hinge->getAFrame(), fixed);
      door.motor_sign = a1 > a0 ? 1.0 : -1.0;
      if (door.motor_sign > 0)
        hinge->setLimit(a0, a0 + d.max_open_angle, 0.9, 0.3, 0.5);
      else
        hinge->setLimit(a0 - d.max_open_angle, a0, 0.9, 0.3, 0.5);
      door.hinge = hinge.get();
      dynamics->addConstraint(hinge.get(), true);
      constraints.push_back(std::move(hinge));
      door.reach = d.LeafReach();
      const Eigen::Vector3d edge = d.CalcFreeEdge(0.0);
      door.along = (edge - d.p_WH).head<2>().normalized();
      door.centre = d.p_WH.head<2>() + door.along * door.reach / 2;
      door.normal = Eigen::Vector2d(-door.along.y(), door.along.x());
      if (door.spec) {
        door.op.emplace(door.spec->timing, d.max_open_angle);
        for (const auto& actuator : door.spec->actuators) {
          const ShapeDescription& a = *world.ShapesOfModel(actuator).front();
          ActuatorBox box{a.X_WS, a.box_size};
          if (door.spec->kind == OperatorKind::kPushButton) {
            door.buttons.emplace_back(box, door.spec->button_stroke, door.spec->button_spring_force,
                                      door.spec->button_max_force);
          } else if (door.spec->kind == OperatorKind::kProximityPlate) {
            door.plates.emplace_back(box, door.spec->proximity_range);
          }
        }
      }
      doors.push_back(std::move(door));
    }
  }

  void BuildRobot() {
    std::mt19937_64 rng(DeriveSeed(seed, 2));
    const auto& r = scenario.randomize;
    Pose2 start = scenario.robot_start;
    start.x += r.robot_dx.Sample(rng);
    start.y += r.robot_dy.Sample(rng);
    start.yaw = WrapAngle(start.yaw + r.robot_dyaw.Sample(rng));
    robot_radius = model->footprint_radius();
    const int e = AddEntity(EntityKind::kRobotBase, "hsrb", -1);
    const Pose3 X_WB =
        Pose3::FromPose2(start) * Pose3(Eigen::Vector3d(0, 0, 0.02 + kRobotBodyHeight / 2));
    base = AddBody(std::make_unique<btCylinderShapeZ>(
                       btVector3(robot_radius, robot_radius, kRobotBodyHeight / 2)),
                   X_WB, config.robot_mass, kGBase, kMaskBase, e);
    base->setFlags(base->getFlags() | BT_DISABLE_WORLD_GRAVITY);
    base->setGravity(btVector3(0, 0, 0));
    base->setLinearFactor(btVector3(1, 1, 0));
    base->setAngularFactor(btVector3(0, 0, 1));
    base->setActivationState(DISABLE_DEACTIVATION);
    base->setFriction(0.0);
    // Arm at the HSR's "go" pose (tucked): flex 0, roll −π/2, wrist −π/2.
    arm_q = {{"arm_lift_joint", 0.0},       {"arm_flex_joint", 0.0},
             {"arm_roll_joint", -M_PI / 2}, {"wrist_flex_joint", -M_PI / 2},
             {"wrist_roll_joint", 0.0},     {"head_pan_joint", 0.0},
             {"head_tilt_joint", 0.0}};
    for (auto& [name, q] : arm_q) {
      const JointLimits lim = model->GetJointLimits(name);
      q = std::clamp(q, lim.lower, lim.upper);
    }
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
    const int fe = AddEntity(EntityKind::kRobotArm, "hsrb_forearm", -1);
    forearm_body =
        AddBody(std::make_unique<btCapsuleShapeZ>(0.045, 0.2), Pose3(), 0.0, kGArm, kMaskArm, fe);
    MakeKinematic(forearm_body);
    UpdateArmBodies();
  }

  void BuildPayloads() {
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

  // A payload that starts inside furniture, a wall or another payload is thrown out by the first
  // physics step (a bottle tipped over by the books it overlaps): the scenario's placement, or
  // its randomization, is wrong, and the run would not test what the scenario says.
  void CheckPayloadClear(const Payload& p) const {
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
          other = a->getCollisionObject() == self
                      ? impl->EntityOf(b->getCollisionObject(), index_b)
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

  void BuildPeople() {
    std::mt19937_64 rng(DeriveSeed(seed, 4));
    // Its own stream: a scenario without the range draws exactly what it drew before.
    std::mt19937_64 hold_rng(DeriveSeed(seed, 5));
    const auto& r = scenario.randomize;
    for (const auto& spec : scenario.people) {
      const int count = spec.behavior == PersonBehavior::kEvacuate ? spec.count : 1;
      const int columns = int(std::ceil(std::sqrt(double(count))));
      for (int k = 0; k < count; ++k) {
        Person p;
        p.state.name = count == 1 ? spec.name : spec.name + "_" + std::to_string(k);
        p.state.behavior = spec.behavior;
        p.state.radius = spec.radius;
        p.state.phase = "waiting";
        // A group stands in a grid around its start, 2.2 radii apart.
        Eigen::Vector2d offset = Eigen::Vector2d::Zero();
        if (count > 1) {
          offset = Eigen::Vector2d((k % columns) - (columns - 1) / 2.0,
                                   (k / columns) - (columns - 1) / 2.0) *
                   2.2 * spec.radius;
        }
        p.walker.position = spec.start + offset;
        p.walker.radius = spec.radius;
        p.walker.desired_speed = 0.0;
        p.walker.target = p.walker.position;
        p.speed = spec.speed.Sample(rng) * r.person_speed_scale.Sample(rng);
        p.trigger = spec.trigger;
        p.trigger_delay = r.person_delay_s.Sample(rng) + (count > 1 ? 0.3 * k : 0.0);
        p.door = spec.door.empty() ? -1 : FindDoor(spec.door);
        p.hold_angle = spec.hold_angle_deg * kDegToRad;
        if (spec.behavior == PersonBehavior::kHoldDoor && r.hold_angle_deg.max > 0.0)
          p.hold_angle = r.hold_angle_deg.Sample(hold_rng) * kDegToRad;
        p.hold_duration = spec.hold_duration;
        p.state.position = p.walker.position;
        BuildRoute(spec, &p);
        const int e = AddEntity(EntityKind::kPerson, p.state.name, int(people.size()));
        const Pose3 X_W(
            Eigen::Vector3d(p.walker.position.x(), p.walker.position.y(), kPersonHeight / 2));
        p.body =
            AddBody(std::make_unique<btCapsuleShapeZ>(spec.radius, kPersonHeight - 2 * spec.radius),
                    X_W, 0.0, kGPerson, kMaskPerson, e);
        MakeKinematic(p.body);
        people.push_back(std::move(p));
        states_cache.push_back(people.back().state);
      }
    }
  }

  int FindDoor(const std::string& name) const {
    for (std::size_t i = 0; i < world.doors.size(); ++i) {
      if (world.doors[i].name == name) return int(i);
    }
    return -1;
  }

  void BuildRoute(const PersonSpec& spec, Person* p) {
    const Eigen::Vector2d start = p->walker.position;
    auto through_door = [&](int door_index) {
      const Door& d = doors[door_index];
      const double side = (start - d.centre).dot(d.normal) >= 0 ? 1.0 : -1.0;
      // People keep right: wait and leave kKeepRight to the right of the doorway's axis, so two
      // walkers crossing in opposite directions do not meet head-on at its ends.
      const Eigen::Vector2d heading = -d.normal * side;
      const Eigen::Vector2d right(heading.y(), -heading.x());
      p->route.push_back(d.centre - heading * 1.0 + right * kKeepRight);
      p->wait_before_waypoint = int(p->route.size());
      p->route.push_back(d.centre);
      p->route.push_back(d.centre + heading * 1.0 + right * kKeepRight);
    };
    switch (spec.behavior) {
      case PersonBehavior::kCrossDoorway:
      case PersonBehavior::kEvacuate:
        for (const auto& v : spec.via)
          p->route.push_back(v);
        through_door(p->door);
        p->route.push_back(spec.goal);
        break;
      case PersonBehavior::kHoldDoor: {
        const Door& d = doors[p->door];
        const double side = (start - d.centre).dot(d.normal) >= 0 ? 1.0 : -1.0;
        // Beside the hinge jamb on the person's side, out of the doorway.
        p->route.push_back(d.desc->p_WH.head<2>() - d.along * 0.45 + d.normal * side * 0.45);
        break;
      }
      case PersonBehavior::kWalkPast:
      case PersonBehavior::kApproachAndWait:
        for (const auto& v : spec.via)
          p->route.push_back(v);
        p->route.push_back(spec.goal);
        break;
    }
  }

  // ----- per-step updates ------------------------------------------------------------
  bool HasEvent(const std::string& name) const { return fired_events.count(name) > 0; }

  void AddEvent(const std::string& kind, const std::string& subject,
                const std::string& detail = "") {
    events.push_back({time, kind, subject, detail});
    fired_events.insert(kind + ":" + subject);
  }

  void UpdatePeople() {
    const Pose2 X_WB = RobotPose();
    for (auto& p : people) {
      if (!p.state.started) {
        bool go = false;
        switch (p.trigger.kind) {
          case TriggerSpec::Kind::kImmediately:
            go = time >= p.trigger_delay;
            break;
          case TriggerSpec::Kind::kAtTime:
            go = time >= p.trigger.value + p.trigger_delay;
            break;
          case TriggerSpec::Kind::kRobotWithin:
            go = (X_WB.translation() - p.walker.position).norm() <= p.trigger.value;
            break;
          case TriggerSpec::Kind::kEvent:
            go = HasEvent(p.trigger.event);
            break;
        }
        if (go) {
          p.state.started = true;
          p.state.phase = "walking";
          AddEvent("person_started", p.state.name);
        }
        continue;
      }
      if (p.state.phase == "holding") {
        if (time - p.hold_started >= p.hold_duration) {
          p.state.phase = "walking";
          AddEvent("person_released_door", p.state.name, doors[p.door].desc->name);
          const PersonSpec* spec = FindSpec(p.state.name);
          if (spec != nullptr && (spec->goal - p.walker.position).norm() > 0.3)
            p.route.push_back(spec->goal);
        }
        continue;
      }
      if (p.state.phase == "standing") {
        if (p.state.behavior == PersonBehavior::kApproachAndWait && p.wait_started >= 0 &&
            time - p.wait_started >= p.hold_duration && p.hold_duration > 0) {
          p.state.phase = "done";
        }
        continue;
      }
      if (p.route.empty()) {
        p.walker.desired_speed = 0.0;
        if (p.state.behavior == PersonBehavior::kHoldDoor && p.hold_started < 0) {
          p.state.phase = "holding";
          p.hold_started = time;
          AddEvent("person_holding_door", p.state.name, doors[p.door].desc->name);
        } else if (p.state.phase != "done") {
          p.state.phase =
              p.state.behavior == PersonBehavior::kApproachAndWait ? "standing" : "done";
          if (p.wait_started < 0) p.wait_started = time;
        }
        continue;
      }
      // Wait in front of a door that is not open enough.
      p.walker.target = p.route.front();
      p.walker.final_target = p.route.size() == 1;
      p.walker.desired_speed = p.speed;
      if (p.door >= 0 && p.wait_before_waypoint >= 0 && PendingDoorWaypoint(p) &&
          (doors[p.door].angle < config.door_crossed_open_angle_deg * kDegToRad ||
           DoorwayTaken(p))) {
        p.state.phase = "waiting_for_door";
        p.walker.desired_speed = 0.0;
      } else if (p.state.phase == "waiting_for_door") {
        p.state.phase = "walking";
      }
      // Pushed against a jamb (a social-force local minimum, e.g. after making way for the
      // robot), a walker heading for the doorway steps back onto the door's axis and goes again.
      const bool heading_for_doorway =
          p.door >= 0 && p.reached == p.wait_before_waypoint && p.state.phase == "walking";
      p.stuck_for = heading_for_doorway && p.walker.velocity.norm() < 0.05 ? p.stuck_for + dt : 0.0;
      if (p.stuck_for > kStuckSec && !p.realigned) {
        const Door& d = doors[std::size_t(p.door)];
        const double side = (p.walker.position - d.centre).dot(d.normal) >= 0 ? 1.0 : -1.0;
        p.route.insert(p.route.begin(), d.centre + d.normal * side * 0.8);
        --p.reached;  // the doorway centre stays the next waypoint after this one
        p.realigned = true;
        p.stuck_for = 0.0;
        p.walker.target = p.route.front();
        p.walker.final_target = false;
      }
      const double reached_radius = p.route.size() == 1 ? 0.25 : 0.4;
      if ((p.walker.position - p.route.front()).norm() < reached_radius &&
          p.state.phase != "waiting_for_door") {
        p.route.erase(p.route.begin());
        ++p.reached;
      }
    }
    // Social forces: the robot is a disc to avoid; door leaves are walls.
    std::vector<Walker> walkers;
    walkers.reserve(people.size());
    for (const auto& p : people)
      walkers.push_back(p.walker);
    std::vector<WallSegment> all_walls = walls;
    for (const auto& d : doors) {
      all_walls.push_back({d.desc->p_WH.head<2>(), d.desc->CalcFreeEdge(d.angle).head<2>()});
    }
    const Twist2 V_B = RobotVelocity();
    const Eigen::Vector2d v_W = X_WB.rotation() * Eigen::Vector2d(V_B.vx, V_B.vy);
    const std::vector<DiscObstacle> discs = {{X_WB.translation(), v_W, robot_radius}};
    // Standing people do not integrate (they would drift under wall forces).
    sfm.Step(&walkers, discs, all_walls, dt);
    for (std::size_t i = 0; i < people.size(); ++i) {
      Person& p = people[i];
      if (!p.state.started) continue;
      p.walker = walkers[i];
      p.state.position = p.walker.position;
      p.state.velocity = p.walker.velocity;
      const btTransform T(
          btQuaternion::getIdentity(),
          btVector3(p.walker.position.x(), p.walker.position.y(), kPersonHeight / 2));
      p.body->getMotionState()->setWorldTransform(T);
      p.body->setWorldTransform(T);
    }
  }

  // Someone else is in the doorway: wait for them to come through (one at a time).
  bool DoorwayTaken(const Person& me) const {
    const Door& d = doors[me.door];
    for (const auto& other : people) {
      if (&other == &me || !other.state.started) continue;
      if ((other.walker.position - d.centre).norm() < 0.9) return true;
    }
    return false;
  }

  // True while the next waypoint is the doorway centre (the person has reached the approach
  // point and must not step into a closed door).
  static bool PendingDoorWaypoint(const Person& p) { return p.reached == p.wait_before_waypoint; }

  const PersonSpec* FindSpec(const std::string& person_name) const {
    for (const auto& s : scenario.people) {
      if (person_name == s.name || person_name.rfind(s.name + "_", 0) == 0) return &s;
    }
    return nullptr;
  }

  void UpdateRobot() {
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
    UpdateGripper();
  }

  WholeBodyVector Configuration() const {
    const Pose2 X_WB = RobotPose();
    WholeBodyVector q;
    q << X_WB.x, X_WB.y, X_WB.yaw, arm_q.at("arm_lift_joint"), arm_q.at("arm_flex_joint"),
        arm_q.at("arm_roll_joint"), arm_q.at("wrist_flex_joint"), arm_q.at("wrist_roll_joint");
    return q;
  }

  void UpdateArmBodies() {
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
      const Pose3 X_BR = model->CalcLinkPoseInBase("arm_roll_link", joints);
      const Pose3 X_BW = model->CalcLinkPoseInBase("wrist_flex_link", joints);
      X_BForearm_a = X_BR.translation();
      X_BForearm_b = X_BW.translation();
      arm_pose_cache_q = joints;
      arm_pose_cache_valid = true;
    }
    const Eigen::Vector3d a = X_WB * X_BForearm_a, b = X_WB * X_BForearm_b;
    const Eigen::Vector3d mid = (a + b) / 2;
    const Eigen::Vector3d dir =
        (b - a).norm() > 1e-6 ? Eigen::Vector3d((b - a).normalized()) : Eigen::Vector3d::UnitZ();
    const Eigen::Quaterniond rot =
        Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), dir);
    const btTransform F = ToBt(Pose3(rot, mid));
    forearm_body->getMotionState()->setWorldTransform(F);
    forearm_body->setWorldTransform(F);
  }

  void UpdateGripper() {
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
          hand_q = std::max(
              hand_q, kHandTouching + (kHandOpen - kHandTouching) * p.diameter / kHandMaxWidth);
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

  void Release() {
    Payload& p = payloads[held];
    p.held = false;
    dynamics->removeRigidBody(p.body);
    p.body->setCollisionFlags(p.body->getCollisionFlags() &
                              ~btCollisionObject::CF_KINEMATIC_OBJECT);
    p.body->setLinearVelocity(btVector3(0, 0, 0));
    p.body->setAngularVelocity(btVector3(0, 0, 0));
    p.body->forceActivationState(ACTIVE_TAG);
    dynamics->addRigidBody(p.body, kGPayload, kMaskPayload);
    AddEvent("release", p.spec.name);
    held = -1;
    grasp_tried.clear();
  }

  void UpdateActuators() {
    const std::vector<Eigen::Vector3d> hand_points = {fingertip, palm.translation()};
    for (std::size_t i = 0; i < doors.size(); ++i) {
      Door& d = doors[i];
      const std::string* triggered = nullptr;  // the actuator that opened the door this step
      for (std::size_t k = 0; k < d.buttons.size(); ++k) {
        const auto result = d.buttons[k].Update(fingertip);
        if (result == PushButton::Result::kPressed) {
          triggered = &d.spec->actuators[k];
        } else if (result == PushButton::Result::kOverForce) {
          AddEvent("button_overforce", d.desc->name, StrCat(d.buttons[k].force(), " N"));
        }
      }
      for (std::size_t k = 0; k < d.plates.size(); ++k) {
        if (d.plates[k].Update(hand_points)) triggered = &d.spec->actuators[k];
      }
      if (d.spec && d.next_open_at < d.spec->open_at.size() &&
          time >= d.spec->open_at[d.next_open_at]) {
        ++d.next_open_at;
        AddEvent("door_triggered", d.desc->name, "scheduled");
        d.op->Trigger(time);
      }
      if (triggered != nullptr) {
        ++d.presses;
        AddEvent("button_pressed", d.desc->name, *triggered);
        d.op->Trigger(time);
      }
    }
  }

  double MeasureDoorAngle(const Door& d) const {
    const Eigen::Matrix3d R =
        FromBt(d.leaf->getWorldTransform()).rotation() * d.desc->X_WL.rotation().transpose();
    const double about_axis = std::atan2(R(1, 0), R(0, 0)) * (d.desc->axis_W.z() > 0 ? 1.0 : -1.0);
    return std::max(0.0, d.desc->open_sign * about_axis);
  }

  void UpdateDoors() {
    for (std::size_t i = 0; i < doors.size(); ++i) {
      Door& d = doors[i];
      d.angle = MeasureDoorAngle(d);
      const double stall_impulse = (d.spec ? d.spec->timing.stall_force : 67.0) * d.reach * dt;
      if (d.op) {
        const double rate = d.op->Update(time, d.angle);
        d.hinge->enableAngularMotor(true, d.motor_sign * rate, stall_impulse);
        if (d.op->phase() != d.last_phase) {
          AddEvent(StrCat("door_", ToString(d.op->phase())), d.desc->name);
          d.last_phase = d.op->phase();
        }
      } else {
        // A manual door with a closer: gently back to closed (≥ 5 s from 90° to 12°).
        const double closer_rate = d.angle > AdaDoorOperator::kClosedAngle ? -0.25 : 0.0;
        d.hinge->enableAngularMotor(true, d.motor_sign * closer_rate, 15.0 * d.reach * dt);
      }
      const btVector3 axis = ToBt(d.desc->axis_W * d.desc->open_sign);
      const double omega = d.leaf->getAngularVelocity().dot(axis);
      btVector3 torque = -d.desc->damping * omega * axis;
      // People holding this door push it towards their hold angle.
      for (const auto& p : people) {
        if (p.state.phase != "holding" || p.door != int(i)) continue;
        const double max_torque = config.person_hold_force * d.reach;
        const double tau =
            std::clamp(1000.0 * (p.hold_angle - d.angle) - 100.0 * omega, -max_torque, max_torque);
        torque += tau * axis;
      }
      d.leaf->applyTorque(torque);
      const double open_threshold = config.door_crossed_open_angle_deg * kDegToRad;
      if (!d.reported_open && d.angle >= open_threshold) {
        d.reported_open = true;
        d.reported_closed = false;
        AddEvent("door_opened", d.desc->name);
      } else if (!d.reported_closed && d.angle <= AdaDoorOperator::kClosedAngle) {
        d.reported_closed = true;
        d.reported_open = false;
        AddEvent("door_closed", d.desc->name);
      }
    }
  }

  void RecordContacts() {
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

  void FollowHeldPayload() {
    if (held < 0) return;
    const btTransform T = ToBt(palm * payloads[held].X_GP);
    payloads[held].body->getMotionState()->setWorldTransform(T);
    payloads[held].body->setWorldTransform(T);
  }

  void StepOnce() {
    UpdatePeople();
    UpdateRobot();
    UpdateArmBodies();
    FollowHeldPayload();
    UpdateActuators();
    UpdateDoors();
    dynamics->stepSimulation(dt, 1, dt);
    ++step;
    time = double(step) * dt;
    UpdateArmBodies();
    FollowHeldPayload();
    RecordContacts();
    for (std::size_t i = 0; i < people.size(); ++i)
      states_cache[i] = people[i].state;
    ray_proxies_stale = true;  // re-posed before the next ray cast (sensors run at 5-40 Hz)
  }

  Pose2 RobotPose() const {
    const btTransform& T = base->getWorldTransform();
    const btVector3 x = T.getBasis().getColumn(0);
    return {T.getOrigin().x(), T.getOrigin().y(), std::atan2(x.y(), x.x())};
  }

  // The base's actual velocity in B (what the wheels do, not what was commanded).
  Twist2 RobotVelocity() const {
    const Pose2 X_WB = RobotPose();
    const btVector3 v = base->getLinearVelocity();
    const Eigen::Vector2d v_B = X_WB.rotation().transpose() * Eigen::Vector2d(v.x(), v.y());
    return {v_B.x(), v_B.y(), base->getAngularVelocity().z()};
  }

  Scenario scenario;
  WorldDescription world;
  std::uint64_t seed;
  std::shared_ptr<const RobotModel> model;
  TwinConfig config;
  double dt;
  std::uint64_t step{0};
  double time{0.0};

  std::unique_ptr<btDefaultCollisionConfiguration> collision_config;
  std::unique_ptr<btCollisionDispatcher> dispatcher;
  std::unique_ptr<btDbvtBroadphase> broadphase;
  std::unique_ptr<btSequentialImpulseConstraintSolver> solver;
  std::unique_ptr<btDiscreteDynamicsWorld> dynamics;
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btStridingMeshInterface>> meshes;
  std::vector<std::unique_ptr<btMotionState>> states;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  std::vector<std::unique_ptr<btTypedConstraint>> constraints;

  static constexpr int kMergedStatic = -2;  // user index of the merged static mesh body
  std::vector<int> static_triangle_entity;
  btBvhTriangleMeshShape* static_mesh_shape{nullptr};
  btRigidBody* static_mesh_body{nullptr};
  // Static boxes and planes (half extent 0 along the normal) for analytic ray tests.
  struct RayBox {
    Eigen::Matrix3d R_SW;  // world to shape
    Eigen::Vector3d p_WS;
    Eigen::Vector3d half;
    int entity{-1};
  };
  std::vector<RayBox> ray_boxes;
  btBvhTriangleMeshShape* ray_mesh_shape{nullptr};  // the static meshes only, for rays
  std::vector<int> ray_triangle_entity;
  struct RayProxy {
    std::unique_ptr<btCollisionObject> proxy;
    const btCollisionObject* source;
  };
  std::vector<RayProxy> ray_proxies;
  std::vector<const btCollisionObject*> ray_targets;  // cast one by one in CastRay
  mutable std::vector<std::pair<btVector3, btVector3>> ray_target_aabbs;  // their world bounds
  mutable bool ray_proxies_stale{true};  // bodies moved since the proxies were posed

  RayHit CastSegment(const Eigen::Vector3d& from, const Eigen::Vector3d& to, GlassMode mode,
                     double glass_max_incidence) const;
  // The ray callbacks' views of the entities, made once rather than per ray.
  const std::function<bool(int)> ray_is_glass = [this](int e) {
    return e >= 0 && entities[std::size_t(e)].glass;
  };
  const std::function<int(const btCollisionObject*, int)> ray_entity_of =
      [this](const btCollisionObject* o, int t) { return EntityOf(o, t); };
  std::vector<Entity> entities;
  std::vector<Door> doors;
  std::vector<Person> people;
  std::vector<PersonState> states_cache;
  std::vector<Payload> payloads;
  std::vector<WallSegment> walls;
  SocialForceModel sfm;

  btRigidBody* base{nullptr};
  btRigidBody* hand_body{nullptr};
  btRigidBody* forearm_body{nullptr};
  double robot_radius{0.215};
  Twist2 command;
  Twist2 current;
  double last_command_time{-1e9};
  std::map<std::string, double> arm_q;
  std::optional<JointTrajectory> trajectory;
  std::vector<double> trajectory_q0;
  double trajectory_start{0.0};
  double hand_q{kHandOpen};
  GripperCommand gripper_command;
  int held{-1};
  std::set<int> grasp_tried;
  Pose3 palm;
  Eigen::Vector3d fingertip{Eigen::Vector3d::Zero()};
  Eigen::Vector3d X_BForearm_a{Eigen::Vector3d::Zero()}, X_BForearm_b{Eigen::Vector3d::Zero()};
  std::vector<std::pair<std::string, double>> arm_pose_cache_q;
  bool arm_pose_cache_valid{false};

  std::vector<TwinEvent> events;
  std::set<std::string> fired_events;
  std::set<std::pair<int, int>> touching;
  std::set<std::pair<int, int>> arm_touching, arm_touching_now;
};

TwinWorld::TwinWorld(const Scenario& scenario, const WorldDescription& world, std::uint64_t seed,
                     std::shared_ptr<const RobotModel> robot_model, TwinConfig config)
    : impl_(std::make_unique<Impl>(scenario, world, seed, std::move(robot_model), config)) {}

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
  impl_->trajectory = trajectory;
  impl_->trajectory_q0 = std::move(q0);
  impl_->trajectory_start =
      trajectory.start.count() == 0 ? impl_->time : ToSeconds(trajectory.start);
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
  return *impl_->doors.at(i).desc;
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

const std::vector<PersonState>& TwinWorld::people() const {
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
    out.push_back({door_is_glass(i) ? "glass_door" : "door", d.desc->name,
                   FromBt(d.leaf->getWorldTransform()), d.desc->leaf_size / 2,
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

namespace {

class TwinRayCallback : public btCollisionWorld::RayResultCallback {
 public:
  TwinRayCallback(const btVector3& dir, GlassMode mode, double glass_max_incidence,
                  const std::function<bool(int)>& is_glass,
                  const std::function<int(const btCollisionObject*, int)>& entity_of)
      : dir_(dir.normalized()),
        mode_(mode),
        glass_max_incidence_(glass_max_incidence),
        is_glass_(is_glass),
        entity_of_(entity_of) {}

  btScalar addSingleResult(btCollisionWorld::LocalRayResult& r, bool normal_in_world) override {
    const btVector3 n =
        normal_in_world ? r.m_hitNormalLocal
                        : r.m_collisionObject->getWorldTransform().getBasis() * r.m_hitNormalLocal;
    const int entity =
        entity_of_(r.m_collisionObject,
                   r.m_localShapeInfo != nullptr ? r.m_localShapeInfo->m_triangleIndex : -1);
    const bool glass = is_glass_(entity);
    if (glass && (mode_ == GlassMode::kTransparent ||
                  (mode_ == GlassMode::kLaser &&
                   std::abs(n.normalized().dot(dir_)) < std::cos(glass_max_incidence_)))) {
      return m_closestHitFraction;  // the ray passes through the glass
    }
    m_closestHitFraction = r.m_hitFraction;
    m_collisionObject = r.m_collisionObject;
    normal = n;
    this->entity = entity;
    this->glass = glass;
    return r.m_hitFraction;
  }

  btVector3 normal{0, 0, 0};
  int entity{-1};
  bool glass{false};

 private:
  btVector3 dir_;
  GlassMode mode_;
  double glass_max_incidence_;  // [rad]; its cosine is needed only on a glass hit
  const std::function<bool(int)>& is_glass_;
  const std::function<int(const btCollisionObject*, int)>& entity_of_;
};

// The static triangle mesh's hits, passed on to the twin's ray callback. The mesh may be cast on
// a piece [0, scale] of the twin's ray; fractions are rescaled to the whole ray.
class StaticMeshRayCallback : public btTriangleRaycastCallback {
 public:
  StaticMeshRayCallback(const btVector3& from, const btVector3& to, btScalar scale,
                        const btCollisionObject* mesh, TwinRayCallback* out,
                        const std::vector<int>& triangle_entity)
      : btTriangleRaycastCallback(from, to),
        scale_(scale),
        mesh_(mesh),
        out_(out),
        triangle_entity_(triangle_entity) {}
  btScalar reportHit(const btVector3& normal, btScalar fraction, int, int triangle) override {
    const btScalar whole = fraction * scale_;
    if (whole >= out_->m_closestHitFraction) return m_hitFraction;
    out_->m_closestHitFraction = whole;
    out_->m_collisionObject = mesh_;
    out_->normal = normal;
    out_->entity = triangle >= 0 && std::size_t(triangle) < triangle_entity_.size()
                       ? triangle_entity_[std::size_t(triangle)]
                       : -1;
    out_->glass = false;
    return fraction;
  }

 private:
  btScalar scale_;
  const btCollisionObject* mesh_;
  TwinRayCallback* out_;
  const std::vector<int>& triangle_entity_;
};

}  // namespace

RayHit TwinWorld::Impl::CastSegment(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                                    GlassMode mode, double glass_max_incidence) const {
  const btVector3 a = ToBt(from), b = ToBt(to);
  TwinRayCallback cb(b - a, mode, glass_max_incidence, ray_is_glass, ray_entity_of);
  // Bullet's ray tests, object by object rather than through the broadphase: first the cheap
  // targets (the ground plane, and every other target whose bounding box the ray still crosses
  // before its closest hit so far), then the static triangle mesh on the ray clipped just past
  // that hit: the mesh's BVH walk costs in proportion to the ray's length. Dynamic bodies are
  // cast as triangle proxies of their shapes (see BuildRayProxies): Bullet's triangle ray test
  // is exact and much cheaper than its iterative convex cast.
  const btTransform from_T(btMatrix3x3::getIdentity(), a), to_T(btMatrix3x3::getIdentity(), b);
  for (std::size_t i = 0; i < ray_targets.size(); ++i) {
    const btCollisionObject* target = ray_targets[i];
    btVector3 normal;
    btScalar param = cb.m_closestHitFraction;
    const bool plane = target->getCollisionShape()->getShapeType() == STATIC_PLANE_PROXYTYPE;
    if (!plane &&
        !btRayAabb(a, b, ray_target_aabbs[i].first, ray_target_aabbs[i].second, param, normal))
      continue;
    btCollisionWorld::rayTestSingle(from_T, to_T, const_cast<btCollisionObject*>(target),
                                    target->getCollisionShape(), target->getWorldTransform(), cb);
  }
  // Static boxes and planes: slab tests in each shape's frame, on the ray as a segment t in
  // [0, 1]. A ray starting inside a box hits its far side (as the triangles' did).
  const Eigen::Vector3d d = to - from;
  for (const RayBox& box : ray_boxes) {
    const Eigen::Vector3d o = box.R_SW * (from - box.p_WS);
    const Eigen::Vector3d v = box.R_SW * d;
    double t_in = -std::numeric_limits<double>::infinity();
    double t_out = std::numeric_limits<double>::infinity();
    int axis_in = -1, axis_out = -1;
    bool miss = false;
    for (int i = 0; i < 3 && !miss; ++i) {
      if (std::abs(v[i]) < 1e-12) {
        miss = std::abs(o[i]) > box.half[i] || box.half[i] == 0.0;
        continue;
      }
      double ta = (-box.half[i] - o[i]) / v[i], tb = (box.half[i] - o[i]) / v[i];
      if (ta > tb) std::swap(ta, tb);
      if (ta > t_in) {
        t_in = ta;
        axis_in = i;
      }
      if (tb < t_out) {
        t_out = tb;
        axis_out = i;
      }
      miss = t_in > t_out;
    }
    if (miss) continue;
    const bool inside = t_in < 0.0;
    const double t = inside ? t_out : t_in;
    const int axis = inside ? axis_out : axis_in;
    if (axis < 0 || t < 0.0 || t >= cb.m_closestHitFraction) continue;
    // Outward normal of the face the ray meets.
    const double sign = (v[axis] > 0.0) == inside ? 1.0 : -1.0;
    cb.m_closestHitFraction = btScalar(t);
    cb.m_collisionObject = static_mesh_body;
    cb.normal = ToBt(box.R_SW.row(axis).transpose() * sign);
    cb.entity = box.entity;
    cb.glass = false;
  }
  if (ray_mesh_shape != nullptr) {
    // A hair past the closest hit, so that a mesh standing on the floor still wins the tie.
    const btScalar scale = std::min<btScalar>(1.0, cb.m_closestHitFraction * 1.001 + 1e-6);
    const btVector3 b_clipped = a + (b - a) * scale;
    StaticMeshRayCallback mesh_cb(a, b_clipped, scale, static_mesh_body, &cb, ray_triangle_entity);
    ray_mesh_shape->performRaycast(&mesh_cb, a, b_clipped);
  }
  RayHit hit;
  if (!cb.hasHit()) return hit;
  hit.hit = true;
  hit.distance = cb.m_closestHitFraction * (to - from).norm();
  hit.point = from + cb.m_closestHitFraction * (to - from);
  hit.normal = FromBt(cb.normal).normalized();
  hit.entity = cb.entity;
  hit.glass = cb.glass;
  return hit;
}

RayHit TwinWorld::CastRay(const Eigen::Vector3d& from, const Eigen::Vector3d& to, GlassMode mode,
                          double glass_max_incidence) const {
  // The sensors see doors, people and payloads where they are now.
  if (impl_->ray_proxies_stale) impl_->SyncRayProxies();
  // Cast near first, then the rest: most rays indoors hit within a few metres, and a hit in the
  // near piece skips the far piece's walk of the BVH.
  constexpr double kNearSegment = 3.0;  // [m]
  const double length = (to - from).norm();
  if (length > 1.5 * kNearSegment) {
    const Eigen::Vector3d mid = from + (to - from) * (kNearSegment / length);
    RayHit near = impl_->CastSegment(from, mid, mode, glass_max_incidence);
    if (near.hit) return near;
    RayHit far = impl_->CastSegment(mid, to, mode, glass_max_incidence);
    if (far.hit) far.distance += kNearSegment;
    return far;
  }
  return impl_->CastSegment(from, to, mode, glass_max_incidence);
}

EntityKind TwinWorld::entity_kind(int entity) const {
  return impl_->entities.at(std::size_t(entity)).kind;
}
const std::string& TwinWorld::entity_name(int entity) const {
  return impl_->entities.at(std::size_t(entity)).name;
}

const Scenario& TwinWorld::scenario() const {
  return impl_->scenario;
}
const WorldDescription& TwinWorld::world() const {
  return impl_->world;
}
const TwinConfig& TwinWorld::config() const {
  return impl_->config;
}
std::uint64_t TwinWorld::seed() const {
  return impl_->seed;
}

}  // namespace egress::twin
