#pragma once
/// @file
/// Observers of a tree's status changes: a console logger, per-node statistics for tests
/// (like BT.CPP's TreeObserver), and a `.btlog` writer in BT.CPP's FileLogger2 layout so
/// Groot2 can replay a run.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <ostream>
#include <string>
#include <vector>

#include "egress/bt/tree.h"

namespace egress::bt {

class BehaviorTreeFactory;

/// Base of the observers: subscribes on construction, unsubscribes on destruction. The tree
/// must outlive the observer.
class StatusObserver {
 public:
  explicit StatusObserver(Tree& tree, bool include_idle = true);
  virtual ~StatusObserver();
  StatusObserver(const StatusObserver&) = delete;
  StatusObserver& operator=(const StatusObserver&) = delete;

 protected:
  virtual void OnStatusChange(Duration time, const TreeNode& node, NodeStatus previous,
                              NodeStatus status) = 0;

 private:
  Tree& tree_;
  int id_;
};

/// One line per transition: "[1.234 s] path: PREVIOUS -> STATUS".
class ConsoleLogger final : public StatusObserver {
 public:
  ConsoleLogger(Tree& tree, std::ostream& out, bool include_idle = false);

 protected:
  void OnStatusChange(Duration time, const TreeNode& node, NodeStatus previous,
                      NodeStatus status) override;

 private:
  std::ostream& out_;
};

/// Per-node statistics, keyed by instance path (for tests that assert which nodes ran).
class TreeObserver final : public StatusObserver {
 public:
  struct Statistics {
    NodeStatus current_status{NodeStatus::kIdle};
    NodeStatus last_result{NodeStatus::kIdle};  ///< Last SUCCESS/FAILURE.
    std::uint64_t transitions{0};
    std::uint64_t successes{0};
    std::uint64_t failures{0};
    std::uint64_t starts{0};  ///< Transitions into RUNNING.
    std::uint64_t halts{0};   ///< RUNNING -> IDLE (halted while running).
  };
  explicit TreeObserver(Tree& tree);
  /// @throws std::out_of_range for an unknown path.
  const Statistics& at(const std::string& path) const { return statistics_.at(path); }
  const std::map<std::string, Statistics>& statistics() const { return statistics_; }
  /// Every transition seen, in order: (uid, previous, new).
  struct Transition {
    std::uint16_t uid;
    NodeStatus previous;
    NodeStatus status;
  };
  const std::vector<Transition>& transitions() const { return transitions_; }

 protected:
  void OnStatusChange(Duration time, const TreeNode& node, NodeStatus previous,
                      NodeStatus status) override;

 private:
  std::map<std::string, Statistics> statistics_;
  std::vector<Transition> transitions_;
};

/// Writes a `.btlog` file (BT.CPP 4.10 FileLogger2 layout, little-endian):
///   "BTCPP4-FileLogger2" (18 ASCII bytes), protocol byte 1, int32 length of the tree XML,
///   the tree XML (WriteTreeToXml), int64 start time [µs since the Unix epoch], then one 9-byte
///   record per transition (IDLE included): 6-byte offset from the start [µs], uint16 node
///   uid, uint8 status.
/// Records are buffered in memory and written by Flush() and on destruction, so file I/O stays
/// off the tick path. `start_epoch_us` defaults to 0 for reproducible files (a twin run has no
/// wall-clock start); the offsets come from the tree's clock.
class FileLogger2 final : public StatusObserver {
 public:
  static constexpr std::string_view kMagic = "BTCPP4-FileLogger2";
  /// @throws LogicError if the extension is not .btlog or the file cannot be created.
  FileLogger2(Tree& tree, const BehaviorTreeFactory& factory, const std::filesystem::path& path,
              std::int64_t start_epoch_us = 0);
  ~FileLogger2() override;
  void Flush();

 protected:
  void OnStatusChange(Duration time, const TreeNode& node, NodeStatus previous,
                      NodeStatus status) override;

 private:
  std::ofstream file_;
  Duration first_time_;
  std::vector<char> buffer_;
};

}  // namespace egress::bt
