// ScanMotion (perception/scan_motion.h): which laser returns off the map moved.

#include "egress/perception/scan_motion.h"

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress::perception {
namespace {

Time At(double t) {
  return SecondsToDuration(t);
}

// Two legs of a person at p: returns on their near sides.
std::vector<Eigen::Vector2d> Legs(const Eigen::Vector2d& p) {
  return {p + Eigen::Vector2d(-0.1, 0.0), p + Eigen::Vector2d(-0.1, 0.02),
          p + Eigen::Vector2d(0.1, 0.0), p + Eigen::Vector2d(0.1, 0.02)};
}

TEST(ScanMotionTest, StandingLegsStayAndWalkingOnesMove) {
  ScanMotion motion;
  const Pose2 X_ML{0.0, 0.0, 0.0};
  // Standing: the same returns give or take the laser's noise, scan after scan.
  for (int k = 0; k <= 10; ++k) {
    std::vector<Eigen::Vector2d> legs = Legs({2.0, 0.0});
    for (auto& q : legs)
      q.x() += (k % 2 ? 0.01 : -0.01);
    EXPECT_TRUE(motion.Update(At(0.1 * k), X_ML, legs).empty()) << "scan " << k;
  }
  // Walking at 1 m/s: half a second later the legs are half a metre on.
  ScanMotion walking;
  std::size_t moved = 0;
  for (int k = 0; k <= 10; ++k)
    moved = walking.Update(At(0.1 * k), X_ML, Legs({2.0 + 0.1 * k, 0.0})).size();
  EXPECT_EQ(moved, 4u);
}

TEST(ScanMotionTest, NothingMovesUntilAScanAWindowOldAndNotFromAMovingLaser) {
  ScanMotion motion;  // window 0.5 s
  EXPECT_TRUE(motion.Update(At(0.0), {0, 0, 0}, Legs({2.0, 0.0})).empty());
  EXPECT_TRUE(motion.Update(At(0.3), {0, 0, 0}, Legs({2.3, 0.0})).empty());  // too recent
  EXPECT_FALSE(motion.Update(At(0.6), {0, 0, 0}, Legs({2.6, 0.0})).empty());
  // The laser moved 0.2 m: the earlier scans are from elsewhere (shadows shift), no motion.
  EXPECT_TRUE(motion.Update(At(1.2), {0.2, 0, 0}, Legs({3.2, 0.0})).empty());
  EXPECT_TRUE(motion.Update(At(1.5), {0.2, 0, 0}, Legs({3.5, 0.0})).empty());
  EXPECT_FALSE(motion.Update(At(1.8), {0.2, 0, 0}, Legs({3.8, 0.0})).empty());
  // A return with nothing near it earlier came out from behind something: not motion.
  EXPECT_TRUE(motion.Update(At(2.4), {0.2, 0, 0}, {Eigen::Vector2d(-3.0, 4.0)}).empty());
}

TEST(ScanMotionTest, MoreOfAStandingBodySeenPastAShadowsEdgeIsNotMotion) {
  ScanMotion motion;
  const Pose2 X_ML{0.0, 0.0, 0.0};
  // A person standing at 4 m, half in another's shadow: then a ray that grazed their far leg
  // hits it, 0.2 m from the returns already seen, all of which are still there.
  const std::vector<Eigen::Vector2d> half = Legs({4.0, 0.0});
  std::vector<Eigen::Vector2d> whole = half;
  whole.emplace_back(4.0, 0.25);
  EXPECT_TRUE(motion.Update(At(0.0), X_ML, half).empty());
  EXPECT_TRUE(motion.Update(At(0.5), X_ML, whole).empty());
  // A leg that leaves its place for one 0.3 m on still moves.
  std::vector<Eigen::Vector2d> stepped = whole;
  stepped[0] += Eigen::Vector2d(0.0, -0.3);
  stepped[1] += Eigen::Vector2d(0.0, -0.3);
  EXPECT_EQ(motion.Update(At(1.0), X_ML, stepped).size(), 2u);
}

TEST(ScanMotionTest, NothingFartherThanMaxRangeIsJudged) {
  // The same walk 4 m and 9 m from the laser: beyond max_range (6 m) a wall's grazed returns
  // slide with the pose estimate's heading error, so nothing there is reported moving.
  for (const double x : {4.0, 9.0}) {
    ScanMotion motion;
    std::size_t moved = 0;
    for (int k = 0; k <= 10; ++k)
      moved = motion.Update(At(0.1 * k), {0, 0, 0}, Legs({x + 0.1 * k, 0.0})).size();
    EXPECT_EQ(moved, x < 6.0 ? 4u : 0u) << "at " << x << " m";
  }
  ScanMotionConfig far;
  far.max_range = 20.0;
  ScanMotion motion(far);
  std::size_t moved = 0;
  for (int k = 0; k <= 10; ++k)
    moved = motion.Update(At(0.1 * k), {0, 0, 0}, Legs({9.0 + 0.1 * k, 0.0})).size();
  EXPECT_EQ(moved, 4u);
}

TEST(ScanMotionTest, BadInputIsRefused) {
  ScanMotionConfig bad;
  bad.step = 2.0;  // beyond reach
  EXPECT_THROW(ScanMotion{bad}, InvalidArgument);
  ScanMotionConfig no_range;
  no_range.max_range = 0.0;
  EXPECT_THROW(ScanMotion{no_range}, InvalidArgument);
  ScanMotion motion;
  motion.Update(At(1.0), {0, 0, 0}, {});
  EXPECT_THROW(motion.Update(At(0.5), {0, 0, 0}, {}), InvalidArgument);
  EXPECT_THROW(motion.Update(At(2.0), {NAN, 0, 0}, {}), InvalidArgument);
}

}  // namespace
}  // namespace egress::perception
