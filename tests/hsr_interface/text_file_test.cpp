#include "egress/hsr_interface/text_file.h"

#include <sys/stat.h>

#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "egress/hsr_interface/error.h"
#include "test_paths.h"

namespace egress {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

TEST(ReadTextFileTest, ReadsARegularFileWhole) {
  const auto path = egress::testing::TestTempPath("text_file.txt");
  const std::string content = std::string("line 1\nline 2\0x", 15) + std::string(200000, 'y');
  std::ofstream(path, std::ios::binary) << content;
  EXPECT_EQ(ReadTextFile(path, "test file"), content);
  std::filesystem::remove(path);
}

// What a hostile path names is refused before anything is read: nothing there, a device that
// never ends, a FIFO no one writes, a directory; and a file over the cap is refused once the cap
// is passed, however large it is.
TEST(ReadTextFileTest, RefusesWhatIsNotABoundedRegularFile) {
  EXPECT_THAT([] { ReadTextFile("/nonexistent/world.sdf", "world file"); },
              ThrowsMessage<LoadError>(HasSubstr("/nonexistent/world.sdf: no such world file")));
  EXPECT_THAT([] { ReadTextFile("/dev/zero", "world file"); },
              ThrowsMessage<LoadError>(HasSubstr("/dev/zero: the world file is not a regular")));
  const auto fifo = egress::testing::TestTempPath("text_file.fifo");
  std::filesystem::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_THAT([&] { ReadTextFile(fifo, "scenario file"); },
              ThrowsMessage<LoadError>(HasSubstr("not a regular file")));
  std::filesystem::remove(fifo);
  EXPECT_THAT([] { ReadTextFile("/tmp", "scenario file"); },
              ThrowsMessage<LoadError>(HasSubstr("not a regular file")));
  const auto big = egress::testing::TestTempPath("text_file_big.txt");
  std::ofstream(big) << std::string(4096, 'z');
  EXPECT_THAT([&] { ReadTextFile(big, "URDF file", 1000); },
              ThrowsMessage<LoadError>(HasSubstr("larger than 1000 bytes")));
  EXPECT_EQ(ReadTextFile(big, "URDF file", 4096).size(), 4096u);
  std::filesystem::remove(big);
}

// Under a ScopedReadRoot only what resolves under the root is read, however the path gets out;
// nesting restores the outer root and leaving the scope lifts it.
TEST(ReadTextFileTest, AReadRootConfinesEveryRead) {
  const auto base = egress::testing::TestTempPath("root");
  std::filesystem::create_directories(base / "root" / "sub");
  std::filesystem::create_directories(base / "outside");
  std::ofstream(base / "root" / "sub" / "in.txt") << "in";
  std::ofstream(base / "outside" / "out.txt") << "out";
  std::filesystem::create_symlink(base / "outside" / "out.txt", base / "root" / "link.txt");
  {
    const ScopedReadRoot root(base / "root");
    EXPECT_EQ(ReadTextFile("sub/in.txt", "file"), "in");  // relative to the root
    EXPECT_EQ(ReadTextFile(base / "root" / "sub" / "in.txt", "file"), "in");
    for (const std::filesystem::path& escape :
         {std::filesystem::path("../outside/out.txt"), base / "outside" / "out.txt",
          std::filesystem::path("link.txt"), std::filesystem::path("sub/../../outside/out.txt")}) {
      EXPECT_THROW(ReadTextFile(escape, "file"), PathOutsideRoot) << escape;
    }
    {
      const ScopedReadRoot inner(base / "root" / "sub");
      EXPECT_THROW(ReadTextFile(base / "root" / "link.txt", "file"), PathOutsideRoot);
      EXPECT_EQ(ReadTextFile("in.txt", "file"), "in");
    }
    EXPECT_EQ(ScopedReadRoot::Current(), std::filesystem::canonical(base / "root"));
  }
  EXPECT_TRUE(ScopedReadRoot::Current().empty());
  EXPECT_EQ(ReadTextFile(base / "outside" / "out.txt", "file"), "out");
  EXPECT_THROW(ScopedReadRoot(base / "missing"), LoadError);
  std::filesystem::remove_all(base);
}

}  // namespace
}  // namespace egress
