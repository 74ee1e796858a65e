#pragma once
// Internal to twin/src: the collision groups, constants and Bullet helpers that the compiled
// model (twin_model_compiled.h) and a run's state (twin_world_impl.h) share.

#include "egress/twin/twin_model.h"
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
// People are kinematic: against the (static) walls Bullet's contacts would do nothing (the
// social force model keeps them off walls), yet cost a convex-mesh test per person per step.
constexpr int kMaskStatic = kGBase | kGArm | kGPayload;
constexpr int kMaskFloor = kGPayload;
// People are not in the leaves' collisions: the social forces keep them off a leaf, and a leaf
// that swings into someone stops (TwinWorld::Impl::LeafSwingsIntoSomeone).
constexpr int kMaskDoor = kGBase | kGArm | kGPayload;
constexpr int kMaskBase = kGStatic | kGDoor | kGPerson | kGPayload;
constexpr int kMaskArm = kGStatic | kGDoor | kGPerson | kGPayload;
constexpr double kStuckSec =
    2.0;  // [s] a walker that wants to move but has not, this long, is stuck
// [m] beyond an open leaf's free edge a walker blocked by the leaf steps round it: a shoulder
// (0.25 m) and a margin
constexpr double kStepRoundLeaf = 0.45;
// [m] Off a doorway's midline, a step out of it onto one side: clear of the jambs and of a body
// in the doorway.
constexpr double kOutOfDoorwayM = 0.8;
constexpr double kKeepRight = 0.2;  // [m] off the doorway axis, clear of a 0.9 m door's jambs
// [m] People wait this far beyond the reach of a leaf that opens towards them: a wide body
// (0.3 m) and a margin.
constexpr double kClearOfSweepM = 0.45;
// [m] A waiting person steps this far (plus their radius) beyond the reach of a leaf opening
// towards them.
constexpr double kSweepMarginM = 0.1;
// [deg] A waiting person goes on once the leaf is this far past the open-enough angle.
constexpr double kResumeMarginDeg = 5.0;
// [m] A leaf this close to a person's body (beyond touching) counts as touching them.
constexpr double kLeafTouchMarginM = 0.02;
// [N m] What stops a leaf that swings into someone (far above any operator's stall torque).
constexpr double kLeafBrakeTorqueNm = 2000.0;
constexpr int kMaskPerson = kGBase | kGArm | kGPayload;
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
// The forearm body runs from the first's origin to the second's (see BuildRobot).
inline constexpr const char* kForearmLink = "arm_roll_link";
inline constexpr const char* kWristLink = "wrist_flex_link";
constexpr double kForearmRadius = 0.045;  // [m]

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

}  // namespace egress::twin
