// The worker pool: results in item order whatever the jobs, a dying worker's item recorded as
// crashed while the others go on, skipped items not run, each result reported as it arrives.

#include "workers.h"

#include <signal.h>
#include <unistd.h>

#include <map>

#include <gtest/gtest.h>

namespace egress::apps {
namespace {

TEST(WorkersTest, ADeadWorkersItemIsCrashedAndTheRestGoOn) {
  for (int jobs : {1, 3}) {
    std::map<std::size_t, nlohmann::json> reported;
    WorkerPoolOptions options;
    options.jobs = jobs;
    options.on_result = [&](std::size_t i, const nlohmann::json& r) { reported[i] = r; };
    const auto results = RunInWorkers(
        8,
        [](std::size_t i) -> nlohmann::json {
          if (i == 2) ::raise(SIGKILL);
          if (i == 5) ::_exit(7);
          if (i == 6) throw std::runtime_error("bad seed");
          return {{"square", i * i}};
        },
        options);
    ASSERT_EQ(results.size(), 8u);
    for (std::size_t i : {0u, 1u, 3u, 4u, 7u})
      EXPECT_EQ(results[i].at("square").get<std::size_t>(), i * i) << "jobs " << jobs;
    EXPECT_EQ(results[2].at("crashed").at("signal").get<int>(), SIGKILL);
    EXPECT_NE(results[2].at("error").get<std::string>().find("worker died: signal 9"),
              std::string::npos);
    EXPECT_EQ(results[5].at("crashed").at("exit_code").get<int>(), 7);
    EXPECT_EQ(results[6].at("error").get<std::string>(), "bad seed");
    EXPECT_FALSE(results[6].contains("crashed"));
    EXPECT_EQ(reported.size(), 8u);
  }
}

TEST(WorkersTest, SkippedItemsAreNotRun) {
  WorkerPoolOptions options;
  options.jobs = 2;
  options.skip = {true, false, true, false};
  const auto results = RunInWorkers(
      4,
      [](std::size_t i) -> nlohmann::json {
        return {{"ran", i}};
      },
      options);
  EXPECT_TRUE(results[0].is_null());
  EXPECT_TRUE(results[2].is_null());
  EXPECT_EQ(results[1].at("ran").get<int>(), 1);
  EXPECT_EQ(results[3].at("ran").get<int>(), 3);
}

}  // namespace
}  // namespace egress::apps
