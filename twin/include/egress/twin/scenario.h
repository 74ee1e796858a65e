#pragma once
/// @file
/// A twin scenario: which world, where the robot starts and should go, which door operators,
/// people, payloads and extra obstacles, what is randomized, the time limit and the success
/// predicates. Read from YAML (schema in worlds/README.md); every error names the file, line
/// and field. A scenario plus a seed fully determines a twin run.

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "egress/hsr_interface/geometry.h"
#include "egress/twin/building.h"
#include "egress/twin/world_description.h"

namespace egress::twin {

/// A closed interval to draw from uniformly; min == max is a fixed value.
struct Range {
  double min{0.0};
  double max{0.0};
  double Sample(std::mt19937_64& rng) const;
};

/// ADA low-energy operator timing (ANSI/BHMA A156.19; social_sim_notes §4.4) and limits.
struct DoorTiming {
  double open_angle_deg{80.0};  ///< Angle the operator opens to (back-check) [deg].
  double open_time_s{3.5};      ///< 0 → open_angle [s].
  double hold_open_s{10.0};     ///< Held open after reaching open_angle [s] (paper's window).
  double close_time_s{3.5};     ///< 90° → 10° [s] (slower is allowed, faster is not).
  double latch_time_s{1.5};     ///< 10° → 0° [s].
  double stall_force{67.0};     ///< Force to stop the moving leaf at its latch edge [N].
};

/// How an actuator opens its door.
enum class OperatorKind {
  kPushButton,      ///< Press a button: fingertip travels the stroke with force < the limit.
  kProximityPlate,  ///< Wave: a hand within the sensing range of the plate.
  kManual,          ///< No operator: the door moves only when pushed or pulled.
};

/// One door and its operator.
struct DoorOperatorSpec {
  std::string door;  ///< SDF model name of the hinged door.
  /// SDF model names of its buttons or plates, all of the operator's kind: one on each side of
  /// the wall is usual for ADA doors (empty for kManual).
  std::vector<std::string> actuators;
  OperatorKind kind{OperatorKind::kPushButton};
  bool glass{false};        ///< Glass leaf: the laser sees it only near normal incidence.
  bool glass_given{false};  ///< `glass` was in the file (else the building's word stands).
  DoorTiming timing;
  double button_stroke{0.004};      ///< Push-button travel that counts as a press [m].
  double button_max_force{22.0};    ///< Force above which a press is refused [N].
  double button_spring_force{5.0};  ///< Spring force at full stroke [N].
  double proximity_range{0.3};      ///< Proximity-plate sensing range [m].
  /// Times [s] at which someone else (out of the scene) operates the door: fault injection and
  /// staged scenarios. These are not the robot's presses.
  std::vector<double> open_at;
};

enum class PersonBehavior { kCrossDoorway, kHoldDoor, kWalkPast, kApproachAndWait, kEvacuate };
std::string_view ToString(PersonBehavior behavior);

/// When a person starts its behavior.
struct TriggerSpec {
  enum class Kind { kImmediately, kAtTime, kRobotWithin, kEvent };
  Kind kind{Kind::kImmediately};
  double value{0.0};  ///< Time [s] or distance [m].
  std::string event;  ///< Event name, e.g. "button_pressed:door_a" or "door_opened:door_a".
};

/// A person (or, for kEvacuate, a group of `count` people around `start`).
struct PersonSpec {
  std::string name;
  PersonBehavior behavior{PersonBehavior::kCrossDoorway};
  Eigen::Vector2d start{Eigen::Vector2d::Zero()};  ///< In W [m].
  Eigen::Vector2d goal{Eigen::Vector2d::Zero()};   ///< Final goal in W [m].
  std::vector<Eigen::Vector2d> via;  ///< Extra waypoints before the goal (walk_past, ...).
  /// approach_and_wait: where they walk after the wait (none: they stay at the goal).
  std::optional<Eigen::Vector2d> leave;
  std::string door;       ///< Door the behavior is about (cross/hold/evacuate).
  Range speed{1.2, 1.4};  ///< Desired walking speed [m/s].
  TriggerSpec trigger;
  double hold_angle_deg{80.0};  ///< hold_door: opening angle to hold the leaf at [deg].
  double hold_duration{8.0};    ///< hold_door: time to hold it [s]; approach_and_wait: wait.
  int count{1};                 ///< evacuate: group size.
  double radius{0.25};          ///< Body radius [m].
  /// evacuate: the group's mobility mix, class name (mobility.h) -> share (normalized); each
  /// member's class is drawn by the run's seed and sets their speed, size and whether they can
  /// operate a door's actuator. Empty: everyone walks at `speed` with `radius` and operates.
  std::vector<std::pair<std::string, double>> mobility;
  /// evacuate: the exit route's doors in order (`route:`); empty: `door` alone.
  std::vector<std::string> route_doors;
};

enum class PayloadKind { kWaterBottle, kFlashlight };
std::string_view ToString(PayloadKind kind);

struct PayloadSpec {
  std::string name;
  PayloadKind kind{PayloadKind::kWaterBottle};
  Pose3 X_WP;  ///< Pose of the payload's centre (bottle upright, flashlight along x).
};

/// Sensor and detector settings (defaults in the comments; all overridable per scenario).
struct SensorConfig {
  double laser_rate_hz{10.0};
  double laser_fov_deg{270.0};
  double laser_step_deg{0.25};
  double laser_range_min{0.05};
  double laser_range_max{20.0};
  double laser_noise{0.01};                    ///< Range noise s.d. [m].
  double laser_glass_max_incidence_deg{15.0};  ///< Glass returns only closer to normal.
  double laser_latency_s{0.0};
  double depth_rate_hz{5.0};
  int depth_width{80};
  int depth_height{60};
  double depth_hfov_deg{58.0};
  double depth_range_max{10.0};
  double depth_noise_coeff{0.001};  ///< Depth noise s.d. = coeff * z² [m].
  double depth_latency_s{0.0};
  double odometry_rate_hz{50.0};
  double odometry_noise{0.01};       ///< Relative speed noise (s.d. of a multiplicative factor).
  double odometry_yaw_drift{0.002};  ///< Constant yaw-rate bias [rad/s].
  double detector_rate_hz{8.0};
  Range detector_latency_s{0.125, 0.2};
  double detector_miss_rate{0.02};
  double detector_false_positive_rate{0.02};  ///< Per frame.
  double detector_min_visible{0.35};          ///< Drop objects less visible than this fraction.
  double detector_lighting{1.0};              ///< Scene lighting factor in (0, 1].
  int detector_visibility_samples{12};        ///< Ray-cast samples per object.
};

/// A fault injected into a run (`faults:` in the scenario): what goes wrong and when. Start and
/// duration are drawn per seed from their ranges (a pure function of scenario and seed). The
/// twin applies them; the brain is not told (it must notice).
struct FaultSpec {
  enum class Kind {
    kLaserDropout,     ///< No scans during the window.
    kCameraBlackout,   ///< No depth images and no detections during the window.
    kDetectorLatency,  ///< Detections made in the window arrive `latency_s` later.
    kOdometrySlip,     ///< Odometry reports `odometry_scale` times the true motion in the window.
    kKidnap,           ///< At `start` the robot is moved by `offset` (in W) if the spot is free.
    kDoorClosesEarly,  ///< At `start`, `door`'s operator starts closing, whatever its hold.
    kDoorRefuses,      ///< `door` ignores presses and waves during the window.
    kGraspSlip,        ///< At `start`, a payload in the gripper slips out (if one is held).
  };
  Kind kind{Kind::kLaserDropout};
  Range start;     ///< [s] simulated time.
  Range duration;  ///< [s] for window faults; 0 for the instantaneous ones.
  double latency_s{1.0};
  double odometry_scale{1.5};
  Pose2 offset;      ///< kKidnap: [m, m, rad] added to the true pose in W.
  std::string door;  ///< kDoorClosesEarly, kDoorRefuses.
  int line{0};       ///< In the scenario file, for messages.
  /// True for a fault that happens at an instant (kidnap, door closing early, grasp slip).
  bool Instantaneous() const;
};
/// laser_dropout, camera_blackout, detector_latency, odometry_slip, kidnap, door_closes_early,
/// door_refuses, grasp_slip (the file's names).
std::string_view ToString(FaultSpec::Kind kind);

/// A success predicate the judge evaluates at the end of a run.
struct PredicateSpec {
  enum class Kind {
    kReachGoal,            ///< Robot within goal tolerance at the end (or ever, see judge).
    kCrossDoor,            ///< Robot's centre crossed `door`'s plane.
    kDoorOpenWhenCrossed,  ///< At each crossing the leaf was open >= 60°.
    kButtonPressed,        ///< `door`'s actuator was pressed at least once.
    kButtonNotPressed,     ///< ... never.
    kPayloadHeld,          ///< `payload` in the gripper at the end.
    kPayloadDelivered,     ///< `payload` within `radius` of `target` (xy) at the end, released,
                           ///< its centre at least `min_z` high (on a table, not the floor).
    kNoPersonContact,      ///< No robot–person contact.
    kNoDoorStrike,         ///< The robot's body or arm never touched a door leaf.
    kNoContactWith,        ///< Neither the robot nor what it holds ever touched `model`.
    kWithinTimeLimit,      ///< Finished before the time limit (always checked).
  };
  Kind kind{Kind::kReachGoal};
  std::string door;
  std::string payload;
  std::string model;  ///< A world model or scenario obstacle, for kNoContactWith.
  Eigen::Vector2d target{Eigen::Vector2d::Zero()};
  double radius{0.3};
  double min_z{-1e9};  ///< [m] for kPayloadDelivered
};
std::string ToString(const PredicateSpec& predicate);

/// Randomization applied per seed (zero ranges = no randomization).
struct RandomizeSpec {
  Range robot_dx, robot_dy, robot_dyaw;  ///< Offsets added to the robot's start [m, rad].
  double payload_xy{0.0};                ///< Payload xy jitter half-width [m].
  Range hold_open_s;                     ///< Overrides doors' hold time when non-zero.
  Range hold_angle_deg;  ///< Overrides hold_door people's hold angle when non-zero [deg].
  /// Each person starts this long after their trigger's moment: the start time, the robot's
  /// coming within reach, or the event's first firing [s].
  Range person_delay_s;
  Range person_speed_scale{1.0, 1.0};  ///< Multiplies sampled speeds.
  // A scenario family: each seed draws a variant (DrawScenarioVariant) before the run.
  std::vector<std::string> start_places;   ///< The robot starts at one of these places.
  std::vector<std::string> goal_places;    ///< It goes to one of these (not where it starts).
  std::vector<std::string> person_places;  ///< Each person walks between two of these.
  double open_doors{0.0};   ///< Chance that each operated door is opened at t = 0 by someone.
  double obstacle_xy{0.0};  ///< Obstacle (furniture) xy jitter half-width [m].
  /// True when seeds draw variants of the scenario (places, open doors, furniture).
  bool DrawsVariants() const;
};

/// The robot brain's task in a scenario. The twin does not read it (it knows nothing of the
/// brain); the executive does: which behavior tree to run, and the blackboard entries it starts
/// with (strings, converted by the tree's ports).
struct MissionSpec {
  std::filesystem::path tree_file;  ///< BehaviorTree.CPP v4 XML, resolved against the scenario.
  std::string tree_id;              ///< Tree to run; empty = the file's main tree.
  std::map<std::string, std::string> blackboard;
  int tree_line{0};  ///< Line of `mission.tree` in the scenario file (for error messages).
};

/// The largest seed a scenario (or a batch's trial) may have: 2^53, the last integer a double
/// (YAML, JSON) holds exactly.
inline constexpr std::uint64_t kMaxScenarioSeed = std::uint64_t{1} << 53;

struct Scenario {
  std::string name;
  std::filesystem::path source;      ///< The YAML file.
  std::filesystem::path world_file;  ///< Resolved path of the SDF world.
  /// Resolved path of the building YAML (`building:`); empty = `<world stem>.building.yaml`
  /// beside the world if there is one.
  std::filesystem::path building_file;
  /// `robot.start: {place: ..}` / `robot.goal: {place: ..}`: named places of the building,
  /// resolved into robot_start / goal by ApplyBuildingDefaults.
  std::string start_place;
  std::string goal_place;
  std::uint64_t seed{1};     ///< At most kMaxScenarioSeed.
  double time_limit{120.0};  ///< [s]
  Pose2 robot_start;
  /// The robot takes no part (`robot: {off_scene: true}`): it stands kOffSceneDistanceM beyond
  /// the world (OffScenePose), with no goal; e.g. a crowd study's runs without a robot.
  bool robot_off_scene{false};
  std::optional<Pose2> goal;
  double goal_tolerance{0.3};  ///< [m]
  std::vector<DoorOperatorSpec> doors;
  std::vector<PersonSpec> people;
  std::vector<PayloadSpec> payloads;
  std::vector<ShapeDescription> obstacles;  ///< Extra static boxes/cylinders.
  RandomizeSpec randomize;
  std::vector<PredicateSpec> success;
  SensorConfig sensors;
  std::vector<FaultSpec> faults;
  std::optional<MissionSpec> mission;

  /// Checks the scenario against its world: doors and actuators exist, poses are free of
  /// walls. @throws LoadError naming the scenario file and field.
  void ValidateAgainst(const WorldDescription& world) const;
};

/// The building of `scenario`'s world: the world's doors, actuators and places
/// (DescribeBuilding with the scenario's building YAML, or the one beside the world), and the
/// actuators the scenario's `doors` list by name (of the door and kind it gives them).
/// @throws LoadError naming the file and field or model.
BuildingDescription DescribeScenarioBuilding(const Scenario& scenario,
                                             const WorldDescription& world);
/// Fills in what the scenario leaves to its building: start and goal places become poses; a
/// listed door without `actuator` gets the building's actuators of its operator's kind; a door
/// the scenario does not list but whose actuators the building found gets an operator of their
/// kind (ADA defaults); a glass leaf in the building is glass in the twin.
/// @throws LoadError naming the scenario file and field (an unknown place, a push door whose
/// building has only plates, a door whose actuators are of both kinds).
void ApplyBuildingDefaults(const BuildingDescription& building, Scenario* scenario);

/// The variant of a scenario family `scenario` for `seed`: start and goal places, people's
/// routes, doors already opened, furniture jitter drawn from `randomize` (a pure function of
/// the scenario and the seed; a scenario that draws no variants is returned as it is). Places
/// are the building's. @throws LoadError naming the field for a place the building lacks.
Scenario DrawScenarioVariant(const Scenario& scenario, const BuildingDescription& building,
                             std::uint64_t seed);

/// How far beyond the world a robot off the scene stands [m].
inline constexpr double kOffSceneDistanceM = 50.0;
/// Where a robot off the scene stands: kOffSceneDistanceM beyond the world's walls in +x.
Pose2 OffScenePose(const WorldDescription& world);

/// Reads a scenario YAML file. @throws LoadError naming file, line and field.
Scenario LoadScenario(const std::filesystem::path& path);
/// The same from text; `base_dir` resolves the relative world path.
Scenario LoadScenarioFromString(const std::string& yaml, std::string_view source_name,
                                const std::filesystem::path& base_dir);

}  // namespace egress::twin
