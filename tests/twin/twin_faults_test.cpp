// Injected faults (`faults:`): each acts in its window or at its instant, is drawn per seed,
// and a malformed fault is refused naming its field and line.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"
#include "egress/twin/twin_robot.h"
#include "twin_test_util.h"

namespace egress::twin {
namespace {

using testing::CountEvents;
using ::testing::HasSubstr;
using testing::Hsr;
using testing::LoadText;
using testing::WorldsDir;

constexpr double kDeg = M_PI / 180.0;

// The lab: the robot before its door (push button), nobody else.
std::string Lab(const std::string& faults) {
  return "world: lab.sdf\nrobot: {start: {x: 0.0, y: 1.0, yaw: 1.5708}}\n"
         "doors: [{door: lab_door, operator: push, actuator: lab_button}]\nfaults:\n" +
         faults;
}

// What the sensors deliver per 0.1 s slot over `seconds`: scans, depth images, detections.
struct SensorLog {
  std::vector<double> scans, depths, detections;
};
SensorLog RunSensors(TwinWorld* world, double seconds) {
  TwinRobot robot(world);
  SensorLog log;
  while (world->time() < seconds) {
    robot.Advance(0.05);
    const SensorSnapshot s = robot.Sense();
    if (s.scan) log.scans.push_back(world->time());
    if (s.depth) log.depths.push_back(world->time());
    if (!s.detections.empty()) log.detections.push_back(world->time());
  }
  return log;
}

int CountIn(const std::vector<double>& times, double from, double to) {
  int n = 0;
  for (double t : times)
    n += t >= from && t < to ? 1 : 0;
  return n;
}

TEST(TwinFaultsTest, LaserDropoutAndCameraBlackoutSilenceTheirSensorsInTheWindow) {
  auto loaded = LoadText(Lab("  - {kind: laser_dropout, start: 1.0, duration: 1.0}\n"
                             "  - {kind: camera_blackout, start: 2.5, duration: 1.0}\n"),
                         WorldsDir() / "lab");
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  const SensorLog log = RunSensors(&world, 4.5);
  EXPECT_GE(CountIn(log.scans, 0.2, 1.0), 7);
  EXPECT_EQ(CountIn(log.scans, 1.05, 2.0), 0);  // nothing captured in [1, 2)
  EXPECT_GE(CountIn(log.scans, 2.1, 3.0), 8);
  EXPECT_GE(CountIn(log.depths, 1.0, 2.5), 6);
  EXPECT_EQ(CountIn(log.depths, 2.55, 3.5), 0);
  EXPECT_EQ(CountIn(log.detections, 2.8, 3.5), 0);  // the door is in view otherwise
  EXPECT_GE(CountIn(log.detections, 0.5, 2.5), 5);
  EXPECT_GE(CountIn(log.depths, 3.6, 4.5), 3);
}

TEST(TwinFaultsTest, OdometrySlipScalesTheReportedMotionAndAKidnapIsUnseenByOdometry) {
  auto loaded = LoadText(Lab("  - {kind: odometry_slip, start: 0.0, duration: 2.0, "
                             "odometry_scale: 2.0}\n"
                             "  - {kind: kidnap, start: 3.0, offset: {x: 0.0, y: -0.5}}\n"),
                         WorldsDir() / "lab");
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  TwinRobot robot(&world);
  const Pose2 start = world.robot_pose();
  const Pose2 odom0 = robot.Sense().odometry.X_OB;
  while (world.time() < 2.0) {
    robot.SendBaseVelocity({0.2, 0.0, 0.0});
    robot.Advance(0.05);
  }
  robot.SendBaseVelocity({});
  robot.Advance(0.5);
  const Pose2 end = world.robot_pose();
  const Pose2 odom = robot.Sense().odometry.X_OB;
  const double truth = std::hypot(end.x - start.x, end.y - start.y);
  const double reported = std::hypot(odom.x - odom0.x, odom.y - odom0.y);
  ASSERT_GT(truth, 0.2);
  EXPECT_NEAR(reported / truth, 2.0, 0.15);
  // Standing still at t = 3: moved 0.5 m in -y by the kidnap; odometry does not see it.
  const Pose2 before = world.robot_pose();
  const Pose2 odom_before = robot.Sense().odometry.X_OB;
  robot.Advance(1.0);
  EXPECT_NEAR(world.robot_pose().y - before.y, -0.5, 0.02);
  const Pose2 odom_after = robot.Sense().odometry.X_OB;
  EXPECT_NEAR(std::hypot(odom_after.x - odom_before.x, odom_after.y - odom_before.y), 0.0, 0.02);
  EXPECT_EQ(CountEvents(world, "fault", "kidnap"), 1);
}

// Into a wall (the lab's dividing wall at y = 3) or through one: skipped.
TEST(TwinFaultsTest, AKidnapIntoOrThroughAWallIsSkipped) {
  for (const char* offset : {"{x: 2.0, y: 2.0}", "{x: 1.5, y: 3.0}"}) {
    auto loaded =
        LoadText(Lab(std::string("  - {kind: kidnap, start: 0.5, offset: ") + offset + "}\n"),
                 WorldsDir() / "lab");
    TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
    const Pose2 before = world.robot_pose();
    world.StepFor(1.0);
    EXPECT_NEAR(world.robot_pose().y, before.y, 0.02) << offset;
    EXPECT_EQ(CountEvents(world, "fault_skipped", "kidnap"), 1) << offset;
  }
}

TEST(TwinFaultsTest, ADoorClosesEarlyAndARefusingDoorIgnoresItsTriggers) {
  auto loaded = LoadText(
      "world: lab.sdf\nrobot: {start: {x: 0.0, y: 1.0}}\n"
      "doors: [{door: lab_door, operator: push, actuator: lab_button, open_at: [0.0, 20.0]}]\n"
      "faults:\n  - {kind: door_closes_early, door: lab_door, start: 6.0}\n"
      "  - {kind: door_refuses, door: lab_door, start: 15.0, duration: 10.0}\n",
      WorldsDir() / "lab");
  TwinWorld world(loaded.scenario, loaded.world, 1, Hsr());
  world.StepFor(5.5);
  EXPECT_GT(world.door_angle(0), 70 * kDeg);  // open and held (10 s hold)
  world.StepFor(6.0);                         // t = 11.5: closed 5.5 s after the fault
  EXPECT_LT(world.door_angle(0), 2 * kDeg);
  EXPECT_EQ(CountEvents(world, "fault", "door_closes_early"), 1);
  world.StepFor(12.0);  // t = 23.5: the scheduled open at 20 s falls in the refusal
  EXPECT_LT(world.door_angle(0), 2 * kDeg);
  EXPECT_EQ(CountEvents(world, "fault_refused_press", "lab_door"), 1);
}

TEST(TwinFaultsTest, WindowsAreDrawnPerSeedAndReproducible) {
  auto loaded =
      LoadText(Lab("  - {kind: laser_dropout, start: [1.0, 9.0], duration: [0.5, 2.0]}\n"),
               WorldsDir() / "lab");
  const auto window = [&](std::uint64_t seed) {
    TwinWorld world(loaded.scenario, loaded.world, seed, Hsr());
    const auto& f = world.faults().at(0);
    EXPECT_GE(f.start, 1.0);
    EXPECT_LE(f.start, 9.0);
    EXPECT_GE(f.end - f.start, 0.5);
    return std::pair{f.start, f.end};
  };
  EXPECT_EQ(window(3), window(3));
  EXPECT_NE(window(3), window(4));
}

TEST(TwinFaultsTest, MalformedFaultsAreRefusedByFieldAndLine) {
  const auto error = [](const std::string& faults) {
    try {
      LoadText(Lab(faults), WorldsDir() / "lab");
    } catch (const LoadError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(error("  - {kind: meteor, start: 1}\n"),
              HasSubstr("test.yaml:5: field 'faults[0].kind': unknown fault 'meteor'"));
  EXPECT_THAT(error("  - {kind: kidnap, start: 1, offset: {x: 9, y: 0}}\n"), HasSubstr("5 m"));
  EXPECT_THAT(error("  - {kind: grasp_slip, start: 1, duration: 2}\n"),
              HasSubstr("does not apply to a grasp_slip fault"));
  EXPECT_THAT(error("  - {kind: laser_dropout, start: 1}\n"), HasSubstr("duration"));
  EXPECT_THAT(error("  - {kind: door_refuses, start: 1, duration: 1}\n"), HasSubstr("door"));
  EXPECT_THAT(error("  - {kind: laser_dropout, start: -1, duration: 1}\n"), HasSubstr("start"));
  EXPECT_THAT(error("  - {kind: odometry_slip, start: 1, duration: .nan}\n"),
              HasSubstr("duration"));
  // A door the world lacks is refused when the scenario meets its world.
  auto loaded = LoadText(Lab("  - {kind: door_closes_early, door: nowhere, start: 1}\n"),
                         WorldsDir() / "lab");
  EXPECT_THROW(loaded.scenario.ValidateAgainst(loaded.world), LoadError);
}

}  // namespace
}  // namespace egress::twin
