#include "doorway_judge.h"

#include <cmath>
#include <utility>

namespace egress::apps {

DoorwayBlockJudge::DoorwayBlockJudge(std::vector<twin::DoorwayFrame> doorways)
    : doorways_(std::move(doorways)) {}

bool DoorwayBlockJudge::InDoorway(const Eigen::Vector2d& p_WB) const {
  for (const auto& d : doorways_) {
    const Eigen::Vector2d rel = p_WB - d.centre;
    if (std::abs(rel.dot(d.normal)) < kInDoorwayM && std::abs(rel.dot(d.along)) < d.half_width)
      return true;
  }
  return false;
}

void DoorwayBlockJudge::Step(double dt, const Eigen::Vector2d& p_WB, double speed,
                             const std::vector<Eigen::Vector2d>& p_WR) {
  if (!InDoorway(p_WB)) return;
  bool near = false;
  for (const auto& p : p_WR)
    near = near || (p - p_WB).norm() < kDoorwayBlockRadiusM;
  if (!near) return;
  in_doorway_s_ += dt;
  if (speed < twin::ScenarioJudge::kWaitSpeed) standing_s_ += dt;
}

}  // namespace egress::apps
