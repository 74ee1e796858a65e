// egress-navd request latency for a typical office plan (room 1 -> room 3 through two doors)
// at 1 and 8 concurrent clients, over loopback with the real gRPC server (8 workers; each
// client plans on its own loaded world, as robots of a fleet would). Prints a table and writes
// navd_bench.json. Run: build/bench/navd_bench [requests_per_client]

#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>

#include <nlohmann/json.hpp>

#include "egress/nav/v1/navigation.grpc.pb.h"
#include "navigation_server.h"

namespace {

namespace v1 = egress::nav::v1;

v1::LoadWorldRequest OfficeRequest() {
  // The office map (worlds/office): the bytes of its PGM image.
  std::ifstream in(std::filesystem::path(EGRESS_OFFICE_MAP).parent_path() / "office.pgm",
                   std::ios::binary);
  const std::string pgm{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  v1::LoadWorldRequest request;
  request.mutable_map()->set_image(pgm);
  request.mutable_map()->set_resolution(0.05);
  for (auto [id, hx, hy, lx, ly] :
       {std::tuple{"A", 5.0, 2.5, 5.0, 3.5}, std::tuple{"B", 9.0, 1.0, 9.0, 2.0}}) {
    auto* door = request.add_doors();
    door->set_id(id);
    door->mutable_hinge()->set_x(hx);
    door->mutable_hinge()->set_y(hy);
    door->mutable_latch()->set_x(lx);
    door->mutable_latch()->set_y(ly);
  }
  return request;
}

// One client: its own channel and world, `n` sequential plans; returns latencies [ms].
std::vector<double> Client(int port, int n, int* failures) {
  auto stub = v1::Navigation::NewStub(
      grpc::CreateChannel("127.0.0.1:" + std::to_string(port), grpc::InsecureChannelCredentials()));
  v1::LoadWorldResponse world;
  {
    grpc::ClientContext context;
    if (!stub->LoadWorld(&context, OfficeRequest(), &world).ok()) return {};
  }
  v1::PlanPathRequest request;
  request.set_world_id(world.world_id());
  request.mutable_start()->set_x(1.5);
  request.mutable_start()->set_y(4.5);
  request.mutable_goal()->set_x(12.5);
  request.mutable_goal()->set_y(1.5);
  std::vector<double> latencies;
  for (int i = 0; i < n; ++i) {
    grpc::ClientContext context;
    v1::PlanPathResponse response;
    const auto t0 = std::chrono::steady_clock::now();
    const grpc::Status status = stub->PlanPath(&context, request, &response);
    latencies.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    if (!status.ok() || response.status() != v1::PLAN_STATUS_SUCCESS) ++*failures;
    if (std::getenv("NAVD_BENCH_VERBOSE") != nullptr && i < 3) {
      std::printf("  server planning time %.2f ms, round trip %.2f ms\n",
                  response.planning_time() * 1000, latencies.back());
    }
  }
  return latencies;
}

}  // namespace

int main(int argc, char** argv) {
  const int per_client = argc > 1 ? std::atoi(argv[1]) : 100;
  egress::navd::NavigationServerConfig config;
  config.listen = "127.0.0.1:0";
  config.max_workers = 8;
  egress::navd::NavigationServer server(config);
  nlohmann::json json = nlohmann::json::array();
  std::printf("%-10s %10s %12s %12s %10s\n", "clients", "requests", "median [ms]", "p99 [ms]",
              "failures");
  for (int clients : {1, 8}) {
    std::vector<std::future<std::vector<double>>> runs;
    std::vector<int> failures(std::size_t(clients), 0);
    for (int c = 0; c < clients; ++c) {
      runs.push_back(std::async(std::launch::async, Client, server.port(), per_client,
                                &failures[std::size_t(c)]));
    }
    std::vector<double> all;
    for (auto& run : runs) {
      const auto latencies = run.get();
      all.insert(all.end(), latencies.begin(), latencies.end());
    }
    std::sort(all.begin(), all.end());
    int failed = 0;
    for (int f : failures)
      failed += f;
    const double median = all[all.size() / 2],
                 p99 = all[std::min(all.size() - 1, all.size() * 99 / 100)];
    std::printf("%-10d %10zu %12.2f %12.2f %10d\n", clients, all.size(), median, p99, failed);
    json.push_back({{"clients", clients},
                    {"requests", all.size()},
                    {"median_ms", median},
                    {"p99_ms", p99},
                    {"failures", failed}});
  }
  std::ofstream("navd_bench.json") << json.dump(2) << "\n";
  return 0;
}
