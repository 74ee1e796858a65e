#include "egress/perception/world_state.h"

#include <numbers>

#include <gtest/gtest.h>

#include "synthetic.h"

namespace egress::perception {
namespace {

using std::chrono::milliseconds;

// End to end on synthetic data: a push button and a person seen by the camera for a few
// frames, a half-open door in the scan, then the snapshot the behavior tree reads.
TEST(PerceptionPipelineTest, BuildsTheWorldState) {
  const DoorModel door{"lab", {6.0, 3.5}, {6.0, 4.5}, -1.0, std::numbers::pi / 2};
  PerceptionPipeline pipeline({door});
  const CameraIntrinsics K = CameraIntrinsics::FromHorizontalFov(80, 60, 1.047);
  const Pose3 X_MC =
      Pose3::FromXyzRpy({4.0, 4.0, 1.0}, {-std::numbers::pi / 2, 0.0, -std::numbers::pi / 2});
  DepthImage depth;
  depth.width = 80;
  depth.height = 60;
  depth.depth.assign(80 * 60, 1.8f);
  for (int frame = 0; frame < 4; ++frame) {
    depth.stamp = milliseconds(125 * frame);
    const std::vector<Detection2D> detections = {
        {"push_button", 0.9, {300, 200, 330, 230}, depth.stamp},
        {"person", 0.8, {380, 100, 440, 400}, depth.stamp},
        {"bottle", 0.2, {10, 10, 20, 20}, depth.stamp},  // below the confidence threshold
    };
    pipeline.ProcessCameraFrame(detections, {640, 480}, depth, K, X_MC);
  }
  // A scan that sees the leaf open at 45 degrees: hinge (6, 3.5), swinging clockwise to +x.
  std::vector<Box2> walls = {{{6.0, 1.75, 0.0}, {0.1, 3.5}}, {{6.0, 6.25, 0.0}, {0.1, 3.5}}};
  const Eigen::Vector2d tip = door.LeafTip(std::numbers::pi / 4);
  walls.push_back(
      {{(6.0 + tip.x()) / 2, (3.5 + tip.y()) / 2, std::atan2(tip.y() - 3.5, tip.x() - 6.0)},
       {1.0, 0.04}});
  const OccupancyGrid grid = OccupancyGrid::FromBoxes(walls, {0, 0}, {12, 8}, 0.02);
  LaserScan scan = testing::MakeScan(1081, 10.0);
  testing::CastScan(grid, {8.0, 4.0, std::numbers::pi}, &scan);
  scan.stamp = milliseconds(500);
  pipeline.ProcessScan(scan, {8.0, 4.0, std::numbers::pi}, K, Pose3());

  const WorldState world =
      pipeline.Snapshot(milliseconds(500), {4.0, 4.0, 0.0}, Eigen::Matrix3d::Identity() * 1e-4);
  ASSERT_EQ(world.buttons.size(), 1u);
  EXPECT_NEAR(world.buttons[0].p_MO.x(), 5.8, 0.05);
  EXPECT_TRUE(world.payloads.empty());
  ASSERT_EQ(world.people.size(), 1u);
  EXPECT_EQ(world.people[0].door_id, "lab");
  ASSERT_EQ(world.doors.size(), 1u);
  EXPECT_NEAR(world.doors[0].state.angle, std::numbers::pi / 4, 4 * std::numbers::pi / 180);
  EXPECT_EQ(world.door_zone_forecast.at("lab").size(), 5u);
}

}  // namespace
}  // namespace egress::perception
