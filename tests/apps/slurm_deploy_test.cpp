// deploy/slurm against a real single-node Slurm on loopback (deploy/slurm/local-cluster.sh:
// its own munged, slurmctld and slurmd under a scratch directory): a batch split into a job
// array of shards and merged by a dependent job equals the batch run on one machine.
// Skipped (saying why) where slurm-wlm and munge are not installed (`./egress.sh deps-slurm`)
// or the test does not run as root (slurmd needs it).

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace {

int Shell(const std::string& command, std::string* output = nullptr) {
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return -1;
  char buffer[4096];
  std::string text;
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr)
    text += buffer;
  if (output != nullptr) *output = text;
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

nlohmann::json Results(const std::filesystem::path& dir) {
  nlohmann::json j = nlohmann::json::parse(std::ifstream(dir / "batch.json"));
  for (auto& t : j.at("trials"))
    t.erase("wall_time");
  return {{"batch", j.at("batch")}, {"summary", j.at("summary")}, {"trials", j.at("trials")}};
}

class SlurmDeployTest : public ::testing::Test {
 protected:
  void SetUp() override {
    for (const char* tool : {"munged", "mungekey", "slurmctld", "slurmd", "sbatch", "sinfo"}) {
      if (Shell(std::string("command -v ") + tool) != 0)
        GTEST_SKIP() << tool << " is not installed (./egress.sh deps-slurm installs Slurm)";
    }
    if (::geteuid() != 0) GTEST_SKIP() << "slurmd needs root";
    // Short: munge's socket path must fit a sockaddr_un (108 bytes).
    char name[] = "/tmp/egress-slurm-XXXXXX";
    ASSERT_NE(::mkdtemp(name), nullptr);
    dir_ = name;
    std::string output;
    const int code =
        Shell(kScripts + "/local-cluster.sh start " + (dir_ / "cluster").string() + " 2", &output);
    ASSERT_EQ(code, 0) << output;
    started_ = true;
  }
  void TearDown() override {
    if (started_) Shell(kScripts + "/local-cluster.sh stop " + (dir_ / "cluster").string());
    if (!dir_.empty()) std::filesystem::remove_all(dir_);
  }
  const std::string kScripts = std::string(EGRESS_SOURCE_DIR) + "/deploy/slurm";
  std::filesystem::path dir_;
  bool started_{false};
};

TEST_F(SlurmDeployTest, AJobArrayOfShardsMergesToOneMachinesBatch) {
  const std::string scenarios = std::string(EGRESS_SOURCE_DIR) +
                                "/worlds/scenarios/s3_held_door.yaml " + EGRESS_SOURCE_DIR +
                                "/worlds/scenarios/s1_nominal.yaml:2 --trials 4";
  std::string output;
  const int code =
      Shell("SLURM_CONF=" + (dir_ / "cluster" / "slurm.conf").string() + " timeout 120 " +
                kScripts + "/egress-batch.sh --shards 3 --wait --egress " + EGRESS_CLI_PATH +
                " --out " + (dir_ / "out").string() + " -- " + scenarios,
            &output);
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find("shards: job array"), std::string::npos) << output;
  for (int i = 1; i <= 3; ++i)
    EXPECT_TRUE(
        std::filesystem::exists(dir_ / "out" / ("shard-" + std::to_string(i)) / "journal.jsonl"));
  ASSERT_EQ(Shell(std::string(EGRESS_CLI_PATH) + " sim batch " + scenarios + " -q --out " +
                      (dir_ / "one").string(),
                  &output),
            0)
      << output;
  EXPECT_EQ(Results(dir_ / "out" / "merged"), Results(dir_ / "one"));
}

}  // namespace
