#include "egress/perception/object_tracker.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress::perception {
namespace {

using std::chrono::milliseconds;

PlacedDetection At(const std::string& label, double x, double y) {
  return {{label, 0.8, {0, 0, 10, 10}, Time{0}}, {x, y, 0.9}};
}

TEST(ObjectTrackerTest, SuppressesAOneFrameFalsePositive) {
  ObjectTracker tracker;
  tracker.Update({At("push_button", 2.0, 1.0), At("bottle", 4.0, 0.0)},
                 milliseconds(0));  // bottle: a flicker
  tracker.Update({At("push_button", 2.01, 1.0)}, milliseconds(125));
  tracker.Update({At("push_button", 2.0, 1.01)}, milliseconds(250));
  EXPECT_EQ(tracker.Confirmed("push_button").size(), 1u);
  EXPECT_TRUE(tracker.Confirmed("bottle").empty());
  for (const auto& track : tracker.tracks())
    EXPECT_NE(track.label, "bottle");  // dropped entirely
}

TEST(ObjectTrackerTest, KeepsATrueObjectThroughOneMissedFrame) {
  ObjectTracker tracker;
  for (int i = 0; i < 3; ++i)
    tracker.Update({At("bottle", 1.0, 1.0)}, milliseconds(125 * i));
  ASSERT_EQ(tracker.Confirmed("bottle").size(), 1u);
  const int id = tracker.Confirmed("bottle")[0].id;
  tracker.Update({}, milliseconds(375));  // missed once (occlusion)
  ASSERT_EQ(tracker.Confirmed("bottle").size(), 1u);
  tracker.Update({At("bottle", 1.02, 1.0)}, milliseconds(500));
  EXPECT_EQ(tracker.Confirmed("bottle")[0].id, id);  // the same track, not a new one
  for (int i = 0; i < 3; ++i)
    tracker.Update({}, milliseconds(625 + 125 * i));
  EXPECT_TRUE(tracker.Confirmed("bottle").empty());  // gone after drop_misses
}

TEST(ObjectTrackerTest, AssociatesByLabelAndDistance) {
  ObjectTracker tracker({0.4, 1, 3, 1.0});
  tracker.Update({At("push_button", 0.0, 0.0), At("proximity_plate", 0.1, 0.0)}, milliseconds(0));
  tracker.Update({At("push_button", 0.05, 0.0), At("proximity_plate", 0.12, 0.0)},
                 milliseconds(100));
  EXPECT_EQ(tracker.tracks().size(), 2u);
  tracker.Update({At("push_button", 1.0, 0.0)}, milliseconds(200));  // too far: a new object
  EXPECT_EQ(tracker.Confirmed("push_button").size(), 2u);
  EXPECT_THROW(tracker.Update({At("bottle", std::nan(""), 0)}, milliseconds(300)), InvalidArgument);
}

TEST(PlaceDetectionTest, MedianDepthThroughTheIntrinsics) {
  const CameraIntrinsics K = CameraIntrinsics::FromHorizontalFov(80, 60, 1.047);
  DepthImage depth;
  depth.width = 80;
  depth.height = 60;
  depth.depth.assign(80 * 60, 2.0f);
  depth.depth[30 * 80 + 40] = 0.3f;  // an outlier inside the box: the median ignores it
  const Pose3 X_MC =
      Pose3::FromXyzRpy({1.0, 0.0, 1.0}, {-std::numbers::pi / 2, 0.0, -std::numbers::pi / 2});
  // A box centred on the image, given in the 640x480 RGB image.
  const Detection2D detection{"push_button", 0.9, {300, 220, 340, 260}, Time{0}};
  const auto p_MO = PlaceDetection(detection, {640, 480}, depth, K, X_MC);
  ASSERT_TRUE(p_MO.has_value());
  EXPECT_NEAR(p_MO->x(), 3.0, 1e-6);  // 2 m ahead of the camera at x = 1
  EXPECT_NEAR(p_MO->y(), 0.0, 0.02);
  EXPECT_NEAR(p_MO->z(), 1.0, 0.02);
  // Glass: no valid depth, not placed.
  depth.depth.assign(80 * 60, std::nanf(""));
  EXPECT_FALSE(PlaceDetection(detection, {640, 480}, depth, K, X_MC).has_value());
  depth.depth.pop_back();
  EXPECT_THROW(PlaceDetection(detection, {640, 480}, depth, K, X_MC), InvalidArgument);
}

TEST(PlaceDetectionTest, APersonBehindGlassIsPlacedByTheSizeOfTheirBoxNotAtTheFrame) {
  const CameraIntrinsics K = CameraIntrinsics::FromHorizontalFov(80, 60, 1.047);
  const Pose3 X_MC =
      Pose3::FromXyzRpy({1.0, 0.0, 1.0}, {-std::numbers::pi / 2, 0.0, -std::numbers::pi / 2});
  // Glass over the whole box but for one column of the door's frame at 1.0 m.
  DepthImage depth;
  depth.width = 80;
  depth.height = 60;
  depth.depth.assign(80 * 60, std::nanf(""));
  for (int v = 0; v < 60; ++v)
    depth.depth[std::size_t(v * 80 + 40)] = 1.0f;
  // A person 1.7 m tall whose box is 160 px high in the 640x480 image (20 px in the depth's).
  const Detection2D person{"person", 0.9, {300, 160, 340, 320}, Time{0}};
  EXPECT_FALSE(PlaceDetection(person, {640, 480}, depth, K, X_MC).has_value())
      << "a few valid pixels (the frame) must not place the person at the frame's depth";
  const auto p_MP = PlacePersonBySize(person, {640, 480}, K, X_MC, 1.7);
  ASSERT_TRUE(p_MP.has_value());
  const double expected = K.fy * 1.7 / 20.0;  // distance along the optical axis
  EXPECT_NEAR(p_MP->x(), 1.0 + expected, 1e-6);
  EXPECT_GT(p_MP->x(), 3.0);  // far behind the frame, not at 1 m
  // Cut off by the image's edge: its height says nothing.
  const Detection2D cut{"person", 0.9, {300, 0, 340, 320}, Time{0}};
  EXPECT_FALSE(PlacePersonBySize(cut, {640, 480}, K, X_MC, 1.7).has_value());
}

}  // namespace
}  // namespace egress::perception
