#include "egress/planning/base_planner.h"

#include <cmath>
#include <mutex>
#include <numbers>
#include <queue>

#include <fcl/geometry/octree/octree.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/collision.h>
#include <ompl/base/objectives/PathLengthOptimizationObjective.h>
#include <ompl/base/objectives/StateCostIntegralObjective.h>
#include <ompl/base/spaces/SE2StateSpace.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/informedtrees/BITstar.h>
#include <ompl/geometric/planners/prm/PRMstar.h>
#include <ompl/geometric/planners/rrt/InformedRRTstar.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/geometric/planners/rrt/RRTstar.h>
#include <ompl/tools/benchmark/Benchmark.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

#include "egress/hsr_interface/error.h"

namespace egress::planning {

namespace ob = ompl::base;
namespace og = ompl::geometric;
using perception::kInscribedCost;
using perception::kLethalCost;
using perception::kUnknownCost;

void BasePlannerConfig::Validate() const {
  const auto names = BasePlanner::PlannerNames();
  ThrowUnless(std::find(names.begin(), names.end(), planner) != names.end(),
              "Invalid BasePlannerConfig: planner '", planner,
              "' is not one of RRTConnect, RRTstar, PRMstar, BITstar, InformedRRTstar.");
  ThrowUnless(time_budget > 0.0 && simplify_time >= 0.0,
              "Invalid BasePlannerConfig: time_budget must be > 0 and ", "simplify_time >= 0.");
  ThrowUnless(footprint_radius > 0.0 && robot_height > 0.0,
              "Invalid BasePlannerConfig: footprint_radius and ", "robot_height must be > 0.");
  ThrowUnless(costmap_cost_weight >= 0.0 && door_standoff > 0.0,
              "Invalid BasePlannerConfig: costmap_cost_weight ",
              "must be >= 0 and door_standoff > 0.");
  ThrowUnless(std::isfinite(clearance_weight) && clearance_weight >= 0.0 &&
                  std::isfinite(clearance_margin) && clearance_margin >= 0.0,
              "Invalid BasePlannerConfig: clearance_weight and clearance_margin must be finite ",
              "and >= 0, got ", clearance_weight, " and ", clearance_margin, ".");
  ThrowUnless(std::isfinite(personal_space_weight) && personal_space_weight >= 0.0,
              "Invalid BasePlannerConfig: personal_space_weight must be finite and >= 0, got ",
              personal_space_weight, ".");
  ThrowUnless(std::isfinite(doorway_weight) && doorway_weight >= 0.0,
              "Invalid BasePlannerConfig: doorway_weight must be finite and >= 0, got ",
              doorway_weight, ".");
}

std::string_view ToString(PlanStatus status) {
  switch (status) {
    case PlanStatus::kSuccess:
      return "success";
    case PlanStatus::kInvalidRequest:
      return "invalid_request";
    case PlanStatus::kStartInCollision:
      return "start_in_collision";
    case PlanStatus::kGoalInCollision:
      return "goal_in_collision";
    case PlanStatus::kGoalUnreachable:
      return "goal_unreachable";
    case PlanStatus::kTimeout:
      return "timeout";
  }
  return "unknown";
}

std::vector<std::string> BasePlanner::PlannerNames() {
  return {"RRTConnect", "RRTstar", "PRMstar", "BITstar", "InformedRRTstar"};
}

namespace {

// OMPL's SO2 asserts yaw in [-pi, pi) — WrapAngle's (-pi, pi] differs at exactly pi (a door
// normal along -x gives atan2(+0, -1) = pi).
double So2Yaw(double yaw) {
  const double wrapped = WrapAngle(yaw);
  return wrapped >= std::numbers::pi ? wrapped - 2.0 * std::numbers::pi : wrapped;
}

// Checks a base pose against the costmap and, if present, the OctoMap through FCL.
class FootprintValidityChecker final : public ob::StateValidityChecker {
 public:
  FootprintValidityChecker(const ob::SpaceInformationPtr& si, const perception::Costmap2D& costmap,
                           const fcl::OcTree<double>* octree, const BasePlannerConfig& config)
      : ob::StateValidityChecker(si),
        costmap_(costmap),
        octree_(octree),
        config_(config),
        cylinder_(std::make_shared<fcl::Cylinderd>(config.footprint_radius, config.robot_height)) {
    if (config.carry) box_ = std::make_shared<fcl::Boxd>(config.carry->size);
  }

  bool isValid(const ob::State* state) const override {
    const auto* s = state->as<ob::SE2StateSpace::StateType>();
    return IsValidPose({s->getX(), s->getY(), s->getYaw()});
  }

  bool IsValidPose(const Pose2& X_MB) const {
    const std::uint8_t cost = costmap_.CostAt(X_MB.translation());
    if (cost == kUnknownCost ? !config_.allow_unknown : cost >= kInscribedCost) return false;
    if (config_.carry) {
      // The carried box's footprint must not touch lethal cells.
      const Eigen::Vector2d half = config_.carry->size.head<2>() / 2;
      const double step = costmap_.geometry().resolution;
      for (double x = -half.x(); x <= half.x() + 1e-9; x += step) {
        for (double y = -half.y(); y <= half.y() + 1e-9; y += step) {
          const Eigen::Vector2d p =
              X_MB * (config_.carry->p_BBox.head<2>() + Eigen::Vector2d(x, y));
          if (costmap_.CostAt(p) == kLethalCost) return false;
        }
      }
    }
    if (octree_ == nullptr) return true;
    fcl::CollisionObjectd world(std::shared_ptr<fcl::CollisionGeometryd>(
        const_cast<fcl::OcTree<double>*>(octree_), [](fcl::CollisionGeometryd*) {}));
    fcl::CollisionRequestd request;
    const Pose3 X_MB3 = Pose3::FromPose2(X_MB);
    auto collides = [&](const std::shared_ptr<fcl::CollisionGeometryd>& geometry,
                        const Pose3& X_MS) {
      fcl::Transform3d X = fcl::Transform3d::Identity();
      X.linear() = X_MS.rotation();
      X.translation() = X_MS.translation();
      fcl::CollisionObjectd object(geometry, X);
      fcl::CollisionResultd result;
      return fcl::collide(&object, &world, request, result) > 0;
    };
    if (body_.empty()) {
      if (collides(cylinder_, X_MB3 * Pose3(Eigen::Vector3d(0, 0, config_.robot_height / 2))))
        return false;
    } else if (collides(body_bound_, X_MB3 * X_BBound_)) {
      // Near a 3D obstacle: the shapes themselves decide.
      for (const auto& [geometry, X_BS] : body_) {
        if (collides(geometry, X_MB3 * X_BS)) return false;
      }
    }
    fcl::CollisionResultd result;
    if (box_) {
      fcl::Transform3d X_MBox = fcl::Transform3d::Identity();
      X_MBox.linear() = Eigen::AngleAxisd(X_MB.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      X_MBox.translation() = Pose3::FromPose2(X_MB) * config_.carry->p_BBox;
      fcl::CollisionObjectd carried(box_, X_MBox);
      if (fcl::collide(&carried, &world, request, result) > 0) return false;
    }
    return true;
  }

  // All or nothing: a bad shape leaves the body as it was.
  void SetBody(const std::vector<PlacedShape>& shapes) {
    std::vector<std::pair<std::shared_ptr<fcl::CollisionGeometryd>, Pose3>> body;
    double radius = 0.0, z_low = 0.0, z_high = 0.0;
    for (const PlacedShape& placed : shapes) {
      const CollisionShape& s = placed.shape;
      ThrowUnless(placed.X_BS.IsFinite() && s.size.allFinite() && s.size.minCoeff() > 0.0,
                  "BasePlanner::SetBodyShapes: shape '", s.name, "' of link '", s.link,
                  "' has a non-finite pose or a non-positive size");
      std::shared_ptr<fcl::CollisionGeometryd> geometry;
      switch (s.kind) {
        case CollisionShape::Kind::kBox:
          geometry = std::make_shared<fcl::Boxd>(s.size);
          break;
        case CollisionShape::Kind::kCylinder:
          geometry = std::make_shared<fcl::Cylinderd>(s.size.x(), s.size.z());
          break;
        case CollisionShape::Kind::kSphere:
          geometry = std::make_shared<fcl::Sphered>(s.size.x());
          break;
      }
      const Eigen::Vector3d p = placed.X_BS.translation();
      const double r = s.BoundingRadius();
      radius = std::max(radius, p.head<2>().norm() + r);
      z_low = body.empty() ? p.z() - r : std::min(z_low, p.z() - r);
      z_high = body.empty() ? p.z() + r : std::max(z_high, p.z() + r);
      body.emplace_back(std::move(geometry), placed.X_BS);
    }
    body_ = std::move(body);
    if (body_.empty()) return;
    body_bound_ = std::make_shared<fcl::Cylinderd>(radius, std::max(z_high - z_low, 1e-3));
    X_BBound_ = Pose3(Eigen::Vector3d(0, 0, (z_low + z_high) / 2));
  }

 private:
  const perception::Costmap2D& costmap_;
  const fcl::OcTree<double>* octree_;
  const BasePlannerConfig& config_;
  std::shared_ptr<fcl::Cylinderd> cylinder_;
  std::shared_ptr<fcl::Boxd> box_;
  std::vector<std::pair<std::shared_ptr<fcl::CollisionGeometryd>, Pose3>> body_;  // shapes in B
  std::shared_ptr<fcl::CollisionGeometryd> body_bound_;  // a cylinder round all of them
  Pose3 X_BBound_;
};

// Whether p_MQ is in a cell `doorway` (DoorwayCells over `geometry`, or empty: none) marks.
bool InDoorway(const perception::GridGeometry& geometry, const std::vector<std::uint8_t>& doorway,
               const Eigen::Vector2d& p_MQ) {
  if (doorway.empty()) return false;
  const auto cell = geometry.CellOf(p_MQ);
  return cell && doorway[geometry.Index(cell->x(), cell->y())] != 0;
}

// Costmap cost as a state cost, for the optional clearance term of the objective.
class CostmapObjective final : public ob::StateCostIntegralObjective {
 public:
  CostmapObjective(const ob::SpaceInformationPtr& si, const perception::Costmap2D& costmap,
                   double personal_space_weight, const std::vector<std::uint8_t>& doorway,
                   double doorway_weight)
      : ob::StateCostIntegralObjective(si, true),
        costmap_(costmap),
        personal_space_weight_(personal_space_weight),
        doorway_(doorway),
        doorway_weight_(doorway_weight) {}
  ob::Cost stateCost(const ob::State* state) const override {
    const auto* s = state->as<ob::SE2StateSpace::StateType>();
    const Eigen::Vector2d p(s->getX(), s->getY());
    const std::uint8_t c = costmap_.CostAt(p);
    const double personal = personal_space_weight_ * costmap_.PersonalSpaceCostAt(p) /
                            double(perception::kPersonalSpacePeakCost);
    const double doorway = InDoorway(costmap_.geometry(), doorway_, p) ? doorway_weight_ : 0.0;
    return ob::Cost((c >= kInscribedCost ? 1.0 : double(c) / double(kInscribedCost)) + personal +
                    doorway);
  }

 private:
  const perception::Costmap2D& costmap_;
  double personal_space_weight_;
  const std::vector<std::uint8_t>& doorway_;  // DoorwayCells, or empty
  double doorway_weight_;
};

double PathLength(const std::vector<Pose2>& path) {
  double length = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i)
    length += (path[i].translation() - path[i - 1].translation()).norm();
  return length;
}

// Segment–segment intersection in the plane.
bool Crosses(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
             const Eigen::Vector2d& d) {
  const auto cross = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) {
    return u.x() * v.y() - u.y() * v.x();
  };
  const double d1 = cross(d - c, a - c), d2 = cross(d - c, b - c), d3 = cross(b - a, c - a),
               d4 = cross(b - a, d - a);
  return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0));
}

}  // namespace

struct BasePlanner::Impl {
  const perception::Costmap2D& costmap;
  std::shared_ptr<const octomap::OcTree> octomap;
  std::unique_ptr<fcl::OcTree<double>> fcl_octree;
  BasePlannerConfig config;
  std::shared_ptr<const Clock> clock;
  std::vector<PlannerDoor> doors;
  std::vector<std::uint8_t> doorway;  // the doors' doorway cells (DoorwayCells), per AddDoor
  std::shared_ptr<ob::SE2StateSpace> space;
  ob::SpaceInformationPtr si;
  std::shared_ptr<FootprintValidityChecker> checker;

  Impl(const perception::Costmap2D& c, std::shared_ptr<const octomap::OcTree> o,
       BasePlannerConfig cfg, std::shared_ptr<const Clock> clk)
      : costmap(c), octomap(std::move(o)), config(std::move(cfg)), clock(std::move(clk)) {
    config.Validate();
    static std::once_flag seeded;
    const std::uint32_t seed = config.seed;
    std::call_once(seeded, [seed] {
      ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
      ompl::RNG::setSeed(seed);
    });
    if (!clock) clock = std::make_shared<SteadyClock>();
    if (octomap) {
      fcl_octree = std::make_unique<fcl::OcTree<double>>(octomap);
      // Below the tree's occupancy threshold a node holds nothing to collide with: FCL may skip
      // it whole (its default, 0, makes it descend into every node the shape overlaps).
      fcl_octree->setFreeThres(octomap->getOccupancyThres());
    }
    const auto& g = costmap.geometry();
    space = std::make_shared<ob::SE2StateSpace>();
    ob::RealVectorBounds bounds(2);
    bounds.setLow(0, g.origin.x());
    bounds.setLow(1, g.origin.y());
    bounds.setHigh(0, g.origin.x() + g.width * g.resolution);
    bounds.setHigh(1, g.origin.y() + g.height * g.resolution);
    space->setBounds(bounds);
    si = std::make_shared<ob::SpaceInformation>(space);
    checker = std::make_shared<FootprintValidityChecker>(si, costmap, fcl_octree.get(), config);
    si->setStateValidityChecker(checker);
    // Check motions at a quarter cell: fine enough that a straight motion cannot slip between
    // two diagonally touching occupied cells.
    si->setStateValidityCheckingResolution(0.25 * g.resolution / space->getMaximumExtent());
    si->setup();
  }

  ob::PlannerPtr MakePlanner() const { return MakePlanner(config.planner); }
  ob::PlannerPtr MakePlanner(const std::string& name) const {
    if (name == "RRTstar") return std::make_shared<og::RRTstar>(si);
    if (name == "PRMstar") return std::make_shared<og::PRMstar>(si);
    if (name == "BITstar") return std::make_shared<og::BITstar>(si);
    if (name == "InformedRRTstar") return std::make_shared<og::InformedRRTstar>(si);
    return std::make_shared<og::RRTConnect>(si);
  }

  bool MotionValid(const Pose2& a, const Pose2& b) const {
    ob::ScopedState<ob::SE2StateSpace> sa(space), sb(space);
    sa->setXY(a.x, a.y);
    sa->setYaw(So2Yaw(a.yaw));
    sb->setXY(b.x, b.y);
    sb->setYaw(So2Yaw(b.yaw));
    return si->checkMotion(sa.get(), sb.get());
  }

  // Greedy line-of-sight shortcutting of a dense path (a grid seed): from each kept state, jump
  // to the farthest later state reachable by a valid straight motion (exponential then binary
  // search). OMPL's simplifier is far slower on thousands of states.
  // The cost of a cell clearance_margin beyond the footprint from an obstacle.
  std::uint8_t CloseCost() const {
    return std::max<std::uint8_t>(
        1, costmap.InflatedCost(costmap.config().robot_radius + config.clearance_margin));
  }

  // With `keep_clearance`, a shortcut must also keep clearance_margin from obstacles unless the
  // stretch of path it replaces came closer (its highest costmap cost bounds the shortcut's).
  // With `keep_personal_space`, likewise it may go no deeper into anyone's personal space, and
  // with `keep_out_of_doorways` no further through doorways than the stretch it replaces went.
  og::PathGeometric StringPull(const og::PathGeometric& dense, bool keep_clearance,
                               bool keep_personal_space, bool keep_out_of_doorways) const {
    og::PathGeometric pulled(si);
    const std::size_t n = dense.getStateCount();
    const auto xy = [&](std::size_t i) {
      const auto* st = dense.getState(i)->as<ob::SE2StateSpace::StateType>();
      return Eigen::Vector2d(st->getX(), st->getY());
    };
    const auto in_doorway = [&](const Eigen::Vector2d& p) {
      return InDoorway(costmap.geometry(), doorway, p);
    };
    keep_out_of_doorways = keep_out_of_doorways && !doorway.empty();
    std::vector<std::uint8_t> cost(n), personal(n);
    std::vector<bool> doorways(n);
    for (std::size_t i = 0; i < n; ++i) {
      cost[i] = costmap.CostAt(xy(i));
      personal[i] = costmap.PersonalSpaceCostAt(xy(i));
      doorways[i] = in_doorway(xy(i));
    }
    // How far the dense path has run in doorways up to each state [m].
    std::vector<double> doorway_run(n, 0.0);
    for (std::size_t i = 1; i < n; ++i)
      doorway_run[i] = doorway_run[i - 1] + (doorways[i] ? (xy(i) - xy(i - 1)).norm() : 0.0);
    const double step_length = 0.25 * costmap.geometry().resolution;
    const auto shortcut_ok = [&](std::size_t from, std::size_t to) {
      if (!si->checkMotion(dense.getState(from), dense.getState(to))) return false;
      if (!keep_clearance && !keep_personal_space && !keep_out_of_doorways) return true;
      const auto highest = [&](const std::vector<std::uint8_t>& along) {
        return *std::max_element(along.begin() + long(from), along.begin() + long(to) + 1);
      };
      const std::uint8_t bound = highest(cost), personal_bound = highest(personal);
      // A cell's worth of slack: the samples and the cell centres see a doorway's edge apart.
      double doorway_left = doorway_run[to] - doorway_run[from] + costmap.geometry().resolution;
      const Eigen::Vector2d a = xy(from), b = xy(to);
      const int steps = int(std::ceil((b - a).norm() / step_length));
      for (int k = 1; k < steps; ++k) {
        const Eigen::Vector2d p = a + (b - a) * (double(k) / steps);
        if (keep_clearance && costmap.CostAt(p) > bound) return false;
        if (keep_personal_space && costmap.PersonalSpaceCostAt(p) > personal_bound) return false;
        if (keep_out_of_doorways && in_doorway(p) && (doorway_left -= (b - a).norm() / steps) < 0)
          return false;
      }
      return true;
    };
    std::size_t anchor = 0;
    pulled.append(dense.getState(0));
    while (anchor + 1 < n) {
      std::size_t good = anchor + 1, step = 2;
      while (anchor + step < n && shortcut_ok(anchor, anchor + step)) {
        good = anchor + step;
        step *= 2;
      }
      std::size_t lo = good, hi = std::min(anchor + step, n - 1);
      while (hi > lo + 1) {
        const std::size_t mid = (lo + hi) / 2;
        if (shortcut_ok(anchor, mid)) {
          lo = mid;
        } else {
          hi = mid;
        }
      }
      anchor = lo;
      pulled.append(dense.getState(anchor));
    }
    return pulled;
  }

  // The grid's shortest path from start to goal, string-pulled; nullopt without one.
  std::optional<og::PathGeometric> GridSeed(const Pose2& start, const Pose2& goal,
                                            const ob::State* s, const ob::State* g) const {
    const auto cells =
        GridCheapestPath(costmap, start.translation(), goal.translation(),
                         {CloseCost(), config.clearance_weight, config.personal_space_weight,
                          doorway.empty() ? nullptr : &doorway, config.doorway_weight},
                         config.allow_unknown);
    if (!cells) return std::nullopt;
    og::PathGeometric dense(si);
    ob::ScopedState<ob::SE2StateSpace> state(space);
    dense.append(s);
    for (std::size_t i = 1; i + 1 < cells->size(); ++i) {
      state->setXY((*cells)[i].x(), (*cells)[i].y());
      state->setYaw(0.0);
      dense.append(state.get());
    }
    dense.append(g);
    return StringPull(dense, config.clearance_weight > 0.0, config.personal_space_weight > 0.0,
                      config.doorway_weight > 0.0);
  }

  // One OMPL query between two valid poses.
  PlanResult PlanSegment(const Pose2& start, const Pose2& goal, double budget) const {
    PlanResult result;
    og::SimpleSetup setup(si);
    ob::ScopedState<ob::SE2StateSpace> s(space), g(space);
    s->setXY(start.x, start.y);
    s->setYaw(So2Yaw(start.yaw));
    g->setXY(goal.x, goal.y);
    g->setYaw(So2Yaw(goal.yaw));
    setup.setStartAndGoalStates(s, g);
    auto length = std::make_shared<ob::PathLengthOptimizationObjective>(si);
    if (config.costmap_cost_weight > 0.0) {
      auto multi = std::make_shared<ob::MultiOptimizationObjective>(si);
      multi->addObjective(length, 1.0);
      multi->addObjective(
          std::make_shared<CostmapObjective>(si, costmap, config.personal_space_weight, doorway,
                                             config.doorway_weight),
          config.costmap_cost_weight);
      setup.setOptimizationObjective(multi);
    } else {
      setup.setOptimizationObjective(length);
    }
    if (config.deterministic) {
      // No sampling: the string-pulled grid path, checked by the same validity checker.
      auto seed = GridSeed(start, goal, s.get(), g.get());
      if (!seed || seed->getStateCount() < 2 || !seed->check()) {
        result.status = PlanStatus::kGoalUnreachable;
        result.message = "no collision-free grid path between start and goal";
        return result;
      }
      for (std::size_t i = 0; i < seed->getStateCount(); ++i) {
        const auto* st = seed->getState(i)->as<ob::SE2StateSpace::StateType>();
        result.path.push_back({st->getX(), st->getY(), st->getYaw()});
      }
      result.status = PlanStatus::kSuccess;
      return result;
    }
    setup.setPlanner(MakePlanner());
    const double sampling =
        config.grid_seed_after > 0.0 ? std::min(budget, config.grid_seed_after) : budget;
    const ob::PlannerStatus status = setup.solve(sampling);
    og::PathGeometric raw(si);
    bool seeded = false;
    if (status == ob::PlannerStatus::EXACT_SOLUTION) {
      raw = setup.getSolutionPath();
    } else if (config.grid_seed_after > 0.0) {
      if (auto seed = GridSeed(start, goal, s.get(), g.get())) {
        raw = std::move(*seed);
        seeded = true;
      }
    }
    if (raw.getStateCount() < 2 || !raw.check()) {
      result.status = PlanStatus::kTimeout;
      result.message = Cat("no path found within the time budget (", budget, " s, planner ",
                           config.planner, ")");
      return result;
    }
    og::PathGeometric path = raw;
    if (config.simplify_time > 0.0 && !seeded) {
      og::PathSimplifier simplifier(si);
      simplifier.simplify(path, config.simplify_time);
      if (!path.check()) path = raw;  // the simplified path must still be valid
    }
    // For the pure length objective, a sampled path that took a long way round (another
    // homotopy class) loses to the string-pulled grid path.
    if (!seeded && config.grid_seed_after > 0.0 && config.costmap_cost_weight == 0.0) {
      if (auto seed = GridSeed(start, goal, s.get(), g.get());
          seed && seed->length() < path.length() && seed->check()) {
        path = std::move(*seed);
      }
    }
    for (std::size_t i = 0; i < path.getStateCount(); ++i) {
      const auto* st = path.getState(i)->as<ob::SE2StateSpace::StateType>();
      result.path.push_back({st->getX(), st->getY(), st->getYaw()});
    }
    result.status = PlanStatus::kSuccess;
    return result;
  }

  static std::string Cat(const auto&... parts) { return StrCat(parts...); }
};

BasePlanner::BasePlanner(const perception::Costmap2D& costmap,
                         std::shared_ptr<const octomap::OcTree> octree, BasePlannerConfig config,
                         std::shared_ptr<const Clock> clock)
    : impl_(std::make_unique<Impl>(costmap, std::move(octree), std::move(config),
                                   std::move(clock))) {}

BasePlanner::~BasePlanner() = default;
BasePlanner::BasePlanner(BasePlanner&&) noexcept = default;
BasePlanner& BasePlanner::operator=(BasePlanner&&) noexcept = default;

void BasePlanner::AddDoor(const PlannerDoor& door) {
  ThrowUnless(
      door.p_MA.allFinite() && door.p_MB.allFinite() && (door.p_MB - door.p_MA).norm() > 0.1,
      "Invalid door '", door.id, "': jambs must be finite and at least 0.1 m apart.");
  impl_->doors.push_back(door);
  impl_->doorway = DoorwayCells(impl_->costmap.geometry(), impl_->doors,
                                impl_->config.door_standoff, impl_->config.footprint_radius);
}

void BasePlanner::SetBodyShapes(std::vector<PlacedShape> shapes) {
  impl_->checker->SetBody(shapes);
}

bool BasePlanner::IsValid(const Pose2& X_MB) const {
  ThrowUnless(X_MB.IsFinite(), "Invalid pose: must be finite.");
  return impl_->checker->IsValidPose(X_MB);
}

bool BasePlanner::IsPathValid(const std::vector<Pose2>& path) const {
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (!IsValid(path[i])) return false;
    if (i > 0 && !impl_->MotionValid(path[i - 1], path[i])) return false;
  }
  return true;
}

PlanResult BasePlanner::Plan(const Pose2& start, const Pose2& goal) const {
  const Duration t0 = impl_->clock->Now();
  const auto finish = [&](PlanResult result) {
    result.planning_time = ToSeconds(impl_->clock->Now() - t0);
    result.length = PathLength(result.path);
    return result;
  };
  PlanResult result;
  const auto& g = impl_->costmap.geometry();
  const auto in_map = [&](const Pose2& p) { return g.CellOf(p.translation()).has_value(); };
  if (!start.IsFinite() || !goal.IsFinite()) {
    result.message = "start and goal must be finite";
    return finish(result);
  }
  if (!in_map(start) || !in_map(goal)) {
    result.message =
        StrCat(!in_map(start) ? "start" : "goal", " (", (!in_map(start) ? start : goal).x, ", ",
               (!in_map(start) ? start : goal).y, ") is outside the map");
    return finish(result);
  }
  if (!IsValid(start)) {
    result.status = PlanStatus::kStartInCollision;
    result.message = StrCat("start (", start.x, ", ", start.y, ") is in collision");
    return finish(result);
  }
  if (!IsValid(goal)) {
    result.status = PlanStatus::kGoalInCollision;
    result.message = StrCat("goal (", goal.x, ", ", goal.y, ") is in collision");
    return finish(result);
  }
  // The grid's shortest path decides reachability and which doors lie on the way (in order).
  const auto grid_path = GridShortestPath(impl_->costmap, start.translation(), goal.translation(),
                                          impl_->config.allow_unknown);
  if (!grid_path) {
    result.status = PlanStatus::kGoalUnreachable;
    result.message =
        "no free connection from start to goal on the costmap (a closed door or a blocked passage)";
    return finish(result);
  }
  struct Crossing {
    Eigen::Vector2d direction;  // of travel through the door
    const PlannerDoor* door;
  };
  std::vector<Crossing> crossings;
  for (std::size_t i = 1; i < grid_path->size(); ++i) {
    for (const auto& door : impl_->doors) {
      if (Crosses((*grid_path)[i - 1], (*grid_path)[i], door.p_MA, door.p_MB)) {
        crossings.push_back({(*grid_path)[i] - (*grid_path)[i - 1], &door});
      }
    }
  }
  if (crossings.empty()) return finish(impl_->PlanSegment(start, goal, impl_->config.time_budget));
  // Second pass: through each door on its centreline, approach pose to exit pose.
  std::vector<Pose2> path;
  Pose2 from = start;
  for (const Crossing& crossing : crossings) {
    const PlannerDoor& door = *crossing.door;
    const Eigen::Vector2d center = (door.p_MA + door.p_MB) / 2;
    const Eigen::Vector2d along = (door.p_MB - door.p_MA).normalized();
    Eigen::Vector2d normal(-along.y(), along.x());
    if (crossing.direction.dot(normal) < 0) normal = -normal;  // point in the direction of travel
    const double yaw = std::atan2(normal.y(), normal.x());
    const Eigen::Vector2d a = center - impl_->config.door_standoff * normal;
    const Eigen::Vector2d b = center + impl_->config.door_standoff * normal;
    const Pose2 approach{a.x(), a.y(), yaw}, exit{b.x(), b.y(), yaw};
    if (!IsValid(approach) || !IsValid(exit) || !impl_->MotionValid(approach, exit)) {
      result.status = PlanStatus::kGoalUnreachable;
      result.message = StrCat("door '", door.id, "': its centreline is blocked");
      return finish(result);
    }
    PlanResult leg = impl_->PlanSegment(from, approach, impl_->config.time_budget);
    if (!leg.ok()) return finish(leg);
    if (!path.empty()) leg.path.erase(leg.path.begin());
    path.insert(path.end(), leg.path.begin(), leg.path.end());
    path.push_back(exit);
    result.doors_crossed.push_back(door.id);
    from = exit;
  }
  PlanResult last = impl_->PlanSegment(from, goal, impl_->config.time_budget);
  if (!last.ok()) return finish(last);
  path.insert(path.end(), last.path.begin() + 1, last.path.end());
  result.path = std::move(path);
  result.status = PlanStatus::kSuccess;
  return finish(result);
}

std::vector<BasePlanner::BenchmarkSummary> BasePlanner::RunOmplBenchmark(
    const Pose2& start, const Pose2& goal, const std::vector<std::string>& planners, int runs,
    double time_limit, const std::string& experiment, const std::filesystem::path& log_path) const {
  const auto names = PlannerNames();
  for (const auto& name : planners) {
    ThrowUnless(std::find(names.begin(), names.end(), name) != names.end(), "Unknown planner '",
                name, "'.");
  }
  ThrowUnless(runs >= 1 && time_limit > 0.0,
              "Invalid benchmark: runs must be >= 1 and time_limit > 0.");
  ThrowUnless(IsValid(start) && IsValid(goal),
              "Invalid benchmark problem: start and goal must be collision-free.");
  og::SimpleSetup setup(impl_->si);
  ob::ScopedState<ob::SE2StateSpace> s(impl_->space), g(impl_->space);
  s->setXY(start.x, start.y);
  s->setYaw(So2Yaw(start.yaw));
  g->setXY(goal.x, goal.y);
  g->setYaw(So2Yaw(goal.yaw));
  setup.setStartAndGoalStates(s, g);
  setup.setOptimizationObjective(std::make_shared<ob::PathLengthOptimizationObjective>(impl_->si));
  ompl::tools::Benchmark benchmark(setup, experiment);
  for (const auto& name : planners)
    benchmark.addPlanner(impl_->MakePlanner(name));
  ompl::tools::Benchmark::Request request(time_limit, 4096.0, static_cast<unsigned>(runs));
  request.displayProgress = false;
  request.saveConsoleOutput = false;  // OMPL would write ompl_<host>_<date>.console into the cwd
  request.simplify = true;
  benchmark.benchmark(request);
  if (!benchmark.saveResultsToFile(log_path.string().c_str())) {
    throw LoadError(StrCat("Cannot write the benchmark log '", log_path.string(), "'."));
  }
  std::vector<BenchmarkSummary> rows;
  for (const auto& planner : benchmark.getRecordedExperimentData().planners) {
    BenchmarkSummary row;
    row.planner = planner.name;
    std::vector<double> times, lengths;
    for (const auto& run : planner.runs) {
      ++row.runs;
      const auto get = [&](const char* key) -> std::optional<double> {
        auto it = run.find(key);
        if (it == run.end() || it->second.empty()) return std::nullopt;
        return std::stod(it->second);
      };
      if (auto t = get("time REAL")) times.push_back(*t);
      if (get("solved BOOLEAN").value_or(0.0) != 0.0 &&
          get("approximate solution BOOLEAN").value_or(0.0) == 0.0) {
        ++row.solved;
        if (auto l = get("simplified solution length REAL")) lengths.push_back(*l);
      }
    }
    const auto median = [](std::vector<double> v) {
      if (v.empty()) return 0.0;
      std::sort(v.begin(), v.end());
      return v[v.size() / 2];
    };
    row.median_time = median(times);
    row.median_length = median(lengths);
    rows.push_back(row);
  }
  return rows;
}

}  // namespace egress::planning
