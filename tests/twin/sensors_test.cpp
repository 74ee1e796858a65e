#include "egress/twin/sensors.h"

#include <gtest/gtest.h>

#include "egress/twin/twin_robot.h"
#include "twin_test_util.h"

namespace egress::twin {
namespace {

using testing::Hsr;
using testing::LoadText;
using testing::WorldsDir;

constexpr double kDeg = M_PI / 180.0;
const char* const kQuiet =
    "sensors:\n  laser: {noise: 0}\n  depth: {noise_coeff: 0}\n  detector: {miss_rate: 0, "
    "false_positive_rate: 0}\n";

std::string At(const char* world, double x, double y, double yaw, const std::string& extra = "") {
  return std::string("world: ") + world + "\nrobot: {start: {x: " + std::to_string(x) +
         ", y: " + std::to_string(y) + ", yaw: " + std::to_string(yaw) + "}}\n" + kQuiet + extra;
}

std::size_t BeamAt(const LaserScan& scan, double angle) {
  return std::size_t(std::lround((angle - scan.angle_min) / scan.angle_increment));
}

TEST(LaserSimulatorTest, RangesEqualTheAnalyticDistancesToTheLabWalls) {
  auto loaded = LoadText(At("lab.sdf", -1.5, 0.0, 0.0), WorldsDir() / "lab");
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  const LaserSimulator laser(loaded.scenario.sensors);
  std::mt19937_64 rng(1);
  const LaserScan scan = laser.Capture(world, rng);
  ASSERT_NO_THROW(scan.Validate());
  ASSERT_EQ(scan.ranges.size(), 1081u);  // 270° in 0.25° steps
  const Eigen::Vector3d p_WL =
      (Pose3::FromPose2(world.robot_pose()) * Hsr()->laser_pose()).translation();
  EXPECT_NEAR(scan.ranges[BeamAt(scan, 0.0)], 3.0 - p_WL.x(), 1e-3);  // east wall face x = 3
  EXPECT_NEAR(scan.ranges[BeamAt(scan, M_PI / 2)], 2.95 - p_WL.y(),
              1e-3);  // door wall face y = 2.95
  EXPECT_NEAR(scan.ranges[BeamAt(scan, -M_PI / 2)], p_WL.y() + 1.0,
              1e-3);  // south wall face y = −1
  // An oblique beam at 20° hits the east wall at (3 − x) / cos 20°; at −30° the south wall.
  EXPECT_NEAR(scan.ranges[BeamAt(scan, 20 * kDeg)], (3.0 - p_WL.x()) / std::cos(20 * kDeg), 2e-3);
  EXPECT_NEAR(scan.ranges[BeamAt(scan, -30 * kDeg)], (p_WL.y() + 1.0) / std::sin(30 * kDeg), 2e-3);
}

TEST(LaserSimulatorTest, NoiseHasTheConfiguredSpread) {
  auto loaded = LoadText(At("lab.sdf", -1.5, 0.0, 0.0), WorldsDir() / "lab");
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  SensorConfig config = loaded.scenario.sensors;
  config.laser_noise = 0.02;
  const LaserSimulator noisy(config), exact(loaded.scenario.sensors);
  std::mt19937_64 rng(1);
  const LaserScan a = noisy.Capture(world, rng), b = exact.Capture(world, rng);
  double sum2 = 0;
  int n = 0;
  for (std::size_t i = 0; i < a.ranges.size(); ++i) {
    if (std::isfinite(a.ranges[i]) && std::isfinite(b.ranges[i])) {
      sum2 += std::pow(a.ranges[i] - b.ranges[i], 2);
      ++n;
    }
  }
  EXPECT_NEAR(std::sqrt(sum2 / n), 0.02, 0.003);
}

TEST(LaserSimulatorTest, GlassReturnsOnlyNearNormalIncidence) {
  const std::string doors_glass =
      "doors: [{door: door_b, operator: proximity, actuator: door_b_plate, glass: true}]\n";
  const std::string doors_solid =
      "doors: [{door: door_b, operator: proximity, actuator: door_b_plate, glass: false}]\n";
  auto glass = LoadText(At("office.sdf", 7.5, 1.3, 0.0, doors_glass), WorldsDir() / "office");
  auto solid = LoadText(At("office.sdf", 7.5, 1.3, 0.0, doors_solid), WorldsDir() / "office");
  TwinWorld glass_world(glass.scenario, glass.world, 1, Hsr());
  TwinWorld solid_world(solid.scenario, solid.world, 1, Hsr());
  const LaserSimulator laser(glass.scenario.sensors);
  std::mt19937_64 rng(1);
  const LaserScan g = laser.Capture(glass_world, rng), s = laser.Capture(solid_world, rng);
  const double p_x =
      (Pose3::FromPose2(glass_world.robot_pose()) * Hsr()->laser_pose()).translation().x();
  // Straight at the leaf (x = 8.99): both return.
  EXPECT_NEAR(g.ranges[BeamAt(g, 0.0)], 8.99 - p_x, 2e-3);
  EXPECT_NEAR(s.ranges[BeamAt(s, 0.0)], 8.99 - p_x, 2e-3);
  // 25° off the normal: the solid leaf returns, the glass lets the beam through to room 3.
  const std::size_t oblique = BeamAt(g, 25 * kDeg);
  EXPECT_NEAR(s.ranges[oblique], (8.99 - p_x) / std::cos(25 * kDeg), 5e-3);
  EXPECT_GT(g.ranges[oblique], 3.0);
}

TEST(TwinWorldRayTest, ADownwardRayMeetsAPersonBeforeTheFloorBehindThem) {
  // Only the floor's crossing bounds how far a ray looks for what it meets first: a person (a
  // moving body) standing short of it is hit, wherever along the ray the crossing lies.
  auto loaded = LoadText(At("lab.sdf", -1.5, 0.0, 0.0,
                            "people:\n  - {name: p, behavior: walk_past, start: [2.5, 0.0], goal: "
                            "[2.5, 2.0], trigger: {at: 100.0}}\n"),
                         WorldsDir() / "lab");
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  const Eigen::Vector3d from(0.0, 0.0, 1.2);
  const RayHit level = world.CastRay(from, {5.0, 0.0, 1.2}, GlassMode::kOpaque);
  ASSERT_TRUE(level.hit);
  const double face = level.point.x();
  ASSERT_NEAR(face, 2.5 - world.people().front().radius, 0.05) << "the level ray meets the person";
  for (const double past : {0.3, 0.6, 1.0}) {
    // Aimed at the floor `past` beyond the person's face, and on for as long again.
    const Eigen::Vector3d floor(face + past, 0.0, 0.0);
    const RayHit hit = world.CastRay(from, from + 2.0 * (floor - from), GlassMode::kOpaque);
    ASSERT_TRUE(hit.hit) << "past " << past;
    EXPECT_GT(hit.point.z(), 0.01) << "the floor, not the person, past " << past;
    EXPECT_LT(hit.distance, (floor - from).norm()) << "past " << past;
  }
  // Aimed at the floor short of the person: the floor.
  const Eigen::Vector3d short_of(face - 0.3, 0.0, 0.0);
  const RayHit floor_hit = world.CastRay(from, from + 2.0 * (short_of - from), GlassMode::kOpaque);
  ASSERT_TRUE(floor_hit.hit);
  EXPECT_NEAR(floor_hit.distance, (short_of - from).norm(), 1e-4);
}

TEST(TwinWorldRayTest, AWalkingPersonsBodyIsWhereTheirStateSaysAfterEveryStep) {
  // A person's body is posed on the body itself (no motion state) and people() is copied when
  // asked for: after each step both must agree, or the sensors see someone the judge does not.
  auto loaded = LoadText(At("lab.sdf", -1.5, 0.0, 0.0,
                            "people:\n  - {name: p, behavior: walk_past, start: [2.5, -1.0], "
                            "goal: [2.5, 1.5]}\n"),
                         WorldsDir() / "lab");
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  const double start_y = world.people().front().position.y();
  int steps_checked = 0;
  while (world.time() < 3.0) {
    world.Step();
    const PersonState& p = world.people().front();
    if (world.step_count() % 24 != 0) continue;
    // A level ray along x through the person's centre meets their front surface.
    const Eigen::Vector3d from(0.0, p.position.y(), 1.0);
    const RayHit hit = world.CastRay(from, {5.0, p.position.y(), 1.0}, GlassMode::kOpaque);
    ASSERT_TRUE(hit.hit) << "t " << world.time();
    EXPECT_NEAR(hit.point.x(), p.position.x() - p.radius, 0.02) << "t " << world.time();
    ++steps_checked;
  }
  EXPECT_GT(steps_checked, 20);
  const PersonState& p = world.people().front();
  EXPECT_GT(p.position.y() - start_y, 1.0) << "they walked";
  // Where they started, nobody is left.
  const RayHit at_start =
      world.CastRay({0.0, start_y, 1.0}, {5.0, start_y, 1.0}, GlassMode::kOpaque);
  EXPECT_TRUE(!at_start.hit || at_start.point.x() > 2.5 + p.radius) << at_start.point.x();
}
TEST(TwinWorldRayTest, AFanCastsTheSameHitsAsOneRayAtATime) {
  // CastRayFan bins the candidates by bearing once instead of walking the grid per ray: the hits
  // must be CastRay's, bit for bit, among walking people, doors (door_b's glass leaf) and walls,
  // for rays level, down to the floor, up, straight down, and short or long, in every glass mode.
  const Scenario scenario = LoadScenario(WorldsDir() / "scenarios/evacuation/clinic_escort.yaml");
  TwinWorld world(scenario, LoadSdfWorld(scenario.world_file), 3, Hsr());
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> x(0.5, 21.5), y(-2.0, 6.0), unit(-1.0, 1.0);
  int hits = 0, people = 0, glass = 0, fans = 0;
  for (const double t : {0.0, 70.0, 40.0}) {
    world.StepFor(t);
    for (int f = 0; f < 12; ++f, ++fans) {
      const Eigen::Vector3d from(x(rng), y(rng), f % 3 == 0 ? 0.2 : 1.0);
      std::vector<Eigen::Vector3d> tos;
      for (int k = 0; k < 300; ++k) {
        Eigen::Vector3d d(unit(rng), unit(rng), k % 2 == 0 ? 0.0 : 0.5 * unit(rng));
        if (k % 60 == 1) d = Eigen::Vector3d(0.0, 0.0, -1.0);
        tos.push_back(from + d.normalized() * (k % 3 == 0 ? 2.0 : 12.0));
      }
      const GlassMode mode = std::array{GlassMode::kOpaque, GlassMode::kLaser,
                                        GlassMode::kTransparent}[std::size_t(f % 3)];
      std::vector<RayHit> fan;
      world.CastRayFan(from, tos, mode, &fan, 0.3);
      ASSERT_EQ(fan.size(), tos.size());
      for (std::size_t k = 0; k < tos.size(); ++k) {
        const RayHit one = world.CastRay(from, tos[k], mode, 0.3);
        ASSERT_EQ(fan[k].hit, one.hit) << "fan " << fans << " ray " << k;
        EXPECT_EQ(fan[k].distance, one.distance) << "fan " << fans << " ray " << k;
        EXPECT_EQ(fan[k].point, one.point) << "fan " << fans << " ray " << k;
        EXPECT_EQ(fan[k].normal, one.normal) << "fan " << fans << " ray " << k;
        EXPECT_EQ(fan[k].entity, one.entity) << "fan " << fans << " ray " << k;
        EXPECT_EQ(fan[k].glass, one.glass) << "fan " << fans << " ray " << k;
        hits += one.hit;
        people += one.hit && world.entity_kind(one.entity) == EntityKind::kPerson;
        glass += one.glass;
      }
    }
  }
  // The rays met what the comparison is about.
  EXPECT_GT(hits, 5000);
  EXPECT_GT(people, 20);
  EXPECT_GT(glass, 0);
}

TEST(DepthCameraSimulatorTest, DepthEqualsTheAnalyticDistanceAndGlassIsInvalid) {
  auto loaded = LoadText(At("lab.sdf", -1.5, 0.0, 0.0), WorldsDir() / "lab");
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  const DepthCameraSimulator camera(loaded.scenario.sensors);
  std::mt19937_64 rng(1);
  const DepthImage image = camera.Capture(world, rng);
  ASSERT_NO_THROW(image.Validate());
  ASSERT_EQ(image.width, 80);
  ASSERT_EQ(image.height, 60);
  const Pose3 X_WC = world.head_camera_pose();
  int checked = 0;
  for (int v = 5; v < 60; v += 10) {
    for (int u = 5; u < 80; u += 10) {
      const Eigen::Vector3d d_W =
          X_WC.rotation() * camera.intrinsics().Unproject(u + 0.5, v + 0.5, 1.0);
      // The ray to the east wall face (x = 3) or the floor (z = 0), whichever is first.
      const double s_wall = (3.0 - X_WC.translation().x()) / d_W.x();
      const double s_floor = d_W.z() < 0 ? -X_WC.translation().z() / d_W.z() : 1e9;
      const double s = std::min(s_wall, s_floor);  // depth along the optical axis (d_C.z = 1)
      const Eigen::Vector3d hit = X_WC.translation() + s * d_W;
      if (hit.y() < -0.95 || hit.y() > 2.9 || hit.z() > 1.95) continue;  // the plain wall and floor
      EXPECT_NEAR(image.At(u, v), s, 2e-3) << u << "," << v;
      ++checked;
    }
  }
  EXPECT_GT(checked, 20);
  // Facing the glass leaf of door_b straight on: the centre pixels have no valid depth.
  auto office = LoadText(
      At("office.sdf", 7.8, 1.5, 0.0,
         "doors: [{door: door_b, operator: proximity, actuator: door_b_plate, glass: true}]\n"),
      WorldsDir() / "office");
  TwinWorld glass_world(office.scenario, office.world, 1, Hsr());
  const DepthImage g = camera.Capture(glass_world, rng);
  EXPECT_FALSE(g.IsValidAt(40, 30));
}

TEST(DetectorSimulatorTest, BoxesMatchTheProjectionAndOccludedObjectsAreDropped) {
  // In front of the lab button, 1.4 m back, looking at it.
  const std::string base = At("lab.sdf", 1.075, 1.5, M_PI / 2,
                              "doors: [{door: lab_door, operator: push, actuator: lab_button}]\n");
  auto loaded = LoadText(base, WorldsDir() / "lab");
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  const DepthCameraSimulator camera(loaded.scenario.sensors);
  const DetectorSimulator detector(loaded.scenario.sensors, camera.intrinsics());
  std::mt19937_64 rng(3);
  const auto detections = detector.Detect(world, rng);
  const DetectableObject* button = nullptr;
  const auto objects = world.DetectableObjects();
  for (const auto& o : objects) {
    if (o.label == "push_button") button = &o;
  }
  ASSERT_NE(button, nullptr);
  const auto expected = detector.Project(*button, world.head_camera_pose());
  ASSERT_TRUE(expected.has_value());
  const Detection2D* found = nullptr;
  for (const auto& d : detections) {
    EXPECT_NO_THROW(d.Validate());
    if (d.label == "push_button") found = &d;
  }
  ASSERT_NE(found, nullptr);
  EXPECT_NEAR(found->box.center().x(), expected->center().x(), 1.0);
  EXPECT_NEAR(found->box.center().y(), expected->center().y(), 1.0);
  EXPECT_NEAR(found->box.width(), expected->width(), 0.5 + 0.1 * expected->width());
  EXPECT_GT(found->confidence, 0.5);
  // The door leaf, partly in view at the image's left edge, is detected too (truncated box).
  bool door_seen = false;
  for (const auto& d : detections)
    door_seen = door_seen || (d.label == "door" && d.box.u_min < 1.0);
  EXPECT_TRUE(door_seen);
  // A cabinet between the camera and the button hides it.
  auto occluded =
      LoadText(base + "obstacles: [{name: cabinet, box: [0.5, 0.2, 1.5], x: 1.075, y: 2.3}]\n",
               WorldsDir() / "lab");
  TwinWorld hidden(occluded.scenario, occluded.world, 1, Hsr());
  for (const auto& d : detector.Detect(hidden, rng))
    EXPECT_NE(d.label, "push_button");
}

TEST(TwinRobotTest, SensorsArriveAtTheirRatesAfterTheirLatency) {
  auto loaded = LoadText(At("lab.sdf", 1.075, 1.5, M_PI / 2,
                            "doors: [{door: lab_door, operator: push, actuator: lab_button}]\n"),
                         WorldsDir() / "lab");
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  TwinRobot robot(&world);
  int scans = 0, images = 0, detections = 0;
  for (int i = 0; i < 20; ++i) {  // 2 s at the executive's 10 Hz
    robot.Advance(0.1);
    const SensorSnapshot s = robot.Sense();  // validated by RobotPort
    scans += s.scan ? 1 : 0;
    images += s.depth ? 1 : 0;
    for (const auto& d : s.detections) {
      ++detections;
      const double age = ToSeconds(s.stamp - d.stamp);
      EXPECT_GE(age, 0.125 - 1e-6);
      EXPECT_LE(age, 0.2 + 0.1 + 1e-6);
    }
    EXPECT_EQ(s.stamp, robot.clock().Now());
  }
  EXPECT_NEAR(scans, 20, 1);   // 10 Hz laser
  EXPECT_NEAR(images, 10, 1);  // 5 Hz depth
  EXPECT_GE(detections, 14);   // 8 Hz, button + door visible in most frames
}

TEST(OdometrySimulatorTest, ExactWithoutNoiseAndDriftsWithIt) {
  SensorConfig exact;
  exact.odometry_noise = 0.0;
  exact.odometry_yaw_drift = 0.0;
  std::mt19937_64 rng(1);
  OdometrySimulator odom(exact, {}, rng);
  for (int i = 0; i < 100; ++i)
    odom.Integrate({0.5, 0.0, 0.1}, 0.01);
  const Odometry o = odom.Read(Time{0});
  const double yaw = 0.1;
  EXPECT_NEAR(o.X_OB.yaw, yaw, 1e-9);
  EXPECT_NEAR(o.X_OB.x, 0.5 * std::sin(yaw) / 0.1, 1e-3);
  SensorConfig drifting;
  drifting.odometry_yaw_drift = 0.01;
  OdometrySimulator drift(drifting, {}, rng);
  for (int i = 0; i < 1000; ++i)
    drift.Integrate({0.5, 0.0, 0.0}, 0.01);
  EXPECT_GT(std::abs(drift.Read(Time{0}).X_OB.yaw), 0.09);
  EXPECT_NO_THROW(drift.Read(Time{0}).Validate());
}

}  // namespace
}  // namespace egress::twin
