// The returns localization matches against the building map: a door's leaf, open or closed,
// seen from either side, is not on the floor plan.

#include "localization_scan.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace egress::behavior::detail {
namespace {

// A wall along y = 0 (0.1 m thick) with a 0.9 m doorway from x = 0 (hinge) to 0.9 (latch), its
// leaf opening to +y.
MissionMap WallWithDoor() {
  MissionMap map;
  map.grid = perception::OccupancyGrid::FromBoxes(
      {{{-1.5, 0.0, 0.0}, {3.0, 0.1}}, {{2.45, 0.0, 0.0}, {3.1, 0.1}}}, {-3.0, -2.0}, {4.0, 2.0},
      0.05);
  map.doors.push_back({"door", {0.0, 0.0}, {0.9, 0.0}, 1.0, std::numbers::pi / 2});
  return map;
}

// A scan from the laser at X_ML whose beams end at the points p_M (one beam each, in the order
// given, at whatever angle they are; the increment is nominal).
LaserScan ScanOf(const Pose2& X_ML, const std::vector<Eigen::Vector2d>& p_M) {
  LaserScan scan;
  scan.angle_min = -std::numbers::pi;
  scan.angle_increment = 2 * std::numbers::pi / double(p_M.size());
  scan.range_min = 0.05;
  scan.range_max = 20.0;
  for (std::size_t i = 0; i < p_M.size(); ++i) {
    const Eigen::Vector2d p_L = X_ML.Inverse() * p_M[i];
    const double a = scan.AngleAt(i);
    // The beam's own direction must point at the point: place the point along it instead.
    const double r = p_L.norm();
    scan.ranges.push_back(float(r));
    EXPECT_LT(std::abs(std::remainder(std::atan2(p_L.y(), p_L.x()) - a, 2 * std::numbers::pi)),
              1e-9)
        << "test set-up: point " << i << " is not on its beam";
  }
  return scan;
}

// A scan all round from the laser at X_ML (south of the wall) of the wall's south face
// (y = -0.05) and, between the jambs, of the closed leaf's (y = -0.02); beams that never meet
// them have no return. `ends`: where each beam ends (NaN for none).
LaserScan ScanOfShutDoor(const Pose2& X_ML, std::size_t beams, std::vector<Eigen::Vector2d>* ends) {
  LaserScan scan;
  scan.angle_min = -std::numbers::pi;
  scan.angle_increment = 2 * std::numbers::pi / double(beams);
  scan.range_min = 0.05;
  scan.range_max = 20.0;
  for (std::size_t i = 0; i < beams; ++i) {
    const double a = X_ML.yaw + scan.AngleAt(i);
    const Eigen::Vector2d d(std::cos(a), std::sin(a));
    Eigen::Vector2d end = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
    float range = std::numeric_limits<float>::infinity();
    if (d.y() > 1e-6) {
      double t = (-0.02 - X_ML.y) / d.y();
      end = X_ML.translation() + t * d;
      if (end.x() <= 0.0 || end.x() >= 0.9) {
        t = (-0.05 - X_ML.y) / d.y();
        end = X_ML.translation() + t * d;
      }
      if (t <= scan.range_max) range = float(t);
    }
    scan.ranges.push_back(range);
    ends->push_back(end);
  }
  return scan;
}

TEST(LocalizationScanTest, AClosedLeafSeenFromTheSideItDoesNotOpenToIsLeftOut) {
  // The laser 0.8 m south of the doorway's middle, facing it.
  const Pose2 X_ML{0.45, -0.8, std::numbers::pi / 2};
  std::vector<Eigen::Vector2d> ends;
  const LaserScan scan = ScanOfShutDoor(X_ML, 720, &ends);
  const LaserScan kept = WithoutDoorLeaves(scan, WallWithDoor(), X_ML);
  int leaf = 0, wall = 0;
  for (std::size_t i = 0; i < ends.size(); ++i) {
    const Eigen::Vector2d& p = ends[i];
    if (!std::isfinite(scan.ranges[i])) continue;
    if (p.x() > 0.05 && p.x() < 0.85) {
      EXPECT_TRUE(std::isinf(kept.ranges[i])) << "leaf return at x = " << p.x() << " kept";
      ++leaf;
    } else if (p.x() < -0.1 || p.x() > 1.0) {
      EXPECT_EQ(kept.ranges[i], scan.ranges[i]) << "wall return at x = " << p.x() << " dropped";
      ++wall;
    }
  }
  EXPECT_GT(leaf, 50);
  EXPECT_GT(wall, 50);
}

// Returns all round a door, out to past its reach (and the door line's band beyond the
// latch): each is dropped exactly when one of the documented tests holds (in the leaf's reach;
// in its sweep away from the mapped walls; on the door's line between the jambs).
TEST(LocalizationScanTest, EachReturnIsDroppedExactlyWhenALeafTestHolds) {
  const MissionMap map = WallWithDoor();
  const auto& door = map.doors.front();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> range(0.05, 1.6);
  for (const Pose2& X_ML : {Pose2{0.45, 0.6, 0.3}, Pose2{1.2, -0.4, 2.0}, Pose2{-0.2, 0.3, 1.0}}) {
    const std::size_t beams = 2000;
    std::vector<Eigen::Vector2d> points;
    for (std::size_t i = 0; i < beams; ++i) {
      const double a = X_ML.yaw - std::numbers::pi + 2 * std::numbers::pi * double(i) / beams;
      points.push_back(X_ML.translation() + range(rng) * Eigen::Vector2d(std::cos(a), std::sin(a)));
    }
    const LaserScan scan = ScanOf(X_ML, points);
    const LaserScan kept = WithoutDoorLeaves(scan, map, X_ML);
    int dropped = 0;
    for (std::size_t i = 0; i < beams; ++i) {
      const Eigen::Vector2d& p = points[i];
      const Eigen::Vector2d offset = p - door.p_MHinge;
      const bool in_sweep =
          offset.norm() <= door.width() + kSweepMarginM && offset.dot(door.SwingSide()) > 0.0;
      const bool leaf = door.InLeafReach(p, kSweepMarginM) ||
                        (in_sweep && !NearMappedWall(map.grid, p)) ||
                        door.OnDoorLine(p, kClosedLeafBandM);
      ASSERT_EQ(std::isinf(kept.ranges[i]), leaf) << "return at " << p.transpose();
      dropped += leaf;
    }
    EXPECT_GT(dropped, 100);
    EXPECT_LT(dropped, int(beams) - 100);
  }
}

TEST(LocalizationScanTest, InTheSweepOnlyTheMappedWallsAreKept) {
  const MissionMap map = WallWithDoor();
  const Pose2 X_ML{0.45, 1.5, -std::numbers::pi / 2};
  // Beam 0 points behind the laser (north), then round counter-clockwise in quarter turns.
  const std::vector<Eigen::Vector2d> points = {
      {0.45, 3.0},  // behind the laser: open floor, kept
      {-1.0, 1.5},  // west: beyond the sweep, kept
      {0.45, 0.6},  // the open leaf (or someone under it), in the sweep: left out
      {2.0, 1.5}};  // east: kept
  const LaserScan scan = ScanOf(X_ML, points);
  const LaserScan kept = WithoutDoorLeaves(scan, map, X_ML);
  EXPECT_EQ(kept.ranges[0], scan.ranges[0]);
  EXPECT_EQ(kept.ranges[1], scan.ranges[1]);
  EXPECT_TRUE(std::isinf(kept.ranges[2]));
  EXPECT_EQ(kept.ranges[3], scan.ranges[3]);
  // The wall's face beside the hinge lies in the sweep's quarter disc but is the floor plan.
  const Pose2 X_ML_west{-0.3, 1.0, -std::numbers::pi / 2};
  const LaserScan at_wall = ScanOf(X_ML_west, {{-0.3, 2.0}, {-1.3, 1.0}, {-0.3, 0.05}, {0.7, 1.0}});
  const LaserScan wall_kept = WithoutDoorLeaves(at_wall, map, X_ML_west);
  EXPECT_EQ(wall_kept.ranges[2], at_wall.ranges[2]);
}

TEST(LocalizationScanTest, AnOpenLeafIsLeftOutRightUpToItsHingeBesideTheWall) {
  // The clinic's exit: the robot past the door line, the leaf open 90 degrees along +y from the
  // hinge, its face at x = 0.02. By the hinge its returns lie within kWallMatchM of the wall's
  // end: matched to it, they pulled the estimate back and round.
  const MissionMap map = WallWithDoor();
  const Pose2 X_ML{0.6, 0.8, std::numbers::pi / 2};
  const std::vector<Eigen::Vector2d> points = {
      {0.6, 3.0},     // ahead: open floor, kept
      {0.02, 0.08},   // the leaf 8 cm from the hinge
      {0.02, 0.14},   // and 14 cm
      {0.02, 0.5},    // and mid-leaf
      {-1.2, 0.05}};  // the wall's face past the hinge: the floor plan, kept
  ASSERT_TRUE(NearMappedWall(map.grid, points[1]));
  // 3600 beams, a return only on the beam nearest each point (within 2 mm of it here).
  LaserScan scan;
  scan.angle_min = -std::numbers::pi;
  scan.angle_increment = 2 * std::numbers::pi / 3600.0;
  scan.range_min = 0.05;
  scan.range_max = 20.0;
  scan.ranges.assign(3600, std::numeric_limits<float>::infinity());
  std::vector<std::size_t> beam;
  for (const Eigen::Vector2d& p_M : points) {
    const Eigen::Vector2d p_L = X_ML.Inverse() * p_M;
    const double a = std::atan2(p_L.y(), p_L.x());
    beam.push_back(std::size_t(std::lround((a - scan.angle_min) / scan.angle_increment)) % 3600);
    scan.ranges[beam.back()] = float(p_L.norm());
  }
  const LaserScan kept = WithoutDoorLeaves(scan, map, X_ML);
  EXPECT_EQ(kept.ranges[beam[0]], scan.ranges[beam[0]]);
  EXPECT_TRUE(std::isinf(kept.ranges[beam[1]]));
  EXPECT_TRUE(std::isinf(kept.ranges[beam[2]]));
  EXPECT_TRUE(std::isinf(kept.ranges[beam[3]]));
  EXPECT_EQ(kept.ranges[beam[4]], scan.ranges[beam[4]]);
}

TEST(LocalizationScanTest, ReturnsBesideADoorwayAreTheWall) {
  const MissionMap map = WallWithDoor();
  EXPECT_TRUE(NearMappedWall(map.grid, {-0.5, 0.06}));
  EXPECT_FALSE(NearMappedWall(map.grid, {0.45, 0.0}));  // the doorway is a gap in the plan
  EXPECT_FALSE(NearMappedWall(map.grid, {-0.5, 0.5}));
}

// The leaf where it was last estimated: the segment from the hinge to its free edge, not the
// sweep round it (someone standing in a held-open leaf's sweep is no leaf).
TEST(LocalizationScanTest, ReturnsOnALeafWhereItWasLastEstimatedAreNearIt) {
  perception::TrackedDoor door;
  door.model = WallWithDoor().doors.front();  // hinge (0, 0), 0.9 m, opening to +y
  door.state.angle = std::numbers::pi / 2;    // the free edge at (0, 0.9)
  EXPECT_FALSE(NearEstimatedLeaf(door, {0.05, 0.5}, 0.15)) << "never observed";
  door.state.observed = true;
  EXPECT_TRUE(NearEstimatedLeaf(door, {0.05, 0.5}, 0.15));
  EXPECT_TRUE(NearEstimatedLeaf(door, {-0.1, 0.95}, 0.15));  // past the free edge, within margin
  EXPECT_FALSE(NearEstimatedLeaf(door, {0.0, 1.1}, 0.15));
  EXPECT_FALSE(NearEstimatedLeaf(door, {0.5, 0.5}, 0.15));  // in its sweep, off the leaf
  door.state.angle = 0.0;                                   // shut: along the door line
  EXPECT_TRUE(NearEstimatedLeaf(door, {0.5, 0.1}, 0.15));
  EXPECT_FALSE(NearEstimatedLeaf(door, {0.05, 0.5}, 0.15));
}

}  // namespace
}  // namespace egress::behavior::detail
