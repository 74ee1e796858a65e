// FreeSpaceMotion (perception/free_space_motion.h): whether the returns at a place moved, judged
// along the beams of a laser that may itself be moving.

#include "egress/perception/free_space_motion.h"

#include <cmath>

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"
#include "synthetic.h"

namespace egress::perception {
namespace {

using testing::Disc;

// A 270 deg, 1081-beam scan at `t` from a laser at X_ML, of discs (legs, pillars), in the
// two-room map when `in_rooms` (its walls behind them).
LaserScan Cast(double t, const Pose2& X_ML, const std::vector<Disc>& discs, bool in_rooms = false) {
  static const OccupancyGrid kRooms = testing::TwoRoomMap();
  LaserScan scan = testing::MakeScan(1081, 10.0);
  scan.stamp = SecondsToDuration(t);
  testing::CastScanAtDiscs(discs, X_ML, &scan, in_rooms ? &kRooms : nullptr);
  return scan;
}

// A person's two legs (6 cm radius) about p, 0.25 m apart across the direction `heading`.
std::vector<Disc> Legs(const Eigen::Vector2d& p, double heading = 0.0) {
  const Eigen::Vector2d side(-std::sin(heading) * 0.125, std::cos(heading) * 0.125);
  return {{p + side, 0.06}, {p - side, 0.06}};
}

constexpr double kPlaceRadiusM = 0.35;

TEST(FreeSpaceMotionTest, StandingLegsSeenFromALaserDrivingAndTurningPastThemAreStill) {
  // Three people standing 2-3 m off the robot's path in a room (one beside a box); it drives by
  // at 0.4 m/s, turning.
  const std::vector<Eigen::Vector2d> people{{3.0, 3.0}, {3.3, 3.6}, {4.0, 2.5}};
  std::vector<Disc> discs;
  for (const auto& p : people)
    for (const Disc& leg : Legs(p, 0.7))
      discs.push_back(leg);
  FreeSpaceMotion motion;
  int still = 0;
  double slid = 0.0;  // how far a person's returns' centroid moved between scans, at most
  std::vector<Eigen::Vector2d> centroid_before;
  for (int k = 0; k <= 40; ++k) {
    const double t = 0.1 * k;
    const Pose2 X_ML{1.0 + 0.4 * t, 1.0, 0.15 * t};
    const LaserScan scan = Cast(t, X_ML, discs, true);
    motion.AddScan(scan, X_ML);
    std::vector<Eigen::Vector2d> centroid;
    for (const auto& p : people) {
      const PlaceMotion m = motion.Judge(p, kPlaceRadiusM);
      EXPECT_NE(m, PlaceMotion::kMoved) << "t " << t << " person at " << p.transpose();
      still += m == PlaceMotion::kStill;
      Eigen::Vector2d sum = Eigen::Vector2d::Zero();
      int n = 0;
      for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
        if (!scan.IsValidReturn(i)) continue;
        const double a = scan.AngleAt(i), r = scan.ranges[i];
        const Eigen::Vector2d q = X_ML * Eigen::Vector2d(r * std::cos(a), r * std::sin(a));
        if ((q - p).norm() < 0.25) {
          sum += q;
          ++n;
        }
      }
      centroid.push_back(n > 0 ? Eigen::Vector2d(sum / n) : p);
    }
    for (std::size_t i = 0; i < centroid_before.size(); ++i)
      slid = std::max(slid, (centroid[i] - centroid_before[i]).norm());
    centroid_before = centroid;
  }
  // Not merely unknown: most places are judged, and still ...
  EXPECT_GT(still, 75);  // of 111 after the first baseline
  // ... while their returns slid by what would read as a walk differenced scan to scan.
  EXPECT_GT(slid, 0.03);
}

TEST(FreeSpaceMotionTest, SomeoneWalkingAcrossOrAwayMovedWhetherTheLaserMovesOrNot) {
  for (const double laser_speed : {0.0, 0.4}) {
    for (const double heading : {M_PI / 2, 0.0}) {  // across the beams, then straight away
      FreeSpaceMotion motion;
      int moved = 0, judged = 0;
      for (int k = 0; k <= 20; ++k) {
        const double t = 0.1 * k;
        const Pose2 X_ML{laser_speed * t, 0.0, 0.0};
        const Eigen::Vector2d p = Eigen::Vector2d(2.5, -0.5) +
                                  1.0 * t * Eigen::Vector2d(std::cos(heading), std::sin(heading));
        motion.AddScan(Cast(t, X_ML, Legs(p, heading)), X_ML);
        const PlaceMotion m = motion.Judge(p, kPlaceRadiusM);
        moved += m == PlaceMotion::kMoved;
        judged += m != PlaceMotion::kUnknown;
      }
      EXPECT_GT(judged, 10) << "laser " << laser_speed << " m/s, heading " << heading;
      EXPECT_EQ(moved, judged) << "laser " << laser_speed << " m/s, heading " << heading;
    }
  }
}

TEST(FreeSpaceMotionTest, SomeoneComingOutFromBehindAPillarAsTheLaserPassesIsNotMotion) {
  // A person standing behind a pillar (from where the laser starts), seen as it drives on.
  const Eigen::Vector2d person(4.0, 1.0);
  const std::vector<Disc> discs{{{2.0, 0.5}, 0.3}, Legs(person)[0], Legs(person)[1]};
  FreeSpaceMotion motion;
  int still = 0;
  for (int k = 0; k <= 30; ++k) {
    const double t = 0.1 * k;
    const Pose2 X_ML{0.0, -0.5 * t, 0.0};
    motion.AddScan(Cast(t, X_ML, discs), X_ML);
    const PlaceMotion m = motion.Judge(person, kPlaceRadiusM);
    EXPECT_NE(m, PlaceMotion::kMoved) << "t " << t;
    still += m == PlaceMotion::kStill;
  }
  EXPECT_GT(still, 0);
}

TEST(FreeSpaceMotionTest, UnknownWithoutAScanABaselineOlderOrWithNothingAtThePlace) {
  FreeSpaceMotion motion;  // baseline 0.4 s
  const Pose2 X_ML{0.0, 0.0, 0.0};
  const Eigen::Vector2d p(2.0, 0.0);
  motion.AddScan(Cast(0.0, X_ML, Legs(p)), X_ML);
  EXPECT_EQ(motion.Judge(p, kPlaceRadiusM), PlaceMotion::kUnknown);  // one scan
  motion.AddScan(Cast(0.3, X_ML, Legs(p)), X_ML);
  EXPECT_EQ(motion.Judge(p, kPlaceRadiusM), PlaceMotion::kUnknown);  // too recent
  motion.AddScan(Cast(0.5, X_ML, Legs(p)), X_ML);
  EXPECT_EQ(motion.Judge(p, kPlaceRadiusM), PlaceMotion::kStill);
  EXPECT_EQ(motion.Judge({-2.0, 3.0}, kPlaceRadiusM), PlaceMotion::kUnknown);  // no returns
  // A gap of seconds in the scans: the one before it is too old to say what moved now.
  motion.AddScan(Cast(5.0, X_ML, Legs(p)), X_ML);
  EXPECT_EQ(motion.Judge(p, kPlaceRadiusM), PlaceMotion::kUnknown);
}

TEST(FreeSpaceMotionTest, BadInputIsAClearError) {
  FreeSpaceMotionConfig config;
  config.margin = 0.0;
  EXPECT_THROW(
      {
        try {
          FreeSpaceMotion{config};
        } catch (const InvalidArgument& e) {
          EXPECT_NE(std::string(e.what()).find("margin"), std::string::npos) << e.what();
          throw;
        }
      },
      InvalidArgument);
  config = {};
  config.min_moved_share = 1.5;
  EXPECT_THROW(FreeSpaceMotion{config}, InvalidArgument);
  FreeSpaceMotion motion;
  const Pose2 X_ML{0.0, 0.0, 0.0};
  motion.AddScan(Cast(1.0, X_ML, {}), X_ML);
  EXPECT_THROW(motion.AddScan(Cast(0.5, X_ML, {}), X_ML), InvalidArgument);  // back in time
  EXPECT_THROW(motion.AddScan(Cast(2.0, X_ML, {}), {std::nan(""), 0.0, 0.0}), InvalidArgument);
  EXPECT_THROW(motion.Judge({std::nan(""), 0.0}, 0.3), InvalidArgument);
}

}  // namespace
}  // namespace egress::perception
