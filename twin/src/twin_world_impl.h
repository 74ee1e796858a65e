#pragma once
// Internal to twin/src: the state of one run (TwinWorld::Impl) over its fixed model
// (twin_model_compiled.h). The Impl's methods live by concern: twin_world.cpp (building,
// stepping, contacts and the public API), twin_statics.cpp (the model's statics as bodies of the
// run, ray proxies), twin_doors.cpp (leaves, ADA operators, actuators), twin_crowd.cpp (people),
// twin_robot_body.cpp (base, arm, gripper, payloads), twin_rays.cpp (ray casting for the
// sensors).

#include <map>
#include <optional>

#include "ray_convex.h"
#include "ray_fan.h"
#include "twin_model_compiled.h"

namespace egress::twin {
namespace world_detail {
// A door in the run: its fixed model and its state.
struct Door {
  const DoorModel* fixed{nullptr};       // its geometry and description (fixed->desc)
  std::optional<DoorOperatorSpec> spec;  // fixed->spec with the run's seeded hold time
  std::optional<AdaDoorOperator> op;
  std::vector<PushButton> buttons;     // one per push-button actuator, in spec order
  std::vector<ProximityPlate> plates;  // one per proximity-plate actuator, in spec order
  std::size_t next_open_at{0};
  btRigidBody* leaf{nullptr};
  btHingeConstraint* hinge{nullptr};
  double motor_sign{1.0};
  double angle{0.0};
  int presses{0};
  bool reported_open{false};
  bool reported_closed{true};
  DoorPhase last_phase{DoorPhase::kClosed};
};

// A person in the run.
struct Person {
  PersonState state;
  Walker walker;
  // [m/s²] The social terms' acceleration, summed every few steps and held between
  // (TwinConfig::crowd_social_rate_hz).
  Eigen::Vector2d social_acceleration{Eigen::Vector2d::Zero()};
  TriggerSpec trigger;
  double trigger_delay{0.0};  // [s] after the trigger's moment (RandomizeSpec::person_delay_s)
  double robot_came_within_at{-1.0};  // [s] when a robot_within trigger's condition first held
  double speed{1.3};
  std::vector<Eigen::Vector2d> route;  // waypoints still to go
  // An exit route's waypoints as planned (route rewinds to them when the crowd pushes someone
  // back through a doorway they had passed).
  std::vector<Eigen::Vector2d> planned_route;
  int door{-1};
  int wait_before_waypoint{-1};  // route index (counted from the start) of the doorway centre
  int reached{0};                // waypoints reached so far
  double stuck_for{0.0};         // [s] wanting to walk but not moving
  bool realigned{false};         // stepped back onto the door's axis once
  int round_leaf{-1};            // the door whose leaf the route's first waypoint goes round
  bool stepped_aside{false};     // walked to the side of the corridor at the end of its route
  std::optional<Eigen::Vector2d> aside_spot;  // where it then stands (held against the walls' push)
  double blocked_for{0.0};                    // [s] walking but not moving (any leg of the route)
  double slow_for{0.0};                       // [s] slower than kHeldUpMps (any phase)
  double give_way_until{-1.0};  // [s] stepping back for someone nearer the bottleneck until then
  Eigen::Vector2d give_way_spot{Eigen::Vector2d::Zero()};  // where it then steps back to
  // Through a doorway to where the waypoint is in sight (FindWayBackThroughDoorway): walked to
  // front first, ahead of the route, each dropped once reached.
  std::vector<Eigen::Vector2d> way_back;
  double hold_angle{0.0};
  double hold_duration{0.0};
  double hold_started{-1.0};
  double wait_started{-1.0};
  // Doorway centres of a multi-door route (evacuate's `route`): route index counted from the
  // start -> door index. A single-door behaviour uses door and wait_before_waypoint instead.
  std::map<int, int> doorway_waypoints;
  bool can_operate{false};   // operates a waiting door's actuator (evacuees; their class decides)
  double operate_time{1.5};  // [s] at the actuator until the door triggers
  int operating{-1};         // the door whose actuator they are going to or operating
  Eigen::Vector2d operate_spot{Eigen::Vector2d::Zero()};
  double operate_elapsed{0.0};      // [s] at the actuator so far
  double operate_progress_at{0.0};  // [s] when they set off for the actuator or were last at it
  double operate_retry_at{0.0};     // [s] not before this (after giving up)
  const people::PersonBehaviorModel* behavior{nullptr};  // the model's behaviour
  btRigidBody* body{nullptr};
  // Bullet's body sleeps while far from everything it can touch (Impl::WakeNearPeople); placing
  // it then keeps the transform it had before, from which Bullet takes its velocity on waking.
  bool body_asleep{false};
  btTransform body_before{btTransform::getIdentity()};  // the body's pose before the last placing
  std::uint64_t body_placed_step{0};                    // the physics step it was placed in
};

}  // namespace world_detail
using namespace world_detail;

// A run's state (MuJoCo's mjData to TwinModel's mjModel): the Bullet world with the run's
// bodies (the statics' shapes are the model's), and the doors, people, robot and payloads as
// this run's seed drew and moved them.
struct TwinWorld::Impl {
  using Entity = world_detail::Entity;
  using Door = world_detail::Door;
  using Person = world_detail::Person;

  struct Payload {
    PayloadSpec spec;
    btRigidBody* body{nullptr};
    double diameter{0.0};
    bool held{false};
    Pose3 X_GP;  // pose in the palm while held
  };

  Impl(std::shared_ptr<const TwinModel> twin_model_in, std::uint64_t seed_in);

  ~Impl();

  int AddEntity(EntityKind kind, std::string name, int index, bool glass = false);

  btRigidBody* AddBody(std::unique_ptr<btCollisionShape> shape, const Pose3& X_W, double mass,
                       int group, int mask, int entity);
  // A body whose shape someone else owns (the model's statics).
  btRigidBody* AddBodyWithShape(btCollisionShape* shape, const Pose3& X_W, double mass, int group,
                                int mask, int entity);

  void MakeKinematic(btRigidBody* body);

  // The model's statics as bodies of this run's Bullet world (their shapes are the model's).
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
  // When the event "kind:subject" first fired [s], if it has.
  std::optional<double> FirstEventTime(const std::string& name) const {
    const auto it = fired_events.find(name);
    return it == fired_events.end() ? std::nullopt : std::optional<double>(it->second);
  }

  void AddEvent(const std::string& kind, const std::string& subject,
                const std::string& detail = "");

  void UpdatePeople();
  // Between the people's steps: each body moved on at its velocity for one physics step.
  void CarryPeople();
  // The person's Bullet body to where its walker stands.
  void PlacePersonBody(Person& p);
  // Wakes the bodies of people within reach of the robot or a payload (the bodies people can
  // touch in Bullet) and puts the others to sleep: Bullet neither derives a sleeping kinematic
  // body's velocity nor updates its bounds, most of what 100 people cost it.
  void WakeNearPeople();

  // Someone else is in the doorway: wait for them to come through (one at a time).
  bool DoorwayTaken(const Person& me, int door) const;

  // True while the next waypoint is the doorway centre (the person has reached the approach
  // point and must not step into a closed door).
  static bool PendingDoorWaypoint(const Person& p) { return p.reached == p.wait_before_waypoint; }
  // An evacuee past a doorway of their route (pushed through by the crowd) resumes their route
  // beyond it; one pushed into it before reaching the waypoints before it, from its centre.
  void AdvancePastDoorways(Person& p) const;
  // Drops the route's waypoints before index `waypoint` of the whole route (p.reached indexes
  // the first remaining one), with any way round a leaf: every step on along the route.
  static void SkipRouteTo(Person& p, int waypoint);
  // Whether the crowd carried the person past their next waypoint (a via point along a corridor,
  // not a doorway's or the spot before one) towards the one after it, in sight of it: they go
  // on from there rather than back against the crowd (clinic two wards seed 26: a pushed
  // wheelchair swept 0.6 m past the point beyond door_d, on 10 m along the corridor by the
  // group behind, walked back the 10 m to it, meeting the robot in door_d's doorway).
  bool PassedWaypoint(const Person& p) const;
  // An evacuee stuck with a wall between them and their next waypoint, on the near side of a
  // doorway of their route they had passed (the crowd pushed them back through it), takes up
  // their route again from before that doorway.
  void RewindIfPushedBack(Person& p);
  // Stuck in a jam, a walker touching someone nearer the bottleneck (the next doorway of its
  // route, else its waypoint) steps back from it for kGiveWaySec: pressed on from behind and the
  // sides, the one ahead could not move on.
  void GiveWayIfJammed(Person& p);
  // Stuck with a wall between them and their waypoint (carried by the crowd through the doorway
  // of a room off their route), a walker goes back through the nearest open doorway in sight
  // from whose far side the waypoint is in sight (Person::way_back).
  void FindWayBackThroughDoorway(Person& p);
  // The door whose doorway centre is the person's next waypoint, or -1. Also, for an evacuee
  // held up (slower than kHeldUpMps for kHeldUpSec) within kQueueNearSpotM of the spot before a
  // shut door's doorway, that door: they queue for it where the crowd lets them stand.
  int GateDoor(const Person& p) const;
  // Where someone waiting at door `gate` who cannot operate it goes to keep the front of its
  // actuator clear for whoever can (a resident, the robot); nullopt: they are clear of it (or
  // can operate it).
  std::optional<Eigen::Vector2d> ClearOfActuator(const Person& p, int gate) const;
  // Where that person steps to be out of the robot's straight way to the actuator's `spot` on
  // their `side` of door `gate`, when the robot is on that side within kMakeWayForRobotM of it
  // and they stand in its way; nullopt otherwise.
  std::optional<Eigen::Vector2d> OutOfRobotsWayTo(const Person& p, int gate,
                                                  const Eigen::Vector2d& spot, double side) const;
  // Where a person on `side` (+1/-1 along the door's normal) stands to operate door `door`'s
  // actuator: in front of its free face, on their side of the door; nullopt if none is there.
  std::optional<Eigen::Vector2d> ActuatorSpot(int door, double side,
                                              const Eigen::Vector2d& p_W) const;
  // Per building actuator: the spot in front of it cleared of the walls, once found.
  mutable std::vector<std::optional<Eigen::Vector2d>> actuator_spots;
  // A waiting person who can goes to the actuator, operates it for their operate_time and
  // triggers the door; true while they are busy with it (their walker is set).
  bool OperateDoor(Person& p, int gate);

  const PersonSpec* FindSpec(const std::string& person_name) const;
  // Where a walker who has arrived at p stands out of the way: beside the nearest wall, off
  // any doorway (nullopt: no wall near).
  std::optional<Eigen::Vector2d> SpotBesideWall(const Eigen::Vector2d& p) const;
  // p moved out of every wall it is nearer than `clearance` to [m].
  Eigen::Vector2d ClearOfWalls(Eigen::Vector2d p, double clearance) const;
  // Whether a building wall (not a door leaf) crosses the straight way from a to b in W.
  bool WallBetween(const Eigen::Vector2d& a, const Eigen::Vector2d& b) const;
  // What a group's members may neither start on nor beyond, besides the walls (GroupLayout's
  // keep_off): the doorways' lines and the robot.
  std::vector<WallSegment> StartKeepOff() const;

  void UpdateRobot();

  WholeBodyVector Configuration() const;

  void UpdateArmBodies();

  void UpdateGripper();

  void Release();

  void UpdateActuators();

  double MeasureDoorAngle(const Door& d) const;

  void UpdateDoors();
  // Whether door d's leaf, as it turns now, swings into someone touching it.
  bool LeafSwingsIntoSomeone(const Door& d) const;

  void RecordContacts();

  void FollowHeldPayload();

  void StepOnce();
  // Fires the instantaneous faults whose time has come (kidnap, door closing early, grasp
  // slip): twin_faults.cpp.
  void DrawFaults();
  void ApplyFaults();
  bool DoorRefusesAt(const Door& d, double t) const;
  std::vector<TwinWorld::DrawnFault> faults;

  Pose2 RobotPose() const;

  // The base's actual velocity in B (what the wheels do, not what was commanded).
  Twist2 RobotVelocity() const;

  std::shared_ptr<const TwinModel> twin_model;
  const TwinModel::Compiled& fixed;
  const Scenario& scenario;
  const WorldDescription& world;
  std::uint64_t seed;
  std::shared_ptr<const RobotModel> model;
  const TwinConfig& config;
  double dt;
  // The people are stepped every crowd_every physics steps, crowd_dt [s] apart
  // (TwinConfig::crowd_rate_hz); between, CarryPeople moves their bodies on.
  std::uint64_t crowd_every;
  double crowd_dt;
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
  btRigidBody* static_mesh_body{nullptr};
  struct RayProxy {
    std::unique_ptr<btCollisionObject> proxy;
    const btCollisionObject* source;
    std::unique_ptr<world_detail::ConvexPolytope> body;  // its shape, in the source's frame
  };
  std::vector<RayProxy> ray_proxies;
  std::vector<const btCollisionObject*> ray_targets;  // cast one by one in CastRay
  // Per ray target: the proxy's polytope, cast analytically; null for Bullet shapes.
  std::vector<const world_detail::ConvexPolytope*> ray_target_polytopes;
  mutable std::vector<std::pair<btVector3, btVector3>> ray_target_aabbs;  // their world bounds
  // Their XY extents (a plane's infinite), binned for a single ray and for a fan.
  mutable std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> ray_target_extents;
  mutable world_detail::RayBins ray_target_bins;  // which ray_targets a ray may cross
  mutable bool ray_proxies_stale{true};           // bodies moved since the proxies were posed

  // The fraction of the segment from-to (W) past which a static plane (a floor) hides
  // everything, with a small margin; 1 when it crosses none.
  double PlaneClip(const Eigen::Vector3d& from, const Eigen::Vector3d& to) const;

  // The candidates of a fan of rays from one point (CastRayFan): the targets and the static
  // boxes by bearing from it.
  struct RayFanBins {
    world_detail::RayFan targets, boxes;
  };
  // The closest hit on the segment from-to; the candidates from `fan`'s `fan_bin` (a ray of the
  // fan from its origin, or the far piece of one) instead of the grid walks when given: the same
  // hit.
  RayHit CastSegment(const Eigen::Vector3d& from, const Eigen::Vector3d& to, GlassMode mode,
                     double glass_max_incidence, const RayFanBins* fan = nullptr,
                     long fan_bin = 0) const;
  // CastRay's near piece, then its far one.
  RayHit CastRayInPieces(const Eigen::Vector3d& from, const Eigen::Vector3d& to, GlassMode mode,
                         double glass_max_incidence, const RayFanBins* fan) const;
  // The ray callbacks' views of the entities, made once rather than per ray.
  const std::function<bool(int)> ray_is_glass = [this](int e) {
    return e >= 0 && entities[std::size_t(e)].glass;
  };
  const std::function<int(const btCollisionObject*, int)> ray_entity_of =
      [this](const btCollisionObject* o, int t) { return EntityOf(o, t); };
  std::vector<Entity> entities;
  std::vector<Door> doors;
  // The leaves' free edges on the floor (DoorDescription::CalcFreeEdge), per door, with the angle
  // each is at: the people's rules ask for them per person and step. Not in Door: GCC 12's
  // sanitizer build reads a grown Door's copy as maybe-uninitialized.
  mutable std::vector<std::pair<double, Eigen::Vector2d>> free_edges;
  // The free edge of `d` (an element of `doors`: its index keys the cache) at its angle now.
  Eigen::Vector2d FreeEdge(const Door& d) const;
  std::vector<Person> people;
  // What TwinWorld::people() returns: the people's states, copied from `people` when asked for
  // after a step (states_stale), not every physics step (their names are strings: ~1 % of a
  // 100-resident run). Steps are the only writers of the states, so it is the same copy.
  mutable std::vector<PersonState> states_cache;
  mutable bool states_stale{false};
  std::vector<Payload> payloads;
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
  std::optional<HeadCommand> head_command;
  int held{-1};
  std::set<int> grasp_tried;
  Pose3 palm;
  Eigen::Vector3d fingertip{Eigen::Vector3d::Zero()};
  Eigen::Vector3d X_BForearm_a{Eigen::Vector3d::Zero()}, X_BForearm_b{Eigen::Vector3d::Zero()};
  std::vector<std::pair<std::string, double>> arm_pose_cache_q;
  bool arm_pose_cache_valid{false};

  std::vector<TwinEvent> events;
  std::map<std::string, double> fired_events;  // "kind:subject" -> first time [s]
  std::set<std::pair<int, int>> touching;
  std::set<std::pair<int, int>> arm_touching, arm_touching_now;
};

}  // namespace egress::twin
