#include "egress/twin/sdf_world_loader.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <sstream>

#include <ignition/math/Inertial.hh>
#include <sdf/Box.hh>
#include <sdf/Collision.hh>
#include <sdf/Console.hh>
#include <sdf/Cylinder.hh>
#include <sdf/Frame.hh>
#include <sdf/Geometry.hh>
#include <sdf/Joint.hh>
#include <sdf/JointAxis.hh>
#include <sdf/Link.hh>
#include <sdf/Mesh.hh>
#include <sdf/Model.hh>
#include <sdf/Plane.hh>
#include <sdf/Root.hh>
#include <sdf/Sensor.hh>
#include <sdf/Sphere.hh>
#include <sdf/World.hh>

#include "egress/hsr_interface/error.h"
#include "egress/hsr_interface/text_file.h"

namespace egress::twin {
namespace {
// No shape of a building is larger, nor further from its origin, than this [m]: anything past
// it is a typo (or an attack) that would make every map of the world absurd.
constexpr double kMaxShapeExtentM = 1000.0;
}  // namespace

namespace {

namespace fs = std::filesystem;

Pose3 ToPose3(const ignition::math::Pose3d& p) {
  const auto& q = p.Rot();
  return Pose3(Eigen::Quaterniond(q.W(), q.X(), q.Y(), q.Z()).normalized(),
               Eigen::Vector3d(p.Pos().X(), p.Pos().Y(), p.Pos().Z()));
}

Eigen::Vector3d ToEigen(const ignition::math::Vector3d& v) {
  return {v.X(), v.Y(), v.Z()};
}

std::string FormatErrors(const sdf::Errors& errors, std::string_view source) {
  std::ostringstream out;
  for (const auto& e : errors) {
    out << "\n  " << e.FilePath().value_or(std::string(source));
    if (e.LineNumber().has_value()) out << ":" << *e.LineNumber();
    out << ": " << e.Message();
  }
  return out.str();
}

// Resolves a frame's pose relative to its default frame (model in world, link in model,
// collision in link, joint in child link).
template <typename T>
Pose3 ResolvePose(const T& element, std::string_view source, std::string_view what) {
  ignition::math::Pose3d pose;
  const sdf::Errors errors = element.SemanticPose().Resolve(pose);
  if (!errors.empty()) {
    throw LoadError(
        StrCat(source, ": cannot resolve the pose of ", what, FormatErrors(errors, source)));
  }
  return ToPose3(pose);
}

class WorldReader {
 public:
  WorldReader(std::string source, fs::path base_dir)
      : source_(std::move(source)), base_dir_(std::move(base_dir)) {}

  WorldDescription Read(const sdf::Root& root) {
    if (root.WorldCount() == 0) throw LoadError(StrCat(source_, ": the file holds no <world>"));
    const sdf::World& world = *root.WorldByIndex(0);
    out_.name = world.Name();
    NoteUnknownChildren(world.Element(), "world '" + world.Name() + "'");
    for (uint64_t i = 0; i < world.ModelCount(); ++i) {
      ReadModel(*world.ModelByIndex(i), Pose3());
    }
    for (uint64_t i = 0; i < world.FrameCount(); ++i) {
      const sdf::Frame& frame = *world.FrameByIndex(i);
      out_.frames.emplace_back(frame.Name(),
                               ResolvePose(frame, source_, StrCat("frame '", frame.Name(), "'")));
    }
    return std::move(out_);
  }

 private:
  // Plugins and sensors are outside what the twin simulates: one note each.
  void NoteUnknownChildren(const sdf::ElementPtr& element, const std::string& owner) {
    if (!element) return;
    for (auto plugin = element->GetFirstElement(); plugin; plugin = plugin->GetNextElement()) {
      if (plugin->GetName() == "plugin") {
        const std::string name = plugin->Get<std::string>("name");
        const std::string file = plugin->Get<std::string>("filename");
        out_.notes.push_back(StrCat("ignoring plugin '", name, "' (", file, ") of ", owner));
      }
    }
  }

  void ReadModel(const sdf::Model& model, const Pose3& X_WParent) {
    const std::string where = StrCat("model '", model.Name(), "'");
    const Pose3 X_WM = X_WParent * ResolvePose(model, source_, where);
    NoteUnknownChildren(model.Element(), where);
    for (uint64_t i = 0; i < model.ModelCount(); ++i)
      ReadModel(*model.ModelByIndex(i), X_WM);

    const sdf::Joint* hinge = nullptr;
    bool fixed_to_world = false;
    for (uint64_t j = 0; j < model.JointCount(); ++j) {
      const sdf::Joint* joint = model.JointByIndex(j);
      if (joint->Type() == sdf::JointType::REVOLUTE) {
        if (hinge != nullptr) {
          throw LoadError(StrCat(source_, ": ", where, " has more than one revolute joint ('",
                                 hinge->Name(), "', '", joint->Name(),
                                 "'); the twin models a door as one hinge"));
        }
        hinge = joint;
      } else if (joint->Type() == sdf::JointType::FIXED && joint->ParentLinkName() == "world") {
        fixed_to_world = true;
      } else if (joint->Type() != sdf::JointType::FIXED) {
        out_.notes.push_back(StrCat("treating joint '", joint->Name(), "' of ", where,
                                    " as fixed (only revolute door hinges move)"));
      }
    }
    if (!model.Static() && !fixed_to_world && hinge == nullptr && model.LinkCount() > 0) {
      out_.notes.push_back(StrCat(where, " is not static; the twin holds it fixed"));
    }
    for (uint64_t l = 0; l < model.LinkCount(); ++l) {
      const sdf::Link& link = *model.LinkByIndex(l);
      NoteUnknownChildren(link.Element(), StrCat(where, " link '", link.Name(), "'"));
      for (uint64_t s = 0; s < link.SensorCount(); ++s) {
        out_.notes.push_back(StrCat("ignoring sensor '", link.SensorByIndex(s)->Name(), "' of ",
                                    where, " link '", link.Name(), "'"));
      }
      if (hinge != nullptr && link.Name() == hinge->ChildLinkName()) continue;
      const Pose3 X_WL = X_WM * ResolvePose(link, source_, StrCat(where, " link ", link.Name()));
      for (uint64_t c = 0; c < link.CollisionCount(); ++c) {
        const sdf::Collision& col = *link.CollisionByIndex(c);
        ReadShape(model.Name(), link.Name(), col,
                  X_WL * ResolvePose(col, source_, StrCat(where, " collision ", col.Name())));
      }
    }
    if (hinge != nullptr) ReadDoor(model, *hinge, X_WM);
  }

  void ReadDoor(const sdf::Model& model, const sdf::Joint& joint, const Pose3& X_WM) {
    const std::string where = StrCat("door model '", model.Name(), "' joint '", joint.Name(), "'");
    const sdf::Link* leaf = model.LinkByName(joint.ChildLinkName());
    if (leaf == nullptr) {
      throw LoadError(
          StrCat(source_, ": ", where, " has no child link '", joint.ChildLinkName(), "'"));
    }
    const sdf::Collision* box = nullptr;
    for (uint64_t c = 0; c < leaf->CollisionCount(); ++c) {
      const sdf::Collision* col = leaf->CollisionByIndex(c);
      if (col->Geom()->Type() == sdf::GeometryType::BOX) {
        if (box != nullptr) {
          throw LoadError(StrCat(source_, ": ", where, ": the leaf link '", leaf->Name(),
                                 "' has more than one box collision; the twin needs one leaf box"));
        }
        box = col;
      } else {
        throw LoadError(StrCat(source_, ": ", where, ": leaf collision '", col->Name(),
                               "' is not a box; the twin models a door leaf as one box"));
      }
    }
    if (box == nullptr) {
      throw LoadError(StrCat(source_, ": ", where, ": the leaf link '", leaf->Name(),
                             "' has no box collision"));
    }
    const sdf::JointAxis* axis = joint.Axis(0);
    if (axis == nullptr) throw LoadError(StrCat(source_, ": ", where, " has no <axis>"));
    const Pose3 X_WLeaf = X_WM * ResolvePose(*leaf, source_, where + " leaf link");
    const Pose3 X_WJ = X_WLeaf * ResolvePose(joint, source_, where);
    ignition::math::Vector3d xyz = axis->Xyz();
    if (const auto errors = axis->ResolveXyz(xyz); !errors.empty()) {
      throw LoadError(
          StrCat(source_, ": ", where, ": cannot resolve the axis", FormatErrors(errors, source_)));
    }
    DoorDescription door;
    door.name = model.Name();
    door.joint = joint.Name();
    door.p_WH = X_WJ.translation();
    door.axis_W = (X_WJ.rotation() * ToEigen(xyz)).normalized();
    if (std::abs(door.axis_W.z()) < 0.99) {
      throw LoadError(StrCat(source_, ": ", where,
                             ": hinge axis is not vertical; the twin's doors "
                             "swing about z"));
    }
    door.X_WL = X_WLeaf * ResolvePose(*box, source_, where + " leaf collision");
    door.leaf_size = ToEigen(box->Geom()->BoxShape()->Size());
    if (!(door.leaf_size.allFinite() && door.leaf_size.minCoeff() > 0.0 &&
          door.leaf_size.maxCoeff() <= kMaxShapeExtentM))
      throw LoadError(StrCat(source_, ": ", where, ": the leaf's box size must be in (0, ",
                             kMaxShapeExtentM, "] m"));
    const double lower = axis->Lower(), upper = axis->Upper();
    if (!(std::abs(lower) <= 2 * M_PI && std::abs(upper) <= 2 * M_PI)) {
      throw LoadError(StrCat(source_, ": ", where, ": limits [", lower, ", ", upper,
                             "] must be finite angles within +-2 pi rad"));
    }
    if (!(lower <= 0.0 && upper >= 0.0) || lower == upper) {
      throw LoadError(StrCat(source_, ": ", where, ": limits [", lower, ", ", upper,
                             "] must contain the closed position 0"));
    }
    door.open_sign = std::abs(lower) > std::abs(upper) ? -1.0 : 1.0;
    door.max_open_angle = std::min(std::max(std::abs(lower), std::abs(upper)), M_PI);
    door.max_velocity =
        std::isfinite(axis->MaxVelocity()) && axis->MaxVelocity() > 0 ? axis->MaxVelocity() : 0.0;
    door.effort = std::isfinite(axis->Effort()) && axis->Effort() > 0 ? axis->Effort() : 0.0;
    door.damping = axis->Damping();
    door.mass = leaf->Inertial().MassMatrix().Mass();
    if (!(door.mass > 0.0)) door.mass = 1.0;
    if (door.LeafReach() < 0.3) {
      throw LoadError(StrCat(source_, ": ", where, ": the leaf reaches only ", door.LeafReach(),
                             " m from the hinge; is the joint at the leaf's edge?"));
    }
    out_.doors.push_back(std::move(door));
  }

  void ReadShape(const std::string& model, const std::string& link, const sdf::Collision& col,
                 const Pose3& X_WS) {
    ShapeDescription shape;
    shape.model = model;
    shape.link = link;
    shape.collision = col.Name();
    shape.X_WS = X_WS;
    const sdf::Geometry& geom = *col.Geom();
    const std::string where = StrCat("model '", model, "' collision '", col.Name(), "'");
    switch (geom.Type()) {
      case sdf::GeometryType::BOX:
        shape.kind = ShapeKind::kBox;
        shape.box_size = ToEigen(geom.BoxShape()->Size());
        break;
      case sdf::GeometryType::CYLINDER:
        shape.kind = ShapeKind::kCylinder;
        shape.radius = geom.CylinderShape()->Radius();
        shape.length = geom.CylinderShape()->Length();
        break;
      case sdf::GeometryType::SPHERE:
        shape.kind = ShapeKind::kSphere;
        shape.radius = geom.SphereShape()->Radius();
        break;
      case sdf::GeometryType::PLANE: {
        shape.kind = ShapeKind::kPlane;
        const Eigen::Vector3d normal = ToEigen(geom.PlaneShape()->Normal());
        if (!(normal.allFinite() && normal.norm() > 1e-9))
          throw LoadError(StrCat(source_, ": ", where, ": plane normal must be a non-zero vector"));
        const Eigen::Vector3d n = normal.normalized();
        // Frame S with its z axis along the normal.
        const Eigen::Quaterniond q =
            Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), n);
        shape.X_WS = X_WS * Pose3(q, Eigen::Vector3d::Zero());
        shape.plane_size = {geom.PlaneShape()->Size().X(), geom.PlaneShape()->Size().Y()};
        break;
      }
      case sdf::GeometryType::MESH: {
        shape.kind = ShapeKind::kMesh;
        const sdf::Mesh& mesh = *geom.MeshShape();
        const fs::path file = ResolveMeshUri(mesh.Uri(), mesh.FilePath(), where);
        const Eigen::Vector3d scale = ToEigen(mesh.Scale());
        if (!(scale.allFinite() && scale.cwiseAbs().minCoeff() > 0.0 &&
              scale.cwiseAbs().maxCoeff() <= kMaxShapeExtentM))
          throw LoadError(StrCat(source_, ": ", where, ": mesh scale must be finite and non-zero"));
        shape.mesh = std::make_shared<TriangleMesh>(LoadTriangleMesh(file, scale));
        break;
      }
      default:
        out_.notes.push_back(StrCat("ignoring ", where,
                                    ": geometry type not supported (only box, "
                                    "cylinder, sphere, plane, mesh)"));
        return;
    }
    const auto require_size = [&](double value, const char* what) {
      if (!(value > 0.0 && value <= kMaxShapeExtentM))
        throw LoadError(StrCat(source_, ": ", where, ": ", what, " ", value, " must be in (0, ",
                               kMaxShapeExtentM, "] m"));
    };
    switch (shape.kind) {
      case ShapeKind::kBox:
        require_size(shape.box_size.x(), "box size x");
        require_size(shape.box_size.y(), "box size y");
        require_size(shape.box_size.z(), "box size z");
        break;
      case ShapeKind::kCylinder:
        require_size(shape.radius, "cylinder radius");
        require_size(shape.length, "cylinder length");
        break;
      case ShapeKind::kSphere:
        require_size(shape.radius, "sphere radius");
        break;
      case ShapeKind::kPlane:
        if (!(shape.plane_size.allFinite() && shape.plane_size.minCoeff() >= 0.0))
          throw LoadError(StrCat(source_, ": ", where, ": plane size must be finite and >= 0"));
        break;
      case ShapeKind::kMesh:
        break;
    }
    if (!shape.X_WS.translation().allFinite() || !shape.X_WS.rotation().allFinite() ||
        shape.X_WS.translation().cwiseAbs().maxCoeff() > kMaxShapeExtentM)
      throw LoadError(StrCat(source_, ": ", where, ": its pose must be finite and within ",
                             kMaxShapeExtentM, " m of the origin"));
    out_.shapes.push_back(std::move(shape));
  }

  fs::path ResolveMeshUri(const std::string& uri, const std::string& defined_in,
                          const std::string& where) const {
    const fs::path dir = defined_in.empty() ? base_dir_ : fs::path(defined_in).parent_path();
    std::vector<fs::path> candidates;
    std::string rest = uri;
    if (rest.rfind("file://", 0) == 0) {
      rest = rest.substr(7);
      candidates.push_back(fs::path(rest).is_absolute() ? fs::path(rest) : dir / rest);
    } else if (rest.rfind("model://", 0) == 0) {
      rest = rest.substr(8);
      candidates.push_back(dir / rest);
      candidates.push_back(dir / "models" / rest);
      for (const char* var : {"GZ_SIM_RESOURCE_PATH", "IGN_GAZEBO_RESOURCE_PATH"}) {
        if (const char* env = std::getenv(var)) {
          std::stringstream paths(env);
          for (std::string p; std::getline(paths, p, ':');) {
            if (!p.empty()) candidates.push_back(fs::path(p) / rest);
          }
        }
      }
    } else if (rest.find("://") != std::string::npos) {
      throw LoadError(StrCat(source_, ": ", where, ": mesh URI '", uri,
                             "' uses a scheme the twin cannot fetch (use a file path)"));
    } else {
      candidates.push_back(fs::path(rest).is_absolute() ? fs::path(rest) : dir / rest);
    }
    for (const auto& c : candidates) {
      if (PathExists(c)) return c;
    }
    throw LoadError(StrCat(source_, ": ", where, ": mesh '", uri, "' not found (looked at ",
                           candidates.front().string(), ")"));
  }

  std::string source_;
  fs::path base_dir_;
  WorldDescription out_;
};

WorldDescription LoadRoot(const sdf::Root& root, const sdf::Errors& errors,
                          const std::string& source, const fs::path& base_dir) {
  if (!errors.empty()) {
    throw LoadError(StrCat(source, ": not a valid SDF world:", FormatErrors(errors, source)));
  }
  WorldDescription out = WorldReader(source, base_dir).Read(root);
  return out;
}

}  // namespace

WorldDescription LoadSdfWorld(const std::filesystem::path& path) {
  WorldDescription out =
      LoadSdfWorldFromString(ReadTextFile(path, "world file"), path.string(), path.parent_path());
  out.source = path;
  return out;
}

WorldDescription LoadSdfWorldFromString(const std::string& sdf_xml, std::string_view source_name,
                                        const std::filesystem::path& base_dir) {
  // Errors come back as LoadError; libsdformat's own console lines would only repeat them.
  sdf::Console::Instance()->SetQuiet(true);
  // libsdformat reads <include>d files itself, past ReadTextFile: where reads are confined to
  // a root (egress-navd), a world must be self-contained.
  if (!ScopedReadRoot::Current().empty() && sdf_xml.find("<include") != std::string::npos) {
    throw PathOutsideRoot(StrCat(source_name,
                                 ": <include> is not read here (files are confined to the data "
                                 "root); inline the included model"));
  }
  // libsdformat reads a document that is not valid SDF again as URDF, through urdfdom, whose
  // model of a malformed robot (a kinematic cycle, a self-joint) leaks or recurses without end
  // (fuzzer: sdf_world, kept in fuzz/regressions/sdf_world/urdf_*). A world is SDF: a <robot>
  // element, the one urdfdom looks for, is refused before libsdformat sees the text.
  if (const std::size_t at = sdf_xml.find("<robot"); at != std::string::npos) {
    const auto line = 1 + std::count(sdf_xml.begin(), sdf_xml.begin() + std::ptrdiff_t(at), '\n');
    throw LoadError(StrCat(source_name, ":", line,
                           ": a <robot> element (URDF); a world file must be SDF (<sdf><world>)"));
  }
  sdf::Root root;
  const sdf::Errors errors = root.LoadSdfString(sdf_xml);
  WorldDescription out = LoadRoot(root, errors, std::string(source_name), base_dir);
  out.source = std::string(source_name);
  return out;
}

TriangleMesh LoadTriangleMesh(const std::filesystem::path& path, const Eigen::Vector3d& scale) {
  // Read by egress (a regular file, bounded), parsed by assimp from memory: a mesh URI naming a
  // device or a FIFO must not be read without end. Collision needs no materials or textures.
  const std::string bytes = ReadTextFile(path, "mesh file");
  std::string hint = path.extension().string();
  if (!hint.empty()) hint.erase(0, 1);
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFileFromMemory(
      bytes.data(), bytes.size(),
      aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices,
      hint.c_str());
  if (scene == nullptr || scene->mNumMeshes == 0) {
    throw LoadError(StrCat(path.string(), ": cannot read mesh: ", importer.GetErrorString()));
  }
  TriangleMesh mesh;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh& in = *scene->mMeshes[m];
    const int offset = int(mesh.vertices.size());
    for (unsigned v = 0; v < in.mNumVertices; ++v) {
      const aiVector3D& p = in.mVertices[v];
      mesh.vertices.emplace_back(p.x * scale.x(), p.y * scale.y(), p.z * scale.z());
    }
    for (unsigned f = 0; f < in.mNumFaces; ++f) {
      if (in.mFaces[f].mNumIndices != 3) continue;  // points and lines carry no volume
      mesh.triangles.emplace_back(offset + int(in.mFaces[f].mIndices[0]),
                                  offset + int(in.mFaces[f].mIndices[1]),
                                  offset + int(in.mFaces[f].mIndices[2]));
    }
  }
  if (mesh.triangles.empty()) throw LoadError(StrCat(path.string(), ": mesh has no triangles"));
  return mesh;
}

}  // namespace egress::twin
