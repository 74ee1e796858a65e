#include "egress/hsr_interface/text_file.h"

#include <fstream>

#include "egress/hsr_interface/error.h"

namespace egress {
namespace {
thread_local std::filesystem::path t_read_root;
}  // namespace

ScopedReadRoot::ScopedReadRoot(const std::filesystem::path& root) : previous_(t_read_root) {
  std::error_code error;
  const auto resolved = std::filesystem::canonical(root, error);
  if (error || !std::filesystem::is_directory(resolved)) {
    throw LoadError(StrCat(root.string(), ": the data root is not an existing directory"));
  }
  t_read_root = resolved;
}

ScopedReadRoot::~ScopedReadRoot() {
  t_read_root = previous_;
}

bool PathExists(const std::filesystem::path& path) {
  std::error_code error;
  return std::filesystem::exists(path, error) && !error;
}

std::filesystem::path ScopedReadRoot::Current() {
  return t_read_root;
}

std::filesystem::path CheckUnderReadRoot(const std::filesystem::path& path, std::string_view what) {
  if (t_read_root.empty()) return path;
  std::error_code error;
  // Relative paths are relative to the root, not to the server's working directory.
  const auto absolute = path.is_absolute() ? path : t_read_root / path;
  const auto resolved = std::filesystem::weakly_canonical(absolute, error);
  const auto relative = resolved.lexically_relative(t_read_root);
  if (error || relative.empty() || *relative.begin() == "..") {
    throw PathOutsideRoot(StrCat("the ", what, " '", path.string(), "' is outside the data root"));
  }
  return resolved;
}

std::string ReadTextFile(const std::filesystem::path& requested, std::string_view what,
                         std::size_t max_bytes) {
  const std::filesystem::path path = CheckUnderReadRoot(requested, what);
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (!std::filesystem::exists(status)) throw LoadError(StrCat(path.string(), ": no such ", what));
  if (!std::filesystem::is_regular_file(status))
    throw LoadError(StrCat(path.string(), ": the ", what, " is not a regular file"));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw LoadError(StrCat(path.string(), ": cannot open the ", what));
  // Read at most one byte past the cap: the size on disk may be stale (a growing file).
  std::string text;
  char buffer[1 << 16];
  while (in && text.size() <= max_bytes) {
    in.read(buffer, sizeof(buffer));
    text.append(buffer, std::size_t(in.gcount()));
  }
  if (text.size() > max_bytes)
    throw LoadError(StrCat(path.string(), ": the ", what, " is larger than ", max_bytes,
                           " bytes, the most egress reads"));
  if (in.bad()) throw LoadError(StrCat(path.string(), ": cannot read the ", what));
  return text;
}

}  // namespace egress
