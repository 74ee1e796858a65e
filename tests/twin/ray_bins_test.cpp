// RayBins (twin/src/ray_bins.h): which boxes a ray's ground track may cross.
#include "ray_bins.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "ground_boxes.h"

namespace egress::twin::world_detail {
namespace {

// n boxes of 0.05-3 m sides in the square -5..25 m.
std::vector<Box> RandomBoxes(std::mt19937_64& rng, int n) {
  std::uniform_real_distribution<double> pos(-5.0, 25.0), size(0.05, 3.0);
  std::vector<Box> boxes;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d lo(pos(rng), pos(rng));
    boxes.emplace_back(lo, lo + Eigen::Vector2d(size(rng), size(rng)));
  }
  return boxes;
}

TEST(RayBinsTest, AWalkYieldsBoxesOnceInOrderAndCanStopAtTheClosest) {
  // What a ray cast relies on: each box comes once; none still to come touches the segment
  // before the step's t_beyond; so stopping once the closest entry so far is before t_beyond
  // finds the closest box (lowest index on a tie) an exhaustive search finds.
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> pos(-5.0, 25.0);
  std::vector<Box> boxes = RandomBoxes(rng, 300);
  boxes.emplace_back(Eigen::Vector2d::Constant(-INFINITY), Eigen::Vector2d::Constant(INFINITY));
  RayBins bins;
  bins.Build(boxes, 1.0);
  std::vector<int> step_boxes;
  int stopped_early = 0;
  for (int k = 0; k < 3000; ++k) {
    const Eigen::Vector2d a(pos(rng), pos(rng));
    const double reach = k % 3 == 0 ? 40.0 : 4.0;
    std::uniform_real_distribution<double> step(-reach, reach);
    Eigen::Vector2d b = a + Eigen::Vector2d(step(rng), step(rng));
    if (k % 7 == 0) b.x() = a.x();  // along a cell line's direction
    double exhaustive = INFINITY;
    int exhaustive_box = -1;
    for (std::size_t i = 0; i + 1 < boxes.size(); ++i) {  // the plane is not a box to hit
      const double t = EntryAlong(a, b, boxes[i]);
      if (t < exhaustive) {
        exhaustive = t;
        exhaustive_box = int(i);
      }
    }
    RayBins::Walk walk(bins, a, b);
    std::vector<int> seen;
    double t_beyond = 0.0, previous_beyond = 0.0, closest = INFINITY;
    int closest_box = -1;
    bool stopped = false;
    while (walk.Next(&step_boxes, &t_beyond)) {
      for (const int i : step_boxes) {
        ASSERT_EQ(std::find(seen.begin(), seen.end(), i), seen.end()) << "box " << i << " twice";
        seen.push_back(i);
        if (std::size_t(i) + 1 == boxes.size()) continue;
        const double t = EntryAlong(a, b, boxes[std::size_t(i)]);
        ASSERT_GE(t, previous_beyond - 1e-9) << "box " << i << " came after a step past it";
        if (t < closest || (t == closest && i < closest_box)) {
          closest = t;
          closest_box = i;
        }
      }
      previous_beyond = t_beyond;
      if (closest < t_beyond - 1e-9) {
        stopped = true;
        break;
      }
    }
    ASSERT_EQ(closest_box, exhaustive_box)
        << "(" << a.transpose() << ") - (" << b.transpose() << ")";
    stopped_early += stopped && walk.Next(&step_boxes, &t_beyond);
  }
  EXPECT_GT(stopped_early, 500);  // the walks did stop short of their ends
}

TEST(RayBinsTest, ReturnsEveryBoxTheSegmentTouchesAscendingAndOnce) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> pos(-5.0, 25.0);
  std::vector<Box> boxes = RandomBoxes(rng, 300);
  RayBins bins;
  bins.Build(boxes, 1.0);
  std::vector<int> got;
  int touched_total = 0;
  for (int k = 0; k < 2000; ++k) {
    const Eigen::Vector2d a(pos(rng), pos(rng));
    // Short rays (a few metres, the sensors' near piece) and long ones (across the grid).
    const double reach = k % 2 ? 3.0 : 40.0;
    std::uniform_real_distribution<double> step(-reach, reach);
    const Eigen::Vector2d b = a + Eigen::Vector2d(step(rng), step(rng));
    bins.Query(a, b, &got);
    ASSERT_TRUE(std::is_sorted(got.begin(), got.end()));
    ASSERT_EQ(std::adjacent_find(got.begin(), got.end()), got.end());
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      if (!SegmentTouchesBox(a, b, boxes[i])) continue;
      ++touched_total;
      ASSERT_TRUE(std::binary_search(got.begin(), got.end(), int(i)))
          << "box " << i << " missed by the segment (" << a.transpose() << ") - (" << b.transpose()
          << ")";
    }
  }
  EXPECT_GT(touched_total, 1000);  // the check above was exercised
}

TEST(RayBinsTest, SegmentsAlongCellLinesAndThroughCornersMissNothing) {
  // Unit boxes on a unit grid, every other one, touching at corners; segments on the grid's
  // lines, through its corners, and ending exactly on them: where a grid walk's rounding bites.
  std::vector<Box> boxes;
  for (int x = 0; x < 12; ++x) {
    for (int y = 0; y < 12; ++y) {
      if ((x + y) % 2 == 0)
        boxes.emplace_back(Eigen::Vector2d(x, y), Eigen::Vector2d(x + 1, y + 1));
    }
  }
  RayBins bins;
  bins.Build(boxes, 1.0);
  std::vector<int> got;
  int touched = 0;
  for (int x0 = 0; x0 <= 12; x0 += 3) {
    for (int y0 = 0; y0 <= 12; y0 += 2) {
      for (const Eigen::Vector2d& d :
           {Eigen::Vector2d(5, 5), Eigen::Vector2d(-4, 4), Eigen::Vector2d(6, 0),
            Eigen::Vector2d(0, -7), Eigen::Vector2d(3, 6), Eigen::Vector2d(-2.5, -7.5)}) {
        const Eigen::Vector2d a(x0, y0), b = a + d;
        bins.Query(a, b, &got);
        for (std::size_t i = 0; i < boxes.size(); ++i) {
          if (!SegmentTouchesBox(a, b, boxes[i])) continue;
          ++touched;
          ASSERT_TRUE(std::binary_search(got.begin(), got.end(), int(i)))
              << "box " << i << " missed by (" << a.transpose() << ") - (" << b.transpose() << ")";
        }
      }
    }
  }
  EXPECT_GT(touched, 500);
}

TEST(RayBinsTest, CullsBoxesFarFromTheSegment) {
  std::vector<Box> boxes;
  for (int i = 0; i < 100; ++i)
    boxes.emplace_back(Eigen::Vector2d(i, 0.0), Eigen::Vector2d(i + 0.5, 0.5));
  RayBins bins;
  bins.Build(boxes, 1.0);
  std::vector<int> got;
  bins.Query({10.2, -1.0}, {10.2, 2.0}, &got);
  EXPECT_TRUE(std::binary_search(got.begin(), got.end(), 10));
  EXPECT_LE(got.size(), 4u);
  bins.Query({-10.0, 50.0}, {-20.0, 60.0}, &got);  // off the grid entirely
  EXPECT_TRUE(got.empty());
}

TEST(RayBinsTest, UnboundedBoxesAreReturnedByEveryQuery) {
  std::vector<Box> boxes = {
      {Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 1)},
      {Eigen::Vector2d::Constant(-INFINITY), Eigen::Vector2d::Constant(INFINITY)},  // a plane
      {Eigen::Vector2d(-1e4, -1e4), Eigen::Vector2d(1e4, 1e4)}};  // too many cells to bin
  RayBins bins;
  bins.Build(boxes, 1.0);
  std::vector<int> got;
  bins.Query({50.0, 50.0}, {51.0, 50.0}, &got);
  EXPECT_EQ(got, (std::vector<int>{1, 2}));
  bins.Query({0.5, -1.0}, {0.5, 2.0}, &got);
  EXPECT_EQ(got, (std::vector<int>{0, 1, 2}));
}

}  // namespace
}  // namespace egress::twin::world_detail
