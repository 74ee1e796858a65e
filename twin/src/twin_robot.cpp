#include "egress/twin/twin_robot.h"

#include <chrono>

#include "egress/hsr_interface/error.h"
#include "seeds.h"

namespace egress::twin {
namespace {

// Moves outputs whose latency has elapsed from a queue to `sink`.
template <typename Queue, typename Sink>
void Deliver(Queue* queue, double now, Sink sink) {
  while (!queue->empty() && queue->front().ready_time <= now + 1e-12) {
    sink(std::move(queue->front().value));
    queue->pop_front();
  }
}

}  // namespace

TwinRobot::TwinRobot(TwinWorld* world)
    : world_(world),
      config_(world->scenario().sensors),
      clock_(world->now()),
      laser_(config_),
      depth_(config_),
      detector_(config_, depth_.intrinsics()),
      laser_rng_(DeriveSeed(world->seed(), 101)),
      depth_rng_(DeriveSeed(world->seed(), 102)),
      detector_rng_(DeriveSeed(world->seed(), 103)),
      odometry_rng_(DeriveSeed(world->seed(), 104)),
      odometry_(config_, world->robot_pose(), odometry_rng_) {
  ThrowUnless(world != nullptr, "TwinRobot: world is null");
  last_odometry_ = odometry_.Read(world->now());
}

void TwinRobot::Advance(double seconds) {
  const double end = world_->time() + seconds - 1e-9;
  while (world_->time() < end)
    StepOnce();
}

void TwinRobot::StepOnce() {
  using WallClock = std::chrono::steady_clock;
  auto timed = [this](double* bucket, auto&& fn) {
    if (!measure_cost_) return fn();
    const auto t0 = WallClock::now();
    fn();
    *bucket += std::chrono::duration<double>(WallClock::now() - t0).count();
  };
  world_->Step();
  const double t = world_->time();
  clock_.AdvanceTo(world_->now());
  using Fault = FaultSpec::Kind;
  timed(&cost_.odometry, [&] {
    Twist2 V_B = world_->robot_velocity();
    if (const FaultSpec* slip = world_->ActiveFault(Fault::kOdometrySlip, t)) {
      V_B = {V_B.vx * slip->odometry_scale, V_B.vy * slip->odometry_scale,
             V_B.wz * slip->odometry_scale};
    }
    odometry_.Integrate(V_B, world_->step_size());
  });
  if (t + 1e-9 >= next_odometry_) {
    last_odometry_ = odometry_.Read(world_->now());
    next_odometry_ += 1.0 / config_.odometry_rate_hz;
  }
  if (t + 1e-9 >= next_laser_ && world_->ActiveFault(Fault::kLaserDropout, t) != nullptr) {
    next_laser_ += 1.0 / config_.laser_rate_hz;  // a scan that never comes
  } else if (t + 1e-9 >= next_laser_) {
    timed(&cost_.laser, [&] {
      laser_queue_.push_back({t + config_.laser_latency_s, laser_.Capture(*world_, laser_rng_)});
    });
    next_laser_ += 1.0 / config_.laser_rate_hz;
  }
  const bool blackout = world_->ActiveFault(Fault::kCameraBlackout, t) != nullptr;
  if (t + 1e-9 >= next_depth_ && blackout) {
    next_depth_ += 1.0 / config_.depth_rate_hz;
  } else if (t + 1e-9 >= next_depth_) {
    timed(&cost_.depth, [&] {
      depth_queue_.push_back(
          {t + config_.depth_latency_s,
           {depth_.Capture(*world_, depth_rng_),
            Pose3::FromPose2(world_->robot_pose()).Inverse() * world_->head_camera_pose()}});
    });
    next_depth_ += 1.0 / config_.depth_rate_hz;
  }
  if (t + 1e-9 >= next_detector_ && blackout) {
    next_detector_ += 1.0 / config_.detector_rate_hz;
  } else if (t + 1e-9 >= next_detector_) {
    timed(&cost_.detector, [&] {
      double latency = config_.detector_latency_s.Sample(detector_rng_);
      if (const FaultSpec* spike = world_->ActiveFault(Fault::kDetectorLatency, t))
        latency += spike->latency_s;
      for (auto& d : detector_.Detect(*world_, detector_rng_))
        detection_queue_.push_back({t + latency, std::move(d)});
    });
    next_detector_ += 1.0 / config_.detector_rate_hz;
  }
  Deliver(&laser_queue_, t, [&](LaserScan&& s) { ready_scan_ = std::move(s); });
  Deliver(&depth_queue_, t, [&](std::pair<DepthImage, Pose3>&& d) { ready_depth_ = std::move(d); });
  Deliver(&detection_queue_, t,
          [&](Detection2D&& d) { ready_detections_.push_back(std::move(d)); });
}

SensorSnapshot TwinRobot::DoSense() {
  SensorSnapshot s;
  s.stamp = world_->now();
  s.scan = std::move(ready_scan_);
  ready_scan_.reset();
  s.depth_intrinsics = depth_.intrinsics();
  if (ready_depth_) {
    s.depth = std::move(ready_depth_->first);
    s.X_BC = ready_depth_->second;
    ready_depth_.reset();
  }
  s.detections = std::move(ready_detections_);
  ready_detections_.clear();
  s.odometry = last_odometry_;
  s.joints.stamp = world_->now();
  for (const auto& [name, q] : world_->joint_positions()) {
    s.joints.names.push_back(name);
    s.joints.positions.push_back(q);
  }
  s.gripper.stamp = world_->now();
  s.gripper.hand_motor_position = world_->hand_motor_position();
  s.gripper.effort = world_->gripper_effort();
  return s;
}

void TwinRobot::DoSendBaseVelocity(const Twist2& V_B) {
  world_->SetBaseVelocity(V_B);
}
void TwinRobot::DoSendArmTrajectory(const JointTrajectory& trajectory) {
  world_->SetArmTrajectory(trajectory);
}
void TwinRobot::DoSendGripperCommand(const GripperCommand& command) {
  world_->SetGripperCommand(command);
}
void TwinRobot::DoSendHeadCommand(const HeadCommand& command) {
  world_->SetHeadCommand(command);
}

}  // namespace egress::twin
