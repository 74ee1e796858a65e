// cmake/EgressRevision.cmake: the revision `egress --version` shows is read at every build, so
// it follows new commits without a new configure, and an unchanged tree keeps its header.

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace {

namespace fs = std::filesystem;

std::string Shell(const std::string& command) {
  const int status = std::system((command + " > /dev/null 2>&1").c_str());
  EXPECT_EQ(status, 0) << command;
  return command;
}

std::string Read(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string Head(const fs::path& repo) {
  FILE* pipe = ::popen(("git -C " + repo.string() + " rev-parse --short=12 HEAD").c_str(), "r");
  EXPECT_NE(pipe, nullptr);
  std::string head;
  char buffer[64];
  while (pipe != nullptr && std::fgets(buffer, sizeof buffer, pipe) != nullptr)
    head += buffer;
  if (pipe != nullptr) ::pclose(pipe);
  while (!head.empty() && (head.back() == '\n' || head.back() == '\r'))
    head.pop_back();
  return head;
}

TEST(RevisionTest, TheHeaderFollowsTheCommitAndMarksUncommittedChanges) {
  const fs::path repo =
      fs::temp_directory_path() / ("egress_revision_test_" + std::to_string(::getpid()));
  fs::remove_all(repo);
  fs::create_directories(repo);
  const std::string git =
      "git -C " + repo.string() + " -c user.name=test -c user.email=test@example.invalid ";
  Shell("git init -q " + repo.string());
  std::ofstream(repo / "a.txt") << "one\n";
  Shell(git + "add a.txt");
  Shell(git + "commit -qm one");
  const fs::path header = repo / "out" / "egress_revision.h";
  fs::create_directories(header.parent_path());
  const std::string generate = std::string("cmake -DSOURCE_DIR=") + repo.string() +
                               " -DOUTPUT=" + header.string() + " -P " + EGRESS_REVISION_SCRIPT;
  Shell(generate);
  const std::string first = Head(repo);
  EXPECT_NE(Read(header).find("\"" + first + "\""), std::string::npos) << Read(header);

  // Unchanged: the file is not rewritten (nothing recompiles).
  const auto stamp = fs::last_write_time(header);
  Shell(generate);
  EXPECT_EQ(fs::last_write_time(header), stamp);

  // A new commit, no reconfigure: the next build names it.
  std::ofstream(repo / "a.txt") << "two\n";
  Shell(git + "commit -qam two");
  Shell(generate);
  const std::string second = Head(repo);
  EXPECT_NE(second, first);
  EXPECT_NE(Read(header).find("\"" + second + "\""), std::string::npos) << Read(header);

  // An edited tracked file: -dirty.
  std::ofstream(repo / "a.txt") << "three\n";
  Shell(generate);
  EXPECT_NE(Read(header).find("\"" + second + "-dirty\""), std::string::npos) << Read(header);
  fs::remove_all(repo);
}

}  // namespace
