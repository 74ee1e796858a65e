#pragma once
/// @file
/// The detection front end: a Detector turns a camera frame into Detection2D boxes. Two
/// implementations: YoloDetector (an ONNX YOLOv8/YOLO11 export run by OpenCV's dnn module) and
/// PortDetector (the detections that arrive through RobotPort, e.g. from the twin's simulated
/// detector). Several detectors (the paper's general + fine-tuned models) are merged with
/// MergeDetections; ConfidenceFilter applies per-class thresholds.

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "egress/hsr_interface/sensor_types.h"

namespace egress::perception {

/// One camera frame: the BGR image (may be empty when only upstream detections exist) and the
/// detections a robot-side detector already produced for it.
struct CameraFrame {
  Time stamp{};
  std::string frame_id{frames::kHeadCamera};
  cv::Mat image;
  std::vector<Detection2D> upstream;
};

class Detector {
 public:
  virtual ~Detector() = default;
  virtual std::vector<Detection2D> Detect(const CameraFrame& frame) = 0;
};

/// Returns the frame's upstream detections (RobotPort's), unchanged.
class PortDetector final : public Detector {
 public:
  std::vector<Detection2D> Detect(const CameraFrame& frame) override { return frame.upstream; }
};

struct YoloConfig {
  std::filesystem::path model_path;  ///< ONNX export with output (1, 4 + classes, anchors).
  int input_width{640};              ///< Network input size [px].
  int input_height{640};
  std::vector<std::string> class_names;  ///< Index i names class score row 4 + i.
  double confidence_threshold{0.25};     ///< Anchors below this are dropped before NMS.
  double nms_iou_threshold{0.45};        ///< Class-wise non-maximum suppression.
  void Validate() const;
};

/// How an image was fitted into the network input: uniform scale, then centred padding.
struct Letterbox {
  double scale{1.0};
  double pad_x{0.0};
  double pad_y{0.0};
  /// @throws InvalidArgument for empty sizes.
  static Letterbox Compute(cv::Size image, cv::Size input);
};

class YoloDetector final : public Detector {
 public:
  /// Loads the model. @throws LoadError naming the file if it is missing or not a valid ONNX.
  explicit YoloDetector(YoloConfig config);
  ~YoloDetector() override;
  /// Runs the network on frame.image. @throws InvalidArgument for an empty or non-BGR image.
  std::vector<Detection2D> Detect(const CameraFrame& frame) override;

  /// Letterboxes `bgr` into the network input (gray 114 padding), RGB, scaled to [0, 1].
  static cv::Mat Preprocess(const cv::Mat& bgr, cv::Size input, Letterbox* letterbox);
  /// Decodes a (1, 4 + C, N) output: per anchor the best class above the threshold, the box
  /// (cx, cy, w, h in input pixels) mapped back through the letterbox and clipped to the image,
  /// then class-wise NMS. @throws LoadError if the output shape does not match the classes.
  static std::vector<Detection2D> Decode(const cv::Mat& output, const Letterbox& letterbox,
                                         cv::Size image, const YoloConfig& config, Time stamp,
                                         const std::string& frame_id);

 private:
  YoloConfig config_;
  struct Net;
  std::unique_ptr<Net> net_;
};

/// Intersection over union of two boxes (0 for empty boxes).
double IntersectionOverUnion(const PixelBox& a, const PixelBox& b);
/// Greedy class-wise non-maximum suppression: highest confidence first, dropping boxes of the
/// same label overlapping a kept one by more than `iou_threshold`.
std::vector<Detection2D> NonMaximumSuppression(std::vector<Detection2D> detections,
                                               double iou_threshold);
/// Merges the outputs of several detectors on the same frame (class-wise NMS across them).
std::vector<Detection2D> MergeDetections(const std::vector<std::vector<Detection2D>>& per_detector,
                                         double iou_threshold);

/// Per-class confidence thresholds.
struct ConfidenceFilter {
  double default_threshold{0.5};
  std::map<std::string, double> per_class;
  std::vector<Detection2D> Apply(const std::vector<Detection2D>& detections) const;
};

}  // namespace egress::perception
