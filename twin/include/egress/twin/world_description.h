#pragma once
/// @file
/// What a world file says, independent of any physics engine: static collision shapes and
/// hinged doors, all posed in the world frame W. The SDF loader produces it; the Bullet world,
/// the navigation service's map rasterizer and tests consume it.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "egress/hsr_interface/geometry.h"

namespace egress::twin {

/// A triangle mesh in its shape frame S [m] (SDF scale already applied).
struct TriangleMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> triangles;  ///< Indices into vertices.
};

enum class ShapeKind { kBox, kCylinder, kSphere, kPlane, kMesh };

/// One collision shape of a static model. Cylinders are along the shape's z axis; a plane's
/// normal is the shape's z axis.
struct ShapeDescription {
  std::string model;      ///< SDF model name.
  std::string link;       ///< SDF link name.
  std::string collision;  ///< SDF collision name.
  ShapeKind kind{ShapeKind::kBox};
  Pose3 X_WS;                                           ///< Shape frame S in the world.
  Eigen::Vector3d box_size{Eigen::Vector3d::Zero()};    ///< Full box extents [m].
  double radius{0.0};                                   ///< Cylinder/sphere radius [m].
  double length{0.0};                                   ///< Cylinder length [m].
  Eigen::Vector2d plane_size{Eigen::Vector2d::Zero()};  ///< Plane extents [m] (0 = infinite).
  std::shared_ptr<const TriangleMesh> mesh;             ///< For kMesh.

  /// Axis-aligned bounds in W of the shape [m] (planes: their finite size, or empty).
  void CalcWorldBounds(Eigen::Vector3d* lower, Eigen::Vector3d* upper) const;
};

/// A hinged door: a leaf box turning about a vertical hinge axis. The door's opening angle
/// (0 = closed, positive = open) maps to the SDF joint position q = open_sign * angle.
struct DoorDescription {
  std::string name;                                  ///< SDF model name.
  std::string joint;                                 ///< SDF revolute joint name.
  Eigen::Vector3d p_WH{Eigen::Vector3d::Zero()};     ///< A point on the hinge axis (frame H) [m].
  Eigen::Vector3d axis_W{Eigen::Vector3d::UnitZ()};  ///< Hinge axis in W (unit).
  Pose3 X_WL;  ///< The leaf box's centre frame L in W with the door closed (q = 0).
  Eigen::Vector3d leaf_size{Eigen::Vector3d::Zero()};  ///< Full leaf box extents in L [m].
  double open_sign{1.0};       ///< +1 if the door opens towards positive q, else −1.
  double max_open_angle{0.0};  ///< Largest opening angle allowed by the joint limits [rad].
  double max_velocity{0.0};    ///< Joint velocity limit [rad/s]; 0 = none given.
  double effort{0.0};          ///< Joint effort limit [N·m]; 0 = none given.
  double damping{0.0};         ///< Viscous damping [N·m·s/rad].
  double mass{0.0};            ///< Leaf mass [kg].

  /// Distance from the hinge axis to the leaf's free (latch) edge [m].
  double LeafReach() const;
  /// The leaf box pose in W at opening angle `angle` [rad].
  Pose3 CalcLeafPose(double angle) const;
  /// The free edge's point at the leaf's mid-height in W for opening angle `angle` [m].
  Eigen::Vector3d CalcFreeEdge(double angle) const;
};

/// A static shape's outline on the floor plan: an oriented rectangle in W. Boxes and cylinders
/// standing upright keep their shape (a cylinder by its bounding square); tilted shapes and
/// meshes use their world-axis bounds.
struct FloorFootprint {
  std::string model;
  Pose2 X_WF;                                     ///< Rectangle centre and orientation in W.
  Eigen::Vector2d size{Eigen::Vector2d::Zero()};  ///< Full extents [m].
};

struct WorldDescription;

/// Footprints of the static shapes that reach into the height band [z_min, z_max] [m]; planes
/// are skipped, and so are door leaves (doors are doorways, not walls, on a floor plan).
std::vector<FloorFootprint> CalcFloorFootprints(const WorldDescription& world, double z_min = 0.05,
                                                double z_max = 1.8);
/// The same for a single shape; nullopt if it is a plane or outside the band.
std::optional<FloorFootprint> CalcFloorFootprint(const ShapeDescription& shape, double z_min = 0.05,
                                                 double z_max = 1.8);

/// Everything the twin reads from one world file.
struct WorldDescription {
  std::string name;                      ///< SDF world name.
  std::filesystem::path source;          ///< File it came from (or a label for strings).
  std::vector<ShapeDescription> shapes;  ///< Static collision shapes.
  std::vector<DoorDescription> doors;
  /// The world's own `<frame name="...">` elements (SDF 1.7+), posed in W: named places (a
  /// room, an exit, a responder's post) that Gazebo ignores and the building description reads.
  std::vector<std::pair<std::string, Pose3>> frames;
  /// Informational lines: plugins and sensors the twin ignores, non-static models it fixes.
  std::vector<std::string> notes;

  /// The static shape(s) of a model, or an empty list.
  std::vector<const ShapeDescription*> ShapesOfModel(const std::string& model) const;
  /// The door of that model name, or nullptr.
  const DoorDescription* FindDoor(const std::string& model) const;
};

}  // namespace egress::twin
