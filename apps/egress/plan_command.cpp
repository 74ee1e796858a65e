// `egress plan`: plan a base path on a map_server map, through egress-navd (default) or
// in-process (--local), and optionally draw it over the costmap as a PNG.

#include <grpcpp/grpcpp.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "egress/hsr_interface/error.h"
#include "egress/nav/v1/navigation.grpc.pb.h"
#include "egress/perception/image_io.h"
#include "egress/planning/base_planner.h"
#include "egress/twin/sdf_world_loader.h"
#include "render.h"
#include "sdf_map.h"

namespace egress::apps {
namespace {

namespace v1 = egress::nav::v1;

struct PlanOptions {
  std::string map;
  std::vector<double> start, goal;  // x y yaw
  std::vector<std::string> doors;   // "id:hx,hy,lx,ly"
  std::vector<std::string> closed;  // door ids closed
  std::string planner{"RRTConnect"};
  double budget{1.0};
  std::string server{"127.0.0.1:50051"};
  std::string token_file;
  bool local{false};
  std::string png;
  double resolution{0.05};
  bool overwrite{false};
  bool json{false};
};

struct DoorSpec {
  std::string id;
  Eigen::Vector2d hinge, latch;
};

std::vector<DoorSpec> ParseDoors(const std::vector<std::string>& specs) {
  std::vector<DoorSpec> doors;
  for (const auto& spec : specs) {
    const auto colon = spec.find(':');
    double v[4];
    if (colon == std::string::npos ||
        std::sscanf(spec.c_str() + colon + 1, "%lf,%lf,%lf,%lf", &v[0], &v[1], &v[2], &v[3]) != 4) {
      throw CommandFailed(
          fmt::format("--door '{}': expected ID:HINGE_X,HINGE_Y,LATCH_X,LATCH_Y [m]", spec));
    }
    doors.push_back({spec.substr(0, colon), {v[0], v[1]}, {v[2], v[3]}});
  }
  return doors;
}

// The map as PNG bytes + its parameters, so that the server needs no access to our files.
v1::MapBytes ToMapBytes(const perception::OccupancyGrid& grid) {
  const auto& g = grid.geometry();
  cv::Mat image(g.height, g.width, CV_8UC1);
  for (int iy = 0; iy < g.height; ++iy) {
    for (int ix = 0; ix < g.width; ++ix) {
      const std::uint8_t cell = grid.at(ix, iy);
      image.at<std::uint8_t>(g.height - 1 - iy, ix) =
          cell == perception::kLethalCost ? 0 : (cell == perception::kUnknownCost ? 205 : 254);
    }
  }
  std::vector<std::uint8_t> png;
  perception::EncodeImage(".png", image, &png);
  v1::MapBytes bytes;
  bytes.set_image(std::string(png.begin(), png.end()));
  bytes.set_resolution(g.resolution);
  bytes.mutable_origin()->set_x(g.origin.x());
  bytes.mutable_origin()->set_y(g.origin.y());
  return bytes;
}

planning::PlanResult PlanRemote(const PlanOptions& options, const perception::OccupancyGrid& grid,
                                const std::vector<DoorSpec>& doors) {
  auto channel = grpc::CreateChannel(options.server, grpc::InsecureChannelCredentials());
  auto stub = v1::Navigation::NewStub(channel);
  std::string token;
  if (!options.token_file.empty()) {
    std::ifstream in(options.token_file);
    std::getline(in, token);
  }
  const auto context = [&] {
    auto c = std::make_unique<grpc::ClientContext>();
    c->set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10) +
                    std::chrono::milliseconds(int(options.budget * 1000)));
    if (!token.empty()) c->AddMetadata("authorization", "Bearer " + token);
    return c;
  };
  const auto check = [&](const grpc::Status& status, const char* rpc) {
    if (!status.ok()) {
      throw CommandFailed(fmt::format("{} on {}: {} ({})", rpc, options.server,
                                      status.error_message(), int(status.error_code())));
    }
  };
  v1::LoadWorldRequest load;
  *load.mutable_map() = ToMapBytes(grid);
  for (const auto& door : doors) {
    auto* d = load.add_doors();
    d->set_id(door.id);
    d->mutable_hinge()->set_x(door.hinge.x());
    d->mutable_hinge()->set_y(door.hinge.y());
    d->mutable_latch()->set_x(door.latch.x());
    d->mutable_latch()->set_y(door.latch.y());
  }
  v1::LoadWorldResponse loaded;
  check(stub->LoadWorld(context().get(), load, &loaded), "LoadWorld");
  for (const auto& id : options.closed) {
    v1::SetDoorStateRequest request;
    request.set_world_id(loaded.world_id());
    request.set_door_id(id);
    request.set_angle(0.0);
    v1::SetDoorStateResponse ignored;
    check(stub->SetDoorState(context().get(), request, &ignored), "SetDoorState");
  }
  v1::PlanPathRequest request;
  request.set_world_id(loaded.world_id());
  request.mutable_start()->set_x(options.start[0]);
  request.mutable_start()->set_y(options.start[1]);
  request.mutable_start()->set_yaw(options.start[2]);
  request.mutable_goal()->set_x(options.goal[0]);
  request.mutable_goal()->set_y(options.goal[1]);
  request.mutable_goal()->set_yaw(options.goal[2]);
  request.set_planner(options.planner);
  request.set_time_budget(options.budget);
  v1::PlanPathResponse response;
  check(stub->PlanPath(context().get(), request, &response), "PlanPath");
  planning::PlanResult result;
  result.status = response.status() == v1::PLAN_STATUS_SUCCESS ? planning::PlanStatus::kSuccess
                  : response.status() == v1::PLAN_STATUS_GOAL_UNREACHABLE
                      ? planning::PlanStatus::kGoalUnreachable
                      : planning::PlanStatus::kTimeout;
  result.message = response.message();
  for (const auto& p : response.path())
    result.path.push_back({p.x(), p.y(), p.yaw()});
  result.length = response.length();
  result.planning_time = response.planning_time();
  result.doors_crossed.assign(response.doors_crossed().begin(), response.doors_crossed().end());
  return result;
}

void Run(const PlanOptions& options) {
  if (!options.png.empty() && std::filesystem::exists(options.png) && !options.overwrite) {
    throw CommandFailed(fmt::format("'{}' exists; pass --overwrite to replace it", options.png));
  }
  // A map_server YAML, or an SDF world whose walls are rasterized and whose doors are known.
  const std::filesystem::path map_path(options.map);
  const bool sdf = map_path.extension() == ".sdf" || map_path.extension() == ".world";
  perception::OccupancyGrid grid;
  auto doors = ParseDoors(options.doors);
  std::vector<double> swing_signs(doors.size(), 1.0);
  if (sdf) {
    SdfMap map;  // from common/sdf_map.h
    try {
      map = RasterizeSdfWorld(twin::LoadSdfWorld(map_path), options.resolution,
                              std::int64_t(1) << 26);
    } catch (const InvalidArgument& e) {
      throw CommandFailed(e.what());
    }
    grid = map.grid;
    for (const auto& d : map.doors) {
      doors.push_back({d.id, d.p_MHinge, d.p_MLatch});
      swing_signs.push_back(d.swing_sign);
    }
  } else {
    grid = perception::OccupancyGrid::LoadMapServerYaml(map_path);
  }
  perception::Costmap2D costmap(grid);
  for (std::size_t i = 0; i < doors.size(); ++i) {
    perception::Doorway doorway{doors[i].id, doors[i].hinge, doors[i].latch};
    doorway.swing_sign = swing_signs[i];
    costmap.AddDoorway(doorway);
  }
  for (const auto& id : options.closed) {
    if (!costmap.doorways().contains(id))
      throw CommandFailed(fmt::format("--closed '{}' is not a --door", id));
    costmap.SetDoorLeafAngle(id, 0.0);
  }
  planning::PlanResult result;
  if (options.local) {
    planning::BasePlannerConfig config;
    config.planner = options.planner;
    config.time_budget = options.budget;
    planning::BasePlanner planner(costmap, nullptr, config);
    for (const auto& door : doors)
      planner.AddDoor({door.id, door.hinge, door.latch});
    result = planner.Plan({options.start[0], options.start[1], options.start[2]},
                          {options.goal[0], options.goal[1], options.goal[2]});
    if (result.status == planning::PlanStatus::kInvalidRequest ||
        result.status == planning::PlanStatus::kStartInCollision ||
        result.status == planning::PlanStatus::kGoalInCollision) {
      throw CommandFailed(fmt::format("{}: {}", planning::ToString(result.status), result.message));
    }
  } else {
    result = PlanRemote(options, grid, doors);
  }
  if (!options.png.empty()) {
    cv::Mat image = RenderCostmap(costmap);
    DrawPath(image, costmap.geometry(), result.path);
    if (!perception::WriteImageFile(options.png, image))
      throw CommandFailed(fmt::format("cannot write '{}'", options.png));
  }
  if (options.json) {
    nlohmann::json path = nlohmann::json::array();
    for (const auto& p : result.path)
      path.push_back({p.x, p.y, p.yaw});
    std::cout << nlohmann::json{{"status", planning::ToString(result.status)},
                                {"message", result.message},
                                {"length", result.length},
                                {"planning_time", result.planning_time},
                                {"doors_crossed", result.doors_crossed},
                                {"path", path}}
                     .dump(2)
              << "\n";
  } else {
    fmt::print("status         {}{}\n", planning::ToString(result.status),
               result.message.empty() ? "" : " (" + result.message + ")");
    fmt::print("length         {:.2f} m in {} waypoints\n", result.length, result.path.size());
    fmt::print("planning time  {:.1f} ms ({})\n", result.planning_time * 1000,
               options.local ? "local" : options.server);
    fmt::print("doors crossed  {}\n",
               result.doors_crossed.empty()
                   ? "none"
                   : fmt::format("{}", fmt::join(result.doors_crossed, ", ")));
    if (!options.png.empty()) fmt::print("picture        {}\n", options.png);
  }
  if (!result.ok()) throw CommandFailed("");
}

}  // namespace

void AddPlanCommand(CLI::App& app) {
  auto options = std::make_shared<PlanOptions>();
  auto* plan =
      app.add_subcommand("plan", "Plan a base path on a map (via egress-navd, or --local)");
  plan->add_option("--map", options->map,
                   "map_server YAML, or an SDF world (.sdf/.world; its doors are added)")
      ->required()
      ->check(CLI::ExistingFile);
  plan->add_option("--resolution", options->resolution, "cell size for an SDF world [m]")
      ->capture_default_str()
      ->check(FiniteIn(0.005, 10.0));
  plan->add_option("--start", options->start, "x y yaw [m, m, rad] in the map frame")
      ->required()
      ->expected(3);
  plan->add_option("--goal", options->goal, "x y yaw [m, m, rad]")->required()->expected(3);
  plan->add_option("--door", options->doors, "ID:HINGE_X,HINGE_Y,LATCH_X,LATCH_Y (repeatable)");
  plan->add_option("--closed", options->closed, "ID of a door that is closed (repeatable)");
  plan->add_option("--planner", options->planner,
                   "RRTConnect, RRTstar, PRMstar, BITstar, InformedRRTstar")
      ->capture_default_str();
  plan->add_option("--budget", options->budget, "time budget [s]")
      ->capture_default_str()
      ->check(FiniteIn(1e-3, 3600.0));
  plan->add_option("--server", options->server, "egress-navd address")->capture_default_str();
  plan->add_option("--token-file", options->token_file, "token for a remote server")
      ->check(CLI::ExistingFile);
  plan->add_flag("--local", options->local, "plan in this process instead of calling egress-navd");
  plan->add_option("--png", options->png, "draw the path over the costmap into this PNG");
  plan->add_flag("--overwrite", options->overwrite, "replace an existing PNG");
  plan->add_flag("--json", options->json, "print JSON");
  plan->callback([options] { Run(*options); });
}

}  // namespace egress::apps
