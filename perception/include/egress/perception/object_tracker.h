#pragma once
/// @file
/// From 2D boxes to tracked objects in the map: 3D placement through the depth image, then
/// tracking across frames by association at nearby positions. A track is confirmed after
/// `confirm_hits` consecutive hits (so a one-frame false positive never reaches the behavior
/// tree) and dropped after `drop_misses` consecutive misses (so one missed frame does not lose a
/// real object).

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "egress/hsr_interface/geometry.h"
#include "egress/hsr_interface/sensor_types.h"

namespace egress::perception {

struct PlacementConfig {
  double center_fraction{0.5};  ///< Depths are taken from this central fraction of the box.
  int min_valid_pixels{3};      ///< Fewer valid depths: not placed (e.g. a glass door).
  /// Fewer valid depths than this share of the central region: not placed by depth. A person
  /// seen through a glass leaf has no depth; the few valid pixels in the box are the door's
  /// frame, metres nearer, and placed them in the doorway.
  double min_valid_fraction{0.25};
  double max_depth{8.0};  ///< Farther depths are ignored [m].
};

/// Places a person's detection in M without depth, by the box's height in the image and a
/// person's height `person_height` [m] (pinhole: distance = fy * height / box height): for a
/// person behind glass. nullopt when the box touches the image's top or bottom edge (cut off,
/// its height says nothing) or is degenerate. @throws InvalidArgument as PlaceDetection.
std::optional<Eigen::Vector3d> PlacePersonBySize(const Detection2D& detection,
                                                 cv::Size detection_image,
                                                 const CameraIntrinsics& intrinsics,
                                                 const Pose3& X_MC, double person_height);

/// Places a detection in M: the median of the valid depths in the box's central region,
/// unprojected at the box centre, transformed by X_MC. `detection_image` is the size of the
/// image the box refers to (scaled to the depth image). nullopt when too few depths are valid.
/// @throws InvalidArgument for mismatched image/intrinsics or a non-finite pose.
std::optional<Eigen::Vector3d> PlaceDetection(const Detection2D& detection,
                                              cv::Size detection_image, const DepthImage& depth,
                                              const CameraIntrinsics& intrinsics, const Pose3& X_MC,
                                              const PlacementConfig& config = {});

struct PlacedDetection {
  Detection2D detection;
  Eigen::Vector3d p_MO;  ///< Object position in M [m].
};

struct TrackedObject {
  int id{0};
  std::string label;
  Eigen::Vector3d p_MO{Eigen::Vector3d::Zero()};
  double confidence{0.0};  ///< Smoothed detector confidence.
  int hits{0};             ///< Consecutive frames with a match.
  int misses{0};           ///< Consecutive frames without one.
  bool confirmed{false};
  Time last_seen{};
};

struct ObjectTrackerConfig {
  double gate_distance{0.4};  ///< Max distance for a detection to match a track [m].
  int confirm_hits{3};
  int drop_misses{3};
  double smoothing{0.5};  ///< Weight of a new measurement in the position average.
  void Validate() const;
};

class ObjectTracker {
 public:
  explicit ObjectTracker(ObjectTrackerConfig config = {});
  /// One frame's placed detections (all labels). Each track matches at most one detection of its
  /// label, nearest first within the gate; unmatched detections start tentative tracks.
  void Update(const std::vector<PlacedDetection>& detections, Time stamp);
  const std::vector<TrackedObject>& tracks() const { return tracks_; }
  /// Confirmed tracks, optionally of one label.
  std::vector<TrackedObject> Confirmed(const std::string& label = "") const;

 private:
  ObjectTrackerConfig config_;
  std::vector<TrackedObject> tracks_;
  int next_id_{1};
};

}  // namespace egress::perception
