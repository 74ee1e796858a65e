#include "egress/hsr_interface/sensor_types.h"

#include <cmath>
#include <limits>
#include <numbers>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"

namespace egress {
namespace {

using ::testing::HasSubstr;

LaserScan HsrScan() {
  // The HSR's base laser: 721 beams over [-2.1, 2.1] rad, 0.05–60 m.
  LaserScan scan;
  scan.angle_min = -2.1;
  scan.angle_increment = 4.2 / 720.0;
  scan.range_min = 0.05;
  scan.range_max = 60.0;
  scan.ranges.assign(721, 3.0f);
  return scan;
}

std::string ErrorOf(const auto& value) {
  try {
    value.Validate();
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "";
}

TEST(LaserScanTest, BeamAnglesAndValidity) {
  LaserScan scan = HsrScan();
  EXPECT_NO_THROW(scan.Validate());
  EXPECT_DOUBLE_EQ(scan.AngleAt(0), -2.1);
  EXPECT_NEAR(scan.AngleAt(360), 0.0, 1e-12);
  EXPECT_NEAR(scan.angle_max(), 2.1, 1e-12);
  scan.ranges[1] = std::numeric_limits<float>::infinity();
  scan.ranges[2] = std::nanf("");
  scan.ranges[3] = 0.01f;            // below range_min
  EXPECT_NO_THROW(scan.Validate());  // inf and NaN are legal encodings
  EXPECT_TRUE(scan.IsValidReturn(0));
  EXPECT_FALSE(scan.IsValidReturn(1));
  EXPECT_FALSE(scan.IsValidReturn(2));
  EXPECT_FALSE(scan.IsValidReturn(3));
}

TEST(LaserScanTest, ValidationNamesTheField) {
  LaserScan scan = HsrScan();
  scan.angle_increment = std::nan("");
  EXPECT_THAT(ErrorOf(scan), HasSubstr("angle_increment"));
  scan = HsrScan();
  scan.angle_increment = -0.01;
  EXPECT_THAT(ErrorOf(scan), HasSubstr("angle_increment"));
  scan = HsrScan();
  scan.range_max = 0.01;
  EXPECT_THAT(ErrorOf(scan), HasSubstr("range_max"));
  scan = HsrScan();
  scan.ranges[5] = -1.0f;
  EXPECT_THAT(ErrorOf(scan), HasSubstr("ranges[5]"));
  scan = HsrScan();
  scan.intensities.assign(3, 1.0f);
  EXPECT_THAT(ErrorOf(scan), HasSubstr("intensities"));
  scan = HsrScan();
  scan.angle_increment = 0.1;  // 721 beams x 0.1 rad > 2 pi
  EXPECT_THAT(ErrorOf(scan), HasSubstr("full turn"));
}

TEST(CameraIntrinsicsTest, ProjectUnprojectRoundTrip) {
  // The HSR's Xtion: 640x480, hfov 1.047 rad -> fx ≈ 554 px.
  const CameraIntrinsics K = CameraIntrinsics::FromHorizontalFov(640, 480, 1.047);
  EXPECT_NEAR(K.fx, 554.3, 0.5);
  EXPECT_DOUBLE_EQ(K.cx, 320.0);
  EXPECT_NO_THROW(K.Validate());
  const Eigen::Vector3d p_CQ(0.4, -0.3, 2.5);
  const auto pixel = K.Project(p_CQ);
  ASSERT_TRUE(pixel.has_value());
  EXPECT_LT((K.Unproject(pixel->x(), pixel->y(), 2.5) - p_CQ).norm(), 1e-12);
  EXPECT_FALSE(K.Project(Eigen::Vector3d(0, 0, -1)).has_value());  // behind the camera
  EXPECT_THROW(CameraIntrinsics::FromHorizontalFov(640, 480, 3.5), InvalidArgument);
  EXPECT_THROW(CameraIntrinsics::FromHorizontalFov(0, 480, 1.0), InvalidArgument);
  CameraIntrinsics bad = K;
  bad.fy = 0.0;
  EXPECT_THAT(ErrorOf(bad), HasSubstr("fy"));
}

TEST(DepthImageTest, SizeAndValues) {
  DepthImage image;
  image.width = 4;
  image.height = 3;
  image.depth.assign(12, 1.0f);
  image.depth[5] = std::nanf("");
  image.depth[6] = 0.0f;
  EXPECT_NO_THROW(image.Validate());
  EXPECT_TRUE(image.IsValidAt(0, 0));
  EXPECT_FALSE(image.IsValidAt(1, 1));  // NaN: no return
  EXPECT_FALSE(image.IsValidAt(2, 1));  // 0: no return
  EXPECT_FALSE(image.IsValidAt(4, 0));  // outside
  image.depth[7] = -2.0f;
  EXPECT_THAT(ErrorOf(image), HasSubstr("(3, 1)"));
  image.depth.pop_back();
  EXPECT_THAT(ErrorOf(image), HasSubstr("width*height"));
}

TEST(Detection2DTest, Validation) {
  Detection2D detection{"push_button", 0.9, {10, 20, 30, 40}, Time{0}};
  EXPECT_NO_THROW(detection.Validate());
  EXPECT_DOUBLE_EQ(detection.box.center().x(), 20.0);
  detection.confidence = 1.2;
  EXPECT_THAT(ErrorOf(detection), HasSubstr("confidence"));
  detection.confidence = 0.5;
  detection.box.u_max = 5.0;
  EXPECT_THAT(ErrorOf(detection), HasSubstr("box"));
  detection.box.u_max = 30.0;
  detection.label.clear();
  EXPECT_THAT(ErrorOf(detection), HasSubstr("label"));
}

}  // namespace
}  // namespace egress

namespace egress {
namespace {

TEST(ColorImageTest, SizeAndBufferMustAgree) {
  ColorImage image;
  image.width = 4;
  image.height = 2;
  image.bgr.assign(4 * 2 * 3, 0);
  EXPECT_NO_THROW(image.Validate());
  image.bgr.pop_back();
  EXPECT_THROW(image.Validate(), InvalidArgument);
  image.bgr.clear();
  image.width = 0;
  EXPECT_THROW(image.Validate(), InvalidArgument);
}

}  // namespace
}  // namespace egress
