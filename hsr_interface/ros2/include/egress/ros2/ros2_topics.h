#pragma once
/// @file
/// The ROS 2 topics the brain and the robot speak on, with the HSR's ROS 2 names as defaults;
/// every one remappable from one YAML file (`topics: {scan: /my/scan, ...}`).

#include <string>
#include <vector>

namespace egress::ros2 {

struct Ros2Topics {
  // The robot publishes:
  std::string scan{"/scan"};  ///< sensor_msgs/LaserScan, base laser (sensor-data QoS)
  std::string depth_image{"/head_rgbd_sensor/depth_registered/image_rect_raw"};
  std::string depth_camera_info{"/head_rgbd_sensor/depth_registered/camera_info"};
  std::string color_image{"/head_rgbd_sensor/rgb/image_rect_color"};
  std::string joint_states{"/whole_body/joint_states"};      ///< sensor_msgs/JointState
  std::string odometry{"/omni_base_controller/wheel_odom"};  ///< nav_msgs/Odometry
  /// tf2_msgs/TFMessage: base_footprint -> head_rgbd_sensor_link (the camera in the base).
  std::string tf{"/tf"};
  std::string clock{"/clock"};  ///< rosgraph_msgs/Clock (simulated time)
  /// vision_msgs/Detection2DArray, for a robot that runs its own detector.
  std::string detections{"/egress/detections"};
  // The brain publishes:
  std::string cmd_vel{"/omni_base_controller/cmd_vel"};  ///< geometry_msgs/Twist
  std::string arm_trajectory{"/arm_trajectory_controller/joint_trajectory"};
  /// trajectory_msgs/JointTrajectory for head_pan_joint and head_tilt_joint.
  std::string head_trajectory{"/head_trajectory_controller/joint_trajectory"};
  /// The gripper controller's actions (tmc_control_msgs/action/GripperApplyEffort; their goals
  /// go to `<name>/_action/send_goal`): `grasp` takes a motor torque [Nm] (egress opens with
  /// it), `apply_force` a grip force [N] (egress grasps with it).
  std::string gripper_grasp_action{"/gripper_controller/grasp"};
  std::string gripper_apply_force_action{"/gripper_controller/apply_force"};
  /// std_msgs/String: the mission tree's status (IDLE, RUNNING, SUCCESS, FAILURE, HALTED: why).
  std::string status{"/egress/status"};
  /// rosgraph_msgs/Clock: the time of the control step the brain has just finished (lock-step
  /// simulation waits for it).
  std::string brain_clock{"/egress/brain_clock"};
  // Either side:
  std::string estop{"/egress/estop"};  ///< std_msgs/Bool: true stops the base and halts the tree

  /// Every topic a valid absolute ROS 2 name. @throws InvalidArgument naming the entry.
  void Validate() const;
  /// Reads `path`: a YAML map (or one under `topics:`) of the entries above; entries left out
  /// keep their defaults. @throws InvalidArgument naming the file and the unknown or bad entry.
  static Ros2Topics FromYamlFile(const std::string& path);
};

}  // namespace egress::ros2
