#pragma once
/// @file
/// A twin scenario run by the robot brain: the building map the brain gets (the world's floor plan
/// and doors, the scenario's actuators), the executive built for the scenario's mission, and one
/// RunBrainTrial that `egress sim run`, `egress sim batch` and the scenario tests all use. The
/// control period is the executive's own (ExecutiveConfig::control_rate_hz).

#include <cstdint>
#include <functional>
#include <memory>

#include "egress/behavior/executive.h"
#include "egress/behavior/mission_map.h"
#include "egress/twin/scenario.h"
#include "egress/twin/twin_run.h"
#include "egress/twin/twin_world.h"
#include "egress/twin/world_description.h"

namespace egress::apps {

/// Free space the brain's map keeps round a place outside the building's walls [m] (beyond the
/// exit): the robot must still be on its map, and localized, where the route leads out.
inline constexpr double kPlaceMapMarginM = 2.0;

/// The building map the robot brain gets: the world's floor plan (RasterizeSdfWorld, grown to
/// cover every place and `cover` point by kPlaceMapMarginM), its doors, the building's actuators
/// (each face and facing from its own box) and named places. The scenario's extra obstacles, people
/// and payloads are not in it: the robot perceives them. @throws InvalidArgument for a map the grid
/// cannot hold.
behavior::MissionMap BuildMissionMap(const twin::WorldDescription& world,
                                     const twin::BuildingDescription& building,
                                     const std::vector<Eigen::Vector2d>& cover = {},
                                     double resolution = 0.05);

}  // namespace egress::apps

namespace egress::apps {

/// The robot brain for a twin run of `scenario`: its mission tree and blackboard (whose {goal}
/// defaults to the scenario's robot goal, a place or a pose), the building map, and as the
/// initial pose the twin's start (what an operator's initial pose estimate
/// gives a real robot; after that the brain localizes on odometry alone).
/// @throws InvalidArgument / LogicError naming the file for a scenario without a mission, a bad
/// tree or an unknown node.
std::unique_ptr<behavior::Executive> MakeScenarioExecutive(const twin::Scenario& scenario,
                                                           const twin::WorldDescription& world,
                                                           const twin::TwinWorld& twin_world,
                                                           std::shared_ptr<const RobotModel> model,
                                                           const behavior::ExecutiveConfig& config);

struct BrainTrialOptions {
  behavior::ExecutiveConfig config;
  /// The twin's physics and crowd settings (RunBrainTrial from a scenario; a compiled model
  /// carries its own).
  twin::TwinConfig twin_config;
  /// How the twin runs (duration, trace, progress); its control_period is replaced by the
  /// executive's 1 / config.control_rate_hz.
  twin::RunOptions run;
  /// Called once the brain exists, before the run (attaching a .btlog writer or a Groot2
  /// publisher to its tree). What it attaches must be detached before the trial is destroyed.
  std::function<void(behavior::Executive&)> on_brain;
  /// Called after every control step (ground-truth probes, debugging output).
  std::function<void(const twin::TwinWorld&, const behavior::Executive&)> after_step;
  /// Called with what the brain reads of the robot at each step (recording a run as a bag).
  std::function<void(const SensorSnapshot&)> on_sense;
  /// What each trace sample shows of the brain (the running action, its path, the costmap).
  std::function<twin::TraceAnnotation(const twin::TwinWorld&, const behavior::Executive&)> annotate;
};

/// A RobotPort that passes everything to `robot` and shows each reading to `see` (recording a
/// run). Both must outlive it.
class ObservedPort final : public RobotPort {
 public:
  ObservedPort(RobotPort& robot, const std::function<void(const SensorSnapshot&)>& see)
      : robot_(robot), see_(see) {}
  const Clock& clock() const override { return robot_.clock(); }

 protected:
  SensorSnapshot DoSense() override {
    SensorSnapshot s = robot_.Sense();
    if (see_) see_(s);
    return s;
  }
  void DoSendBaseVelocity(const Twist2& V) override { robot_.SendBaseVelocity(V); }
  void DoSendArmTrajectory(const JointTrajectory& t) override { robot_.SendArmTrajectory(t); }
  void DoSendGripperCommand(const GripperCommand& c) override { robot_.SendGripperCommand(c); }
  void DoSendHeadCommand(const HeadCommand& c) override { robot_.SendHeadCommand(c); }

 private:
  RobotPort& robot_;
  const std::function<void(const SensorSnapshot&)>& see_;
};

/// The model a trial of `seed` runs: `twin_model` itself, or for a scenario family (randomize)
/// the seed's variant of it.
std::shared_ptr<const twin::TwinModel> TwinModelForSeed(
    std::shared_ptr<const twin::TwinModel> twin_model, std::uint64_t seed);

/// The twin, the brain and the judge's verdict of one trial.
struct BrainTrial {
  std::unique_ptr<twin::TwinWorld> world;
  std::unique_ptr<behavior::Executive> brain;
  twin::RunResult result;
};

/// Runs a compiled scenario with `seed`, driven by the brain (on the model's robot
/// description), to the end of its mission or time limit. Trials of one scenario share its
/// TwinModel: only the run's own state is built per seed.
/// @throws what the tree or executive throw, naming the file or field.
BrainTrial RunBrainTrial(std::shared_ptr<const twin::TwinModel> twin_model, std::uint64_t seed,
                         const BrainTrialOptions& options = {});
/// Compiles `scenario` and runs it once (as above).
/// @throws what the scenario, world, tree or executive throw, naming the file or field.
BrainTrial RunBrainTrial(const twin::Scenario& scenario, const twin::WorldDescription& world,
                         std::uint64_t seed, std::shared_ptr<const RobotModel> model,
                         const BrainTrialOptions& options = {});

}  // namespace egress::apps
