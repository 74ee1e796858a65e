#pragma once
/// @file
/// Groot2Publisher: serves a running tree to Groot2 over its publisher protocol (BT.CPP 4.10's
/// Groot2Publisher, protocol 2), so Groot2 attaches to a twin run or the robot and shows the
/// tree and its statuses live.
///
/// Two ZeroMQ sockets: a REP server on `port` answering Groot2's requests (full tree XML,
/// statuses of all nodes, blackboards as MessagePack JSON, recording of transitions), and a PUB
/// socket on `port + 1` (Groot2 subscribes; breakpoint notices go there in BT.CPP). Requests are
/// answered on a thread of the publisher's own; statuses are copied into a buffer by the
/// tree's status observer (the ticking thread) under a mutex, and blackboards are read through
/// their own locks. Breakpoints and node replacement (hooks) are refused with an error reply:
/// egress runs are deterministic and a tree is never paused from outside.
///
/// Off unless an application creates one; it binds to the loopback interface unless told
/// otherwise, since anyone who can reach the port can read the blackboards.

#include <cstdint>
#include <memory>
#include <string>

#include "egress/bt/tree.h"

namespace egress::bt {

class BehaviorTreeFactory;

struct Groot2Options {
  /// The server's port; the publisher takes port + 1. 0: the first free pair from 1667 up
  /// (Groot2's default is 1667).
  std::uint16_t port{1667};
  /// The interface to bind: "127.0.0.1" (default: this machine only), "*" (every interface)
  /// or an address of this machine.
  std::string bind_address{"127.0.0.1"};
};

/// The version of the ZeroMQ library the publisher runs on ("4.3.4").
std::string ZeroMqVersion();

class Groot2Publisher {
 public:
  /// Subscribes to `tree` and starts serving. The tree and factory must outlive it.
  /// @throws RuntimeError naming the address when a socket cannot be bound.
  Groot2Publisher(Tree& tree, const BehaviorTreeFactory& factory, Groot2Options options = {});
  ~Groot2Publisher();
  Groot2Publisher(const Groot2Publisher&) = delete;
  Groot2Publisher& operator=(const Groot2Publisher&) = delete;

  /// The server's port (the publisher's is one more).
  std::uint16_t port() const;
  /// Requests answered so far (any type, errors included).
  std::uint64_t requests_served() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace egress::bt
