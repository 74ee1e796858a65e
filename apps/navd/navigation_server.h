#pragma once
// NavigationServer: the gRPC service of api/egress/nav/v1/navigation.proto over egress's
// costmap and BasePlanner. Used by egress-navd, by `egress plan` (local mode shares the world
// loading) and by the tests, which start it on a loopback port.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace egress::navd {

struct NavigationServerConfig {
  std::string listen{"127.0.0.1:50051"};  ///< host:port; port 0 picks a free one.
  bool allow_remote{false};               ///< Needed to listen on a non-loopback address.
  std::string token;                      ///< Required with allow_remote; clients send it as
                                          ///< "authorization: Bearer <token>" metadata.
  int max_workers{4};  ///< Concurrent planning requests; more get RESOURCE_EXHAUSTED.
  std::int64_t max_map_cells{16'000'000};  ///< Larger maps are refused (INVALID_ARGUMENT),
                                           ///< checked on an image's header before decoding.
  /// Directory file paths in requests are confined to (with every file they reference);
  /// empty: paths are refused (PERMISSION_DENIED) and worlds come by value only.
  std::string data_root;
  /// The world cache: loaded worlds past either cap are evicted, least recently used first.
  std::int64_t max_cached_cells{64'000'000};
  int max_worlds{32};
  /// Connections: more than max_connections open at once are closed on arrival; at most
  /// max_streams_per_connection calls run on one connection.
  int max_connections{256};
  int max_streams_per_connection{16};
  double idle_timeout_s{60.0};       ///< A connection with no call for this long is closed.
  double handshake_timeout_s{10.0};  ///< A connection that sends no HTTP/2 preface is closed.
  double keepalive_time_s{30.0};     ///< The server pings an idle connection this often...
  double keepalive_timeout_s{10.0};  ///< ...and closes it when the ping goes unanswered.
  int max_message_bytes{64 << 20};   ///< Largest request accepted [bytes].
  int max_threads{64};               ///< gRPC threads serving calls.
  double max_time_budget_s{30.0};    ///< Longest planning time a request may ask for [s].
  /// One structured line per request (JSON); null for silence.
  std::function<void(const std::string&)> log;
};

/// @throws std::invalid_argument naming the problem: a port outside 0..65535, a non-loopback
/// address without allow_remote, allow_remote without a token, a data root that is not a
/// directory, or a limit out of range.
void ValidateListenAddress(const NavigationServerConfig& config);

/// The service's request handlers called in-process, without the gRPC transport (the fuzz
/// target, tests): the same code a server runs for each call, minus authentication and the
/// log line. Calls may come from several threads, as on a server.
class NavigationHandlers {
 public:
  explicit NavigationHandlers(NavigationServerConfig config);
  ~NavigationHandlers();
  NavigationHandlers(const NavigationHandlers&) = delete;
  NavigationHandlers& operator=(const NavigationHandlers&) = delete;
  /// Calls `rpc` (one of Rpcs()) with a serialized request; returns the gRPC status code (an
  /// unparsable request: INTERNAL, as gRPC answers). @throws std::invalid_argument for an
  /// unknown RPC name.
  int Call(std::string_view rpc, std::string_view request_bytes);
  /// The RPC names of egress.nav.v1.Navigation.
  static const std::vector<std::string>& Rpcs();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

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
