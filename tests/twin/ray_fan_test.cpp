// RayFan (twin/src/ray_fan.h): which boxes a ray from the fan's origin may cross, nearest first.
#include "ray_fan.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "ground_boxes.h"

namespace egress::twin::world_detail {
namespace {

// The least distance from p to the box (0 inside it).
double DistanceToBox(const Eigen::Vector2d& p, const Box& box) {
  return (box.first - p).cwiseMax(p - box.second).cwiseMax(0.0).norm();
}

TEST(RayFanTest, EveryBoxARayTouchesIsInItsBinNearestFirstAtItsTrueDistance) {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> pos(-5.0, 25.0), size(0.02, 3.0), unit(-1.0, 1.0);
  for (int scene = 0; scene < 20; ++scene) {
    std::vector<Box> boxes;
    for (int i = 0; i < 200; ++i) {
      const Eigen::Vector2d lo(pos(rng), pos(rng));
      boxes.emplace_back(lo, lo + Eigen::Vector2d(size(rng), size(rng)));
    }
    // A plane (every ray's), and a box whose corner is the origin.
    boxes.emplace_back(Eigen::Vector2d::Constant(-INFINITY), Eigen::Vector2d::Constant(INFINITY));
    const Eigen::Vector2d origin(pos(rng), pos(rng));
    boxes.emplace_back(origin, origin + Eigen::Vector2d(0.5, 0.5));
    const double reach = scene % 2 == 0 ? 8.0 : 40.0;
    RayFan fan;
    fan.Build(origin, boxes, reach);
    EXPECT_EQ(fan.origin(), origin);
    for (int k = 0; k < 2000; ++k) {
      Eigen::Vector2d d(unit(rng), unit(rng));
      if (k % 50 == 0) d = Eigen::Vector2d(1.0, 0.0);   // along the bins' seam at ±π ...
      if (k % 50 == 1) d = Eigen::Vector2d(-1.0, 0.0);  // ... and across it
      if (k % 50 == 2) d = Eigen::Vector2d::Zero();     // straight up or down
      d *= reach / std::max(d.norm(), 1e-12) * std::abs(unit(rng));
      const auto bin = fan.Along(d);
      std::vector<int> listed;
      for (std::size_t e = 0; e < bin.size(); ++e) {
        listed.push_back(bin[e].box);
        if (e > 0) {
          ASSERT_LE(bin[e - 1].near, bin[e].near) << "nearest first";
        }
        const Box& box = boxes[std::size_t(bin[e].box)];
        const double expected = box.first.allFinite() ? DistanceToBox(origin, box) : 0.0;
        ASSERT_DOUBLE_EQ(bin[e].near, expected) << "box " << bin[e].box;
      }
      std::sort(listed.begin(), listed.end());
      ASSERT_TRUE(std::adjacent_find(listed.begin(), listed.end()) == listed.end()) << "once";
      for (std::size_t i = 0; i < boxes.size(); ++i) {
        const bool touched =
            !boxes[i].first.allFinite() || SegmentTouchesBox(origin, origin + d, boxes[i]);
        if (!touched) continue;
        EXPECT_TRUE(std::binary_search(listed.begin(), listed.end(), int(i)))
            << "scene " << scene << " ray " << k << ": box " << i << " is touched, not listed";
      }
    }
    // Boxes wholly beyond the reach are in no bin.
    for (int b = 0; b < 16; ++b) {
      const double angle = 2 * M_PI * b / 16;
      for (const auto& e : fan.Along({std::cos(angle), std::sin(angle)}))
        EXPECT_LE(e.near, reach);
    }
  }
}

TEST(RayFanTest, AnEmptyFanListsNothingAndANonFiniteOriginListsEveryBox) {
  RayFan empty;
  EXPECT_TRUE(empty.Along({1.0, 0.0}).empty());
  const std::vector<Box> boxes{{{1.0, 1.0}, {2.0, 2.0}}, {{-3.0, 0.0}, {-2.0, 1.0}}};
  RayFan fan;
  fan.Build(Eigen::Vector2d(NAN, 0.0), boxes, 10.0);
  EXPECT_EQ(fan.Along({1.0, 0.0}).size(), 2u);
  EXPECT_EQ(fan.Along({0.0, -1.0}).size(), 2u);
}

}  // namespace
}  // namespace egress::twin::world_detail
