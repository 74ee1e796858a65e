// Tick-for-tick conformance with BehaviorTree.CPP 4.10: each case under
// tests/behavior/bt/conformance/ is a tree (leaves are stand-ins declared in its
// TreeNodesModel), a trace script of outcomes per tick, and the status-change stream
// BehaviorTree.CPP 4.10.0 itself printed for them (`.btcpp`, written by tools/btcpp_peer). The
// test runs `egress bt trace --format btcpp --ticks N` on the same files and compares line by
// line.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    lines.push_back(line);
  return lines;
}

std::string RunCommand(const std::string& command) {
  std::string output;
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen((command + " 2>&1").c_str(), "r"), pclose);
  if (!pipe) return "popen failed";
  std::array<char, 4096> buffer;
  while (std::size_t n = fread(buffer.data(), 1, buffer.size(), pipe.get()))
    output.append(buffer.data(), n);
  return output;
}

std::vector<std::string> Cases() {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(EGRESS_CONFORMANCE_DIR)) {
    if (entry.path().extension() == ".btcpp") names.push_back(entry.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

class BtConformanceTest : public ::testing::TestWithParam<std::string> {};

TEST_P(BtConformanceTest, StatusStreamEqualsBehaviorTreeCpp) {
  const fs::path dir = EGRESS_CONFORMANCE_DIR;
  const std::string name = GetParam();
  std::ifstream golden_file(dir / (name + ".btcpp"));
  std::stringstream golden_text;
  golden_text << golden_file.rdbuf();
  const std::vector<std::string> expected = Lines(golden_text.str());
  const auto ticks = std::count_if(expected.begin(), expected.end(),
                                   [](const std::string& l) { return l.starts_with("tick "); });
  ASSERT_GT(ticks, 0) << name << ".btcpp has no tick lines";
  const std::string command = std::string(EGRESS_CLI_PATH) + " bt trace " +
                              (dir / (name + ".xml")).string() + " --script " +
                              (dir / (name + ".yaml")).string() + " --format btcpp --ticks " +
                              std::to_string(ticks);
  const std::vector<std::string> actual = Lines(RunCommand(command));
  for (std::size_t i = 0; i < std::max(expected.size(), actual.size()); ++i) {
    const std::string want = i < expected.size() ? expected[i] : "<end>";
    const std::string got = i < actual.size() ? actual[i] : "<end>";
    ASSERT_EQ(got, want) << name << ": line " << i + 1 << " differs from BT.CPP 4.10";
  }
}

INSTANTIATE_TEST_SUITE_P(Cases, BtConformanceTest, ::testing::ValuesIn(Cases()),
                         [](const auto& info) { return info.param; });

}  // namespace
