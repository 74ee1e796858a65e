#include "egress/twin/sensors.h"

#include <algorithm>
#include <cmath>

#include "egress/hsr_interface/error.h"
#include "egress/hsr_interface/frames.h"

namespace egress::twin {
namespace {
constexpr double kDegToRad = M_PI / 180.0;
const char* const kDetectorClasses[] = {"person",          "door",   "glass_door", "push_button",
                                        "proximity_plate", "bottle", "flashlight"};
}  // namespace

LaserSimulator::LaserSimulator(const SensorConfig& config) : config_(config) {
  ThrowUnless(config.laser_step_deg > 0 && config.laser_fov_deg > 0,
              "laser: fov and step must be positive");
  beams_ = std::size_t(std::floor(config.laser_fov_deg / config.laser_step_deg + 1e-9)) + 1;
  const double a0 = -config.laser_fov_deg / 2 * kDegToRad;
  for (std::size_t i = 0; i < beams_; ++i) {
    const double a = a0 + double(i) * config.laser_step_deg * kDegToRad;
    directions_L_.emplace_back(std::cos(a), std::sin(a), 0.0);
  }
}

LaserScan LaserSimulator::Capture(const TwinWorld& world, std::mt19937_64& rng) const {
  const Pose3 X_WL = Pose3::FromPose2(world.robot_pose()) * world.robot_model().laser_pose();
  LaserScan scan;
  scan.frame_id = std::string(frames::kLaser);
  scan.stamp = world.now();
  scan.angle_min = -config_.laser_fov_deg / 2 * kDegToRad;
  scan.angle_increment = config_.laser_step_deg * kDegToRad;
  scan.range_min = config_.laser_range_min;
  scan.range_max = config_.laser_range_max;
  scan.ranges.resize(beams_);
  std::normal_distribution<double> noise(0.0, config_.laser_noise);
  const double glass_incidence = config_.laser_glass_max_incidence_deg * kDegToRad;
  // The beams' ends, cast as one fan from the laser's origin (CastRayFan: CastRay's hits).
  thread_local std::vector<Eigen::Vector3d> ends;
  thread_local std::vector<RayHit> hits;
  ends.resize(beams_);
  for (std::size_t i = 0; i < beams_; ++i)
    ends[i] = X_WL * (directions_L_[i] * config_.laser_range_max);
  world.CastRayFan(X_WL.translation(), ends, GlassMode::kLaser, &hits, glass_incidence);
  for (std::size_t i = 0; i < beams_; ++i) {
    const RayHit& hit = hits[i];
    const double n = config_.laser_noise > 0 ? noise(rng) : 0.0;
    if (!hit.hit) {
      scan.ranges[i] = std::numeric_limits<float>::infinity();
    } else {
      const double r = hit.distance + n;
      scan.ranges[i] = r < config_.laser_range_min ? std::numeric_limits<float>::quiet_NaN()
                                                   : float(std::min(r, config_.laser_range_max));
    }
  }
  return scan;
}

DepthCameraSimulator::DepthCameraSimulator(const SensorConfig& config)
    : config_(config),
      intrinsics_(CameraIntrinsics::FromHorizontalFov(config.depth_width, config.depth_height,
                                                      config.depth_hfov_deg * kDegToRad)) {
  for (int v = 0; v < intrinsics_.height; ++v) {
    for (int u = 0; u < intrinsics_.width; ++u) {
      directions_C_.push_back(intrinsics_.Unproject(u + 0.5, v + 0.5, 1.0).normalized());
    }
  }
}

DepthImage DepthCameraSimulator::Capture(const TwinWorld& world, std::mt19937_64& rng) const {
  const Pose3 X_WC = world.head_camera_pose();
  DepthImage image;
  image.frame_id = std::string(frames::kHeadCamera);
  image.stamp = world.now();
  image.width = intrinsics_.width;
  image.height = intrinsics_.height;
  image.depth.resize(directions_C_.size());
  std::normal_distribution<double> unit(0.0, 1.0);
  // The pixels' rays, cast as one fan from the camera's origin (CastRayFan: CastRay's hits).
  thread_local std::vector<Eigen::Vector3d> ends;
  thread_local std::vector<RayHit> hits;
  ends.resize(directions_C_.size());
  for (std::size_t k = 0; k < directions_C_.size(); ++k) {
    const Eigen::Vector3d& d_C = directions_C_[k];
    ends[k] = X_WC * (d_C * (config_.depth_range_max / d_C.z()));
  }
  world.CastRayFan(X_WC.translation(), ends, GlassMode::kOpaque, &hits);
  for (std::size_t k = 0; k < directions_C_.size(); ++k) {
    const Eigen::Vector3d& d_C = directions_C_[k];
    const RayHit& hit = hits[k];
    if (!hit.hit || hit.glass) {
      image.depth[k] = std::numeric_limits<float>::quiet_NaN();
      continue;
    }
    const double z = hit.distance * d_C.z();
    const double sigma = config_.depth_noise_coeff * z * z;
    image.depth[k] = float(std::max(0.01, z + (sigma > 0 ? sigma * unit(rng) : 0.0)));
  }
  return image;
}

DetectorSimulator::DetectorSimulator(const SensorConfig& config, CameraIntrinsics intrinsics)
    : config_(config), intrinsics_(intrinsics) {}

std::optional<PixelBox> DetectorSimulator::Project(const DetectableObject& object,
                                                   const Pose3& X_WC) const {
  const Pose3 X_CW = X_WC.Inverse();
  PixelBox box{1e18, 1e18, -1e18, -1e18};
  int in_front = 0;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d corner_O((c & 1 ? 1 : -1) * object.half.x(),
                                   (c & 2 ? 1 : -1) * object.half.y(),
                                   (c & 4 ? 1 : -1) * object.half.z());
    Eigen::Vector3d p_C = X_CW * (object.X_WO * corner_O);
    if (p_C.z() < 0.05)
      p_C.z() = 0.05;  // clamp corners behind the image plane
    else
      ++in_front;
    const double u = intrinsics_.fx * p_C.x() / p_C.z() + intrinsics_.cx;
    const double v = intrinsics_.fy * p_C.y() / p_C.z() + intrinsics_.cy;
    box.u_min = std::min(box.u_min, u);
    box.v_min = std::min(box.v_min, v);
    box.u_max = std::max(box.u_max, u);
    box.v_max = std::max(box.v_max, v);
  }
  if (in_front == 0) return std::nullopt;
  box.u_min = std::clamp(box.u_min, 0.0, double(intrinsics_.width));
  box.u_max = std::clamp(box.u_max, 0.0, double(intrinsics_.width));
  box.v_min = std::clamp(box.v_min, 0.0, double(intrinsics_.height));
  box.v_max = std::clamp(box.v_max, 0.0, double(intrinsics_.height));
  if (box.width() < 1.0 || box.height() < 1.0) return std::nullopt;
  return box;
}

double DetectorSimulator::CalcVisibleFraction(const TwinWorld& world,
                                              const DetectableObject& object, const Pose3& X_WC,
                                              std::mt19937_64& rng) const {
  const int n = config_.detector_visibility_samples;
  std::uniform_real_distribution<double> unit(-0.9, 0.9);
  const Pose3 X_CW = X_WC.Inverse();
  // Rejection sampling: up to 4n points of the object's box, until n fall inside the image.
  int visible = 0, in_image = 0;
  for (int k = 0; k < 4 * n && in_image < n; ++k) {
    const Eigen::Vector3d p_W =
        object.X_WO * Eigen::Vector3d(unit(rng) * object.half.x(), unit(rng) * object.half.y(),
                                      unit(rng) * object.half.z());
    const Eigen::Vector3d p_C = X_CW * p_W;
    if (p_C.z() < 0.05) continue;
    const auto pix = intrinsics_.Project(p_C);
    if (!pix || pix->x() < 0 || pix->y() < 0 || pix->x() >= intrinsics_.width ||
        pix->y() >= intrinsics_.height) {
      continue;  // outside the image: truncation, not occlusion
    }
    ++in_image;
    // Through glass, unless the glass leaf is what we look at.
    const GlassMode mode =
        object.label == "glass_door" ? GlassMode::kOpaque : GlassMode::kTransparent;
    const Eigen::Vector3d to = X_WC.translation() + (p_W - X_WC.translation()) * 1.05;
    const RayHit hit = world.CastRay(X_WC.translation(), to, mode);
    if (hit.hit && hit.entity == object.entity) ++visible;
  }
  // Too few samples in the image to judge: treat as not visible.
  return in_image >= std::max(2, n / 4) ? double(visible) / in_image : 0.0;
}

std::vector<Detection2D> DetectorSimulator::Detect(const TwinWorld& world,
                                                   std::mt19937_64& rng) const {
  const Pose3 X_WC = world.head_camera_pose();
  std::vector<Detection2D> out;
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (const DetectableObject& object : world.DetectableObjects()) {
    const double distance = (object.X_WO.translation() - X_WC.translation()).norm();
    if (distance > config_.depth_range_max) continue;
    const auto box = Project(object, X_WC);
    if (!box) continue;
    const double visible = CalcVisibleFraction(world, object, X_WC, rng);
    if (visible < config_.detector_min_visible) continue;
    if (uniform(rng) < config_.detector_miss_rate) continue;
    const double distance_factor = std::clamp(1.0 - (distance - 3.0) / 11.0, 0.4, 1.0);
    double confidence = 0.92 * distance_factor * (0.6 + 0.4 * visible) * config_.detector_lighting +
                        0.03 * gauss(rng);
    confidence = std::clamp(confidence, 0.05, 0.99);
    Detection2D d;
    d.label = object.label;
    d.confidence = confidence;
    // A few per cent of jitter on the box edges, as a real detector's boxes have.
    const double ju = 0.02 * box->width(), jv = 0.02 * box->height();
    d.box = {std::clamp(box->u_min + ju * gauss(rng), 0.0, double(intrinsics_.width)),
             std::clamp(box->v_min + jv * gauss(rng), 0.0, double(intrinsics_.height)),
             std::clamp(box->u_max + ju * gauss(rng), 0.0, double(intrinsics_.width)),
             std::clamp(box->v_max + jv * gauss(rng), 0.0, double(intrinsics_.height))};
    if (d.box.u_max <= d.box.u_min || d.box.v_max <= d.box.v_min) d.box = *box;
    d.stamp = world.now();
    d.frame_id = std::string(frames::kHeadCamera);
    out.push_back(std::move(d));
  }
  if (uniform(rng) < config_.detector_false_positive_rate) {
    Detection2D fp;
    fp.label = kDetectorClasses[std::size_t(uniform(rng) * 7) % 7];
    fp.confidence = 0.25 + 0.2 * uniform(rng);
    const double w = intrinsics_.width, h = intrinsics_.height;
    const double u0 = uniform(rng) * w * 0.8, v0 = uniform(rng) * h * 0.8;
    fp.box = {u0, v0, std::min(w, u0 + 2 + uniform(rng) * w * 0.2),
              std::min(h, v0 + 2 + uniform(rng) * h * 0.2)};
    fp.stamp = world.now();
    fp.frame_id = std::string(frames::kHeadCamera);
    out.push_back(std::move(fp));
  }
  return out;
}

OdometrySimulator::OdometrySimulator(const SensorConfig& config, const Pose2& /*X_WB_start*/,
                                     std::mt19937_64& rng)
    : config_(config) {
  // One scale error per run (wheel radius, tyre wear): drift, not white noise.
  std::normal_distribution<double> n(0.0, config.odometry_noise);
  scale_ = 1.0 + (config.odometry_noise > 0 ? n(rng) : 0.0);
}

void OdometrySimulator::Integrate(const Twist2& V_B, double dt) {
  V_B_ = {V_B.vx * scale_, V_B.vy * scale_, V_B.wz * scale_ + config_.odometry_yaw_drift};
  if (V_B.vx == 0.0 && V_B.vy == 0.0 && V_B.wz == 0.0) V_B_ = Twist2{};  // no drift at rest
  X_OB_ = X_OB_ * Pose2{V_B_.vx * dt, V_B_.vy * dt, V_B_.wz * dt};
  distance_ += std::hypot(V_B_.vx, V_B_.vy) * dt + 0.2 * std::abs(V_B_.wz) * dt;
}

Odometry OdometrySimulator::Read(Time stamp) const {
  Odometry odom;
  odom.stamp = stamp;
  odom.X_OB = X_OB_;
  odom.V_B = V_B_;
  // Uncertainty grows with the distance travelled (1 % position, 0.5 % heading per metre).
  const double s_xy = 0.01 * distance_ + 1e-4, s_yaw = 0.005 * distance_ + 1e-4;
  odom.covariance = Eigen::Vector3d(s_xy * s_xy, s_xy * s_xy, s_yaw * s_yaw).asDiagonal();
  return odom;
}

}  // namespace egress::twin
