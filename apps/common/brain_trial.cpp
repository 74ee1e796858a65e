#include "brain_trial.h"

#include "egress/hsr_interface/error.h"
#include "egress/twin/twin_robot.h"
#include "sdf_map.h"

namespace egress::apps {

behavior::MissionMap BuildMissionMap(const twin::WorldDescription& world,
                                     const twin::Scenario& scenario, double resolution) {
  SdfMap sdf = RasterizeSdfWorld(world, resolution, 20'000'000);
  behavior::MissionMap map;
  map.grid = std::move(sdf.grid);
  map.doorways = sdf.doors;
  for (const auto& doorway : sdf.doors) {
    perception::DoorModel door;
    door.id = doorway.id;
    door.p_MHinge = doorway.p_MHinge;
    door.p_MLatch = doorway.p_MLatch;
    door.swing_sign = doorway.swing_sign;
    if (const twin::DoorDescription* d = world.FindDoor(doorway.id))
      door.max_open_angle = d->max_open_angle;
    map.doors.push_back(door);
  }
  for (const auto& spec : scenario.doors) {
    if (spec.kind == twin::OperatorKind::kManual) continue;
    for (const auto& id : spec.actuators) {
      const auto shapes = world.ShapesOfModel(id);
      ThrowUnless(!shapes.empty(), scenario.source.string(), ": actuator '", id,
                  "' has no shape in ", world.source.string());
      const twin::ShapeDescription& shape = *shapes.front();
      const perception::DoorModel* door = map.FindDoor(spec.door);
      ThrowUnless(door != nullptr, scenario.source.string(), ": door '", spec.door,
                  "' is not a door of ", world.source.string());
      behavior::MapActuator actuator;
      actuator.id = id;
      actuator.door = spec.door;
      actuator.type = spec.kind == twin::OperatorKind::kPushButton
                          ? planning::ButtonType::kPushButton
                          : planning::ButtonType::kProximityPlate;
      const Eigen::Vector3d centre = shape.X_WS.translation();
      const Eigen::Vector2d along = (door->p_MLatch - door->p_MHinge).normalized();
      Eigen::Vector2d n(-along.y(), along.x());
      if (n.dot(centre.head<2>() - door->p_MHinge) < 0) n = -n;
      actuator.n_M = Eigen::Vector3d(n.x(), n.y(), 0.0);
      // The face: half the box's extent along the normal in front of its centre.
      const Eigen::Matrix3d& R = shape.X_WS.rotation();
      double half = 0.0;
      for (int i = 0; i < 3; ++i)
        half += std::abs(actuator.n_M.dot(R.col(i))) * shape.box_size[i] / 2;
      actuator.p_M = centre + actuator.n_M * half;
      actuator.protrusion = 2 * half;  // mounted on the wall's surface
      map.actuators.push_back(actuator);
    }
  }
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
  try {
    return std::make_unique<behavior::Executive>(std::move(model), BuildMissionMap(world, scenario),
                                                 tree, twin_world.robot_pose(), config);
  } catch (const std::exception& e) {
    throw InvalidArgument(StrCat(scenario.source.string(), ":", scenario.mission->tree_line,
                                 ": mission.tree '", tree.file.string(), "': ", e.what()));
  }
}

BrainTrial RunBrainTrial(const twin::Scenario& scenario, const twin::WorldDescription& world,
                         std::uint64_t seed, std::shared_ptr<const RobotModel> model,
                         const BrainTrialOptions& options) {
  return RunBrainTrial(std::make_shared<const twin::TwinModel>(scenario, world, std::move(model)),
                       seed, options);
}

BrainTrial RunBrainTrial(std::shared_ptr<const twin::TwinModel> twin_model, std::uint64_t seed,
                         const BrainTrialOptions& options) {
  ThrowUnless(twin_model != nullptr, "RunBrainTrial: the twin model is null");
  BrainTrial trial;
  trial.world = std::make_unique<twin::TwinWorld>(twin_model, seed);
  trial.brain = MakeScenarioExecutive(twin_model->scenario(), twin_model->world(), *trial.world,
                                      twin_model->robot_model(), options.config);
  twin::TwinRobot robot(trial.world.get());
  twin::RunOptions run = options.run;
  run.control_period = 1.0 / options.config.control_rate_hz;
  const twin::TwinWorld& w = *trial.world;
  const behavior::Executive& brain = *trial.brain;
  if (options.annotate) run.annotate = [&] { return options.annotate(w, brain); };
  trial.result = twin::RunScenario(
      robot,
      [&](RobotPort& port) {
        const bool more = trial.brain->Step(port);
        if (options.after_step) options.after_step(w, brain);
        return more;
      },
      run);
  return trial;
}

}  // namespace egress::apps
