#include "egress/bt/loggers.h"

#include <cstdio>

#include "egress/bt/factory.h"

namespace egress::bt {

StatusObserver::StatusObserver(Tree& tree, bool include_idle) : tree_(tree) {
  id_ = tree.AddStatusObserver(
      [this, include_idle](Duration t, const TreeNode& n, NodeStatus p, NodeStatus s) {
        if (include_idle || s != NodeStatus::kIdle) OnStatusChange(t, n, p, s);
      });
}

StatusObserver::~StatusObserver() {
  tree_.RemoveStatusObserver(id_);
}

ConsoleLogger::ConsoleLogger(Tree& tree, std::ostream& out, bool include_idle)
    : StatusObserver(tree, include_idle), out_(out) {}

void ConsoleLogger::OnStatusChange(Duration time, const TreeNode& node, NodeStatus previous,
                                   NodeStatus status) {
  char stamp[32];
  std::snprintf(stamp, sizeof(stamp), "[%.3f s]", std::chrono::duration<double>(time).count());
  out_ << stamp << " " << node.path() << ": " << ToString(previous) << " -> " << ToString(status)
       << "\n";
}

TreeObserver::TreeObserver(Tree& tree) : StatusObserver(tree, true) {
  for (const auto& node : tree.nodes())
    statistics_[node->path()];
}

void TreeObserver::OnStatusChange(Duration, const TreeNode& node, NodeStatus previous,
                                  NodeStatus status) {
  Statistics& s = statistics_[node.path()];
  s.current_status = status;
  ++s.transitions;
  if (status == NodeStatus::kSuccess) ++s.successes;
  if (status == NodeStatus::kFailure) ++s.failures;
  if (IsCompleted(status)) s.last_result = status;
  if (status == NodeStatus::kRunning) ++s.starts;
  if (previous == NodeStatus::kRunning && status == NodeStatus::kIdle) ++s.halts;
  transitions_.push_back({node.uid(), previous, status});
}

namespace {
template <typename T>
void PutLittleEndian(std::vector<char>& out, T value, int bytes = sizeof(T)) {
  const auto bits = static_cast<std::uint64_t>(value);
  for (int i = 0; i < bytes; ++i)
    out.push_back(static_cast<char>((bits >> (8 * i)) & 0xFF));
}
}  // namespace

FileLogger2::FileLogger2(Tree& tree, const BehaviorTreeFactory& factory,
                         const std::filesystem::path& path, std::int64_t start_epoch_us)
    : StatusObserver(tree, true), first_time_(tree.clock().Now()) {
  if (path.extension() != ".btlog") {
    throw LogicError(
        Cat("FileLogger2: '", path.string(), "' must have the extension .btlog (Groot2 needs it)"));
  }
  file_.open(path, std::ios::binary | std::ios::trunc);
  if (!file_) throw LogicError(Cat("FileLogger2: cannot create '", path.string(), "'"));
  const std::string xml = WriteTreeToXml(tree, factory);
  std::vector<char> header(kMagic.begin(), kMagic.end());
  header.push_back(1);  // protocol
  PutLittleEndian(header, static_cast<std::int32_t>(xml.size()));
  header.insert(header.end(), xml.begin(), xml.end());
  PutLittleEndian(header, start_epoch_us);
  file_.write(header.data(), std::streamsize(header.size()));
}

FileLogger2::~FileLogger2() {
  Flush();
}

void FileLogger2::Flush() {
  if (!buffer_.empty()) {
    file_.write(buffer_.data(), std::streamsize(buffer_.size()));
    buffer_.clear();
  }
  file_.flush();
}

void FileLogger2::OnStatusChange(Duration time, const TreeNode& node, NodeStatus,
                                 NodeStatus status) {
  const auto offset_us =
      std::chrono::duration_cast<std::chrono::microseconds>(time - first_time_).count();
  PutLittleEndian(buffer_, offset_us < 0 ? 0 : offset_us, 6);
  PutLittleEndian(buffer_, node.uid());
  PutLittleEndian(buffer_, static_cast<std::uint8_t>(status));
}

}  // namespace egress::bt
