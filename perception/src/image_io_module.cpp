// libegress_image_io.so: OpenCV's imgcodecs and videoio for egress::perception's image_io.h,
// opened on first use (see there why). Links OpenCV alone, none of egress's own libraries.

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "egress/perception/image_io.h"

namespace {

using egress::perception::internal::ImageIoModule;

bool WriteFile(const std::string& path, const cv::Mat& image) {
  try {
    return cv::imwrite(path, image);
  } catch (const cv::Exception&) {
    return false;  // no writer for that extension, or an image it cannot write
  }
}

bool Encode(const std::string& extension, const cv::Mat& image, std::vector<unsigned char>* out) {
  try {
    return cv::imencode(extension, image, *out);
  } catch (const cv::Exception&) {
    return false;
  }
}

cv::Mat DecodeGray(const cv::Mat& encoded) {
  try {
    return cv::imdecode(encoded, cv::IMREAD_GRAYSCALE);
  } catch (const cv::Exception&) {
    return {};
  }
}

void* OpenVideo(const std::string& path, int fourcc, double fps, cv::Size size) {
  auto writer = std::make_unique<cv::VideoWriter>(path, fourcc, fps, size);
  return writer->isOpened() ? writer.release() : nullptr;
}

void WriteVideo(void* writer, const cv::Mat& frame) {
  static_cast<cv::VideoWriter*>(writer)->write(frame);
}

void CloseVideo(void* writer) {
  delete static_cast<cv::VideoWriter*>(writer);
}

constexpr ImageIoModule kModule{egress::perception::internal::kImageIoModuleVersion,
                                WriteFile,
                                Encode,
                                DecodeGray,
                                OpenVideo,
                                WriteVideo,
                                CloseVideo};

}  // namespace

extern "C" __attribute__((visibility("default"))) const ImageIoModule* egress_image_io_module() {
  return &kModule;
}
