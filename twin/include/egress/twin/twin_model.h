#pragma once
/// @file
/// TwinModel: the fixed part of a twin run, as MuJoCo's mjModel is to mjData. A scenario
/// compiled against its world and the robot description: the static collision geometry (one
/// merged triangle BVH for contacts; analytic boxes and a mesh BVH for rays; the convex statics),
/// the outline of walls and furniture the people steer round, each doorway's geometry, one model
/// per people behaviour, and the physics settings. It does not depend on the seed and never
/// changes once built: any number of runs (TwinWorld, one per seed) share one model, so a batch
/// compiles a scenario once and each run builds only its own state (bodies, doors, people, robot,
/// payloads, the seeded draws).
///
/// Thread safety: a model is immutable; runs on different threads may share it (Bullet only
/// reads a shared static shape during collision queries).

#include <memory>

#include "egress/hsr_interface/robot_model.h"
#include "egress/twin/scenario.h"
#include "egress/twin/world_description.h"

namespace egress::twin {

/// Physics and robot-body settings.
struct TwinConfig {
  double physics_rate_hz{240.0};
  /// The people's social terms (HM95's repulsion from each other, the robot and walls) are
  /// summed at this rate and held between [Hz]; at most crowd_rate_hz. Below it, the drive and
  /// body contact are still summed every crowd step (holding them too, at 120 Hz with 240 Hz
  /// steps, jammed the clinic's door_e for good: 11 residents left behind in 30 clinic runs
  /// against 0). At 60 Hz the 100-resident bench ran ~1.2x faster, but the study's robot trials
  /// came out otherwise in ways not yet understood (505 trials: 8 with the robot in a doorway
  /// beside a resident against 2, one robot-resident contact against none), so by default
  /// every term is summed every crowd step.
  double crowd_social_rate_hz{120.0};
  /// The people (their decisions and the social force model's sums and velocities) are stepped
  /// at this rate [Hz]: physics_rate_hz divided by a whole number, at least
  /// crowd_social_rate_hz. Between their steps each body is carried on at its velocity every
  /// physics step, so a person moves as smoothly as the robot (what Bullet's contacts and the
  /// sensors see); over one crowd step the model integrates the same as at the lower rate. The
  /// people are most of a crowd run's cost: at 120 Hz (every other physics step) the
  /// 100-resident bench runs ~15 % faster, and a dense group's flow through a door stays in
  /// the hydraulic band (EvacueesTest); at 80 Hz it neared the band's floor and residents were
  /// left behind in the two wards without the robot.
  double crowd_rate_hz{120.0};
  double base_max_linear_acceleration{1.0};   ///< [m/s²]
  double base_max_angular_acceleration{2.0};  ///< [rad/s²]
  double base_max_linear_speed{0.8};          ///< [m/s] (HSR: ~3 km/h)
  double base_max_angular_speed{1.5};         ///< [rad/s]
  double base_command_timeout{0.5};           ///< Velocity command held this long [s]
  double robot_mass{37.0};                    ///< [kg]
  double base_max_force{100.0};               ///< Drive force limit of the wheels [N]
  double grasp_tolerance{0.02};               ///< Lateral centring error a grasp accepts [m]
  double person_hold_force{100.0};            ///< Force a person holds a door with [N]
  double door_crossed_open_angle_deg{60.0};   ///< "Open when crossed" threshold [deg]
  /// A person's Bullet body is awake only within this of the robot's base or a payload [m] (the
  /// bodies people can touch there); asleep, Bullet neither derives its velocity nor updates its
  /// bounds, most of what a crowd costs it, and waking it gives it the velocity and bounds it
  /// would have had awake, so runs are the same (infinity: always awake). The arm reaches ~1 m
  /// from the base and a body is at most ~0.7 m across: at least 2 m.
  double person_body_awake_reach{3.0};
  /// @throws InvalidArgument naming the field for a physics rate below 60 Hz, a crowd rate that
  /// does not divide it or a crowd social rate above the crowd rate, a non-positive or
  /// non-finite limit, or a person body awake reach under 2 m.
  void Validate() const;
};

class TwinModel {
 public:
  /// Compiles `scenario` against `world` for the robot `robot_model`.
  /// @throws LoadError if the scenario does not fit the world; InvalidArgument for a null robot
  /// model or a bad config.
  TwinModel(Scenario scenario, WorldDescription world,
            std::shared_ptr<const RobotModel> robot_model, TwinConfig config = {});
  ~TwinModel();
  TwinModel(const TwinModel&) = delete;
  TwinModel& operator=(const TwinModel&) = delete;

  /// The scenario with its building's defaults applied (ApplyBuildingDefaults).
  const Scenario& scenario() const;
  const WorldDescription& world() const;
  /// The scenario's building (DescribeScenarioBuilding).
  const BuildingDescription& building() const { return building_; }
  const std::shared_ptr<const RobotModel>& robot_model() const;
  const TwinConfig& config() const;
  double step_size() const;  ///< [s] 1 / physics_rate_hz

  /// The compiled geometry (defined in twin/src: only the twin's own code reads it).
  struct Compiled;
  const Compiled& compiled() const;

 private:
  Scenario scenario_;
  WorldDescription world_;
  BuildingDescription building_;
  std::shared_ptr<const RobotModel> robot_model_;
  TwinConfig config_;
  std::unique_ptr<Compiled> compiled_;
};

}  // namespace egress::twin
