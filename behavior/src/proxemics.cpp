#include "egress/behavior/proxemics.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "egress/hsr_interface/error.h"

namespace egress::behavior {
namespace {
constexpr double kMovingMps = 1e-3;  // [m/s] slower than this the robot goes nowhere
}  // namespace

void ProxemicsConfig::Validate() const {
  ThrowUnless(
      std::isfinite(slow_gap) && std::isfinite(stop_gap) && stop_gap >= 0 && slow_gap > stop_gap,
      "ProxemicsConfig: need 0 <= stop_gap < slow_gap (m)");
  ThrowUnless(std::isfinite(horizon) && horizon >= 0, "ProxemicsConfig: horizon must be >= 0");
  ThrowUnless(cone_deg > 0 && cone_deg <= 180, "ProxemicsConfig: cone_deg must be in (0, 180]");
  ThrowUnless(std::isfinite(pass_gap) && pass_gap >= 0,
              "ProxemicsConfig: pass_gap must be >= 0 (m)");
  ThrowUnless(std::isfinite(goal_radius) && goal_radius >= 0,
              "ProxemicsConfig: goal_radius must be >= 0");
  ThrowUnless(std::isfinite(space_horizon) && space_horizon >= 0 && std::isfinite(space_step) &&
                  space_step > 0,
              "ProxemicsConfig: space_horizon must be >= 0 and space_step > 0 (s)");
  ThrowUnless(std::isfinite(patience_s) && patience_s >= 0,
              "ProxemicsConfig: patience_s must be >= 0 (s)");
  ThrowUnless(std::isfinite(squeeze_gap) && squeeze_gap >= 0 && squeeze_gap < stop_gap,
              "ProxemicsConfig: need 0 <= squeeze_gap < stop_gap (m)");
  ThrowUnless(std::isfinite(standing_speed) && standing_speed >= 0,
              "ProxemicsConfig: standing_speed must be >= 0 (m/s)");
  ThrowUnless(std::isfinite(doorway_depth) && doorway_depth >= 0,
              "ProxemicsConfig: doorway_depth must be >= 0 (m)");
}

bool IsWhomTheRobotGoesTo(const Eigen::Vector2d& p_MP, const Eigen::Vector2d& p_MB,
                          const Eigen::Vector2d& p_MGoal, double goal_radius) {
  // The nearness to the robot matters too: with the end's radius alone, a resident queueing by
  // the button the robot went to press was "whom it goes to", and the robot drove past them at
  // 0.2 m/s and 6 cm (two wards seed 8).
  return (p_MP - p_MGoal).norm() < goal_radius && (p_MP - p_MB).norm() >= (p_MGoal - p_MB).norm();
}

bool IsPassedOnTheWay(const Eigen::Vector2d& p_MP, const Eigen::Vector2d& p_MB,
                      const Eigen::Vector2d& p_MGoal, double reach) {
  const Eigen::Vector2d way = p_MGoal - p_MB;
  const double length = way.norm();
  if (length < 1e-9) return false;
  const Eigen::Vector2d d = p_MP - p_MB;
  const double along = way.dot(d) / length;
  return along > 0.0 && along < length &&
         std::abs(way.x() * d.y() - way.y() * d.x()) / length < reach;
}

double ApproachSpeedScale(const Pose2& X_MB, const Eigen::Vector2d& v_M,
                          const std::optional<Eigen::Vector2d>& p_MGoal,
                          const std::vector<perception::TrackedPersonWithIntent>& people,
                          double robot_radius, double person_radius, const ProxemicsConfig& config,
                          bool squeeze) {
  if (!config.slow_near_people || v_M.norm() < kMovingMps) return 1.0;
  const Eigen::Vector2d way = v_M.normalized();
  const double cos_cone = std::cos(config.cone_deg * M_PI / 180.0);
  double scale = 1.0;
  for (const auto& entry : people) {
    const auto& person = entry.person;
    // Whom it goes to stands there waiting, and not beside its straight way there (within
    // pass_gap): someone walking up, or passed on the way, is not (atrium seed 71: a step making
    // room, ending 0.5 m past where a resident walking up to queue stopped, took the robot into
    // her at 0.5 m/s).
    if (p_MGoal && person.v_MP.norm() < config.standing_speed &&
        IsWhomTheRobotGoesTo(person.p_MP, X_MB.translation(), *p_MGoal, config.goal_radius) &&
        !IsPassedOnTheWay(person.p_MP, X_MB.translation(), *p_MGoal,
                          robot_radius + person_radius + config.pass_gap))
      continue;
    const bool edge_past = squeeze && person.v_MP.norm() < config.standing_speed;
    const double slow_gap = edge_past ? config.stop_gap : config.slow_gap;
    const double stop_gap = edge_past ? config.squeeze_gap : config.stop_gap;
    for (const Eigen::Vector2d& p_MP :
         {person.p_MP, Eigen::Vector2d(person.p_MP + person.v_MP * config.horizon)}) {
      const Eigen::Vector2d d = p_MP - X_MB.translation();
      const double distance = d.norm();
      const double gap = distance - robot_radius - person_radius;
      if (gap >= slow_gap) continue;
      // Not towards them. Edging past someone standing, going by them counts too (the path may
      // pass them closer than it heads at them), at a crawl that ends short of touching. So does
      // going by anyone ahead of abeam within pass_gap (atrium seed 71: she was 61 degrees off).
      if (distance > 1e-9) {
        const double along = way.dot(d);
        const double pass = std::abs(way.x() * d.y() - way.y() * d.x());
        const bool grazing = along > 0.0 && pass - robot_radius - person_radius < config.pass_gap;
        if (along < (edge_past ? 0.0 : cos_cone) * distance && !grazing) continue;
      }
      scale = std::min(scale, std::clamp((gap - stop_gap) / (slow_gap - stop_gap), 0.0, 1.0));
    }
  }
  return scale;
}

bool IsLeavingDoorway(const Pose2& X_MB, const Eigen::Vector2d& v_M,
                      const std::vector<perception::DoorModel>& doors, double doorway_depth,
                      double robot_radius) {
  if (doorway_depth <= 0.0 || v_M.norm() < kMovingMps) return false;
  for (const perception::DoorModel& door : doors) {
    const double width = door.width();
    if (!(width > 1e-9)) continue;
    const Eigen::Vector2d along = (door.p_MLatch - door.p_MHinge) / width;
    const Eigen::Vector2d normal(-along.y(), along.x());
    const Eigen::Vector2d from_centre = X_MB.translation() - 0.5 * (door.p_MHinge + door.p_MLatch);
    const double depth = from_centre.dot(normal);
    if (std::abs(depth) < doorway_depth &&
        std::abs(from_centre.dot(along)) < 0.5 * width + robot_radius &&
        depth * v_M.dot(normal) > 0.0)
      return true;
  }
  return false;
}

ApproachPace::ApproachPace(ProxemicsConfig config) : config_(std::move(config)) {
  config_.Validate();
}

double ApproachPace::Update(double now_s, const Pose2& X_MB, const Eigen::Vector2d& v_M,
                            const std::optional<Eigen::Vector2d>& p_MGoal,
                            const std::vector<perception::TrackedPersonWithIntent>& people,
                            double robot_radius, double person_radius, bool leaving_doorway) {
  double scale =
      ApproachSpeedScale(X_MB, v_M, p_MGoal, people, robot_radius, person_radius, config_);
  if (leaving_doorway && scale < kHeldScale) {
    // Out of the doorway at a crawl: slowed for anyone ahead from stop_gap, stopped at
    // squeeze_gap (where standing would be a contact, not only a nuisance).
    ProxemicsConfig out = config_;
    out.slow_gap = config_.stop_gap;
    out.stop_gap = config_.squeeze_gap;
    scale =
        std::max(scale, std::min(kHeldScale, ApproachSpeedScale(X_MB, v_M, p_MGoal, people,
                                                                robot_radius, person_radius, out)));
  }
  // Going nowhere tells nothing: held to a standstill at a path's start, the planned pace
  // itself hovers there, and a step in which it is below kMovingMps is no step free.
  if (v_M.norm() < kMovingMps) return scale;
  squeezing_ = false;
  if (config_.patience_s <= 0.0 || scale >= kHeldScale) {
    held_since_.reset();
    return scale;
  }
  // Held by people standing still: edging past them would go faster. Held by someone walking
  // (who will be gone), the patience starts afresh.
  const double edging = ApproachSpeedScale(X_MB, v_M, p_MGoal, people, robot_radius, person_radius,
                                           config_, /*squeeze=*/true);
  if (!(edging > scale)) {
    held_since_.reset();
    return scale;
  }
  // Held again after a while with no path (a pause to let people by): patience afresh.
  if (!held_since_ || now_s - last_held_s_ > kHeldGapSec) held_since_ = now_s;
  last_held_s_ = now_s;
  if (now_s - *held_since_ < config_.patience_s) return scale;
  squeezing_ = true;
  return edging;
}

std::optional<double> OncomingPassTime(const perception::TrackedPerson& person,
                                       const Eigen::Vector2d& p_MB, double robot_radius,
                                       double person_radius, double gap, double horizon,
                                       double walking_speed) {
  const Eigen::Vector2d& v = person.v_MP;
  const double speed = v.norm();
  const Eigen::Vector2d to_robot = p_MB - person.p_MP;
  if (!(speed > walking_speed) || to_robot.dot(v) <= 0.0) return std::nullopt;
  // Their nearest point to the robot on their straight way, and within the horizon.
  const double t_pass = to_robot.dot(v) / (speed * speed);
  const double t = std::min(t_pass, horizon);
  if ((person.p_MP + v * t - p_MB).norm() - robot_radius - person_radius >= gap)
    return std::nullopt;
  return t_pass;
}

}  // namespace egress::behavior
