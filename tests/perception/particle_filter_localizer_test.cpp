#include "egress/perception/particle_filter_localizer.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"
#include "synthetic.h"

namespace egress::perception {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// Drives a multi-room route (through the doorway and back) at 0.5 m/s with 2% odometry drift
// (scale error on translation and rotation) and checks the pose is held within 5 cm / 2 deg.
TEST(ParticleFilterLocalizerTest, HoldsThePoseOverAMultiRoomRouteWithDriftingOdometry) {
  const OccupancyGrid map = testing::TwoRoomMap();
  const Pose2 X_BL{0.1675, 0.0, 0.0};
  ParticleFilterLocalizer localizer(map, X_BL);
  const std::vector<Eigen::Vector2d> route = {{1.5, 1.5}, {4.5, 4.0}, {7.5, 4.0}, {10.5, 3.0},
                                              {8.0, 6.5}, {6.5, 4.0}, {2.0, 4.5}};
  Pose2 truth{route[0].x(), route[0].y(), 0.6};
  Pose2 odometry = truth;  // odom frame starts aligned with the map
  localizer.Initialize({truth.x + 0.1, truth.y - 0.08, truth.yaw + 3 * kDeg},
                       Eigen::Vector3d(0.01, 0.01, 0.003).asDiagonal());
  LaserScan scan = testing::MakeScan(181, 8.0);
  localizer.Update(odometry, scan);

  constexpr double kDt = 0.2, kSpeed = 0.5, kDrift = 1.02;
  double worst_position = 0.0, worst_yaw = 0.0, travelled = 0.0;
  int steps = 0;
  for (std::size_t w = 1; w < route.size(); ++w) {
    while ((route[w] - truth.translation()).norm() > kSpeed * kDt) {
      const Eigen::Vector2d to_goal = route[w] - truth.translation();
      const double heading = std::atan2(to_goal.y(), to_goal.x());
      // The omnidirectional base translates toward the goal and turns toward its heading.
      const Pose2 step_B{
          kSpeed * kDt * std::cos(heading - truth.yaw),
          kSpeed * kDt * std::sin(heading - truth.yaw),
          std::clamp(WrapAngle(heading - truth.yaw), -0.3 * kDt * 5, 0.3 * kDt * 5) * 0.2};
      truth = truth * step_B;
      odometry = odometry * Pose2{step_B.x * kDrift, step_B.y * kDrift, step_B.yaw * kDrift};
      travelled += kSpeed * kDt;
      testing::CastScan(map, truth * X_BL, &scan);
      localizer.Update(odometry, scan);
      if (++steps > 10) {  // after the initial convergence
        const Pose2 estimate = localizer.Estimate();
        worst_position =
            std::max(worst_position, std::hypot(estimate.x - truth.x, estimate.y - truth.y));
        worst_yaw = std::max(worst_yaw, std::abs(WrapAngle(estimate.yaw - truth.yaw)));
      }
    }
  }
  // Odometry alone drifted by decimetres by now.
  EXPECT_GT((odometry.translation() - truth.translation()).norm(), 0.1);
  EXPECT_GT(travelled, 20.0);
  RecordProperty("worst_position_error_m", std::to_string(worst_position));
  RecordProperty("worst_yaw_error_deg", std::to_string(worst_yaw / kDeg));
  EXPECT_LT(worst_position, 0.05) << "worst position error [m]";
  EXPECT_LT(worst_yaw, 2 * kDeg) << "worst yaw error [rad]";
  const Eigen::Matrix3d covariance = localizer.Covariance();
  EXPECT_LT(covariance(0, 0), 0.01);
  EXPECT_GT(localizer.resample_count(), 0);
}

TEST(ParticleFilterLocalizerTest, IsDeterministicForASeed) {
  const OccupancyGrid map = testing::TwoRoomMap();
  LaserScan scan = testing::MakeScan(121, 8.0);
  testing::CastScan(map, {2.0, 2.0, 0.3}, &scan);
  Pose2 a, b;
  for (Pose2* out : {&a, &b}) {
    ParticleFilterLocalizer localizer(map, {}, {});
    localizer.Initialize({2.05, 1.95, 0.32}, Eigen::Vector3d(0.02, 0.02, 0.01).asDiagonal());
    localizer.Predict({0, 0, 0}, {0.1, 0.0, 0.0});
    localizer.Correct(scan);
    *out = localizer.Estimate();
  }
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.yaw, b.yaw);
}

// AMCL's spacing of corrections: driving, one per moving_update_distance; coming to rest, one
// as soon as the motion since the last passes update_min_distance; standing, none.
TEST(ParticleFilterLocalizerTest, DrivingItCorrectsEachTenthOfAMetreAndOnceMoreAtRest) {
  const OccupancyGrid map = testing::TwoRoomMap();
  LocalizerConfig config;
  config.recover_below = 0.0;  // no standing relocalization checks
  config.drift_check_below = 0.0;
  ASSERT_EQ(config.moving_update_distance, 0.1);
  ASSERT_EQ(config.update_min_distance, 0.02);
  LaserScan scan = testing::MakeScan(121, 8.0);
  for (const double moving_spacing : {config.moving_update_distance, config.update_min_distance}) {
    config.moving_update_distance = moving_spacing;
    ParticleFilterLocalizer localizer(map, {}, config);
    Pose2 truth{2.0, 2.0, 0.0};
    localizer.Initialize(truth, Eigen::Vector3d(1e-4, 1e-4, 1e-4).asDiagonal());
    testing::CastScan(map, truth, &scan);
    ASSERT_TRUE(localizer.Correct(scan));  // the first scan after Initialize
    std::vector<bool> corrected;
    // Six scans 0.04 m apart, driving; then two at rest.
    for (const double step : {0.04, 0.04, 0.04, 0.04, 0.04, 0.04, 0.0, 0.0}) {
      const Pose2 before = truth;
      truth.x += step;
      localizer.Predict(before, truth);
      testing::CastScan(map, truth, &scan);
      corrected.push_back(localizer.Correct(scan));
    }
    if (moving_spacing == 0.1) {
      // 0.12 m at the third scan and again at the sixth; at rest after it, nothing to correct.
      EXPECT_EQ(corrected,
                (std::vector<bool>{false, false, true, false, false, true, false, false}));
    } else {
      EXPECT_EQ(corrected, (std::vector<bool>{true, true, true, true, true, true, false, false}));
    }
    const Pose2 estimate = localizer.Estimate();
    EXPECT_NEAR(estimate.x, truth.x, 0.03);
    EXPECT_NEAR(estimate.y, truth.y, 0.03);
  }
  // Stopping short of the spacing: the scan at rest corrects.
  ParticleFilterLocalizer localizer(map, {}, config = LocalizerConfig{});
  localizer.Initialize({2.0, 2.0, 0.0}, Eigen::Vector3d(1e-4, 1e-4, 1e-4).asDiagonal());
  testing::CastScan(map, {2.0, 2.0, 0.0}, &scan);
  ASSERT_TRUE(localizer.Correct(scan));
  testing::CastScan(map, {2.05, 2.0, 0.0}, &scan);
  localizer.Predict({2.0, 2.0, 0.0}, {2.05, 2.0, 0.0});
  EXPECT_FALSE(localizer.Correct(scan));  // 5 cm, still moving
  localizer.Predict({2.05, 2.0, 0.0}, {2.05, 2.0, 0.0});
  EXPECT_TRUE(localizer.Correct(scan));  // at rest, 5 cm since the last correction
}

TEST(ParticleFilterLocalizerTest, AFewReturnsDoNotCorrectThePose) {
  // Out in the open with a handful of returns (an unmapped leaf, a person), the correction is
  // skipped: the same returns with enough beams do correct.
  const OccupancyGrid map = testing::TwoRoomMap();
  LaserScan scan = testing::MakeScan(121, 8.0);
  testing::CastScan(map, {2.0, 2.0, 0.3}, &scan);
  LocalizerConfig config;
  config.max_beams = 121;
  ParticleFilterLocalizer localizer(map, {}, config);
  localizer.Initialize({2.05, 1.95, 0.32}, Eigen::Vector3d(0.02, 0.02, 0.01).asDiagonal());
  LaserScan few = scan;
  for (std::size_t i = 0; i < few.ranges.size(); ++i)
    if (i % 12 != 0) few.ranges[i] = std::numeric_limits<float>::infinity();  // 11 beams left
  localizer.Predict({0, 0, 0}, {0.1, 0.0, 0.0});
  EXPECT_FALSE(localizer.Correct(few));
  EXPECT_TRUE(localizer.Correct(scan));
  config.min_beams = 0;
  EXPECT_THROW(ParticleFilterLocalizer(map, {}, config), InvalidArgument);
}

// A kidnap: the base is carried 0.36 m and 6 deg off without its odometry noticing, then stands.
// The cloud, a few centimetres wide, cannot reach the true pose by resampling, and a standing
// base does not correct at all: the relocalization check finds the pose the scan fits and
// spreads the cloud there.
TEST(ParticleFilterLocalizerTest, RelocalizesAfterAKidnapWhileStanding) {
  const OccupancyGrid map = testing::TwoRoomMap();
  const Pose2 X_BL{0.1675, 0.0, 0.0};
  const Pose2 truth{2.0, 2.8, 0.3};
  const Pose2 believed{truth.x - 0.3, truth.y + 0.2, truth.yaw - 0.1};
  LaserScan scan = testing::MakeScan(181, 8.0);
  testing::CastScan(map, truth * X_BL, &scan);
  for (const bool recover : {false, true}) {
    LocalizerConfig config;
    if (!recover) config.recover_below = config.drift_check_below = 0.0;
    ParticleFilterLocalizer localizer(map, X_BL, config);
    localizer.Initialize(believed, Eigen::Vector3d(1e-4, 1e-4, 1e-5).asDiagonal());
    const Pose2 odometry{5.0, -1.0, 0.2};  // standing: the same odometry at every scan
    for (int i = 0; i < 3 * config.recover_check_scans; ++i)
      localizer.Update(odometry, scan);
    const Pose2 estimate = localizer.Estimate();
    const double error = std::hypot(estimate.x - truth.x, estimate.y - truth.y);
    if (!recover) {
      EXPECT_GT(error, 0.3);  // the old behaviour: stuck where it believed it was
      EXPECT_EQ(localizer.recover_count(), 0);
      continue;
    }
    EXPECT_EQ(localizer.recover_count(), 1);
    EXPECT_LT(error, 0.02);
    EXPECT_LT(std::abs(WrapAngle(estimate.yaw - truth.yaw)), 1 * kDeg);
    // The jump reported is the one made, in the believed pose's frame.
    const Pose2 jump = localizer.last_recovery();
    EXPECT_NEAR(std::hypot(jump.x, jump.y), std::hypot(0.3, 0.2), 0.03);
    EXPECT_NEAR(jump.yaw, 0.1, 1 * kDeg);
  }
}

// Out in the open (past an exit) most beams have no return: the few left cannot tell where the
// base is along the wall they hit, so the check does not search — though the same returns show
// a kidnap the search would act on.
TEST(ParticleFilterLocalizerTest, AFewReturnsDoNotRelocalize) {
  const OccupancyGrid map = testing::TwoRoomMap();
  const Pose2 X_BL{0.1675, 0.0, 0.0};
  const Pose2 truth{2.0, 2.8, 0.3};
  const Pose2 believed{truth.x - 0.3, truth.y + 0.2, truth.yaw - 0.1};
  LaserScan scan = testing::MakeScan(181, 8.0);
  testing::CastScan(map, truth * X_BL, &scan);
  int returns = 0;
  for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
    if (i % 5 != 0) scan.ranges[i] = std::numeric_limits<float>::infinity();  // 1 in 5 left
    returns += std::isfinite(scan.ranges[i]) ? 1 : 0;
  }
  ASSERT_GE(returns, 12);  // enough to correct, too few to search
  for (const double min_returns : {0.3, 0.0}) {
    LocalizerConfig config;
    config.recover_min_returns = min_returns;
    ParticleFilterLocalizer localizer(map, X_BL, config);
    localizer.Initialize(believed, Eigen::Vector3d(1e-4, 1e-4, 1e-5).asDiagonal());
    for (int i = 0; i < 3 * config.recover_check_scans; ++i)
      localizer.Update({5.0, -1.0, 0.2}, scan);
    EXPECT_EQ(localizer.recover_count(), min_returns > 0.0 ? 0 : 1) << min_returns;
  }
}

// People crowding the laser's view of a well-localized robot leave few returns on the map's
// walls: the check searches, but nothing fits much better than where the robot is, and it
// stays — standing, then driving past them.
TEST(ParticleFilterLocalizerTest, PeopleCloseAroundDoNotPullThePoseAway) {
  const OccupancyGrid map = testing::TwoRoomMap();
  const Pose2 X_BL{0.1675, 0.0, 0.0};
  Pose2 truth{2.0, 4.0, 0.0};
  std::vector<testing::Disc> people;
  for (int i = 0; i < 7; ++i) {
    const double a = -1.2 + 0.4 * i;
    people.push_back({truth.translation() + 0.9 * Eigen::Vector2d(std::cos(a), std::sin(a)), 0.2});
  }
  LaserScan scan = testing::MakeScan(181, 8.0);
  ParticleFilterLocalizer localizer(map, X_BL);
  localizer.Initialize(truth, Eigen::Vector3d(1e-4, 1e-4, 1e-5).asDiagonal());
  Pose2 odometry;
  int low_fit = 0;
  for (int i = 0; i < 60; ++i) {
    if (i >= 30) {  // sideways past them at 0.2 m/s
      truth = truth * Pose2{0.0, -0.02, 0.0};
      odometry = odometry * Pose2{0.0, -0.02, 0.0};
    }
    testing::CastScanAtDiscs(people, truth * X_BL, &scan, &map);
    int on_people = 0;
    for (float r : scan.ranges)
      on_people += r < 1.0f ? 1 : 0;
    low_fit += on_people > 181 * 0.4 ? 1 : 0;
    localizer.Update(odometry, scan);
    const Pose2 estimate = localizer.Estimate();
    ASSERT_LT(std::hypot(estimate.x - truth.x, estimate.y - truth.y), 0.03) << "scan " << i;
  }
  EXPECT_GT(low_fit, 30);  // the check did have reason to search
  EXPECT_EQ(localizer.recover_count(), 0);
}

// A corridor 1.6 m wide and 14 m long, closed at its east end, with a doorway in its north
// wall: along it the side walls fit any x.
OccupancyGrid CorridorMap() {
  const std::vector<Box2> walls = {
      {{7.0, 0.05, 0.0}, {14.0, 0.1}},  // south
      {{3.0, 1.75, 0.0}, {6.0, 0.1}},   // north, west of the doorway at x in [6, 7]
      {{10.5, 1.75, 0.0}, {7.0, 0.1}},  // north, east of it
      {{13.95, 0.9, 0.0}, {0.1, 1.8}},  // the end wall
  };
  return OccupancyGrid::FromBoxes(walls, {0.0, 0.0}, {14.0, 1.8}, 0.05);
}

// Drift along a corridor: the estimate 0.25 m behind the base in x when it stops 1.5 m short of
// the end wall (as in the two wards, after 9 m east). The side walls fit either way, so too many
// beams fit for the kidnap check; the cloud, 1 cm wide, cannot reach the truth standing. The
// drift check takes the pose that fits the end wall too and loses none of the side walls.
TEST(ParticleFilterLocalizerTest, CorrectsDriftAlongACorridorWhileStanding) {
  const OccupancyGrid map = CorridorMap();
  const Pose2 X_BL{0.1675, 0.0, 0.0};
  const Pose2 truth{12.3, 0.85, 0.0};
  const Pose2 believed{truth.x - 0.25, truth.y, truth.yaw};
  LaserScan scan = testing::MakeScan(181, 20.0);
  testing::CastScan(map, truth * X_BL, &scan);
  for (const bool drift : {false, true}) {
    LocalizerConfig config;
    if (!drift) config.drift_check_below = 0.0;
    ParticleFilterLocalizer localizer(map, X_BL, config);
    localizer.Initialize(believed, Eigen::Vector3d(1e-4, 1e-4, 1e-5).asDiagonal());
    for (int i = 0; i < 3 * config.recover_check_scans; ++i)
      localizer.Update({5.0, -1.0, 0.2}, scan);
    const Pose2 estimate = localizer.Estimate();
    if (!drift) {
      EXPECT_NEAR(estimate.x, believed.x, 0.05);  // the kidnap check alone leaves it
      EXPECT_EQ(localizer.recover_count(), 0);
      continue;
    }
    EXPECT_EQ(localizer.recover_count(), 1);
    EXPECT_NEAR(estimate.x, truth.x, 0.03);
    EXPECT_NEAR(estimate.y, truth.y, 0.03);
    EXPECT_NEAR(localizer.last_recovery().x, 0.25, 0.03);
  }
}

// The same corridor, well localized, with a queue of people along its south wall ahead: their
// legs are off the map at any pose nearby, and the poses that put some of them on a wall lose
// the wall returns behind them. No jump, standing or driving.
TEST(ParticleFilterLocalizerTest, PeopleAlongACorridorWallDoNotReadAsDrift) {
  const OccupancyGrid map = CorridorMap();
  const Pose2 X_BL{0.1675, 0.0, 0.0};
  Pose2 truth{4.0, 0.9, 0.0};
  std::vector<testing::Disc> people;
  for (int i = 0; i < 8; ++i)
    people.push_back({{5.0 + 0.6 * i, 0.35 + 0.1 * (i % 2)}, 0.2});
  LaserScan scan = testing::MakeScan(181, 20.0);
  ParticleFilterLocalizer localizer(map, X_BL);
  localizer.Initialize(truth, Eigen::Vector3d(1e-4, 1e-4, 1e-5).asDiagonal());
  Pose2 odometry;
  LaserScan walls_only = scan;
  int low_fit = 0;  // scans with over 10 % of the beams on people: the drift check searches
  for (int i = 0; i < 60; ++i) {
    if (i >= 30) {  // on along the corridor at 0.2 m/s
      truth = truth * Pose2{0.02, 0.0, 0.0};
      odometry = odometry * Pose2{0.02, 0.0, 0.0};
    }
    testing::CastScanAtDiscs(people, truth * X_BL, &scan, &map);
    testing::CastScan(map, truth * X_BL, &walls_only);
    int on_people = 0;
    for (std::size_t k = 0; k < scan.ranges.size(); ++k)
      on_people += scan.ranges[k] < walls_only.ranges[k] - 0.05f ? 1 : 0;
    low_fit += on_people > int(scan.ranges.size()) / 10 ? 1 : 0;
    localizer.Update(odometry, scan);
    const Pose2 estimate = localizer.Estimate();
    ASSERT_LT(std::hypot(estimate.x - truth.x, estimate.y - truth.y), 0.03) << "scan " << i;
  }
  EXPECT_GT(low_fit, 30);  // the check had reason to search
  EXPECT_EQ(localizer.recover_count(), 0);
}

TEST(ParticleFilterLocalizerTest, RejectsBadInput) {
  const OccupancyGrid map = testing::TwoRoomMap();
  ParticleFilterLocalizer localizer(map, {});
  EXPECT_THROW(localizer.Estimate(), InvalidArgument);  // not initialized
  EXPECT_THROW(localizer.Initialize({std::nan(""), 0, 0}, Eigen::Matrix3d::Identity()),
               InvalidArgument);
  EXPECT_THROW(localizer.Initialize({1, 1, 0}, -Eigen::Matrix3d::Identity()), InvalidArgument);
  localizer.Initialize({2, 2, 0}, Eigen::Matrix3d::Identity() * 0.01);
  LaserScan empty = testing::MakeScan(2);
  empty.ranges.assign(2, std::numeric_limits<float>::infinity());
  EXPECT_FALSE(localizer.Correct(empty));  // no usable beam
  EXPECT_THROW(ParticleFilterLocalizer(map, {}, LocalizerConfig{5}), InvalidArgument);
  LocalizerConfig config;
  config.recover_below = 1.5;
  EXPECT_THROW(ParticleFilterLocalizer(map, {}, config), InvalidArgument);
  config.recover_below = 0.6;
  config.recover_step = 0.0;
  EXPECT_THROW(ParticleFilterLocalizer(map, {}, config), InvalidArgument);
  config.recover_step = 0.1;
  config.recover_min_returns = 1.5;
  EXPECT_THROW(ParticleFilterLocalizer(map, {}, config), InvalidArgument);
  config.recover_min_returns = 0.3;
  EXPECT_NO_THROW(ParticleFilterLocalizer(map, {}, config));
  for (const auto& [field, value] :
       std::vector<std::pair<double*, double>>{{&config.drift_check_below, -0.1},
                                               {&config.drift_gain, 0.0},
                                               {&config.drift_loss, std::nan("")}}) {
    const double good = *field;
    *field = value;
    EXPECT_THROW(ParticleFilterLocalizer(map, {}, config), InvalidArgument) << value;
    *field = good;
  }
  config.recover_below = 0.0;  // kidnap check disabled: the drift check still needs the steps
  config.recover_step = 0.0;
  EXPECT_THROW(ParticleFilterLocalizer(map, {}, config), InvalidArgument);
  config.recover_step = 0.1;
  config.drift_check_below = 0.0;  // both disabled: their other fields are not used
  config.drift_gain = 0.0;
  config.recover_step = 0.0;
  EXPECT_NO_THROW(ParticleFilterLocalizer(map, {}, config));
  config = LocalizerConfig{};
  // The spacing while moving is at least that at rest; none of them NaN.
  config.moving_update_distance = 0.01;
  EXPECT_THROW(ParticleFilterLocalizer(map, {}, config), InvalidArgument);
  config.moving_update_distance = 0.1;
  config.update_min_angle = std::nan("");
  try {
    ParticleFilterLocalizer(map, {}, config);
    ADD_FAILURE() << "a NaN update_min_angle was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("update_min_angle"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace egress::perception
