#pragma once
// NavigationServer: the gRPC service of api/egress/nav/v1/navigation.proto over egress's
// costmap and BasePlanner. Used by egress-navd, by `egress plan` (local mode shares the world
// loading) and by the tests, which start it on a loopback port.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

namespace egress::navd {

struct NavigationServerConfig {
  std::string listen{"127.0.0.1:50051"};  ///< host:port; port 0 picks a free one.
  bool allow_remote{false};               ///< Needed to listen on a non-loopback address.
  std::string token;                      ///< Required with allow_remote; clients send it as
                                          ///< "authorization: Bearer <token>" metadata.
  int max_workers{4};  ///< Concurrent planning requests; more get RESOURCE_EXHAUSTED.
  std::int64_t max_map_cells{16'000'000};  ///< Larger maps are refused (INVALID_ARGUMENT).
  /// One structured line per request (JSON); null for silence.
  std::function<void(const std::string&)> log;
};

/// @throws std::invalid_argument naming the problem: a non-loopback address without
/// allow_remote, or allow_remote without a token.
void ValidateListenAddress(const NavigationServerConfig& config);

class NavigationServer {
 public:
  /// Starts serving. @throws std::invalid_argument (see ValidateListenAddress) or
  /// std::runtime_error if the address cannot be bound.
  explicit NavigationServer(NavigationServerConfig config);
  /// Shuts down (waiting up to 5 s for running requests).
  ~NavigationServer();
  NavigationServer(const NavigationServer&) = delete;
  NavigationServer& operator=(const NavigationServer&) = delete;

  int port() const;
  /// Blocks until Shutdown.
  void Wait();
  /// Stops accepting requests; requests already running finish (or are cancelled after
  /// `grace`), so nothing already answered is lost.
  void Shutdown(std::chrono::milliseconds grace = std::chrono::seconds(5));

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace egress::navd
