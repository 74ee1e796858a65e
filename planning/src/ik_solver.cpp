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
  ThrowUnless(min_damping >= 0.0, "Invalid IkConfig: min_damping (", min_damping,
              ") must be >= 0.");
  ThrowUnless(max_adaptive_joint_step >= max_joint_step,
              "Invalid IkConfig: ", "max_adaptive_joint_step (", max_adaptive_joint_step,
              ") must be >= max_joint_step.");
  ThrowUnless(restarts >= 0, "Invalid IkConfig: restarts (", restarts, ") must be >= 0.");
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

// What one configuration scores against the target.
struct Evaluation {
  Eigen::Matrix<double, 6, 1> e{Eigen::Matrix<double, 6, 1>::Zero()};  // task error
  Eigen::Vector3d z{Eigen::Vector3d::UnitZ()};                         // palm approach axis
  WholeBodyJacobian full;
  double position_error{0.0};
  double orientation_error{0.0};
  double cost{0.0};  // |e|² over the task rows
};

// The per-solve constants: the target, the active joints, the limits.
struct DlsIkSolver::Run {
  const RobotModel& model;
  const IkConfig& config;
  Eigen::Vector3d p_MT;
  Eigen::Vector3d approach{Eigen::Vector3d::Zero()};
  bool oriented{false};
  int rows{3};
  std::array<int, kNumWholeBodyJoints> active{};
  int n{0};
  WholeBodyVector lower{WholeBodyVector::Zero()}, upper{WholeBodyVector::Zero()};
  Eigen::Vector3d p_GQ{Eigen::Vector3d::Zero()};

  void Evaluate(const WholeBodyVector& q, Evaluation* out) const {
    Pose3 X_MG;
    model.CalcPalmPoseAndJacobian(q, p_GQ, &X_MG, &out->full);
    out->e.head<3>() = p_MT - X_MG * p_GQ;
    out->position_error = out->e.head<3>().norm();
    out->z = X_MG.rotation().col(2);
    out->cost = out->e.head<3>().squaredNorm();
    if (oriented) {
      // Rotate z toward the approach axis; rotation about z itself is free.
      const Eigen::Vector3d axis_error = out->z.cross(approach);
      out->orientation_error = std::atan2(axis_error.norm(), out->z.dot(approach));
      out->e.tail<3>() = config.orientation_weight * axis_error;
      out->cost += out->e.tail<3>().squaredNorm();
    }
  }

  bool Done(const Evaluation& v) const {
    return v.position_error < config.tolerance &&
           (!oriented || v.orientation_error < config.orientation_tolerance);
  }

  // One damped least-squares step from q (its evaluation v) with damping λ, step α and the
  // per-joint clamp; limits enforced.
  WholeBodyVector Step(const WholeBodyVector& q, const Evaluation& v, double lambda, double alpha,
                       double clamp) const {
    Eigen::Matrix<double, 6, kNumWholeBodyJoints> J;
    for (int k = 0; k < n; ++k) {
      const int j = active[k];
      J.col(k).head<3>() = v.full.col(j).head<3>();
      if (oriented) {
        const Eigen::Vector3d w = v.full.col(j).tail<3>();
        J.col(k).tail<3>() = config.orientation_weight * (w - v.z * v.z.dot(w));
      }
      if (config.wrist_leveling && j == kArmFlex) {
        // d q_wrist_flex / d q_arm_flex = −1.
        J.col(k).head<3>() -= v.full.col(kWristFlex).head<3>();
        if (oriented) {
          const Eigen::Vector3d w = v.full.col(kWristFlex).tail<3>();
          J.col(k).tail<3>() -= config.orientation_weight * (w - v.z * v.z.dot(w));
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
      A.diagonal().array() += lambda * lambda;
      dq = alpha * (Jn.transpose() * A.ldlt().solve(v.e.head(rows)));
      bool removed = false;
      for (int k = 0; k < n; ++k) {
        const int j = active[k];
        const bool at_lower = q[j] <= lower[j] && dq[k] < 0.0;
        const bool at_upper = q[j] >= upper[j] && dq[k] > 0.0;
        if ((at_lower || at_upper) && !J.col(k).isZero()) {
          J.col(k).setZero();
          removed = true;
        }
      }
      if (!removed) break;
    }
    WholeBodyVector next = q;
    if (!dq.allFinite()) return next;
    for (int k = 0; k < n; ++k) {
      const int j = active[k];
      next[j] = std::clamp(q[j] + std::clamp(dq[k], -clamp, clamp), lower[j], upper[j]);
    }
    if (config.wrist_leveling) Level(next);
    return next;
  }
};

IkResult DlsIkSolver::Solve(const IkTarget& target, const WholeBodyVector& q_start) const {
  ThrowUnless(target.p_MT.allFinite(), "Invalid IK target: position must be finite.");
  ThrowUnless(q_start.allFinite(), "Invalid IK start configuration: must be finite.");
  if (target.approach_M) {
    ThrowUnless(target.approach_M->allFinite() && target.approach_M->norm() > 1e-9,
                "Invalid IK target: the approach axis must be finite and non-zero.");
  }
  if (config_.method == IkMethod::kPaperDls)
    return SolveFrom(target, q_start, config_.max_iterations, false);

  // Adaptive: the given start first, then interior arm postures (flex at a quarter, half and
  // three quarters of its range, lift mid-range, the rest as given) when a run stalls.
  IkResult best = SolveFrom(target, q_start, config_.max_iterations, true);
  int used = best.iterations;
  const WholeBodyVector lower = model_.lower_limits(), upper = model_.upper_limits();
  for (int r = 1; r <= config_.restarts && !best.converged && used < config_.max_iterations; ++r) {
    WholeBodyVector seed = q_start;
    const double f = double(r) / (config_.restarts + 1);
    seed[kArmLift] = 0.5 * (lower[kArmLift] + upper[kArmLift]);
    seed[kArmFlex] = upper[kArmFlex] + f * (lower[kArmFlex] - upper[kArmFlex]);
    IkResult next = SolveFrom(target, seed, config_.max_iterations - used, true);
    used += next.iterations;
    const auto score = [](const IkResult& x) { return x.position_error + x.orientation_error; };
    if (next.converged || score(next) < score(best)) best = next;
  }
  best.iterations = used;
  return best;
}

IkResult DlsIkSolver::SolveFrom(const IkTarget& target, const WholeBodyVector& q_start, int budget,
                                bool adaptive) const {
  Run run{.model = model_, .config = config_, .p_MT = target.p_MT};
  run.oriented = target.approach_M.has_value() && config_.orientation_weight > 0.0;
  if (target.approach_M) run.approach = target.approach_M->normalized();
  // Active joints: base x, y (whole-body), the arm joints; wrist flex follows arm flex when
  // leveling. Base yaw is held.
  if (config_.use_base) {
    run.active[run.n++] = kBaseX;
    run.active[run.n++] = kBaseY;
  }
  for (int j = kArmLift; j < kNumWholeBodyJoints; ++j) {
    if (config_.wrist_leveling && j == kWristFlex) continue;
    run.active[run.n++] = j;
  }
  run.rows = run.oriented ? 6 : 3;
  run.lower = model_.lower_limits();
  run.upper = model_.upper_limits();
  run.p_GQ = config_.fingertip ? model_.fingertip_in_palm() : Eigen::Vector3d::Zero();

  IkResult result;
  result.q = model_.ClampToLimits(q_start);
  if (config_.wrist_leveling) Level(result.q);
  Evaluation now, trial;
  run.Evaluate(result.q, &now);
  double lambda = config_.damping, clamp = config_.max_joint_step;
  double alpha = adaptive ? 1.0 : config_.step;
  double cost_10_ago = now.cost;
  const auto finish = [&](bool converged) {
    result.converged = converged;
    result.position_error = now.position_error;
    result.orientation_error = run.oriented ? now.orientation_error : 0.0;
    return result;
  };
  for (;;) {
    if (run.Done(now)) return finish(true);
    if (result.iterations >= budget) return finish(false);
    ++result.iterations;
    const WholeBodyVector next = run.Step(result.q, now, lambda, alpha, clamp);
    if (!adaptive) {
      result.q = next;
      run.Evaluate(result.q, &now);
      continue;
    }
    run.Evaluate(next, &trial);
    if (trial.cost < now.cost) {
      // A step that did not halve the error: the damping holds the solve back (λ dominates
      // a small singular value near a singular or far-stretched arm): damp less. Big strides
      // keep the paper's damping, and with it the paper's split between base and arm.
      if (trial.cost > 0.25 * now.cost && alpha >= 1.0)
        lambda = std::max(config_.min_damping, 0.5 * lambda);
      result.q = next;
      std::swap(now, trial);
      alpha = std::min(1.0, 2.0 * alpha);
      clamp = std::min(config_.max_adaptive_joint_step, 2.0 * clamp);
    } else {
      // Refused: back toward the paper's conservative step. At the paper's values already and
      // still no descent: a stall (a limit or a singularity holds the solve).
      if (alpha <= config_.step && lambda >= config_.damping && clamp <= config_.max_joint_step)
        return finish(false);
      alpha = std::max(config_.step, 0.5 * alpha);
      lambda = std::min(config_.damping, 4.0 * lambda);
      clamp = std::max(config_.max_joint_step, 0.5 * clamp);
    }
    // Creeping (less than 5 % better over ten iterations) is a stall too.
    if (result.iterations % 10 == 0) {
      if (now.cost > 0.9025 * cost_10_ago) return finish(false);
      cost_10_ago = now.cost;
    }
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
