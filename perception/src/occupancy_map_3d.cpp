#include "egress/perception/occupancy_map_3d.h"

#include <cmath>

#include "egress/hsr_interface/error.h"

namespace egress::perception {

void OccupancyMap3DConfig::Validate() const {
  ThrowUnless(resolution > 0.0 && std::isfinite(resolution),
              "Invalid OccupancyMap3DConfig: resolution (", resolution, ") must be > 0.");
  ThrowUnless(max_range > 0.0, "Invalid OccupancyMap3DConfig: max_range must be > 0.");
  ThrowUnless(pixel_stride >= 1, "Invalid OccupancyMap3DConfig: pixel_stride (", pixel_stride,
              ") must be >= 1.");
  ThrowUnless(occupied_threshold > 0.5 && occupied_threshold < 1.0,
              "Invalid OccupancyMap3DConfig: occupied_threshold must be in (0.5, 1).");
  ThrowUnless(prob_hit > 0.5 && prob_hit < 1.0 && prob_miss > 0.0 && prob_miss < 0.5,
              "Invalid OccupancyMap3DConfig: prob_hit must be in (0.5, 1) and prob_miss in "
              "(0, 0.5).");
  ThrowUnless(decay_s >= 0.0 && std::isfinite(decay_s), "Invalid OccupancyMap3DConfig: decay_s (",
              decay_s, ") must be finite and >= 0.");
  ThrowUnless(max_obstacle_height > min_obstacle_height,
              "Invalid OccupancyMap3DConfig: max_obstacle_height must exceed min_obstacle_height.");
}

OccupancyMap3D::OccupancyMap3D(OccupancyMap3DConfig config)
    : config_(config), tree_(std::make_shared<octomap::OcTree>(config.resolution)) {
  config_.Validate();
  tree_->setProbHit(config_.prob_hit);
  tree_->setProbMiss(config_.prob_miss);
  tree_->setOccupancyThres(config_.occupied_threshold);
}

std::size_t OccupancyMap3D::InsertDepthImage(const DepthImage& depth,
                                             const CameraIntrinsics& intrinsics, const Pose3& X_MC,
                                             const PointFilter& keep) {
  depth.Validate();
  intrinsics.Validate();
  ThrowUnless(depth.width == intrinsics.width && depth.height == intrinsics.height,
              "Invalid depth image: ", depth.width, "x", depth.height,
              " does not match its intrinsics ", intrinsics.width, "x", intrinsics.height, ".");
  ThrowUnless(X_MC.IsFinite(), "Invalid camera pose X_MC: must be finite.");
  const Eigen::Vector3d& p_MC = X_MC.translation();
  const octomap::point3d origin(float(p_MC.x()), float(p_MC.y()), float(p_MC.z()));
  octomap::KeySet occupied, free;
  octomap::KeyRay ray;
  std::size_t inserted = 0;
  for (int v = 0; v < depth.height; ++v) {
    for (int u = 0; u < depth.width; ++u) {
      const bool mark = u % config_.pixel_stride == 0 && v % config_.pixel_stride == 0;
      const bool carve = u % config_.clearing_stride == 0 && v % config_.clearing_stride == 0;
      if ((!mark && !carve) || !depth.IsValidAt(u, v)) continue;
      const double z = depth.At(u, v);
      const Eigen::Vector3d p_MQ = X_MC * intrinsics.Unproject(u + 0.5, v + 0.5, z);
      const Eigen::Vector3d ray_M = p_MQ - p_MC;
      const double distance = ray_M.norm();
      if (mark && distance <= config_.max_range && (!keep || keep(p_MQ))) {
        octomap::OcTreeKey key;
        if (tree_->coordToKeyChecked(p_MQ.x(), p_MQ.y(), p_MQ.z(), key)) {
          occupied.insert(key);
          ++inserted;
        }
      }
      if (carve && config_.clearing_range > 0.0) {
        const Eigen::Vector3d end = p_MC + ray_M * std::min(1.0, config_.clearing_range / distance);
        if (tree_->computeRayKeys(
                origin, octomap::point3d(float(end.x()), float(end.y()), float(end.z())), ray)) {
          free.insert(ray.begin(), ray.end());
        }
      }
    }
  }
  for (const auto& key : free) {
    if (occupied.count(key) == 0) tree_->updateNode(key, false, /*lazy_eval=*/true);
  }
  const double now = ToSeconds(depth.stamp);
  for (const auto& key : occupied) {
    tree_->updateNode(key, true, /*lazy_eval=*/true);
    marked_at_[key] = now;
  }
  if (config_.decay_s > 0.0) {
    for (auto it = marked_at_.begin(); it != marked_at_.end();) {
      if (now - it->second <= config_.decay_s) {
        ++it;
        continue;
      }
      tree_->setNodeValue(it->first, 0.0f, /*lazy_eval=*/true);  // even odds: as if unseen
      it = marked_at_.erase(it);
    }
  }
  tree_->updateInnerOccupancy();
  return inserted;
}

std::vector<Eigen::Vector2d> OccupancyMap3D::ProjectObstacles() const {
  std::vector<Eigen::Vector2d> points;
  for (auto it = tree_->begin_leafs(), end = tree_->end_leafs(); it != end; ++it) {
    if (!tree_->isNodeOccupied(*it)) continue;
    const double z = it.getZ();
    if (z < config_.min_obstacle_height || z > config_.max_obstacle_height) continue;
    // The leaf's whole footprint, not its centre: a point at the centre of a 5 cm voxel may lie
    // 2.5 cm inside the obstacle's true edge, and the costmap cell it falls in adds its own
    // rounding. Its corners and centres at voxel spacing mark every cell the leaf overlaps
    // (a coarse leaf covers several voxels).
    const double size = it.getSize();
    const int n = std::max(1, static_cast<int>(std::round(size / config_.resolution)));
    const double x0 = it.getX() - size / 2, y0 = it.getY() - size / 2;
    const double step = config_.resolution / 2;
    for (int i = 0; i <= 2 * n; ++i) {
      for (int j = 0; j <= 2 * n; ++j)
        points.emplace_back(x0 + i * step, y0 + j * step);
    }
  }
  return points;
}

bool OccupancyMap3D::IsOccupied(const Eigen::Vector3d& p_MQ) const {
  const octomap::OcTreeNode* node = tree_->search(p_MQ.x(), p_MQ.y(), p_MQ.z());
  return node != nullptr && tree_->isNodeOccupied(node);
}

}  // namespace egress::perception
