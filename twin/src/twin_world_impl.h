#pragma once
// Internal to twin/src: TwinWorld's implementation state (TwinWorld::Impl) and the helpers its
// parts share. The Impl's methods live by concern: twin_world.cpp (building, stepping, contacts
// and the public API), twin_statics.cpp (walls and furniture, ray proxies), twin_doors.cpp (leaves,
// ADA operators, actuators), twin_crowd.cpp (people), twin_robot_body.cpp (base, arm, gripper,
// payloads), twin_rays.cpp (ray casting for the sensors).

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
namespace world_detail {

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
// [m] beyond an open leaf's free edge a walker blocked by the leaf steps round it: a shoulder
// (0.25 m) and a margin
constexpr double kStepRoundLeaf = 0.45;
constexpr double kKeepRight = 0.2;  // [m] off the doorway axis, clear of a 0.9 m door's jambs
constexpr int kMaskPerson = kGStatic | kGDoor | kGBase | kGArm | kGPayload;
constexpr int kMaskPayload = kGStatic | kGFloor | kGDoor | kGBase | kGArm | kGPerson | kGPayload;

constexpr double kPersonHeight = 1.7;  // [m]
// [m] height of the solid round base whose inertia the trunk is given (the wheels' torque
// limit assumes it)
constexpr double kRobotBodyHeight = 1.0;
constexpr double kHandOpen = 1.24;          // hand_motor_joint fully open [rad]
constexpr double kHandTouching = -0.3;      // fingertips meet [rad]
constexpr double kHandMaxWidth = 0.135;     // finger gap when fully open [m]
constexpr double kHandSpeed = 1.0;          // [rad/s] (URDF limit)
constexpr double kGraspDepthInPalm = 0.07;  // grasp centre along the palm's approach z [m]
constexpr double kDegToRad = M_PI / 180.0;
// A payload may start this deep in what it stands on (contact margins), no deeper [m].
constexpr double kPayloadStartOverlapTolerance = 0.002;

inline btVector3 ToBt(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}
inline Eigen::Vector3d FromBt(const btVector3& v) {
  return {v.x(), v.y(), v.z()};
}

inline btTransform ToBt(const Pose3& X) {
  const Eigen::Quaterniond q = X.quaternion();
  return btTransform(btQuaternion(q.x(), q.y(), q.z(), q.w()), ToBt(X.translation()));
}

inline Pose3 FromBt(const btTransform& T) {
  const btQuaternion q = T.getRotation();
  return Pose3(Eigen::Quaterniond(q.w(), q.x(), q.y(), q.z()).normalized(), FromBt(T.getOrigin()));
}

inline double HandWidth(double hand_q) {
  return kHandMaxWidth *
         std::clamp((hand_q - kHandTouching) / (kHandOpen - kHandTouching), 0.0, 1.0);
}

// The links whose shapes make the robot's trunk (the base body): they move only with the lift
// and the head. The arm from its flex link on has its own kinematic bodies.
inline bool IsTrunkLink(std::string_view link) {
  return link == "base_link" || link == "torso_lift_link" || link == "head_pan_link" ||
         link == "head_tilt_link" || link == "arm_lift_link";
}
inline constexpr const char* kUpperArmLink = "arm_flex_link";

// A robot description's collision primitive as a Bullet shape (centred on its frame S).
inline std::unique_ptr<btCollisionShape> MakeRobotShape(const CollisionShape& s) {
  switch (s.kind) {
    case CollisionShape::Kind::kBox:
      return std::make_unique<btBoxShape>(ToBt(Eigen::Vector3d(s.size / 2)));
    case CollisionShape::Kind::kCylinder:
      return std::make_unique<btCylinderShapeZ>(btVector3(s.size.x(), s.size.x(), s.size.z() / 2));
    case CollisionShape::Kind::kSphere:
      break;
  }
  return std::make_unique<btSphereShape>(s.size.x());
}

// Outline segments of a static shape on the floor (for the people's wall forces).
inline void AppendFootprint(const ShapeDescription& s, int obstacle,
                            std::vector<WallSegment>* out) {
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
inline void AppendQuad(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                       const Eigen::Vector3d& d, btTriangleMesh* mesh) {
  mesh->addTriangle(ToBt(a), ToBt(b), ToBt(c));
  mesh->addTriangle(ToBt(a), ToBt(c), ToBt(d));
}

// Appends a static box's, plane's or mesh's triangles, in W, to `mesh`; false for other kinds.
inline bool AppendTriangles(const ShapeDescription& s, btTriangleMesh* mesh) {
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
inline std::unique_ptr<btCollisionShape> MakeConvexShape(const ShapeDescription& s) {
  if (s.kind == ShapeKind::kSphere) return std::make_unique<btSphereShape>(s.radius);
  return std::make_unique<btCylinderShapeZ>(btVector3(s.radius, s.radius, s.length / 2));
}

}  // namespace world_detail

namespace people {
class PersonBehaviorModel;  // people/person_behavior.h
}  // namespace people

namespace world_detail {
// A door in the run: its description (fixed) and its state.
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

// A person in the run.
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
  double blocked_for{0.0};       // [s] walking but not moving (any leg of the route)
  double hold_angle{0.0};
  double hold_duration{0.0};
  double hold_started{-1.0};
  double wait_started{-1.0};
  const people::PersonBehaviorModel* behavior{nullptr};  // owned by behavior_models
  btRigidBody* body{nullptr};
};

}  // namespace world_detail
using namespace world_detail;

struct TwinWorld::Impl {
  struct Entity {
    EntityKind kind;
    std::string name;
    int index;  // into doors_/people_/payloads_ where that applies
    bool glass{false};
  };

  using Door = world_detail::Door;
  using Person = world_detail::Person;

  struct Payload {
    PayloadSpec spec;
    btRigidBody* body{nullptr};
    double diameter{0.0};
    bool held{false};
    Pose3 X_GP;  // pose in the palm while held
  };

  Impl(const Scenario& s, const WorldDescription& w, std::uint64_t seed_in,
       std::shared_ptr<const RobotModel> model_in, TwinConfig cfg);

  ~Impl();

  int AddEntity(EntityKind kind, std::string name, int index, bool glass = false);

  btRigidBody* AddBody(std::unique_ptr<btCollisionShape> shape, const Pose3& X_W, double mass,
                       int group, int mask, int entity);

  void MakeKinematic(btRigidBody* body);

  // Static boxes, planes and meshes become one triangle mesh (one BVH for contacts); the entity
  // of each triangle is kept so rays and contacts still name the model they touch. Rays test
  // boxes and planes analytically (a slab test is far cheaper than a BVH walk over their
  // triangles) and only the meshes' triangles through their own BVH.
  void BuildStatics();

  // A collision object outside the dynamics world with a triangle version of `source`'s shape,
  // for ray casts only; it follows `source` (SyncRayProxies).
  void AddRayProxy(const btCollisionObject* source, const std::vector<btVector3>& triangles_local);

  static std::vector<btVector3> BoxTriangles(const btVector3& h);

  // A 16-sided prism along `axis` (0 = x, 2 = z) circumscribing a cylinder or capsule.
  static std::vector<btVector3> PrismTriangles(double radius, double half_length, int axis);

  void BuildRayProxies();

  // Const because ray casts are: the proxies are a cache of the bodies' poses.
  void SyncRayProxies() const;

  // The entity of a collision object; for the merged static mesh, of its triangle.
  int EntityOf(const btCollisionObject* object, int triangle) const;

  void BuildDoors();

  void BuildRobot();

  void BuildPayloads();

  // A payload that starts inside furniture, a wall or another payload is thrown out by the first
  // physics step (a bottle tipped over by the books it overlaps): the scenario's placement, or
  // its randomization, is wrong, and the run would not test what the scenario says.
  void CheckPayloadClear(const Payload& p) const;

  void BuildPeople();

  int FindDoor(const std::string& name) const;

  // ----- per-step updates ------------------------------------------------------------
  bool HasEvent(const std::string& name) const { return fired_events.count(name) > 0; }

  void AddEvent(const std::string& kind, const std::string& subject,
                const std::string& detail = "");

  void UpdatePeople();

  // Someone else is in the doorway: wait for them to come through (one at a time).
  bool DoorwayTaken(const Person& me) const;

  // True while the next waypoint is the doorway centre (the person has reached the approach
  // point and must not step into a closed door).
  static bool PendingDoorWaypoint(const Person& p) { return p.reached == p.wait_before_waypoint; }

  const PersonSpec* FindSpec(const std::string& person_name) const;

  void UpdateRobot();

  WholeBodyVector Configuration() const;

  void UpdateArmBodies();

  void UpdateGripper();

  void Release();

  void UpdateActuators();

  double MeasureDoorAngle(const Door& d) const;

  void UpdateDoors();

  void RecordContacts();

  void FollowHeldPayload();

  void StepOnce();

  Pose2 RobotPose() const;

  // The base's actual velocity in B (what the wheels do, not what was commanded).
  Twist2 RobotVelocity() const;

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
  // One model per people behaviour the scenario uses (the fixed model; Person is the run's state).
  std::map<PersonBehavior, std::unique_ptr<people::PersonBehaviorModel>> behavior_models;
  std::vector<PersonState> states_cache;
  std::vector<Payload> payloads;
  std::vector<WallSegment> walls;
  SocialForceModel sfm;

  btRigidBody* base{nullptr};
  btCompoundShape* trunk{nullptr};             // the base body's shape
  std::vector<std::size_t> trunk_shape_index;  // child -> CalcCollisionShapesInBase's index
  btRigidBody* upper_arm_body{nullptr};        // null when the description has no upper arm shape
  Pose3 X_BUpperArm;
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

}  // namespace egress::twin
