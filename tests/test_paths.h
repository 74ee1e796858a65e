#pragma once
// Temporary paths unique to the running test and process: ctest runs tests in parallel, so two
// tests must never share a scratch file.

#include <unistd.h>

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace egress::testing {

inline std::filesystem::path TestTempPath(const std::string& leaf) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string test =
      info != nullptr ? std::string(info->test_suite_name()) + "_" + info->name() : "global";
  return std::filesystem::temp_directory_path() /
         ("egress_" + test + "_" + std::to_string(::getpid()) + "_" + leaf);
}

}  // namespace egress::testing
