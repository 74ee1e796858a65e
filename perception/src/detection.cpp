#include "egress/perception/detection.h"

#include <algorithm>
#include <cmath>

#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>

#include "egress/hsr_interface/error.h"

namespace egress::perception {

void YoloConfig::Validate() const {
  ThrowUnless(input_width > 0 && input_height > 0, "Invalid YoloConfig: input size (", input_width,
              "x", input_height, ") must be positive.");
  ThrowUnless(!class_names.empty(), "Invalid YoloConfig: class_names must not be empty.");
  ThrowUnless(confidence_threshold >= 0.0 && confidence_threshold <= 1.0,
              "Invalid YoloConfig: confidence_threshold (", confidence_threshold,
              ") must be in [0, 1].");
  ThrowUnless(nms_iou_threshold > 0.0 && nms_iou_threshold <= 1.0,
              "Invalid YoloConfig: nms_iou_threshold (", nms_iou_threshold, ") must be in (0, 1].");
}

Letterbox Letterbox::Compute(cv::Size image, cv::Size input) {
  ThrowUnless(image.width > 0 && image.height > 0 && input.width > 0 && input.height > 0,
              "Invalid letterbox: image and input sizes must be positive.");
  Letterbox box;
  box.scale = std::min(double(input.width) / image.width, double(input.height) / image.height);
  box.pad_x = (input.width - std::round(image.width * box.scale)) / 2.0;
  box.pad_y = (input.height - std::round(image.height * box.scale)) / 2.0;
  return box;
}

struct YoloDetector::Net {
  cv::dnn::Net net;
};

YoloDetector::YoloDetector(YoloConfig config)
    : config_(std::move(config)), net_(std::make_unique<Net>()) {
  config_.Validate();
  const std::string path = config_.model_path.string();
  if (!std::filesystem::is_regular_file(config_.model_path)) {
    throw LoadError(StrCat("Cannot load detector model: '", path, "' does not exist."));
  }
  try {
    net_->net = cv::dnn::readNetFromONNX(path);
  } catch (const cv::Exception& e) {
    throw LoadError(StrCat("Cannot load detector model '", path, "': ", e.what()));
  }
  if (net_->net.empty())
    throw LoadError(StrCat("Cannot load detector model '", path, "': the network is empty."));
}

YoloDetector::~YoloDetector() = default;

cv::Mat YoloDetector::Preprocess(const cv::Mat& bgr, cv::Size input, Letterbox* letterbox) {
  *letterbox = Letterbox::Compute(bgr.size(), input);
  cv::Mat resized;
  const cv::Size scaled(int(std::round(bgr.cols * letterbox->scale)),
                        int(std::round(bgr.rows * letterbox->scale)));
  cv::resize(bgr, resized, scaled, 0, 0, cv::INTER_LINEAR);
  cv::Mat canvas(input, CV_8UC3, cv::Scalar(114, 114, 114));
  resized.copyTo(canvas(cv::Rect(int(std::floor(letterbox->pad_x)),
                                 int(std::floor(letterbox->pad_y)), scaled.width, scaled.height)));
  return cv::dnn::blobFromImage(canvas, 1.0 / 255.0, input, cv::Scalar(), /*swapRB=*/true,
                                /*crop=*/false);
}

std::vector<Detection2D> YoloDetector::Decode(const cv::Mat& output, const Letterbox& letterbox,
                                              cv::Size image, const YoloConfig& config, Time stamp,
                                              const std::string& frame_id) {
  const int classes = int(config.class_names.size());
  if (output.dims != 3 || output.size[0] != 1 || output.size[1] != 4 + classes) {
    throw LoadError(StrCat("YOLO output has shape (", output.dims >= 1 ? output.size[0] : 0, ", ",
                           output.dims >= 2 ? output.size[1] : 0, ", ",
                           output.dims >= 3 ? output.size[2] : 0, "); expected (1, ", 4 + classes,
                           ", N) for ", classes, " class names"));
  }
  const int anchors = output.size[2];
  const cv::Mat table(4 + classes, anchors, CV_32F, const_cast<float*>(output.ptr<float>()));
  std::vector<Detection2D> detections;
  for (int a = 0; a < anchors; ++a) {
    int best = 0;
    float score = table.at<float>(4, a);
    for (int c = 1; c < classes; ++c) {
      if (table.at<float>(4 + c, a) > score) {
        score = table.at<float>(4 + c, a);
        best = c;
      }
    }
    if (score < config.confidence_threshold) continue;
    const double cx = table.at<float>(0, a), cy = table.at<float>(1, a);
    const double w = table.at<float>(2, a), h = table.at<float>(3, a);
    const auto to_image_x = [&](double x) {
      return std::clamp((x - letterbox.pad_x) / letterbox.scale, 0.0, double(image.width));
    };
    const auto to_image_y = [&](double y) {
      return std::clamp((y - letterbox.pad_y) / letterbox.scale, 0.0, double(image.height));
    };
    Detection2D detection;
    detection.label = config.class_names[std::size_t(best)];
    detection.confidence = std::clamp(double(score), 0.0, 1.0);
    detection.box = {to_image_x(cx - w / 2), to_image_y(cy - h / 2), to_image_x(cx + w / 2),
                     to_image_y(cy + h / 2)};
    detection.stamp = stamp;
    detection.frame_id = frame_id;
    if (detection.box.width() <= 0.0 || detection.box.height() <= 0.0) continue;
    detections.push_back(std::move(detection));
  }
  return NonMaximumSuppression(std::move(detections), config.nms_iou_threshold);
}

std::vector<Detection2D> YoloDetector::Detect(const CameraFrame& frame) {
  ThrowUnless(!frame.image.empty() && frame.image.type() == CV_8UC3,
              "Invalid camera frame for YOLO: the image ", "must be a non-empty 8-bit BGR image.");
  Letterbox letterbox;
  net_->net.setInput(
      Preprocess(frame.image, {config_.input_width, config_.input_height}, &letterbox));
  const cv::Mat output = net_->net.forward();
  return Decode(output, letterbox, frame.image.size(), config_, frame.stamp, frame.frame_id);
}

double IntersectionOverUnion(const PixelBox& a, const PixelBox& b) {
  const double w = std::min(a.u_max, b.u_max) - std::max(a.u_min, b.u_min);
  const double h = std::min(a.v_max, b.v_max) - std::max(a.v_min, b.v_min);
  if (w <= 0.0 || h <= 0.0) return 0.0;
  const double intersection = w * h;
  const double united = a.width() * a.height() + b.width() * b.height() - intersection;
  return united > 0.0 ? intersection / united : 0.0;
}

std::vector<Detection2D> NonMaximumSuppression(std::vector<Detection2D> detections,
                                               double iou_threshold) {
  std::stable_sort(
      detections.begin(), detections.end(),
      [](const Detection2D& a, const Detection2D& b) { return a.confidence > b.confidence; });
  std::vector<Detection2D> kept;
  for (auto& candidate : detections) {
    bool suppressed = false;
    for (const auto& k : kept) {
      if (k.label == candidate.label &&
          IntersectionOverUnion(k.box, candidate.box) > iou_threshold) {
        suppressed = true;
        break;
      }
    }
    if (!suppressed) kept.push_back(std::move(candidate));
  }
  return kept;
}

std::vector<Detection2D> MergeDetections(const std::vector<std::vector<Detection2D>>& per_detector,
                                         double iou_threshold) {
  std::vector<Detection2D> all;
  for (const auto& detections : per_detector)
    all.insert(all.end(), detections.begin(), detections.end());
  return NonMaximumSuppression(std::move(all), iou_threshold);
}

std::vector<Detection2D> ConfidenceFilter::Apply(const std::vector<Detection2D>& detections) const {
  std::vector<Detection2D> kept;
  for (const auto& d : detections) {
    auto it = per_class.find(d.label);
    if (d.confidence >= (it != per_class.end() ? it->second : default_threshold)) kept.push_back(d);
  }
  return kept;
}

}  // namespace egress::perception
