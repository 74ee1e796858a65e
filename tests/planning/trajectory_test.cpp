#include "egress/planning/trajectory.h"

#include <algorithm>
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

// The paper's rule at door speed asks 5.77 * 0.6 / 1.5² = 1.54 m/s² of a 0.6 m step, more than
// the base's 1 m/s². Such a segment accelerates at the base's limit, coasts and brakes instead,
// in no less than 2 * sqrt(L / a); where the quintic fits within the limit it stays.
TEST(TrajectoryTest, ShortDoorSpeedSegmentsPeakWithinTheBaseAcceleration) {
  const RobotModel model = RobotModel::LoadDefault();
  const TrajectoryConfig config;
  for (const double length : {0.2, 0.4, 0.6, 0.8, 1.2, 3.0}) {
    WholeBodyVector a = WholeBodyVector::Zero(), b = a;
    b[kBaseX] = length;
    const WholeBodyTrajectory trajectory = WholeBodyTrajectory::Plan({a, b}, model, config, {true});
    double peak = 0.0, previous_x = 0.0;
    for (double t = 0.0; t <= trajectory.duration(); t += 1e-3) {
      const TrajectorySample sample = trajectory.Sample(t);
      peak = std::max(peak, std::abs(sample.qdd[kBaseX]));
      EXPECT_GE(sample.q[kBaseX], previous_x - 1e-12) << "never back: " << length << " m";
      previous_x = sample.q[kBaseX];
    }
    EXPECT_LE(peak, config.max_base_acceleration + 1e-9) << length << " m";
    const TrajectorySample end = trajectory.Sample(trajectory.duration());
    EXPECT_NEAR(end.q[kBaseX], length, 1e-12);
    EXPECT_NEAR(end.qd[kBaseX], 0.0, 1e-12);
    // Never shorter than the paper's rule, nor than the base needs.
    EXPECT_GE(trajectory.duration(), std::max(length / config.door_speed, config.min_duration));
    EXPECT_GE(trajectory.duration(), 2.0 * std::sqrt(length / config.max_base_acceleration));
  }
  // 0.6 m: the base's 2 * sqrt(0.6) = 1.55 s, near the paper's 1.5 s (a quintic within 1 m/s²
  // would take 1.86 s); it coasts at no more than it reaches accelerating half the time.
  EXPECT_NEAR(SegmentDuration(0.6, true, config), 2.0 * std::sqrt(0.6), 1e-12);
  EXPECT_FALSE(SegmentTimeScaling(0.6, SegmentDuration(0.6, true, config), config).quintic());
  // At the nominal speed and on long door-speed segments the paper's quintic stays.
  EXPECT_TRUE(SegmentTimeScaling(0.6, SegmentDuration(0.6, false, config), config).quintic());
  EXPECT_TRUE(SegmentTimeScaling(3.0, SegmentDuration(3.0, true, config), config).quintic());
  EXPECT_TRUE(SegmentTimeScaling(0.0, 1.5, config).quintic());
  // A gentler base takes longer; a stronger one gets the paper's time (and quintic) back.
  TrajectoryConfig gentle = config, strong = config;
  gentle.max_base_acceleration = 0.5;
  strong.max_base_acceleration = 10.0;
  EXPECT_GT(SegmentDuration(0.6, true, gentle), SegmentDuration(0.6, true, config));
  EXPECT_DOUBLE_EQ(SegmentDuration(0.6, true, strong), 1.5);
  EXPECT_TRUE(SegmentTimeScaling(0.6, 1.5, strong).quintic());
  for (const double bad : {0.0, -1.0, std::nan("")}) {
    TrajectoryConfig invalid = config;
    invalid.max_base_acceleration = bad;
    EXPECT_THROW(invalid.Validate(), InvalidArgument) << bad;
  }
  EXPECT_THROW(SegmentTimeScaling(-0.1, 1.5, config), InvalidArgument);
  EXPECT_THROW(SegmentTimeScaling(0.5, 0.0, config), InvalidArgument);
}

// The coasting profile: progress, rate and acceleration agree with one another (finite
// differences), start and end at rest, and peak at peak_rate().
TEST(TrajectoryTest, TheCoastingProfileIsConsistent) {
  const TrajectoryConfig config;
  const SegmentTimeScaling s(0.9, SegmentDuration(0.9, true, config), config);
  ASSERT_FALSE(s.quintic());
  EXPECT_DOUBLE_EQ(s.Progress(0.0), 0.0);
  EXPECT_DOUBLE_EQ(s.Progress(s.duration()), 1.0);
  EXPECT_DOUBLE_EQ(s.Rate(0.0), 0.0);
  EXPECT_NEAR(s.Rate(s.duration()), 0.0, 1e-12);
  double peak = 0.0;
  const double h = 1e-6;
  for (double t = 0.01; t < s.duration() - 0.01; t += 0.01) {
    EXPECT_NEAR((s.Progress(t + h) - s.Progress(t - h)) / (2 * h), s.Rate(t), 1e-6) << t;
    peak = std::max(peak, s.Rate(t));
  }
  EXPECT_NEAR(peak, s.peak_rate(), 1e-9);
  // The base's acceleration is the limit while it accelerates: L * d²σ/dt².
  EXPECT_NEAR(0.9 * s.Acceleration(0.01), config.max_base_acceleration, 1e-12);
  EXPECT_NEAR(0.9 * s.Acceleration(s.duration() - 0.01), -config.max_base_acceleration, 1e-12);
}

// A brisk segment (a step out of someone's way) accelerates at the base's limit from the
// start where the quintic, which would keep within it, starts at zero acceleration; in the
// same time, it ends at rest where the quintic does, and peaks no faster.
TEST(TrajectoryTest, BriskSegmentsAccelerateAtTheLimitFromTheStart) {
  TrajectoryConfig config;
  config.nominal_speed = 0.4;
  const double L = 1.0, T = SegmentDuration(L, false, config);
  const SegmentTimeScaling gentle(L, T, config);
  config.brisk = true;
  const SegmentTimeScaling brisk(L, T, config);
  ASSERT_TRUE(gentle.quintic());
  ASSERT_FALSE(brisk.quintic());
  EXPECT_DOUBLE_EQ(brisk.duration(), gentle.duration());
  EXPECT_NEAR(L * brisk.Acceleration(0.01), config.max_base_acceleration, 1e-12);
  EXPECT_LT(L * gentle.Acceleration(0.01), 0.05);
  // 5 cm/s within 0.06 s: the quintic takes 0.16 s.
  EXPECT_GT(L * brisk.Rate(0.06), 0.05);
  EXPECT_LT(L * gentle.Rate(0.1), 0.05);
  EXPECT_DOUBLE_EQ(brisk.Progress(T), 1.0);
  EXPECT_NEAR(brisk.Rate(T), 0.0, 1e-12);
  EXPECT_LE(brisk.peak_rate(), gentle.peak_rate());
  // A turn on the spot has no base distance to accelerate over: the quintic; nor has a step
  // too small to tell from none (its acceleration time would round to 0).
  EXPECT_TRUE(SegmentTimeScaling(0.0, 1.5, config).quintic());
  const SegmentTimeScaling tiny(1e-300, 1.5, config);
  EXPECT_TRUE(std::isfinite(tiny.Progress(0.7)) && std::isfinite(tiny.Acceleration(0.7)));
  EXPECT_TRUE(std::isfinite(tiny.peak_rate()));
}

// A short step with a turn: the coasting profile's peak rate (up to 2/T) still keeps the yaw
// under max_yaw_rate.
TEST(TrajectoryTest, ACoastingSegmentKeepsTheYawRate) {
  const RobotModel model = RobotModel::LoadDefault();
  const TrajectoryConfig config;
  WholeBodyVector a = WholeBodyVector::Zero(), b = a;
  b[kBaseX] = 0.6;
  b[kBaseYaw] = 0.5;
  const WholeBodyTrajectory trajectory = WholeBodyTrajectory::Plan({a, b}, model, config, {true});
  double peak = 0.0;
  for (double t = 0.0; t <= trajectory.duration(); t += 1e-3)
    peak = std::max(peak, std::abs(trajectory.Sample(t).qd[kBaseYaw]));
  EXPECT_LE(peak, config.max_yaw_rate + 1e-9);
  EXPECT_GT(trajectory.duration(), SegmentDuration(0.6, true, config));  // stretched for it
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
