#pragma once
/// @file
/// Kinematic model of the Toyota HSR-B loaded from a URDF file: joint limits, forward
/// kinematics of the palm and the fingertip point, the geometric Jacobian of the whole-body
/// chain, and the mounting of the head camera and base laser.
///
/// The whole-body chain has eight joints (WholeBodyJoint): three virtual joints of the
/// omnidirectional base — x and y translation along the map axes and yaw about +z — followed by
/// arm_lift, arm_flex, arm_roll, wrist_flex and wrist_roll. With the base joints the chain starts
/// in the map frame M, so FK returns X_MG (palm G in M); with base joints at zero, M coincides
/// with the base frame B.

#include <array>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "egress/hsr_interface/geometry.h"

namespace egress {

/// Joints of the whole-body chain, in the order of WholeBodyVector's entries.
enum WholeBodyJoint : int {
  kBaseX = 0,  ///< Base translation along M's x axis [m] (virtual).
  kBaseY,      ///< Base translation along M's y axis [m] (virtual).
  kBaseYaw,    ///< Base rotation about +z [rad] (virtual).
  kArmLift,    ///< arm_lift_joint [m].
  kArmFlex,    ///< arm_flex_joint [rad]; −π/2 holds the arm horizontal, forward.
  kArmRoll,    ///< arm_roll_joint [rad].
  kWristFlex,  ///< wrist_flex_joint [rad].
  kWristRoll,  ///< wrist_roll_joint [rad].
  kNumWholeBodyJoints,
};

/// Positions of the whole-body chain's joints, indexed by WholeBodyJoint.
using WholeBodyVector = Eigen::Matrix<double, kNumWholeBodyJoints, 1>;
/// Geometric Jacobian: rows 0–2 map joint rates to the point's linear velocity in M [m/s],
/// rows 3–5 to the angular velocity of the palm in M [rad/s].
using WholeBodyJacobian = Eigen::Matrix<double, 6, kNumWholeBodyJoints>;

/// Names of the whole-body joints (the virtual base joints are "base_x", "base_y", "base_yaw",
/// the others are the URDF joint names).
const std::array<std::string_view, kNumWholeBodyJoints>& WholeBodyJointNames();

/// Position limits of one joint. Continuous or virtual joints have infinite bounds.
struct JointLimits {
  double lower{0.0};     ///< [m] or [rad]
  double upper{0.0};     ///< [m] or [rad]
  double velocity{0.0};  ///< [m/s] or [rad/s]; 0 when the URDF gives none.
  double effort{0.0};    ///< [N] or [N·m]; 0 when the URDF gives none.
  bool Contains(double q) const { return q >= lower && q <= upper; }
};

/// Configuration of the head: pan and tilt [rad]. The torso rises with the arm lift (the
/// URDF's torso_lift_joint mimics arm_lift_joint), so the camera pose depends on it as well.
struct HeadConfiguration {
  double pan{0.0};
  double tilt{0.0};
};

/// One collision primitive of a link, from a URDF <collision> element (meshes are not kept:
/// the shipped model describes its outline with primitives).
struct CollisionShape {
  enum class Kind { kBox, kCylinder, kSphere };
  std::string link;  ///< The link it is fixed to.
  std::string name;  ///< The <collision> element's name (may be empty).
  Kind kind{Kind::kBox};
  /// Box: full extents; cylinder: (radius, radius, length along its z); sphere: (r, r, r) [m].
  Eigen::Vector3d size{Eigen::Vector3d::Zero()};
  Pose3 X_LS;  ///< Shape frame S in the link frame L.
  /// Radius of the smallest sphere about S's origin that holds the shape [m].
  double BoundingRadius() const;
  /// Whether point p_SQ (in S) lies inside the shape grown by `margin` [m].
  bool Contains(const Eigen::Vector3d& p_SQ, double margin = 0.0) const;
};

/// A collision shape placed in the base frame B.
struct PlacedShape {
  CollisionShape shape;
  Pose3 X_BS;  ///< Shape frame S in B.
};

/// The HSR's kinematics. Immutable after loading; all Calc methods are const and thread-safe.
class RobotModel {
 public:
  /// Default footprint radius of the round base [m], used when the URDF's base_link has no
  /// cylinder collision shape.
  static constexpr double kDefaultFootprintRadius = 0.215;

  /// Loads a URDF file. @throws LoadError naming the file for a missing or unreadable file,
  /// malformed XML, or a URDF that lacks a link or joint the model needs (named in the message).
  static RobotModel LoadFromFile(const std::filesystem::path& urdf_path);
  /// Loads URDF text; `source_name` is used in error messages.
  static RobotModel LoadFromString(const std::string& urdf_xml, std::string_view source_name);
  /// Loads the HSR model egress ships (hsr_interface/models/hsrb.urdf, or the file named by the
  /// EGRESS_HSR_URDF environment variable).
  static RobotModel LoadDefault();
  /// Path of the URDF LoadDefault() reads.
  static std::filesystem::path DefaultUrdfPath();

  ~RobotModel();
  RobotModel(RobotModel&&) noexcept;
  RobotModel& operator=(RobotModel&&) noexcept;
  RobotModel(const RobotModel&);
  RobotModel& operator=(const RobotModel&);

  /// Robot name from the URDF.
  const std::string& name() const;
  /// Where this model came from (file path or the source name given to LoadFromString).
  const std::string& source() const;

  /// Limits of one whole-body joint; the base joints are unbounded.
  const JointLimits& limits(WholeBodyJoint joint) const;
  /// Limits of any URDF joint by name. @throws InvalidArgument naming an unknown joint.
  JointLimits GetJointLimits(std::string_view joint_name) const;
  /// Lower and upper limit vectors of the whole-body chain.
  WholeBodyVector lower_limits() const;
  WholeBodyVector upper_limits() const;
  /// Clamps q into the joint limits.
  WholeBodyVector ClampToLimits(const WholeBodyVector& q) const;
  bool IsWithinLimits(const WholeBodyVector& q) const;

  /// A named configuration from the URDF: a root-level `<group_state name=".." group="..">`
  /// element with `<joint name=".." value=".."/>` children (SRDF's vocabulary; urdfdom skips
  /// the element). Base joints are zero; arm joints it does not name are zero clamped to their
  /// limits. @throws InvalidArgument naming the configuration and the ones the URDF has.
  WholeBodyVector NamedConfiguration(std::string_view name) const;
  /// Names of the URDF's named configurations, sorted.
  std::vector<std::string> named_configurations() const;
  /// The arm folded over the base (nothing outside the footprint): the named configuration
  /// "tucked" (kTuckedConfigurationName), or, for a URDF without one, every arm joint at zero
  /// clamped to its limits.
  WholeBodyVector tucked_configuration() const;
  static constexpr std::string_view kTuckedConfigurationName = "tucked";

  /// Radius of the round base footprint [m].
  double footprint_radius() const;

  /// Pose of the palm frame hand_palm_link (G) in M. @throws InvalidArgument if q is not finite.
  Pose3 CalcPalmPose(const WholeBodyVector& q) const;
  /// Position in M of the fingertip point: the midpoint of the two fingertip frames with the
  /// gripper at hand_motor_joint = 0, rigidly attached to the palm.
  Eigen::Vector3d CalcFingertipPosition(const WholeBodyVector& q) const;
  /// The fingertip point in the palm frame, p_GF [m].
  const Eigen::Vector3d& fingertip_in_palm() const;
  /// Geometric Jacobian of the palm origin (linear rows) and palm rotation (angular rows).
  WholeBodyJacobian CalcPalmJacobian(const WholeBodyVector& q) const;
  /// Geometric Jacobian of the fingertip point (linear rows) and palm rotation (angular rows).
  WholeBodyJacobian CalcFingertipJacobian(const WholeBodyVector& q) const;
  /// The palm pose and the Jacobian of the palm point p_GQ in one pass (the IK's inner loop).
  void CalcPalmPoseAndJacobian(const WholeBodyVector& q, const Eigen::Vector3d& p_GQ, Pose3* X_MG,
                               WholeBodyJacobian* J) const;
  /// Jacobian of an arbitrary point p_GQ fixed in the palm frame.
  WholeBodyJacobian CalcJacobianOfPalmPoint(const WholeBodyVector& q,
                                            const Eigen::Vector3d& p_GQ) const;

  /// Pose of the head RGB-D camera's optical frame C in the base frame B.
  Pose3 CalcHeadCameraPose(double arm_lift, const HeadConfiguration& head) const;
  /// Pose of the base laser frame L in B.
  const Pose3& laser_pose() const;

  /// The collision primitives of every link (URDF order of links, then of elements).
  const std::vector<CollisionShape>& collision_shapes() const;
  /// Every collision primitive placed in B for the named joint positions (as for
  /// CalcLinkPoseInBase: joints not given are at 0, mimic joints follow their leader). With
  /// `skip_fingers`, the finger links (hand_*_proximal/distal) are left out: they fold inside
  /// the hand's outline and a grasp opens them round the payload.
  /// @throws InvalidArgument for an unknown joint or a non-finite position.
  std::vector<PlacedShape> CalcCollisionShapesInBase(
      const std::vector<std::pair<std::string, double>>& joint_positions,
      bool skip_fingers = true) const;

  /// Pose of any link in B for the named joint positions (joints not given are at 0; mimic
  /// joints follow their leader). @throws InvalidArgument for an unknown link or joint name.
  Pose3 CalcLinkPoseInBase(
      std::string_view link_name,
      const std::vector<std::pair<std::string, double>>& joint_positions) const;

 private:
  struct Impl;
  explicit RobotModel(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace egress
