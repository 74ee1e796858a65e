#include "egress/perception/world_state.h"

#include <limits>

#include "egress/hsr_interface/error.h"

namespace egress::perception {

PerceptionPipeline::PerceptionPipeline(std::vector<DoorModel> doors, PerceptionConfig config)
    : config_(std::move(config)), objects_(config_.objects), people_(config_.people) {
  for (auto& door : doors)
    doors_.emplace_back(std::move(door), config_.door_state);
}

void PerceptionPipeline::ProcessCameraFrame(const std::vector<Detection2D>& detections,
                                            cv::Size detection_image, const DepthImage& depth,
                                            const CameraIntrinsics& intrinsics, const Pose3& X_MC) {
  std::vector<PlacedDetection> placed;
  std::vector<Eigen::Vector2d> people;
  unplaced_glass_.clear();
  for (const Detection2D& detection : config_.confidence.Apply(detections)) {
    const auto p_MO =
        PlaceDetection(detection, detection_image, depth, intrinsics, X_MC, config_.placement);
    if (!p_MO) {
      if (detection.label == labels::kGlassDoor) unplaced_glass_.push_back(detection);
      continue;
    }
    if (detection.label == labels::kPerson) {
      people.push_back(p_MO->head<2>());
    } else {
      placed.push_back({detection, *p_MO});
    }
  }
  objects_.Update(placed, depth.stamp);
  people_.Update(people, depth.stamp);
}

void PerceptionPipeline::ProcessScan(const LaserScan& scan, const Pose2& X_ML,
                                     const CameraIntrinsics& intrinsics, const Pose3& X_LC) {
  // People are not door leaves: returns from around a tracked person never vote for an angle.
  std::vector<Eigen::Vector2d> points;
  for (const Eigen::Vector2d& p : ScanPoints(scan, X_ML)) {
    bool on_person = false;
    for (const auto& person : people_.people())
      on_person = on_person || (p - person.p_MP).norm() < config_.person_mask_radius;
    if (!on_person) points.push_back(p);
  }
  std::vector<bool> measured(doors_.size(), false);
  // Glass leaves: a line fit in the slice under each box, assigned to the nearest door.
  for (const Detection2D& box : unplaced_glass_) {
    const auto [lo, hi] = BoxBearingsInLaser(box.box, intrinsics, X_LC);
    const auto fit = FitLineRansac(ScanPointsInBearings(scan, X_ML, lo, hi), config_.glass_line);
    if (!fit) continue;
    std::size_t best = doors_.size();
    double best_distance = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < doors_.size(); ++i) {
      const double d = (fit->p_M - doors_[i].door().p_MHinge).norm();
      if (d < best_distance && d <= doors_[i].door().width() * 1.2) {
        best = i;
        best_distance = d;
      }
    }
    if (best == doors_.size()) continue;
    doors_[best].Update(DoorAngleFromLine(doors_[best].door(), *fit), scan.stamp);
    measured[best] = true;
  }
  for (std::size_t i = 0; i < doors_.size(); ++i) {
    if (measured[i]) continue;
    if (auto m = MeasureDoorAngle(doors_[i].door(), points)) doors_[i].Update(m->angle, scan.stamp);
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
  for (const auto& tracker : doors_) {
    world.doors.push_back({tracker.door(), tracker.state()});
    const DoorZone zone{tracker.door(), config_.door_zone_depth};
    world.door_zone_forecast[tracker.door().id] = ForecastZoneOccupancy(people_.people(), zone);
  }
  for (const auto& object : objects_.Confirmed()) {
    if (object.label == labels::kPushButton || object.label == labels::kProximityPlate)
      world.buttons.push_back(object);
    if (object.label == labels::kBottle || object.label == labels::kFlashlight)
      world.payloads.push_back(object);
  }
  for (const auto& person : people_.people()) {
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
