#include "navigation_server.h"

#include <grpcpp/grpcpp.h>

#include <atomic>
#include <cmath>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "egress/hsr_interface/version.h"
#include "egress/nav/v1/navigation.grpc.pb.h"
#include "egress/perception/costmap.h"
#include "egress/planning/base_planner.h"
#include "egress/planning/route_planner.h"
#include "egress/twin/sdf_world_loader.h"
#include "sdf_map.h"

namespace egress::navd {
namespace {

namespace v1 = egress::nav::v1;
using grpc::ServerContext;
using grpc::Status;
using grpc::StatusCode;

bool IsLoopback(const std::string& host) {
  return host == "localhost" || host.rfind("127.", 0) == 0 || host == "[::1]" || host == "::1";
}

std::string HostOf(const std::string& address) {
  const auto colon = address.rfind(':');
  return colon == std::string::npos ? address : address.substr(0, colon);
}

// One loaded world: the static map, its costmap and planner. Requests on a world are
// serialized by its mutex (OMPL setups are not shared across threads).
struct World {
  std::mutex mutex;
  std::unique_ptr<perception::Costmap2D> costmap;
  std::unique_ptr<planning::BasePlanner> planner;
  std::map<std::string, perception::Doorway> doors;
  std::unique_ptr<planning::RoutePlanner> routes;  // over the static map, doors passable
};

void SetPose(const Pose2& X, v1::Pose2* out) {
  out->set_x(X.x);
  out->set_y(X.y);
  out->set_yaw(X.yaw);
}

Status Invalid(const std::string& message) {
  return {StatusCode::INVALID_ARGUMENT, message};
}

bool Finite(const v1::Pose2& p) {
  return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.yaw());
}

class Service final : public v1::Navigation::Service {
 public:
  explicit Service(const NavigationServerConfig& config) : config_(config) {}

  Status LoadWorld(ServerContext* context, const v1::LoadWorldRequest* request,
                   v1::LoadWorldResponse* response) override {
    return Handle("LoadWorld", true, context, [&] { return DoLoadWorld(*request, response); });
  }
  Status UpdateCostmap(ServerContext* context, const v1::UpdateCostmapRequest* request,
                       v1::UpdateCostmapResponse*) override {
    return Handle("UpdateCostmap", false, context, [&] { return DoUpdateCostmap(*request); });
  }
  Status SetDoorState(ServerContext* context, const v1::SetDoorStateRequest* request,
                      v1::SetDoorStateResponse*) override {
    return Handle("SetDoorState", false, context, [&] { return DoSetDoorState(*request); });
  }
  Status PlanPath(ServerContext* context, const v1::PlanPathRequest* request,
                  v1::PlanPathResponse* response) override {
    return Handle("PlanPath", true, context,
                  [&] { return DoPlanPath(context, *request, response); });
  }
  Status ListPlanners(ServerContext* context, const v1::ListPlannersRequest*,
                      v1::ListPlannersResponse* response) override {
    return Handle("ListPlanners", false, context, [&] {
      for (const auto& name : planning::BasePlanner::PlannerNames())
        response->add_planners(name);
      return Status::OK;
    });
  }
  Status Health(ServerContext* context, const v1::HealthRequest*,
                v1::HealthResponse* response) override {
    return Handle("Health", false, context, [&] {
      response->set_version(Version());
      {
        std::lock_guard lock(worlds_mutex_);
        response->set_worlds(int(worlds_.size()));
      }
      response->set_busy_workers(busy_.load());
      response->set_max_workers(config_.max_workers);
      return Status::OK;
    });
  }

 private:
  // Authentication, the worker bound (for the heavy calls: loading and planning), exception
  // safety and the log line, around each call.
  template <typename Body>
  Status Handle(const char* rpc, bool bounded, ServerContext* context, Body body) {
    const auto start = std::chrono::steady_clock::now();
    Status status;
    bool counted = false;
    if (!config_.token.empty() && !Authorized(*context)) {
      status = {StatusCode::UNAUTHENTICATED,
                "missing or wrong 'authorization: Bearer <token>' metadata"};
    } else if (bounded && busy_.fetch_add(1) >= config_.max_workers) {
      counted = true;
      status = {StatusCode::RESOURCE_EXHAUSTED, "all " + std::to_string(config_.max_workers) +
                                                    " planning workers are busy; retry later"};
    } else {
      counted = bounded;
      try {
        status = body();
      } catch (const std::exception& e) {
        status = Invalid(e.what());  // a malformed request never crashes the server
      }
    }
    if (counted) busy_.fetch_sub(1);
    if (config_.log) {
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count();
      config_.log(nlohmann::json{{"rpc", rpc},
                                 {"peer", context->peer()},
                                 {"code", int(status.error_code())},
                                 {"message", status.error_message()},
                                 {"ms", std::round(ms * 1000) / 1000}}
                      .dump());
    }
    return status;
  }

  bool Authorized(const ServerContext& context) const {
    const auto& metadata = context.client_metadata();
    const auto it = metadata.find("authorization");
    return it != metadata.end() &&
           std::string(it->second.data(), it->second.size()) == "Bearer " + config_.token;
  }

  std::shared_ptr<World> Find(const std::string& id) {
    std::lock_guard lock(worlds_mutex_);
    auto it = worlds_.find(id);
    return it == worlds_.end() ? nullptr : it->second;
  }

  Status DoLoadWorld(const v1::LoadWorldRequest& request, v1::LoadWorldResponse* response) {
    perception::OccupancyGrid grid;
    std::vector<perception::Doorway> sdf_doors;
    switch (request.source_case()) {
      case v1::LoadWorldRequest::kMapYamlPath:
        try {
          grid = perception::OccupancyGrid::LoadMapServerYaml(request.map_yaml_path());
        } catch (const std::exception& e) {
          return Invalid(std::string("map_yaml_path: ") + e.what());
        }
        break;
      case v1::LoadWorldRequest::kMap: {
        const auto& map = request.map();
        const std::vector<std::uint8_t> bytes(map.image().begin(), map.image().end());
        if (bytes.empty()) return Invalid("map.image is empty");
        const cv::Mat image = cv::imdecode(bytes, cv::IMREAD_GRAYSCALE);
        if (image.empty()) return Invalid("map.image is not a PGM or PNG image");
        if (std::int64_t(image.cols) * image.rows > config_.max_map_cells) {
          return Invalid("map.image has " + std::to_string(image.cols) + " x " +
                         std::to_string(image.rows) + " cells, more than the server's limit of " +
                         std::to_string(config_.max_map_cells));
        }
        try {
          grid = perception::OccupancyGrid::FromImage(
              image, map.resolution(), {map.origin().x(), map.origin().y()}, map.negate(),
              map.occupied_thresh() > 0 ? map.occupied_thresh() : 0.65,
              map.free_thresh() > 0 ? map.free_thresh() : 0.196);
        } catch (const std::exception& e) {
          return Invalid(std::string("map: ") + e.what());
        }
        break;
      }
      case v1::LoadWorldRequest::kSdfPath:
      case v1::LoadWorldRequest::kSdfText: {
        const bool by_path = request.source_case() == v1::LoadWorldRequest::kSdfPath;
        try {
          const apps::SdfMap map = apps::RasterizeSdfWorld(
              by_path ? twin::LoadSdfWorld(request.sdf_path())
                      : twin::LoadSdfWorldFromString(request.sdf_text(), "sdf_text"),
              request.sdf_resolution() != 0 ? request.sdf_resolution() : 0.05,
              config_.max_map_cells);
          grid = map.grid;
          sdf_doors = map.doors;
        } catch (const std::exception& e) {
          return Invalid(std::string(by_path ? "sdf_path: " : "sdf_text: ") + e.what());
        }
        break;
      }
      default:
        return Invalid("source: set map_yaml_path or map");
    }
    if (std::int64_t(grid.geometry().size()) > config_.max_map_cells) {
      return Invalid("the map has " + std::to_string(grid.geometry().size()) +
                     " cells, more than the limit " + std::to_string(config_.max_map_cells));
    }
    perception::CostmapConfig costmap_config;
    if (request.robot_radius() != 0) costmap_config.robot_radius = request.robot_radius();
    if (request.inflation_radius() != 0)
      costmap_config.inflation_radius = request.inflation_radius();
    auto world = std::make_shared<World>();
    world->costmap = std::make_unique<perception::Costmap2D>(grid, costmap_config);
    planning::BasePlannerConfig planner_config;
    planner_config.footprint_radius = costmap_config.robot_radius;
    world->planner =
        std::make_unique<planning::BasePlanner>(*world->costmap, nullptr, planner_config);
    for (const auto& doorway : sdf_doors) {
      world->costmap->AddDoorway(doorway);
      world->planner->AddDoor({doorway.id, doorway.p_MHinge, doorway.p_MLatch});
      world->doors[doorway.id] = doorway;
    }
    for (const auto& door : request.doors()) {
      if (door.id().empty()) return Invalid("doors[].id must not be empty");
      if (world->doors.count(door.id()) > 0) {
        return Invalid("doors[].id '" + door.id() +
                       "' is given twice (or is a door of the SDF world)");
      }
      const perception::Doorway doorway{
          door.id(), {door.hinge().x(), door.hinge().y()}, {door.latch().x(), door.latch().y()}};
      world->costmap->AddDoorway(doorway);
      world->planner->AddDoor({door.id(), doorway.p_MHinge, doorway.p_MLatch});
      world->doors[door.id()] = doorway;
    }
    {
      std::vector<perception::Doorway> doorways;
      for (const auto& [door_id, doorway] : world->doors)
        doorways.push_back(doorway);
      planning::RoutePlannerConfig route_config;
      route_config.clearance = costmap_config.robot_radius + 0.025;
      try {
        world->routes = std::make_unique<planning::RoutePlanner>(grid, doorways, route_config);
      } catch (const std::exception& e) {
        return Invalid(std::string("route planner: ") + e.what());
      }
    }
    std::string id;
    {
      std::lock_guard lock(worlds_mutex_);
      id = "world-" + std::to_string(++next_world_);
      worlds_[id] = world;
    }
    response->set_world_id(id);
    response->set_width(grid.geometry().width);
    response->set_height(grid.geometry().height);
    response->set_resolution(grid.geometry().resolution);
    return Status::OK;
  }

  Status DoUpdateCostmap(const v1::UpdateCostmapRequest& request) {
    const auto world = Find(request.world_id());
    if (!world)
      return {StatusCode::NOT_FOUND, "world_id '" + request.world_id() + "' is not loaded"};
    std::lock_guard lock(world->mutex);
    if (request.has_scan()) {
      const auto& s = request.scan();
      if (!Finite(s.laser_pose())) return Invalid("scan.laser_pose must be finite");
      LaserScan scan;
      scan.angle_min = s.angle_min();
      scan.angle_increment = s.angle_increment();
      scan.range_min = s.range_min();
      scan.range_max = s.range_max();
      scan.ranges.assign(s.ranges().begin(), s.ranges().end());
      try {
        world->costmap->UpdateWithScan(
            scan, {s.laser_pose().x(), s.laser_pose().y(), s.laser_pose().yaw()});
      } catch (const std::exception& e) {
        return Invalid(std::string("scan: ") + e.what());
      }
      return Status::OK;
    }
    if (request.has_obstacles()) {
      std::vector<Eigen::Vector2d> points;
      for (const auto& p : request.obstacles().points()) {
        if (!std::isfinite(p.x()) || !std::isfinite(p.y()))
          return Invalid("obstacles.points must be finite");
        points.emplace_back(p.x(), p.y());
      }
      world->costmap->SetProjectedObstacles(points);
      return Status::OK;
    }
    return Invalid("update: set scan or obstacles");
  }

  Status DoSetDoorState(const v1::SetDoorStateRequest& request) {
    const auto world = Find(request.world_id());
    if (!world)
      return {StatusCode::NOT_FOUND, "world_id '" + request.world_id() + "' is not loaded"};
    std::lock_guard lock(world->mutex);
    if (!world->doors.contains(request.door_id())) {
      return {StatusCode::NOT_FOUND,
              "door_id '" + request.door_id() + "' is not a door of " + request.world_id()};
    }
    if (request.has_angle() && !std::isfinite(request.angle()))
      return Invalid("angle must be finite");
    world->costmap->SetDoorLeafAngle(request.door_id(), request.has_angle()
                                                            ? std::optional<double>(request.angle())
                                                            : std::nullopt);
    return Status::OK;
  }

  Status DoPlanPath(ServerContext* context, const v1::PlanPathRequest& request,
                    v1::PlanPathResponse* response) {
    const auto world = Find(request.world_id());
    if (!world)
      return {StatusCode::NOT_FOUND, "world_id '" + request.world_id() + "' is not loaded"};
    if (!Finite(request.start())) return Invalid("start must be finite (x, y, yaw)");
    if (!Finite(request.goal())) return Invalid("goal must be finite (x, y, yaw)");
    if (!std::isfinite(request.time_budget()) || request.time_budget() < 0) {
      return Invalid("time_budget must be a finite number >= 0");
    }
    planning::BasePlannerConfig config;
    if (!request.planner().empty()) config.planner = request.planner();
    double budget = request.time_budget() > 0 ? request.time_budget() : 1.0;
    // Honour the request deadline: never plan past it.
    const auto deadline = context->deadline();
    if (deadline != std::chrono::system_clock::time_point::max()) {
      const double remaining =
          std::chrono::duration<double>(deadline - std::chrono::system_clock::now()).count();
      if (remaining <= 0.005)
        return {StatusCode::DEADLINE_EXCEEDED, "the request deadline passed before planning"};
      budget = std::min(budget, remaining * 0.8);
    }
    config.time_budget = budget;
    config.costmap_cost_weight = request.costmap_cost_weight();
    std::lock_guard lock(world->mutex);
    if (context->IsCancelled()) return {StatusCode::CANCELLED, "the client cancelled the request"};
    std::unique_ptr<planning::BasePlanner> planner;
    try {
      planner = std::make_unique<planning::BasePlanner>(*world->costmap, nullptr, config);
    } catch (const std::exception& e) {
      return Invalid(std::string("planner: ") + e.what());
    }
    for (const auto& [id, door] : world->doors)
      planner->AddDoor({id, door.p_MHinge, door.p_MLatch});
    const auto& s = request.start();
    const auto& g = request.goal();
    const planning::PlanResult result =
        planner->Plan({s.x(), s.y(), s.yaw()}, {g.x(), g.y(), g.yaw()});
    switch (result.status) {
      case planning::PlanStatus::kInvalidRequest:
        return Invalid(result.message);
      case planning::PlanStatus::kStartInCollision:
      case planning::PlanStatus::kGoalInCollision:
        return {StatusCode::FAILED_PRECONDITION, result.message};
      case planning::PlanStatus::kTimeout:
        if (deadline != std::chrono::system_clock::time_point::max() &&
            std::chrono::system_clock::now() >= deadline) {
          return {StatusCode::DEADLINE_EXCEEDED, result.message};
        }
        response->set_status(v1::PLAN_STATUS_TIMEOUT);
        break;
      case planning::PlanStatus::kGoalUnreachable:
        response->set_status(v1::PLAN_STATUS_GOAL_UNREACHABLE);
        break;
      case planning::PlanStatus::kSuccess:
        response->set_status(v1::PLAN_STATUS_SUCCESS);
        break;
    }
    response->set_message(result.message);
    for (const Pose2& p : result.path) {
      auto* pose = response->add_path();
      pose->set_x(p.x);
      pose->set_y(p.y);
      pose->set_yaw(p.yaw);
    }
    response->set_length(result.length);
    response->set_planning_time(result.planning_time);
    for (const auto& door : result.doors_crossed)
      response->add_doors_crossed(door);
    const planning::RouteResult route =
        world->routes->Plan({s.x(), s.y(), s.yaw()}, {g.x(), g.y(), g.yaw()});
    if (route.ok()) {
      for (const auto& leg : route.route->legs) {
        auto* door = response->add_doors_on_route();
        door->set_door(leg.door);
        SetPose(leg.X_MB_approach, door->mutable_approach());
        SetPose(leg.X_MB_exit, door->mutable_exit());
        door->set_opens_towards_robot(leg.opens_towards_robot);
      }
    }
    return Status::OK;
  }

  const NavigationServerConfig& config_;
  std::atomic<int> busy_{0};
  std::mutex worlds_mutex_;
  std::map<std::string, std::shared_ptr<World>> worlds_;
  int next_world_{0};
};

}  // namespace

void ValidateListenAddress(const NavigationServerConfig& config) {
  const std::string host = HostOf(config.listen);
  if (!IsLoopback(host) && !config.allow_remote) {
    throw std::invalid_argument(
        "refusing to listen on '" + config.listen +
        "': it is not a loopback address; pass --allow-remote with --token-file");
  }
  if (config.allow_remote && config.token.empty()) {
    throw std::invalid_argument(
        "--allow-remote needs a token (--token-file): remote requests must authenticate");
  }
  if (config.max_workers < 1) throw std::invalid_argument("max_workers must be >= 1");
}

struct NavigationServer::Impl {
  NavigationServerConfig config;
  std::unique_ptr<Service> service;
  std::unique_ptr<grpc::Server> server;
  int port{0};
  std::once_flag shutdown;
};

NavigationServer::NavigationServer(NavigationServerConfig config)
    : impl_(std::make_unique<Impl>()) {
  ValidateListenAddress(config);
  impl_->config = std::move(config);
  impl_->service = std::make_unique<Service>(impl_->config);
  grpc::ServerBuilder builder;
  builder.AddListeningPort(impl_->config.listen, grpc::InsecureServerCredentials(), &impl_->port);
  builder.RegisterService(impl_->service.get());
  impl_->server = builder.BuildAndStart();
  if (!impl_->server || impl_->port == 0) {
    throw std::runtime_error("cannot listen on '" + impl_->config.listen +
                             "' (address in use or invalid)");
  }
}

NavigationServer::~NavigationServer() {
  Shutdown();
}

int NavigationServer::port() const {
  return impl_->port;
}

void NavigationServer::Wait() {
  impl_->server->Wait();
}

void NavigationServer::Shutdown(std::chrono::milliseconds grace) {
  std::call_once(impl_->shutdown,
                 [&] { impl_->server->Shutdown(std::chrono::system_clock::now() + grace); });
}

}  // namespace egress::navd
