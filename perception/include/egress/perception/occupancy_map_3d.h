#pragma once
/// @file
/// OccupancyMap3D: an OctoMap of obstacles seen by the head depth camera, for what the planar
/// laser misses (table tops, overhangs), with a projection into the costmap and the tree itself
/// for FCL collision checks.

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include <octomap/OcTree.h>

#include "egress/hsr_interface/geometry.h"
#include "egress/hsr_interface/sensor_types.h"

namespace egress::perception {

/// Marking and clearing are separate, as in Nav2's voxel layer: every return within max_range
/// marks its voxel, but free space is carved only along every clearing_stride-th ray and only up
/// to clearing_range. Carving the whole frustum at 5 cm costs ~30 ms per 80x60 frame; bounded
/// like this an insert stays near 2 ms, and space is cleared as the robot comes near it.
struct OccupancyMap3DConfig {
  double resolution{0.05};     ///< Voxel size [m].
  double max_range{4.0};       ///< Returns beyond this are ignored [m].
  double clearing_range{1.5};  ///< Rays carve free space up to this distance [m].
  int clearing_stride{4};      ///< Carve along every n-th pixel's ray in u and v.
  int pixel_stride{1};         ///< Mark every n-th pixel in u and v.
  /// OctoMap's sensor model. A miss (a ray through a voxel) counts less than OctoMap's default
  /// 0.4: rays that graze an obstacle's edge at a shallow angle pass through its edge voxels
  /// often, and would wear a table top's edge away as the robot drives along it.
  double prob_hit{0.7};
  double prob_miss{0.45};
  /// A voxel is an obstacle (projected, and for FCL) only at this occupancy: three hits in a
  /// row. Something seen once or twice — a person walking past before the tracker has them,
  /// whose voxels no later ray may ever clear — never becomes a wall nobody can see.
  double occupied_threshold{0.9};
  double min_obstacle_height{0.05};  ///< Projection band in M's z [m]: the floor is below it,
  double max_obstacle_height{1.5};   ///< and what the robot passes under is above it.
  /// An occupied voxel no image has marked for this long is forgotten [s] (0: never). Beyond
  /// clearing_range no ray clears a voxel, and people the tracker does not hold (the detector
  /// misses some in a crowd) are marked where they stood: without decay the robot would never
  /// again plan through a doorway a queue stood in while it looked away (Nav2's
  /// spatio-temporal voxel layer decays its voxels for the same reason). Anything still there
  /// is marked again as soon as the camera faces it.
  double decay_s{20.0};
  void Validate() const;
};

class OccupancyMap3D {
 public:
  explicit OccupancyMap3D(OccupancyMap3DConfig config = {});

  /// Which points may mark their voxel (p_MQ in M); the rays still carve free space.
  using PointFilter = std::function<bool(const Eigen::Vector3d& p_MQ)>;

  /// Inserts a depth image seen from camera pose X_MC (optical frame: z forward). Invalid
  /// pixels (NaN, 0) are skipped; with `keep`, only the points it accepts are marked (the
  /// robot's own body, tracked people, the floor). Returns the number of points inserted.
  /// @throws InvalidArgument if the image and intrinsics disagree or the pose is not finite.
  std::size_t InsertDepthImage(const DepthImage& depth, const CameraIntrinsics& intrinsics,
                               const Pose3& X_MC, const PointFilter& keep = {});
  /// Points (x, y) covering the footprint of every occupied voxel whose z lies within the
  /// obstacle band (its corners and centre, at half-voxel spacing), for the costmap.
  std::vector<Eigen::Vector2d> ProjectObstacles() const;
  bool IsOccupied(const Eigen::Vector3d& p_MQ) const;
  /// The OctoMap (shared so that FCL can hold it).
  std::shared_ptr<const octomap::OcTree> tree() const { return tree_; }
  const OccupancyMap3DConfig& config() const { return config_; }

 private:
  OccupancyMap3DConfig config_;
  std::shared_ptr<octomap::OcTree> tree_;
  /// Brings the inner nodes on the paths from `node` (at `depth`, the root's 0) to the leaves
  /// `codes` (ascending Morton codes) up to date.
  void UpdateInnerNodes(octomap::OcTreeNode* node, int depth, std::span<const std::uint64_t> codes);
  /// The occupied leaves within the obstacle band, by Morton code. The tree is never pruned
  /// (every write is lazy), so every leaf is a voxel at the finest resolution.
  std::unordered_set<std::uint64_t> occupied_in_band_;
  /// [s] When each voxel was last marked (the image's stamp), for decay_s.
  std::unordered_map<octomap::OcTreeKey, double, octomap::OcTreeKey::KeyHash> marked_at_;
  /// Scratch of InsertDepthImage (Morton codes and their tables), kept to reuse its memory.
  std::vector<std::uint64_t> occupied_scratch_, free_scratch_, occupied_slots_, free_slots_;
};

}  // namespace egress::perception
