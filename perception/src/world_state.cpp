#include "egress/perception/world_state.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "egress/hsr_interface/error.h"
#include "egress/hsr_interface/geometry.h"

namespace egress::perception {

PerceptionPipeline::PerceptionPipeline(std::vector<DoorModel> doors, PerceptionConfig config)
    : config_(std::move(config)),
      objects_(config_.objects),
      people_(config_.people),
      laser_detector_(config_.laser_detector),
      fused_(config_.fused_people),
      laser_motion_(config_.laser_motion) {
  for (auto& door : doors)
    doors_.emplace_back(std::move(door), config_.door_state);
}

// A standing adult's height, for placing a person seen without depth [m].
constexpr double kPersonHeightM = 1.7;

void PerceptionPipeline::ProcessCameraFrame(const std::vector<Detection2D>& detections,
                                            cv::Size detection_image, const DepthImage& depth,
                                            const CameraIntrinsics& intrinsics, const Pose3& X_MC,
                                            const std::optional<Pose3>& X_MC_detections) {
  std::vector<PlacedDetection> placed;
  std::vector<Eigen::Vector2d> people;
  glass_boxes_.clear();
  glass_image_width_ = detection_image.width;
  glass_X_MC_ = X_MC_detections.value_or(X_MC);
  for (const Detection2D& detection : config_.confidence.Apply(detections)) {
    // Glass leaves go to the door-angle estimate of the next scan: their depth is invalid, and
    // what depth there is under the box is the room behind.
    if (detection.label == labels::kGlassDoor) {
      glass_boxes_.push_back(detection);
      continue;
    }
    auto p_MO =
        PlaceDetection(detection, detection_image, depth, intrinsics, X_MC, config_.placement);
    // No depth under a person (seen through glass): by the box's height instead. Depth far
    // nearer than the box's height says is something in front of them (a door leaf they stand
    // behind, seen past its edge): by the height too. The margins keep a seated person (a
    // wheelchair user is ~1.3 m tall: 1.3x farther by height) placed by depth.
    if (detection.label == labels::kPerson) {
      const auto by_size =
          PlacePersonBySize(detection, detection_image, intrinsics, X_MC, kPersonHeightM);
      constexpr double kOccluderRatio = 1.5, kOccluderGapM = 0.75;
      const auto range = [&](const Eigen::Vector3d& p) {
        return (p - X_MC.translation()).head<2>().norm();
      };
      if (!p_MO || (by_size && range(*by_size) > kOccluderRatio * range(*p_MO) &&
                    range(*by_size) - range(*p_MO) > kOccluderGapM)) {
        p_MO = by_size;
      }
      // Depth on an open leaf is the leaf's, whatever the box says: the person stands behind
      // it, and a box cut by the image's edge has no height to place them by (office seed 87:
      // a resident 2 m past door_a, seen past its open leaf, became a "person" standing on the
      // leaf's tip, in the door's zone, and the robot stopped in the doorway for good).
      if (p_MO && IsOnAnOpenLeaf(p_MO->head<2>())) p_MO = by_size;
    }
    if (!p_MO) continue;
    if (detection.label == labels::kPerson) {
      people.push_back(p_MO->head<2>());
    } else {
      placed.push_back({detection, *p_MO});
    }
  }
  objects_.Update(placed, depth.stamp);
  people_.Update(people, depth.stamp);
  if (config_.laser_people) {
    // Which tracks the camera should have seen: ahead of it within its field of view and reach.
    const Eigen::Vector3d forward_M = X_MC.rotation().col(2);
    const double yaw = std::atan2(forward_M.y(), forward_M.x());
    const double half_fov = std::atan2(intrinsics.width / 2.0, intrinsics.fx);
    const Eigen::Vector2d p_MC = X_MC.translation().head<2>();
    const double range = config_.camera_people_range;
    std::vector<PersonObservation> observations;
    for (const auto& p : people)
      observations.push_back({p, PersonSource::kCamera});
    // A frame older than the tracker accepts (a depth image held through a camera outage) is
    // left out of the fusion rather than refused.
    if (ToSeconds(fused_.now() - depth.stamp) > config_.fused_people.max_latency_s) return;
    fused_.Update(observations, depth.stamp, [&](const Eigen::Vector2d& p) {
      const Eigen::Vector2d d = p - p_MC;
      return d.norm() < range && std::abs(WrapAngle(std::atan2(d.y(), d.x()) - yaw)) < half_fov;
    });
  }
}

bool PerceptionPipeline::IsOnAnOpenLeaf(const Eigen::Vector2d& p_MQ) const {
  // [m] Half a leaf's thickness and the depth camera's noise at a few metres.
  constexpr double kOnLeafM = 0.1;
  for (const auto& tracker : doors_) {
    const DoorState& state = tracker.state();
    if (!state.observed || state.angle < config_.door_state.closed_angle) continue;
    const DoorModel& door = tracker.door();
    const Eigen::Vector2d q = ClosestPointOnSegment(p_MQ, door.p_MHinge, door.LeafTip(state.angle));
    if ((p_MQ - q).norm() < kOnLeafM) return true;
  }
  return false;
}

std::vector<TrackedPerson> PerceptionPipeline::CurrentPeople() const {
  return config_.laser_people ? fused_.ConfirmedPeople() : people_.people();
}

void PerceptionPipeline::ProcessScan(
    const LaserScan& scan, const Pose2& X_ML, const CameraIntrinsics& intrinsics, const Pose3& X_LC,
    const std::function<bool(const Eigen::Vector2d&)>& is_background) {
  if (config_.laser_people) {
    std::vector<PersonObservation> observations;
    // A cluster on a straight line through a door's hinge, within the leaf's reach, is the leaf
    // (its angle estimate may lag a moving leaf, so it is not yet background); a person's legs
    // or body are arcs, never on such a line.
    const auto is_leaf = [this](const std::vector<Eigen::Vector2d>& points) {
      constexpr double kLeafReachMarginM = 0.1,
                       kLeafLineToleranceM = 0.05;  // a leaf is ~4 cm thick
      for (const auto& tracker : doors_) {
        const DoorModel& door = tracker.door();
        const Eigen::Vector2d& h = door.p_MHinge;
        const Eigen::Vector2d far = (points.front() - h).norm() > (points.back() - h).norm()
                                        ? points.front()
                                        : points.back();
        if ((far - h).norm() < 1e-6) continue;
        const Eigen::Vector2d along = (far - h).normalized();
        bool on_leaf = true;
        for (const auto& p : points) {
          const Eigen::Vector2d d = p - h;
          const double off_line = std::abs(along.x() * d.y() - along.y() * d.x());
          if (d.norm() > door.width() + kLeafReachMarginM || off_line > kLeafLineToleranceM) {
            on_leaf = false;
            break;
          }
        }
        if (on_leaf) return true;
      }
      return false;
    };
    laser_motion_.AddScan(scan, X_ML);
    // Whether a detection moved is judged on the returns about it: its legs (or body section),
    // a margin past them, and at least a stride round its centre, so that a walker's swinging
    // leg counts when the detector took only the planted one (escorts, 6 trials each: walkers'
    // detections read still in 3.1 % / 5.6 % of scans with the robot moving / still, against
    // 4.1 % / 5.3 % judged on their own returns).
    constexpr double kMotionPlaceMarginM = 0.1, kMotionPlaceMinRadiusM = 0.35;
    for (const auto& d : laser_detector_.Detect(scan, X_ML, is_background, is_leaf))
      observations.push_back(
          {d.p_MP, PersonSource::kLaser, d.at_edge,
           laser_motion_.Judge(d.p_MP,
                               std::max(kMotionPlaceMinRadiusM, d.radius + kMotionPlaceMarginM))});
    // The laser covers its 270 degrees out to the detector's reach.
    const double reach = config_.laser_detector.max_range;
    fused_.Update(observations, scan.stamp, [&](const Eigen::Vector2d& p) {
      const Eigen::Vector2d d = X_ML.Inverse() * p;
      const double bearing = std::atan2(d.y(), d.x());
      return d.norm() < reach && bearing >= scan.angle_min && bearing <= scan.angle_max();
    });
  }
  // People are not door leaves: returns from around a tracked person never vote for an angle.
  const std::vector<TrackedPerson> tracked = CurrentPeople();
  std::vector<Eigen::Vector2d> points;
  for (const Eigen::Vector2d& p : ScanPoints(scan, X_ML)) {
    bool on_person = false;
    for (const auto& person : tracked)
      on_person = on_person || (p - person.p_MP).norm() < config_.person_mask_radius;
    if (!on_person) points.push_back(p);
  }
  std::vector<bool> measured(doors_.size(), false);
  // Glass leaves: a line fit in the slice under each box, assigned to the nearest door.
  for (const Detection2D& box : glass_boxes_) {
    const auto [lo, hi] = BoxBearingsInLaser(box.box, intrinsics, X_LC);
    const auto fit = FitLineRansac(ScanPointsInBearings(scan, X_ML, lo, hi), config_.glass_line);
    // The door whose leaf the line can be (through its hinge, on its swing side), nearest.
    std::size_t best = doors_.size();
    std::optional<double> line_angle;
    double best_distance = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; fit && i < doors_.size(); ++i) {
      const double d = (fit->p_M - doors_[i].door().p_MHinge).norm();
      const auto a = DoorAngleFromLine(doors_[i].door(), *fit);
      if (a && d < best_distance) {
        best = i;
        best_distance = d;
        line_angle = a;
      }
    }
    if (line_angle) {
      doors_[best].Update(*line_angle, scan.stamp);
      measured[best] = true;
      continue;
    }
    // No leaf line (an open glass leaf is seen edge-on, beyond the laser's incidence limit): the
    // box's edges against the leaf's projection, for the door that explains them best. The box
    // is from the camera's pose when the image was taken (the detector's latency), not now.
    const Eigen::Matrix3d& R_MC = glass_X_MC_.rotation();
    const Eigen::Vector3d forward_M = R_MC.col(2);
    const Pose2 X_MV{glass_X_MC_.translation().x(), glass_X_MC_.translation().y(),
                     std::atan2(forward_M.y(), forward_M.x())};
    const double v = (box.box.v_min + box.box.v_max) / 2;
    const auto edge = [&](double u) {
      const Eigen::Vector3d ray_M =
          R_MC * Eigen::Vector3d((u - intrinsics.cx) / intrinsics.fx,
                                 (v - intrinsics.cy) / intrinsics.fy, 1.0);
      return WrapAngle(std::atan2(ray_M.y(), ray_M.x()) - X_MV.yaw);
    };
    constexpr double kBorderPx = 4.0;  // an edge this near the border may be cut
    std::optional<double> at_u_min, at_u_max;
    if (box.box.u_min > kBorderPx) at_u_min = edge(box.box.u_min);
    if (box.box.u_max < glass_image_width_ - kBorderPx) at_u_max = edge(box.box.u_max);
    const bool u_min_is_lo = edge(box.box.u_min) < edge(box.box.u_max);
    const std::optional<double> box_lo = u_min_is_lo ? at_u_min : at_u_max;
    const std::optional<double> box_hi = u_min_is_lo ? at_u_max : at_u_min;
    std::optional<double> angle;
    for (std::size_t i = 0; i < doors_.size(); ++i) {
      if (measured[i]) continue;
      if (const auto a = DoorAngleFromBearings(doors_[i].door(), X_MV, box_lo, box_hi)) {
        if (!angle) best = i;  // the first door that explains the box; boxes rarely fit two
        angle = angle ? angle : a;
      }
    }
    if (best == doors_.size() || !angle) continue;
    doors_[best].Update(*angle, scan.stamp);
    measured[best] = true;
  }
  for (std::size_t i = 0; i < doors_.size(); ++i) {
    if (measured[i]) continue;
    if (auto m = MeasureDoorAngle(doors_[i].door(), points)) {
      doors_[i].Update(m->angle, scan.stamp);
    }
  }
}

WorldState PerceptionPipeline::Snapshot(Time stamp, const Pose2& X_MB,
                                        const Eigen::Matrix3d& X_MB_covariance,
                                        const Costmap2D* costmap,
                                        std::shared_ptr<const octomap::OcTree> octree) const {
  WorldState world;
  world.stamp = stamp;
  world.X_MB = X_MB;
  world.X_MB_covariance = X_MB_covariance;
  world.costmap = costmap;
  world.octree = std::move(octree);
  const std::vector<TrackedPerson> people = CurrentPeople();
  for (const auto& tracker : doors_) {
    world.doors.push_back({tracker.door(), tracker.state(), tracker.IsStaleAt(stamp)});
    const DoorZone zone{tracker.door(), config_.door_zone_depth};
    world.door_zone_forecast[tracker.door().id] = ForecastZoneOccupancy(people, zone);
  }
  for (const auto& object : objects_.Confirmed()) {
    if (object.label == labels::kPushButton || object.label == labels::kProximityPlate)
      world.buttons.push_back(object);
    if (object.label == labels::kBottle || object.label == labels::kFlashlight)
      world.payloads.push_back(object);
  }
  for (const auto& person : people) {
    TrackedPersonWithIntent entry{person, PersonIntent::kUnknown, ""};
    double best = std::numeric_limits<double>::infinity();
    for (const auto& tracker : doors_) {
      const DoorModel& door = tracker.door();
      const double d = (person.p_MP - (door.p_MHinge + door.p_MLatch) / 2).norm();
      if (d < best) {
        best = d;
        entry.door_id = door.id;
        entry.intent = ClassifyIntent(person, {door, config_.door_zone_depth}, tracker.state(),
                                      config_.intent);
      }
    }
    world.people.push_back(std::move(entry));
  }
  return world;
}

}  // namespace egress::perception
