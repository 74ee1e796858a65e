#pragma once
/// @file
/// Damped-least-squares inverse kinematics of the HSR (the paper's solver): per iteration
///   Δq = α · Jᵀ (J Jᵀ + λ² I)⁻¹ e,  then |Δq_i| ≤ max_joint_step for every joint,
/// with joint limits enforced after each step. Position target for the palm origin or the
/// fingertip point, an optional approach-axis term (the palm's z axis toward a direction), the
/// whole-body variant with base x, y as extra joints (base yaw held), warm starting from any
/// configuration, and the wrist-leveling constraint q_wrist_flex = −π/2 − q_arm_flex for
/// flat-palm carrying. A result always says whether it converged: never execute one that did
/// not (the authors' code did).
///
/// Two schedules share that update (IkConfig::method):
/// - kPaperDls: the paper's, verbatim: fixed λ, α and clamp for every iteration, one start.
/// - kAdaptiveDls (default): the same update with the paper's λ and clamp as the start and
///   the floor, and a trust schedule (Levenberg-Marquardt's): the first step is a full one
///   (α = 1); every step that lowers the error relaxes the next (the clamp doubles up to
///   `max_adaptive_joint_step`), every step that would raise it is refused and tightened
///   back toward the paper's values (α halves down to `step`). λ stays at the paper's while
///   full steps at least halve the error (so the big strides, and with them the split between
///   base and arm, are the paper's) and halves down to `min_damping` when one does not (the
///   creep near a singular or stretched arm). A
///   run that stalls there, or creeps (< 5 % better in ten iterations), restarts from interior
///   arm postures (`restarts` of them, from the model's joint ranges) within the same
///   iteration budget. Where the paper's schedule converges this one converges to a nearby
///   configuration (bench/ik_bench: 3 iterations instead of 72 from the tucked pose), and it
///   also converges from the tucked, singular arm for targets below the palm.

#include <optional>

#include <Eigen/Core>

#include "egress/hsr_interface/robot_model.h"

namespace egress::planning {

enum class IkMethod { kPaperDls, kAdaptiveDls };

struct IkConfig {
  IkMethod method{IkMethod::kAdaptiveDls};
  double damping{0.5};         ///< λ
  double step{0.1};            ///< α
  double max_joint_step{0.1};  ///< Per-joint clamp per iteration [rad or m].
  double tolerance{1e-3};      ///< Position error at which the solve stops [m].
  int max_iterations{200};     ///< Over all restarts.
  /// kAdaptiveDls: the smallest λ that steps which fail to halve the error shrink it to.
  double min_damping{0.02};
  double max_adaptive_joint_step{0.5};  ///< kAdaptiveDls: the largest clamp [rad or m].
  int restarts{3};                     ///< kAdaptiveDls: interior arm postures tried after a stall.
  bool fingertip{false};               ///< Target the fingertip point instead of the palm origin.
  bool use_base{true};                 ///< Whole-body: base x, y are extra joints (yaw is held).
  bool wrist_leveling{false};          ///< q_wrist_flex = −π/2 − q_arm_flex (flat palm).
  double orientation_weight{0.3};      ///< Weight of the approach-axis error, when one is given.
  double orientation_tolerance{0.05};  ///< [rad] between the palm z axis and the approach axis.
  /// @throws InvalidArgument naming the field.
  void Validate() const;
};

struct IkTarget {
  Eigen::Vector3d p_MT{Eigen::Vector3d::Zero()};  ///< Where the palm / fingertip point must go [m].
  /// If set, the palm's approach axis (its z) should point along this direction in M.
  std::optional<Eigen::Vector3d> approach_M;
};

struct IkResult {
  WholeBodyVector q{WholeBodyVector::Zero()};
  bool converged{false};
  int iterations{0};              ///< Over all restarts (refused steps count).
  double position_error{0.0};     ///< [m]
  double orientation_error{0.0};  ///< [rad], 0 without an approach axis.
};

class DlsIkSolver {
 public:
  /// The model must outlive the solver. @throws InvalidArgument for a bad config.
  DlsIkSolver(const RobotModel& model, IkConfig config = {});
  /// Solves from `q_start` (the warm start: current or previous configuration).
  /// @throws InvalidArgument for a non-finite target or start.
  IkResult Solve(const IkTarget& target, const WholeBodyVector& q_start) const;
  const IkConfig& config() const { return config_; }

 private:
  struct Run;
  IkResult SolveFrom(const IkTarget& target, const WholeBodyVector& q_start, int budget,
                     bool adaptive) const;

  const RobotModel& model_;
  IkConfig config_;
};

/// The two ADA button types need different end-effector travel.
enum class ButtonType { kPushButton, kProximityPlate };

struct ButtonTargetsConfig {
  double standoff{0.55};  ///< Base centre distance from the button's wall [m].
  double pre_press_offset{
      0.05};                   ///< Fingertip this far in front of the button before pressing [m].
  double press_stroke{0.006};  ///< Push past the surface by the stroke [m] (a few mm).
  double wave_distance{0.12};  ///< Palm this far in front of a proximity plate [m].
  double sensing_range{0.3};   ///< The plate's range; wave_distance must be within it [m].
};

/// Base pose and end-effector targets for one button.
struct ButtonTargets {
  Pose2 X_MB_standoff;  ///< Where the base goes, facing the button.
  IkTarget approach;    ///< Pre-press (push) or wave (proximity) target.
  IkTarget press;       ///< Press target (push); for a plate the same as `approach`.
};

/// For a button at p_MButton on a wall whose outward normal (toward the robot) is n_M.
/// @throws InvalidArgument for non-finite input, a zero normal, or a wave distance outside the
/// plate's sensing range.
ButtonTargets MakeButtonTargets(const Eigen::Vector3d& p_MButton, const Eigen::Vector3d& n_M,
                                ButtonType type, const ButtonTargetsConfig& config = {});

}  // namespace egress::planning
