#include "egress/twin/trace.h"

#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"
#include "test_paths.h"
#include "twin_test_util.h"

namespace egress::twin {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

TEST(TraceRecorderTest, HeaderCarriesTheFloorPlanAndSamplesComeAtTheRate) {
  const Scenario s = LoadScenario(testing::WorldsDir() / "lab/lab_hold_door.yaml");
  TwinWorld world(s, LoadSdfWorld(s.world_file), 1, testing::Hsr());
  TraceRecorder trace(20.0);
  trace.Observe(world);
  while (world.time() < 4.0) {
    world.Step();
    trace.Observe(world);
  }
  EXPECT_EQ(trace.sample_count(), 81u);  // t = 0, 0.05, ..., 4.0
  const std::string text = trace.ToJsonLines();
  const std::string header = text.substr(0, text.find('\n'));
  EXPECT_THAT(header, StartsWith("{\"scenario\":\"lab held door\",\"seed\":1,\"rate_hz\":20.00"));
  EXPECT_THAT(header, HasSubstr("\"doors\":[{\"name\":\"lab_door\",\"hinge\":[0.4750,3.0000]"));
  EXPECT_THAT(header, HasSubstr("\"people\":[\"holder\"]"));
  EXPECT_THAT(text, HasSubstr("{\"t\":1.000,\"kind\":\"person_started\",\"subject\":\"holder\""));
  // Every event appears exactly once.
  std::size_t count = 0;
  for (std::size_t p = text.find("person_started"); p != std::string::npos;
       p = text.find("person_started", p + 1))
    ++count;
  EXPECT_EQ(count, 1u);
  const auto path = egress::testing::TestTempPath("trace.jsonl");
  trace.Write(path);
  std::ifstream in(path);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), text);
  std::filesystem::remove(path);
  EXPECT_THROW(trace.Write("/nonexistent/dir/trace.jsonl"), LoadError);
  EXPECT_THROW(TraceRecorder(0.0), InvalidArgument);
}

TEST(TraceRecorderTest, JsonEscapeHandlesQuotesAndControlCharacters) {
  EXPECT_EQ(JsonEscape("a\"b\\c\nd\te\x01"), "a\\\"b\\\\c\\nd\\te\\u0001");
}

}  // namespace
}  // namespace egress::twin
