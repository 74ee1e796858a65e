#include "egress/perception/image_io.h"

#include <filesystem>
#include <fstream>
#include <iterator>

#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"
#include "test_paths.h"

namespace egress::perception {
namespace {

namespace fs = std::filesystem;

cv::Mat Gradient() {
  cv::Mat image(24, 32, CV_8UC1);
  for (int r = 0; r < image.rows; ++r)
    for (int c = 0; c < image.cols; ++c)
      image.at<std::uint8_t>(r, c) = std::uint8_t(r * 8 + c);
  return image;
}

cv::Mat FileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), {});
  return cv::Mat(bytes, /*copyData=*/true).reshape(1, 1);
}

// The module is opened on first use: a PNG written, encoded and decoded comes back as it was.
TEST(ImageIoTest, AnImageWrittenOrEncodedDecodesToTheSamePixels) {
  const fs::path dir = egress::testing::TestTempPath("image_io");
  fs::create_directories(dir);
  const cv::Mat image = Gradient();
  ASSERT_TRUE(WriteImageFile(dir / "gradient.png", image));
  const cv::Mat from_file = DecodeGrayImage(FileBytes(dir / "gradient.png"));
  ASSERT_EQ(from_file.size(), image.size());
  EXPECT_EQ(cv::countNonZero(from_file != image), 0);
  std::vector<unsigned char> png;
  ASSERT_TRUE(EncodeImage(".png", image, &png));
  EXPECT_EQ(png.size(), fs::file_size(dir / "gradient.png"));
  const cv::Mat decoded = DecodeGrayImage(cv::Mat(png, true).reshape(1, 1));
  EXPECT_EQ(cv::countNonZero(decoded != image), 0);
  fs::remove_all(dir);
}

// What OpenCV cannot do is false or empty, never a crash: a folder that does not exist, a format
// it does not know, bytes that are no image.
TEST(ImageIoTest, WhatCannotBeWrittenOrReadIsFalseOrEmpty) {
  const fs::path missing = egress::testing::TestTempPath("image_io_missing") / "no" / "such";
  EXPECT_FALSE(WriteImageFile(missing / "x.png", Gradient()));
  std::vector<unsigned char> out;
  EXPECT_FALSE(EncodeImage(".not_a_format", Gradient(), &out));
  const std::string text = "not an image at all";
  EXPECT_TRUE(DecodeGrayImage(cv::Mat(1, int(text.size()), CV_8UC1, const_cast<char*>(text.data())))
                  .empty());
  VideoFileWriter nowhere(missing / "x.mp4", "mp4v", 10.0, {32, 24});
  EXPECT_FALSE(nowhere.opened());
  nowhere.Write(cv::Mat(24, 32, CV_8UC3, cv::Scalar(0, 0, 0)));  // ignored
  EXPECT_THROW(VideoFileWriter(missing / "x.mp4", "mp4", 10.0, {32, 24}), InvalidArgument);
}

TEST(ImageIoTest, AVideoIsWrittenFrameByFrame) {
  const fs::path dir = egress::testing::TestTempPath("image_io_video");
  fs::create_directories(dir);
  {
    VideoFileWriter writer(dir / "run.mp4", "mp4v", 10.0, {64, 48});
    ASSERT_TRUE(writer.opened()) << "OpenCV has no MP4 writer here";
    for (int i = 0; i < 10; ++i)
      writer.Write(cv::Mat(48, 64, CV_8UC3, cv::Scalar(i * 20, 100, 200)));
  }  // closed: the file is complete
  EXPECT_GT(fs::file_size(dir / "run.mp4"), 0u);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace egress::perception
