#include "egress/perception/object_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "egress/hsr_interface/error.h"
#include "nearest_first_association.h"

namespace egress::perception {

std::optional<Eigen::Vector3d> PlaceDetection(const Detection2D& detection,
                                              cv::Size detection_image, const DepthImage& depth,
                                              const CameraIntrinsics& intrinsics, const Pose3& X_MC,
                                              const PlacementConfig& config) {
  detection.Validate();
  ThrowUnless(depth.width == intrinsics.width && depth.height == intrinsics.height,
              "Invalid depth image: ", depth.width, "x", depth.height,
              " does not match its intrinsics ", intrinsics.width, "x", intrinsics.height, ".");
  ThrowUnless(depth.depth.size() == std::size_t(depth.width) * std::size_t(depth.height),
              "Invalid depth image: pixel count does not match width*height.");
  ThrowUnless(detection_image.width > 0 && detection_image.height > 0,
              "Invalid detection image size.");
  ThrowUnless(X_MC.IsFinite(), "Invalid camera pose X_MC: must be finite.");
  const double sx = double(depth.width) / detection_image.width,
               sy = double(depth.height) / detection_image.height;
  const PixelBox& b = detection.box;
  const double cu = (b.u_min + b.u_max) / 2 * sx, cv_ = (b.v_min + b.v_max) / 2 * sy;
  const double hw = b.width() * sx * config.center_fraction / 2,
               hh = b.height() * sy * config.center_fraction / 2;
  std::vector<float> depths;
  int pixels = 0;
  for (int v = int(std::floor(cv_ - hh)); v <= int(std::ceil(cv_ + hh)); ++v) {
    for (int u = int(std::floor(cu - hw)); u <= int(std::ceil(cu + hw)); ++u) {
      ++pixels;
      if (depth.IsValidAt(u, v) && depth.At(u, v) <= config.max_depth)
        depths.push_back(depth.At(u, v));
    }
  }
  if (int(depths.size()) < config.min_valid_pixels ||
      double(depths.size()) < config.min_valid_fraction * pixels) {
    return std::nullopt;
  }
  auto middle = depths.begin() + std::ptrdiff_t(depths.size() / 2);
  std::nth_element(depths.begin(), middle, depths.end());
  return X_MC * intrinsics.Unproject(cu, cv_, *middle);
}

std::optional<Eigen::Vector3d> PlacePersonBySize(const Detection2D& detection,
                                                 cv::Size detection_image,
                                                 const CameraIntrinsics& intrinsics,
                                                 const Pose3& X_MC, double person_height) {
  detection.Validate();
  ThrowUnless(detection_image.width > 0 && detection_image.height > 0,
              "Invalid detection image size.");
  ThrowUnless(X_MC.IsFinite(), "Invalid camera pose X_MC: must be finite.");
  ThrowUnless(person_height > 0.0, "Invalid person height: must be > 0.");
  const PixelBox& b = detection.box;
  if (b.v_min <= 1.0 || b.v_max >= detection_image.height - 1.0) return std::nullopt;
  // In the camera's pixels (the intrinsics' image), as the depth placement does.
  const double sx = double(intrinsics.width) / detection_image.width,
               sy = double(intrinsics.height) / detection_image.height;
  const double box_height = b.height() * sy;
  if (!(box_height > 1.0)) return std::nullopt;
  const double distance = intrinsics.fy * person_height / box_height;
  const double cu = (b.u_min + b.u_max) / 2 * sx, cv_ = (b.v_min + b.v_max) / 2 * sy;
  return X_MC * intrinsics.Unproject(cu, cv_, distance);
}

void ObjectTrackerConfig::Validate() const {
  ThrowUnless(gate_distance > 0.0, "Invalid ObjectTrackerConfig: gate_distance must be > 0.");
  ThrowUnless(confirm_hits >= 1 && drop_misses >= 1,
              "Invalid ObjectTrackerConfig: confirm_hits and drop_misses must be >= 1.");
  ThrowUnless(smoothing > 0.0 && smoothing <= 1.0,
              "Invalid ObjectTrackerConfig: smoothing must be in (0, 1].");
}

ObjectTracker::ObjectTracker(ObjectTrackerConfig config) : config_(config) {
  config_.Validate();
}

void ObjectTracker::Update(const std::vector<PlacedDetection>& detections, Time stamp) {
  for (const auto& d : detections) {
    ThrowUnless(d.p_MO.allFinite(), "Invalid placed detection '", d.detection.label,
                "': position must be finite.");
  }
  // Greedy association by distance: all (track, detection) pairs within the gate, nearest first.
  const internal::Association match = internal::AssociateNearestFirst(
      tracks_.size(), detections.size(), config_.gate_distance, [&](std::size_t t, std::size_t k) {
        return detections[k].detection.label == tracks_[t].label
                   ? (detections[k].p_MO - tracks_[t].p_MO).norm()
                   : std::numeric_limits<double>::infinity();
      });
  const std::vector<bool>& track_used = match.track_matched;
  const std::vector<bool>& detection_used = match.detection_matched;
  for (const auto& [t, k] : match.pairs) {
    TrackedObject& track = tracks_[t];
    track.p_MO += config_.smoothing * (detections[k].p_MO - track.p_MO);
    track.confidence += config_.smoothing * (detections[k].detection.confidence - track.confidence);
    ++track.hits;
    track.misses = 0;
    track.last_seen = stamp;
    if (track.hits >= config_.confirm_hits) track.confirmed = true;
  }
  for (std::size_t t = 0; t < tracks_.size(); ++t) {
    if (track_used[t]) continue;
    tracks_[t].hits = 0;
    ++tracks_[t].misses;
  }
  std::erase_if(tracks_, [&](const TrackedObject& track) {
    // A tentative track dies at its first miss; a confirmed one after drop_misses.
    return (!track.confirmed && track.misses > 0) || track.misses >= config_.drop_misses;
  });
  for (std::size_t k = 0; k < detections.size(); ++k) {
    if (detection_used[k]) continue;
    TrackedObject track;
    track.id = next_id_++;
    track.label = detections[k].detection.label;
    track.p_MO = detections[k].p_MO;
    track.confidence = detections[k].detection.confidence;
    track.hits = 1;
    track.last_seen = stamp;
    track.confirmed = config_.confirm_hits <= 1;
    tracks_.push_back(track);
  }
}

std::vector<TrackedObject> ObjectTracker::Confirmed(const std::string& label) const {
  std::vector<TrackedObject> out;
  for (const auto& track : tracks_) {
    if (track.confirmed && (label.empty() || track.label == label)) out.push_back(track);
  }
  return out;
}

}  // namespace egress::perception
