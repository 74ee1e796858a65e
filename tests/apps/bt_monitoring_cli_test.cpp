// `egress sim run --btlog` and `--groot2`: a twin run's tree, replayable and live. The live
// test plays Groot2: it reads the port from the run's output and asks for the statuses while
// the run goes on (held to real time with --pace).

#include <sys/wait.h>
#include <zmq.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_paths.h"

namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const std::string kScenario = std::string(EGRESS_SOURCE_DIR) + "/worlds/scenarios/s1_nominal.yaml";

int RunEgress(const std::string& arguments, std::string* output) {
  const std::string command = std::string(EGRESS_CLI_PATH) + " " + arguments + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return -1;
  std::array<char, 4096> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr)
    *output += buffer.data();
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(BtMonitoringCliTest, SimRunWritesABtlogWithTheRunsStartTime) {
  const fs::path btlog = egress::testing::TestTempPath("run.btlog");
  const auto before = std::chrono::duration_cast<std::chrono::microseconds>(
                          std::chrono::system_clock::now().time_since_epoch())
                          .count();
  std::string output;
  ASSERT_EQ(RunEgress("sim run " + kScenario + " -q --btlog " + btlog.string(), &output), 0)
      << output;
  std::ifstream in(btlog, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  fs::remove(btlog);
  ASSERT_GT(bytes.size(), 18u + 1 + 4);
  EXPECT_EQ(bytes.substr(0, 18), "BTCPP4-FileLogger2");
  std::int32_t xml_size = 0;
  std::memcpy(&xml_size, bytes.data() + 19, 4);
  ASSERT_GT(xml_size, 0);
  const std::string xml = bytes.substr(23, std::size_t(xml_size));
  EXPECT_THAT(xml, HasSubstr("<BehaviorTree ID=\"GoTo\""));
  EXPECT_THAT(xml, HasSubstr("<TreeNodesModel>"));
  std::int64_t start_us = 0;
  std::memcpy(&start_us, bytes.data() + 23 + xml_size, 8);
  EXPECT_GE(start_us, before);  // a real start time, not 0
  const std::size_t records = bytes.size() - (23 + std::size_t(xml_size) + 8);
  EXPECT_EQ(records % 9, 0u);
  EXPECT_GT(records / 9, 50u);  // a whole mission's transitions
}

TEST(BtMonitoringCliTest, Groot2SeesTheTreeRunningLive) {
  // The run in the background, held to 4x real time for 8 s simulated.
  const std::string command = std::string(EGRESS_CLI_PATH) + " sim run " + kScenario +
                              " --groot2 0 --pace 4 --duration 8 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  int port = 0;
  std::array<char, 4096> line;
  while (port == 0 && std::fgets(line.data(), line.size(), pipe) != nullptr) {
    const std::string text = line.data();
    if (const auto at = text.find("127.0.0.1:"); text.starts_with("groot2") && at != text.npos)
      port = std::stoi(text.substr(at + 10));
  }
  ASSERT_GT(port, 0) << "the run did not say where it serves Groot2";

  void* context = zmq_ctx_new();
  void* socket = zmq_socket(context, ZMQ_REQ);
  const int linger = 0, timeout_ms = 5000;
  zmq_setsockopt(socket, ZMQ_LINGER, &linger, sizeof(linger));
  zmq_setsockopt(socket, ZMQ_RCVTIMEO, &timeout_ms, sizeof(timeout_ms));
  zmq_connect(socket, ("tcp://127.0.0.1:" + std::to_string(port)).c_str());
  // Asks for the statuses until some node is RUNNING (the mission under way).
  bool saw_running = false;
  for (int attempt = 0; attempt < 40 && !saw_running; ++attempt) {
    const char header[6] = {2, 'S', 1, 2, 3, 4};
    zmq_send(socket, header, sizeof(header), 0);
    std::string parts[2];
    for (int i = 0; i < 2; ++i) {
      zmq_msg_t message;
      zmq_msg_init(&message);
      ASSERT_GE(zmq_msg_recv(&message, socket, 0), 0) << "no reply from the run";
      parts[i].assign(static_cast<const char*>(zmq_msg_data(&message)), zmq_msg_size(&message));
      zmq_msg_close(&message);
    }
    ASSERT_EQ(parts[0].size(), 22u);
    ASSERT_EQ(parts[1].size() % 3, 0u);
    for (std::size_t i = 2; i < parts[1].size(); i += 3)
      saw_running = saw_running || parts[1][i] == 1;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  zmq_close(socket);
  zmq_ctx_term(context);
  std::string rest;
  while (std::fgets(line.data(), line.size(), pipe) != nullptr)
    rest += line.data();
  const int status = pclose(pipe);
  EXPECT_TRUE(saw_running);
  // 8 s is short of the mission, so the verdict fails (exit 1); the run itself went through.
  EXPECT_TRUE(WIFEXITED(status)) << rest;
  EXPECT_THAT(rest, HasSubstr("groot2    answered"));
  EXPECT_THAT(rest, HasSubstr("ran       8.0 s simulated"));
}

}  // namespace
