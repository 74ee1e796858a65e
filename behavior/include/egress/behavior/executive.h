#pragma once
/// @file
/// Executive: the robot brain's loop, the same against the twin and the real robot. Each
/// control step (100 Hz default): read the RobotPort → localize (particle filter on the
/// building map: odometry predicts, laser scans correct) → update perception (laser: costmap and
/// door angles; camera: detections placed with depth, people tracked with intent) → every tick
/// period (10 Hz default) tick the behavior tree → run the trajectory controller → send the
/// commands. The executive reads time only from the port's clock, so in the twin it runs in
/// lock-step with simulated time.

#include <deque>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "egress/behavior/belief.h"
#include "egress/behavior/grasp_monitor.h"
#include "egress/behavior/head_gaze.h"
#include "egress/behavior/mission_map.h"
#include "egress/behavior/motion_executor.h"
#include "egress/behavior/proxemics.h"
#include "egress/behavior/task_services.h"
#include "egress/bt/status.h"

namespace egress::bt {
class Tree;
class BehaviorTreeFactory;
}  // namespace egress::bt

#include "egress/hsr_interface/robot_port.h"
#include "egress/perception/costmap.h"
#include "egress/perception/detection.h"
#include "egress/perception/occupancy_map_3d.h"
#include "egress/perception/particle_filter_localizer.h"
#include "egress/perception/scan_motion.h"
#include "egress/perception/world_state.h"
#include "egress/planning/base_planner.h"

namespace egress::behavior {

/// The executive's parameters. The robot's own geometry is not among them: the footprint
/// radius (tasks, costmap, planner) and the robot's height come from the RobotModel the
/// executive is given (its URDF), whatever these fields hold.
struct ExecutiveConfig {
  double tick_rate_hz{10.0};      ///< Behavior-tree ticks (the paper's 10 Hz).
  double control_rate_hz{100.0};  ///< Controller steps; Step() is called at this rate.
  TaskConfig tasks;
  HeadGazeConfig head;        ///< Where the head camera looks (HeadGaze).
  ProxemicsConfig proxemics;  ///< Paths slow down towards people (ApproachSpeedScale).
  planning::TrajectoryConfig trajectory;
  planning::ControllerConfig controller;
  ArmMotionConfig arm;       ///< When an arm motion is done (measured joints) or failed.
  GraspMonitorConfig grasp;  ///< When the gripper holds something (its angle and effort).
  perception::PerceptionConfig perception;
  perception::CostmapConfig costmap;
  /// Paths keep this much more than the footprint's radius from obstacles: string-pulled paths
  /// hug corners, and tracking is good to a centimetre or two [m].
  double path_clearance{0.03};
  /// Laser localization on the building map (AMCL-style); false: odometry alone.
  bool localize{true};
  perception::LocalizerConfig localizer = [] {
    perception::LocalizerConfig c;
    c.max_beams = 180;   // a 270° scan at 1.5°: the room's corners and jambs pin the pose
    c.sigma_hit = 0.05;  // the twin's laser is good to a centimetre
    return c;
  }();
  double initial_pose_sigma{0.05};  ///< Spread of the initial pose estimate [m and rad].
  /// The head depth camera's 3D obstacle map (OctoMap): what the base laser misses (table
  /// tops, shelves, overhangs) is projected into the costmap and checked by the planner with
  /// FCL against the robot's 3D outline. False disconnects it: the laser alone.
  bool use_octomap{true};
  perception::OccupancyMap3DConfig octomap;
  /// Depth points this close to what the costmap already knows (the map's walls, laser
  /// returns, door leaves) are left to it: the 3D map adds only what the laser misses, and
  /// people and leaves seen by both leave no stale voxels behind [m].
  double octomap_known_radius{0.15};
  /// Depth points within this of a tracked person's centre are that person [m].
  double octomap_person_radius{0.5};
  /// Depth points within the robot's own outline grown by this are the robot (arm, payload) [m].
  double octomap_self_margin{0.06};
  /// The detector stage's boxes and the port's own are merged above this overlap (IoU).
  double detection_merge_iou{0.5};
  /// A door's leaf is in the costmap while its angle estimate is at most this old [s].
  double door_leaf_max_age{0.5};
  /// A glass leaf not seen lately is kept in the costmap at this angle [rad]: the laser sees
  /// glass only near normal incidence, and an open glass door sticking into a corridor was
  /// driven into (the ADA operators' open angle, 80 deg).
  double glass_leaf_assumed_angle{80.0 * M_PI / 180.0};
  /// A held payload's outline for collision checks: a vertical cylinder at the palm [m].
  double held_payload_radius{0.05};
  double held_payload_length{0.26};
  /// The base laser silent this long (no scan): the base is held still, whatever the tree
  /// commands, until scans come again (the costmap and the localizer would be going blind) [s].
  double scan_hold_after_s{0.5};
  /// ... and this long: the mission fails, naming it (a safe abort) [s].
  double scan_abort_after_s{10.0};
  planning::BasePlannerConfig planner = [] {
    planning::BasePlannerConfig c;
    c.deterministic = true;  // a twin run must be a pure function of its seed
    return c;
  }();
  void Validate() const;
};

/// The tree to run and the blackboard it starts with.
struct MissionTree {
  std::filesystem::path file;
  std::string tree_id;  ///< Empty: the file's main tree.
  std::map<std::string, std::string> blackboard;
};

/// One line of the run's decision log.
struct Decision {
  double time{0.0};  ///< [s] robot clock
  std::string text;
  DecisionEvent event{DecisionEvent::kNote};  ///< What it records; read this, not the text.
};

class Executive {
 public:
  /// Loads the tree (every node must be a registered task node or a built-in).
  /// @throws LogicError / InvalidArgument naming the file, line and node for a bad tree, an
  /// unknown node or a bad map.
  Executive(std::shared_ptr<const RobotModel> model, MissionMap map, MissionTree tree,
            const Pose2& X_MB_initial, ExecutiveConfig config = {});
  ~Executive();
  Executive(const Executive&) = delete;
  Executive& operator=(const Executive&) = delete;

  /// One control step. Returns false once the tree has finished (success or failure); the
  /// robot is then commanded to stand still.
  bool Step(RobotPort& port);

  /// Stops everything at once, for a reason from outside the tree (a stale sensor, an e-stop,
  /// SIGINT): the base is commanded to zero first, then the tree is halted and the reason
  /// logged. Step() then only keeps the base still. Returns at once if already finished.
  void Halt(RobotPort& port, const std::string& reason);
  /// Whether the mission ended (success, failure, or Halt).
  bool finished() const;
  bt::NodeStatus status() const { return status_; }
  const std::vector<Decision>& decisions() const { return decisions_; }
  /// Runs `detector` on every colour image the port gives (a robot that sends images, not
  /// detections); its boxes join the port's own detections. Without one, colour images are
  /// ignored. The executive owns it from here.
  void SetDetector(std::unique_ptr<perception::Detector> detector);
  /// The mission tree and the factory that built it (to attach observers: a .btlog writer,
  /// a Groot2 publisher). Observers must be removed before the executive is destroyed.
  bt::Tree& tree();
  const bt::BehaviorTreeFactory& tree_factory() const;
  /// The running action's name (instance name, else its type), or empty.
  std::string active_action() const;
  const Pose2& X_MB() const { return belief_.X_MB; }
  const perception::Costmap2D& costmap() const { return *costmap_; }
  /// The head camera's 3D obstacle map, or nullptr when config.use_octomap is false.
  const perception::OccupancyMap3D* octomap() const;
  /// The robot's 3D outline in B the planner checks (measured arm, held payload).
  const std::vector<PlacedShape>& body_shapes() const;
  /// What the task nodes believe at this step.
  const Belief& belief() const { return belief_; }
  /// What the task nodes act through (map, task config, motion executor, planner).
  const TaskServices& services() const { return services_; }
  /// How often a precise act re-localized first (TaskConfig::precise_pose_sigma).
  int relocalizations() const { return relocalizations_; }
  /// Time of the first tick at which an IsPathClear check failed after having passed, and of
  /// the first zero-velocity / retract command after it, per event [s] (preemption latency).
  const std::vector<std::pair<double, double>>& preemptions() const { return preemptions_; }

 private:
  // The robot's 3D outline from the measured joints (and a held payload), for the planner.
  void UpdateBody(const SensorSnapshot& snapshot);
  // One depth image into the 3D map (the floor, people, leaves and the robot itself left out)
  // and the map's projection into the costmap.
  void InsertDepth(const DepthImage& depth, const Pose3& X_MC);
  // The estimated door leaves into the costmap.
  void UpdateDoorLeaves();
  // The tracked people's personal space, now and predicted, into the costmap's proxemic layer.
  void UpdatePersonalSpaces();
  // The port's detections, plus the detector stage's on a colour image when there is one.
  std::vector<Detection2D> Detect(const SensorSnapshot& snapshot);
  // Belief::swept_p_MB: the base's position, when it drives the way its laser looks.
  void RememberSwept();

  struct Impl;
  std::unique_ptr<Impl> impl_;
  Belief belief_;  // refreshed every step; the nodes read it
  DecisionLog log_;
  TaskServices services_;
  int relocalizations_{0};
  std::unique_ptr<perception::Costmap2D> costmap_;
  bt::NodeStatus status_{bt::NodeStatus::kIdle};
  std::vector<Decision> decisions_;
  std::vector<std::pair<double, double>> preemptions_;
  static constexpr double kPoseHistorySec = 1.0;  ///< Longer than the detector's latency.
  /// Depth images kept to place late detections with [s]: the detector's latency and a depth
  /// image's period (0.2 s each in the HSR's twin), and some.
  static constexpr double kDepthHistorySec = 0.6;
  /// [m/s] Slower, the base is turning or standing: RememberSwept keeps nothing.
  static constexpr double kSweptMinMps = 0.05;
  /// [rad] The head turned more than this between an image and the depth image that places its
  /// boxes: the boxes are dropped.
  static constexpr double kHeadMovedRad = 0.02;
  /// Per control step: the localized X_MB and the measured head pan and tilt (if the joints
  /// gave them),
  /// for where the base and the head were when a late image was taken.
  struct PoseAt {
    Time t;
    Pose2 X_MB;
    std::optional<double> pan;
    std::optional<double> tilt;
  };
  std::deque<PoseAt> pose_history_;
  /// The latest entry at or before `stamp` (nullptr if the history starts after it).
  const PoseAt* PoseHistoryAt(Time stamp) const;
  perception::ScanMotion
      scan_motion_;  ///< Which returns off the map moved (belief_.moving_returns).
};

}  // namespace egress::behavior
