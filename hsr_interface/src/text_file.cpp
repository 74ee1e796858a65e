#include "egress/hsr_interface/text_file.h"

#include <fstream>

#include "egress/hsr_interface/error.h"

namespace egress {

std::string ReadTextFile(const std::filesystem::path& path, std::string_view what,
                         std::size_t max_bytes) {
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
