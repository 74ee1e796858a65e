#pragma once
/// @file
/// Version of egress and of the libraries each module was built against, for `egress
/// --version` and for run records.

#include <string>
#include <vector>

namespace egress {

/// egress's own version ("0.1.0").
const char* Version();
/// Git revision egress was configured from ("unknown" outside a checkout).
const char* GitRevision();

/// A third-party library and the version a module was compiled or linked against.
struct LibraryVersion {
  std::string name;
  std::string version;
};

/// "major.minor.patch".
std::string DottedVersion(int major, int minor, int patch);

/// Libraries behind egress::hsr_interface (Eigen, urdfdom).
std::vector<LibraryVersion> HsrInterfaceLibraryVersions();

}  // namespace egress
