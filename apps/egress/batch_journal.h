#pragma once
/// @file
/// The journal of a `sim batch` run, DIR/journal.jsonl: its first line is the batch's plan
/// (scenarios with their trial counts, seed base, shard), then one line per finished trial,
/// {"i": work index, "r": trial}, appended and handed to the kernel (fdatasync) as the trial
/// ends. A batch killed at any moment (SIGINT, SIGKILL, a power cut after the sync) keeps every
/// trial that finished; `--resume` reads it back and runs only the others.

#include <cstddef>
#include <filesystem>
#include <map>

#include <nlohmann/json.hpp>

namespace egress::apps {

class BatchJournal {
 public:
  /// Starts a journal at `path` for `plan`. @throws CommandFailed if one exists (unless
  /// `overwrite`) or it cannot be written.
  static BatchJournal Create(const std::filesystem::path& path, const nlohmann::json& plan,
                             bool overwrite);
  /// Continues the journal at `path`: fills `finished` (work index -> trial). A torn last line
  /// (the batch was killed while writing it) is dropped. @throws CommandFailed naming the file
  /// if there is none, it belongs to another plan, or a line other than the last is malformed.
  static BatchJournal Resume(const std::filesystem::path& path, const nlohmann::json& plan,
                             std::map<std::size_t, nlohmann::json>* finished);

  BatchJournal(BatchJournal&& other) noexcept;
  BatchJournal& operator=(BatchJournal&&) = delete;
  ~BatchJournal();

  /// Appends one finished trial and syncs it. @throws CommandFailed if it cannot be written.
  void Append(std::size_t work_index, const nlohmann::json& trial);

 private:
  BatchJournal(std::filesystem::path path, int fd) : path_(std::move(path)), fd_(fd) {}
  void WriteLine(const std::string& line);
  std::filesystem::path path_;
  int fd_{-1};
};

}  // namespace egress::apps
