#include "egress/perception/occupancy_map_3d.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress::perception {
namespace {

// A camera at height 1.0 m looking along M's x axis (optical z = M x, optical x = -M y).
Pose3 ForwardCamera() {
  return Pose3::FromXyzRpy({0.0, 0.0, 1.0}, {-std::numbers::pi / 2, 0.0, -std::numbers::pi / 2});
}

// Renders the depth of an axis-aligned box face x = face_x, y in [y0, y1], z in [z0, z1].
DepthImage RenderFace(const CameraIntrinsics& K, const Pose3& X_MC, double face_x, double y0,
                      double y1, double z0, double z1) {
  DepthImage image;
  image.width = K.width;
  image.height = K.height;
  image.depth.assign(std::size_t(K.width * K.height), std::nanf(""));
  for (int v = 0; v < K.height; ++v) {
    for (int u = 0; u < K.width; ++u) {
      const Eigen::Vector3d ray_M = X_MC.rotation() * K.Unproject(u + 0.5, v + 0.5, 1.0);
      if (ray_M.x() <= 0) continue;
      const double t = (face_x - X_MC.translation().x()) / ray_M.x();
      const Eigen::Vector3d p = X_MC.translation() + t * ray_M;
      if (p.y() >= y0 && p.y() <= y1 && p.z() >= z0 && p.z() <= z1)
        image.depth[std::size_t(v * K.width + u)] = float(t);
    }
  }
  return image;
}

// The face lies on a voxel boundary (x = face_x, a whole number of voxels): accept the voxel on
// either side.
bool OccupiedAtFace(const OccupancyMap3D& map, double y, double z, double face_x = 2.0) {
  return map.IsOccupied({face_x - 0.02, y, z}) || map.IsOccupied({face_x + 0.02, y, z});
}

// Someone 3 m ahead (beyond clearing_range: no ray clears them), and an image with no return.
DepthImage PersonAhead(const CameraIntrinsics& K) {
  return RenderFace(K, ForwardCamera(), 3.0, -0.2, 0.2, 0.3, 1.4);
}
DepthImage NothingInView(const CameraIntrinsics& K, double t) {
  DepthImage empty = RenderFace(K, ForwardCamera(), 3.0, 5.0, 5.0, 0.0, 0.0);
  empty.stamp = SecondsToDuration(t);
  return empty;
}

TEST(OccupancyMap3DTest, SyntheticBoxIsOccupiedAndTheSpaceBeforeItFree) {
  const CameraIntrinsics K = CameraIntrinsics::FromHorizontalFov(80, 60, 1.047);
  const Pose3 X_MC = ForwardCamera();
  OccupancyMap3D map;
  // A table-like face 2 m ahead, 0.4-0.8 m high: above the base laser's scan plane.
  // Seen in three frames (a static obstacle): occupied.
  const std::size_t inserted =
      map.InsertDepthImage(RenderFace(K, X_MC, 2.0, -0.3, 0.3, 0.4, 0.8), K, X_MC);
  EXPECT_GT(inserted, 100u);
  EXPECT_FALSE(OccupiedAtFace(map, 0.0, 0.6)) << "one sighting is not yet an obstacle";
  for (int frame = 0; frame < 2; ++frame)
    map.InsertDepthImage(RenderFace(K, X_MC, 2.0, -0.3, 0.3, 0.4, 0.8), K, X_MC);
  EXPECT_TRUE(OccupiedAtFace(map, 0.0, 0.6));
  EXPECT_FALSE(map.IsOccupied({0.5, 0.0, 0.9}));  // along the rays, within clearing_range: free
  const octomap::OcTreeNode* carved = map.tree()->search(0.5, 0.0, 0.9);
  ASSERT_NE(carved, nullptr);  // observed (carved), not merely unknown
  EXPECT_FALSE(map.tree()->isNodeOccupied(carved));
  const auto projected = map.ProjectObstacles();
  ASSERT_FALSE(projected.empty());
  for (const auto& p : projected) {
    EXPECT_GT(p.x(), 1.9);
    EXPECT_LT(std::abs(p.y()), 0.4);
  }
}

TEST(OccupancyMap3DTest, OverheadObstaclesAreNotProjected) {
  const CameraIntrinsics K = CameraIntrinsics::FromHorizontalFov(80, 60, 1.047);
  const Pose3 X_MC = ForwardCamera();
  OccupancyMap3DConfig config;
  config.max_obstacle_height = 1.5;
  OccupancyMap3D map(config);
  for (int frame = 0; frame < 3; ++frame)  // above the robot
    map.InsertDepthImage(RenderFace(K, X_MC, 2.0, -0.3, 0.3, 1.6, 1.9), K, X_MC);
  EXPECT_TRUE(OccupiedAtFace(map, 0.0, 1.7));
  EXPECT_TRUE(map.ProjectObstacles().empty());
}

TEST(OccupancyMap3DTest, AVoxelNotMarkedAgainForTheDecayTimeIsForgotten) {
  const CameraIntrinsics K = CameraIntrinsics::FromHorizontalFov(80, 60, 1.047);
  const Pose3 X_MC = ForwardCamera();
  OccupancyMap3DConfig config;
  config.decay_s = 10.0;
  OccupancyMap3D map(config);
  DepthImage person = PersonAhead(K);  // seen for 1 s
  for (int frame = 0; frame < 5; ++frame) {
    person.stamp = SecondsToDuration(0.2 * frame);
    map.InsertDepthImage(person, K, X_MC);
  }
  ASSERT_TRUE(OccupiedAtFace(map, 0.0, 0.8, 3.0));
  // Then the camera sees nothing there (it looks elsewhere).
  map.InsertDepthImage(NothingInView(K, 9.0), K, X_MC);
  EXPECT_TRUE(OccupiedAtFace(map, 0.0, 0.8, 3.0)) << "kept within the decay time";
  map.InsertDepthImage(NothingInView(K, 10.9), K, X_MC);
  EXPECT_FALSE(OccupiedAtFace(map, 0.0, 0.8, 3.0));
  EXPECT_TRUE(map.ProjectObstacles().empty());
  // Seen again: marked again (three sightings, as at first).
  for (int frame = 0; frame < 3; ++frame) {
    person.stamp = SecondsToDuration(11.0 + 0.2 * frame);
    map.InsertDepthImage(person, K, X_MC);
  }
  EXPECT_TRUE(OccupiedAtFace(map, 0.0, 0.8, 3.0));
}

TEST(OccupancyMap3DTest, ADecayOfZeroKeepsVoxelsForEver) {
  const CameraIntrinsics K = CameraIntrinsics::FromHorizontalFov(80, 60, 1.047);
  OccupancyMap3DConfig config;
  config.decay_s = 0.0;
  OccupancyMap3D map(config);
  for (int frame = 0; frame < 3; ++frame)
    map.InsertDepthImage(PersonAhead(K), K, ForwardCamera());
  map.InsertDepthImage(NothingInView(K, 1000.0), K, ForwardCamera());
  EXPECT_TRUE(OccupiedAtFace(map, 0.0, 0.8, 3.0));
  config.decay_s = -1.0;
  EXPECT_THROW(config.Validate(), InvalidArgument);
}

TEST(OccupancyMap3DTest, AFilterKeepsPointsFromMarkingButNotFromCarving) {
  const CameraIntrinsics K = CameraIntrinsics::FromHorizontalFov(80, 60, 1.047);
  const Pose3 X_MC = ForwardCamera();
  OccupancyMap3D map;
  // The face 2 m ahead, with its left half (y > 0) refused, e.g. a tracked person there.
  const auto left_refused = [](const Eigen::Vector3d& p_MQ) { return p_MQ.y() < 0.0; };
  const std::size_t inserted =
      map.InsertDepthImage(RenderFace(K, X_MC, 2.0, -0.3, 0.3, 0.4, 0.8), K, X_MC, left_refused);
  EXPECT_GT(inserted, 30u);
  for (int frame = 0; frame < 2; ++frame)
    map.InsertDepthImage(RenderFace(K, X_MC, 2.0, -0.3, 0.3, 0.4, 0.8), K, X_MC, left_refused);
  EXPECT_TRUE(OccupiedAtFace(map, -0.2, 0.6));
  EXPECT_FALSE(OccupiedAtFace(map, 0.2, 0.6));
  const octomap::OcTreeNode* carved = map.tree()->search(0.5, 0.0, 0.9);
  ASSERT_NE(carved, nullptr);
  EXPECT_FALSE(map.tree()->isNodeOccupied(carved));
  // A filter that refuses everything marks nothing.
  OccupancyMap3D none;
  EXPECT_EQ(none.InsertDepthImage(RenderFace(K, X_MC, 2.0, -0.3, 0.3, 0.4, 0.8), K, X_MC,
                                  [](const Eigen::Vector3d&) { return false; }),
            0u);
  EXPECT_TRUE(none.ProjectObstacles().empty());
}

// Someone walking past, seen in one frame at each place, leaves no obstacle behind; the same
// thing standing still for three frames is one.
TEST(OccupancyMap3DTest, WhatIsSeenOnceOrTwiceIsNoObstacle) {
  const CameraIntrinsics K = CameraIntrinsics::FromHorizontalFov(80, 60, 1.047);
  const Pose3 X_MC = ForwardCamera();
  OccupancyMap3D map;
  for (double y : {-1.0, -0.6, -0.2, 0.2, 0.6})  // 0.4 m on per frame
    map.InsertDepthImage(RenderFace(K, X_MC, 3.0, y - 0.15, y + 0.15, 0.3, 1.4), K, X_MC);
  EXPECT_TRUE(map.ProjectObstacles().empty());
  for (int frame = 0; frame < 3; ++frame)
    map.InsertDepthImage(RenderFace(K, X_MC, 3.0, 0.45, 0.75, 0.3, 1.4), K, X_MC);
  EXPECT_FALSE(map.ProjectObstacles().empty());
  OccupancyMap3DConfig bad;
  bad.occupied_threshold = 0.4;
  EXPECT_THROW(OccupancyMap3D{bad}, InvalidArgument);
}

// What a full pass over the tree gives (OctoMap's updateInnerOccupancy, its leaf iterator):
// the inner nodes and the projection kept up along the written paths must equal them, frame
// after frame, as faces appear, move, decay and are carved away.
TEST(OccupancyMap3DTest, IncrementalUpkeepEqualsAFullPassOverTheTree) {
  const CameraIntrinsics K = CameraIntrinsics::FromHorizontalFov(80, 60, 1.047);
  OccupancyMap3DConfig config;
  config.decay_s = 1.0;
  config.min_obstacle_height = 0.3;  // some voxels of each face below the band
  OccupancyMap3D map(config);
  int frames_with_obstacles = 0;
  for (int frame = 0; frame < 24; ++frame) {
    // The camera turns and steps; faces near (carved over) and far, some moving, some still.
    const double yaw = 0.1 * std::sin(0.7 * frame);
    const Pose3 X_MC = Pose3::FromXyzRpy({0.01 * frame, 0.01 * frame, 1.0},
                                         {-std::numbers::pi / 2, 0.0, -std::numbers::pi / 2 + yaw});
    const double y = 0.3 * (frame / 4) - 0.6;
    DepthImage image =
        frame % 7 == 6 ? NothingInView(K, 0.0)
                       : RenderFace(K, X_MC, frame < 12 ? 1.3 : 2.5, y - 0.3, y + 0.3, 0.1, 1.3);
    image.stamp = SecondsToDuration(0.2 * frame);
    map.InsertDepthImage(image, K, X_MC);

    octomap::OcTree full(*map.tree());
    full.updateInnerOccupancy();
    ASSERT_TRUE(full == *map.tree()) << "inner nodes differ at frame " << frame;
    std::vector<Eigen::Vector2d> expected;
    for (auto it = full.begin_leafs(), end = full.end_leafs(); it != end; ++it) {
      ASSERT_EQ(it.getDepth(), full.getTreeDepth()) << "a pruned leaf";
      if (!full.isNodeOccupied(*it) || it.getZ() < config.min_obstacle_height ||
          it.getZ() > config.max_obstacle_height)
        continue;
      const double step = config.resolution / 2;
      for (int i = 0; i <= 2; ++i) {
        for (int j = 0; j <= 2; ++j)
          expected.emplace_back(it.getX() - step + i * step, it.getY() - step + j * step);
      }
    }
    EXPECT_EQ(map.ProjectObstacles(), expected) << "frame " << frame;
    frames_with_obstacles += expected.empty() ? 0 : 1;
  }
  EXPECT_GT(frames_with_obstacles, 10);
}

TEST(OccupancyMap3DTest, MalformedInput) {
  const CameraIntrinsics K = CameraIntrinsics::FromHorizontalFov(80, 60, 1.047);
  OccupancyMap3D map;
  DepthImage image;
  image.width = 40;
  image.height = 30;
  image.depth.assign(40 * 30, 1.0f);
  EXPECT_THROW(map.InsertDepthImage(image, K, ForwardCamera()), InvalidArgument);  // size mismatch
  image.width = 80;
  image.height = 60;
  image.depth.assign(80 * 60, std::nanf(""));  // all invalid: nothing inserted, no crash
  EXPECT_EQ(map.InsertDepthImage(image, K, ForwardCamera()), 0u);
  EXPECT_THROW(OccupancyMap3D(OccupancyMap3DConfig{0.0}), InvalidArgument);
}

}  // namespace
}  // namespace egress::perception
