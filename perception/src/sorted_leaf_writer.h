#pragma once
/// @file
/// SortedLeafWriter (internal to OccupancyMap3D): updates leaves of an OcTree one after another,
/// as octomap's updateNode(key, occupied, lazy_eval = true) does (the same nodes created, the
/// same log-odds, the same early return at the clamping bounds), in one descent instead of two
/// (updateNode searches the key before it descends to update it), and from where the last key's
/// path parts from this one's rather than from the root: an image's voxels, written in Morton
/// order, share all but the last levels of their paths.

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>

#include <octomap/OcTree.h>

#include "morton_code.h"

namespace egress::perception::detail {

class SortedLeafWriter {
 public:
  /// The tree outlives the writer; between writes nothing else may delete or prune its nodes.
  explicit SortedLeafWriter(octomap::OcTree* tree) : tree_(*tree) {}

  /// Updates the leaf of `key` (its Morton `code`) with a hit or a miss; the leaf.
  octomap::OcTreeNode* Update(std::uint64_t code, const octomap::OcTreeKey& key, bool occupied) {
    const float update = occupied ? tree_.getProbHitLog() : tree_.getProbMissLog();
    octomap::OcTreeNode* root = tree_.getRoot();
    // No root yet, a tree of another depth: octomap's own update (then the path is unknown).
    if (root == nullptr || tree_.getTreeDepth() != unsigned(kKeyBits)) {
      known_ = 0;
      return tree_.updateNode(key, update, /*lazy_eval=*/true);
    }
    // The nodes down to where this key's child index first differs from the last key's.
    int depth = 0;
    if (known_ > 0 && path_[0] == root) {
      const std::uint64_t differ = (code ^ last_code_) & kMortonMask;
      const int group = differ == 0 ? -1 : (63 - std::countl_zero(differ)) / 3;
      depth = std::min(known_, kKeyBits - 1 - group);
    }
    path_[0] = root;
    for (; depth < kKeyBits; ++depth) {
      octomap::OcTreeNode* node = path_[std::size_t(depth)];
      const unsigned child = unsigned(code >> (3 * (kKeyBits - 1 - depth))) & 7u;
      if (!tree_.nodeChildExists(node, child)) {
        // A node with no children above the leaves' depth is a pruned one (this map never
        // prunes): octomap's own update, which expands it.
        if (!tree_.nodeHasChildren(node)) {
          known_ = 0;
          return tree_.updateNode(key, update, /*lazy_eval=*/true);
        }
        // Unknown from here down (updateNode's search finds nothing): created to the leaf.
        for (; depth < kKeyBits; ++depth) {
          const unsigned c = unsigned(code >> (3 * (kKeyBits - 1 - depth))) & 7u;
          path_[std::size_t(depth) + 1] = tree_.createNodeChild(path_[std::size_t(depth)], c);
        }
        return Write(code, update, /*existed=*/false);
      }
      path_[std::size_t(depth) + 1] = tree_.getNodeChild(node, child);
    }
    return Write(code, update, /*existed=*/true);
  }

 private:
  octomap::OcTreeNode* Write(std::uint64_t code, float update, bool existed) {
    octomap::OcTreeNode* leaf = path_[std::size_t(kKeyBits)];
    known_ = kKeyBits;
    last_code_ = code;
    // updateNode's early return: no change at the bound the update pushes towards.
    if (existed && ((update >= 0 && leaf->getLogOdds() >= tree_.getClampingThresMaxLog()) ||
                    (update <= 0 && leaf->getLogOdds() <= tree_.getClampingThresMinLog())))
      return leaf;
    tree_.updateNodeLogOdds(leaf, update);
    return leaf;
  }

  octomap::OcTree& tree_;
  std::array<octomap::OcTreeNode*, std::size_t(kKeyBits) + 1> path_{};  // root to leaf
  int known_{0};  // path_[0..known_] is the last key's path
  std::uint64_t last_code_{0};
};

}  // namespace egress::perception::detail
