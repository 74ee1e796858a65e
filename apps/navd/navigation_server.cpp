#include "navigation_server.h"

#include <grpcpp/grpcpp.h>

#include <atomic>
#include <cctype>
#include <cmath>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "connection_gate.h"
#include "egress/hsr_interface/error.h"
#include "egress/hsr_interface/text_file.h"
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
constexpr double kMaxRobotRadiusM = 1.0;
constexpr double kMaxInflationRadiusM = 5.0;
using grpc::ServerContext;
using grpc::Status;
using grpc::StatusCode;

bool IsLoopback(const std::string& host) {
  return host == "localhost" || host.rfind("127.", 0) == 0 || host == "[::1]" || host == "::1";
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

struct CachedWorld {
  std::shared_ptr<World> world;  // requests running on an evicted world keep it alive
  std::int64_t cells{0};
  std::uint64_t last_used{0};
};

// The first ":<digits>:" of an error message (file:line: ...), or empty. (No std::regex: GCC
// 12 warns inside it under -O2 with the sanitizers.)
std::string FirstLineNumber(const std::string& what) {
  for (std::size_t at = what.find(':'); at != std::string::npos; at = what.find(':', at + 1)) {
    std::size_t end = at + 1;
    while (end < what.size() && std::isdigit(static_cast<unsigned char>(what[end])))
      ++end;
    if (end > at + 1 && end < what.size() && what[end] == ':')
      return what.substr(at + 1, end - at - 1);
  }
  return {};
}

// The error for a file named by a client. It names the field, the path as given and the line,
// never the file's content (the client may not read the file; the log has the details).
Status FileError(const std::string& field, const std::string& given, const std::exception& e,
                 const std::function<void(const std::string&)>& log) {
  if (dynamic_cast<const PathOutsideRoot*>(&e) != nullptr) {
    return {StatusCode::PERMISSION_DENIED,
            field + ": '" + given + "' or a file it references lies outside the data root"};
  }
  if (log) log(nlohmann::json{{"file_error", field}, {"path", given}, {"detail", e.what()}}.dump());
  std::string message = field + ": '" + given + "' cannot be loaded";
  const std::string what = e.what();
  if (what.find(": no such ") != std::string::npos) {
    message = field + ": '" + given + "' does not exist";
  } else if (const std::string line = FirstLineNumber(what); !line.empty()) {
    message += " (error at line " + line + ")";
  }
  return {StatusCode::INVALID_ARGUMENT, message + "; the server's log has the details"};
}

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
  Service(const NavigationServerConfig& config, std::function<ConnectionGate::Counts()> counts)
      : config_(config), connection_counts_(std::move(counts)) {}

  Status LoadWorld(ServerContext* context, const v1::LoadWorldRequest* request,
                   v1::LoadWorldResponse* response) override {
    return Handle("LoadWorld", true, context, [&] { return DoLoadWorld(*request, response); });
  }
  Status UpdateCostmap(ServerContext* context, const v1::UpdateCostmapRequest* request,
                       v1::UpdateCostmapResponse*) override {
    return Handle("UpdateCostmap", false, context, [&] { return DoUpdateCostmap(*request); });
  }
  Status UnloadWorld(ServerContext* context, const v1::UnloadWorldRequest* request,
                     v1::UnloadWorldResponse*) override {
    return Handle("UnloadWorld", false, context, [&]() -> Status {
      std::lock_guard lock(worlds_mutex_);
      const auto it = worlds_.find(request->world_id());
      if (it == worlds_.end())
        return {StatusCode::NOT_FOUND, "world_id '" + request->world_id() + "' is not loaded"};
      cached_cells_ -= it->second.cells;
      worlds_.erase(it);
      return Status::OK;
    });
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
        response->set_cached_cells(cached_cells_);
        response->set_worlds_evicted(evicted_);
      }
      response->set_max_cached_cells(config_.max_cached_cells);
      response->set_busy_workers(busy_.load());
      response->set_max_workers(config_.max_workers);
      if (connection_counts_) {
        const ConnectionGate::Counts counts = connection_counts_();
        response->set_connections(counts.live);
        response->set_connections_refused(counts.refused);
      }
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
    // A null context: called in-process by NavigationHandlers (no transport, no token).
    if (context != nullptr && !config_.token.empty() && !Authorized(*context)) {
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
    if (config_.log && context != nullptr) {
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
    if (it == worlds_.end()) return nullptr;
    it->second.last_used = ++use_clock_;
    return it->second.world;
  }

  // Adds a world and evicts the least recently used others past the caps.
  std::string Insert(std::shared_ptr<World> world, std::int64_t cells) {
    std::lock_guard lock(worlds_mutex_);
    const std::string id = "world-" + std::to_string(++next_world_);
    worlds_[id] = {std::move(world), cells, ++use_clock_};
    cached_cells_ += cells;
    while (worlds_.size() > 1 &&
           (cached_cells_ > config_.max_cached_cells || int(worlds_.size()) > config_.max_worlds)) {
      auto oldest = worlds_.end();
      for (auto it = worlds_.begin(); it != worlds_.end(); ++it) {
        if (it->first != id &&
            (oldest == worlds_.end() || it->second.last_used < oldest->second.last_used)) {
          oldest = it;
        }
      }
      cached_cells_ -= oldest->second.cells;
      worlds_.erase(oldest);
      ++evicted_;
    }
    return id;
  }

  // Refuses a file path unless the server has a data root; `load` runs confined to it.
  template <typename Load>
  Status LoadFile(const std::string& field, const std::string& path, Load load) {
    if (config_.data_root.empty()) {
      return {StatusCode::PERMISSION_DENIED,
              field +
                  ": this server reads no files (start egress-navd with --data-root DIR); "
                  "send the world by value"};
    }
    try {
      const ScopedReadRoot root(config_.data_root);
      load(CheckUnderReadRoot(path, field));
    } catch (const std::exception& e) {
      return FileError(field, path, e, config_.log);
    }
    return Status::OK;
  }

  Status DoLoadWorld(const v1::LoadWorldRequest& request, v1::LoadWorldResponse* response) {
    perception::OccupancyGrid grid;
    std::vector<perception::Doorway> sdf_doors;
    switch (request.source_case()) {
      case v1::LoadWorldRequest::kMapYamlPath: {
        const Status status =
            LoadFile("map_yaml_path", request.map_yaml_path(), [&](const auto& path) {
              grid = perception::OccupancyGrid::LoadMapServerYaml(path, config_.max_map_cells);
            });
        if (!status.ok()) return status;
        break;
      }
      case v1::LoadWorldRequest::kMap: {
        const auto& map = request.map();
        if (map.image().empty()) return Invalid("map.image is empty");
        try {
          const cv::Mat image = perception::OccupancyGrid::DecodeMapImage(
              map.image(), config_.max_map_cells, "map.image");
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
        const double resolution = request.sdf_resolution() != 0 ? request.sdf_resolution() : 0.05;
        if (!std::isfinite(resolution) || resolution < 0.005 || resolution > 1.0)
          return Invalid("sdf_resolution must be 0 (default 0.05) or in [0.005, 1] m");
        const auto rasterize = [&](const twin::WorldDescription& world) {
          const apps::SdfMap map =
              apps::RasterizeSdfWorld(world, resolution, config_.max_map_cells);
          grid = map.grid;
          sdf_doors = map.doors;
        };
        if (request.source_case() == v1::LoadWorldRequest::kSdfPath) {
          const Status status = LoadFile("sdf_path", request.sdf_path(), [&](const auto& path) {
            const twin::WorldDescription world = twin::LoadSdfWorld(path);
            // Rasterizing is not reading: a bad resolution is the request's, not the file's.
            try {
              rasterize(world);
            } catch (const std::exception& e) {
              throw InvalidArgument(e.what());
            }
          });
          if (status.ok()) break;
          return status;
        }
        try {
          rasterize(twin::LoadSdfWorldFromString(request.sdf_text(), "sdf_text"));
        } catch (const std::exception& e) {
          return Invalid(std::string("sdf_text: ") + e.what());
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
    // Bounded: an inflation radius of 1e6 m would inflate every cell over the whole map.
    const auto in = [](double v, double lo, double hi) {
      return std::isfinite(v) && v >= lo && v <= hi;
    };
    if (request.robot_radius() != 0 && !in(request.robot_radius(), 0.01, kMaxRobotRadiusM))
      return Invalid("robot_radius must be 0 (default) or in [0.01, 1] m");
    if (request.inflation_radius() != 0 &&
        !in(request.inflation_radius(), 0.0, kMaxInflationRadiusM))
      return Invalid("inflation_radius must be 0 (default) or in [0, 5] m");
    perception::CostmapConfig costmap_config;
    if (request.robot_radius() != 0) costmap_config.robot_radius = request.robot_radius();
    if (request.inflation_radius() != 0)
      costmap_config.inflation_radius = request.inflation_radius();
    if (costmap_config.inflation_radius < costmap_config.robot_radius)
      return Invalid("inflation_radius must not be below robot_radius");
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
      for (const double v :
           {door.hinge().x(), door.hinge().y(), door.latch().x(), door.latch().y()}) {
        if (!std::isfinite(v))
          return Invalid("doors[].hinge and latch of '" + door.id() + "' must be finite");
      }
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
    const std::int64_t cells = std::int64_t(grid.geometry().size());
    if (cells > config_.max_cached_cells) {
      return Invalid("the map has " + std::to_string(cells) +
                     " cells, more than the world cache holds (" +
                     std::to_string(config_.max_cached_cells) + ")");
    }
    response->set_world_id(Insert(std::move(world), cells));
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
    if (!std::isfinite(request.time_budget()) || request.time_budget() < 0 ||
        request.time_budget() > config_.max_time_budget_s) {
      return Invalid("time_budget must be in [0, " + std::to_string(config_.max_time_budget_s) +
                     "] s (0: 1 s)");
    }
    if (!std::isfinite(request.costmap_cost_weight()) || request.costmap_cost_weight() < 0)
      return Invalid("costmap_cost_weight must be a finite number >= 0");
    planning::BasePlannerConfig config;
    if (!request.planner().empty()) config.planner = request.planner();
    double budget = request.time_budget() > 0 ? request.time_budget()
                                              : std::min(1.0, config_.max_time_budget_s);
    // Honour the request deadline: never plan past it.
    const auto deadline =
        context != nullptr ? context->deadline() : std::chrono::system_clock::time_point::max();
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
    if (context != nullptr && context->IsCancelled())
      return {StatusCode::CANCELLED, "the client cancelled the request"};
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
  std::function<ConnectionGate::Counts()> connection_counts_;
  std::atomic<int> busy_{0};
  std::mutex worlds_mutex_;
  std::map<std::string, CachedWorld> worlds_;
  std::int64_t cached_cells_{0};
  std::uint64_t use_clock_{0};
  std::int64_t evicted_{0};
  std::int64_t next_world_{0};
};

}  // namespace

void ValidateListenAddress(const NavigationServerConfig& config) {
  const std::string host = ParseListenAddress(config.listen).host;
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
  const auto at_least_one = [](const char* name, std::int64_t value) {
    if (value < 1) throw std::invalid_argument(std::string(name) + " must be >= 1");
  };
  at_least_one("max_map_cells", config.max_map_cells);
  at_least_one("max_cached_cells", config.max_cached_cells);
  at_least_one("max_worlds", config.max_worlds);
  at_least_one("max_connections", config.max_connections);
  at_least_one("max_streams_per_connection", config.max_streams_per_connection);
  at_least_one("max_message_bytes", config.max_message_bytes);
  at_least_one("max_threads", config.max_threads);
  if (!std::isfinite(config.max_time_budget_s) || config.max_time_budget_s <= 0)
    throw std::invalid_argument("max_time_budget_s must be > 0");
  for (const auto& [name, seconds] :
       {std::pair{"idle_timeout_s", config.idle_timeout_s},
        std::pair{"handshake_timeout_s", config.handshake_timeout_s},
        std::pair{"keepalive_time_s", config.keepalive_time_s},
        std::pair{"keepalive_timeout_s", config.keepalive_timeout_s}}) {
    if (!std::isfinite(seconds) || seconds <= 0 || seconds > 86400)
      throw std::invalid_argument(std::string(name) + " must be in (0, 86400] s");
  }
  if (!config.data_root.empty() && !std::filesystem::is_directory(config.data_root)) {
    throw std::invalid_argument("data root '" + config.data_root + "' is not a directory");
  }
}

struct NavigationHandlers::Impl {
  NavigationServerConfig config;
  std::unique_ptr<Service> service;
};

NavigationHandlers::NavigationHandlers(NavigationServerConfig config)
    : impl_(std::make_unique<Impl>()) {
  impl_->config = std::move(config);
  impl_->config.log = nullptr;
  impl_->service = std::make_unique<Service>(impl_->config, nullptr);
}

NavigationHandlers::~NavigationHandlers() = default;

int NavigationHandlers::Call(std::string_view rpc, std::string_view bytes) {
  Service& s = *impl_->service;
  // Parses `bytes` as the RPC's request (gRPC answers an unparsable message with INTERNAL).
  const auto call = [&](auto request, auto response, auto method) {
    if (!request.ParseFromArray(bytes.data(), int(bytes.size()))) return int(StatusCode::INTERNAL);
    return int((s.*method)(nullptr, &request, &response).error_code());
  };
  if (rpc == "LoadWorld")
    return call(v1::LoadWorldRequest{}, v1::LoadWorldResponse{}, &Service::LoadWorld);
  if (rpc == "UpdateCostmap")
    return call(v1::UpdateCostmapRequest{}, v1::UpdateCostmapResponse{}, &Service::UpdateCostmap);
  if (rpc == "UnloadWorld")
    return call(v1::UnloadWorldRequest{}, v1::UnloadWorldResponse{}, &Service::UnloadWorld);
  if (rpc == "SetDoorState")
    return call(v1::SetDoorStateRequest{}, v1::SetDoorStateResponse{}, &Service::SetDoorState);
  if (rpc == "PlanPath")
    return call(v1::PlanPathRequest{}, v1::PlanPathResponse{}, &Service::PlanPath);
  if (rpc == "ListPlanners")
    return call(v1::ListPlannersRequest{}, v1::ListPlannersResponse{}, &Service::ListPlanners);
  if (rpc == "Health") return call(v1::HealthRequest{}, v1::HealthResponse{}, &Service::Health);
  throw std::invalid_argument("no RPC '" + std::string(rpc) + "' in egress.nav.v1.Navigation");
}

const std::vector<std::string>& NavigationHandlers::Rpcs() {
  static const std::vector<std::string> rpcs = {"LoadWorld",    "UpdateCostmap", "UnloadWorld",
                                                "SetDoorState", "PlanPath",      "ListPlanners",
                                                "Health"};
  return rpcs;
}

struct NavigationServer::Impl {
  NavigationServerConfig config;
  std::unique_ptr<ConnectionGate> gate;
  std::unique_ptr<Service> service;
  std::unique_ptr<grpc::experimental::ExternalConnectionAcceptor> acceptor;
  std::unique_ptr<grpc::Server> server;
  std::once_flag shutdown;
};

NavigationServer::NavigationServer(NavigationServerConfig config)
    : impl_(std::make_unique<Impl>()) {
  ValidateListenAddress(config);
  impl_->config = std::move(config);
  const NavigationServerConfig& c = impl_->config;
  impl_->gate = std::make_unique<ConnectionGate>(c.listen, c.max_connections);
  impl_->service =
      std::make_unique<Service>(c, [gate = impl_->gate.get()] { return gate->counts(); });
  grpc::ServerBuilder builder;
  // Connections come from the gate (see connection_gate.h), not from a gRPC listening port.
  impl_->acceptor = builder.experimental().AddExternalConnectionAcceptor(
      grpc::ServerBuilder::experimental_type::ExternalConnectionType::FROM_FD,
      grpc::InsecureServerCredentials());
  builder.RegisterService(impl_->service.get());
  builder.SetMaxReceiveMessageSize(c.max_message_bytes);
  const auto ms = [](double seconds) { return int(std::min(seconds * 1000.0, 2.0e9)); };
  builder.AddChannelArgument(GRPC_ARG_MAX_CONCURRENT_STREAMS, c.max_streams_per_connection);
  builder.AddChannelArgument(GRPC_ARG_MAX_CONNECTION_IDLE_MS, ms(c.idle_timeout_s));
  builder.AddChannelArgument(GRPC_ARG_SERVER_HANDSHAKE_TIMEOUT_MS, ms(c.handshake_timeout_s));
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIME_MS, ms(c.keepalive_time_s));
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, ms(c.keepalive_timeout_s));
  grpc::ResourceQuota quota("egress-navd");
  quota.SetMaxThreads(c.max_threads);
  builder.SetResourceQuota(quota);
  impl_->server = builder.BuildAndStart();
  if (!impl_->server)
    throw std::runtime_error("cannot start the gRPC server on '" + c.listen + "'");
  impl_->gate->Start(impl_->acceptor.get());
}

NavigationServer::~NavigationServer() {
  Shutdown();
}

int NavigationServer::port() const {
  return impl_->gate->port();
}

void NavigationServer::Wait() {
  impl_->server->Wait();
}

void NavigationServer::Shutdown(std::chrono::milliseconds grace) {
  std::call_once(impl_->shutdown, [&] {
    impl_->gate->Stop();  // no new connections; calls already running finish
    impl_->server->Shutdown(std::chrono::system_clock::now() + grace);
  });
}

}  // namespace egress::navd
