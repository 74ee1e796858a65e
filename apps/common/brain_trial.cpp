#include "brain_trial.h"

#include "egress/hsr_interface/error.h"
#include "egress/twin/twin_robot.h"
#include "sdf_map.h"

namespace egress::apps {

behavior::MissionMap BuildMissionMap(const twin::WorldDescription& world,
                                     const twin::BuildingDescription& building,
                                     const std::vector<Eigen::Vector2d>& cover, double resolution) {
  std::vector<Eigen::Vector2d> points = cover;
  for (const auto& p : building.places)
    points.push_back(p.X_WP.translation());
  SdfMap sdf = RasterizeSdfWorld(world, resolution, 20'000'000, points, kPlaceMapMarginM);
  behavior::MissionMap map;
  map.grid = std::move(sdf.grid);
  map.doorways = sdf.doors;
  for (const auto& doorway : sdf.doors) {
    perception::DoorModel door;
    door.id = doorway.id;
    door.p_MHinge = doorway.p_MHinge;
    door.p_MLatch = doorway.p_MLatch;
    door.swing_sign = doorway.swing_sign;
    if (const twin::BuildingDoor* d = building.FindDoor(doorway.id)) {
      door.max_open_angle = d->max_open_angle;
      if (d->glass) map.glass_doors.insert(d->model);
    }
    map.doors.push_back(door);
  }
  for (const auto& a : building.actuators) {
    behavior::MapActuator actuator;
    actuator.id = a.model;
    actuator.door = a.door;
    actuator.type = a.kind == twin::ActuatorKind::kPushButton
                        ? planning::ButtonType::kPushButton
                        : planning::ButtonType::kProximityPlate;
    actuator.p_M = a.p_W;
    actuator.n_M = a.n_W;
    actuator.protrusion = a.protrusion;
    map.actuators.push_back(actuator);
  }
  for (const auto& p : building.places)
    map.places.push_back({p.name, p.kind, p.X_WP, p.has_yaw});
  map.Validate();
  return map;
}

std::unique_ptr<behavior::Executive> MakeScenarioExecutive(
    const twin::Scenario& scenario, const twin::WorldDescription& world,
    const twin::TwinWorld& twin_world, std::shared_ptr<const RobotModel> model,
    const behavior::ExecutiveConfig& config) {
  if (!scenario.mission) {
    throw InvalidArgument(StrCat(scenario.source.string(),
                                 ": no 'mission' section: the robot brain needs a tree to run"));
  }
  behavior::MissionTree tree;
  tree.file = scenario.mission->tree_file;
  tree.tree_id = scenario.mission->tree_id;
  tree.blackboard = scenario.mission->blackboard;
  // A mission's {goal} defaults to the scenario's robot goal: the place, or the pose.
  if (tree.blackboard.count("goal") == 0) {
    if (!scenario.goal_place.empty()) {
      tree.blackboard["goal"] = scenario.goal_place;
    } else if (scenario.goal) {
      tree.blackboard["goal"] =
          StrCat(scenario.goal->x, ";", scenario.goal->y, ";", scenario.goal->yaw);
    }
  }
  try {
    // A door the scenario says has no operator keeps no actuator on the map (as before the
    // building description: the map says what works).
    twin::BuildingDescription building = twin::DescribeScenarioBuilding(scenario, world);
    for (const auto& spec : scenario.doors) {
      if (spec.kind != twin::OperatorKind::kManual) continue;
      std::erase_if(building.actuators,
                    [&](const twin::BuildingActuator& a) { return a.door == spec.door; });
    }
    std::vector<Eigen::Vector2d> cover{scenario.robot_start.translation()};
    if (scenario.goal) cover.push_back(scenario.goal->translation());
    return std::make_unique<behavior::Executive>(std::move(model),
                                                 BuildMissionMap(world, building, cover), tree,
                                                 twin_world.robot_pose(), config);
  } catch (const std::exception& e) {
    throw InvalidArgument(StrCat(scenario.source.string(), ":", scenario.mission->tree_line,
                                 ": mission.tree '", tree.file.string(), "': ", e.what()));
  }
}

std::shared_ptr<const twin::TwinModel> TwinModelForSeed(
    std::shared_ptr<const twin::TwinModel> twin_model, std::uint64_t seed) {
  // A scenario family: this seed's variant is a scenario of its own.
  if (!twin_model->scenario().randomize.DrawsVariants()) return twin_model;
  return std::make_shared<const twin::TwinModel>(
      twin::DrawScenarioVariant(twin_model->scenario(), twin_model->building(), seed),
      twin_model->world(), twin_model->robot_model(), twin_model->config());
}

BrainTrial RunBrainTrial(const twin::Scenario& scenario, const twin::WorldDescription& world,
                         std::uint64_t seed, std::shared_ptr<const RobotModel> model,
                         const BrainTrialOptions& options) {
  return RunBrainTrial(std::make_shared<const twin::TwinModel>(scenario, world, std::move(model),
                                                               options.twin_config),
                       seed, options);
}

BrainTrial RunBrainTrial(std::shared_ptr<const twin::TwinModel> twin_model, std::uint64_t seed,
                         const BrainTrialOptions& options) {
  ThrowUnless(twin_model != nullptr, "RunBrainTrial: the twin model is null");
  twin_model = TwinModelForSeed(std::move(twin_model), seed);
  BrainTrial trial;
  trial.world = std::make_unique<twin::TwinWorld>(twin_model, seed);
  trial.brain = MakeScenarioExecutive(twin_model->scenario(), twin_model->world(), *trial.world,
                                      twin_model->robot_model(), options.config);
  if (options.on_brain) options.on_brain(*trial.brain);
  twin::TwinRobot robot(trial.world.get());
  twin::RunOptions run = options.run;
  run.control_period = 1.0 / options.config.control_rate_hz;
  const twin::TwinWorld& w = *trial.world;
  const behavior::Executive& brain = *trial.brain;
  if (options.annotate) run.annotate = [&] { return options.annotate(w, brain); };
  // With on_sense, the brain reads the robot through a port that shows each reading to it.
  trial.result = twin::RunScenario(
      robot,
      [&](RobotPort& port) {
        ObservedPort observed(port, options.on_sense);
        const bool more =
            trial.brain->Step(options.on_sense ? static_cast<RobotPort&>(observed) : port);
        if (options.after_step) options.after_step(w, brain);
        return more;
      },
      run);
  return trial;
}

}  // namespace egress::apps
