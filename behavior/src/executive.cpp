#include "egress/behavior/executive.h"

#include <algorithm>
#include <cmath>

#include "egress/behavior/door_rules.h"
#include "egress/behavior/grasp_monitor.h"
#include "egress/behavior/task_nodes.h"
#include "egress/bt/clock.h"
#include "egress/bt/factory.h"
#include "egress/bt/loggers.h"
#include "egress/bt/tree.h"
#include "egress/hsr_interface/error.h"
#include "egress/perception/door_estimation.h"
#include "localization_scan.h"
#include "task_node_support.h"

namespace egress::behavior {

void ExecutiveConfig::Validate() const {
  ThrowUnless(
      tick_rate_hz > 0 && control_rate_hz >= tick_rate_hz,
      "ExecutiveConfig: rates must be positive and the control rate at least the tick rate");
  ThrowUnless(scan_hold_after_s > 0 && scan_abort_after_s >= scan_hold_after_s,
              "ExecutiveConfig: need 0 < scan_hold_after_s <= scan_abort_after_s");
  tasks.Validate();
  head.Validate();
  proxemics.Validate();
  arm.Validate();
  grasp.Validate();
  octomap.Validate();
  ThrowUnless(octomap_known_radius >= 0 && octomap_person_radius >= 0 && octomap_self_margin >= 0,
              "ExecutiveConfig: octomap_known_radius, octomap_person_radius and "
              "octomap_self_margin must be >= 0");
  ThrowUnless(detection_merge_iou > 0 && detection_merge_iou <= 1,
              "ExecutiveConfig: detection_merge_iou must be in (0, 1]");
  ThrowUnless(door_leaf_max_age >= 0, "ExecutiveConfig: door_leaf_max_age must be >= 0");
  ThrowUnless(held_payload_radius > 0 && held_payload_length > 0,
              "ExecutiveConfig: held_payload_radius and held_payload_length must be > 0");
  trajectory.Validate();
  controller.Validate();
  planner.Validate();
}

namespace {

std::string_view StatusWord(bt::NodeStatus s) {
  switch (s) {
    case bt::NodeStatus::kRunning:
      return "started";
    case bt::NodeStatus::kSuccess:
      return "succeeded";
    case bt::NodeStatus::kFailure:
      return "failed";
    default:
      return "halted";
  }
}

// Logs the actions' transitions (started / succeeded / failed / halted) as decisions.
class ActionLog final : public bt::StatusObserver {
 public:
  ActionLog(bt::Tree& tree, std::vector<Decision>* out) : StatusObserver(tree), out_(out) {}
  const bt::TreeNode* running() const { return running_; }

 private:
  void OnStatusChange(Duration time, const bt::TreeNode& node, bt::NodeStatus previous,
                      bt::NodeStatus status) override {
    if (node.kind() != bt::NodeKind::kAction) return;
    if (status == bt::NodeStatus::kRunning) running_ = &node;
    if (status != bt::NodeStatus::kRunning && running_ == &node) running_ = nullptr;
    if (status == bt::NodeStatus::kIdle && previous != bt::NodeStatus::kRunning) return;
    const std::string& name = node.name().empty() ? node.registration_id() : node.name();
    out_->push_back({ToSeconds(time), StrCat(name, " ", StatusWord(status))});
  }
  std::vector<Decision>* out_;
  const bt::TreeNode* running_{nullptr};
};

}  // namespace

struct Executive::Impl {
  std::optional<Time> last_scan_at;  // the last step with a scan
  bool holding_for_laser{false};     // the base is held still for a silent laser
  std::shared_ptr<const RobotModel> model;
  MissionMap map;
  ExecutiveConfig config;
  perception::PerceptionPipeline perception;
  std::unique_ptr<planning::BasePlanner> planner;
  MotionExecutor motion;
  std::shared_ptr<bt::ManualClock> clock = std::make_shared<bt::ManualClock>();
  bt::BehaviorTreeFactory factory;
  std::optional<bt::Tree> tree;
  std::unique_ptr<ActionLog> log;
  std::optional<Pose2> X_MO;  // odometry frame in the map, fixed at the first step
  std::optional<perception::ParticleFilterLocalizer> localizer;
  std::optional<Pose2> last_odometry;  // X_OB at the last scan the localizer used
  Pose2 X_MB_at_scan;                  // the localizer's estimate then
  Pose2 X_MB_initial;
  std::optional<Time> next_tick;
  // The latest depth images (oldest first) with the head camera in the base when each was taken:
  // detections are placed with the one taken nearest their image (the detector runs behind).
  std::deque<std::pair<DepthImage, Pose3>> depths;
  std::optional<Pose3> X_BC;  // the latest depth image's
  CameraIntrinsics intrinsics;
  bool finished{false};
  GraspMonitor grasp;
  std::unique_ptr<perception::Detector> detector;  // on colour images, when set
  std::optional<perception::OccupancyMap3D> octomap;
  std::vector<PlacedShape> body;  // the robot's outline in B
  std::optional<std::vector<std::pair<std::string, double>>> body_joints;  // `body` is for these
  bool body_holding{false};
  std::map<std::string, double> leaf_angles;  // per door: the leaf as the costmap has it
  std::vector<Eigen::Vector2d> projected;     // the 3D map's projection the costmap has
  std::map<std::string, bool> zone_occupied;  // per door, at the last control step
  std::optional<double> occupied_known_at;    // when perception first showed a person there
  HeadGaze gaze;
  ApproachPace pace;  // the paths' pace near people, with patience

  Impl(std::shared_ptr<const RobotModel> m, MissionMap mp, ExecutiveConfig c)
      : model(std::move(m)),
        map(std::move(mp)),
        config(std::move(c)),
        perception(map.doors, config.perception),
        motion(*model, config.trajectory, config.controller, config.arm),
        grasp(config.grasp),
        gaze(config.head),
        pace(config.proxemics) {}
};

Executive::Executive(std::shared_ptr<const RobotModel> model, MissionMap map, MissionTree tree,
                     const Pose2& X_MB_initial, ExecutiveConfig config) {
  ThrowUnless(model != nullptr, "Executive: no robot model");
  ThrowUnless(X_MB_initial.IsFinite(), "Executive: the initial pose must be finite");
  // The robot's geometry comes from its description (the URDF), not from the configs' defaults:
  // the footprint every module plans and checks with, and the robot's height.
  const double footprint = model->footprint_radius();
  config.tasks.footprint_radius = footprint;
  config.costmap.robot_radius = footprint;
  double top = 0.0;
  for (const PlacedShape& s : model->CalcCollisionShapesInBase({}))
    top = std::max(top, s.X_BS.translation().z() + s.shape.BoundingRadius());
  if (top > 0.0) config.planner.robot_height = top;
  config.Validate();
  config.localizer.Validate();
  map.Validate();
  impl_ = std::make_unique<Impl>(std::move(model), std::move(map), std::move(config));
  Impl& m = *impl_;
  m.X_MB_initial = X_MB_initial;
  costmap_ = std::make_unique<perception::Costmap2D>(m.map.grid, m.config.costmap);
  planning::BasePlannerConfig planner_config = m.config.planner;
  planner_config.footprint_radius = m.config.costmap.robot_radius + m.config.path_clearance;
  if (m.config.use_octomap) m.octomap.emplace(m.config.octomap);
  m.planner = std::make_unique<planning::BasePlanner>(
      *costmap_, m.octomap ? m.octomap->tree() : nullptr, planner_config);
  for (const auto& doorway : m.map.doorways) {
    costmap_->AddDoorway(doorway);
    m.planner->AddDoor({doorway.id, doorway.p_MHinge, doorway.p_MLatch});
  }
  if (m.config.localize) {
    const Pose2 X_BL = m.model->laser_pose().ToPose2();
    m.localizer.emplace(m.map.grid, X_BL, m.config.localizer);
    const double sigma = m.config.initial_pose_sigma;
    m.localizer->Initialize(X_MB_initial, Eigen::Vector3d::Constant(sigma * sigma).asDiagonal());
  }
  services_.model = m.model.get();
  services_.map = &m.map;
  services_.config = m.config.tasks;
  services_.motion = &m.motion;
  services_.planner = m.planner.get();
  services_.log = &log_;
  services_.gaze = &m.gaze;
  services_.belief = &belief_;
  services_.proxemics = &m.config.proxemics;
  belief_.X_BL = m.model->laser_pose().ToPose2();
  belief_.X_MB = X_MB_initial;
  belief_.last_safe = X_MB_initial;
  RegisterTaskNodes(m.factory, &services_);
  auto blackboard = bt::Blackboard::Create();
  for (const auto& [key, value] : tree.blackboard)
    blackboard->Set(key, bt::Any(value));
  m.factory.RegisterTreesFromFile(tree.file);
  m.tree.emplace(m.factory.CreateTree(tree.tree_id, blackboard));
  m.tree->SetClock(m.clock);
  m.log = std::make_unique<ActionLog>(*m.tree, &decisions_);
}

Executive::~Executive() = default;

void Executive::SetDetector(std::unique_ptr<perception::Detector> detector) {
  impl_->detector = std::move(detector);
}

std::vector<Detection2D> Executive::Detect(const SensorSnapshot& snapshot) {
  Impl& m = *impl_;
  if (!m.detector || !snapshot.color) return snapshot.detections;
  const ColorImage& image = *snapshot.color;
  perception::CameraFrame frame;
  frame.stamp = image.stamp;
  frame.frame_id = image.frame_id;
  // A view of the port's buffer, not a copy: the detector only reads it.
  frame.image =
      cv::Mat(image.height, image.width, CV_8UC3, const_cast<std::uint8_t*>(image.bgr.data()));
  frame.upstream = snapshot.detections;
  std::vector<Detection2D> found = m.detector->Detect(frame);
  for (Detection2D& d : found)
    d.stamp = image.stamp;
  if (snapshot.detections.empty()) return found;
  return perception::MergeDetections({snapshot.detections, found}, m.config.detection_merge_iou);
}

const perception::OccupancyMap3D* Executive::octomap() const {
  return impl_->octomap ? &*impl_->octomap : nullptr;
}

const std::vector<PlacedShape>& Executive::body_shapes() const {
  return impl_->body;
}

void Executive::UpdateBody(const SensorSnapshot& snapshot) {
  Impl& m = *impl_;
  std::vector<std::pair<std::string, double>> q;
  for (std::string_view joint : WholeBodyJointNames()) {
    if (auto value = snapshot.joints.Position(joint)) q.emplace_back(joint, *value);
  }
  for (std::string_view joint : {"head_pan_joint", "head_tilt_joint"}) {
    if (auto value = snapshot.joints.Position(joint)) q.emplace_back(joint, *value);
  }
  // Each control step, but the outline changes only when a joint or the grip does.
  if (m.body_joints && *m.body_joints == q && m.body_holding == belief_.holding_object) return;
  m.body_joints = q;
  m.body_holding = belief_.holding_object;
  m.body = m.model->CalcCollisionShapesInBase(q);
  if (belief_.holding_object) {
    // The payload hangs between the fingers, ahead of the palm along its approach axis.
    const Pose3 X_BG = m.model->CalcLinkPoseInBase("hand_palm_link", q);
    CollisionShape payload;
    payload.link = "hand_palm_link";
    payload.name = "held_payload";
    payload.kind = CollisionShape::Kind::kCylinder;
    payload.size = {m.config.held_payload_radius, m.config.held_payload_radius,
                    m.config.held_payload_length};
    payload.X_LS = Pose3(Eigen::Vector3d(0, 0, 0.06));
    m.body.push_back({payload, Pose3((X_BG * payload.X_LS).translation())});
  }
  m.planner->SetBodyShapes(m.body);
}

void Executive::InsertDepth(const DepthImage& depth, const Pose3& X_MC) {
  Impl& m = *impl_;
  const Pose3 X_BM = Pose3::FromPose2(belief_.X_MB).Inverse();
  const auto& cfg = m.config;
  std::vector<Eigen::Vector2d> people;
  for (const auto& p : belief_.world.people)
    people.push_back(p.person.p_MP);
  // The robot's shapes as seen from each (S from B), and a radius round the base beyond which
  // no point can be the robot.
  std::vector<std::pair<const CollisionShape*, Pose3>> self;
  double self_reach = 0.0;
  for (const PlacedShape& s : m.body) {
    self.emplace_back(&s.shape, s.X_BS.Inverse());
    self_reach = std::max(self_reach, s.X_BS.translation().head<2>().norm() +
                                          s.shape.BoundingRadius() + cfg.octomap_self_margin);
  }
  const auto keep = [&](const Eigen::Vector3d& p_MQ) {
    if (p_MQ.z() < cfg.octomap.min_obstacle_height || p_MQ.z() > cfg.octomap.max_obstacle_height)
      return false;  // the floor, or above the robot
    const Eigen::Vector2d p = p_MQ.head<2>();
    for (const auto& p_MP : people) {
      if ((p - p_MP).norm() < cfg.octomap_person_radius) return false;
    }
    // A leaf is the door layer's: anywhere it can swing, at any angle the estimate lags behind.
    for (const auto& door : m.map.doorways) {
      if ((p - door.p_MHinge).norm() < door.width() + 0.1) return false;
    }
    const Eigen::Vector3d p_BQ = X_BM * p_MQ;
    if (p_BQ.head<2>().norm() < self_reach) {
      for (const auto& [shape, X_SB] : self) {
        if (shape->Contains(X_SB * p_BQ, cfg.octomap_self_margin)) return false;
      }
    }
    return !costmap_->IsNearSensedObstacle(p, cfg.octomap_known_radius);
  };
  m.octomap->InsertDepthImage(depth, m.intrinsics, X_MC, keep);
  // The costmap recomputes its inflation round whatever changed: only when something did.
  std::vector<Eigen::Vector2d> projected = m.octomap->ProjectObstacles();
  if (projected != m.projected) {
    costmap_->SetProjectedObstacles(projected);
    m.projected = std::move(projected);
  }
}

void Executive::UpdateDoorLeaves() {
  Impl& m = *impl_;
  // The leaf at its estimated angle, so paths keep out of it; re-marked when it moved by more
  // than a degree (each change recomputes the inflation round the door).
  constexpr double kLeafUpdateRad = 0.0175;
  for (const auto& d : belief_.world.doors) {
    auto it = m.leaf_angles.find(d.model.id);
    // Only a leaf seen lately: an old estimate (the leaf out of the laser's view, e.g. from a
    // button's standoff beside the door) may have the leaf where it no longer is, across the
    // very pose the robot lines up at.
    const bool fresh =
        d.state.observed && ToSeconds(belief_.now - d.state.stamp) <= m.config.door_leaf_max_age;
    std::optional<double> angle;
    if (fresh) {
      angle = d.state.angle;
    } else if (m.map.glass_doors.count(d.model.id) > 0) {
      angle = std::min(m.config.glass_leaf_assumed_angle, d.model.max_open_angle);
    }
    if (!angle) {
      if (it != m.leaf_angles.end()) {
        costmap_->SetDoorLeafAngle(d.model.id, std::nullopt);
        m.leaf_angles.erase(it);
      }
      continue;
    }
    if (it != m.leaf_angles.end() && std::abs(it->second - *angle) < kLeafUpdateRad) continue;
    costmap_->SetDoorLeafAngle(d.model.id, *angle);
    m.leaf_angles[d.model.id] = *angle;
  }
}

void Executive::UpdatePersonalSpaces() {
  const ProxemicsConfig& proxemics = impl_->config.proxemics;
  const TaskConfig& tasks = services_.config;
  std::vector<perception::PersonalSpace> spaces;
  if (proxemics.personal_space_layer) {
    const double bodies = tasks.footprint_radius + tasks.person_radius;
    // Every tracked person, however far: a path may be planned a long way.
    for (const detail::Occupant& o : detail::PeopleAround(
             services_, belief_.X_MB.translation(), std::numeric_limits<double>::infinity(),
             proxemics.space_horizon, proxemics.space_step)) {
      if (o.radius <= 0.0) continue;  // a scan return off the map: the laser marks it already
      spaces.push_back({o.p_M, bodies + proxemics.stop_gap, bodies + proxemics.slow_gap,
                        1.0 - o.t / (proxemics.space_horizon + proxemics.space_step)});
    }
  }
  costmap_->SetPersonalSpaces(spaces);
}

void Executive::RememberSwept() {
  auto& swept = belief_.swept_p_MB;
  const auto old = std::find_if(swept.begin(), swept.end(), [&](const auto& s) {
    return ToSeconds(belief_.now - s.first) <= kSweptMemorySec;
  });
  swept.erase(swept.begin(), old);
  if (!belief_.scan) return;
  const double speed = std::hypot(belief_.V_B.vx, belief_.V_B.vy);
  if (speed < kSweptMinMps) return;
  // The heading of the base's velocity in the laser's frame.
  const double bearing =
      std::remainder(std::atan2(belief_.V_B.vy, belief_.V_B.vx) - belief_.X_BL.yaw, 2 * M_PI);
  if (bearing < belief_.scan->angle_min + detail::PeopleRoom::kSweepMarginRad ||
      bearing > belief_.scan->angle_max() - detail::PeopleRoom::kSweepMarginRad)
    return;
  const Eigen::Vector2d p = belief_.X_MB.translation();
  if (swept.empty() || (p - swept.back().second).norm() >= kSweptSampleM)
    swept.emplace_back(belief_.now, p);
}

bt::Tree& Executive::tree() {
  return *impl_->tree;
}

const bt::BehaviorTreeFactory& Executive::tree_factory() const {
  return impl_->factory;
}

std::string Executive::active_action() const {
  const bt::TreeNode* node = impl_->log->running();
  if (node == nullptr) return {};
  return node->name().empty() ? node->registration_id() : node->name();
}

bool Executive::Step(RobotPort& port) {
  Impl& m = *impl_;
  const SensorSnapshot snapshot = port.Sense();
  const Time now = port.clock().Now();
  belief_.now = now;
  m.clock->Set(now);
  // How long the base laser has been silent (from the first step if it never spoke).
  if (snapshot.scan || !m.last_scan_at) m.last_scan_at = now;
  const double scan_silence = ToSeconds(now) - ToSeconds(*m.last_scan_at);

  // Localize: odometry predicts, laser scans correct on the building map (or odometry alone
  // from the initial pose).
  if (m.localizer) {
    // The filter moves its particles once per scan, by the odometry since the last scan (as
    // AMCL does): per-step increments would hardly spread the particles, and the cloud could
    // not catch up with odometry drift. Between scans, odometry carries the estimate.
    if (!m.last_odometry) {
      m.last_odometry = snapshot.odometry.X_OB;
      m.X_MB_at_scan = m.localizer->Estimate();
    }
    if (snapshot.scan) {
      m.localizer->Predict(*m.last_odometry, snapshot.odometry.X_OB);
      const int recoveries = m.localizer->recover_count();
      m.localizer->Correct(
          detail::WithoutDoorLeaves(*snapshot.scan, m.map, m.localizer->Estimate() * belief_.X_BL));
      if (m.localizer->recover_count() != recoveries) {
        const Pose2& jump = m.localizer->last_recovery();
        decisions_.push_back(
            {ToSeconds(now),
             StrCat("localization: the scan fits a pose ",
                    std::round(std::hypot(jump.x, jump.y) * 100), " cm and ",
                    std::round(jump.yaw * 180.0 / M_PI), " deg away: relocalized there"),
             DecisionEvent::kNote});
      }
      m.last_odometry = snapshot.odometry.X_OB;
      m.X_MB_at_scan = m.localizer->Estimate();
    }
    belief_.X_MB = m.X_MB_at_scan * (m.last_odometry->Inverse() * snapshot.odometry.X_OB);
  } else {
    if (!m.X_MO) m.X_MO = m.X_MB_initial * snapshot.odometry.X_OB.Inverse();
    belief_.X_MB = *m.X_MO * snapshot.odometry.X_OB;
  }
  belief_.V_B = snapshot.odometry.V_B;
  const Pose3 X_MB3 = Pose3::FromPose2(belief_.X_MB);

  // Proprioception: the arm's joints (arm motions end when they arrive) and the gripper's
  // angle and effort (whether it holds something).
  ArmPose arm;
  bool arm_measured = true;
  for (std::size_t j = 0; j < arm.size(); ++j) {
    const auto q = snapshot.joints.Position(kArmJointNames[j]);
    arm_measured = arm_measured && q.has_value();
    if (q) arm[j] = *q;
  }
  if (arm_measured) m.motion.SetMeasuredArm(arm);
  m.grasp.Update(snapshot.gripper);
  belief_.holding_object = m.grasp.holding();
  belief_.gripper_at_rest = m.grasp.at_rest();
  // Perceive.
  UpdateBody(snapshot);
  // Where the base and head are now: late images and depth images are placed from here.
  const std::optional<double> pan_now = snapshot.joints.Position("head_pan_joint");
  pose_history_.push_back(
      {now, belief_.X_MB, pan_now, snapshot.joints.Position("head_tilt_joint")});
  while (!pose_history_.empty() && ToSeconds(now - pose_history_.front().t) > kPoseHistorySec)
    pose_history_.pop_front();
  if (snapshot.depth) {
    m.X_BC = snapshot.X_BC;
    m.intrinsics = snapshot.depth_intrinsics;
    if (m.X_BC) {
      m.depths.emplace_back(*snapshot.depth, *m.X_BC);
      while (m.depths.size() > 1 &&
             ToSeconds(now - m.depths.front().first.stamp) > kDepthHistorySec)
        m.depths.pop_front();
      belief_.depth = snapshot.depth;
      belief_.X_MC = X_MB3 * *m.X_BC;
      belief_.depth_intrinsics = snapshot.depth_intrinsics;
      if (m.octomap) InsertDepth(*snapshot.depth, belief_.X_MC);
    }
  }
  const Pose3& X_BL = m.model->laser_pose();
  if (snapshot.scan) {
    const Pose3 X_ML3 = X_MB3 * X_BL;
    const Pose2 X_ML = X_ML3.ToPose2();
    costmap_->UpdateWithScan(*snapshot.scan, X_ML);
    if (m.X_BC)
      m.perception.ProcessScan(
          *snapshot.scan, X_ML, m.intrinsics, X_BL.Inverse() * *m.X_BC,
          [this](const Eigen::Vector2d& p) { return costmap_->IsNearMappedObstacle(p, kOffMapM); });
  }
  const std::vector<Detection2D> detections = Detect(snapshot);
  if (!detections.empty() && !m.depths.empty()) {
    // The depth image taken nearest the detections' image, placed from where the base was when
    // it was taken: boxes laid on a later depth image, from a base that has driven on, cover
    // what has since come into them (P1 seed 2097: the near edge of an open leaf, under the
    // box of someone seen past it 0.2 s before, placed them 0.13 m past the leaf's tip, in the
    // doorway, at 0.7 m/s).
    const Time capture_stamp = detections.front().stamp;
    const auto& [depth, X_BC] =
        *std::min_element(m.depths.begin(), m.depths.end(), [&](const auto& a, const auto& b) {
          return std::abs(ToSeconds(a.first.stamp - capture_stamp)) <
                 std::abs(ToSeconds(b.first.stamp - capture_stamp));
        });
    // An image taken while the head turned away from where it was for that depth image would
    // put its boxes in the wrong place: they are dropped.
    const PoseAt* capture = PoseHistoryAt(capture_stamp);
    const PoseAt* taken = PoseHistoryAt(depth.stamp);
    const auto same = [](const std::optional<double>& x, const std::optional<double>& y) {
      return !x || !y || std::abs(*x - *y) <= kHeadMovedRad;
    };
    const bool head_still =
        !capture || !taken || (same(capture->pan, taken->pan) && same(capture->tilt, taken->tilt));
    if (head_still) {
      const Pose2 X_MB_capture = capture ? capture->X_MB : belief_.X_MB;
      const Pose2 X_MB_taken = taken ? taken->X_MB : belief_.X_MB;
      m.perception.ProcessCameraFrame(detections, cv::Size(m.intrinsics.width, m.intrinsics.height),
                                      depth, m.intrinsics, Pose3::FromPose2(X_MB_taken) * X_BC,
                                      Pose3::FromPose2(X_MB_capture) * X_BC);
    }
  }
  belief_.world = m.perception.Snapshot(
      now, belief_.X_MB, m.localizer ? m.localizer->Covariance() : Eigen::Matrix3d::Zero().eval(),
      costmap_.get(), m.octomap ? m.octomap->tree() : nullptr);
  UpdateDoorLeaves();
  // Each door's current opening starts when it is first seen wide enough to pass, and ends
  // when it is seen closed or closing (a dip in the estimate, e.g. a person in front of the
  // leaf, does not end it).
  for (const auto& d : belief_.world.doors) {
    if (!d.state.observed) continue;
    const std::string& id = d.model.id;
    if (d.state.motion == perception::DoorMotion::kClosed ||
        d.state.motion == perception::DoorMotion::kClosing) {
      belief_.door_open_since.erase(id);
    } else if (d.state.clearance_width >= 2 * services_.config.footprint_radius &&
               belief_.door_open_since.try_emplace(id, now).second) {
      // A new opening. Its age is taken as known from when the laser first sees the leaf wide
      // enough — except a glass leaf's: the laser sees it only near normal incidence and the
      // estimate may read it shut while it stands open edge-on, so it may have opened a whole
      // window before it was first seen open.
      if (m.map.glass_doors.count(id) == 0) {
        belief_.door_opening_witnessed.insert(id);
      } else {
        belief_.door_opening_witnessed.erase(id);
      }
    }
  }
  if (snapshot.scan) {
    belief_.scan = snapshot.scan;
    belief_.off_map_returns.clear();
    const Pose2 X_ML = (X_MB3 * X_BL).ToPose2();
    // Only as far as the laser's people are detected: farther out a return off the map is as
    // likely a wall seen a few centimetres off (range noise, the pose's yaw error times the
    // range) as a body (clinic room A seed 22: one return by a wall 17 m away took the robot's
    // spot beside door_e, and kept someone "near" it, until the time limit).
    belief_.people_range = m.config.perception.laser_detector.max_range;
    // Nor on a leaf where it was last seen: the costmap holds a leaf only door_leaf_max_age after
    // its last measurement (UpdateDoorLeaves), and from beside the hinge the laser sees a leaf
    // edge-on, too little of it to measure (random building seed 12: from the plate's standoff,
    // the held-open leaf was unmeasured 0.6-1 s at a time and read as someone near the door;
    // the hold's clear time restarted, and it waved for nobody every 24 s to the time limit).
    const auto on_last_seen_leaf = [&](const Eigen::Vector2d& p) {
      return std::any_of(belief_.world.doors.begin(), belief_.world.doors.end(),
                         [&](const auto& d) { return detail::NearEstimatedLeaf(d, p, kOffMapM); });
    };
    for (const Eigen::Vector2d& p : perception::ScanPoints(*snapshot.scan, X_ML)) {
      const double range = (p - X_ML.translation()).norm();
      if (range <= belief_.people_range &&
          !costmap_->IsNearMappedObstacle(p, kOffMapM + kOffMapPerRangeM * range) &&
          !on_last_seen_leaf(p))
        belief_.off_map_returns.push_back(p);
    }
    belief_.moving_returns = scan_motion_.Update(now, X_ML, belief_.off_map_returns);
  }
  bool newly_occupied = false;
  const bool in_any_zone = IsInAnyDoorZone(services_, belief_.X_MB.translation());
  for (const auto& door : m.map.doors) {
    const bool occupied = IsDoorZoneOccupied(services_, door.id);
    if (occupied) belief_.zone_occupied_at[door.id] = now;
    if (services_.config.passage_clearance > 0.0 && IsPassageBusy(services_, door.id, 0.0))
      belief_.passage_used_at[door.id] = now;
    if (occupied && !m.zone_occupied[door.id]) newly_occupied = true;
    m.zone_occupied[door.id] = occupied;
  }
  if (!in_any_zone && !m.motion.base_failed()) belief_.last_safe = belief_.X_MB;
  RememberSwept();
  if (newly_occupied && !m.occupied_known_at) m.occupied_known_at = ToSeconds(now);
  bool any_occupied = false;
  for (const auto& entry : m.zone_occupied)
    any_occupied = any_occupied || entry.second;
  if (!any_occupied) m.occupied_known_at.reset();

  // Decide.
  if (!m.finished && (!m.next_tick || now >= *m.next_tick)) {
    m.next_tick = now + SecondsToDuration(1.0 / m.config.tick_rate_hz);
    UpdatePersonalSpaces();  // at the tree's rate: only its nodes plan paths
    status_ = m.tree->TickOnce();
    bool preempted = false;
    for (NodeNote& note : log_.Take()) {
      preempted = preempted || note.event == DecisionEvent::kPersonInDoorZone;
      if (note.event == DecisionEvent::kRelocalizing) ++relocalizations_;
      decisions_.push_back({ToSeconds(now), std::move(note.text), note.event});
    }
    if (preempted && m.occupied_known_at) {
      // The halt (zero velocity) and the standby's first command go out in this same step.
      preemptions_.push_back({*m.occupied_known_at, ToSeconds(now)});
      m.occupied_known_at.reset();
    }
    if (status_ == bt::NodeStatus::kSuccess || status_ == bt::NodeStatus::kFailure) {
      m.finished = true;
      m.motion.StopBase();
      decisions_.push_back(
          {ToSeconds(now),
           status_ == bt::NodeStatus::kSuccess ? "mission succeeded" : "mission failed",
           DecisionEvent::kNote});
    }
  }

  // Act. A Bug2 detour steers by the latest scan and the tracked people.
  if (m.motion.bug_active() && snapshot.scan) {
    std::vector<Eigen::Vector2d> people;
    for (const auto& p : belief_.world.people)
      people.push_back(p.person.p_MP);
    m.motion.SetSurroundings(
        perception::ScanPoints(*snapshot.scan, (Pose3::FromPose2(belief_.X_MB) * X_BL).ToPose2()),
        std::move(people));
  }
  std::optional<Eigen::Vector2d> p_MGoal;
  if (!m.motion.path().empty()) p_MGoal = m.motion.path().back().translation();
  const bool was_squeezing = m.pace.squeezing();
  const Eigen::Vector2d v_M = m.motion.planned_velocity();
  m.motion.SetSpeedScale(m.pace.Update(
      ToSeconds(now), belief_.X_MB, v_M, p_MGoal, belief_.world.people,
      m.config.tasks.footprint_radius, m.config.tasks.person_radius,
      IsLeavingDoorway(belief_.X_MB, v_M, m.map.doors, m.config.proxemics.doorway_depth,
                       m.config.tasks.footprint_radius)));
  if (m.pace.squeezing() && !was_squeezing) {
    decisions_.push_back({ToSeconds(now),
                          StrCat("held back ", m.config.proxemics.patience_s,
                                 " s by people standing in the way: edging past them"),
                          DecisionEvent::kNote});
  }
  Twist2 V_B = m.motion.Update(now, belief_.X_MB, snapshot.odometry.V_B);
  if (scan_silence > m.config.scan_hold_after_s) {
    V_B = Twist2{};  // blind: stand still until scans come again
    if (!m.holding_for_laser) {
      decisions_.push_back(
          {ToSeconds(now),
           StrCat("the base laser is silent (", scan_silence, " s): holding the base still"),
           DecisionEvent::kNote});
    }
    m.holding_for_laser = true;
    if (scan_silence > m.config.scan_abort_after_s && !m.finished) {
      m.motion.StopBase();
      m.tree->HaltTree();
      m.finished = true;
      status_ = bt::NodeStatus::kFailure;
      decisions_.push_back(
          {ToSeconds(now),
           StrCat("the base laser has been silent for ", scan_silence, " s: giving up"),
           DecisionEvent::kNote});
      decisions_.push_back({ToSeconds(now), "mission failed", DecisionEvent::kNote});
    }
  } else if (m.holding_for_laser) {
    m.holding_for_laser = false;
    decisions_.push_back({ToSeconds(now), "the base laser is back", DecisionEvent::kNote});
  }
  port.SendBaseVelocity(V_B);
  const GazeReason gaze_before = m.gaze.reason();
  if (auto head = m.gaze.Update(belief_, pan_now)) {
    port.SendHeadCommand(*head);
    if (m.gaze.reason() != gaze_before) {
      static constexpr const char* kWhy[] = {"ahead", "through the door", "at a person coming",
                                             "at what the task needs", "behind (a wall ahead)"};
      decisions_.push_back({ToSeconds(now), StrCat("head: looking ", kWhy[int(m.gaze.reason())]),
                            DecisionEvent::kNote});
    }
  }
  if (auto arm = m.motion.TakeArmCommand()) port.SendArmTrajectory(*arm);
  if (auto gripper = m.motion.TakeGripperCommand()) {
    m.grasp.OnCommand(*gripper);
    port.SendGripperCommand(*gripper);
  }
  return !m.finished;
}

void Executive::Halt(RobotPort& port, const std::string& reason) {
  Impl& m = *impl_;
  if (m.finished) return;
  port.SendBaseVelocity(Twist2{});  // the base first: halting the tree may take a moment
  m.motion.StopBase();
  m.tree->HaltTree();
  m.finished = true;
  status_ = bt::NodeStatus::kIdle;
  decisions_.push_back({ToSeconds(port.clock().Now()), "halted: " + reason, DecisionEvent::kNote});
}

const Executive::PoseAt* Executive::PoseHistoryAt(Time stamp) const {
  const PoseAt* found = nullptr;
  for (const PoseAt& entry : pose_history_) {
    if (entry.t > stamp) break;
    found = &entry;
  }
  return found;
}

bool Executive::finished() const {
  return impl_->finished;
}

}  // namespace egress::behavior
