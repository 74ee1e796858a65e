#include "manipulation_support.h"

#include <algorithm>
#include <cmath>

namespace egress::behavior::detail {
namespace {

// Calls fn(p_MQ) for every valid pixel of the latest depth image, unprojected into M.
template <typename Fn>
void ForEachDepthPointInMap(const TaskServices& task, Fn&& fn) {
  const DepthImage& depth = *task.belief->depth;
  for (int v = 0; v < depth.height; ++v) {
    for (int u = 0; u < depth.width; ++u) {
      if (!depth.IsValidAt(u, v)) continue;
      fn(Eigen::Vector3d(task.belief->X_MC * task.belief->depth_intrinsics.Unproject(
                                                 u + 0.5, v + 0.5, depth.At(u, v))));
    }
  }
}

}  // namespace

Eigen::Vector3d ParsePoint3(std::string_view text) {
  const Pose2 xy = ParsePose2(text);  // x;y;z parses as x;y;yaw
  return {xy.x, xy.y, xy.yaw};
}

planning::IkTarget PalmTarget(const Eigen::Vector3d& p_M, const Eigen::Vector3d& approach_M) {
  return {p_M - approach_M * kGraspDepthInPalm, approach_M};
}

std::optional<HandReach> SolveHandReach(const TaskServices& task, const Eigen::Vector3d& p_M,
                                        const Eigen::Vector3d& approach_M,
                                        const Eigen::Vector3d& toward_M) {
  // Seeds: reaching forward (palm level), or from above (lift high, upper arm level, palm
  // down), so the solve lands on the posture whose hand comes in from that side.
  static constexpr ArmPose kReachArm{0.2, -1.0, 0.0, -0.5, 0.0};
  static constexpr ArmPose kReachFromAboveArm{0.5, -1.5707963267948966, 0.0, -1.5707963267948966,
                                              0.0};
  const bool from_above = approach_M.z() < -0.9;
  const Eigen::Vector2d a = toward_M.head<2>().normalized();
  const Eigen::Vector2d base = p_M.head<2>() - a * 0.6;
  WholeBodyVector q0 = WholeBodyVector::Zero();
  q0[kBaseX] = base.x();
  q0[kBaseY] = base.y();
  q0[kBaseYaw] = std::atan2(a.y(), a.x());
  q0 = WithArm(q0, from_above ? kReachFromAboveArm : kReachArm);
  planning::IkConfig ik = task.config.ik;
  ik.fingertip = false;
  ik.use_base = true;
  const planning::IkResult r =
      planning::DlsIkSolver(*task.model, ik).Solve(PalmTarget(p_M, approach_M), q0);
  if (!r.converged) return std::nullopt;
  return HandReach{{r.q[kBaseX], r.q[kBaseY], r.q[kBaseYaw]}, ArmOf(r.q)};
}

Eigen::Vector3d HorizontalApproach(const Pose2& X_MB, const Eigen::Vector3d& p_M) {
  Eigen::Vector2d a = p_M.head<2>() - X_MB.translation();
  if (a.norm() < 1e-6) a = Eigen::Vector2d(std::cos(X_MB.yaw), std::sin(X_MB.yaw));
  a.normalize();
  return {a.x(), a.y(), 0.0};
}

double PayloadCentreHeight(std::string_view kind) {
  if (kind == perception::labels::kBottle) return 0.105;
  if (kind == perception::labels::kFlashlight) return 0.021;
  return 0.05;
}

std::optional<ClutterBeforeGrasp> FindClutterBeforeGrasp(const TaskServices& task,
                                                         const Eigen::Vector3d& p_M,
                                                         const Eigen::Vector3d& approach_M,
                                                         double payload_radius, double surface_z) {
  if (!task.belief->depth) return std::nullopt;
  constexpr double kHandHalfWidth = 0.07;  // [m] fingers open, with a margin
  constexpr double kFlat = 0.02;           // [m] bumps lower than this are the surface
  const Eigen::Vector2d a = approach_M.head<2>().normalized();
  std::optional<ClutterBeforeGrasp> clutter;
  ForEachDepthPointInMap(task, [&](const Eigen::Vector3d& p) {
    const Eigen::Vector2d d = p.head<2>() - p_M.head<2>();
    const double along = d.dot(a);
    const double lateral = (d - along * a).norm();
    if (along > -(payload_radius + 0.01) || along < -(kPreGraspOffset + 0.1) ||
        lateral > kHandHalfWidth || p.z() < surface_z + kFlat) {
      return;
    }
    if (!clutter) {
      clutter = ClutterBeforeGrasp{p.z(), -along};
    } else {
      clutter->top_z = std::max(clutter->top_z, p.z());
      clutter->reach = std::max(clutter->reach, -along);
    }
  });
  return clutter;
}

std::optional<Eigen::Vector3d> LowPayloadCentre(const TaskServices& task,
                                                const Eigen::Vector3d& p_M, double surface_z,
                                                double radius) {
  if (!task.belief->depth) return std::nullopt;
  constexpr double kAboveSurface = 0.01;  // [m] points lower than this are the surface
  constexpr int kMinPoints = 20;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  int n = 0;
  ForEachDepthPointInMap(task, [&](const Eigen::Vector3d& p) {
    if (p.z() < surface_z + kAboveSurface || p.z() > p_M.z() + radius ||
        (p.head<2>() - p_M.head<2>()).norm() > radius)
      return;
    sum += p.head<2>();
    ++n;
  });
  if (n < kMinPoints) return std::nullopt;
  const Eigen::Vector2d c = sum / n;
  return Eigen::Vector3d(c.x(), c.y(), p_M.z());
}

}  // namespace egress::behavior::detail
