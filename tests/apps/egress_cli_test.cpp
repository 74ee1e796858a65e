// Runs the real `egress` program as a user would and checks what it prints and returns.

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace {

using ::testing::HasSubstr;

struct Result {
  int exit_code;
  std::string output;  // stdout and stderr
};

Result RunEgress(const std::string& arguments) {
  const std::string command = std::string(EGRESS_CLI_PATH) + " " + arguments + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return {-1, "popen failed"};
  std::string output;
  std::array<char, 4096> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr)
    output += buffer.data();
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

TEST(EgressCliTest, VersionListsEveryModulesLibraries) {
  const Result result = RunEgress("--version");
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("egress 0.1.0"));
  for (const char* library : {"Eigen", "urdfdom", "Bullet", "sdformat", "assimp", "OpenCV",
                              "OctoMap", "OMPL", "FCL", "tinyxml2", "gRPC"}) {
    EXPECT_THAT(result.output, HasSubstr(library));
  }
  EXPECT_THAT(result.output, HasSubstr("double precision"));
}

TEST(EgressCliTest, ModelFkPrintsPalmPoseAsJson) {
  const Result result = RunEgress("model fk --arm 0 -1.5707963267948966 --json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const auto json = nlohmann::json::parse(result.output);
  const auto xyz = json.at("X_MG").at("xyz");
  EXPECT_NEAR(xyz[0].get<double>(), 0.627, 1e-3);
  EXPECT_NEAR(xyz[1].get<double>(), 0.078, 1e-3);
  EXPECT_NEAR(xyz[2].get<double>(), 0.323, 1e-3);
  EXPECT_TRUE(json.at("within_limits").get<bool>());
}

TEST(EgressCliTest, ModelInfoTable) {
  const Result result = RunEgress("model info");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("footprint radius      0.215 m"));
  EXPECT_THAT(result.output, HasSubstr("arm_flex_joint"));
}

TEST(EgressCliTest, ClearErrors) {
  Result result = RunEgress("model info --urdf /nonexistent.urdf");
  EXPECT_NE(result.exit_code, 0);
  EXPECT_THAT(result.output, HasSubstr("/nonexistent.urdf"));

  result = RunEgress("model fk --arm 0 nan");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.output, HasSubstr("arm_flex_joint"));

  result = RunEgress("sim");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.output, HasSubstr("not available in this build yet"));

  result = RunEgress("no-such-command");
  EXPECT_NE(result.exit_code, 0);
}

}  // namespace
