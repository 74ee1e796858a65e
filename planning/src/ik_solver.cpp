#include "egress/planning/ik_solver.h"

#include <cmath>
#include <numbers>

#include <Eigen/Cholesky>

#include "egress/hsr_interface/error.h"

namespace egress::planning {

void IkConfig::Validate() const {
  ThrowUnless(damping >= 0.0 && std::isfinite(damping), "Invalid IkConfig: damping (", damping,
              ") must be >= 0.");
  ThrowUnless(step > 0.0 && step <= 1.0, "Invalid IkConfig: step (", step, ") must be in (0, 1].");
  ThrowUnless(max_joint_step > 0.0, "Invalid IkConfig: max_joint_step (", max_joint_step,
              ") must be > 0.");
  ThrowUnless(tolerance > 0.0, "Invalid IkConfig: tolerance (", tolerance, ") must be > 0.");
  ThrowUnless(max_iterations >= 1, "Invalid IkConfig: max_iterations (", max_iterations,
              ") must be >= 1.");
  ThrowUnless(orientation_weight >= 0.0 && orientation_tolerance > 0.0,
              "Invalid IkConfig: orientation_weight must be >= 0 and orientation_tolerance > 0.");
}

DlsIkSolver::DlsIkSolver(const RobotModel& model, IkConfig config)
    : model_(model), config_(config) {
  config_.Validate();
}

namespace {
constexpr double kLevelOffset = -std::numbers::pi / 2;  // q_wrist_flex = −π/2 − q_arm_flex

void Level(WholeBodyVector& q) {
  q[kWristFlex] = kLevelOffset - q[kArmFlex];
}
}  // namespace

IkResult DlsIkSolver::Solve(const IkTarget& target, const WholeBodyVector& q_start) const {
  ThrowUnless(target.p_MT.allFinite(), "Invalid IK target: position must be finite.");
  ThrowUnless(q_start.allFinite(), "Invalid IK start configuration: must be finite.");
  Eigen::Vector3d approach = Eigen::Vector3d::Zero();
  const bool oriented = target.approach_M.has_value() && config_.orientation_weight > 0.0;
  if (target.approach_M) {
    ThrowUnless(target.approach_M->allFinite() && target.approach_M->norm() > 1e-9,
                "Invalid IK target: the approach axis must be finite and non-zero.");
    approach = target.approach_M->normalized();
  }
  // Active joints: base x, y (whole-body), the arm joints; wrist flex follows arm flex when
  // leveling. Base yaw is held.
  std::array<int, kNumWholeBodyJoints> active{};
  int n = 0;
  if (config_.use_base) {
    active[n++] = kBaseX;
    active[n++] = kBaseY;
  }
  for (int j = kArmLift; j < kNumWholeBodyJoints; ++j) {
    if (config_.wrist_leveling && j == kWristFlex) continue;
    active[n++] = j;
  }
  const int rows = oriented ? 6 : 3;
  const WholeBodyVector lower = model_.lower_limits(), upper = model_.upper_limits();
  const Eigen::Vector3d p_GQ =
      config_.fingertip ? model_.fingertip_in_palm() : Eigen::Vector3d::Zero();

  IkResult result;
  result.q = model_.ClampToLimits(q_start);
  if (config_.wrist_leveling) Level(result.q);
  Eigen::Matrix<double, 6, kNumWholeBodyJoints> J;
  Eigen::Matrix<double, 6, 1> e;
  WholeBodyJacobian full;
  Pose3 X_MG;
  for (;;) {
    model_.CalcPalmPoseAndJacobian(result.q, p_GQ, &X_MG, &full);
    const Eigen::Vector3d p_MQ = X_MG * p_GQ;
    e.head<3>() = target.p_MT - p_MQ;
    result.position_error = e.head<3>().norm();
    const Eigen::Vector3d z = X_MG.rotation().col(2);
    if (oriented) {
      // Rotate z toward the approach axis; rotation about z itself is free.
      const Eigen::Vector3d axis_error = z.cross(approach);
      result.orientation_error = std::atan2(axis_error.norm(), z.dot(approach));
      e.tail<3>() = config_.orientation_weight * axis_error;
    }
    const bool done = result.position_error < config_.tolerance &&
                      (!oriented || result.orientation_error < config_.orientation_tolerance);
    if (done) {
      result.converged = true;
      return result;
    }
    if (result.iterations >= config_.max_iterations) return result;
    ++result.iterations;

    for (int k = 0; k < n; ++k) {
      const int j = active[k];
      J.col(k).head<3>() = full.col(j).head<3>();
      if (oriented) {
        const Eigen::Vector3d w = full.col(j).tail<3>();
        J.col(k).tail<3>() = config_.orientation_weight * (w - z * z.dot(w));
      }
      if (config_.wrist_leveling && j == kArmFlex) {
        // d q_wrist_flex / d q_arm_flex = −1.
        J.col(k).head<3>() -= full.col(kWristFlex).head<3>();
        if (oriented) {
          const Eigen::Vector3d w = full.col(kWristFlex).tail<3>();
          J.col(k).tail<3>() -= config_.orientation_weight * (w - z * z.dot(w));
        }
      }
    }
    // Clamping loop: a joint at a limit whose step points outward is taken out (its column
    // zeroed) and the step recomputed, so the other joints carry the task instead of the
    // clamped share being lost every iteration.
    using SmallMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;
    using SmallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kNumWholeBodyJoints, 1>;
    SmallVector dq;
    for (int pass = 0; pass <= n; ++pass) {
      const auto Jn = J.topLeftCorner(rows, n);
      SmallMatrix A = Jn * Jn.transpose();
      A.diagonal().array() += config_.damping * config_.damping;
      dq = config_.step * (Jn.transpose() * A.ldlt().solve(e.head(rows)));
      bool removed = false;
      for (int k = 0; k < n; ++k) {
        const int j = active[k];
        const bool at_lower = result.q[j] <= lower[j] && dq[k] < 0.0;
        const bool at_upper = result.q[j] >= upper[j] && dq[k] > 0.0;
        if ((at_lower || at_upper) && !J.col(k).isZero()) {
          J.col(k).setZero();
          removed = true;
        }
      }
      if (!removed) break;
    }
    if (!dq.allFinite()) return result;
    for (int k = 0; k < n; ++k) {
      const int j = active[k];
      const double step = std::clamp(dq[k], -config_.max_joint_step, config_.max_joint_step);
      result.q[j] = std::clamp(result.q[j] + step, lower[j], upper[j]);
    }
    if (config_.wrist_leveling) Level(result.q);
  }
}

ButtonTargets MakeButtonTargets(const Eigen::Vector3d& p_MButton, const Eigen::Vector3d& n_M,
                                ButtonType type, const ButtonTargetsConfig& config) {
  ThrowUnless(p_MButton.allFinite() && n_M.allFinite(),
              "Invalid button: position and normal must be finite.");
  Eigen::Vector3d n = n_M;
  n.z() = 0.0;  // buttons sit on vertical walls
  ThrowUnless(n.norm() > 1e-6, "Invalid button: the wall normal must have a horizontal component.");
  n.normalize();
  ThrowUnless(config.standoff > 0.0 && config.press_stroke >= 0.0,
              "Invalid button targets: standoff must be > 0 ", "and press_stroke >= 0.");
  ButtonTargets targets;
  const Eigen::Vector3d base = p_MButton + config.standoff * n;
  targets.X_MB_standoff = {base.x(), base.y(), std::atan2(-n.y(), -n.x())};
  if (type == ButtonType::kPushButton) {
    targets.approach = {p_MButton + config.pre_press_offset * n, -n};
    targets.press = {p_MButton - config.press_stroke * n, -n};
  } else {
    ThrowUnless(config.wave_distance > 0.0 && config.wave_distance < config.sensing_range,
                "Invalid button targets: wave_distance (", config.wave_distance,
                ") must be inside the plate's sensing range (", config.sensing_range, ").");
    targets.approach = {p_MButton + config.wave_distance * n, -n};
    targets.press = targets.approach;
  }
  return targets;
}

}  // namespace egress::planning
