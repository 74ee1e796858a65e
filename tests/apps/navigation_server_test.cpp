// The navigation service, started for real on a loopback port and called with the generated
// gRPC client.

#include "navigation_server.h"

#include <grpcpp/grpcpp.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <future>
#include <limits>
#include <thread>

#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "egress/nav/v1/navigation.grpc.pb.h"
#include "egress/perception/image_io.h"

namespace egress::navd {
namespace {

namespace v1 = egress::nav::v1;
using ::testing::HasSubstr;

// The office map (worlds/office) as the bytes of its PGM image.
std::string OfficePng() {
  std::ifstream in(std::filesystem::path(EGRESS_OFFICE_MAP).parent_path() / "office.pgm",
                   std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

v1::Pose2 Pose(double x, double y, double yaw = 0.0) {
  v1::Pose2 p;
  p.set_x(x);
  p.set_y(y);
  p.set_yaw(yaw);
  return p;
}

class NavigationServerTest : public ::testing::Test {
 protected:
  void Start(NavigationServerConfig config = {}) {
    config.listen = "127.0.0.1:0";
    server_ = std::make_unique<NavigationServer>(config);
    channel_ = grpc::CreateChannel("127.0.0.1:" + std::to_string(server_->port()),
                                   grpc::InsecureChannelCredentials());
    stub_ = v1::Navigation::NewStub(channel_);
  }
  void SetUp() override { Start(); }

  std::string LoadOffice(const std::string& token = "") {
    v1::LoadWorldRequest request;
    request.mutable_map()->set_image(OfficePng());
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
    grpc::ClientContext context;
    if (!token.empty()) context.AddMetadata("authorization", "Bearer " + token);
    v1::LoadWorldResponse response;
    const grpc::Status status = stub_->LoadWorld(&context, request, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return response.world_id();
  }

  grpc::Status Plan(const std::string& world, v1::Pose2 start, v1::Pose2 goal,
                    v1::PlanPathResponse* response, const std::string& planner = "",
                    double budget = 0.0,
                    std::chrono::milliseconds deadline = std::chrono::seconds(30)) {
    v1::PlanPathRequest request;
    request.set_world_id(world);
    *request.mutable_start() = start;
    *request.mutable_goal() = goal;
    request.set_planner(planner);
    request.set_time_budget(budget);
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + deadline);
    return stub_->PlanPath(&context, request, response);
  }

  std::unique_ptr<NavigationServer> server_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::Navigation::Stub> stub_;
};

TEST_F(NavigationServerTest, PlansThroughAnOpenDoorAndNotThroughAClosedOne) {
  const std::string world = LoadOffice();
  v1::PlanPathResponse response;
  ASSERT_TRUE(Plan(world, Pose(1.5, 4.5), Pose(7.0, 4.5), &response).ok());
  EXPECT_EQ(response.status(), v1::PLAN_STATUS_SUCCESS) << response.message();
  EXPECT_THAT(
      std::vector<std::string>(response.doors_crossed().begin(), response.doors_crossed().end()),
      ::testing::ElementsAre("A"));
  EXPECT_GT(response.length(), 5.0);
  EXPECT_GE(response.path_size(), 2);

  v1::SetDoorStateRequest close;
  close.set_world_id(world);
  close.set_door_id("A");
  close.set_angle(0.0);
  grpc::ClientContext context;
  v1::SetDoorStateResponse ignored;
  ASSERT_TRUE(stub_->SetDoorState(&context, close, &ignored).ok());
  v1::PlanPathResponse blocked;
  ASSERT_TRUE(Plan(world, Pose(1.5, 4.5), Pose(7.0, 4.5), &blocked).ok());
  EXPECT_EQ(blocked.status(), v1::PLAN_STATUS_GOAL_UNREACHABLE);
  EXPECT_THAT(blocked.message(), HasSubstr("closed door"));
  EXPECT_EQ(blocked.path_size(), 0);
}

TEST_F(NavigationServerTest, BadInputsGetClearStatuses) {
  const std::string world = LoadOffice();
  v1::PlanPathResponse response;
  grpc::Status status = Plan(world, Pose(std::nan(""), 1.0), Pose(7.0, 4.5), &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("start"));
  status = Plan(world, Pose(1.5, 4.5), Pose(40.0, 4.5), &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("outside the map"));
  status = Plan("world-999", Pose(1.5, 4.5), Pose(7.0, 4.5), &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
  status = Plan(world, Pose(5.0, 1.0), Pose(7.0, 4.5), &response);  // inside a wall
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  status = Plan(world, Pose(1.5, 4.5), Pose(7.0, 4.5), &response, "AStar");
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("planner"));

  v1::LoadWorldRequest empty;
  empty.mutable_map()->set_resolution(0.05);
  grpc::ClientContext c1;
  v1::LoadWorldResponse loaded;
  status = stub_->LoadWorld(&c1, empty, &loaded);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("map.image is empty"));
  v1::LoadWorldRequest no_source;
  grpc::ClientContext c2;
  EXPECT_EQ(stub_->LoadWorld(&c2, no_source, &loaded).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  v1::SetDoorStateRequest unknown_door;
  unknown_door.set_world_id(world);
  unknown_door.set_door_id("Z");
  grpc::ClientContext c3;
  v1::SetDoorStateResponse ignored;
  EXPECT_EQ(stub_->SetDoorState(&c3, unknown_door, &ignored).error_code(),
            grpc::StatusCode::NOT_FOUND);
  v1::UpdateCostmapRequest bad_scan;
  bad_scan.set_world_id(world);
  bad_scan.mutable_scan()->set_angle_increment(0.0);
  bad_scan.mutable_scan()->set_range_max(5.0);
  bad_scan.mutable_scan()->add_ranges(1.0f);
  grpc::ClientContext c4;
  v1::UpdateCostmapResponse updated;
  status = stub_->UpdateCostmap(&c4, bad_scan, &updated);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("angle_increment"));
}

TEST_F(NavigationServerTest, RefusesMapsBeyondTheCellLimit) {
  server_.reset();
  NavigationServerConfig config;
  config.max_map_cells = 10'000;  // the office is 280 x 120 = 33,600 cells
  Start(config);
  v1::LoadWorldRequest request;
  request.mutable_map()->set_image(OfficePng());
  request.mutable_map()->set_resolution(0.05);
  grpc::ClientContext context;
  v1::LoadWorldResponse response;
  const grpc::Status status = stub_->LoadWorld(&context, request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("280 x 120 cells; the limit is 10000"));
}

TEST_F(NavigationServerTest, AnswersThirtyTwoConcurrentRequests) {
  const std::string world = LoadOffice();
  std::vector<std::future<grpc::Status>> calls;
  for (int i = 0; i < 32; ++i) {
    calls.push_back(std::async(std::launch::async, [&, i] {
      v1::PlanPathResponse response;
      return Plan(world, Pose(1.0 + 0.05 * (i % 8), 4.5), Pose(12.5, 1.5), &response);
    }));
  }
  int ok = 0, exhausted = 0;
  for (auto& call : calls) {
    const grpc::Status status = call.get();  // every request gets an answer
    if (status.ok()) ++ok;
    if (status.error_code() == grpc::StatusCode::RESOURCE_EXHAUSTED) ++exhausted;
  }
  EXPECT_EQ(ok + exhausted, 32);
  EXPECT_GT(ok, 0);
  grpc::ClientContext context;
  v1::HealthResponse health;
  ASSERT_TRUE(stub_->Health(&context, {}, &health).ok());
  EXPECT_EQ(health.busy_workers(), 0);
  EXPECT_EQ(health.max_workers(), 4);
  EXPECT_EQ(health.worlds(), 1);
}

TEST_F(NavigationServerTest, HonoursDeadlines) {
  const std::string world = LoadOffice();
  // An optimizing planner asked for 10 s inside a 300 ms deadline plans within the deadline.
  v1::PlanPathResponse response;
  const grpc::Status status = Plan(world, Pose(1.5, 4.5), Pose(7.0, 4.5), &response, "RRTstar",
                                   10.0, std::chrono::milliseconds(300));
  ASSERT_TRUE(status.ok() || status.error_code() == grpc::StatusCode::DEADLINE_EXCEEDED)
      << status.error_message();
  if (status.ok()) {
    EXPECT_LT(response.planning_time(), 0.3);  // the budget was capped by the deadline
  }
  // A deadline that has already passed is reported as such.
  v1::PlanPathRequest request;
  request.set_world_id(world);
  *request.mutable_start() = Pose(1.5, 4.5);
  *request.mutable_goal() = Pose(7.0, 4.5);
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() - std::chrono::seconds(1));
  EXPECT_EQ(stub_->PlanPath(&context, request, &response).error_code(),
            grpc::StatusCode::DEADLINE_EXCEEDED);
}

TEST_F(NavigationServerTest, ShutdownLosesNothingAlreadyRunning) {
  const std::string world = LoadOffice();
  std::vector<std::future<grpc::Status>> calls;
  for (int i = 0; i < 3; ++i) {
    calls.push_back(std::async(std::launch::async, [&] {
      v1::PlanPathResponse response;
      return Plan(world, Pose(1.5, 4.5), Pose(12.5, 1.5), &response, "RRTstar", 0.5);
    }));
  }
  // Wait until the three are running, then shut down: they still complete.
  for (int i = 0; i < 200; ++i) {
    grpc::ClientContext context;
    v1::HealthResponse health;
    if (stub_->Health(&context, {}, &health).ok() && health.busy_workers() >= 3) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  server_->Shutdown(std::chrono::seconds(10));
  for (auto& call : calls)
    EXPECT_TRUE(call.get().ok());
}

TEST_F(NavigationServerTest, TokensAndListenAddresses) {
  server_.reset();
  NavigationServerConfig config;
  config.allow_remote = true;
  config.token = "s3cret";
  Start(config);
  v1::LoadWorldRequest request;
  request.mutable_map()->set_image(OfficePng());
  request.mutable_map()->set_resolution(0.05);
  grpc::ClientContext context;
  v1::LoadWorldResponse response;
  EXPECT_EQ(stub_->LoadWorld(&context, request, &response).error_code(),
            grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_FALSE(LoadOffice("s3cret").empty());

  NavigationServerConfig remote;
  remote.listen = "0.0.0.0:50051";
  EXPECT_THROW(ValidateListenAddress(remote), std::invalid_argument);
  remote.allow_remote = true;
  EXPECT_THROW(ValidateListenAddress(remote), std::invalid_argument);  // no token
  remote.token = "t";
  EXPECT_NO_THROW(ValidateListenAddress(remote));
  // Ports outside 0..65535 or missing are refused, not replaced by a random one.
  for (const char* listen : {"127.0.0.1:99999", "127.0.0.1:-1", "127.0.0.1", "127.0.0.1:80x"}) {
    NavigationServerConfig bad;
    bad.listen = listen;
    EXPECT_THROW(ValidateListenAddress(bad), std::invalid_argument) << listen;
  }
}

TEST_F(NavigationServerTest, ListsPlanners) {
  grpc::ClientContext context;
  v1::ListPlannersResponse planners;
  ASSERT_TRUE(stub_->ListPlanners(&context, {}, &planners).ok());
  EXPECT_EQ(planners.planners(0), "RRTConnect");
  EXPECT_EQ(planners.planners_size(), 5);
}

TEST_F(NavigationServerTest, LoadsTheOfficeSdfWorldWithItsDoors) {
  server_.reset();
  NavigationServerConfig config;
  const auto worlds = std::filesystem::path(EGRESS_OFFICE_MAP).parent_path().parent_path();
  config.data_root = worlds.string();
  Start(config);
  v1::LoadWorldRequest sdf;
  sdf.set_sdf_path("office/office.sdf");  // relative to the data root
  grpc::ClientContext context;
  v1::LoadWorldResponse loaded;
  const grpc::Status status = stub_->LoadWorld(&context, sdf, &loaded);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(loaded.width(), 280);  // 14 m x 6 m at 5 cm
  EXPECT_EQ(loaded.height(), 120);
  v1::PlanPathResponse response;
  ASSERT_TRUE(Plan(loaded.world_id(), Pose(1.5, 4.5), Pose(12.5, 1.5), &response).ok());
  ASSERT_EQ(response.status(), v1::PLAN_STATUS_SUCCESS) << response.message();
  EXPECT_THAT(
      std::vector<std::string>(response.doors_crossed().begin(), response.doors_crossed().end()),
      ::testing::ElementsAre("door_a", "door_b"));
  // The building's route: both doors, each with where to wait before it, facing it.
  ASSERT_EQ(response.doors_on_route_size(), 2);
  EXPECT_EQ(response.doors_on_route(0).door(), "door_a");
  EXPECT_EQ(response.doors_on_route(1).door(), "door_b");
  EXPECT_NEAR(response.doors_on_route(0).approach().x(), 5.0 - 1.2, 1e-9);  // before x = 5
  EXPECT_NEAR(response.doors_on_route(0).approach().yaw(), 0.0, 1e-9);      // facing east
  EXPECT_FALSE(response.doors_on_route(0).opens_towards_robot());           // it opens east
  EXPECT_GT(response.doors_on_route(1).exit().x(), 9.0);
  // The SDF's door ids work with SetDoorState.
  v1::SetDoorStateRequest close;
  close.set_world_id(loaded.world_id());
  close.set_door_id("door_b");
  close.set_angle(0.0);
  grpc::ClientContext c2;
  v1::SetDoorStateResponse ignored;
  ASSERT_TRUE(stub_->SetDoorState(&c2, close, &ignored).ok());
  v1::PlanPathResponse blocked;
  ASSERT_TRUE(Plan(loaded.world_id(), Pose(1.5, 4.5), Pose(12.5, 1.5), &blocked).ok());
  EXPECT_EQ(blocked.status(), v1::PLAN_STATUS_GOAL_UNREACHABLE);
  // A missing file under the root is INVALID_ARGUMENT naming it; one outside is refused.
  sdf.set_sdf_path("office/missing.sdf");
  grpc::ClientContext c3;
  const grpc::Status missing = stub_->LoadWorld(&c3, sdf, &loaded);
  EXPECT_EQ(missing.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(missing.error_message(), HasSubstr("'office/missing.sdf' does not exist"));
  sdf.set_sdf_path("/nonexistent/office.sdf");
  grpc::ClientContext c3b;
  EXPECT_EQ(stub_->LoadWorld(&c3b, sdf, &loaded).error_code(), grpc::StatusCode::PERMISSION_DENIED);
  sdf.set_sdf_path((worlds / "office" / "office.sdf").string());  // absolute, under the root
  sdf.set_sdf_resolution(0.001);
  grpc::ClientContext c4;
  EXPECT_EQ(stub_->LoadWorld(&c4, sdf, &loaded).error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  // By value: the same world as text; malformed text is INVALID_ARGUMENT naming sdf_text.
  std::ifstream in(std::filesystem::path(EGRESS_OFFICE_MAP).parent_path() / "office.sdf");
  v1::LoadWorldRequest by_value;
  by_value.set_sdf_text(std::string(std::istreambuf_iterator<char>(in), {}));
  grpc::ClientContext c5;
  v1::LoadWorldResponse from_text;
  ASSERT_TRUE(stub_->LoadWorld(&c5, by_value, &from_text).ok());
  EXPECT_EQ(from_text.width(), 280);
  v1::PlanPathResponse through;
  ASSERT_TRUE(Plan(from_text.world_id(), Pose(1.5, 4.5), Pose(12.5, 1.5), &through).ok());
  EXPECT_EQ(through.doors_crossed_size(), 2);
  by_value.set_sdf_text("<sdf version='1.6'><world name='w'>");
  grpc::ClientContext c6;
  const grpc::Status bad = stub_->LoadWorld(&c6, by_value, &from_text);
  EXPECT_EQ(bad.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(bad.error_message(), HasSubstr("sdf_text"));
}

// A scratch directory tree: `root` (the data root) and `outside` next to it.
class DataRootTest : public NavigationServerTest {
 protected:
  void SetUp() override {
    base_ = std::filesystem::temp_directory_path() /
            ("egress_navd_root_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(base_);
    std::filesystem::create_directories(base_ / "root");
    std::filesystem::create_directories(base_ / "outside");
    NavigationServerConfig config;
    config.data_root = (base_ / "root").string();
    Start(config);
  }
  void TearDown() override { std::filesystem::remove_all(base_); }
  void Write(const std::filesystem::path& relative, const std::string& text) {
    std::ofstream(base_ / relative, std::ios::binary) << text;
  }
  grpc::Status LoadPath(const std::string& yaml_or_sdf, bool sdf = false) {
    v1::LoadWorldRequest request;
    if (sdf) {
      request.set_sdf_path(yaml_or_sdf);
    } else {
      request.set_map_yaml_path(yaml_or_sdf);
    }
    grpc::ClientContext context;
    v1::LoadWorldResponse response;
    return stub_->LoadWorld(&context, request, &response);
  }
  std::filesystem::path base_;
};

TEST_F(DataRootTest, PathsStayUnderTheRootWithEveryFileTheyReference) {
  Write("root/map.pgm", OfficePng());
  Write("outside/map.pgm", OfficePng());
  Write("root/ok.yaml", "image: map.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n");
  EXPECT_TRUE(LoadPath("ok.yaml").ok()) << LoadPath("ok.yaml").error_message();
  Write("outside/ok.yaml", "image: map.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n");
  // Outside by '..', by an absolute path, by a symbolic link, and by the image a YAML names.
  std::filesystem::create_symlink(base_ / "outside" / "ok.yaml", base_ / "root" / "link.yaml");
  Write("root/escape.yaml", "image: ../outside/map.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n");
  for (const std::string& path :
       {std::string("../outside/ok.yaml"), (base_ / "outside" / "ok.yaml").string(),
        std::string("link.yaml"), std::string("escape.yaml")}) {
    const grpc::Status status = LoadPath(path);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::PERMISSION_DENIED) << path;
    EXPECT_THAT(status.error_message(), HasSubstr("outside the data root")) << path;
  }
  // An SDF world that <include>s (libsdformat would read the file itself) or names a mesh
  // outside the root.
  Write("root/include.sdf", "<sdf version='1.9'><world name='w'><include><uri>" +
                                (base_ / "outside").string() + "</uri></include></world></sdf>");
  EXPECT_EQ(LoadPath("include.sdf", true).error_code(), grpc::StatusCode::PERMISSION_DENIED);
  Write("outside/box.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  Write("root/mesh.sdf",
        "<sdf version='1.9'><world name='w'><model name='m'><static>true</static><link "
        "name='l'><collision name='c'><geometry><mesh><uri>../outside/box.obj</uri></mesh>"
        "</geometry></collision></link></model></world></sdf>");
  EXPECT_EQ(LoadPath("mesh.sdf", true).error_code(), grpc::StatusCode::PERMISSION_DENIED)
      << LoadPath("mesh.sdf", true).error_message();
}

TEST_F(DataRootTest, AnErrorNamesTheFileAndLineButNeverItsContent) {
  Write("root/secret.yaml", "image: map.pgm\nresolution: 0.05\nSECRET-d41d8cd9 no colon here\n");
  const grpc::Status status = LoadPath("secret.yaml");
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("'secret.yaml' cannot be loaded"));
  EXPECT_THAT(status.error_message(), HasSubstr("line 3"));
  EXPECT_THAT(status.error_message(), ::testing::Not(HasSubstr("SECRET")));
  Write("root/secret.sdf", "<sdf version='1.9'><world name='SECRET-d41d8cd9'><bogus/>");
  const grpc::Status sdf = LoadPath("secret.sdf", true);
  EXPECT_EQ(sdf.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(sdf.error_message(), ::testing::Not(HasSubstr("SECRET")));
}

TEST_F(NavigationServerTest, WithoutADataRootPathsAreRefused) {
  v1::LoadWorldRequest request;
  request.set_map_yaml_path(std::string(EGRESS_OFFICE_MAP));
  grpc::ClientContext context;
  v1::LoadWorldResponse response;
  const grpc::Status status = stub_->LoadWorld(&context, request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_THAT(status.error_message(), HasSubstr("--data-root"));
}

TEST_F(NavigationServerTest, AnImageIsMeasuredBeforeItIsDecoded) {
  server_.reset();
  NavigationServerConfig config;
  config.max_map_cells = 1'000'000;
  Start(config);
  // 4000 x 4000 white: a few kB of PNG, 16 M cells decoded.
  std::vector<std::uint8_t> png;
  ASSERT_TRUE(perception::EncodeImage(".png", cv::Mat(4000, 4000, CV_8UC1, cv::Scalar(255)), &png));
  ASSERT_LT(png.size(), 100'000u);
  v1::LoadWorldRequest request;
  request.mutable_map()->set_image(std::string(png.begin(), png.end()));
  request.mutable_map()->set_resolution(0.05);
  grpc::ClientContext context;
  v1::LoadWorldResponse response;
  const grpc::Status status = stub_->LoadWorld(&context, request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("4000 x 4000 cells; the limit is 1000000"));
  request.mutable_map()->set_image("GIF89a....");
  grpc::ClientContext c2;
  EXPECT_THAT(stub_->LoadWorld(&c2, request, &response).error_message(),
              HasSubstr("not a PGM or PNG"));
}

TEST_F(NavigationServerTest, TheWorldCacheEvictsTheLeastRecentlyUsedAndUnloads) {
  server_.reset();
  NavigationServerConfig config;
  config.max_worlds = 2;
  Start(config);
  const auto health = [&] {
    grpc::ClientContext context;
    v1::HealthResponse response;
    EXPECT_TRUE(stub_->Health(&context, v1::HealthRequest{}, &response).ok());
    return response;
  };
  const std::string a = LoadOffice();
  const std::string b = LoadOffice();
  v1::PlanPathResponse plan;
  ASSERT_TRUE(Plan(a, Pose(1.5, 4.5), Pose(3.5, 4.5), &plan).ok());  // a is now the newer
  const std::string c = LoadOffice();                                // evicts b
  EXPECT_EQ(Plan(b, Pose(1.5, 4.5), Pose(3.5, 4.5), &plan).error_code(),
            grpc::StatusCode::NOT_FOUND);
  EXPECT_TRUE(Plan(a, Pose(1.5, 4.5), Pose(3.5, 4.5), &plan).ok());
  EXPECT_EQ(health().worlds(), 2);
  EXPECT_EQ(health().worlds_evicted(), 1);
  EXPECT_EQ(health().cached_cells(), 2 * 280 * 120);
  v1::UnloadWorldRequest unload;
  unload.set_world_id(a);
  v1::UnloadWorldResponse unloaded;
  grpc::ClientContext c1;
  EXPECT_TRUE(stub_->UnloadWorld(&c1, unload, &unloaded).ok());
  grpc::ClientContext c2;
  EXPECT_EQ(stub_->UnloadWorld(&c2, unload, &unloaded).error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(Plan(a, Pose(1.5, 4.5), Pose(3.5, 4.5), &plan).error_code(),
            grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(health().worlds(), 1);
  EXPECT_EQ(health().cached_cells(), 280 * 120);
}

}  // namespace
}  // namespace egress::navd
