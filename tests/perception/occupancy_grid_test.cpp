#include "egress/perception/occupancy_grid.h"

#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_paths.h"

#include "egress/hsr_interface/error.h"
#include "egress/perception/image_io.h"

namespace egress::perception {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

class MapServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = egress::testing::TestTempPath("map");
    fs::create_directories(dir_);
    // 4 x 3 image: top-left black (occupied), bottom-right white (free), one gray (unknown).
    cv::Mat image(3, 4, CV_8UC1, cv::Scalar(254));
    image.at<std::uint8_t>(0, 0) = 0;
    image.at<std::uint8_t>(1, 1) = 205;
    ASSERT_TRUE(WriteImageFile(dir_ / "map.pgm", image));
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path WriteYaml(const std::string& text) {
    const auto path = dir_ / "map.yaml";
    std::ofstream(path) << text;
    return path;
  }
  std::string ErrorOf(const std::string& yaml) {
    try {
      OccupancyGrid::LoadMapServerYaml(WriteYaml(yaml));
    } catch (const LoadError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

TEST_F(MapServerTest, LoadsTheMapServerConvention) {
  const OccupancyGrid grid = OccupancyGrid::LoadMapServerYaml(
      WriteYaml("image: map.pgm\nresolution: 0.5\norigin: [-1.0, 2.0, 0.0]\nnegate: 0\n"
                "occupied_thresh: 0.65\nfree_thresh: 0.196\n"));
  EXPECT_EQ(grid.geometry().width, 4);
  EXPECT_EQ(grid.geometry().height, 3);
  // Image row 0 is the top: the black pixel is cell (0, 2), at the map's top-left.
  EXPECT_EQ(grid.at(0, 2), kLethalCost);
  EXPECT_EQ(grid.at(1, 1), kUnknownCost);
  EXPECT_EQ(grid.at(3, 0), kFreeCost);
  EXPECT_TRUE(grid.IsOccupied({-0.75, 3.25}));
  EXPECT_FALSE(grid.IsOccupied({0.75, 2.25}));
}

TEST_F(MapServerTest, ErrorsNameFileLineAndField) {
  EXPECT_THAT(ErrorOf("image: map.pgm\norigin: [0, 0, 0]\n"),
              HasSubstr("required field 'resolution' is missing"));
  EXPECT_THAT(ErrorOf("image: map.pgm\nresolution: fine\norigin: [0, 0, 0]\n"),
              HasSubstr("map.yaml:2: field 'resolution' (fine) must be a number"));
  EXPECT_THAT(ErrorOf("image: map.pgm\nresolution: 0.05\norigin: [0, 0]\n"),
              HasSubstr("map.yaml:3: field 'origin' must have 3 numbers"));
  EXPECT_THAT(ErrorOf("image: missing.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n"),
              HasSubstr("map.yaml:1: image"));
  EXPECT_THAT(ErrorOf("image: map.pgm\nresolution: 0.05\norigin: [0, 0, 0.3]\n"),
              HasSubstr("rotated map origin"));
  EXPECT_THAT(ErrorOf("image: map.pgm\nresolution: -1\norigin: [0, 0, 0]\n"),
              HasSubstr("must be > 0"));
  EXPECT_THROW(OccupancyGrid::LoadMapServerYaml(dir_ / "absent.yaml"), LoadError);
}

TEST(OccupancyGridTest, BoxesAndRayCasts) {
  const OccupancyGrid grid =
      OccupancyGrid::FromBoxes({{{3.0, 2.0, 0.0}, {0.2, 4.0}}}, {0, 0}, {5, 4}, 0.05);
  EXPECT_TRUE(grid.IsOccupied({3.0, 1.0}));
  EXPECT_FALSE(grid.IsOccupied({2.5, 1.0}));
  const auto hit = RayCast(grid, {1.0, 1.0}, 0.0, 10.0);
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(*hit, 1.9, 0.05);  // the wall's face at x = 2.9
  EXPECT_FALSE(RayCast(grid, {1.0, 1.0}, 3.14159, 0.5).has_value());
  EXPECT_THROW(OccupancyGrid::FromBoxes({}, {0, 0}, {0, 4}, 0.05), InvalidArgument);
}

}  // namespace
}  // namespace egress::perception
