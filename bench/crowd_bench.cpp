// Timed command: how the crowd scales. (1) The social force model alone: N walkers crossing a
// 30 m x 15 m hall to random goals, cost per simulated second with and without the neighbour
// grid's benefit visible as N grows; (2) a twin run of N evacuees through the clinic's three
// doors (propped open) with every sensor at its default rate and with sensors off (the robot
// standing, stepped through TwinRobot, whose sensors they are).
//   crowd_bench [SECONDS]   (default 30 s simulated per case)
// Writes crowd_bench.json in the working directory.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <string>

#include <nlohmann/json.hpp>

#include "egress/twin/scenario.h"
#include "egress/twin/sdf_world_loader.h"
#include "egress/twin/social_force.h"
#include "egress/twin/twin_robot.h"
#include "egress/twin/twin_world.h"

namespace {

using WallClock = std::chrono::steady_clock;
double Since(WallClock::time_point t0) {
  return std::chrono::duration<double>(WallClock::now() - t0).count();
}

// The social force model alone: wall seconds per simulated second for n walkers.
double SfmCost(int n, double seconds) {
  using namespace egress::twin;
  SocialForceModel sfm;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> x(1.0, 29.0), y(1.0, 14.0);
  std::vector<Walker> walkers(static_cast<std::size_t>(n));
  for (auto& w : walkers) {
    w.position = {x(rng), y(rng)};
    w.target = {x(rng), y(rng)};
    w.desired_speed = 1.2;
  }
  const std::vector<WallSegment> walls = {
      {{0, 0}, {30, 0}}, {{30, 0}, {30, 15}}, {{30, 15}, {0, 15}}, {{0, 15}, {0, 0}}};
  const double dt = 0.01;
  const WallCells cells(walls);  // once, as the twin does: the walls do not move
  const auto t0 = WallClock::now();
  for (double t = 0; t < seconds; t += dt) {
    sfm.Step(&walkers, {}, cells, {}, dt);
    for (auto& w : walkers) {
      if ((w.position - w.target).norm() < 0.5) w.target = {x(rng), y(rng)};
    }
  }
  return Since(t0) / seconds;
}

std::string ClinicCrowd(int n, bool sensors) {
  std::string s = "world: " EGRESS_WORLDS_DIR
                  "/clinic/clinic.sdf\n"
                  "time_limit: 600\n"
                  "robot: {start: {x: 9.0, y: -1.6}}\n"
                  "doors:\n";
  for (const char* d : {"door_a", "door_d", "door_e", "exit_door"})
    s += std::string("  - {door: ") + d +
         ", operator: push, open_at: [0.0], hold_open_s: 1000000}\n";
  if (!sensors)
    s += "sensors: {laser: {rate_hz: 0.000001}, depth: {rate_hz: 0.000001}, "
         "detector: {rate_hz: 0.000001}}\n";
  s += "people:\n";
  // Groups of at most 25 in the south ward and rooms a, b and c, two of them side by side in a
  // room where it has room for their 5 x 5 grids, 1.8 m a side (a group is laid out only where
  // the building has room for it: (7, 5) was inside wall_ab, and (12.5, 5) ran past wall_bc).
  const char* starts[] = {"[3.0, -3.0]", "[9.5, -3.0]", "[4.0, 5.0]", "[8.5, 5.0]",
                          "[16.0, 5.0]", "[6.5, -3.0]", "[1.5, 4.5]", "[11.5, 5.0]"};
  const char* routes[] = {"[door_d, door_e, exit_door]", "[door_d, door_e, exit_door]",
                          "[door_a, door_e, exit_door]", "[door_a, door_e, exit_door]",
                          "[door_a, door_e, exit_door]", "[door_d, door_e, exit_door]",
                          "[door_a, door_e, exit_door]", "[door_a, door_e, exit_door]"};
  for (int g = 0, left = n; left > 0; ++g, left -= 25) {
    (void)g;
    s += "  - {name: g" + std::to_string(g) + ", behavior: evacuate, route: " + routes[g % 8] +
         ", start: " + starts[g % 8] +
         ", goal: [21.0, 11.5], radius: 0.2, count: " + std::to_string(std::min(left, 25)) + "}\n";
  }
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace egress;
  double seconds = 30.0;
  if (argc > 1) {
    // The whole argument a positive, finite number of seconds, or a clear error.
    char* end = nullptr;
    seconds = std::strtod(argv[1], &end);
    if (end == argv[1] || *end != '\0' || !std::isfinite(seconds) || seconds <= 0.0) {
      std::fprintf(stderr, "crowd_bench: SECONDS must be a positive number, got '%s'\n", argv[1]);
      std::fprintf(stderr, "usage: crowd_bench [SECONDS]\n");
      return 2;
    }
  }
  nlohmann::json out = {
      {"seconds", seconds}, {"sfm", nlohmann::json::array()}, {"twin", nlohmann::json::array()}};
  std::printf("social force model alone (30 m x 15 m hall), 1 core:\n");
  for (int n : {10, 50, 100, 200}) {
    const double cost = SfmCost(n, seconds);
    std::printf("  %3d walkers: %.4f s wall per simulated s  (%.0fx real time)\n", n, cost,
                1.0 / cost);
    out["sfm"].push_back({{"walkers", n}, {"wall_per_sim_s", cost}});
  }
  auto model = std::make_shared<const RobotModel>(RobotModel::LoadDefault());
  std::printf("twin: evacuees through the clinic's doors (propped open), first %.0f s, 1 core:\n",
              seconds);
  for (int n : {10, 50, 100, 200}) {
    for (bool sensors : {true, false}) {
      const twin::Scenario scenario =
          twin::LoadScenarioFromString(ClinicCrowd(n, sensors), "crowd_bench", ".");
      const twin::WorldDescription world = twin::LoadSdfWorld(scenario.world_file);
      twin::TwinWorld run(scenario, world, 1, model);
      // The sensors are the robot's: stepped through it, they capture at their rates (a robot
      // standing still; "off" sets the rates to nothing).
      twin::TwinRobot robot(&run);
      const auto t0 = WallClock::now();
      robot.Advance(seconds);
      const double rtf = seconds / Since(t0);
      std::printf("  %3d evacuees, sensors %s: %.0fx real time\n", n, sensors ? "on " : "off", rtf);
      out["twin"].push_back({{"evacuees", n}, {"sensors", sensors}, {"real_time_factor", rtf}});
    }
  }
  std::ofstream("crowd_bench.json") << out.dump(2) << "\n";
  std::printf("wrote crowd_bench.json\n");
}
