#include "egress/behavior/task_nodes.h"

#include <sstream>

#include "egress/hsr_interface/error.h"
#include "task_node_support.h"

namespace egress::behavior {

void TaskConfig::Validate() const {
  ThrowUnless(footprint_radius > 0 && door_entry_distance > 0 && door_exit_distance > 0 &&
                  zone_depth > 0 && person_radius >= 0,
              "TaskConfig: distances must be positive");
  ThrowUnless(arm_tuck_time > 0 && press_reach_time > 0 && press_time > 0 && wave_hold_time >= 0,
              "TaskConfig: motion times must be positive");
  ThrowUnless(std::isfinite(door_peek_time) && door_peek_time >= 0,
              "TaskConfig: door_peek_time must be >= 0 (s)");
  ThrowUnless(
      std::isfinite(door_peek_turn_deg) && door_peek_turn_deg >= 0 && door_peek_turn_deg <= 90,
      "TaskConfig: door_peek_turn_deg must be in [0, 90] (deg)");
  ThrowUnless(std::isfinite(passage_clearance) && passage_clearance >= 0 &&
                  std::isfinite(passage_quiet_time) && passage_quiet_time >= 0 &&
                  std::isfinite(passage_max_wait) && passage_max_wait >= 0,
              "TaskConfig: passage_clearance (m), passage_quiet_time and passage_max_wait (s) "
              "must be >= 0");
  ThrowUnless(right_of_way_radius >= 0 && right_of_way_time >= 0,
              "TaskConfig: right_of_way_radius and right_of_way_time must be >= 0");
  ThrowUnless(std::isfinite(near_waiter_radius) && near_waiter_radius >= 0 &&
                  std::isfinite(near_waiter_time) && near_waiter_time >= 0,
              "TaskConfig: near_waiter_radius (m) and near_waiter_time (s) must be >= 0");
  ThrowUnless(std::isfinite(comfort_distance) && comfort_distance >= 0,
              "TaskConfig: comfort_distance must be >= 0 (m)");
  ThrowUnless(std::isfinite(retreat_speed) && retreat_speed > 0,
              "TaskConfig: retreat_speed must be > 0 (m/s)");
  ThrowUnless(std::isfinite(give_way_horizon) && give_way_horizon >= 0 &&
                  std::isfinite(give_way_clear_for) && give_way_clear_for >= 0,
              "TaskConfig: give_way_horizon and give_way_clear_for must be >= 0 (s)");
  ThrowUnless(std::isfinite(person_sidestep) && person_sidestep >= 0 &&
                  std::isfinite(person_sidestep_speed) && person_sidestep_speed >= 0,
              "TaskConfig: person_sidestep (m) and person_sidestep_speed (m/s) must be >= 0");
  ThrowUnless(precise_pose_sigma > 0 && relocalize_timeout >= 0,
              "TaskConfig: precise_pose_sigma must be > 0 and relocalize_timeout >= 0");
  ik.Validate();
  route.Validate();
}

Pose2 ParsePose2(std::string_view text) {
  std::vector<double> values;
  std::stringstream in{std::string(text)};
  std::string part;
  while (std::getline(in, part, ';')) {
    try {
      std::size_t used = 0;
      values.push_back(std::stod(part, &used));
      if (part.find_first_not_of(" \t", used) != std::string::npos) throw std::invalid_argument("");
    } catch (const std::exception&) {
      throw InvalidArgument(StrCat("pose '", text, "': '", part, "' is not a number"));
    }
  }
  ThrowUnless(values.size() == 2 || values.size() == 3, "pose '", text,
              "': expected x;y;yaw (or x;y)");
  const Pose2 X{values[0], values[1], values.size() == 3 ? values[2] : 0.0};
  ThrowUnless(X.IsFinite(), "pose '", text, "': must be finite");
  return X;
}

Pose2 ResolveGoal(const MissionMap& map, std::string_view text, const Pose2& X_MB) {
  const std::string name(text);
  if (const MapPlace* place = map.FindPlace(name)) {
    if (place->has_yaw) return place->X_MP;
    // Any heading will do: arrive facing the way from here.
    const Eigen::Vector2d d = place->X_MP.translation() - X_MB.translation();
    return {place->X_MP.x, place->X_MP.y, d.norm() > 0.05 ? std::atan2(d.y(), d.x()) : X_MB.yaw};
  }
  const bool looks_like_pose = name.find(';') != std::string::npos;
  if (looks_like_pose) return ParsePose2(text);
  std::string places;
  for (const auto& p : map.places)
    places += (places.empty() ? "" : ", ") + p.name;
  throw InvalidArgument(StrCat("goal '", name, "' is neither a pose (x;y;yaw) nor a place of the ",
                               "building (places: ", places.empty() ? "none" : places, ")"));
}

std::string TaskNodesModelXml() {
  // Registration needs only the node types' ports; no node is built, so no services.
  bt::BehaviorTreeFactory factory;
  detail::RegisterConditionNodes(factory, nullptr);
  detail::RegisterNavigationNodes(factory, nullptr);
  detail::RegisterDoorNodes(factory, nullptr);
  detail::RegisterManipulationNodes(factory, nullptr);
  detail::RegisterGraspNodes(factory, nullptr);
  detail::RegisterReleaseNodes(factory, nullptr);
  detail::RegisterRouteNodes(factory, nullptr);
  detail::RegisterEscortNodes(factory, nullptr);
  detail::RegisterSweepNodes(factory, nullptr);
  return factory.WriteTreeNodesModelXml(false);
}

void RegisterTaskNodes(bt::BehaviorTreeFactory& factory, const TaskServices* services) {
  ThrowUnless(services != nullptr && services->map != nullptr && services->model != nullptr &&
                  services->motion != nullptr && services->planner != nullptr &&
                  services->log != nullptr && services->belief != nullptr,
              "RegisterTaskNodes: the services need a map, a robot model, a motion executor, a "
              "planner, a decision log and a belief");
  detail::RegisterConditionNodes(factory, services);
  detail::RegisterNavigationNodes(factory, services);
  detail::RegisterRouteNodes(factory, services);
  detail::RegisterDoorNodes(factory, services);
  detail::RegisterManipulationNodes(factory, services);
  detail::RegisterGraspNodes(factory, services);
  detail::RegisterReleaseNodes(factory, services);
  detail::RegisterEscortNodes(factory, services);
  detail::RegisterSweepNodes(factory, services);
}

}  // namespace egress::behavior
