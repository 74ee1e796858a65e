#include "egress/hsr_interface/sensor_types.h"

#include <cmath>
#include <numbers>

#include "check.h"

namespace egress {

using internal::CheckFinite;

double LaserScan::angle_max() const {
  return ranges.empty() ? angle_min : AngleAt(ranges.size() - 1);
}

bool LaserScan::IsValidReturn(std::size_t i) const {
  const float r = ranges[i];
  return std::isfinite(r) && r >= range_min && r <= range_max;
}

void LaserScan::Validate() const {
  constexpr std::string_view kType = "LaserScan";
  ThrowUnless(!frame_id.empty(), "Invalid LaserScan: frame_id must not be empty.");
  CheckFinite(angle_min, kType, "angle_min");
  CheckFinite(angle_increment, kType, "angle_increment");
  CheckFinite(range_min, kType, "range_min");
  CheckFinite(range_max, kType, "range_max");
  ThrowUnless(angle_increment > 0.0, "Invalid LaserScan: angle_increment (", angle_increment,
              ") must be > 0.");
  ThrowUnless(range_min >= 0.0 && range_max > range_min, "Invalid LaserScan: range_min (",
              range_min, ") and range_max (", range_max, ") must satisfy 0 <= min < max.");
  const double span = ranges.empty() ? 0.0 : angle_increment * double(ranges.size() - 1);
  ThrowUnless(span <= 2.0 * std::numbers::pi + 1e-6, "Invalid LaserScan: ranges (", ranges.size(),
              " beams of ", angle_increment, " rad) span more than a full turn.");
  ThrowUnless(intensities.empty() || intensities.size() == ranges.size(),
              "Invalid LaserScan: intensities (", intensities.size(),
              ") must be empty or the same size as ranges (", ranges.size(), ").");
  for (std::size_t i = 0; i < ranges.size(); ++i) {
    ThrowUnless(std::isnan(ranges[i]) || ranges[i] >= 0.0f, "Invalid LaserScan: ranges[", i, "] (",
                ranges[i], ") must be >= 0, +inf (no return) or NaN (invalid).");
  }
}

CameraIntrinsics CameraIntrinsics::FromHorizontalFov(int width, int height, double hfov) {
  ThrowUnless(width > 0 && height > 0, "Invalid CameraIntrinsics: width (", width, ") and height (",
              height, ") must be > 0.");
  ThrowUnless(std::isfinite(hfov) && hfov > 0.0 && hfov < std::numbers::pi,
              "Invalid CameraIntrinsics: hfov (", hfov, " rad) must be in (0, pi).");
  const double f = (width / 2.0) / std::tan(hfov / 2.0);
  return {width, height, f, f, width / 2.0, height / 2.0};
}

std::optional<Eigen::Vector2d> CameraIntrinsics::Project(const Eigen::Vector3d& p_CQ) const {
  if (!(p_CQ.z() > 0.0) || !p_CQ.allFinite()) return std::nullopt;
  return Eigen::Vector2d(fx * p_CQ.x() / p_CQ.z() + cx, fy * p_CQ.y() / p_CQ.z() + cy);
}

Eigen::Vector3d CameraIntrinsics::Unproject(double u, double v, double depth) const {
  return {(u - cx) * depth / fx, (v - cy) * depth / fy, depth};
}

void CameraIntrinsics::Validate() const {
  constexpr std::string_view kType = "CameraIntrinsics";
  ThrowUnless(width > 0 && height > 0, "Invalid CameraIntrinsics: width (", width, ") and height (",
              height, ") must be > 0.");
  CheckFinite(fx, kType, "fx");
  CheckFinite(fy, kType, "fy");
  CheckFinite(cx, kType, "cx");
  CheckFinite(cy, kType, "cy");
  ThrowUnless(fx > 0.0 && fy > 0.0, "Invalid CameraIntrinsics: fx (", fx, ") and fy (", fy,
              ") must be > 0.");
}

bool DepthImage::IsValidAt(int u, int v) const {
  if (u < 0 || v < 0 || u >= width || v >= height) return false;
  const float d = At(u, v);
  return std::isfinite(d) && d > 0.0f;
}

void DepthImage::Validate() const {
  ThrowUnless(width >= 0 && height >= 0, "Invalid DepthImage: width (", width, ") and height (",
              height, ") must be >= 0.");
  ThrowUnless(depth.size() == std::size_t(width) * std::size_t(height),
              "Invalid DepthImage: depth has ", depth.size(), " pixels but width*height is ",
              std::size_t(width) * std::size_t(height), ".");
  ThrowUnless(!frame_id.empty(), "Invalid DepthImage: frame_id must not be empty.");
  for (std::size_t i = 0; i < depth.size(); ++i) {
    const float d = depth[i];
    ThrowUnless(std::isnan(d) || (d >= 0.0f && std::isfinite(d)), "Invalid DepthImage: pixel (",
                i % std::size_t(width), ", ", i / std::size_t(width), ") depth (", d,
                ") must be >= 0 and finite, or NaN for no return.");
  }
}

void Detection2D::Validate() const {
  ThrowUnless(!label.empty(), "Invalid Detection2D: label must not be empty.");
  ThrowUnless(std::isfinite(confidence) && confidence >= 0.0 && confidence <= 1.0,
              "Invalid Detection2D '", label, "': confidence (", confidence,
              ") must be in [0, 1].");
  const bool finite = std::isfinite(box.u_min) && std::isfinite(box.v_min) &&
                      std::isfinite(box.u_max) && std::isfinite(box.v_max);
  ThrowUnless(finite && box.u_max >= box.u_min && box.v_max >= box.v_min, "Invalid Detection2D '",
              label, "': box (", box.u_min, ", ", box.v_min, ") – (", box.u_max, ", ", box.v_max,
              ") must be finite with min <= max.");
  ThrowUnless(!frame_id.empty(), "Invalid Detection2D '", label, "': frame_id must not be empty.");
}

void ColorImage::Validate() const {
  ThrowUnless(width > 0 && height > 0, "Invalid ColorImage: size ", width, "x", height,
              " must be positive.");
  ThrowUnless(bgr.size() == std::size_t(width) * std::size_t(height) * 3u,
              "Invalid ColorImage: ", bgr.size(), " bytes for ", width, "x", height,
              " BGR pixels (expected ", std::size_t(width) * std::size_t(height) * 3u, ").");
}

}  // namespace egress
