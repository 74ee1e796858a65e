// egress-navd: the navigation service (gRPC). Loopback only unless --allow-remote with a token.

#include <sys/resource.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <thread>

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include "navigation_server.h"

namespace {
volatile std::sig_atomic_t g_stop = 0;
void OnSignal(int) {
  g_stop = 1;
}
}  // namespace

int main(int argc, char** argv) {
  egress::navd::NavigationServerConfig config;
  std::string token_file;
  CLI::App app{"egress-navd: plans base paths for other programs over gRPC (api/egress/nav/v1)",
               "egress-navd"};
  app.add_option("--listen", config.listen,
                 "host:port to listen on (loopback unless --allow-remote)")
      ->capture_default_str();
  app.add_flag("--allow-remote", config.allow_remote,
               "allow a non-loopback address (needs --token-file)");
  app.add_option("--token-file", token_file, "file holding the token remote clients must send")
      ->check(CLI::ExistingFile);
  app.add_option("--workers", config.max_workers, "concurrent planning requests")
      ->capture_default_str();
  app.add_option("--max-map-cells", config.max_map_cells, "largest map accepted [cells]")
      ->capture_default_str();
  app.add_option("--data-root", config.data_root,
                 "directory request file paths are confined to (default: none, paths refused)")
      ->check(CLI::ExistingDirectory);
  app.add_option("--max-cached-cells", config.max_cached_cells,
                 "world cache cap [cells]; least recently used worlds are evicted past it")
      ->capture_default_str();
  app.add_option("--max-worlds", config.max_worlds, "world cache cap [worlds]")
      ->capture_default_str();
  app.add_option("--max-connections", config.max_connections,
                 "open connections; more are closed on arrival")
      ->capture_default_str();
  app.add_option("--max-streams", config.max_streams_per_connection,
                 "concurrent calls on one connection")
      ->capture_default_str();
  app.add_option("--idle-timeout", config.idle_timeout_s,
                 "close a connection without calls after this long [s]")
      ->capture_default_str();
  app.add_option("--max-time-budget", config.max_time_budget_s,
                 "longest planning time a request may ask for [s]")
      ->capture_default_str();
  app.add_option("--handshake-timeout", config.handshake_timeout_s,
                 "close a connection that does not speak HTTP/2 within this [s]")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (!token_file.empty()) {
    std::ifstream in(token_file);
    std::getline(in, config.token);
    if (config.token.empty()) {
      std::fprintf(stderr, "egress-navd: error: token file '%s' is empty\n", token_file.c_str());
      return 1;
    }
  }
  config.log = [](const std::string& line) { spdlog::info("{}", line); };
  // Each connection is a descriptor: make room for the cap (up to the hard limit).
  if (rlimit limit{}; getrlimit(RLIMIT_NOFILE, &limit) == 0) {
    const rlim_t wanted = rlim_t(config.max_connections) + 256;
    if (limit.rlim_cur < wanted) {
      limit.rlim_cur = std::min(wanted, limit.rlim_max);
      setrlimit(RLIMIT_NOFILE, &limit);
    }
  }
  try {
    egress::navd::NavigationServer server(config);
    spdlog::info("egress-navd listening on {} (port {}, {} workers)", config.listen, server.port(),
                 config.max_workers);
    std::signal(SIGINT, OnSignal);
    std::signal(SIGTERM, OnSignal);
    std::thread waiter([&] { server.Wait(); });
    while (g_stop == 0)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    spdlog::info("egress-navd: shutting down; running requests finish first");
    server.Shutdown();
    waiter.join();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "egress-navd: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
