// Groot2Publisher over libzmq's C API (BT.CPP 4.10's Groot2 protocol 2; see the header).

#include "egress/bt/groot2_publisher.h"

#include <zmq.h>

#include <atomic>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>
#include <random>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "egress/bt/factory.h"

namespace egress::bt {
namespace {

constexpr std::uint8_t kProtocolId = 2;
constexpr std::size_t kRequestHeaderBytes = 6;  // protocol, type, uint32 request id
constexpr int kPollTimeoutMs = 100;             // how soon the server thread sees a stop
constexpr std::size_t kMaxRecordedTransitions = 1000;

// What Groot2 sends as the request type (first byte after the protocol).
enum RequestType : std::uint8_t {
  kFullTree = 'T',
  kStatus = 'S',
  kBlackboard = 'B',
  kHookInsert = 'I',
  kHookRemove = 'R',
  kBreakpointUnlock = 'U',
  kHooksDump = 'D',
  kRemoveAllHooks = 'A',
  kDisableAllHooks = 'X',
  kToggleRecording = 'r',
  kGetTransitions = 't',
};

// A status as Groot2 reads it: IDLE is sent as 10 + the status it left, so a node just reset
// still shows how it ended.
char WireStatus(NodeStatus previous, NodeStatus status) {
  return status == NodeStatus::kIdle ? char(10 + int(previous)) : char(status);
}

nlohmann::json ValueJson(const Any& value) {
  if (const auto* v = value.Peek<std::int64_t>()) return *v;
  if (const auto* v = value.Peek<double>()) return *v;
  if (const auto* v = value.Peek<bool>()) return *v;
  if (const auto* v = value.Peek<std::string>()) return *v;
  return value.ToString();
}

nlohmann::json BlackboardJson(const Blackboard& blackboard) {
  nlohmann::json out = nlohmann::json::object();
  for (const std::string& key : blackboard.LocalKeys()) {
    const std::optional<Any> value = blackboard.GetAny(key);
    out[key] = value ? ValueJson(*value) : nlohmann::json();
  }
  return out;
}

std::vector<std::string> Split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(separator, start), text.size());
    if (end > start) parts.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  return parts;
}

}  // namespace

struct Groot2Publisher::Impl {
  Tree& tree;
  std::string tree_xml;
  void* context{nullptr};
  void* server{nullptr};
  void* publisher{nullptr};
  std::uint16_t port{0};
  std::array<char, 16> uuid{};
  // Blackboards by the name Groot2 asks for: the main tree's ID, each SubTree's path.
  std::map<std::string, Blackboard::Ptr, std::less<>> blackboards;

  std::mutex mutex;           // guards what the ticking thread writes below
  std::string status_buffer;  // per node: uint16 uid, uint8 status
  bool recording{false};
  Duration recording_start{};
  struct Transition {
    std::int64_t time_us;
    std::uint16_t uid;
    std::uint8_t status;
  };
  std::deque<Transition> transitions;

  int observer{0};
  std::atomic<bool> running{true};
  std::atomic<std::uint64_t> served{0};
  std::thread thread;

  explicit Impl(Tree& t) : tree(t) {}
  ~Impl() {
    if (server) zmq_close(server);
    if (publisher) zmq_close(publisher);
    if (context) zmq_ctx_term(context);
  }

  void OnStatusChange(Duration time, const TreeNode& node, NodeStatus previous, NodeStatus status) {
    std::lock_guard lock(mutex);
    status_buffer[3 * (std::size_t(node.uid()) - 1) + 2] = WireStatus(previous, status);
    if (recording) {
      transitions.push_back(
          {std::chrono::duration_cast<std::chrono::microseconds>(time - recording_start).count(),
           node.uid(), std::uint8_t(status)});
      while (transitions.size() > kMaxRecordedTransitions)
        transitions.pop_front();
    }
  }

  // Binds REP on port and PUB on port + 1; false (sockets unbound) if either is taken.
  bool Bind(const std::string& address, std::uint16_t p) {
    const std::string rep = Cat("tcp://", address, ":", p);
    const std::string pub = Cat("tcp://", address, ":", p + 1);
    if (zmq_bind(server, rep.c_str()) != 0) return false;
    if (zmq_bind(publisher, pub.c_str()) != 0) {
      zmq_unbind(server, rep.c_str());
      return false;
    }
    port = p;
    return true;
  }

  static bool Receive(void* socket, std::vector<std::string>& parts) {
    parts.clear();
    int more = 0;
    do {
      zmq_msg_t message;
      zmq_msg_init(&message);
      if (zmq_msg_recv(&message, socket, 0) < 0) {
        zmq_msg_close(&message);
        return false;
      }
      parts.emplace_back(static_cast<const char*>(zmq_msg_data(&message)), zmq_msg_size(&message));
      more = zmq_msg_more(&message);
      zmq_msg_close(&message);
    } while (more != 0);
    return true;
  }

  static void Send(void* socket, const std::vector<std::string>& parts) {
    for (std::size_t i = 0; i < parts.size(); ++i) {
      const int flags = i + 1 < parts.size() ? ZMQ_SNDMORE : 0;
      if (zmq_send(socket, parts[i].data(), parts[i].size(), flags) < 0) return;
    }
  }

  void Serve() {
    std::vector<std::string> request;
    while (running) {
      zmq_pollitem_t item{server, 0, ZMQ_POLLIN, 0};
      if (zmq_poll(&item, 1, kPollTimeoutMs) <= 0 || (item.revents & ZMQ_POLLIN) == 0) continue;
      if (!Receive(server, request)) continue;
      ++served;
      Send(server, Answer(request));
    }
  }

  std::vector<std::string> Error(const std::string& what) const { return {"error", what}; }

  std::vector<std::string> Answer(const std::vector<std::string>& request) {
    if (request.empty() || request[0].size() != kRequestHeaderBytes)
      return Error("wrong request header");
    const auto type = static_cast<std::uint8_t>(request[0][1]);
    std::string header = request[0];
    header[0] = char(kProtocolId);
    header.append(uuid.data(), uuid.size());
    std::vector<std::string> reply{header};
    switch (type) {
      case kFullTree:
        reply.push_back(tree_xml);
        return reply;
      case kStatus: {
        std::lock_guard lock(mutex);
        reply.push_back(status_buffer);
        return reply;
      }
      case kBlackboard: {
        if (request.size() != 2) return Error("must be 2 parts message");
        nlohmann::json dump = nlohmann::json::object();
        for (const std::string& name : Split(request[1], ';')) {
          if (auto it = blackboards.find(name); it != blackboards.end())
            dump[name] = BlackboardJson(*it->second);
        }
        const std::vector<std::uint8_t> packed = nlohmann::json::to_msgpack(dump);
        reply.emplace_back(packed.begin(), packed.end());
        return reply;
      }
      case kToggleRecording: {
        if (request.size() != 2) return Error("must be 2 parts message");
        std::lock_guard lock(mutex);
        if (request[1] == "start") {
          recording = true;
          recording_start = tree.clock().Now();
          transitions.clear();
          const auto now = std::chrono::duration_cast<std::chrono::microseconds>(
              std::chrono::system_clock::now().time_since_epoch());
          reply.push_back(std::to_string(now.count()));
        } else if (request[1] == "stop") {
          recording = false;
        }
        return reply;
      }
      case kGetTransitions: {
        std::deque<Transition> taken;
        {
          std::lock_guard lock(mutex);
          std::swap(taken, transitions);
        }
        std::string bytes;
        bytes.reserve(9 * taken.size());
        for (const Transition& t : taken) {
          char record[9];
          std::memcpy(record, &t.time_us, 6);  // little-endian: the low 6 bytes
          std::memcpy(record + 6, &t.uid, 2);
          record[8] = char(t.status);
          bytes.append(record, sizeof(record));
        }
        reply.push_back(std::move(bytes));
        return reply;
      }
      case kHooksDump:
        reply.push_back("[]");
        return reply;
      case kRemoveAllHooks:
      case kDisableAllHooks:
        return reply;  // there are none
      case kHookInsert:
      case kHookRemove:
      case kBreakpointUnlock:
        return Error("egress does not support breakpoints or node replacement");
      default:
        return Error("Request not recognized");
    }
  }
};

Groot2Publisher::Groot2Publisher(Tree& tree, const BehaviorTreeFactory& factory,
                                 Groot2Options options)
    : impl_(std::make_unique<Impl>(tree)) {
  Impl& p = *impl_;
  p.tree_xml = WriteTreeToXml(tree, factory);
  p.status_buffer.resize(3 * tree.nodes().size());
  for (const auto& node : tree.nodes()) {
    const std::size_t offset = 3 * (std::size_t(node->uid()) - 1);
    const std::uint16_t uid = node->uid();
    std::memcpy(&p.status_buffer[offset], &uid, 2);
    p.status_buffer[offset + 2] = char(node->status());
    if (node->kind() == NodeKind::kSubTree && !node->children().empty()) {
      const std::string& child = node->children().front()->path();
      p.blackboards[child.substr(0, child.rfind('/'))] =
          node->children().front()->config().blackboard;
    }
  }
  p.blackboards[tree.main_tree_id()] = tree.root_blackboard();
  std::random_device random;
  for (std::size_t i = 0; i < p.uuid.size(); i += 4) {
    const std::uint32_t word = random();
    std::memcpy(&p.uuid[i], &word, 4);
  }

  p.context = zmq_ctx_new();
  p.server = zmq_socket(p.context, ZMQ_REP);
  p.publisher = zmq_socket(p.context, ZMQ_PUB);
  if (p.context == nullptr || p.server == nullptr || p.publisher == nullptr)
    throw RuntimeError(
        Cat("Groot2 publisher: cannot create ZeroMQ sockets: ", zmq_strerror(errno)));
  const int linger = 0;
  zmq_setsockopt(p.server, ZMQ_LINGER, &linger, sizeof(linger));
  zmq_setsockopt(p.publisher, ZMQ_LINGER, &linger, sizeof(linger));
  const int send_timeout_ms = 1000;  // a client that went away must not block the server
  zmq_setsockopt(p.server, ZMQ_SNDTIMEO, &send_timeout_ms, sizeof(send_timeout_ms));
  bool bound = false;
  if (options.port != 0) {
    bound = p.Bind(options.bind_address, options.port);
  } else {
    for (unsigned port = 1667; !bound && port < 65534; port += 2)
      bound = p.Bind(options.bind_address, std::uint16_t(port));
  }
  if (!bound) {
    throw RuntimeError(Cat("Groot2 publisher: cannot bind tcp://", options.bind_address, ":",
                           options.port, " and :", options.port + 1, ": ", zmq_strerror(errno),
                           " (another run serving Groot2 there? pick another --groot2 port)"));
  }
  p.observer = tree.AddStatusObserver(
      [&p](Duration time, const TreeNode& node, NodeStatus previous, NodeStatus status) {
        p.OnStatusChange(time, node, previous, status);
      });
  p.thread = std::thread([&p] { p.Serve(); });
}

Groot2Publisher::~Groot2Publisher() {
  impl_->tree.RemoveStatusObserver(impl_->observer);
  impl_->running = false;
  if (impl_->thread.joinable()) impl_->thread.join();
}

std::string ZeroMqVersion() {
  int major = 0, minor = 0, patch = 0;
  zmq_version(&major, &minor, &patch);
  return Cat(major, ".", minor, ".", patch);
}

std::uint16_t Groot2Publisher::port() const {
  return impl_->port;
}
std::uint64_t Groot2Publisher::requests_served() const {
  return impl_->served;
}

}  // namespace egress::bt
