#pragma once
/// @file
/// Belief: what the robot believes at this control step — its localized pose, the world state
/// (doors, people, payloads, costmap), its latest sensor data and what the executive derives from
/// them over time (when each door's current opening began, when a person was last in each door
/// zone, the last pose outside every door zone). The executive refreshes it every control step;
/// task nodes only read it (they hold a const reference), so no node can leave state in it for
/// another: state nodes share travels on blackboard ports.

#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "egress/hsr_interface/geometry.h"
#include "egress/hsr_interface/sensor_types.h"
#include "egress/hsr_interface/time.h"
#include "egress/perception/world_state.h"

namespace egress::behavior {

/// [m] A laser return this far from every wall and door leaf of the costmap is off the map: three
/// cells, more than the localizer's error at a wall.
inline constexpr double kOffMapM = 0.15;
/// [m per m of range] How much farther from the map a return must lie, per metre of its range,
/// to be off it: the estimate's heading error (~0.5 degrees) moves a far return sideways (room A
/// seed 11: returns off the corridor's wall 10 m away, 0.1 m off it, read as someone on the
/// robot's spot beside door_e, which it then waited to be free of until the time limit).
inline constexpr double kOffMapPerRangeM = 0.01;
/// [s] How long Belief::swept_p_MB remembers where the base drove.
inline constexpr double kSweptMemorySec = 5.0;
/// [m] Belief::swept_p_MB's spacing.
inline constexpr double kSweptSampleM = 0.05;

struct Belief {
  Time now{};  ///< The robot clock at this step.
  Pose2 X_MB;  ///< The localized base pose.
  Twist2 V_B;  ///< The base's measured velocity (wheel odometry), in B.
  perception::WorldState world;
  bool holding_object{false};  ///< From the gripper's own measurement (GraspMonitor).
  /// The fingers moved after the last gripper command and have come to rest (GraspMonitor).
  bool gripper_at_rest{false};
  std::optional<LaserScan> scan;  ///< The latest laser scan.
  /// The latest scan's returns off the map (farther than kOffMapM, plus kOffMapPerRangeM per
  /// metre of range, from every wall and door leaf of the costmap) within the laser people
  /// detector's max_range of the laser: people, and
  /// whatever else is not on the map. In M.
  std::vector<Eigen::Vector2d> off_map_returns;
  /// How far from the laser people are known: its off-map returns and people detections reach
  /// this far (the detector's max_range) [m].
  double people_range{std::numeric_limits<double>::infinity()};
  /// Those of them that moved (perception::ScanMotion): people walking. In M.
  std::vector<Eigen::Vector2d> moving_returns;
  /// The latest head depth image, the camera in M when it was taken, and its intrinsics.
  std::optional<DepthImage> depth;
  Pose3 X_MC;
  CameraIntrinsics depth_intrinsics;
  Pose2 X_BL;  ///< The laser in the base frame.
  /// The last pose at which the robot stood outside every door zone (where a standby retreats).
  std::optional<Pose2> last_safe;
  /// Where the base has been over the last kSweptMemorySec while it drove the way its laser
  /// looked (its velocity inside the sweep), oldest first, every kSweptSampleM: nobody stood
  /// there as it passed, though the place may now be behind it, in the laser's blind sector.
  std::vector<std::pair<Time, Eigen::Vector2d>> swept_p_MB;
  /// Per door: since when it has been open enough to pass in its current opening (from the
  /// angle estimate: it starts when the leaf is first seen wide enough, ends when it is seen
  /// closed or closing).
  std::map<std::string, Time> door_open_since;
  /// Doors whose current opening's age door_open_since gives (from when the leaf was first
  /// seen wide enough; never a glass leaf's, which may stand open long before it is seen so).
  /// For any other opening the age is unknown — it may have begun a whole hold window ago.
  std::set<std::string> door_opening_witnessed;
  /// Per door: the last step at which a person (not one holding the door aside) was in, or
  /// forecast into, its zone. Absent: never seen occupied.
  std::map<std::string, Time> zone_occupied_at;
  /// Per door: the last step at which a person (not one holding the door aside) was within
  /// TaskConfig::passage_clearance of its opening's middle (IsPassageBusy now). Absent: never.
  std::map<std::string, Time> passage_used_at;

  double now_s() const { return ToSeconds(now); }
};

}  // namespace egress::behavior
