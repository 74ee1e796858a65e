#pragma once
// ConnectionGate: egress-navd's own TCP listener. It accepts connections and hands them to
// the gRPC server (gRPC's external connection acceptor), refusing any beyond a cap.
// Why not gRPC's listener: in gRPC 1.51 (Debian's) an accept() that fails with EMFILE closes
// the listening socket for good, so one flood of idle connections leaves the server deaf
// after the flood ends. Here a connection beyond the cap is closed at once, a descriptor
// shortage refuses that one connection (a spare descriptor is kept for exactly that), and the
// listener lives on.

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace grpc::experimental {
class ExternalConnectionAcceptor;
}

namespace egress::navd {

/// host and port of "host:port" ("[::1]:50051" too). @throws std::invalid_argument naming the
/// address when the port is missing, not a number or outside 0..65535.
struct HostPort {
  std::string host;
  int port{0};
};
HostPort ParseListenAddress(const std::string& address);

class ConnectionGate {
 public:
  struct Counts {
    std::int64_t accepted{0};  ///< Handed to gRPC.
    std::int64_t refused{0};   ///< Closed at once: over the cap or out of descriptors.
    int live{0};               ///< Handed over and not yet closed by gRPC.
  };

  /// Binds and listens on `address` (port 0: a free one). @throws std::runtime_error naming
  /// the address when it cannot be bound.
  ConnectionGate(const std::string& address, int max_connections);
  ~ConnectionGate();
  ConnectionGate(const ConnectionGate&) = delete;
  ConnectionGate& operator=(const ConnectionGate&) = delete;

  int port() const { return port_; }
  /// Starts accepting; connections go to `acceptor` (which must outlive Stop()).
  void Start(grpc::experimental::ExternalConnectionAcceptor* acceptor);
  /// Stops accepting and closes the listening socket (connections already handed over stay).
  void Stop();
  Counts counts();

 private:
  struct Handed {
    int fd;
    std::uint64_t inode;  // a closed and reused descriptor number has another socket inode
  };
  void Loop(grpc::experimental::ExternalConnectionAcceptor* acceptor);
  int PruneClosed();  // requires mutex_

  int listen_fd_{-1};
  int spare_fd_{-1};
  int port_{0};
  int max_connections_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  std::mutex mutex_;
  std::vector<Handed> handed_;
  Counts counts_;
};

}  // namespace egress::navd
