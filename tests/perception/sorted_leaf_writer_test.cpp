// SortedLeafWriter (perception/src/sorted_leaf_writer.h) against octomap's own updateNode.
#include "sorted_leaf_writer.h"

#include <algorithm>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace egress::perception::detail {
namespace {

TEST(SortedLeafWriterTest, LeavesAndNodesAreOctomapsUpdateNodesWhateverTheOrder) {
  std::mt19937_64 rng(9);
  // Keys in a few clusters round the centre (shared paths), some far apart.
  std::uniform_int_distribution<int> near(-4, 4), far(0, 0xffff), coin(0, 1);
  for (const bool sorted : {true, false}) {
    octomap::OcTree ours(0.05), theirs(0.05);
    for (octomap::OcTree* t : {&ours, &theirs}) {
      t->setProbHit(0.7);
      t->setProbMiss(0.4);
      t->setClampingThresMin(0.12);
      t->setClampingThresMax(0.97);
    }
    for (int image = 0; image < 30; ++image) {
      std::vector<std::uint64_t> codes;
      for (int k = 0; k < 400; ++k) {
        const bool cluster = k % 10 != 0;
        const auto c = [&] { return octomap::key_type(cluster ? 32768 + near(rng) : far(rng)); };
        codes.push_back(MortonCode(octomap::OcTreeKey(c(), c(), c())));
      }
      if (sorted) std::sort(codes.begin(), codes.end());
      // Hits, then misses, then either: the leaves reach both clamping bounds.
      const bool occupied = image < 10 ? true : image < 20 ? false : coin(rng) == 1;
      SortedLeafWriter writer(&ours);
      for (const std::uint64_t code : codes) {
        const octomap::OcTreeKey key = KeyOfMortonCode(code);
        const octomap::OcTreeNode* a = writer.Update(code, key, occupied);
        const octomap::OcTreeNode* b = theirs.updateNode(key, occupied, /*lazy_eval=*/true);
        ASSERT_NE(a, nullptr);
        ASSERT_NE(b, nullptr);
        ASSERT_EQ(a->getLogOdds(), b->getLogOdds()) << "image " << image;
        ASSERT_EQ(a, ours.search(key)) << "the leaf of the key";
      }
      ASSERT_EQ(ours.size(), theirs.size()) << "the same nodes, image " << image;
    }
    // Every leaf the same (repeated keys reached the clamping bounds on the way).
    int leaves = 0, clamped = 0;
    for (auto it = theirs.begin_leafs(); it != theirs.end_leafs(); ++it, ++leaves) {
      const octomap::OcTreeNode* mine = ours.search(it.getKey());
      ASSERT_NE(mine, nullptr);
      EXPECT_EQ(mine->getLogOdds(), it->getLogOdds());
      clamped += it->getLogOdds() >= theirs.getClampingThresMaxLog() ||
                 it->getLogOdds() <= theirs.getClampingThresMinLog();
    }
    EXPECT_GT(leaves, 500);
    EXPECT_GT(clamped, 10) << "the bounds' early return was exercised";
  }
}

}  // namespace
}  // namespace egress::perception::detail
