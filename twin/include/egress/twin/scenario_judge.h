#pragma once
/// @file
/// The scenario judge: the only consumer of ground truth besides the sensors. It watches a twin
/// run step by step and, at the end, evaluates the scenario's success predicates and the
/// metrics of social_sim_notes §2.2–2.3.
///
/// Conventions: person distances are surface to surface (centre distance minus both radii);
/// "personal space" is a surface gap below 1.2 m; a door is crossed when the robot's centre
/// passes the doorway plane between its jambs; "open when crossed" means the leaf was open at
/// least TwinConfig::door_crossed_open_angle_deg at that instant; reach_goal holds if the robot
/// came within the goal tolerance at any time.

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "egress/twin/twin_world.h"

namespace egress::twin {

struct DoorCrossing {
  std::string door;
  double t{0.0};
  double angle{0.0};  ///< Leaf opening angle at the crossing [rad]
  int direction{0};   ///< +1 along the doorway normal, −1 against
};

/// A doorway's frame in the plane: centre, unit normal and unit along-axis (hinge -> latch) of
/// the closed leaf's line, and half its width [m] (the judge's crossings, the evac study's flows).
struct DoorwayFrame {
  Eigen::Vector2d centre{Eigen::Vector2d::Zero()};
  Eigen::Vector2d normal{Eigen::Vector2d::UnitY()};
  Eigen::Vector2d along{Eigen::Vector2d::UnitX()};
  double half_width{0.0};
};
DoorwayFrame CalcDoorwayFrame(const DoorDescription& door);

struct RunMetrics {
  double end_time{0.0};                                                 ///< [s]
  std::optional<double> time_to_goal;                                   ///< [s]
  double path_length{0.0};                                              ///< [m]
  double min_person_distance{std::numeric_limits<double>::infinity()};  ///< Surface gap [m]
  /// The robot's speed at the moment of min_person_distance [m/s]: below kWaitSpeed the
  /// person came to a standing robot, above it the robot came to the person.
  double closest_robot_speed{0.0};
  double closest_time{0.0};  ///< When it was [s].
  /// The least surface gap to a person in sight of the robot: nothing of the building (a wall,
  /// furniture, a door leaf, glass or not) on the straight line between them at
  /// ScenarioJudge::kSightHeight [m]. A person behind a wall is not in the robot's personal
  /// space, however near: min_person_distance counts them too (issue 21: H12's person waits
  /// behind the wall beside the button the robot presses).
  double min_person_distance_in_sight{std::numeric_limits<double>::infinity()};
  double closest_in_sight_robot_speed{0.0};  ///< The robot's speed then [m/s].
  double time_in_personal_space{0.0};        ///< [s] with a surface gap < 1.2 m
  std::map<std::string, int> contacts;       ///< By kind: person, static, door, payload, carried
  /// By the model touched (the robot's body or arm, or the payload it holds).
  std::map<std::string, int> contacts_with;
  std::map<std::string, double> door_wait_time;  ///< Per door [s]
  std::map<std::string, int> button_presses;     ///< Per door
  std::vector<DoorCrossing> crossings;
  /// Button presses per crossing, over all doors (presses when nothing was crossed).
  double presses_per_traversal{0.0};

  /// The robot's bumps into the building: walls and furniture ("static") and doors' leaves. Not
  /// people, a payload it handles, or one it carries set down on furniture ("carried").
  int ObstacleContacts() const;
};

struct PredicateResult {
  std::string name;
  bool passed{false};
  std::string detail;
};

struct Verdict {
  bool success{false};
  std::vector<PredicateResult> predicates;
  RunMetrics metrics;
};

class ScenarioJudge {
 public:
  static constexpr double kPersonalSpace = 1.2;  ///< [m]
  static constexpr double kWaitSpeed = 0.05;     ///< Below this the robot is waiting [m/s]
  static constexpr double kDoorZone = 2.0;       ///< Waiting counts within this of a door [m]
  /// Whether a person is in sight is judged along a line at this height (a standing person's
  /// chest; over tables and counters) [m].
  static constexpr double kSightHeight = 1.2;

  /// Call after every world step.
  void Observe(const TwinWorld& world);
  /// Evaluates the predicates on the world's final state.
  Verdict Finish(const TwinWorld& world) const;

 private:
  bool initialized_{false};
  Pose2 last_pose_;
  double last_time_{0.0};
  RunMetrics metrics_;
  std::vector<double> last_side_;  ///< Per door: signed distance to the doorway plane
};

/// A table people read at a glance: predicates with PASS/FAIL, then the metrics.
std::string FormatVerdict(const Verdict& verdict);
/// The verdict as one JSON object.
std::string VerdictToJson(const Verdict& verdict);

}  // namespace egress::twin
