#pragma once
// Internal to twin/src: what TwinModel compiles from a scenario and its world (twin_model.cpp),
// shared read-only by every run built on it.

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "ray_bins.h"
#include "twin_detail.h"

namespace egress::twin {
namespace people {
class PersonBehaviorModel;  // people/person_behavior.h
}  // namespace people

namespace world_detail {

// What a collision object is, by index (RayHit::entity, a body's user index).
struct Entity {
  EntityKind kind;
  std::string name;
  int index;  // into the run's doors/people/payloads where that applies
  bool glass{false};
};

// A static box or plane (half extent 0 along the normal) for analytic ray tests.
struct RayBox {
  Eigen::Matrix3d R_SW;  // world to shape
  Eigen::Vector3d p_WS;
  Eigen::Vector3d half;
  int entity{-1};
};

// A static cylinder or sphere: a body of its own in each run, its shape shared.
struct StaticConvex {
  std::unique_ptr<btCollisionShape> shape;
  Pose3 X_WS;
  bool floor{false};
  int entity{-1};
};

// A doorway's fixed geometry, in the plane.
struct DoorModel {
  const DoorDescription* desc{nullptr};
  std::optional<DoorOperatorSpec> spec;  // the scenario's operator, before the seeded draws
  double reach{0.0};                     // [m] hinge to free edge
  Eigen::Vector2d centre{Eigen::Vector2d::Zero()};  // doorway centre
  Eigen::Vector2d normal{Eigen::Vector2d::Zero()};  // doorway plane normal
  Eigen::Vector2d along{Eigen::Vector2d::Zero()};   // hinge → latch direction (closed)
  // The side of the doorway plane (+1: along `normal`, −1: against) the leaf opens into; 0 for
  // a leaf that cannot open.
  double swing_side{0.0};
};

}  // namespace world_detail

struct TwinModel::Compiled {
  // The statics' entities, first in every run's entity table (doors, robot, payloads and
  // people follow, added by the run).
  std::vector<world_detail::Entity> entities;
  // Static boxes, planes and meshes as one triangle mesh (one BVH for contacts); the entity of
  // each triangle is kept so rays and contacts still name the model they touch.
  std::unique_ptr<btTriangleMesh> static_mesh;
  std::unique_ptr<btBvhTriangleMeshShape> static_mesh_shape;  // null without such statics
  std::vector<int> static_triangle_entity;
  // Rays test boxes and planes analytically (a slab test is far cheaper than a BVH walk over
  // their triangles) and only the meshes' triangles through their own BVH.
  std::vector<world_detail::RayBox> ray_boxes;
  // Their XY extents in W (lower, upper corners), binned for a single ray and for a fan.
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> ray_box_extents;
  world_detail::RayBins ray_box_bins;   // which ray_boxes a ray may cross
  std::vector<std::size_t> ray_planes;  // the ray_boxes that are planes (floors), opaque
  std::unique_ptr<btTriangleMesh> ray_mesh;
  std::unique_ptr<btBvhTriangleMeshShape> ray_mesh_shape;  // null without static meshes
  std::vector<int> ray_triangle_entity;
  std::vector<world_detail::StaticConvex> convex_statics;
  // Outline of walls and furniture at body height, for the people's wall forces.
  std::vector<WallSegment> walls;
  WallCells wall_cells;                        // the same, binned for the social force model
  std::vector<world_detail::DoorModel> doors;  // in the world's door order
  // One model per people behaviour the scenario uses.
  std::map<PersonBehavior, std::unique_ptr<people::PersonBehaviorModel>> behavior_models;

  Compiled();
  ~Compiled();
};

}  // namespace egress::twin
