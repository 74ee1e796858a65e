#include "egress/perception/detection.h"

#include <cstdlib>
#include <filesystem>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_paths.h"

#include "egress/hsr_interface/error.h"

namespace egress::perception {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

// Generates the tiny ONNX model with Debian's python3-onnx (see make_tiny_yolo.py).
class YoloDetectorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    model_ = egress::testing::TestTempPath("tiny_yolo.onnx");
    const std::string command =
        std::string("/usr/bin/python3 ") + EGRESS_TINY_YOLO_SCRIPT + " " + model_.string() +
        " 64 3 8"
        " 0:20,30,10,20,0.9,0.05,0.0"   // person
        " 1:20.5,30,10,20,0.8,0.0,0.0"  // the same person again: NMS drops it
        " 2:21,31,10,20,0.0,0.7,0.0"    // a push button on top: other class, kept
        " 3:50,40,6,6,0.0,0.0,0.1"      // a bottle below the threshold
        " 4:60,5,20,20,0.0,0.0,0.6";    // a bottle clipped at the image edge
    if (std::system(command.c_str()) != 0 || !fs::exists(model_)) {
      GTEST_SKIP() << "could not generate the ONNX model: install python3-onnx (./egress.sh deps)";
    }
  }
  void TearDown() override { fs::remove(model_); }

  YoloConfig Config() const {
    YoloConfig config;
    config.model_path = model_;
    config.input_width = config.input_height = 64;
    config.class_names = {"person", "push_button", "bottle"};
    return config;
  }
  fs::path model_;
};

TEST_F(YoloDetectorTest, DecodesLetterboxesAndSuppresses) {
  YoloDetector detector(Config());
  CameraFrame frame;
  frame.image =
      cv::Mat(96, 128, CV_8UC3, cv::Scalar(40, 80, 120));  // letterbox: scale 0.5, pad_y 8
  frame.stamp = std::chrono::milliseconds(1500);
  const auto detections = detector.Detect(frame);
  ASSERT_EQ(detections.size(), 3u);
  EXPECT_EQ(detections[0].label, "person");
  EXPECT_NEAR(detections[0].confidence, 0.9, 1e-6);
  // (cx, cy, w, h) = (20, 30, 10, 20) in the input -> ((20 - 0) / 0.5, (30 - 8) / 0.5) +- (10, 20).
  EXPECT_NEAR(detections[0].box.u_min, 30.0, 1e-4);
  EXPECT_NEAR(detections[0].box.v_min, 24.0, 1e-4);
  EXPECT_NEAR(detections[0].box.u_max, 50.0, 1e-4);
  EXPECT_NEAR(detections[0].box.v_max, 64.0, 1e-4);
  EXPECT_EQ(detections[0].stamp, frame.stamp);
  EXPECT_EQ(detections[1].label, "push_button");
  EXPECT_EQ(detections[2].label, "bottle");
  EXPECT_NEAR(detections[2].box.v_min, 0.0, 1e-9);  // clipped to the image
}

TEST_F(YoloDetectorTest, ModelAndImageErrors) {
  YoloConfig config = Config();
  config.class_names = {"person"};  // the model has 3 classes
  YoloDetector mismatched(config);
  CameraFrame frame;
  frame.image = cv::Mat(64, 64, CV_8UC3, cv::Scalar::all(0));
  try {
    mismatched.Detect(frame);
    FAIL() << "expected LoadError";
  } catch (const LoadError& e) {
    EXPECT_THAT(e.what(), HasSubstr("expected (1, 5, N) for 1 class names"));
  }
  YoloDetector detector(Config());
  frame.image = cv::Mat();
  EXPECT_THROW(detector.Detect(frame), InvalidArgument);
  frame.image = cv::Mat(64, 64, CV_8UC1, cv::Scalar::all(0));
  EXPECT_THROW(detector.Detect(frame), InvalidArgument);
}

TEST(YoloDetectorLoadTest, MissingModelIsNamed) {
  YoloConfig config;
  config.model_path = "/nonexistent/yolo11n.onnx";
  config.class_names = {"person"};
  try {
    YoloDetector detector(config);
    FAIL() << "expected LoadError";
  } catch (const LoadError& e) {
    EXPECT_THAT(e.what(), HasSubstr("/nonexistent/yolo11n.onnx"));
  }
  config.class_names.clear();
  EXPECT_THROW(YoloDetector{config}, InvalidArgument);
}

TEST(DetectionTest, LetterboxGeometry) {
  const Letterbox box = Letterbox::Compute({640, 480}, {640, 640});
  EXPECT_DOUBLE_EQ(box.scale, 1.0);
  EXPECT_DOUBLE_EQ(box.pad_x, 0.0);
  EXPECT_DOUBLE_EQ(box.pad_y, 80.0);
  EXPECT_THROW(Letterbox::Compute({0, 480}, {640, 640}), InvalidArgument);
}

Detection2D Box(const std::string& label, double confidence, double u) {
  return {label, confidence, {u, 10, u + 20, 40}, Time{0}};
}

TEST(DetectionTest, MergeTwoModelsAndFilterPerClass) {
  // The general model and the fine-tuned door/button model both see the button.
  const std::vector<Detection2D> general = {Box("person", 0.9, 100), Box("push_button", 0.4, 10)};
  const std::vector<Detection2D> fine_tuned = {Box("push_button", 0.85, 12),
                                               Box("glass_door", 0.6, 200)};
  const auto merged = MergeDetections({general, fine_tuned}, 0.45);
  ASSERT_EQ(merged.size(), 3u);
  EXPECT_EQ(merged[1].label, "push_button");
  EXPECT_DOUBLE_EQ(merged[1].confidence, 0.85);  // the better one survives
  ConfidenceFilter filter{0.7, {{"glass_door", 0.5}}};
  const auto kept = filter.Apply(merged);
  ASSERT_EQ(kept.size(), 3u);
  filter.per_class["glass_door"] = 0.65;
  EXPECT_EQ(filter.Apply(merged).size(), 2u);
  EXPECT_DOUBLE_EQ(IntersectionOverUnion({0, 0, 10, 10}, {5, 0, 15, 10}), 50.0 / 150.0);
  EXPECT_DOUBLE_EQ(IntersectionOverUnion({0, 0, 10, 10}, {20, 20, 30, 30}), 0.0);
}

TEST(DetectionTest, PortDetectorPassesUpstreamDetections) {
  PortDetector detector;
  CameraFrame frame;
  frame.upstream = {Box("bottle", 0.7, 5)};
  EXPECT_EQ(detector.Detect(frame).size(), 1u);
}

}  // namespace
}  // namespace egress::perception
