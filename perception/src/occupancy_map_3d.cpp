#include "egress/perception/occupancy_map_3d.h"

#include <algorithm>
#include <cmath>

#include "egress/hsr_interface/error.h"
#include "morton_code.h"
#include "sorted_leaf_writer.h"

namespace egress::perception {
namespace {

using detail::KeyOfMortonCode;
using detail::MortonCode;

// Adds each Morton code to `out` once, in the order first offered: an open-addressing table of
// code + 1 (0 marks an empty slot) in `slots`, kept from image to image for its memory. A depth
// image's carving rays offer the same voxels near the camera over and over.
class UniqueCodes {
 public:
  UniqueCodes(std::vector<std::uint64_t>* slots, std::vector<std::uint64_t>* out)
      : slots_(*slots), out_(*out) {
    out_.clear();
    if (slots_.size() < kMinSlots) slots_.resize(kMinSlots);
    std::fill(slots_.begin(), slots_.end(), 0);
    SetBits();
  }
  void Add(std::uint64_t code) {
    if (2 * (out_.size() + 1) > slots_.size()) Grow();
    if (Place(code + 1)) out_.push_back(code);
  }

 private:
  static constexpr std::size_t kMinSlots = 1024;  // a power of two
  std::vector<std::uint64_t>& slots_;
  std::vector<std::uint64_t>& out_;
  int shift_{0};

  void SetBits() {
    shift_ = 64;
    for (std::size_t n = slots_.size(); n > 1; n /= 2)
      --shift_;
  }
  // False when already there.
  bool Place(std::uint64_t stored) {
    const std::size_t mask = slots_.size() - 1;
    // Fibonacci hashing: neighbouring voxels differ in the low bits of their codes.
    std::size_t i = std::size_t((stored * 0x9E3779B97F4A7C15ull) >> shift_);
    while (slots_[i] != 0) {
      if (slots_[i] == stored) return false;
      i = (i + 1) & mask;
    }
    slots_[i] = stored;
    return true;
  }
  void Grow() {
    slots_.assign(slots_.size() * 2, 0);
    SetBits();
    for (const std::uint64_t code : out_)
      Place(code + 1);
  }
};
}  // namespace

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
  // The voxels to mark and to carve by Morton code, each once, then sorted: written in the tree's
  // own order (each leaf is written once per image, so the order changes nothing but the cache
  // misses).
  std::vector<std::uint64_t>& occupied = occupied_scratch_;
  std::vector<std::uint64_t>& free = free_scratch_;
  UniqueCodes occupied_codes(&occupied_slots_, &occupied);
  UniqueCodes free_codes(&free_slots_, &free);
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
          occupied_codes.Add(MortonCode(key));
          ++inserted;
        }
      }
      if (carve && config_.clearing_range > 0.0) {
        const Eigen::Vector3d end = p_MC + ray_M * std::min(1.0, config_.clearing_range / distance);
        if (tree_->computeRayKeys(
                origin, octomap::point3d(float(end.x()), float(end.y()), float(end.z())), ray)) {
          for (const octomap::OcTreeKey& key : ray)
            free_codes.Add(MortonCode(key));
        }
      }
    }
  }
  std::sort(occupied.begin(), occupied.end());
  std::sort(free.begin(), free.end());
  // Every leaf written is noted (its occupancy may have changed): the inner nodes above them are
  // brought up to date, and the occupied leaves kept, without walking the whole tree.
  std::vector<std::uint64_t> touched;
  touched.reserve(free.size() + occupied.size());
  const auto note = [&](std::uint64_t code, const octomap::OcTreeKey& key,
                        const octomap::OcTreeNode* leaf) {
    touched.push_back(code);
    const double z = tree_->keyToCoord(key[2]);
    if (leaf != nullptr && tree_->isNodeOccupied(leaf) && z >= config_.min_obstacle_height &&
        z <= config_.max_obstacle_height) {
      occupied_in_band_.insert(code);
    } else {
      occupied_in_band_.erase(code);
    }
  };
  // A voxel both marked and carved is marked. Both written in order, each from where the last
  // one's path parts (octomap's updateNode, in one descent).
  detail::SortedLeafWriter writer(tree_.get());
  auto marked = occupied.begin();
  for (const std::uint64_t code : free) {
    while (marked != occupied.end() && *marked < code)
      ++marked;
    if (marked != occupied.end() && *marked == code) continue;
    const octomap::OcTreeKey key = KeyOfMortonCode(code);
    note(code, key, writer.Update(code, key, /*occupied=*/false));
  }
  const auto carved_end = long(touched.size());
  const double now = ToSeconds(depth.stamp);
  for (const std::uint64_t code : occupied) {
    const octomap::OcTreeKey key = KeyOfMortonCode(code);
    note(code, key, writer.Update(code, key, /*occupied=*/true));
    marked_at_[key] = now;
  }
  const auto marked_end = long(touched.size());
  if (config_.decay_s > 0.0) {
    for (auto it = marked_at_.begin(); it != marked_at_.end();) {
      if (now - it->second <= config_.decay_s) {
        ++it;
        continue;
      }
      // Even odds: as if unseen.
      note(MortonCode(it->first), it->first,
           tree_->setNodeValue(it->first, 0.0f, /*lazy_eval=*/true));
      it = marked_at_.erase(it);
    }
  }
  // Carved and marked are each in order already; the decayed come in the table's order.
  std::inplace_merge(touched.begin(), touched.begin() + carved_end, touched.begin() + marked_end);
  std::sort(touched.begin() + marked_end, touched.end());
  std::inplace_merge(touched.begin(), touched.begin() + marked_end, touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  if (tree_->getRoot() != nullptr) UpdateInnerNodes(tree_->getRoot(), 0, touched);
  return inserted;
}

std::vector<Eigen::Vector2d> OccupancyMap3D::ProjectObstacles() const {
  // Ascending Morton codes: the order of the tree's own leaf iterator.
  std::vector<std::uint64_t> codes(occupied_in_band_.begin(), occupied_in_band_.end());
  std::sort(codes.begin(), codes.end());
  std::vector<Eigen::Vector2d> points;
  points.reserve(codes.size() * 9);
  for (const std::uint64_t code : codes) {
    const octomap::OcTreeKey key = KeyOfMortonCode(code);
    // The voxel's whole footprint, not its centre: a point at the centre of a 5 cm voxel may lie
    // 2.5 cm inside the obstacle's true edge, and the costmap cell it falls in adds its own
    // rounding. Its corners, edge midpoints and centre mark every cell the voxel overlaps.
    const double step = config_.resolution / 2;
    const double x0 = tree_->keyToCoord(key[0]) - step, y0 = tree_->keyToCoord(key[1]) - step;
    for (int i = 0; i <= 2; ++i) {
      for (int j = 0; j <= 2; ++j)
        points.emplace_back(x0 + i * step, y0 + j * step);
    }
  }
  return points;
}

void OccupancyMap3D::UpdateInnerNodes(octomap::OcTreeNode* node, int depth,
                                      std::span<const std::uint64_t> codes) {
  // As OcTree::updateInnerOccupancy (an inner node holds its children's maximum), but only
  // along the paths to the leaves just written: everything else already holds.
  if (!tree_->nodeHasChildren(node)) return;
  if (depth < int(tree_->getTreeDepth())) {
    const int shift = 3 * (int(tree_->getTreeDepth()) - 1 - depth);
    for (std::size_t begin = 0; begin < codes.size();) {
      const unsigned child = unsigned(codes[begin] >> shift) & 7u;
      std::size_t end = begin + 1;
      while (end < codes.size() && (unsigned(codes[end] >> shift) & 7u) == child)
        ++end;
      if (tree_->nodeChildExists(node, child))
        UpdateInnerNodes(tree_->getNodeChild(node, child), depth + 1,
                         codes.subspan(begin, end - begin));
      begin = end;
    }
  }
  node->updateOccupancyChildren();
}

bool OccupancyMap3D::IsOccupied(const Eigen::Vector3d& p_MQ) const {
  const octomap::OcTreeNode* node = tree_->search(p_MQ.x(), p_MQ.y(), p_MQ.z());
  return node != nullptr && tree_->isNodeOccupied(node);
}

}  // namespace egress::perception
