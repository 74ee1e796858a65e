#pragma once
// Task services and a belief for ticking task nodes one at a time in the family tests: the lab's
// door (the wall y = 3, hinge at x = 0.475, latch at x = -0.475, opening north) with a push button
// south of it at x = 1.075, a free floor around it, the real robot model, motion executor and
// planner, and the factory with every task node registered.

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "egress/behavior/door_rules.h"
#include "egress/behavior/task_nodes.h"
#include "egress/bt/factory.h"
#include "egress/hsr_interface/error.h"

namespace egress::behavior::node_testing {

inline Time At(double t) {
  return Time{} + SecondsToDuration(t);
}

inline MissionMap LabDoor() {
  MissionMap map;
  map.grid = perception::OccupancyGrid::FromBoxes({}, {-3.0, -1.0}, {3.0, 7.0}, 0.05);
  perception::Doorway doorway;
  doorway.id = "lab_door";
  doorway.p_MHinge = {0.475, 3.0};
  doorway.p_MLatch = {-0.475, 3.0};
  map.doorways.push_back(doorway);
  perception::DoorModel door;
  door.id = "lab_door";
  door.p_MHinge = doorway.p_MHinge;
  door.p_MLatch = doorway.p_MLatch;
  door.swing_sign = -1.0;
  map.doors.push_back(door);
  MapActuator button;
  button.id = "lab_button";
  button.door = "lab_door";
  button.type = planning::ButtonType::kPushButton;
  button.p_M = {1.075, 2.93, 1.0};
  button.n_M = {0.0, -1.0, 0.0};
  button.protrusion = 0.02;
  map.actuators.push_back(button);
  return map;
}

inline perception::TrackedPersonWithIntent Person(const Eigen::Vector2d& p_MP,
                                                  perception::PersonIntent intent) {
  perception::TrackedPersonWithIntent entry;
  entry.person.p_MP = p_MP;
  entry.intent = intent;
  entry.door_id = "lab_door";
  return entry;
}

// A 270-degree scan (the HSR's base laser) with every return at 5 m: only its sweep matters.
inline LaserScan SweepScan() {
  LaserScan scan;
  scan.angle_min = -0.75 * M_PI;
  scan.angle_increment = 1.5 * M_PI / 100;
  scan.ranges.assign(101, 5.0f);
  scan.range_max = 20.0;
  return scan;
}

class TaskNodeFixture : public ::testing::Test {
 protected:
  TaskNodeFixture()
      : model_(RobotModel::LoadDefault()),
        motion_(model_),
        costmap_(map_.grid),
        planner_(costmap_, nullptr) {
    services_.map = &map_;
    services_.model = &model_;
    services_.motion = &motion_;
    services_.planner = &planner_;
    belief_.X_MB = {0.0, 2.0, M_PI / 2};  // 1 m south of the door, facing it
    services_.log = &log_;
    services_.belief = &belief_;
    RegisterTaskNodes(factory_, &services_);
  }
  // A tree of the one node `xml`, on `blackboard` if given (each call registers a tree of its
  // own, so a test may build several).
  bt::Tree Tree(const std::string& xml, bt::Blackboard::Ptr blackboard = nullptr) {
    std::string id = "t";
    id += std::to_string(trees_made_++);
    std::string text = R"(<root BTCPP_format="4"><BehaviorTree ID=")";
    text += id;
    text += R"(">)";
    text += xml;
    text += "</BehaviorTree></root>";
    return factory_.CreateTreeFromText(text, id, blackboard);
  }
  // The door seen open at `angle_deg`, steady, `open_for` seconds at `now` (an opening the robot
  // saw begin, unless `witnessed` is false).
  void DoorSeenOpen(double angle_deg, double open_for, bool witnessed = true) {
    perception::TrackedDoor door;
    door.model = map_.doors[0];
    door.state.observed = true;
    door.state.angle = angle_deg * M_PI / 180.0;
    door.state.clearance_width = door.model.ClearanceWidth(door.state.angle);
    door.state.motion = perception::DoorMotion::kHeldOpen;
    door.state.stamp = belief_.now;
    belief_.world.doors = {door};
    belief_.door_open_since["lab_door"] = belief_.now - SecondsToDuration(open_for);
    if (witnessed) {
      belief_.door_opening_witnessed.insert("lab_door");
    } else {
      belief_.door_opening_witnessed.erase("lab_door");
    }
  }
  // The people the robot sees now, and the door zones they occupy and the doorways they are near
  // recorded in the belief as the executive records them every control step.
  void See(std::vector<perception::TrackedPersonWithIntent> people) {
    belief_.world.people = std::move(people);
    for (const auto& door : map_.doors) {
      if (IsDoorZoneOccupied(services_, door.id)) belief_.zone_occupied_at[door.id] = belief_.now;
      if (IsPassageBusy(services_, door.id, 0.0)) belief_.passage_used_at[door.id] = belief_.now;
    }
  }
  // Whether any note so far carries `event`.
  bool Noted(DecisionEvent event) const {
    for (const auto& note : log_.pending())
      if (note.event == event) return true;
    return false;
  }

  // Whether any note so far contains `text`.
  bool NotedText(std::string_view text) const {
    for (const auto& note : log_.pending())
      if (note.text.find(text) != std::string::npos) return true;
    return false;
  }

  MissionMap map_ = LabDoor();
  RobotModel model_;
  MotionExecutor motion_;
  perception::Costmap2D costmap_;
  planning::BasePlanner planner_;
  Belief belief_;
  DecisionLog log_;
  TaskServices services_;
  bt::BehaviorTreeFactory factory_;
  int trees_made_{0};
};

}  // namespace egress::behavior::node_testing
