// The batch journal: appended trials read back on resume; a torn last line dropped (and cut
// from the file before appending); another batch's journal and a corrupt line refused by name.

#include "batch_journal.h"

#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "commands.h"
#include "test_paths.h"

namespace egress::apps {
namespace {

using ::testing::HasSubstr;

std::string Read(const std::filesystem::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(BatchJournalTest, ResumeReadsWhatFinishedAndDropsATornLine) {
  const auto path = egress::testing::TestTempPath("journal.jsonl");
  const nlohmann::json plan = {{"seed_base", 1}, {"shard", {1, 1}}};
  {
    BatchJournal journal = BatchJournal::Create(path, plan, false);
    journal.Append(0, {{"seed", 1}});
    journal.Append(3, {{"seed", 4}});
  }
  EXPECT_THROW(BatchJournal::Create(path, plan, false), CommandFailed);  // never overwritten
  std::ofstream(path, std::ios::app) << R"({"i": 5, "r": {"se)";         // killed mid-write
  std::map<std::size_t, nlohmann::json> finished;
  {
    BatchJournal journal = BatchJournal::Resume(path, plan, &finished);
    EXPECT_EQ(finished.size(), 2u);
    EXPECT_EQ(finished.at(3).at("seed").get<int>(), 4);
    journal.Append(5, {{"seed", 6}});
  }
  finished.clear();
  BatchJournal::Resume(path, plan, &finished);
  EXPECT_EQ(finished.size(), 3u);
  EXPECT_THAT(Read(path), ::testing::Not(HasSubstr("\"se{")));
  // Another batch's journal, and a corrupt line that is not the last.
  try {
    BatchJournal::Resume(path, {{"seed_base", 2}, {"shard", {1, 1}}}, &finished);
    FAIL();
  } catch (const CommandFailed& e) {
    EXPECT_THAT(e.what(), HasSubstr("another batch"));
  }
  std::string text = Read(path);
  text.insert(text.find('\n') + 1, "garbage\n");
  std::ofstream(path, std::ios::trunc) << text;
  try {
    BatchJournal::Resume(path, plan, &finished);
    FAIL();
  } catch (const CommandFailed& e) {
    EXPECT_THAT(e.what(), HasSubstr(path.string() + ":2:"));
  }
  std::filesystem::remove(path);
  EXPECT_THROW(BatchJournal::Resume(path, plan, &finished), CommandFailed);
}

}  // namespace
}  // namespace egress::apps
