#include "egress/perception/door_estimation.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress::perception {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
using std::chrono::milliseconds;

// A 0.9 m door in a wall along y = 0, hinge at x = 0, latch at x = 0.9, opening toward +y.
DoorModel LabDoor() {
  return {"lab", {0.0, 0.0}, {0.9, 0.0}, 1.0, std::numbers::pi / 2};
}

// Laser-like samples of the leaf at `angle` and of the wall on both sides, with noise.
std::vector<Eigen::Vector2d> DoorPoints(const DoorModel& door, double angle, std::mt19937& random) {
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<Eigen::Vector2d> points;
  const Eigen::Vector2d tip = door.LeafTip(angle);
  for (double s = 0.02; s <= 1.0; s += 0.04) {
    points.push_back(door.p_MHinge + s * (tip - door.p_MHinge) +
                     Eigen::Vector2d(noise(random), noise(random)));
  }
  for (double x = -1.5; x < -0.05; x += 0.05)
    points.emplace_back(x, noise(random));  // wall, hinge side
  for (double x = 0.95; x < 2.5; x += 0.05)
    points.emplace_back(x, noise(random));  // wall, latch side
  return points;
}

TEST(DoorEstimationTest, AngleOpenFractionAndClearanceAtKeyAngles) {
  const DoorModel door = LabDoor();
  std::mt19937 random(3);
  for (double degrees : {0.0, 30.0, 60.0, 90.0}) {
    const auto measurement = MeasureDoorAngle(door, DoorPoints(door, degrees * kDeg, random));
    ASSERT_TRUE(measurement.has_value()) << degrees;
    EXPECT_NEAR(measurement->angle / kDeg, degrees, 3.0);
    DoorStateTracker tracker(door);
    tracker.Update(measurement->angle, milliseconds(0));
    EXPECT_NEAR(tracker.state().open_fraction, degrees / 90.0, 0.04) << degrees;
    EXPECT_NEAR(tracker.state().clearance_width, 0.9 * (1 - std::cos(degrees * kDeg)), 0.05)
        << degrees;
  }
  // The paper's S3 failure: a half-open door is not "closed".
  DoorStateTracker half(door);
  half.Update(45 * kDeg, milliseconds(0));
  EXPECT_NE(half.state().motion, DoorMotion::kClosed);
  EXPECT_GT(half.state().clearance_width, 0.25);
}

TEST(DoorEstimationTest, TheLeafReachIsTheQuarterDiscItTurnsThroughGrownByTheMargin) {
  const DoorModel door = LabDoor();  // hinge at the origin, latch at (0.9, 0), opening to +y
  EXPECT_TRUE(door.InLeafReach({0.5, 0.5}, 0.0));     // under the opening leaf
  EXPECT_TRUE(door.InLeafReach({0.02, 0.1}, 0.1));    // the open leaf by its hinge
  EXPECT_TRUE(door.InLeafReach({-0.05, 0.5}, 0.1));   // the open leaf's far face
  EXPECT_FALSE(door.InLeafReach({-0.2, 0.5}, 0.1));   // past the open leaf
  EXPECT_FALSE(door.InLeafReach({-0.3, 0.05}, 0.1));  // the wall's face beside the hinge
  EXPECT_TRUE(door.InLeafReach({0.5, -0.05}, 0.1));   // the closed leaf's other face
  EXPECT_FALSE(door.InLeafReach({0.5, -0.2}, 0.1));   // behind the door line
  EXPECT_FALSE(door.InLeafReach({0.8, 0.8}, 0.1));    // 1.13 m from the hinge
  EXPECT_TRUE(door.InLeafReach({0.05, 0.0}, 0.1));    // at the hinge
  DoorModel narrow = door;
  narrow.max_open_angle = std::numbers::pi / 4;  // a leaf that opens only 45 degrees
  EXPECT_TRUE(narrow.InLeafReach({0.5, 0.4}, 0.0));
  EXPECT_FALSE(narrow.InLeafReach({0.2, 0.5}, 0.0));
}

TEST(DoorEstimationTest, TheSweepIsTheHalfDiscOnTheSwingSideGrownByTheMargin) {
  const DoorModel door = LabDoor();
  EXPECT_TRUE(door.InSweep({0.5, 0.5}, 0.0));    // under the opening leaf
  EXPECT_FALSE(door.InSweep({0.5, -0.5}, 0.0));  // behind the door line
  EXPECT_FALSE(door.InSweep({0.8, 0.8}, 0.0));   // 1.13 m from the hinge
  EXPECT_TRUE(door.InSweep({0.8, 0.8}, 0.3));
  EXPECT_TRUE(door.InSweep({0.5, -0.1}, 0.2));  // within the margin of the line
  EXPECT_FALSE(door.InSweep({0.5, -0.3}, 0.2));
}

TEST(DoorEstimationTest, TheDoorLineIsBetweenTheJambsOnEitherSide) {
  const DoorModel door = LabDoor();
  EXPECT_TRUE(door.OnDoorLine({0.5, 0.0}, 0.1));
  EXPECT_TRUE(door.OnDoorLine({0.5, 0.08}, 0.1));    // the swing side
  EXPECT_TRUE(door.OnDoorLine({0.5, -0.08}, 0.1));   // the other side (a closed leaf's face)
  EXPECT_TRUE(door.OnDoorLine({0.88, -0.05}, 0.1));  // by the latch
  EXPECT_FALSE(door.OnDoorLine({0.5, -0.12}, 0.1));
  EXPECT_FALSE(door.OnDoorLine({-0.05, 0.0}, 0.1));  // past the hinge jamb: the wall
  EXPECT_FALSE(door.OnDoorLine({0.95, 0.0}, 0.1));   // past the latch jamb
  EXPECT_FALSE(door.OnDoorLine({0.5, 0.5}, 0.1));    // under the opening leaf, not on the line
}

TEST(DoorEstimationTest, NoLeafSeenIsNoMeasurement) {
  EXPECT_FALSE(MeasureDoorAngle(LabDoor(), {{5.0, 5.0}, {-2.0, 0.0}}).has_value());
}

TEST(DoorEstimationTest, GlassDoorLineFitRecoversTheAngleWithin3Degrees) {
  const DoorModel door = LabDoor();
  std::mt19937 random(11);
  std::normal_distribution<double> noise(0.0, 0.012);
  std::uniform_real_distribution<double> clutter(-0.5, 1.5);
  for (double degrees : {20.0, 37.0, 75.0}) {
    const Eigen::Vector2d tip = door.LeafTip(degrees * kDeg);
    std::vector<Eigen::Vector2d> points;
    for (double s = 0.1; s <= 0.95; s += 0.03) {
      points.push_back(s * tip + Eigen::Vector2d(noise(random), noise(random)));
    }
    for (int i = 0; i < 10; ++i)
      points.emplace_back(clutter(random), clutter(random));  // ~30% outliers
    const auto fit = FitLineRansac(points);
    ASSERT_TRUE(fit.has_value());
    const auto angle = DoorAngleFromLine(door, *fit);
    ASSERT_TRUE(angle.has_value());
    EXPECT_NEAR(*angle / kDeg, degrees, 3.0);
    EXPECT_LT(fit->rms, 0.02);
  }
  EXPECT_FALSE(FitLineRansac({{0, 0}, {1, 1}}).has_value());  // too few points
}

TEST(DoorEstimationTest, BoxBearingsFollowTheCameraMount) {
  // Camera optical frame looking along the laser's x axis.
  const Pose3 X_LC =
      Pose3::FromXyzRpy({0.0, 0.0, 0.8}, {-std::numbers::pi / 2, 0.0, -std::numbers::pi / 2});
  const CameraIntrinsics K = CameraIntrinsics::FromHorizontalFov(640, 480, 1.047);
  const auto [lo, hi] = BoxBearingsInLaser({0, 200, 640, 280}, K, X_LC);
  EXPECT_NEAR(lo, -1.047 / 2, 1e-6);  // the image's right edge is to the robot's right
  EXPECT_NEAR(hi, 1.047 / 2, 1e-6);
}

TEST(DoorStateTrackerTest, OpeningHeldAndClosing) {
  DoorStateTracker tracker(LabDoor());
  Time t{0};
  const auto step = [&](double degrees) {
    t += milliseconds(100);
    tracker.Update(degrees * kDeg, t);
  };
  step(0);
  EXPECT_EQ(tracker.state().motion, DoorMotion::kClosed);
  for (double a = 10; a <= 80; a += 10)
    step(a);  // ADA operator opening ~25 deg/s
  EXPECT_EQ(tracker.state().motion, DoorMotion::kOpening);
  for (int i = 0; i < 25; ++i)
    step(80);
  EXPECT_EQ(tracker.state().motion, DoorMotion::kHeldOpen);
  for (double a = 70; a >= 30; a -= 10)
    step(a);
  EXPECT_EQ(tracker.state().motion, DoorMotion::kClosing);
  EXPECT_THROW(tracker.Update(std::nan(""), t), InvalidArgument);
  EXPECT_THROW(tracker.Update(0.0, Time{0}), InvalidArgument);  // time went backwards
  EXPECT_THROW(DoorStateTracker({"bad", {0, 0}, {0, 0}}), InvalidArgument);
}

// A leaf seen again after longer than stale_after is where it is seen, not a blend with where it
// was seconds ago (random building seed 7: door_n1 last seen held open, seen shut 12 s later).
// Its rate is unknown then; within stale_after, measurements blend as ever.
TEST(DoorStateTrackerTest, ALeafSeenAgainAfterAGapIsWhereItIsSeen) {
  DoorStateTracker tracker(LabDoor());
  Time t{0};
  for (int i = 0; i < 20; ++i) {
    t += milliseconds(100);
    tracker.Update(75 * kDeg, t);
  }
  ASSERT_EQ(tracker.state().motion, DoorMotion::kHeldOpen);
  t += milliseconds(900);  // within stale_after (1 s): blended
  EXPECT_FALSE(tracker.IsStaleAt(t));
  tracker.Update(0.0, t);
  EXPECT_NEAR(tracker.state().angle, 37.5 * kDeg, 1e-9);
  for (int i = 0; i < 20; ++i) {
    t += milliseconds(100);
    tracker.Update(75 * kDeg, t);
  }
  t += milliseconds(12000);  // the operator has closed it meanwhile
  EXPECT_TRUE(tracker.IsStaleAt(t));
  tracker.Update(0.0, t);
  EXPECT_FALSE(tracker.IsStaleAt(t));
  EXPECT_DOUBLE_EQ(tracker.state().angle, 0.0);
  EXPECT_DOUBLE_EQ(tracker.state().rate, 0.0);
  EXPECT_EQ(tracker.state().motion, DoorMotion::kClosed);
  DoorStateConfig bad;
  bad.stale_after = 0.0;
  EXPECT_THROW(DoorStateTracker(LabDoor(), bad), InvalidArgument);
}

TEST(DoorEstimationTest, ALineThatIsNotTheLeafGivesNoAngle) {
  const DoorModel door = LabDoor();
  const auto line_through = [](Eigen::Vector2d a, Eigen::Vector2d b) {
    std::vector<Eigen::Vector2d> points;
    for (double s = 0.0; s <= 1.0; s += 0.05)
      points.push_back(a + s * (b - a));
    return *FitLineRansac(points);
  };
  // The wall past the hinge: the line runs through the hinge but away from the leaf's side.
  EXPECT_FALSE(DoorAngleFromLine(door, line_through({-0.6, 0.0}, {-0.05, 0.0})).has_value());
  // Something parallel half a metre into the room: misses the hinge.
  EXPECT_FALSE(DoorAngleFromLine(door, line_through({0.0, 0.5}, {0.9, 0.5})).has_value());
  // Only the jamb at the hinge.
  EXPECT_FALSE(DoorAngleFromLine(door, line_through({0.0, -0.03}, {0.0, 0.03})).has_value());
  // The leaf itself at 30°.
  const auto leaf = DoorAngleFromLine(door, line_through(door.p_MHinge, door.LeafTip(30 * kDeg)));
  ASSERT_TRUE(leaf.has_value());
  EXPECT_NEAR(*leaf / kDeg, 30.0, 0.5);
}

TEST(DoorEstimationTest, GlassLeafAngleFromTheDetectorBoxEdges) {
  const DoorModel door = LabDoor();  // opens towards +y
  // The camera 1.2 m before the door on the other side, facing it.
  const Pose2 X_MV{0.45, -1.2, std::numbers::pi / 2};
  const Pose2 X_VM = X_MV.Inverse();
  const auto bearing = [&](const Eigen::Vector2d& p_M) {
    const Eigen::Vector2d p_V = X_VM * p_M;
    return std::atan2(p_V.y(), p_V.x());
  };
  const double hinge = bearing(door.p_MHinge);
  for (double degrees : {0.0, 40.0, 80.0}) {
    const double tip = bearing(door.LeafTip(degrees * kDeg));
    // Both edges, each a degree off (detector noise).
    const auto both =
        DoorAngleFromBearings(door, X_MV, std::min(tip, hinge) + kDeg, std::max(tip, hinge) - kDeg);
    ASSERT_TRUE(both.has_value()) << degrees;
    EXPECT_NEAR(*both / kDeg, degrees, 4.0);
    if (degrees > 0.0) {
      // Only the free edge's side in the image: still enough.
      const auto free_edge = DoorAngleFromBearings(door, X_MV, tip, std::nullopt);
      ASSERT_TRUE(free_edge.has_value()) << degrees;
      EXPECT_NEAR(*free_edge / kDeg, degrees, 2.0);
    }
  }
  // Only the hinge's edge in the image: any angle would do, so none is claimed.
  EXPECT_FALSE(DoorAngleFromBearings(door, X_MV, std::nullopt, hinge).has_value());
  EXPECT_FALSE(DoorAngleFromBearings(door, X_MV, std::nullopt, std::nullopt).has_value());
  // A box nowhere near the door.
  EXPECT_FALSE(DoorAngleFromBearings(door, X_MV, -1.2, -1.0).has_value());
}

TEST(DoorEstimationTest, BeamDirectionsAreEachBeamsCosineAndSineForEveryScanShape) {
  LaserScan a;
  a.angle_min = -2.1;
  a.angle_increment = 0.0175;
  a.ranges.assign(241, 1.0);
  LaserScan b = a;
  b.angle_min = -1.0;
  b.ranges.assign(7, 1.0);
  for (int round = 0; round < 2; ++round) {  // shapes in turn: each recomputed, never mixed up
    for (const LaserScan* scan : {&a, &b}) {
      const std::vector<Eigen::Vector2d>& u_L = BeamDirections(*scan);
      ASSERT_EQ(u_L.size(), scan->ranges.size());
      for (std::size_t i = 0; i < u_L.size(); ++i) {
        EXPECT_EQ(u_L[i].x(), std::cos(scan->AngleAt(i)));
        EXPECT_EQ(u_L[i].y(), std::sin(scan->AngleAt(i)));
      }
    }
  }
}

TEST(DoorEstimationTest, ScanPointsAreTheValidReturnsInTheMapFrame) {
  LaserScan scan;
  scan.angle_min = -std::numbers::pi / 2;
  scan.angle_increment = std::numbers::pi / 2;
  scan.range_min = 0.05;
  scan.range_max = 10.0;
  scan.ranges = {1.0, std::numeric_limits<float>::infinity(), 2.0};
  const Pose2 X_ML{1.0, 2.0, std::numbers::pi / 2};
  const std::vector<Eigen::Vector2d> p_M = ScanPoints(scan, X_ML);
  ASSERT_EQ(p_M.size(), 2u);
  // Beam 0 points along L's -y, which is M's +x; beam 2 along L's +y, M's -x.
  EXPECT_NEAR(p_M[0].x(), 2.0, 1e-12);
  EXPECT_NEAR(p_M[0].y(), 2.0, 1e-12);
  EXPECT_NEAR(p_M[1].x(), -1.0, 1e-12);
  EXPECT_NEAR(p_M[1].y(), 2.0, 1e-12);
  const std::vector<Eigen::Vector2d> ahead = ScanPointsInBearings(scan, X_ML, 0.1, 2.0);
  ASSERT_EQ(ahead.size(), 1u);
  EXPECT_NEAR(ahead[0].x(), -1.0, 1e-12);
}

}  // namespace
}  // namespace egress::perception
