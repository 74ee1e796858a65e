#include "egress/twin/twin_model.h"

#include <cmath>

#include "people/person_behavior.h"
#include "twin_model_compiled.h"

namespace egress::twin {

using namespace world_detail;

void TwinConfig::Validate() const {
  ThrowUnless(std::isfinite(physics_rate_hz) && physics_rate_hz >= 60.0,
              "TwinConfig: physics_rate_hz must be at least 60 (got ", physics_rate_hz, ")");
  // A whole number of physics steps per crowd step (to a part in a million).
  const double per_crowd_step = physics_rate_hz / crowd_rate_hz;
  ThrowUnless(std::isfinite(crowd_rate_hz) && crowd_rate_hz > 0.0 &&
                  crowd_rate_hz <= physics_rate_hz &&
                  std::abs(per_crowd_step - std::round(per_crowd_step)) < 1e-6 * per_crowd_step,
              "TwinConfig: crowd_rate_hz must be physics_rate_hz (", physics_rate_hz,
              ") divided by a whole number (got ", crowd_rate_hz, ")");
  ThrowUnless(std::isfinite(crowd_social_rate_hz) && crowd_social_rate_hz > 0.0 &&
                  crowd_social_rate_hz <= crowd_rate_hz,
              "TwinConfig: crowd_social_rate_hz must be positive and at most crowd_rate_hz (got ",
              crowd_social_rate_hz, ", crowd_rate_hz ", crowd_rate_hz, ")");
  ThrowUnless(person_body_awake_reach >= 2.0,
              "TwinConfig: person_body_awake_reach must be at least 2 m (the arm's reach and a "
              "body's size; infinity: always awake) (got ",
              person_body_awake_reach, ")");
  const std::pair<const char*, double> positive[] = {
      {"base_max_linear_acceleration", base_max_linear_acceleration},
      {"base_max_angular_acceleration", base_max_angular_acceleration},
      {"base_max_linear_speed", base_max_linear_speed},
      {"base_max_angular_speed", base_max_angular_speed},
      {"base_command_timeout", base_command_timeout},
      {"robot_mass", robot_mass},
      {"base_max_force", base_max_force},
      {"grasp_tolerance", grasp_tolerance},
      {"person_hold_force", person_hold_force},
      {"door_crossed_open_angle_deg", door_crossed_open_angle_deg}};
  for (const auto& [name, value] : positive) {
    ThrowUnless(std::isfinite(value) && value > 0.0, "TwinConfig: ", name,
                " must be positive and finite (got ", value, ")");
  }
}

TwinModel::Compiled::Compiled() = default;
TwinModel::Compiled::~Compiled() = default;

namespace {

// Static boxes, planes and meshes into the merged contact mesh (and boxes and planes into the
// analytic ray boxes, meshes into the ray mesh); cylinders and spheres stay convex shapes.
void CompileStatics(const Scenario& scenario, const WorldDescription& world,
                    TwinModel::Compiled* c) {
  bool has_floor = false;
  auto merged = std::make_unique<btTriangleMesh>(true, false);
  auto ray_mesh = std::make_unique<btTriangleMesh>(true, false);
  auto add = [&](const ShapeDescription& s) {
    const bool floor = s.kind == ShapeKind::kPlane;
    has_floor = has_floor || floor;
    c->entities.push_back({floor ? EntityKind::kFloor : EntityKind::kStatic, s.model, -1});
    const int e = int(c->entities.size()) - 1;
    if (!floor) AppendFootprint(s, e, &c->walls);
    if (AppendTriangles(s, merged.get())) {
      c->static_triangle_entity.resize(std::size_t(merged->getNumTriangles()), e);
      if (s.kind == ShapeKind::kBox || s.kind == ShapeKind::kPlane) {
        RayBox box;
        box.R_SW = s.X_WS.rotation().transpose();
        box.p_WS = s.X_WS.translation();
        box.half = s.kind == ShapeKind::kBox
                       ? Eigen::Vector3d(s.box_size / 2)
                       : Eigen::Vector3d(s.plane_size.x() > 0 ? s.plane_size.x() / 2 : 50.0,
                                         s.plane_size.y() > 0 ? s.plane_size.y() / 2 : 50.0, 0.0);
        box.entity = e;
        if (s.kind == ShapeKind::kPlane) c->ray_planes.push_back(c->ray_boxes.size());
        c->ray_boxes.push_back(box);
      } else {
        AppendTriangles(s, ray_mesh.get());
        c->ray_triangle_entity.resize(std::size_t(ray_mesh->getNumTriangles()), e);
      }
      return;
    }
    c->convex_statics.push_back({MakeConvexShape(s), s.X_WS, floor, e});
  };
  for (const auto& s : world.shapes)
    add(s);
  for (const auto& s : scenario.obstacles)
    add(s);
  if (!has_floor) {
    ShapeDescription ground;
    ground.model = "ground_plane";
    ground.kind = ShapeKind::kPlane;
    add(ground);
  }
  c->wall_cells = WallCells(c->walls, SocialForceModel().WallReach());
  for (const RayBox& box : c->ray_boxes) {
    const Eigen::Vector2d half_W = (box.R_SW.transpose().cwiseAbs() * box.half).head<2>();
    c->ray_box_extents.emplace_back(box.p_WS.head<2>() - half_W, box.p_WS.head<2>() + half_W);
  }
  c->ray_box_bins.Build(c->ray_box_extents, kRayBinCellM);
  if (merged->getNumTriangles() > 0) {
    c->static_mesh_shape = std::make_unique<btBvhTriangleMeshShape>(merged.get(), true);
    c->static_mesh = std::move(merged);
  }
  if (ray_mesh->getNumTriangles() > 0) {
    c->ray_mesh_shape = std::make_unique<btBvhTriangleMeshShape>(ray_mesh.get(), true);
    c->ray_mesh = std::move(ray_mesh);
  }
}

void CompileDoors(const Scenario& scenario, const WorldDescription& world, TwinModel::Compiled* c) {
  for (const DoorDescription& d : world.doors) {
    DoorModel door;
    door.desc = &d;
    for (const auto& spec : scenario.doors) {
      if (spec.door == d.name) door.spec = spec;
    }
    door.reach = d.LeafReach();
    const Eigen::Vector3d edge = d.CalcFreeEdge(0.0);
    door.along = (edge - d.p_WH).head<2>().normalized();
    door.centre = d.p_WH.head<2>() + door.along * door.reach / 2;
    door.normal = Eigen::Vector2d(-door.along.y(), door.along.x());
    if (d.max_open_angle > 0.0) {
      const Eigen::Vector2d open_edge = d.CalcFreeEdge(std::min(d.max_open_angle, 0.5)).head<2>();
      door.swing_side = (open_edge - door.centre).dot(door.normal) >= 0.0 ? 1.0 : -1.0;
    }
    c->doors.push_back(std::move(door));
  }
}

}  // namespace

TwinModel::TwinModel(Scenario scenario, WorldDescription world,
                     std::shared_ptr<const RobotModel> robot_model, TwinConfig config)
    : scenario_(std::move(scenario)),
      world_(std::move(world)),
      robot_model_(std::move(robot_model)),
      config_(config),
      compiled_(std::make_unique<Compiled>()) {
  ThrowUnless(robot_model_ != nullptr, "TwinModel: robot model is null");
  config_.Validate();
  building_ = DescribeScenarioBuilding(scenario_, world_);
  ApplyBuildingDefaults(building_, &scenario_);
  if (scenario_.robot_off_scene) scenario_.robot_start = OffScenePose(world_);
  scenario_.ValidateAgainst(world_);
  CompileStatics(scenario_, world_, compiled_.get());
  CompileDoors(scenario_, world_, compiled_.get());
  for (const auto& spec : scenario_.people) {
    auto& behavior = compiled_->behavior_models[spec.behavior];
    if (!behavior) behavior = people::MakePersonBehavior(spec.behavior);
  }
}

TwinModel::~TwinModel() = default;

const Scenario& TwinModel::scenario() const {
  return scenario_;
}
const WorldDescription& TwinModel::world() const {
  return world_;
}
const std::shared_ptr<const RobotModel>& TwinModel::robot_model() const {
  return robot_model_;
}
const TwinConfig& TwinModel::config() const {
  return config_;
}
double TwinModel::step_size() const {
  return 1.0 / config_.physics_rate_hz;
}
const TwinModel::Compiled& TwinModel::compiled() const {
  return *compiled_;
}

}  // namespace egress::twin
