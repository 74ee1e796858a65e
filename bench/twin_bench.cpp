// Timed command: real-time factor of a headless twin run of the office world with every sensor
// at its default rate, and the wall-clock cost of each sensor per simulated second.
//   twin_bench [SCENARIO] [SECONDS]   (default: worlds/office/office_evacuation.yaml, 60 s)
// Writes twin_bench.json next to the working directory.

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "egress/twin/sdf_world_loader.h"
#include "egress/twin/twin_run.h"

int main(int argc, char** argv) {
  using namespace egress;
  const std::string scenario_path =
      argc > 1 ? argv[1] : EGRESS_WORLDS_DIR "/office/office_evacuation.yaml";
  const double seconds = argc > 2 ? std::stod(argv[2]) : 60.0;
  const twin::Scenario scenario = twin::LoadScenario(scenario_path);
  const twin::WorldDescription world_description = twin::LoadSdfWorld(scenario.world_file);
  auto model = std::make_shared<const RobotModel>(RobotModel::LoadDefault());

  auto run = [&](bool sensors_on, bool measure) {
    twin::Scenario s = scenario;
    if (!sensors_on) {  // physics, people and doors only
      s.sensors.laser_rate_hz = s.sensors.depth_rate_hz = s.sensors.detector_rate_hz = 1e-6;
    }
    twin::TwinWorld world(s, world_description, 1, model);
    twin::TwinRobot robot(&world);
    robot.set_measure_cost(measure);
    // The robot drives a slow circle so the sensors see a changing scene.
    const twin::Controller drive = [](RobotPort& port) {
      port.Sense();
      port.SendBaseVelocity({0.2, 0.0, 0.15});
      return true;
    };
    twin::RunOptions options;
    options.duration = seconds;
    options.record_trace = true;
    const auto t0 = std::chrono::steady_clock::now();
    twin::RunScenario(robot, drive, options);
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return std::make_pair(wall, robot.sensor_cost());
  };
  const auto [wall_all, cost] = run(true, false);
  const auto [wall_measured, cost_measured] = run(true, true);
  const auto [wall_bare, unused] = run(false, false);
  (void)wall_measured;
  (void)unused;
  const double rtf = seconds / wall_all;
  const auto per_s = [&](double c) { return 1000.0 * c / seconds; };
  std::printf("twin run of %s, %.0f s simulated, 1 core\n", scenario_path.c_str(), seconds);
  std::printf("  all sensors at defaults: %.2f s wall  -> real-time factor %.0fx\n", wall_all, rtf);
  std::printf("  physics, people, doors only: %.2f s wall -> %.0fx\n", wall_bare,
              seconds / wall_bare);
  std::printf(
      "  per simulated second: laser %.1f ms, depth %.1f ms, detector %.1f ms, odometry %.2f ms\n",
      per_s(cost_measured.laser), per_s(cost_measured.depth), per_s(cost_measured.detector),
      per_s(cost_measured.odometry));
  const nlohmann::json out = {{"scenario", scenario_path},
                              {"simulated_s", seconds},
                              {"wall_s", wall_all},
                              {"real_time_factor", rtf},
                              {"real_time_factor_without_sensors", seconds / wall_bare},
                              {"ms_per_sim_s",
                               {{"laser", per_s(cost_measured.laser)},
                                {"depth", per_s(cost_measured.depth)},
                                {"detector", per_s(cost_measured.detector)},
                                {"odometry", per_s(cost_measured.odometry)}}}};
  std::ofstream("twin_bench.json") << out.dump(2) << "\n";
  return 0;
}
