// IK benchmark: our DLS solver (the paper's update) against KDL's ChainIkSolverPos_LMA on the
// same whole-body chain (base x, y + the 5 arm joints, built from the same URDF), over 10,000
// reachable targets at button height: the ADA operable range of door controls, 0.86-1.22 m
// (34-48 in). Cold: from the tucked pose. Warm: the next target 1 cm on, from the previous
// solution (the approach phase's local refinement). Also reported: convergence for targets
// just below the tucked palm (0.80-0.86 m), which the tucked, vertical arm reaches only through
// its singular configuration, where the paper's damping (0.5) makes progress slow.
// Then the reach the tasks use, cold from the robot description's tucked pose, under both
// schedules (the paper's, IkMethod::kPaperDls, and the default adaptive one): table tops
// 0.40-0.90 m (palm, position only and with a horizontal approach axis, as grasps ask) and
// buttons 0.86-1.22 m (fingertip with the approach axis, as presses ask). Targets are reachable
// by construction (the palm of sampled configurations; for the approach-axis sets, configurations
// whose palm axis is horizontal).
// Prints tables and writes ik_bench.json. Run: build/bench/ik_bench [count]

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <random>

#include <urdf_parser/urdf_parser.h>
#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainiksolverpos_lma.hpp>
#include <nlohmann/json.hpp>

#include "egress/planning/ik_solver.h"

namespace {

using namespace egress;
using Clock = std::chrono::steady_clock;

// The palm chain of the URDF as a KDL chain, with base x and y as prismatic joints.
KDL::Chain MakeKdlChain(const std::string& urdf_path) {
  const auto model = urdf::parseURDFFile(urdf_path);
  if (!model) throw std::runtime_error("cannot parse " + urdf_path);
  std::vector<urdf::JointConstSharedPtr> joints;
  for (auto link = model->getLink("hand_palm_link"); link && link->parent_joint;
       link = link->getParent()) {
    joints.push_back(link->parent_joint);
  }
  std::reverse(joints.begin(), joints.end());
  KDL::Chain chain;
  chain.addSegment(KDL::Segment("base_x", KDL::Joint(KDL::Joint::TransX)));
  chain.addSegment(KDL::Segment("base_y", KDL::Joint(KDL::Joint::TransY)));
  for (const auto& joint : joints) {
    const auto& o = joint->parent_to_joint_origin_transform;
    const KDL::Vector p(o.position.x, o.position.y, o.position.z);
    const KDL::Rotation R =
        KDL::Rotation::Quaternion(o.rotation.x, o.rotation.y, o.rotation.z, o.rotation.w);
    const bool moving =
        (joint->type == urdf::Joint::REVOLUTE || joint->type == urdf::Joint::PRISMATIC) &&
        !(joint->limits && joint->limits->lower == 0.0 && joint->limits->upper == 0.0);
    const KDL::Vector axis = R * KDL::Vector(joint->axis.x, joint->axis.y, joint->axis.z);
    const KDL::Joint kdl_joint =
        !moving ? KDL::Joint(joint->name, KDL::Joint::None)
                : KDL::Joint(joint->name, p, axis,
                             joint->type == urdf::Joint::REVOLUTE ? KDL::Joint::RotAxis
                                                                  : KDL::Joint::TransAxis);
    chain.addSegment(KDL::Segment(joint->child_link_name, kdl_joint, KDL::Frame(R, p)));
  }
  return chain;
}

struct Stats {
  std::vector<double> us;
  int converged{0};
  std::vector<int> iterations;
  double Median() {
    std::sort(us.begin(), us.end());
    return us.empty() ? 0.0 : us[us.size() / 2];
  }
  double P99() {
    std::sort(us.begin(), us.end());
    return us.empty() ? 0.0 : us[std::min(us.size() - 1, us.size() * 99 / 100)];
  }
};

}  // namespace

int main(int argc, char** argv) {
  const int count = argc > 1 ? std::atoi(argv[1]) : 10000;
  const RobotModel model = RobotModel::LoadDefault();
  const planning::DlsIkSolver solver(model);
  const KDL::Chain chain = MakeKdlChain(RobotModel::DefaultUrdfPath().string());
  KDL::ChainFkSolverPos_recursive kdl_fk(chain);
  Eigen::Matrix<double, 6, 1> weights;
  weights << 1, 1, 1, 0, 0, 0;  // position only, like ours
  KDL::ChainIkSolverPos_LMA kdl(chain, weights, 1e-3, 200);

  // The speed comparison keeps the start it has always used (a near-vertical arm, KDL's too).
  WholeBodyVector tucked = WholeBodyVector::Zero();
  tucked[kArmLift] = 0.01;
  tucked[kArmFlex] = -0.01;
  // Reachable by construction: the palm of random arm configurations, kept at button height.
  std::mt19937 random(2026);
  std::uniform_real_distribution<double> lift(0.0, 0.5), flex(-2.0, -0.3), roll(-0.5, 0.5),
      wflex(-1.2, 0.4), wroll(-1.0, 1.0), base(-0.3, 0.3);
  std::vector<Eigen::Vector3d> targets, low_targets;
  while (int(targets.size()) < count || int(low_targets.size()) < count / 10) {
    WholeBodyVector q = WholeBodyVector::Zero();
    q << base(random), base(random), 0.0, lift(random), flex(random), roll(random), wflex(random),
        wroll(random);
    const Eigen::Vector3d p = model.CalcPalmPose(q).translation();
    if (p.x() <= 0.3) continue;
    if (p.z() >= 0.86 && p.z() <= 1.22 && int(targets.size()) < count) targets.push_back(p);
    if (p.z() >= 0.80 && p.z() < 0.86 && int(low_targets.size()) < count / 10)
      low_targets.push_back(p);
  }
  int low_converged = 0;
  for (const auto& target : low_targets)
    low_converged += solver.Solve({target, std::nullopt}, tucked).converged;
  const Eigen::Vector3d nudge(0.007, 0.005, 0.005);  // the next target, ~1 cm on

  Stats ours_cold, ours_warm, kdl_cold, kdl_warm;
  for (const auto& target : targets) {
    auto t0 = Clock::now();
    const auto cold = solver.Solve({target, std::nullopt}, tucked);
    ours_cold.us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
    ours_cold.converged += cold.converged;
    ours_cold.iterations.push_back(cold.iterations);
    t0 = Clock::now();
    const auto warm = solver.Solve({target + nudge, std::nullopt}, cold.q);
    ours_warm.us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
    ours_warm.converged += warm.converged;
    ours_warm.iterations.push_back(warm.iterations);

    KDL::JntArray q_init(chain.getNrOfJoints()), q_out(chain.getNrOfJoints());
    q_init(2) = tucked[kArmLift];
    q_init(3) = tucked[kArmFlex];
    const KDL::Frame goal(KDL::Vector(target.x(), target.y(), target.z()));
    t0 = Clock::now();
    const int kdl_status = kdl.CartToJnt(q_init, goal, q_out);
    kdl_cold.us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
    kdl_cold.converged += kdl_status >= 0;
    const KDL::Frame goal2(
        KDL::Vector(target.x() + nudge.x(), target.y() + nudge.y(), target.z() + nudge.z()));
    KDL::JntArray q_warm(chain.getNrOfJoints());
    t0 = Clock::now();
    const int kdl_warm_status = kdl.CartToJnt(q_out, goal2, q_warm);
    kdl_warm.us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
    kdl_warm.converged += kdl_warm_status >= 0;
  }
  const auto rate = [&](const Stats& s) { return 100.0 * s.converged / double(targets.size()); };
  const auto median_iterations = [](std::vector<int> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  std::printf(
      "IK over %zu reachable targets at 0.86-1.22 m (whole-body chain: base x, y + 5 arm joints)\n",
      targets.size());
  std::printf("%-28s %12s %12s %12s %10s\n", "solver", "median [us]", "p99 [us]", "converged",
              "med iters");
  std::printf("%-28s %12.1f %12.1f %11.2f%% %10d\n", "egress DLS, cold", ours_cold.Median(),
              ours_cold.P99(), rate(ours_cold), median_iterations(ours_cold.iterations));
  std::printf("%-28s %12.1f %12.1f %11.2f%% %10d\n", "egress DLS, warm", ours_warm.Median(),
              ours_warm.P99(), rate(ours_warm), median_iterations(ours_warm.iterations));
  std::printf("%-28s %12.1f %12.1f %11.2f%% %10s\n", "KDL ChainIkSolverPos_LMA, cold",
              kdl_cold.Median(), kdl_cold.P99(), rate(kdl_cold), "-");
  std::printf("%-28s %12.1f %12.1f %11.2f%% %10s\n", "KDL ChainIkSolverPos_LMA, warm",
              kdl_warm.Median(), kdl_warm.P99(), rate(kdl_warm), "-");
  std::printf(
      "median time ratio egress/KDL: cold %.2f, warm %.2f (KDL's LMA ignores joint limits)\n",
      ours_cold.Median() / kdl_cold.Median(), ours_warm.Median() / kdl_warm.Median());
  const double low_rate = 100.0 * low_converged / double(low_targets.size());
  std::printf(
      "below the tucked palm (0.80-0.86 m, %zu targets): egress DLS cold converges %.2f%%\n",
      low_targets.size(), low_rate);

  // --- Reach over what the tasks ask, cold from the robot description's tucked pose.
  const WholeBodyVector q_tucked = model.tucked_configuration();
  struct ReachSet {
    const char* name;
    double z_min, z_max;
    bool fingertip, oriented;
  };
  const ReachSet sets[] = {{"table tops 0.40-0.90 m, palm", 0.40, 0.90, false, false},
                           {"table tops 0.40-0.90 m, palm + axis", 0.40, 0.90, false, true},
                           {"buttons 0.86-1.22 m, fingertip + axis", 0.86, 1.22, true, true}};
  std::uniform_real_distribution<double> lift_all(0.0, 0.69), flex_all(-2.6, 0.0),
      yaw_axis(-0.6, 0.6);
  nlohmann::json reach_json = nlohmann::json::array();
  std::printf("\nreach, cold from the tucked pose (%d targets per set)\n", count);
  std::printf("%-40s %14s %14s %12s %12s\n", "targets", "paper conv.", "adaptive conv.",
              "paper iters", "adapt. iters");
  for (const ReachSet& set : sets) {
    std::vector<planning::IkTarget> reach_targets;
    while (int(reach_targets.size()) < count) {
      WholeBodyVector q = WholeBodyVector::Zero();
      const double flex_q = flex_all(random);
      // Horizontal palm axis: roll 0 and the wrist leveled (then a yaw of the approach from
      // the arm roll would tilt it; keep roll 0 and turn the base instead).
      const double wrist = set.oriented ? -std::numbers::pi / 2 - flex_q : wflex(random);
      q << base(random), base(random), set.oriented ? yaw_axis(random) : 0.0, lift_all(random),
          flex_q, set.oriented ? 0.0 : roll(random), wrist, wroll(random);
      if (!model.IsWithinLimits(q)) continue;
      const Pose3 X = model.CalcPalmPose(q);
      const Eigen::Vector3d p =
          set.fingertip ? model.CalcFingertipPosition(q) : Eigen::Vector3d(X.translation());
      if (p.z() < set.z_min || p.z() > set.z_max || p.head<2>().norm() < 0.35) continue;
      planning::IkTarget target{p, std::nullopt};
      if (set.oriented) target.approach_M = X.rotation().col(2);
      reach_targets.push_back(target);
    }
    planning::IkConfig paper_config, adaptive_config;
    paper_config.method = planning::IkMethod::kPaperDls;
    paper_config.fingertip = adaptive_config.fingertip = set.fingertip;
    const planning::DlsIkSolver paper(model, paper_config), adaptive(model, adaptive_config);
    int paper_ok = 0, adaptive_ok = 0;
    std::vector<int> paper_iterations, adaptive_iterations;
    for (const auto& target : reach_targets) {
      const auto a = paper.Solve(target, q_tucked);
      const auto b = adaptive.Solve(target, q_tucked);
      paper_ok += a.converged;
      adaptive_ok += b.converged;
      paper_iterations.push_back(a.iterations);
      adaptive_iterations.push_back(b.iterations);
    }
    const double paper_rate = 100.0 * paper_ok / count, adaptive_rate = 100.0 * adaptive_ok / count;
    std::printf("%-40s %13.2f%% %13.2f%% %12d %12d\n", set.name, paper_rate, adaptive_rate,
                median_iterations(paper_iterations), median_iterations(adaptive_iterations));
    reach_json.push_back({{"targets", set.name},
                          {"paper_converged_percent", paper_rate},
                          {"adaptive_converged_percent", adaptive_rate},
                          {"paper_median_iterations", median_iterations(paper_iterations)},
                          {"adaptive_median_iterations", median_iterations(adaptive_iterations)}});
  }

  nlohmann::json json = {{"targets", targets.size()},
                         {"egress_cold_converged_percent_below_tucked_palm", low_rate},
                         {"egress_cold_median_us", ours_cold.Median()},
                         {"egress_warm_median_us", ours_warm.Median()},
                         {"egress_cold_converged_percent", rate(ours_cold)},
                         {"egress_warm_converged_percent", rate(ours_warm)},
                         {"kdl_cold_median_us", kdl_cold.Median()},
                         {"kdl_warm_median_us", kdl_warm.Median()},
                         {"kdl_cold_converged_percent", rate(kdl_cold)},
                         {"kdl_warm_converged_percent", rate(kdl_warm)},
                         {"reach_from_tucked", reach_json}};
  std::ofstream("ik_bench.json") << json.dump(2) << "\n";
  return 0;
}
