// Groot2Publisher: a client speaking Groot2's protocol (ZeroMQ REQ over loopback) asks for the
// tree, the statuses and the blackboards of a tree being ticked, as Groot2 does.

#include "egress/bt/groot2_publisher.h"

#include <zmq.h>

#include <cstring>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "egress/bt/factory.h"
#include "test_nodes.h"

namespace egress::bt {
namespace {

using ::testing::HasSubstr;

/// Groot2's side: one REQ socket.
class Groot2Client {
 public:
  explicit Groot2Client(std::uint16_t port) {
    context_ = zmq_ctx_new();
    socket_ = zmq_socket(context_, ZMQ_REQ);
    const int linger = 0, timeout_ms = 5000;
    zmq_setsockopt(socket_, ZMQ_LINGER, &linger, sizeof(linger));
    zmq_setsockopt(socket_, ZMQ_RCVTIMEO, &timeout_ms, sizeof(timeout_ms));
    zmq_connect(socket_, ("tcp://127.0.0.1:" + std::to_string(port)).c_str());
  }
  ~Groot2Client() {
    zmq_close(socket_);
    zmq_ctx_term(context_);
  }

  /// Sends a request of `type` (with `body` as a second part if not empty); returns the reply's
  /// parts, the header's request id checked against the one sent.
  std::vector<std::string> Request(char type, const std::string& body = {},
                                   std::uint32_t id = 0x12345678) {
    std::string header(6, '\0');
    header[0] = 2;  // protocol
    header[1] = type;
    std::memcpy(&header[2], &id, 4);
    zmq_send(socket_, header.data(), header.size(), body.empty() ? 0 : ZMQ_SNDMORE);
    if (!body.empty()) zmq_send(socket_, body.data(), body.size(), 0);
    std::vector<std::string> parts;
    int more = 0;
    do {
      zmq_msg_t message;
      zmq_msg_init(&message);
      if (zmq_msg_recv(&message, socket_, 0) < 0) {
        zmq_msg_close(&message);
        ADD_FAILURE() << "no reply to '" << type << "'";
        return parts;
      }
      parts.emplace_back(static_cast<const char*>(zmq_msg_data(&message)), zmq_msg_size(&message));
      more = zmq_msg_more(&message);
      zmq_msg_close(&message);
    } while (more != 0);
    if (!parts.empty() && parts[0] != "error") {
      EXPECT_EQ(parts[0].size(), 22u);  // 6-byte request header + 16-byte tree UUID
      EXPECT_EQ(parts[0][0], 2);
      EXPECT_EQ(parts[0][1], type);
      std::uint32_t echoed = 0;
      std::memcpy(&echoed, parts[0].data() + 2, 4);
      EXPECT_EQ(echoed, id);
    }
    return parts;
  }

 private:
  void* context_;
  void* socket_;
};

/// uid -> status byte from a STATUS reply.
std::map<int, int> Statuses(const std::string& buffer) {
  std::map<int, int> out;
  for (std::size_t i = 0; i + 3 <= buffer.size(); i += 3) {
    std::uint16_t uid = 0;
    std::memcpy(&uid, buffer.data() + i, 2);
    out[uid] = static_cast<unsigned char>(buffer[i + 2]);
  }
  return out;
}

class Groot2PublisherTest : public ::testing::Test {
 protected:
  Groot2PublisherTest() {
    testing::RegisterTestNodes(factory, &recorder);
    factory.RegisterTreesFromText(R"(
      <root BTCPP_format="4" main_tree_to_execute="Main">
        <BehaviorTree ID="Main">
          <Sequence>
            <Script code="speed := 0.4; door := 'door_a'"/>
            <SubTree ID="Pass" name="pass_door" target="{door}"/>
          </Sequence>
        </BehaviorTree>
        <BehaviorTree ID="Pass">
          <Async name="traverse"/>
        </BehaviorTree>
      </root>)");
  }
  testing::Recorder recorder;
  BehaviorTreeFactory factory;
};

TEST_F(Groot2PublisherTest, ServesTheTreeItsStatusesAndBlackboardsWhileItRuns) {
  Tree tree = factory.CreateTree();
  Groot2Publisher publisher(tree, factory, {0, "127.0.0.1"});
  ASSERT_GE(publisher.port(), 1667);
  Groot2Client groot(publisher.port());

  // The full tree, with the uids Groot2 maps statuses to.
  const auto full = groot.Request('T');
  ASSERT_EQ(full.size(), 2u);
  EXPECT_THAT(full[1], HasSubstr("<SubTree ID=\"Pass\""));
  EXPECT_THAT(full[1], HasSubstr("_uid=\"4\""));

  // Before the first tick everything is IDLE; after it the action runs.
  auto status = groot.Request('S');
  ASSERT_EQ(status.size(), 2u);
  ASSERT_EQ(status[1].size(), 3 * tree.nodes().size());
  for (const auto& [uid, s] : Statuses(status[1]))
    EXPECT_EQ(s, 0) << "uid " << uid;
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kRunning);
  auto after = Statuses(groot.Request('S')[1]);
  EXPECT_EQ(after.at(1), int(NodeStatus::kRunning));  // Sequence
  EXPECT_EQ(after.at(2), int(NodeStatus::kSuccess));  // Script
  EXPECT_EQ(after.at(4), int(NodeStatus::kRunning));  // traverse
  recorder.results["traverse"].push_back(NodeStatus::kSuccess);
  EXPECT_EQ(tree.TickOnce(), NodeStatus::kSuccess);
  after = Statuses(groot.Request('S')[1]);
  EXPECT_EQ(after.at(1), 10 + int(NodeStatus::kSuccess));  // IDLE, having succeeded

  // Blackboards by the main tree's ID and the SubTree's path, as MessagePack.
  const auto boards = groot.Request('B', "Main;pass_door;nonexistent");
  ASSERT_EQ(boards.size(), 2u);
  const nlohmann::json json =
      nlohmann::json::from_msgpack(std::vector<std::uint8_t>(boards[1].begin(), boards[1].end()));
  EXPECT_DOUBLE_EQ(json.at("Main").at("speed").get<double>(), 0.4);
  EXPECT_EQ(json.at("Main").at("door"), "door_a");
  EXPECT_TRUE(json.contains("pass_door"));
  EXPECT_FALSE(json.contains("nonexistent"));
}

TEST_F(Groot2PublisherTest, RecordsTransitionsAndRefusesWhatItDoesNotDo) {
  Tree tree = factory.CreateTree();
  auto clock = std::make_shared<ManualClock>();
  tree.SetClock(clock);
  Groot2Publisher publisher(tree, factory, {0, "127.0.0.1"});
  Groot2Client groot(publisher.port());

  const auto start = groot.Request('r', "start");
  ASSERT_EQ(start.size(), 2u);
  EXPECT_GT(std::stoll(start[1]), 0);  // the wall time the recording started [µs]
  clock->Advance(std::chrono::milliseconds(250));
  tree.TickOnce();
  const auto recorded = groot.Request('t');
  ASSERT_EQ(recorded.size(), 2u);
  ASSERT_EQ(recorded[1].size() % 9, 0u);
  ASSERT_GE(recorded[1].size() / 9, 3u);  // Sequence, Script, SubTree, traverse ...
  std::int64_t time_us = 0;
  std::memcpy(&time_us, recorded[1].data(), 6);
  EXPECT_EQ(time_us, 250'000);  // on the tree's clock, from the start of the recording
  std::uint16_t uid = 0;
  std::memcpy(&uid, recorded[1].data() + 6, 2);
  EXPECT_EQ(uid, 1);
  EXPECT_EQ(recorded[1][8], char(NodeStatus::kRunning));

  // Breakpoints are refused with Groot2's error reply; a bad header too.
  const auto hook = groot.Request('I', R"({"uid": 4, "position": 0})");
  ASSERT_EQ(hook.size(), 2u);
  EXPECT_EQ(hook[0], "error");
  EXPECT_THAT(hook[1], HasSubstr("breakpoints"));
  EXPECT_EQ(groot.Request('D')[1], "[]");
  EXPECT_EQ(groot.Request('?')[0], "error");
  EXPECT_GE(publisher.requests_served(), 5u);
}

TEST_F(Groot2PublisherTest, ATakenPortIsAnErrorNamingIt) {
  Tree tree = factory.CreateTree();
  Groot2Publisher first(tree, factory, {0, "127.0.0.1"});
  try {
    Groot2Publisher second(tree, factory, {first.port(), "127.0.0.1"});
    FAIL() << "bound a port already taken";
  } catch (const RuntimeError& e) {
    EXPECT_THAT(e.what(), HasSubstr(std::to_string(first.port())));
  }
}

}  // namespace
}  // namespace egress::bt
