#pragma once
/// @file
/// Node statuses of BehaviorTree.CPP v4.

#include <optional>
#include <string_view>

namespace egress::bt {

/// Result of ticking a node. SKIPPED is returned only by pre-conditions and by parents whose
/// children were all skipped; it is never a node's own status: a skipped node keeps the status
/// it had (as in BehaviorTree.CPP 4.10).
enum class NodeStatus : unsigned char {
  kIdle = 0,
  kRunning = 1,
  kSuccess = 2,
  kFailure = 3,
  kSkipped = 4
};

/// "IDLE", "RUNNING", "SUCCESS", "FAILURE", "SKIPPED".
std::string_view ToString(NodeStatus status);
/// Parses the names above; nullopt for anything else.
std::optional<NodeStatus> ParseNodeStatus(std::string_view text);
/// True for SUCCESS and FAILURE.
inline bool IsCompleted(NodeStatus s) {
  return s == NodeStatus::kSuccess || s == NodeStatus::kFailure;
}

}  // namespace egress::bt
