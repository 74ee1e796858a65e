#pragma once
/// @file
/// The digital twin's world: Bullet rigid-body dynamics at a fixed step with the static
/// geometry of an SDF world, hinged door leaves driven by ADA operators, push buttons and
/// proximity plates, people moved by the Social Force Model as kinematic capsules, payloads as
/// dynamic bodies, and the HSR body (an omnidirectional base following velocity commands with
/// acceleration limits, arm links posed by RobotModel FK, a gripper). Ground truth lives here;
/// only sensors (through ray casts) and the scenario judge read it.
///
/// Determinism: a world is a pure function of (scenario, world description, seed). Every random
/// draw comes from engines seeded from `seed`, Bullet runs single-threaded with a fixed step.

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "egress/hsr_interface/command_types.h"
#include "egress/hsr_interface/geometry.h"
#include "egress/hsr_interface/robot_model.h"
#include "egress/hsr_interface/time.h"
#include "egress/twin/door_operator.h"
#include "egress/twin/scenario.h"
#include "egress/twin/twin_model.h"
#include "egress/twin/world_description.h"

namespace egress::twin {

/// What a collision object is, for contacts, rays and the detector.
enum class EntityKind { kStatic, kFloor, kDoor, kRobotBase, kRobotArm, kPerson, kPayload };
std::string_view ToString(EntityKind kind);

/// Something that happened, with the simulated time [s].
struct TwinEvent {
  double t{0.0};
  std::string kind;     ///< e.g. "button_pressed", "door_opened", "contact", "grasp"
  std::string subject;  ///< door, person, payload or actuator name
  std::string detail;
};

/// A ray-cast result in W.
struct RayHit {
  bool hit{false};
  double distance{0.0};  ///< [m] from the ray origin
  Eigen::Vector3d point{Eigen::Vector3d::Zero()};
  Eigen::Vector3d normal{Eigen::Vector3d::Zero()};
  int entity{-1};     ///< Index into Entities()
  bool glass{false};  ///< The surface hit is a glass leaf
};

/// How a ray treats glass leaves.
enum class GlassMode {
  kOpaque,       ///< Glass stops the ray like any surface (RayHit::glass tells it was glass).
  kLaser,        ///< Glass returns only within `max_incidence` of its normal, else the ray passes.
  kTransparent,  ///< Glass never stops the ray (a camera looking through it).
};

/// A labelled box the simulated detector can see.
struct DetectableObject {
  std::string label;  ///< "person", "door", "glass_door", "push_button", ... "bottle"
  std::string name;
  Pose3 X_WO;                                     ///< Box centre frame.
  Eigen::Vector3d half{Eigen::Vector3d::Zero()};  ///< Half extents [m].
  int entity{-1};
};

/// What a person is doing.
enum class PersonPhase {
  kWaiting,         ///< Not started (waiting for the trigger).
  kWalking,         ///< On the route.
  kWaitingForDoor,  ///< Before a doorway whose leaf is not open enough, or that someone is in.
  kHolding,         ///< Holding a door open.
  kStanding,        ///< Standing at the route's end (approach_and_wait).
  kDone,            ///< At the route's end for good.
};
/// waiting, walking, waiting_for_door, holding, standing, done (the trace's names).
std::string_view ToString(PersonPhase phase);

/// Ground truth of one person.
struct PersonState {
  std::string name;
  PersonBehavior behavior{PersonBehavior::kCrossDoorway};
  Eigen::Vector2d position{Eigen::Vector2d::Zero()};
  Eigen::Vector2d velocity{Eigen::Vector2d::Zero()};
  double radius{0.25};
  bool started{false};
  PersonPhase phase{PersonPhase::kWaiting};
  std::string mobility;     ///< Mobility class (evacuees with a mobility mix), else empty.
  double arrived_at{-1.0};  ///< When they reached the end of their route [s]; -1: not yet.
  int doors_operated{0};    ///< How often they operated a door's actuator.
  bool can_operate{false};  ///< Operates a door's actuator when they wait at it (evacuees).
  std::string waiting_for;  ///< The door they wait at (phase kWaitingForDoor), else empty.
  /// An evacuee who reached the assembly point beyond the exit: left the scene (no body, no
  /// forces); `position` stays where they arrived.
  bool out{false};
};

/// One run of a TwinModel (its state, as MuJoCo's mjData to mjModel): the seeded draws (robot
/// start, payload jitter, people's speeds and delays, hold times) and everything that moves.
class TwinWorld {
 public:
  /// A run of `model` with `seed`; the model is shared, never copied.
  /// @throws InvalidArgument for a null model; LoadError if a seeded draw makes the scenario
  /// invalid (a payload jittered into furniture).
  TwinWorld(std::shared_ptr<const TwinModel> model, std::uint64_t seed);
  /// Compiles a model of its own and runs it (a single run; batches share one TwinModel).
  /// @throws LoadError if the scenario does not fit the world.
  TwinWorld(const Scenario& scenario, const WorldDescription& world, std::uint64_t seed,
            std::shared_ptr<const RobotModel> robot_model, TwinConfig config = {});
  ~TwinWorld();
  TwinWorld(const TwinWorld&) = delete;
  TwinWorld& operator=(const TwinWorld&) = delete;

  /// A fault of the scenario as drawn for this run (FaultSpec: start and duration drawn).
  struct DrawnFault {
    const FaultSpec* spec{nullptr};
    double start{0.0};  ///< [s]
    double end{0.0};    ///< [s]; == start for an instantaneous fault
    bool fired{false};  ///< An instantaneous fault has happened (or was skipped, see events).
  };
  /// The run's faults, drawn from the scenario's `faults:` by the seed.
  const std::vector<DrawnFault>& faults() const;
  /// A window fault of `kind` in force at time `t` [s] (start <= t < end), or null.
  const FaultSpec* ActiveFault(FaultSpec::Kind kind, double t) const;

  /// One fixed physics step.
  void Step();
  /// Steps until the simulated time has advanced by at least `seconds`.
  void StepFor(double seconds);

  double time() const;  ///< Simulated time [s].
  Time now() const;     ///< Simulated time as a Time.
  double step_size() const;
  std::uint64_t step_count() const;

  // --- The robot's actuators (TwinRobot calls these). -------------------------------------
  /// Base velocity in B; held for the command timeout.
  void SetBaseVelocity(const Twist2& V_B);
  /// Replaces the arm/head trajectory. @throws InvalidArgument for an unknown joint name.
  void SetArmTrajectory(const JointTrajectory& trajectory);
  void SetGripperCommand(const GripperCommand& command);
  /// Head pan/tilt targets: the joints move there at their URDF velocity limits, within their
  /// limits; an arm trajectory that names a head joint takes the head over again.
  void SetHeadCommand(const HeadCommand& command);

  // --- Ground truth (sensors, judge, tests). --------------------------------------------
  Pose2 robot_pose() const;       ///< X_WB
  Twist2 robot_velocity() const;  ///< V_B (in B)
  /// Whole-body configuration (base pose + arm joints).
  WholeBodyVector robot_configuration() const;
  double arm_joint(std::string_view name) const;  ///< arm, head and hand joints
  /// Names and positions of the joints the robot reports.
  std::vector<std::pair<std::string, double>> joint_positions() const;
  double hand_motor_position() const;
  double gripper_effort() const;
  std::optional<std::string> held_payload() const;
  Eigen::Vector3d fingertip_position() const;  ///< p_WF
  Pose3 palm_pose() const;                     ///< X_WG
  Pose3 head_camera_pose() const;              ///< X_WC
  const RobotModel& robot_model() const;
  double robot_radius() const;

  std::size_t door_count() const;
  const DoorDescription& door(std::size_t i) const;
  double door_angle(std::size_t i) const;     ///< Opening angle [rad], 0 = closed
  DoorPhase door_phase(std::size_t i) const;  ///< kClosed for doors without operator
  bool door_is_glass(std::size_t i) const;
  int FindDoorIndex(const std::string& name) const;  ///< −1 if unknown
  int button_presses(std::size_t door_index) const;

  /// The people's states after the last step. The vector is refreshed when this is called
  /// (not by every step): call it again after stepping rather than keep the reference.
  const std::vector<PersonState>& people() const;
  Pose3 payload_pose(const std::string& name) const;
  std::vector<std::string> payload_names() const;

  const std::vector<TwinEvent>& events() const;
  std::vector<DetectableObject> DetectableObjects() const;
  /// Casts a ray from `from` to `to` in W, ignoring the robot's own body.
  RayHit CastRay(const Eigen::Vector3d& from, const Eigen::Vector3d& to, GlassMode mode,
                 double glass_max_incidence = 0.26) const;
  /// CastRay from one point to each of `tos`, bit for bit: hits[k] is CastRay(from, tos[k], ...).
  /// For a sensor's sweep (many rays from one point): the candidates are binned by bearing from
  /// `from` once, instead of a grid walk per ray.
  void CastRayFan(const Eigen::Vector3d& from, std::span<const Eigen::Vector3d> tos, GlassMode mode,
                  std::vector<RayHit>* hits, double glass_max_incidence = 0.26) const;
  /// Kind and name of an entity from RayHit::entity.
  EntityKind entity_kind(int entity) const;
  const std::string& entity_name(int entity) const;

  const Scenario& scenario() const;
  const WorldDescription& world() const;
  const TwinConfig& config() const;
  const std::shared_ptr<const TwinModel>& model() const;  ///< The fixed part of this run.
  std::uint64_t seed() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace egress::twin
