#include "batch_journal.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <string>

#include <fmt/format.h>

#include "commands.h"

namespace egress::apps {

BatchJournal BatchJournal::Create(const std::filesystem::path& path, const nlohmann::json& plan,
                                  bool overwrite) {
  if (std::filesystem::exists(path) && !overwrite) {
    throw CommandFailed(fmt::format(
        "'{}' exists (a batch ran here): pass --resume to continue it or --overwrite to start "
        "over",
        path.string()));
  }
  if (!path.parent_path().empty()) std::filesystem::create_directories(path.parent_path());
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) {
    throw CommandFailed(fmt::format("cannot write '{}': {}", path.string(), std::strerror(errno)));
  }
  BatchJournal journal(path, fd);
  journal.WriteLine(nlohmann::json{{"plan", plan}}.dump());
  return journal;
}

BatchJournal BatchJournal::Resume(const std::filesystem::path& path, const nlohmann::json& plan,
                                  std::map<std::size_t, nlohmann::json>* finished) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw CommandFailed(fmt::format(
        "--resume: no journal '{}' (was the batch started with this --out?)", path.string()));
  }
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::size_t good_bytes = 0;  // up to the end of the last whole, valid line
  std::size_t at = 0;
  for (int line_number = 1; at < text.size(); ++line_number) {
    const std::size_t newline = text.find('\n', at);
    const bool last = newline == std::string::npos || newline + 1 == text.size();
    const std::string line =
        text.substr(at, newline == std::string::npos ? std::string::npos : newline - at);
    nlohmann::json j;
    try {
      if (newline == std::string::npos) throw std::runtime_error("no newline");  // torn write
      j = nlohmann::json::parse(line);
      if (line_number == 1) {
        if (!j.contains("plan")) throw std::runtime_error("no plan");
      } else if (!j.contains("i") || !j.contains("r")) {
        throw std::runtime_error("not a trial line");
      }
    } catch (const std::exception& e) {
      if (last && line_number > 1) break;  // the batch was killed while writing it: drop it
      throw CommandFailed(
          fmt::format("{}:{}: not a journal line ({})", path.string(), line_number, e.what()));
    }
    if (line_number == 1) {
      if (j.at("plan") != plan) {
        throw CommandFailed(fmt::format(
            "{}: the journal is of another batch (its scenarios, trial counts, seed base or "
            "shard differ: {}); use another --out or --overwrite",
            path.string(), j.at("plan").dump()));
      }
    } else {
      (*finished)[j.at("i").get<std::size_t>()] = j.at("r");
    }
    at = newline + 1;
    good_bytes = at;
  }
  const int fd = ::open(path.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
  if (fd < 0 || ::ftruncate(fd, off_t(good_bytes)) != 0) {
    if (fd >= 0) ::close(fd);
    throw CommandFailed(
        fmt::format("cannot append to '{}': {}", path.string(), std::strerror(errno)));
  }
  return BatchJournal(path, fd);
}

BatchJournal::BatchJournal(BatchJournal&& other) noexcept
    : path_(std::move(other.path_)), fd_(other.fd_) {
  other.fd_ = -1;
}

BatchJournal::~BatchJournal() {
  if (fd_ >= 0) ::close(fd_);
}

void BatchJournal::Append(std::size_t work_index, const nlohmann::json& trial) {
  WriteLine(nlohmann::json{{"i", work_index}, {"r", trial}}.dump());
}

void BatchJournal::WriteLine(const std::string& text) {
  const std::string line = text + "\n";
  std::size_t written = 0;
  while (written < line.size()) {
    const ssize_t n = ::write(fd_, line.data() + written, line.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      throw CommandFailed(
          fmt::format("cannot write '{}': {}", path_.string(), std::strerror(errno)));
    }
    written += std::size_t(n);
  }
  ::fdatasync(fd_);
}

}  // namespace egress::apps
