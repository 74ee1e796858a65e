#pragma once
/// @file
/// Image and video files: OpenCV's imgcodecs and videoio, behind a module loaded on first use.
///
/// Why a module: Debian's imgcodecs and videoio pull in ~200 shared libraries (GDAL, GDCM, FFmpeg,
/// GStreamer); linked into `egress` their loading took 0.3-0.5 s of every start (a 60 s crowd run
/// spends ~3 s simulating), though most runs write no image. `libegress_image_io.so` links them
/// and is opened (dlopen) the first time an image is read or written: the file
/// $EGRESS_IMAGE_IO_MODULE names if it is set (that one only), else where the build put it,
/// beside the executable, or in ../lib from it.

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace egress::perception {

/// Writes `image` to `path` in the format its extension names (.png, .pgm, .jpg, ...).
/// False when OpenCV cannot. @throws LoadError when the image module cannot be loaded.
bool WriteImageFile(const std::filesystem::path& path, const cv::Mat& image);

/// Encodes `image` in the format `extension` names (".png") into `out`. False when OpenCV
/// cannot. @throws LoadError when the image module cannot be loaded.
bool EncodeImage(const std::string& extension, const cv::Mat& image,
                 std::vector<unsigned char>* out);

/// Decodes an encoded image (one row of bytes) to 8-bit grey; empty when the bytes are no image
/// OpenCV reads. @throws LoadError when the image module cannot be loaded.
cv::Mat DecodeGrayImage(const cv::Mat& encoded);

/// A video file written frame by frame (OpenCV's VideoWriter).
class VideoFileWriter {
 public:
  /// Opens `path` for frames of `frame_size` at `fps` [1/s], encoded as `fourcc` (four
  /// characters, "mp4v"). opened() tells whether OpenCV could. @throws LoadError when the image
  /// module cannot be loaded.
  VideoFileWriter(const std::filesystem::path& path, const std::string& fourcc, double fps,
                  cv::Size frame_size);
  ~VideoFileWriter();
  VideoFileWriter(const VideoFileWriter&) = delete;
  VideoFileWriter& operator=(const VideoFileWriter&) = delete;

  bool opened() const { return writer_ != nullptr; }
  /// Appends a frame (BGR, frame_size); ignored when not opened.
  void Write(const cv::Mat& frame);

 private:
  void* writer_{nullptr};  // the module's cv::VideoWriter
};

namespace internal {
/// What the module exports (egress_image_io_module); the version guards against a stale module.
struct ImageIoModule {
  int version;
  bool (*write_file)(const std::string& path, const cv::Mat& image);
  bool (*encode)(const std::string& extension, const cv::Mat& image,
                 std::vector<unsigned char>* out);
  cv::Mat (*decode_gray)(const cv::Mat& encoded);
  void* (*open_video)(const std::string& path, int fourcc, double fps, cv::Size size);
  void (*write_video)(void* writer, const cv::Mat& frame);
  void (*close_video)(void* writer);
};
inline constexpr int kImageIoModuleVersion = 1;
}  // namespace internal

}  // namespace egress::perception
