#pragma once
/// @file
/// Simulated sensors of the HSR, each a function of the twin's ground truth through Bullet ray
/// casts plus seeded noise: the base laser (frame L), the head depth camera (frame C), wheel
/// odometry with drift, and a detector standing in for YOLO that outputs exactly the
/// Detection2D a real detector would (boxes in the depth image's pixels).

#include <random>
#include <vector>

#include "egress/hsr_interface/geometry.h"
#include "egress/hsr_interface/robot_state_types.h"
#include "egress/hsr_interface/sensor_types.h"
#include "egress/twin/scenario.h"
#include "egress/twin/twin_world.h"

namespace egress::twin {

/// 2D laser: `fov_deg` wide, `step_deg` between beams, ranges with Gaussian noise; glass leaves
/// return only near normal incidence.
class LaserSimulator {
 public:
  explicit LaserSimulator(const SensorConfig& config);
  /// One sweep from the robot's current pose. Beams without a return read +inf.
  LaserScan Capture(const TwinWorld& world, std::mt19937_64& rng) const;
  std::size_t beam_count() const { return beams_; }

 private:
  SensorConfig config_;
  std::size_t beams_;
  std::vector<Eigen::Vector3d> directions_L_;  ///< Unit beam directions in L.
};

/// Head RGB-D depth by one ray per pixel; glass gives no valid depth (NaN).
class DepthCameraSimulator {
 public:
  explicit DepthCameraSimulator(const SensorConfig& config);
  DepthImage Capture(const TwinWorld& world, std::mt19937_64& rng) const;
  const CameraIntrinsics& intrinsics() const { return intrinsics_; }

 private:
  SensorConfig config_;
  CameraIntrinsics intrinsics_;
  std::vector<Eigen::Vector3d> directions_C_;  ///< Per-pixel unit ray directions in C.
};

/// The YOLO stand-in: projects the boxes of objects of the paper's classes into the camera,
/// keeps those visible enough (ray-cast samples), scores confidence from distance, visibility
/// and lighting, and adds misses and false positives.
class DetectorSimulator {
 public:
  DetectorSimulator(const SensorConfig& config, CameraIntrinsics intrinsics);
  /// Detections for an image captured now (stamped with the world's time).
  std::vector<Detection2D> Detect(const TwinWorld& world, std::mt19937_64& rng) const;
  /// Fraction of the ray-cast samples of `object` inside the image that the camera at X_WC
  /// sees unoccluded (0..1); 0 when too few samples fall inside the image.
  double CalcVisibleFraction(const TwinWorld& world, const DetectableObject& object,
                             const Pose3& X_WC, std::mt19937_64& rng) const;
  /// The object's 3D box projected into the image and clipped; nullopt if not in view.
  std::optional<PixelBox> Project(const DetectableObject& object, const Pose3& X_WC) const;

 private:
  SensorConfig config_;
  CameraIntrinsics intrinsics_;
};

/// Wheel odometry: integrates the base's true velocity with a per-run scale error and a
/// constant yaw-rate drift; pose in the odometry frame O (= W at the start pose).
class OdometrySimulator {
 public:
  OdometrySimulator(const SensorConfig& config, const Pose2& X_WB_start, std::mt19937_64& rng);
  /// Integrates one step of dt [s] with the true base velocity V_B.
  void Integrate(const Twist2& V_B, double dt);
  Odometry Read(Time stamp) const;

 private:
  SensorConfig config_;
  Pose2 X_OB_;
  Twist2 V_B_;
  double scale_;
  double distance_{0.0};
};

}  // namespace egress::twin
