#pragma once
/// @file
/// ReadTextFile: the one way egress reads a document the user names (a world, a scenario, a
/// building, a robot model): only a regular file, and only up to a size cap, so that a path to
/// a FIFO, a device (`/dev/zero`) or a huge file is a clear error instead of an unbounded read.

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

namespace egress {

/// The largest document egress reads [bytes]: far above any world, scenario or URDF (the
/// largest shipped is well under 1 MiB), far below what would exhaust memory.
inline constexpr std::size_t kMaxTextFileBytes = std::size_t{64} << 20;

/// The whole content of `path`. `what` names the document in errors ("world file").
/// @throws LoadError naming the path and `what` if it does not exist, is not a regular file,
/// is larger than `max_bytes` or cannot be read.
std::string ReadTextFile(const std::filesystem::path& path, std::string_view what,
                         std::size_t max_bytes = kMaxTextFileBytes);

/// Whether something exists at `path`; false (not an exception) when the path cannot even be
/// looked at (a name too long, a loop of links): for paths written in a user's document.
bool PathExists(const std::filesystem::path& path);

/// While one is alive on a thread, ReadTextFile on that thread reads only files that resolve
/// (symbolic links and `..` followed) to a place under `root`, and throws PathOutsideRoot for
/// any other. egress-navd holds one around a client's request so that the file the client
/// names and every file that file references (a map's image, a world's meshes) stay under the
/// server's data root. Nests: the innermost root applies.
class ScopedReadRoot {
 public:
  /// @throws LoadError if `root` is not an existing directory.
  explicit ScopedReadRoot(const std::filesystem::path& root);
  ~ScopedReadRoot();
  ScopedReadRoot(const ScopedReadRoot&) = delete;
  ScopedReadRoot& operator=(const ScopedReadRoot&) = delete;

  /// The root in force on this thread, or empty.
  static std::filesystem::path Current();

 private:
  std::filesystem::path previous_;
};

/// `path` resolved (symbolic links, `..`) if it lies under the current ScopedReadRoot, or
/// unchanged when none is in force. @throws PathOutsideRoot otherwise.
std::filesystem::path CheckUnderReadRoot(const std::filesystem::path& path, std::string_view what);

}  // namespace egress
