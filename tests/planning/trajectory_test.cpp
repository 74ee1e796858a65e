#include "egress/planning/trajectory.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress::planning {
namespace {

TEST(QuinticTest, BoundaryConditions) {
  const QuinticPolynomial p(1.0, 0.0, 0.0, 3.0, 0.0, 0.0, 2.0);
  EXPECT_DOUBLE_EQ(p.Position(0.0), 1.0);
  EXPECT_NEAR(p.Position(2.0), 3.0, 1e-12);
  EXPECT_NEAR(p.Velocity(0.0), 0.0, 1e-12);
  EXPECT_NEAR(p.Velocity(2.0), 0.0, 1e-12);
  EXPECT_NEAR(p.Acceleration(0.0), 0.0, 1e-12);
  EXPECT_NEAR(p.Acceleration(2.0), 0.0, 1e-12);
  EXPECT_NEAR(p.Position(1.0), 2.0, 1e-12);                // symmetric
  EXPECT_NEAR(p.Velocity(1.0), 1.875 * 2.0 / 2.0, 1e-12);  // peak = 1.875 x average
  EXPECT_NEAR(p.Position(5.0), 3.0, 1e-12);                // clamped
  const QuinticPolynomial general(0.0, 0.5, -0.2, 1.0, 0.1, 0.3, 1.5);
  EXPECT_NEAR(general.Velocity(0.0), 0.5, 1e-12);
  EXPECT_NEAR(general.Acceleration(1.5), 0.3, 1e-9);
  EXPECT_NEAR(general.Velocity(1.5), 0.1, 1e-9);
  EXPECT_THROW(QuinticPolynomial(0, 0, 0, 1, 0, 0, 0.0), InvalidArgument);
}

TEST(TrajectoryTest, DurationRule) {
  const TrajectoryConfig config;
  EXPECT_DOUBLE_EQ(SegmentDuration(2.0, false, config), 10.0);  // 2 m / 0.2 m/s
  EXPECT_DOUBLE_EQ(SegmentDuration(2.0, true, config), 5.0);    // through a door, 0.4 m/s
  EXPECT_DOUBLE_EQ(SegmentDuration(0.05, false, config), 1.5);  // T_min
  EXPECT_THROW(SegmentDuration(-1.0, false, config), InvalidArgument);
}

// A base that turns far takes longer than its distance says: its yaw peaks at max_yaw_rate (a
// quarter turn, 1.875 * (pi / 2) / 0.6 = 4.9 s), and the whole-body plan takes the same time.
TEST(TrajectoryTest, DurationRuleWithATurn) {
  const TrajectoryConfig config;
  const double quarter = std::numbers::pi / 2;
  EXPECT_DOUBLE_EQ(SegmentDuration(0.5, quarter, true, config), 1.875 * quarter / 0.6);
  EXPECT_DOUBLE_EQ(SegmentDuration(0.5, -quarter, true, config), 1.875 * quarter / 0.6);
  EXPECT_DOUBLE_EQ(SegmentDuration(2.0, 0.1, true, config), 5.0);  // the distance rules
  EXPECT_THROW(SegmentDuration(0.5, std::nan(""), true, config), InvalidArgument);
  const RobotModel model = RobotModel::LoadDefault();
  WholeBodyVector a = WholeBodyVector::Zero(), b = a;
  b[kBaseX] = 0.5;
  b[kBaseYaw] = quarter;
  EXPECT_DOUBLE_EQ(WholeBodyTrajectory::Plan({a, b}, model, config, {true}).duration(),
                   SegmentDuration(0.5, quarter, true, config));
}

TEST(TrajectoryTest, WholeBodySegmentsAreSynchronizedAndTurnTheShortWay) {
  const RobotModel model = RobotModel::LoadDefault();
  WholeBodyVector a = WholeBodyVector::Zero(), b = a, c = a;
  a[kBaseYaw] = 3.0;
  b << 1.0, 0.0, -3.0, 0.3, -1.0, 0, 0, 0;  // yaw 3.0 -> -3.0 is +0.28 rad, not -6
  c << 1.0, 2.0, -3.0, 0.3, -1.0, 0, 0, 0;
  const WholeBodyTrajectory trajectory =
      WholeBodyTrajectory::Plan({a, b, c}, model, {}, {false, true});
  ASSERT_EQ(trajectory.segment_count(), 2u);
  EXPECT_DOUBLE_EQ(trajectory.segment_duration(0), 5.0);  // 1 m at 0.2 m/s
  EXPECT_DOUBLE_EQ(trajectory.segment_duration(1), 5.0);  // 2 m at 0.4 m/s (door)
  const double mid = trajectory.segment_duration(0) / 2;
  EXPECT_NEAR(trajectory.Sample(mid).q[kBaseYaw], WrapAngle(3.0 + (2 * std::numbers::pi - 6.0) / 2),
              1e-9);
  // Base and arm arrive together: at the segment's end both are at rest at the waypoint.
  const TrajectorySample end = trajectory.Sample(trajectory.segment_duration(0));
  EXPECT_NEAR(end.q[kBaseX], 1.0, 1e-9);
  EXPECT_NEAR(end.q[kArmFlex], -1.0, 1e-9);
  EXPECT_NEAR(end.qd.norm(), 0.0, 1e-9);
  EXPECT_NEAR(trajectory.Sample(trajectory.duration()).q[kBaseY], 2.0, 1e-9);
}

TEST(TrajectoryTest, JointSpeedLimitsStretchShortMoves) {
  const RobotModel model = RobotModel::LoadDefault();
  WholeBodyVector a = WholeBodyVector::Zero(), b = a;
  b[kArmFlex] = -2.4;  // 2.4 rad at most 1.2 rad/s: T >= 1.875 * 2.4 / 1.2 = 3.75 s
  const WholeBodyTrajectory trajectory = WholeBodyTrajectory::Plan({a, b}, model);
  EXPECT_NEAR(trajectory.duration(), 3.75, 1e-9);
  double peak = 0.0;
  for (double t = 0; t <= trajectory.duration(); t += 0.01)
    peak = std::max(peak, std::abs(trajectory.Sample(t).qd[kArmFlex]));
  EXPECT_LE(peak, 1.2 + 1e-6);
  EXPECT_THROW(WholeBodyTrajectory::Plan({a}, model), InvalidArgument);
}

}  // namespace
}  // namespace egress::planning
