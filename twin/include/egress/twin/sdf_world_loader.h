#pragma once
/// @file
/// Reads an SDF world (Gazebo's format, 1.6+) with libsdformat into a WorldDescription.
///
/// - Static models (or models fixed to the world) contribute their collision shapes: box,
///   cylinder, sphere, plane and mesh (STL, OBJ, DAE through assimp; URIs relative to the
///   world file, `file://` or `model://` under the world file's folder or GZ_SIM_RESOURCE_PATH).
/// - A model with a revolute joint between a frame link and a leaf link is a hinged door; the
///   hinge side, limits and leaf size come from the file.
/// - Plugins and sensors are not simulated; each one adds a line to WorldDescription::notes.

#include <filesystem>
#include <string>
#include <string_view>

#include "egress/twin/world_description.h"

namespace egress::twin {

/// Loads the first world of an SDF file. @throws LoadError naming the file and line for a
/// missing file, malformed XML/SDF, an unreadable mesh or a door the twin cannot model.
WorldDescription LoadSdfWorld(const std::filesystem::path& path);

/// The same from SDF text; `source_name` labels errors; relative mesh URIs resolve against
/// `base_dir`.
WorldDescription LoadSdfWorldFromString(const std::string& sdf_xml, std::string_view source_name,
                                        const std::filesystem::path& base_dir = {});

/// Loads a triangle mesh (STL, OBJ, DAE, … anything assimp reads), scaled per axis.
/// @throws LoadError naming the file.
TriangleMesh LoadTriangleMesh(const std::filesystem::path& path,
                              const Eigen::Vector3d& scale = Eigen::Vector3d::Ones());

}  // namespace egress::twin
