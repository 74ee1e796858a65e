// egress-navd as a process under abuse, bounded in time (~25 s): a flood of idle TCP
// connections past its descriptor limit, a flood of gRPC channels past its connection cap, and
// a mixed load of good and bad requests. Asserts: every request gets a definite answer, the
// server serves during and after each flood, it sheds idle connections, and its RSS stays under
// a cap. Prints the figures (requests, statuses, p99, RSS) as one JSON line.

#include <arpa/inet.h>
#include <fcntl.h>
#include <grpcpp/grpcpp.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "egress/nav/v1/navigation.grpc.pb.h"

namespace {

namespace v1 = egress::nav::v1;
using Clock = std::chrono::steady_clock;

constexpr int kServerDescriptorLimit = 256;  // RLIMIT_NOFILE of the server under test
constexpr int kMaxConnections = 64;
// Far above a healthy server (~110 MB after the soak); a sanitizer build (navd is built like
// this test) holds freed memory in ASan's quarantine and shadow: ~540 MB.
#if defined(__SANITIZE_ADDRESS__)
constexpr std::int64_t kRssCapKb = 1536 * 1024;
#else
constexpr std::int64_t kRssCapKb = 400 * 1024;
#endif

std::int64_t RssKb(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stoll(line.substr(6));
  }
  return -1;
}

// egress-navd started with a small descriptor limit and short timeouts; its port read from
// its first log line; its output drained so it never blocks on a full pipe.
class NavdProcess {
 public:
  NavdProcess() {
    int out[2];
    EXPECT_EQ(pipe(out), 0);
    pid_ = fork();
    if (pid_ == 0) {
      const rlimit limit{kServerDescriptorLimit, kServerDescriptorLimit};
      setrlimit(RLIMIT_NOFILE, &limit);
      dup2(out[1], STDOUT_FILENO);
      dup2(out[1], STDERR_FILENO);
      close(out[0]);
      execl(EGRESS_NAVD_PATH, EGRESS_NAVD_PATH, "--listen", "127.0.0.1:0", "--max-connections",
            std::to_string(kMaxConnections).c_str(), "--handshake-timeout", "1", "--idle-timeout",
            "2", "--workers", "4", "--max-worlds", "4", nullptr);
      _exit(127);
    }
    close(out[1]);
    out_ = out[0];
    std::string text;
    const auto give_up = Clock::now() + std::chrono::seconds(20);
    // "(port N," in the first log line (no std::regex: GCC 12 warns inside it under ASan).
    const auto find_port = [&]() -> int {
      const auto at = text.find("(port ");
      if (at == std::string::npos) return 0;
      const auto comma = text.find(',', at);
      if (comma == std::string::npos) return 0;
      return std::atoi(text.substr(at + 6, comma - at - 6).c_str());
    };
    while (Clock::now() < give_up && find_port() == 0) {
      pollfd p{out_, POLLIN, 0};
      if (poll(&p, 1, 100) <= 0) continue;
      char buffer[4096];
      const ssize_t n = read(out_, buffer, sizeof(buffer));
      if (n <= 0) break;
      text.append(buffer, std::size_t(n));
    }
    port_ = find_port();
    drain_ = std::thread([this] {
      char buffer[4096];
      while (read(out_, buffer, sizeof(buffer)) > 0) {
      }
    });
  }
  ~NavdProcess() {
    if (pid_ > 0 && !stopped_) Stop();
    if (drain_.joinable()) drain_.join();
    close(out_);
  }
  int Stop() {
    kill(pid_, SIGTERM);
    int status = 0;
    waitpid(pid_, &status, 0);
    stopped_ = true;
    return status;
  }
  pid_t pid() const { return pid_; }
  int port() const { return port_; }
  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }

 private:
  pid_t pid_{-1};
  int out_{-1};
  int port_{0};
  bool stopped_{false};
  std::thread drain_;
};

std::unique_ptr<v1::Navigation::Stub> NewStub(const std::string& address, int distinct) {
  grpc::ChannelArguments args;
  args.SetInt("egress.test.channel", distinct);  // a distinct argument: a connection of its own
  return v1::Navigation::NewStub(
      grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), args));
}

// `wait_for_ready`: a channel whose connection was closed (idle) reconnects within the deadline
// instead of failing at once.
grpc::Status Health(v1::Navigation::Stub& stub, v1::HealthResponse* response,
                    std::chrono::milliseconds deadline = std::chrono::seconds(5),
                    bool wait_for_ready = false) {
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + deadline);
  context.set_wait_for_ready(wait_for_ready);
  return stub.Health(&context, v1::HealthRequest{}, response);
}

// Health on a fresh connection, retried for up to `within`: the server serves new clients.
bool ServesNewClients(const std::string& address, int distinct, std::chrono::seconds within) {
  const auto give_up = Clock::now() + within;
  while (Clock::now() < give_up) {
    auto stub = NewStub(address, distinct);
    v1::HealthResponse response;
    if (Health(*stub, &response, std::chrono::seconds(2)).ok()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  return false;
}

std::string OfficePgm() {
  std::ifstream in(std::filesystem::path(EGRESS_OFFICE_MAP).parent_path() / "office.pgm",
                   std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(NavdSoakTest, SurvivesFloodsAndAnswersEveryRequest) {
  // Room in this process for the flood's sockets.
  if (rlimit limit{}; getrlimit(RLIMIT_NOFILE, &limit) == 0) {
    limit.rlim_cur = limit.rlim_max;
    setrlimit(RLIMIT_NOFILE, &limit);
  }
  NavdProcess navd;
  ASSERT_GT(navd.port(), 0) << "egress-navd did not report its port";
  const std::string address = navd.address();
  auto stub = NewStub(address, 0);
  v1::HealthResponse health;
  ASSERT_TRUE(Health(*stub, &health, std::chrono::seconds(10)).ok());
  const std::int64_t rss_start_kb = RssKb(navd.pid());

  // 1. A mixed load: 4 clients for 6 s, good and bad requests, worlds loaded past the cache.
  std::mutex mutex;
  std::map<std::string, int> codes;
  std::vector<double> latencies_ms;
  std::atomic<int> undefined{0};
  const std::string office = OfficePgm();
  const auto load_end = Clock::now() + std::chrono::seconds(6);
  std::vector<std::thread> clients;
  for (int c = 0; c < 4; ++c) {
    clients.emplace_back([&, c] {
      auto client = NewStub(address, 100 + c);
      std::string world;
      for (int i = 0; Clock::now() < load_end; ++i) {
        grpc::ClientContext context;
        context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
        const auto start = Clock::now();
        grpc::Status status;
        const int kind = (i + c) % 5;
        if (kind == 0 || world.empty()) {
          v1::LoadWorldRequest request;
          request.mutable_map()->set_image(office);
          request.mutable_map()->set_resolution(0.05);
          v1::LoadWorldResponse response;
          status = client->LoadWorld(&context, request, &response);
          if (status.ok()) world = response.world_id();
        } else if (kind == 1 || kind == 2) {
          v1::PlanPathRequest request;
          request.set_world_id(world);
          request.mutable_start()->set_x(1.5);
          request.mutable_start()->set_y(kind == 1 ? 4.5 : std::nan(""));
          request.mutable_goal()->set_x(12.5);
          request.mutable_goal()->set_y(1.5);
          request.set_time_budget(0.2);
          v1::PlanPathResponse response;
          status = client->PlanPath(&context, request, &response);
        } else if (kind == 3) {
          v1::UpdateCostmapRequest request;
          request.set_world_id(world);
          request.mutable_scan()->set_angle_increment(-1.0);  // malformed
          v1::UpdateCostmapResponse response;
          status = client->UpdateCostmap(&context, request, &response);
        } else {
          v1::HealthResponse response;
          status = client->Health(&context, v1::HealthRequest{}, &response);
        }
        const double ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
        const auto code = status.error_code();
        // An evicted world is NOT_FOUND (load it again); every other answer is definite too.
        if (code == grpc::StatusCode::NOT_FOUND) world.clear();
        if (code == grpc::StatusCode::UNAVAILABLE || code == grpc::StatusCode::UNKNOWN ||
            code == grpc::StatusCode::INTERNAL || code == grpc::StatusCode::DEADLINE_EXCEEDED) {
          ++undefined;
        }
        std::lock_guard lock(mutex);
        ++codes[std::to_string(int(code))];
        latencies_ms.push_back(ms);
      }
    });
  }
  for (auto& t : clients)
    t.join();
  EXPECT_EQ(undefined.load(), 0) << "requests without a definite answer";

  // 2. Idle TCP connections past the server's descriptor limit, held: an established client
  // (kept busy, so the 2 s idle timeout does not close it) is still served, and new clients
  // are once the flood ends.
  ASSERT_TRUE(Health(*stub, &health, std::chrono::seconds(10), true).ok());
  std::vector<int> flood;
  for (int i = 0; i < kServerDescriptorLimit + 150; ++i) {
    const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(std::uint16_t(navd.port()));
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (fd < 0 || connect(fd, reinterpret_cast<sockaddr*>(&to), sizeof(to)) != 0) {
      if (fd >= 0) close(fd);
      break;
    }
    flood.push_back(fd);
  }
  EXPECT_GT(int(flood.size()), kServerDescriptorLimit);
  for (int k = 0; k < 3; ++k) {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_TRUE(Health(*stub, &health).ok()) << "an established client lost service";
  }
  for (int fd : flood)
    close(fd);
  EXPECT_TRUE(ServesNewClients(address, 1, std::chrono::seconds(10)))
      << "deaf after a connection flood";
  ASSERT_TRUE(Health(*stub, &health, std::chrono::seconds(10), true).ok());
  const std::int64_t refused_by_tcp_flood = health.connections_refused();
  EXPECT_GT(refused_by_tcp_flood, 0);

  // 3. More gRPC channels than the connection cap, then idle: the excess is refused, the rest
  // is shed after the idle timeout (2 s), and the server serves again.
  // (A refused channel is dropped: gRPC would keep reconnecting it, a client's right.)
  std::vector<std::unique_ptr<v1::Navigation::Stub>> channels;
  int refused = 0;
  for (int i = 0; i < 2 * kMaxConnections; ++i) {
    auto channel = NewStub(address, 1000 + i);
    v1::HealthResponse ignored;
    if (Health(*channel, &ignored, std::chrono::seconds(2)).ok()) {
      channels.push_back(std::move(channel));
    } else {
      ++refused;
    }
  }
  EXPECT_GE(refused, kMaxConnections / 2);
  std::this_thread::sleep_for(std::chrono::seconds(4));
  EXPECT_TRUE(ServesNewClients(address, 2, std::chrono::seconds(10)));
  ASSERT_TRUE(Health(*stub, &health, std::chrono::seconds(10), true).ok());
  EXPECT_LE(health.connections(), 4) << "idle connections were not shed";
  EXPECT_LE(health.worlds(), 4);

  const std::int64_t rss_end_kb = RssKb(navd.pid());
  EXPECT_LT(rss_end_kb, kRssCapKb);
  std::sort(latencies_ms.begin(), latencies_ms.end());
  const auto percentile = [&](double q) {
    return latencies_ms.empty() ? 0.0
                                : latencies_ms[std::size_t(q * double(latencies_ms.size() - 1))];
  };
  const nlohmann::json figures{{"requests", latencies_ms.size()},
                               {"status_counts", codes},
                               {"p50_ms", percentile(0.5)},
                               {"p99_ms", percentile(0.99)},
                               {"tcp_flood_connections", flood.size()},
                               {"refused_total", health.connections_refused()},
                               {"grpc_channels_refused", refused},
                               {"rss_start_kb", rss_start_kb},
                               {"rss_end_kb", rss_end_kb},
                               {"rss_cap_kb", kRssCapKb}};
  std::printf("navd soak: %s\n", figures.dump().c_str());
  channels.clear();
  const int exit_status = navd.Stop();
  EXPECT_TRUE(WIFEXITED(exit_status) && WEXITSTATUS(exit_status) == 0) << exit_status;
}

}  // namespace
