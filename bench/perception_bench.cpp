// Perception costs against the targets: costmap update from one 1081-beam scan
// (<= 0.5 ms), OctoMap insert of an 80x60 depth image (<= 2 ms), a localization update with 500
// particles (<= 2 ms), the pipeline per camera frame (<= 1 ms); people in a 1081-beam scan with
// ten people about (<= 0.5 ms, issue 21), and the pipeline's whole per-scan cost with them
// walking (detection, fused tracking, door angles); the costmap's proxemic layer for ten people,
// each now and at four predictions (the brain redraws it every tick, 10 Hz).

#include <benchmark/benchmark.h>

#include <numbers>

#include "egress/perception/costmap.h"
#include "egress/perception/laser_person_detector.h"
#include "egress/perception/occupancy_map_3d.h"
#include "egress/perception/particle_filter_localizer.h"
#include "egress/perception/world_state.h"
#include "synthetic.h"

namespace {

using namespace egress;
using namespace egress::perception;

void BM_CostmapUpdate1081BeamScan(benchmark::State& state) {
  const OccupancyGrid map = testing::TwoRoomMap();
  // Two scans from poses 5 cm and 2 degrees apart, alternating: like a moving robot, each
  // update flips the cells along the walls' edges and so recomputes their inflation.
  const Pose2 X_ML[2] = {{3.0, 3.0, 0.4}, {3.05, 3.0, 0.435}};
  LaserScan scans[2] = {testing::MakeScan(1081, 20.0), testing::MakeScan(1081, 20.0)};
  for (int i = 0; i < 2; ++i)
    testing::CastScan(map, X_ML[i], &scans[i]);
  // The walls are in the static layer; mark the scans' returns as obstacles too (a room with
  // furniture not on the map) by using an empty static map.
  Costmap2D unmapped(OccupancyGrid(map.geometry(), kFreeCost));
  int k = 0;
  for (auto _ : state) {
    unmapped.UpdateWithScan(scans[k], X_ML[k]);
    k = 1 - k;
  }
}
BENCHMARK(BM_CostmapUpdate1081BeamScan)->Unit(benchmark::kMicrosecond);

void BM_PersonalSpacesTenPeople(benchmark::State& state) {
  Costmap2D costmap(testing::TwoRoomMap());
  // Ten people walking at 1.2 m/s across the rooms, each now and 0.5..2 s ahead (weights as the
  // executive's), moved a little each call as between ticks.
  std::vector<PersonalSpace> spaces[2];
  for (int call = 0; call < 2; ++call)
    for (int person = 0; person < 10; ++person)
      for (int k = 0; k <= 4; ++k)
        spaces[call].push_back({{1.0 + 0.5 * person + 0.6 * k + 0.12 * call, 1.5 + 0.3 * person},
                                0.9,
                                1.7,
                                1.0 - k * 0.5 / 2.5});
  int call = 0;
  for (auto _ : state) {
    costmap.SetPersonalSpaces(spaces[call]);
    call = 1 - call;
  }
}
BENCHMARK(BM_PersonalSpacesTenPeople)->Unit(benchmark::kMicrosecond);

void BM_OctomapInsert80x60(benchmark::State& state) {
  const CameraIntrinsics K = CameraIntrinsics::FromHorizontalFov(80, 60, 1.047);
  const Pose3 X_MC =
      Pose3::FromXyzRpy({0.0, 0.0, 1.0}, {-std::numbers::pi / 2 - 0.3, 0.0, -std::numbers::pi / 2});
  // A room 3 m ahead seen slightly downward: floor and a wall, every pixel valid.
  DepthImage depth;
  depth.width = 80;
  depth.height = 60;
  depth.depth.resize(80 * 60);
  for (int v = 0; v < 60; ++v) {
    for (int u = 0; u < 80; ++u) {
      const Eigen::Vector3d ray = X_MC.rotation() * K.Unproject(u + 0.5, v + 0.5, 1.0);
      const double to_wall = 3.0 / ray.x();
      const double to_floor = ray.z() < 0 ? -1.0 / ray.z() : 1e9;
      depth.depth[std::size_t(v * 80 + u)] = float(std::min(to_wall, to_floor));
    }
  }
  OccupancyMap3D map;
  for (auto _ : state)
    benchmark::DoNotOptimize(map.InsertDepthImage(depth, K, X_MC));
}
BENCHMARK(BM_OctomapInsert80x60)->Unit(benchmark::kMicrosecond);

void BM_LocalizationUpdate500Particles(benchmark::State& state) {
  const OccupancyGrid map = testing::TwoRoomMap();
  ParticleFilterLocalizer localizer(map, {0.1675, 0.0, 0.0});
  localizer.Initialize({3.0, 3.0, 0.4}, Eigen::Vector3d(0.01, 0.01, 0.003).asDiagonal());
  LaserScan scan = testing::MakeScan(1081, 20.0);
  testing::CastScan(map, Pose2{3.0, 3.0, 0.4} * Pose2{0.1675, 0.0, 0.0}, &scan);
  Pose2 odometry{0, 0, 0};
  for (auto _ : state) {
    const Pose2 next = odometry * Pose2{0.03, 0.0, 0.0};  // moved enough to correct every time
    localizer.Predict(odometry, next);
    benchmark::DoNotOptimize(localizer.Correct(scan));
    odometry = next;
  }
}
BENCHMARK(BM_LocalizationUpdate500Particles)->Unit(benchmark::kMicrosecond);

void BM_PipelinePerCameraFrame(benchmark::State& state) {
  const DoorModel door{"lab", {6.0, 3.5}, {6.0, 4.5}, -1.0, std::numbers::pi / 2};
  PerceptionPipeline pipeline({door});
  const CameraIntrinsics K = CameraIntrinsics::FromHorizontalFov(80, 60, 1.047);
  const Pose3 X_MC =
      Pose3::FromXyzRpy({4.0, 4.0, 1.0}, {-std::numbers::pi / 2, 0.0, -std::numbers::pi / 2});
  DepthImage depth;
  depth.width = 80;
  depth.height = 60;
  depth.depth.assign(80 * 60, 1.8f);
  const std::vector<Detection2D> detections = {
      {"push_button", 0.9, {300, 200, 330, 230}, Time{0}},
      {"person", 0.8, {380, 100, 440, 400}, Time{0}},
      {"door", 0.85, {100, 50, 300, 450}, Time{0}},
      {"bottle", 0.7, {500, 300, 520, 340}, Time{0}},
      {"person", 0.6, {20, 100, 80, 400}, Time{0}},
      {"proximity_plate", 0.75, {560, 200, 600, 240}, Time{0}}};
  std::int64_t frame = 0;
  for (auto _ : state) {
    depth.stamp = std::chrono::milliseconds(125 * frame++);
    pipeline.ProcessCameraFrame(detections, {640, 480}, depth, K, X_MC);
    benchmark::DoNotOptimize(
        pipeline.Snapshot(depth.stamp, {4.0, 4.0, 0.0}, Eigen::Matrix3d::Identity()));
  }
}
BENCHMARK(BM_PipelinePerCameraFrame)->Unit(benchmark::kMicrosecond);

void BM_DoorAnglesPerScan(benchmark::State& state) {
  const DoorModel door{"lab", {6.0, 3.5}, {6.0, 4.5}, -1.0, std::numbers::pi / 2};
  PerceptionPipeline pipeline({door});
  const OccupancyGrid map = testing::TwoRoomMap();
  LaserScan scan = testing::MakeScan(1081, 20.0);
  testing::CastScan(map, {8.0, 4.0, std::numbers::pi}, &scan);
  const CameraIntrinsics K = CameraIntrinsics::FromHorizontalFov(80, 60, 1.047);
  std::int64_t n = 0;
  for (auto _ : state) {
    scan.stamp = std::chrono::milliseconds(25 * n++);
    pipeline.ProcessScan(scan, {8.0, 4.0, std::numbers::pi}, K, Pose3());
  }
}
BENCHMARK(BM_DoorAnglesPerScan)->Unit(benchmark::kMicrosecond);

void BM_LaserPeoplePerScan(benchmark::State& state) {
  // Ten people round the robot in the two-room map: five as leg pairs, five as body sections
  // (the twin's capsules); the walls are the costmap's mapped obstacles, left out as background.
  const OccupancyGrid map = testing::TwoRoomMap();
  const Costmap2D costmap(map);
  const Pose2 X_ML{3.0, 4.0, 0.3};
  std::vector<testing::Disc> discs;
  for (int i = 0; i < 10; ++i) {
    // On a 1.5 m circle across the laser's 270 degrees, clear of each other and the furniture.
    const double angle = X_ML.yaw - 2.1 + 0.466 * i;
    const Eigen::Vector2d c =
        X_ML.translation() + 1.5 * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    if (i % 2 == 0) {
      const Eigen::Vector2d side(-std::sin(angle), std::cos(angle));
      discs.push_back({c + 0.15 * side, 0.06});
      discs.push_back({c - 0.15 * side, 0.06});
    } else {
      discs.push_back({c, 0.23});
    }
  }
  LaserScan scan = testing::MakeScan(1081, 20.0);
  testing::CastScanAtDiscs(discs, X_ML, &scan, &map);
  const LaserPersonDetector detector;
  const auto background = [&](const Eigen::Vector2d& p) {
    return costmap.IsNearMappedObstacle(p, 0.15);
  };
  std::size_t found = 0;
  for (auto _ : state) {
    const auto people = detector.Detect(scan, X_ML, background);
    found = people.size();
    benchmark::DoNotOptimize(people.data());
  }
  state.counters["people"] = double(found);
}
BENCHMARK(BM_LaserPeoplePerScan)->Unit(benchmark::kMicrosecond);

void BM_PipelinePerScanTenWalkers(benchmark::State& state) {
  // The whole per-scan cost of laser people in the brain (PerceptionConfig::laser_people, the
  // default): detection, the fused tracker (association, static spots, confirmation) and the door
  // angles, with ten people across the laser's 270 degrees walking away from the robot at 1 m/s,
  // from 1.5 m to 4 m — 25 scans (2.5 s at 10 Hz) cast once, then replayed there and back with
  // advancing stamps.
  const OccupancyGrid map = testing::TwoRoomMap();
  const Costmap2D costmap(map);
  const Pose2 X_ML{3.0, 4.0, 0.3};
  constexpr int kScans = 25;
  constexpr double kScanPeriodSec = 0.1, kStartM = 1.5, kWalkMps = 1.0;
  std::vector<LaserScan> scans;
  for (int s = 0; s < kScans; ++s) {
    std::vector<testing::Disc> discs;
    for (int i = 0; i < 10; ++i) {
      const double angle = X_ML.yaw - 2.1 + 0.466 * i;
      const double range = kStartM + kWalkMps * kScanPeriodSec * s;
      const Eigen::Vector2d c =
          X_ML.translation() + range * Eigen::Vector2d(std::cos(angle), std::sin(angle));
      discs.push_back({c, 0.23});
    }
    scans.push_back(testing::MakeScan(1081, 20.0));
    testing::CastScanAtDiscs(discs, X_ML, &scans.back(), &map);
  }
  PerceptionPipeline pipeline({});
  const CameraIntrinsics K = CameraIntrinsics::FromHorizontalFov(80, 60, 1.047);
  const auto background = [&](const Eigen::Vector2d& p) {
    return costmap.IsNearMappedObstacle(p, 0.15);
  };
  std::int64_t n = 0;
  for (auto _ : state) {
    // There and back (a jump back to the first scan would start every track anew).
    const std::int64_t k = n % (2 * kScans - 2);
    LaserScan& scan = scans[std::size_t(k < kScans ? k : 2 * kScans - 2 - k)];
    scan.stamp = std::chrono::milliseconds(100 * n++);
    pipeline.ProcessScan(scan, X_ML, K, Pose3(), background);
  }
  state.counters["people"] = double(pipeline.fused_people().ConfirmedPeople().size());
  state.counters["spots"] = double(pipeline.fused_people().spots().size());
}
BENCHMARK(BM_PipelinePerScanTenWalkers)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
