#include "egress/bt/loggers.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_paths.h"

#include "egress/bt/factory.h"

namespace egress::bt {
namespace {

using ::testing::HasSubstr;

const char* kTree =
    "<root BTCPP_format='4'><BehaviorTree ID='Main'><Sequence><SubTree ID='Nap' name='nap'/>"
    "<AlwaysSuccess/></Sequence></BehaviorTree><BehaviorTree ID='Nap'><Sleep "
    "msec='100'/></BehaviorTree></root>";

TEST(LoggersTest, ConsoleLoggerPrintsTransitions) {
  BehaviorTreeFactory factory;
  Tree tree = factory.CreateTreeFromText(kTree, "Main");
  auto clock = std::make_shared<ManualClock>();
  tree.SetClock(clock);
  std::ostringstream out;
  {
    ConsoleLogger logger(tree, out);
    tree.TickOnce();
  }
  tree.TickOnce();  // the logger is gone: nothing more is printed
  EXPECT_THAT(out.str(), HasSubstr("[0.000 s] nap/Sleep::3: IDLE -> RUNNING"));
  EXPECT_THAT(out.str(), ::testing::Not(HasSubstr("-> IDLE")));
}

TEST(LoggersTest, TreeObserverCountsPerNode) {
  BehaviorTreeFactory factory;
  Tree tree = factory.CreateTreeFromText(kTree, "Main");
  auto clock = std::make_shared<ManualClock>();
  tree.SetClock(clock);
  TreeObserver observer(tree);
  tree.TickOnce();
  tree.HaltTree();
  const auto& sleep = observer.at("nap/Sleep::3");
  EXPECT_EQ(sleep.starts, 1u);
  EXPECT_EQ(sleep.halts, 1u);
  EXPECT_EQ(sleep.successes, 0u);
  tree.TickOnce();
  clock->Advance(std::chrono::milliseconds(100));
  tree.TickOnce();
  EXPECT_EQ(observer.at("Sequence::1").successes, 1u);
  EXPECT_EQ(observer.at("Sequence::1").last_result, NodeStatus::kSuccess);
}

// Reads back a .btlog: magic, protocol, XML length + XML, start time, 9-byte records.
TEST(LoggersTest, FileLogger2WritesTheDocumentedLayout) {
  BehaviorTreeFactory factory;
  Tree tree = factory.CreateTreeFromText(kTree, "Main");
  auto clock = std::make_shared<ManualClock>();
  tree.SetClock(clock);
  const auto path = egress::testing::TestTempPath("run.btlog");
  {
    FileLogger2 logger(tree, factory, path, 1'700'000'000'000'000);
    tree.TickOnce();
    clock->Advance(std::chrono::milliseconds(100));
    tree.TickOnce();
  }
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::filesystem::remove(path);
  ASSERT_GT(bytes.size(), 30u);
  const auto le = [&](std::size_t at, int n) {
    std::uint64_t v = 0;
    for (int i = n - 1; i >= 0; --i)
      v = (v << 8) | static_cast<unsigned char>(bytes[at + i]);
    return v;
  };
  EXPECT_EQ(bytes.substr(0, 18), "BTCPP4-FileLogger2");
  EXPECT_EQ(bytes[18], 1);
  const std::size_t xml_size = le(19, 4);
  const std::string xml = bytes.substr(23, xml_size);
  EXPECT_THAT(xml, HasSubstr("<BehaviorTree ID=\"Nap\" _fullpath=\"nap\">"));
  EXPECT_THAT(xml, HasSubstr("_uid=\"3\""));
  EXPECT_THAT(xml, HasSubstr("<Action ID=\"Sleep\">"));
  std::size_t at = 23 + xml_size;
  EXPECT_EQ(le(at, 8), 1'700'000'000'000'000u);
  at += 8;
  const std::size_t records = (bytes.size() - at) / 9;
  ASSERT_EQ((bytes.size() - at) % 9, 0u);
  ASSERT_GE(records, 6u);
  // First record: the Sequence (uid 1) starts at offset 0.
  EXPECT_EQ(le(at, 6), 0u);
  EXPECT_EQ(le(at + 6, 2), 1u);
  EXPECT_EQ(le(at + 8, 1), std::uint64_t(NodeStatus::kRunning));
  // Somewhere later: Sleep (uid 3) SUCCESS at +100 ms.
  bool found = false;
  for (std::size_t r = 0; r < records; ++r) {
    const std::size_t p = at + 9 * r;
    if (le(p + 6, 2) == 3 && le(p + 8, 1) == std::uint64_t(NodeStatus::kSuccess)) {
      EXPECT_EQ(le(p, 6), 100'000u);
      found = true;
    }
  }
  EXPECT_TRUE(found);
  EXPECT_THROW(FileLogger2(tree, factory, "/tmp/wrong.log"), LogicError);
}

TEST(LoggersTest, TreeXmlReloads) {
  BehaviorTreeFactory factory;
  Tree tree = factory.CreateTreeFromText(kTree, "Main");
  const std::string xml = WriteTreeToXml(tree, factory);
  BehaviorTreeFactory other;
  other.RegisterTreesFromText(xml, "written.xml");
  EXPECT_THAT(other.RegisteredTreeIds(), ::testing::ElementsAre("Main", "Nap"));
}

}  // namespace
}  // namespace egress::bt
