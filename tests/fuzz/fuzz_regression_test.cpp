// Every input the fuzzers (or probing) found that once crashed, hung or ran without bound, kept
// in fuzz/regressions/<target>/, and the project's own files the fuzzers start from, run
// through the same entry functions as the libFuzzer programs: here in the ordinary build and
// under ASan + UBSan, where a crash, an escaped exception or a leak fails the test.

#include <filesystem>
#include <fstream>
#include <iterator>
#include <ostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fuzz_targets.h"

namespace egress::fuzz {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = EGRESS_SOURCE_DIR;

std::vector<fs::path> FilesIn(const fs::path& dir, const std::string& extension = "") {
  std::vector<fs::path> files;
  if (!fs::is_directory(dir)) return files;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (entry.is_regular_file() && (extension.empty() || entry.path().extension() == extension))
      files.push_back(entry.path());
  }
  return files;
}

// The seeds of a target's corpus: what `./egress.sh fuzz` starts from (keep the two in step).
std::vector<fs::path> Seeds(std::string_view target) {
  if (target == "bt_script") return FilesIn(kSource / "fuzz/seeds/bt_script");
  if (target == "bt_xml") return FilesIn(kSource / "behavior/trees", ".xml");
  if (target == "scenario_yaml") return FilesIn(kSource / "worlds/scenarios", ".yaml");
  if (target == "sdf_world") return FilesIn(kSource / "worlds", ".sdf");
  if (target == "urdf") return FilesIn(kSource / "hsr_interface/models", ".urdf");
  if (target == "map_server") return FilesIn(kSource / "fuzz/seeds/map_server");
  if (target == "navd_requests") return FilesIn(kSource / "fuzz/seeds/navd_requests");
  return {};
}

std::string Read(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class FuzzRegressionTest : public ::testing::TestWithParam<NamedTarget> {};

}  // namespace

// The target's name in test listings, not gtest's byte dump.
void PrintTo(const NamedTarget& target, std::ostream* out) {
  *out << target.name;
}

namespace {

TEST_P(FuzzRegressionTest, KeptInputsAndSeedsRunCleanly) {
  const NamedTarget target = GetParam();
  const auto regressions = FilesIn(kSource / "fuzz/regressions" / std::string(target.name));
  const auto seeds = Seeds(target.name);
  EXPECT_FALSE(regressions.empty()) << target.name << ": no kept inputs";
  EXPECT_FALSE(seeds.empty()) << target.name << ": no seeds";
  for (const auto& files : {regressions, seeds}) {
    for (const fs::path& file : files) {
      SCOPED_TRACE(file.string());
      const std::string bytes = Read(file);
      EXPECT_EQ(target.run(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()), 0);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(AllTargets, FuzzRegressionTest, ::testing::ValuesIn(AllTargets()),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace egress::fuzz
