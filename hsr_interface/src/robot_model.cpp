#include "egress/hsr_interface/robot_model.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>

#include <console_bridge/console.h>
#include <tinyxml2.h>
#include <urdf_parser/urdf_parser.h>

#include "egress/hsr_interface/error.h"
#include "egress/hsr_interface/text_file.h"
#include "urdf_joint_tree.h"

#ifndef EGRESS_HSR_URDF_PATH
#error "EGRESS_HSR_URDF_PATH must be defined by the build"
#endif

namespace egress {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

constexpr std::string_view kRootLink = "base_footprint";
constexpr std::string_view kBaseLink = "base_link";
constexpr std::string_view kPalmLink = "hand_palm_link";
constexpr std::string_view kLaserLink = "base_range_sensor_link";
constexpr std::string_view kHeadCameraLink = "head_rgbd_sensor_link";
constexpr std::string_view kLeftFingertipLink = "hand_l_finger_tip_frame";
constexpr std::string_view kRightFingertipLink = "hand_r_finger_tip_frame";

constexpr std::array<std::string_view, kNumWholeBodyJoints> kWholeBodyJointNames = {
    "base_x",         "base_y",         "base_yaw",         "arm_lift_joint",
    "arm_flex_joint", "arm_roll_joint", "wrist_flex_joint", "wrist_roll_joint"};

enum class JointType { kFixed, kRevolute, kPrismatic };

struct JointInfo {
  std::string name;
  JointType type{JointType::kFixed};
  std::string parent_link;
  std::string child_link;
  Pose3 X_PJ;                                      // Joint frame J in the parent link P at q = 0.
  Eigen::Vector3d axis{Eigen::Vector3d::UnitX()};  // In J, unit length.
  JointLimits limits;
  std::optional<std::string> mimic_leader;
  double mimic_multiplier{1.0};
  double mimic_offset{0.0};

  Pose3 Motion(double q) const {
    if (type == JointType::kRevolute) {
      return Pose3(Eigen::AngleAxisd(q, axis).toRotationMatrix(), Eigen::Vector3d::Zero());
    }
    if (type == JointType::kPrismatic) return Pose3(Eigen::Vector3d(axis * q));
    return Pose3();
  }
};

// One actuated joint of the whole-body chain, with every fixed transform before it folded in.
struct ChainSegment {
  Pose3 X_prev_J;  // Joint frame in the previous segment's moving frame (or in B).
  Eigen::Vector3d axis;
  JointType type;
};

// Collects console_bridge messages (urdfdom reports its errors through it) while a URDF is
// parsed, so they can be put into the exception instead of being lost on stderr.
class CapturingOutputHandler final : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_WARN) {
      if (!messages_.empty()) messages_ += "; ";
      messages_ += text;
    }
  }
  const std::string& messages() const { return messages_; }

 private:
  std::string messages_;
};

std::mutex& ConsoleBridgeMutex() {
  static std::mutex mutex;
  return mutex;
}

Pose3 ToPose3(const urdf::Pose& pose) {
  const Eigen::Quaterniond q(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z);
  return Pose3(q, Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z));
}

}  // namespace

struct RobotModel::Impl {
  std::string name;
  std::string source;
  std::map<std::string, JointInfo, std::less<>> joints;
  std::map<std::string, std::string, std::less<>> parent_joint_of_link;  // link -> joint
  std::array<JointLimits, kNumWholeBodyJoints> limits;
  std::array<ChainSegment, kNumWholeBodyJoints - 3> arm_chain;
  Pose3 X_wrist_G;  // Palm in the last arm joint's moving frame.
  Eigen::Vector3d p_GF{Eigen::Vector3d::Zero()};
  Pose3 X_BL;
  double footprint_radius{RobotModel::kDefaultFootprintRadius};
  std::vector<CollisionShape> collision_shapes;
  std::map<std::string, WholeBodyVector, std::less<>> named_configurations;

  [[noreturn]] void Fail(const std::string& what) const {
    throw LoadError(StrCat("Cannot load robot model from '", source, "': ", what));
  }

  // Root-level <group_state> elements (SRDF's vocabulary), which urdfdom does not read.
  void ReadNamedConfigurations(const std::string& urdf_xml) {
    tinyxml2::XMLDocument doc;
    if (doc.Parse(urdf_xml.c_str(), urdf_xml.size()) != tinyxml2::XML_SUCCESS)
      Fail(StrCat("XML error: ", doc.ErrorStr()));
    const tinyxml2::XMLElement* robot = doc.RootElement();
    for (const auto* state = robot->FirstChildElement("group_state"); state != nullptr;
         state = state->NextSiblingElement("group_state")) {
      const std::string at = StrCat("<group_state> at line ", state->GetLineNum());
      const char* name = state->Attribute("name");
      if (name == nullptr || *name == '\0') Fail(StrCat(at, " has no name."));
      if (named_configurations.count(name) != 0)
        Fail(StrCat(at, ": a configuration named '", name, "' is given twice."));
      WholeBodyVector q = WholeBodyVector::Zero();
      for (int i = kArmLift; i < kNumWholeBodyJoints; ++i)
        q[i] = std::clamp(0.0, limits[i].lower, limits[i].upper);
      for (const auto* joint = state->FirstChildElement("joint"); joint != nullptr;
           joint = joint->NextSiblingElement("joint")) {
        const std::string where =
            StrCat(at, " ('", name, "'), <joint> at line ", joint->GetLineNum());
        const char* joint_name = joint->Attribute("name");
        if (joint_name == nullptr) Fail(StrCat(where, " has no name."));
        int index = -1;
        for (int i = kArmLift; i < kNumWholeBodyJoints; ++i)
          if (kWholeBodyJointNames[i] == joint_name) index = i;
        if (index < 0)
          Fail(StrCat(where, ": '", joint_name, "' is not an arm joint of the whole-body chain."));
        double value = 0.0;
        if (joint->QueryDoubleAttribute("value", &value) != tinyxml2::XML_SUCCESS ||
            !std::isfinite(value))
          Fail(StrCat(where, ": value must be a finite number."));
        if (value < limits[index].lower || value > limits[index].upper)
          Fail(StrCat(where, ": value ", value, " is outside ", joint_name, "'s limits [",
                      limits[index].lower, ", ", limits[index].upper, "]."));
        q[index] = value;
      }
      named_configurations.emplace(name, q);
    }
  }

  // The joints form a tree (urdf_joint_tree.h), before urdfdom reads the model.
  void RequireJointTree(const std::string& urdf_xml) const {
    if (const auto problem = FindJointTreeProblem(urdf_xml, kRootLink)) Fail(*problem);
  }

  // Joints from the root down to `link`, in order.
  std::vector<const JointInfo*> PathFromRoot(std::string_view link) const {
    std::vector<const JointInfo*> path;
    std::string current(link);
    while (current != kRootLink) {
      auto it = parent_joint_of_link.find(current);
      if (it == parent_joint_of_link.end()) {
        throw InvalidArgument(StrCat("Unknown link '", link, "' in robot model '", name, "'."));
      }
      const JointInfo& joint = joints.at(it->second);
      path.push_back(&joint);
      current = joint.parent_link;
    }
    return {path.rbegin(), path.rend()};
  }

  Pose3 LinkPoseInBase(std::string_view link,
                       const std::map<std::string, double, std::less<>>& q) const {
    std::map<std::string, Pose3, std::less<>> cache;
    return CachedLinkPoseInBase(link, q, &cache);
  }

  // A joint's position in q: a mimic joint's from its leader's, a joint not in q at 0.
  static double JointValue(const JointInfo& joint,
                           const std::map<std::string, double, std::less<>>& q) {
    if (joint.mimic_leader) {
      auto it = q.find(*joint.mimic_leader);
      const double leader = it == q.end() ? 0.0 : it->second;
      return joint.mimic_multiplier * leader + joint.mimic_offset;
    }
    auto it = q.find(joint.name);
    return it != q.end() ? it->second : 0.0;
  }

  // A link's pose in B through `cache` (link -> pose in B): its parent's times its joint's, from
  // the identity at the root, so each link on the way is computed once for all the links below
  // it (CalcCollisionShapesInBase shares one cache among all its shapes' links).
  const Pose3& CachedLinkPoseInBase(std::string_view link,
                                    const std::map<std::string, double, std::less<>>& q,
                                    std::map<std::string, Pose3, std::less<>>* cache) const {
    if (auto it = cache->find(link); it != cache->end()) return it->second;
    if (link == kRootLink) return cache->emplace(std::string(link), Pose3()).first->second;
    auto parent_joint = parent_joint_of_link.find(link);
    if (parent_joint == parent_joint_of_link.end()) {
      throw InvalidArgument(StrCat("Unknown link '", link, "' in robot model '", name, "'."));
    }
    const JointInfo& joint = joints.at(parent_joint->second);
    const Pose3 X_BParent = CachedLinkPoseInBase(joint.parent_link, q, cache);
    return cache
        ->emplace(std::string(link), X_BParent * joint.X_PJ * joint.Motion(JointValue(joint, q)))
        .first->second;
  }

  void ReadJoints(const urdf::ModelInterface& model) {
    for (const auto& [joint_name, joint] : model.joints_) {
      JointInfo info;
      info.name = joint_name;
      info.parent_link = joint->parent_link_name;
      info.child_link = joint->child_link_name;
      info.X_PJ = ToPose3(joint->parent_to_joint_origin_transform);
      const Eigen::Vector3d axis(joint->axis.x, joint->axis.y, joint->axis.z);
      info.limits = {-kInf, kInf, 0.0, 0.0};
      switch (joint->type) {
        case urdf::Joint::REVOLUTE:
        case urdf::Joint::CONTINUOUS:
          info.type = JointType::kRevolute;
          break;
        case urdf::Joint::PRISMATIC:
          info.type = JointType::kPrismatic;
          break;
        case urdf::Joint::FIXED:
          info.type = JointType::kFixed;
          break;
        default:
          Fail(StrCat("joint '", joint_name, "' has a type egress does not model (only fixed, ",
                      "revolute, continuous and prismatic joints are supported)."));
      }
      if (info.type != JointType::kFixed) {
        if (!(axis.norm() > 1e-9)) Fail(StrCat("joint '", joint_name, "' has a zero axis."));
        info.axis = axis.normalized();
        if (joint->limits && joint->type != urdf::Joint::CONTINUOUS) {
          info.limits = {joint->limits->lower, joint->limits->upper, joint->limits->velocity,
                         joint->limits->effort};
          if (info.limits.lower > info.limits.upper) {
            Fail(StrCat("joint '", joint_name, "' has lower limit ", info.limits.lower,
                        " above its upper limit ", info.limits.upper, "."));
          }
        } else if (joint->limits) {
          info.limits.velocity = joint->limits->velocity;
          info.limits.effort = joint->limits->effort;
        }
      }
      if (joint->mimic) {
        info.mimic_leader = joint->mimic->joint_name;
        info.mimic_multiplier = joint->mimic->multiplier;
        info.mimic_offset = joint->mimic->offset;
      }
      parent_joint_of_link[info.child_link] = joint_name;
      joints.emplace(joint_name, std::move(info));
    }
    for (const auto& [joint_name, info] : joints) {
      if (info.mimic_leader && !joints.contains(*info.mimic_leader)) {
        Fail(StrCat("joint '", joint_name, "' mimics '", *info.mimic_leader,
                    "', which is not in the model."));
      }
    }
  }

  // Named joint positions as a map. @throws InvalidArgument for an unknown joint or a
  // non-finite position.
  std::map<std::string, double, std::less<>> JointMap(
      const std::vector<std::pair<std::string, double>>& joint_positions) const {
    std::map<std::string, double, std::less<>> q;
    for (const auto& [joint, value] : joint_positions) {
      ThrowUnless(joints.contains(joint), "Unknown joint '", joint, "' in robot model '", name,
                  "'.");
      ThrowUnless(std::isfinite(value), "Invalid joint position: '", joint, "' (", value,
                  ") must be finite.");
      q[joint] = value;
    }
    return q;
  }

  // Primitive <collision> elements of every link reachable from the root; meshes are skipped.
  void ReadCollisionShapes(const urdf::ModelInterface& model) {
    std::vector<urdf::LinkSharedPtr> links;
    model.getLinks(links);
    std::sort(links.begin(), links.end(),
              [](const auto& a, const auto& b) { return a->name < b->name; });
    for (const auto& link : links) {
      if (link->name != kRootLink && !parent_joint_of_link.contains(link->name)) continue;
      for (const auto& collision : link->collision_array) {
        if (!collision || !collision->geometry) continue;
        CollisionShape shape;
        shape.link = link->name;
        shape.name = collision->name;
        shape.X_LS = ToPose3(collision->origin);
        const std::string what =
            StrCat("link '", link->name, "' collision '", collision->name, "'");
        switch (collision->geometry->type) {
          case urdf::Geometry::BOX: {
            const auto& box = static_cast<const urdf::Box&>(*collision->geometry);
            shape.kind = CollisionShape::Kind::kBox;
            shape.size = {box.dim.x, box.dim.y, box.dim.z};
            break;
          }
          case urdf::Geometry::CYLINDER: {
            const auto& c = static_cast<const urdf::Cylinder&>(*collision->geometry);
            shape.kind = CollisionShape::Kind::kCylinder;
            shape.size = {c.radius, c.radius, c.length};
            break;
          }
          case urdf::Geometry::SPHERE: {
            const auto& sphere = static_cast<const urdf::Sphere&>(*collision->geometry);
            shape.kind = CollisionShape::Kind::kSphere;
            shape.size = Eigen::Vector3d::Constant(sphere.radius);
            break;
          }
          default:
            continue;  // meshes: the robot's outline is given by primitives
        }
        if (!shape.size.allFinite() || !(shape.size.minCoeff() > 0.0))
          Fail(StrCat(what, " has a non-positive or non-finite size."));
        collision_shapes.push_back(std::move(shape));
      }
    }
  }

  void RequireLink(const urdf::ModelInterface& model, std::string_view link) const {
    if (!model.getLink(std::string(link))) {
      Fail(StrCat("required link '", link, "' is missing."));
    }
  }

  // Folds the path base_footprint -> hand_palm_link into the five actuated arm segments.
  void BuildArmChain() {
    limits[kBaseX] = limits[kBaseY] = limits[kBaseYaw] = {-kInf, kInf, 0.0, 0.0};
    std::vector<const JointInfo*> path = PathFromRoot(kPalmLink);
    Pose3 pending;  // Fixed transforms since the last actuated joint.
    int next = kArmLift;
    for (const JointInfo* joint : path) {
      const bool locked = joint->type != JointType::kFixed && joint->limits.lower == 0.0 &&
                          joint->limits.upper == 0.0;
      if (joint->type == JointType::kFixed || locked) {
        pending = pending * joint->X_PJ;
        continue;
      }
      if (next >= kNumWholeBodyJoints || joint->name != kWholeBodyJointNames[next]) {
        const std::string_view expected =
            next < kNumWholeBodyJoints ? kWholeBodyJointNames[next] : "no further joint";
        Fail(StrCat("the chain from '", kRootLink, "' to '", kPalmLink, "' has joint '",
                    joint->name, "' where '", expected, "' was expected."));
      }
      const JointType expected_type =
          next == kArmLift ? JointType::kPrismatic : JointType::kRevolute;
      if (joint->type != expected_type) {
        Fail(StrCat("joint '", joint->name, "' must be ",
                    expected_type == JointType::kPrismatic ? "prismatic." : "revolute."));
      }
      arm_chain[next - kArmLift] = {pending * joint->X_PJ, joint->axis, joint->type};
      limits[next] = joint->limits;
      pending = Pose3();
      ++next;
    }
    if (next != kNumWholeBodyJoints) {
      Fail(StrCat("joint '", kWholeBodyJointNames[next], "' is missing from the chain '", kRootLink,
                  "' -> '", kPalmLink, "'."));
    }
    X_wrist_G = pending;
  }

  // Poses of the palm and of each arm joint frame J_i (before its motion) in M. Raw rotation
  // and translation arithmetic: this is the IK's inner loop, so no Pose3 validation here.
  void ForwardKinematics(const WholeBodyVector& q, std::array<Pose3, kNumWholeBodyJoints - 3>* X_MJ,
                         Pose3* X_MG) const {
    for (int i = 0; i < kNumWholeBodyJoints; ++i) {
      ThrowUnless(std::isfinite(q[i]),
                  "Invalid whole-body configuration: ", kWholeBodyJointNames[i], " (", q[i],
                  ") must be finite.");
    }
    const double c = std::cos(q[kBaseYaw]), s = std::sin(q[kBaseYaw]);
    Eigen::Matrix3d R;
    R << c, -s, 0, s, c, 0, 0, 0, 1;
    Eigen::Vector3d p(q[kBaseX], q[kBaseY], 0.0);
    for (int i = 0; i < kNumWholeBodyJoints - 3; ++i) {
      const ChainSegment& segment = arm_chain[i];
      p += R * segment.X_prev_J.translation();
      R = R * segment.X_prev_J.rotation();
      if (X_MJ) (*X_MJ)[i] = Pose3::FromTrustedParts(R, p);
      const double value = q[kArmLift + i];
      if (segment.type == JointType::kRevolute) {
        R = R * Eigen::AngleAxisd(value, segment.axis).toRotationMatrix();
      } else {
        p += R * (segment.axis * value);
      }
    }
    *X_MG = Pose3::FromTrustedParts(R * X_wrist_G.rotation(), p + R * X_wrist_G.translation());
  }
};

const std::array<std::string_view, kNumWholeBodyJoints>& WholeBodyJointNames() {
  return kWholeBodyJointNames;
}

RobotModel::RobotModel(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
RobotModel::~RobotModel() = default;
RobotModel::RobotModel(RobotModel&&) noexcept = default;
RobotModel& RobotModel::operator=(RobotModel&&) noexcept = default;
RobotModel::RobotModel(const RobotModel& other) : impl_(std::make_unique<Impl>(*other.impl_)) {}
RobotModel& RobotModel::operator=(const RobotModel& other) {
  if (this != &other) impl_ = std::make_unique<Impl>(*other.impl_);
  return *this;
}

std::filesystem::path RobotModel::DefaultUrdfPath() {
  if (const char* env = std::getenv("EGRESS_HSR_URDF"); env != nullptr && *env != '\0') {
    return env;
  }
  return EGRESS_HSR_URDF_PATH;
}

RobotModel RobotModel::LoadDefault() {
  return LoadFromFile(DefaultUrdfPath());
}

RobotModel RobotModel::LoadFromFile(const std::filesystem::path& urdf_path) {
  std::string text;
  try {
    text = ReadTextFile(urdf_path, "URDF file");
  } catch (const LoadError& e) {
    throw LoadError(StrCat("Cannot load robot model: ", e.what()));
  }
  return LoadFromString(text, urdf_path.string());
}

RobotModel RobotModel::LoadFromString(const std::string& urdf_xml, std::string_view source_name) {
  auto impl = std::make_unique<Impl>();
  impl->source = std::string(source_name);
  if (urdf_xml.find_first_not_of(" \t\r\n") == std::string::npos)
    impl->Fail("the document is empty.");

  impl->RequireJointTree(urdf_xml);
  // urdfdom reads the document as the checks read it (urdf_joint_tree.h).
  const std::string canonical = CanonicalRobotXml(urdf_xml);
  if (canonical.empty()) impl->Fail("the document has no <robot> element.");
  urdf::ModelInterfaceSharedPtr model;
  std::string parser_messages;
  {
    std::lock_guard lock(ConsoleBridgeMutex());
    CapturingOutputHandler capture;
    console_bridge::useOutputHandler(&capture);
    try {
      model = urdf::parseURDF(canonical);
    } catch (const std::exception& e) {
      console_bridge::restorePreviousOutputHandler();
      impl->Fail(e.what());
    }
    console_bridge::restorePreviousOutputHandler();
    parser_messages = capture.messages();
  }
  if (!model) {
    impl->Fail(StrCat("URDF parse error: ", parser_messages.empty()
                                                ? std::string("the parser rejected the document.")
                                                : parser_messages));
  }
  impl->name = model->getName();
  if (!model->getRoot() || model->getRoot()->name != kRootLink) {
    impl->Fail(StrCat("the root link must be '", kRootLink, "' (found '",
                      model->getRoot() ? model->getRoot()->name : std::string("none"), "')."));
  }
  for (std::string_view link : {kBaseLink, kPalmLink, kLaserLink, kHeadCameraLink,
                                kLeftFingertipLink, kRightFingertipLink}) {
    impl->RequireLink(*model, link);
  }
  impl->ReadJoints(*model);
  impl->BuildArmChain();

  // Fingertip point: midpoint of the two fingertip frames at hand_motor_joint = 0, in the palm.
  const std::map<std::string, double, std::less<>> zero;
  const Pose3 X_BG = impl->LinkPoseInBase(kPalmLink, zero);
  const Eigen::Vector3d p_BF =
      0.5 * (impl->LinkPoseInBase(kLeftFingertipLink, zero).translation() +
             impl->LinkPoseInBase(kRightFingertipLink, zero).translation());
  impl->p_GF = X_BG.Inverse() * p_BF;
  impl->X_BL = impl->LinkPoseInBase(kLaserLink, zero);

  // Footprint radius: the base_link's cylinder collision, if it has one.
  const auto base_link = model->getLink(std::string(kBaseLink));
  for (const auto& collision : base_link->collision_array) {
    if (collision && collision->geometry && collision->geometry->type == urdf::Geometry::CYLINDER) {
      const auto& cylinder = static_cast<const urdf::Cylinder&>(*collision->geometry);
      if (!(cylinder.radius > 0.0)) impl->Fail("base_link's cylinder radius must be > 0.");
      impl->footprint_radius = cylinder.radius;
      break;
    }
  }
  impl->ReadCollisionShapes(*model);
  impl->ReadNamedConfigurations(urdf_xml);
  return RobotModel(std::move(impl));
}

WholeBodyVector RobotModel::NamedConfiguration(std::string_view name) const {
  const auto it = impl_->named_configurations.find(name);
  if (it == impl_->named_configurations.end()) {
    std::string known;
    for (const auto& n : named_configurations())
      known += (known.empty() ? "" : ", ") + n;
    throw InvalidArgument(StrCat("Robot model '", impl_->name, "' has no configuration named '",
                                 name, "' (it has: ", known.empty() ? "none" : known, ")."));
  }
  return it->second;
}

std::vector<std::string> RobotModel::named_configurations() const {
  std::vector<std::string> names;
  for (const auto& [name, q] : impl_->named_configurations)
    names.push_back(name);
  return names;
}

WholeBodyVector RobotModel::tucked_configuration() const {
  if (impl_->named_configurations.count(kTuckedConfigurationName) != 0)
    return NamedConfiguration(kTuckedConfigurationName);
  return ClampToLimits(WholeBodyVector::Zero());
}

const std::string& RobotModel::name() const {
  return impl_->name;
}
const std::string& RobotModel::source() const {
  return impl_->source;
}

const JointLimits& RobotModel::limits(WholeBodyJoint joint) const {
  ThrowUnless(joint >= 0 && joint < kNumWholeBodyJoints, "Invalid whole-body joint index ",
              int(joint), ".");
  return impl_->limits[joint];
}

JointLimits RobotModel::GetJointLimits(std::string_view joint_name) const {
  for (int i = 0; i < kNumWholeBodyJoints; ++i) {
    if (kWholeBodyJointNames[i] == joint_name) return impl_->limits[i];
  }
  auto it = impl_->joints.find(joint_name);
  ThrowUnless(it != impl_->joints.end(), "Unknown joint '", joint_name, "' in robot model '",
              impl_->name, "'.");
  return it->second.limits;
}

WholeBodyVector RobotModel::lower_limits() const {
  WholeBodyVector v;
  for (int i = 0; i < kNumWholeBodyJoints; ++i)
    v[i] = impl_->limits[i].lower;
  return v;
}

WholeBodyVector RobotModel::upper_limits() const {
  WholeBodyVector v;
  for (int i = 0; i < kNumWholeBodyJoints; ++i)
    v[i] = impl_->limits[i].upper;
  return v;
}

WholeBodyVector RobotModel::ClampToLimits(const WholeBodyVector& q) const {
  return q.cwiseMax(lower_limits()).cwiseMin(upper_limits());
}

bool RobotModel::IsWithinLimits(const WholeBodyVector& q) const {
  for (int i = 0; i < kNumWholeBodyJoints; ++i) {
    if (!impl_->limits[i].Contains(q[i])) return false;
  }
  return true;
}

double RobotModel::footprint_radius() const {
  return impl_->footprint_radius;
}

Pose3 RobotModel::CalcPalmPose(const WholeBodyVector& q) const {
  Pose3 X_MG;
  impl_->ForwardKinematics(q, nullptr, &X_MG);
  return X_MG;
}

Eigen::Vector3d RobotModel::CalcFingertipPosition(const WholeBodyVector& q) const {
  return CalcPalmPose(q) * impl_->p_GF;
}

const Eigen::Vector3d& RobotModel::fingertip_in_palm() const {
  return impl_->p_GF;
}

WholeBodyJacobian RobotModel::CalcPalmJacobian(const WholeBodyVector& q) const {
  return CalcJacobianOfPalmPoint(q, Eigen::Vector3d::Zero());
}

WholeBodyJacobian RobotModel::CalcFingertipJacobian(const WholeBodyVector& q) const {
  return CalcJacobianOfPalmPoint(q, impl_->p_GF);
}

WholeBodyJacobian RobotModel::CalcJacobianOfPalmPoint(const WholeBodyVector& q,
                                                      const Eigen::Vector3d& p_GQ) const {
  Pose3 X_MG;
  WholeBodyJacobian J;
  CalcPalmPoseAndJacobian(q, p_GQ, &X_MG, &J);
  return J;
}

void RobotModel::CalcPalmPoseAndJacobian(const WholeBodyVector& q, const Eigen::Vector3d& p_GQ,
                                         Pose3* X_MG_out, WholeBodyJacobian* J_out) const {
  ThrowUnless(p_GQ.allFinite(), "Invalid palm point: p_GQ must be finite.");
  std::array<Pose3, kNumWholeBodyJoints - 3> X_MJ;
  Pose3 X_MG;
  impl_->ForwardKinematics(q, &X_MJ, &X_MG);
  const Eigen::Vector3d p_MQ = X_MG * p_GQ;

  WholeBodyJacobian& J = *J_out;
  J.setZero();
  J.block<3, 1>(0, kBaseX) = Eigen::Vector3d::UnitX();
  J.block<3, 1>(0, kBaseY) = Eigen::Vector3d::UnitY();
  const Eigen::Vector3d p_MB(q[kBaseX], q[kBaseY], 0.0);
  J.block<3, 1>(0, kBaseYaw) = Eigen::Vector3d::UnitZ().cross(p_MQ - p_MB);
  J.block<3, 1>(3, kBaseYaw) = Eigen::Vector3d::UnitZ();
  for (int i = 0; i < kNumWholeBodyJoints - 3; ++i) {
    const Eigen::Vector3d axis_M = X_MJ[i].rotation() * impl_->arm_chain[i].axis;
    if (impl_->arm_chain[i].type == JointType::kPrismatic) {
      J.block<3, 1>(0, kArmLift + i) = axis_M;
    } else {
      J.block<3, 1>(0, kArmLift + i) = axis_M.cross(p_MQ - X_MJ[i].translation());
      J.block<3, 1>(3, kArmLift + i) = axis_M;
    }
  }
  *X_MG_out = X_MG;
}

Pose3 RobotModel::CalcHeadCameraPose(double arm_lift, const HeadConfiguration& head) const {
  ThrowUnless(std::isfinite(arm_lift) && std::isfinite(head.pan) && std::isfinite(head.tilt),
              "Invalid head configuration: arm_lift (", arm_lift, "), pan (", head.pan,
              ") and tilt (", head.tilt, ") must be finite.");
  return impl_->LinkPoseInBase(
      kHeadCameraLink,
      {{"arm_lift_joint", arm_lift}, {"head_pan_joint", head.pan}, {"head_tilt_joint", head.tilt}});
}

const Pose3& RobotModel::laser_pose() const {
  return impl_->X_BL;
}

const std::vector<CollisionShape>& RobotModel::collision_shapes() const {
  return impl_->collision_shapes;
}

std::vector<PlacedShape> RobotModel::CalcCollisionShapesInBase(
    const std::vector<std::pair<std::string, double>>& joint_positions, bool skip_fingers) const {
  const auto q = impl_->JointMap(joint_positions);
  std::vector<PlacedShape> out;
  std::map<std::string, Pose3, std::less<>> link_poses;
  for (const CollisionShape& shape : impl_->collision_shapes) {
    if (skip_fingers && shape.link.starts_with("hand_") &&
        (shape.link.find("proximal") != std::string::npos ||
         shape.link.find("distal") != std::string::npos)) {
      continue;
    }
    out.push_back({shape, impl_->CachedLinkPoseInBase(shape.link, q, &link_poses) * shape.X_LS});
  }
  return out;
}

Pose3 RobotModel::CalcLinkPoseInBase(
    std::string_view link_name,
    const std::vector<std::pair<std::string, double>>& joint_positions) const {
  const auto q = impl_->JointMap(joint_positions);
  return impl_->LinkPoseInBase(link_name, q);
}

}  // namespace egress
