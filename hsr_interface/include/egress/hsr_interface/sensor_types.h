#pragma once
/// @file
/// What the robot's sensors deliver: planar laser scans, depth images with their pinhole
/// intrinsics, and 2D object detections. Each type has Validate(), which throws
/// InvalidArgument naming the offending field, so bad data is stopped at the RobotPort
/// boundary rather than deep inside perception.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "egress/hsr_interface/frames.h"
#include "egress/hsr_interface/time.h"

namespace egress {

/// One sweep of a planar laser in its frame L (x forward, counter-clockwise angles about +z).
struct LaserScan {
  std::string frame_id{frames::kLaser};
  Time stamp{};
  double angle_min{0.0};        ///< Angle of ranges[0] [rad].
  double angle_increment{0.0};  ///< Angle between consecutive beams [rad], > 0.
  double range_min{0.0};        ///< Closest valid return [m].
  double range_max{0.0};        ///< Farthest valid return [m].
  /// Per-beam range [m]. +inf means no return within range_max; NaN means an invalid beam.
  std::vector<float> ranges;
  /// Per-beam intensity (sensor units); empty or the same size as ranges.
  std::vector<float> intensities;

  double AngleAt(std::size_t i) const { return angle_min + angle_increment * double(i); }
  /// Angle of the last beam [rad] (angle_min when there are no beams).
  double angle_max() const;
  /// True if beam i holds a return inside [range_min, range_max].
  bool IsValidReturn(std::size_t i) const;
  /// @throws InvalidArgument naming the field that is non-finite, out of order or mis-sized.
  void Validate() const;
};

/// Pinhole camera intrinsics for an image of width x height pixels; focal lengths and principal
/// point in pixels. Pixel (u, v) has u to the right, v down; the camera frame C is optical
/// (z forward, x right, y down).
struct CameraIntrinsics {
  int width{0};
  int height{0};
  double fx{0.0};
  double fy{0.0};
  double cx{0.0};
  double cy{0.0};

  /// Square pixels, principal point at the image centre, focal length from the horizontal
  /// field of view. @throws InvalidArgument for a non-positive size or fov outside (0, pi).
  static CameraIntrinsics FromHorizontalFov(int width, int height, double hfov);
  /// Projects p_CQ to pixel coordinates; nullopt when Q is not in front of the camera.
  std::optional<Eigen::Vector2d> Project(const Eigen::Vector3d& p_CQ) const;
  /// The point at pixel (u, v) with depth z [m] along the optical axis.
  Eigen::Vector3d Unproject(double u, double v, double depth) const;
  /// @throws InvalidArgument naming the field.
  void Validate() const;
};

/// A depth image: row-major, metres along the optical axis of frame_id. A pixel without a valid
/// return holds NaN (0 is accepted as "invalid" on input too, as many drivers write it).
struct DepthImage {
  std::string frame_id{frames::kHeadCamera};
  Time stamp{};
  int width{0};
  int height{0};
  std::vector<float> depth;

  float At(int u, int v) const {
    return depth[std::size_t(v) * std::size_t(width) + std::size_t(u)];
  }
  /// True if (u, v) is inside the image and holds a finite, positive depth.
  bool IsValidAt(int u, int v) const;
  /// @throws InvalidArgument if the size does not match width*height or a depth is negative/inf.
  void Validate() const;
};

/// Axis-aligned pixel box; u to the right, v down, max exclusive of nothing (continuous coords).
struct PixelBox {
  double u_min{0.0};
  double v_min{0.0};
  double u_max{0.0};
  double v_max{0.0};
  double width() const { return u_max - u_min; }
  double height() const { return v_max - v_min; }
  Eigen::Vector2d center() const { return {(u_min + u_max) / 2, (v_min + v_max) / 2}; }
};

/// One labelled box from a 2D detector, in the image of the camera frame_id.
/// A colour image from the head RGB-D camera, 8-bit BGR, row-major (OpenCV's layout; ROS 2's
/// sensor_msgs/Image with encoding "bgr8"). Same optical frame C as the depth image.
struct ColorImage {
  std::string frame_id{frames::kHeadCamera};
  Time stamp{};  ///< Capture time.
  int width{0};
  int height{0};
  std::vector<std::uint8_t> bgr;  ///< width * height * 3 bytes.
  /// @throws InvalidArgument for a non-positive size or a buffer that does not match it.
  void Validate() const;
};

struct Detection2D {
  std::string label;       ///< Class label, e.g. "person", "push_button", "bottle".
  double confidence{0.0};  ///< In [0, 1].
  PixelBox box;
  Time stamp{};  ///< Capture time of the image the box was found in.
  std::string frame_id{frames::kHeadCamera};
  /// @throws InvalidArgument for an empty label, confidence outside [0, 1], or an inverted or
  /// non-finite box.
  void Validate() const;
};

}  // namespace egress
