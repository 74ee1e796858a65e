// `egress model info|fk`: inspect the HSR robot model egress loads (or any URDF given with
// --urdf): joint limits, sensor mounting and forward kinematics, as a table or as JSON.

#include <cmath>
#include <iostream>
#include <memory>
#include <numbers>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "egress/hsr_interface/robot_model.h"

namespace egress::apps {
namespace {

struct ModelOptions {
  std::string urdf;
  bool json{false};
  std::vector<double> arm;   // arm_lift, arm_flex, arm_roll, wrist_flex, wrist_roll
  std::vector<double> base;  // x, y, yaw
};

RobotModel Load(const ModelOptions& options) {
  return options.urdf.empty() ? RobotModel::LoadDefault() : RobotModel::LoadFromFile(options.urdf);
}

nlohmann::json PoseJson(const Pose3& X) {
  const Eigen::Vector3d p = X.translation();
  const Eigen::Vector3d rpy = X.rpy();
  return {{"xyz", {p.x(), p.y(), p.z()}}, {"rpy", {rpy.x(), rpy.y(), rpy.z()}}};
}

std::string PoseText(const Pose3& X) {
  const Eigen::Vector3d p = X.translation();
  const Eigen::Vector3d rpy = X.rpy();
  return fmt::format("xyz ({:+.4f}, {:+.4f}, {:+.4f}) m  rpy ({:+.4f}, {:+.4f}, {:+.4f}) rad",
                     p.x(), p.y(), p.z(), rpy.x(), rpy.y(), rpy.z());
}

void RunInfo(const ModelOptions& options) {
  const RobotModel model = Load(options);
  const Pose3 X_BC = model.CalcHeadCameraPose(0.0, {});
  if (options.json) {
    nlohmann::json joints = nlohmann::json::array();
    for (int i = 0; i < kNumWholeBodyJoints; ++i) {
      const JointLimits& limits = model.limits(WholeBodyJoint(i));
      joints.push_back({{"name", WholeBodyJointNames()[i]},
                        {"lower", std::isfinite(limits.lower) ? nlohmann::json(limits.lower)
                                                              : nlohmann::json(nullptr)},
                        {"upper", std::isfinite(limits.upper) ? nlohmann::json(limits.upper)
                                                              : nlohmann::json(nullptr)},
                        {"velocity", limits.velocity}});
    }
    const Eigen::Vector3d& p_GF = model.fingertip_in_palm();
    std::cout << nlohmann::json{{"name", model.name()},
                                {"source", model.source()},
                                {"footprint_radius", model.footprint_radius()},
                                {"whole_body_joints", joints},
                                {"fingertip_in_palm", {p_GF.x(), p_GF.y(), p_GF.z()}},
                                {"X_BL", PoseJson(model.laser_pose())},
                                {"X_BC_at_zero", PoseJson(X_BC)}}
                     .dump(2)
              << "\n";
    return;
  }
  fmt::print("robot model '{}' from {}\n", model.name(), model.source());
  fmt::print("footprint radius      {:.3f} m\n", model.footprint_radius());
  const Eigen::Vector3d& p_GF = model.fingertip_in_palm();
  fmt::print("fingertip point p_GF  ({:+.4f}, {:+.4f}, {:+.4f}) m in the palm frame\n", p_GF.x(),
             p_GF.y(), p_GF.z());
  fmt::print("laser X_BL            {}\n", PoseText(model.laser_pose()));
  fmt::print("head camera X_BC      {}  (lift, pan, tilt = 0)\n\n", PoseText(X_BC));
  fmt::print("{:<18} {:>10} {:>10} {:>10}\n", "whole-body joint", "lower", "upper", "max vel");
  for (int i = 0; i < kNumWholeBodyJoints; ++i) {
    const JointLimits& limits = model.limits(WholeBodyJoint(i));
    fmt::print("{:<18} {:>10.3f} {:>10.3f} {:>10.3f}\n", WholeBodyJointNames()[i], limits.lower,
               limits.upper, limits.velocity);
  }
}

void RunFk(const ModelOptions& options) {
  const RobotModel model = Load(options);
  WholeBodyVector q = WholeBodyVector::Zero();
  for (std::size_t i = 0; i < options.base.size(); ++i)
    q[kBaseX + int(i)] = options.base[i];
  for (std::size_t i = 0; i < options.arm.size(); ++i)
    q[kArmLift + int(i)] = options.arm[i];
  for (int i = 0; i < kNumWholeBodyJoints; ++i) {
    if (!std::isfinite(q[i])) {
      throw std::invalid_argument(
          fmt::format("{} ({}) must be a finite number", WholeBodyJointNames()[i], q[i]));
    }
  }
  const Pose3 X_MG = model.CalcPalmPose(q);
  const Eigen::Vector3d p_MF = model.CalcFingertipPosition(q);
  const bool in_limits = model.IsWithinLimits(q);
  if (options.json) {
    std::cout << nlohmann::json{{"q", std::vector<double>(q.data(), q.data() + q.size())},
                                {"within_limits", in_limits},
                                {"X_MG", PoseJson(X_MG)},
                                {"p_MF", {p_MF.x(), p_MF.y(), p_MF.z()}}}
                     .dump(2)
              << "\n";
    return;
  }
  for (int i = 0; i < kNumWholeBodyJoints; ++i) {
    fmt::print("  {:<18} {:+.4f}\n", WholeBodyJointNames()[i], q[i]);
  }
  if (!in_limits) fmt::print("  warning: the configuration is outside the joint limits\n");
  fmt::print("palm X_MG         {}\n", PoseText(X_MG));
  fmt::print("fingertip p_MF    ({:+.4f}, {:+.4f}, {:+.4f}) m\n", p_MF.x(), p_MF.y(), p_MF.z());
}

}  // namespace

void AddModelCommand(CLI::App& app) {
  auto options = std::make_shared<ModelOptions>();
  auto* model = app.add_subcommand("model", "Inspect the HSR robot model (limits, sensors, FK)");
  model->require_subcommand(1);

  auto* info = model->add_subcommand("info", "Joints, limits, footprint and sensor mounting");
  auto* fk = model->add_subcommand("fk", "Forward kinematics of the palm and fingertip point");
  for (auto* command : {info, fk}) {
    command->add_option("--urdf", options->urdf, "URDF file (default: the shipped HSR model)")
        ->check(CLI::ExistingFile);
    command->add_flag("--json", options->json, "Print JSON instead of a table");
  }
  fk->add_option("--arm", options->arm,
                 "arm_lift [m], arm_flex, arm_roll, wrist_flex, wrist_roll [rad]")
      ->expected(1, 5);
  fk->add_option("--base", options->base, "base x [m], y [m], yaw [rad] in the map frame")
      ->expected(1, 3);
  info->callback([options] { RunInfo(*options); });
  fk->callback([options] { RunFk(*options); });
}

}  // namespace egress::apps
