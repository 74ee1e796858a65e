#pragma once
/// @file
/// TwinRobot: the RobotPort of the digital twin. It advances the TwinWorld in fixed steps and
/// samples each sensor at its own rate; outputs become visible to Sense() after the sensor's
/// latency (the detector's is drawn per frame from its range). The executive cannot tell it from
/// the real robot's port except by the clock, which is simulated.

#include <deque>
#include <optional>
#include <random>

#include "egress/hsr_interface/clock.h"
#include "egress/hsr_interface/robot_port.h"
#include "egress/twin/sensors.h"
#include "egress/twin/twin_world.h"

namespace egress::twin {

class TwinRobot final : public RobotPort {
 public:
  /// The world must outlive the robot. Sensor settings come from the world's scenario.
  explicit TwinRobot(TwinWorld* world);

  /// Steps the world (and the sensors) by at least `seconds` of simulated time.
  void Advance(double seconds);
  const Clock& clock() const override { return clock_; }
  TwinWorld& world() { return *world_; }

  /// Simulated seconds spent in each sensor's capture so far, for benchmarks [wall-clock s].
  struct SensorCost {
    double laser{0.0}, depth{0.0}, detector{0.0}, odometry{0.0};
  };
  const SensorCost& sensor_cost() const { return cost_; }
  /// Turns wall-clock cost accounting on (off by default: determinism never depends on it).
  void set_measure_cost(bool on) { measure_cost_ = on; }

 private:
  SensorSnapshot DoSense() override;
  void DoSendBaseVelocity(const Twist2& V_B) override;
  void DoSendArmTrajectory(const JointTrajectory& trajectory) override;
  void DoSendGripperCommand(const GripperCommand& command) override;
  void DoSendHeadCommand(const HeadCommand& command) override;
  void StepOnce();

  template <typename T>
  struct Pending {
    double ready_time;
    T value;
  };

  TwinWorld* world_;
  SensorConfig config_;
  SimClock clock_;
  LaserSimulator laser_;
  DepthCameraSimulator depth_;
  DetectorSimulator detector_;
  std::mt19937_64 laser_rng_, depth_rng_, detector_rng_, odometry_rng_;
  OdometrySimulator odometry_;
  double next_laser_{0.0}, next_depth_{0.0}, next_detector_{0.0}, next_odometry_{0.0};
  std::deque<Pending<LaserScan>> laser_queue_;
  std::deque<Pending<std::pair<DepthImage, Pose3>>> depth_queue_;
  std::deque<Pending<Detection2D>> detection_queue_;
  std::optional<LaserScan> ready_scan_;
  std::optional<std::pair<DepthImage, Pose3>> ready_depth_;
  std::vector<Detection2D> ready_detections_;
  Odometry last_odometry_;
  SensorCost cost_;
  bool measure_cost_{false};
};

}  // namespace egress::twin
