// The output policy: outputs never replace inputs (compared as files, not strings),
// temporary files are unique per writer and never outlive it (signals included), and
// failures carry the system's reason.
#include "liftoff/core/output.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "liftoff/core/file.h"
#include "support/test_support.h"

namespace liftoff {
namespace {

namespace fs = std::filesystem;
using liftoff::testing::ReadFile;
using liftoff::testing::ScratchDir;
using liftoff::testing::WriteFile;
using ::testing::HasSubstr;
using ::testing::Not;

int FilesIn(const fs::path& dir) {
  int count = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++count;
  return count;
}

TEST(SameFile, SeesThroughSpellingsAndLinks) {
  ScratchDir scratch;
  WriteFile(scratch / "log.csv", "x");
  fs::create_directories(scratch / "sub");
  fs::create_hard_link(scratch / "log.csv", scratch / "hard.csv");
  fs::create_symlink(scratch / "log.csv", scratch / "soft.csv");
  EXPECT_TRUE(SameFile(scratch / "log.csv", scratch / "sub" / ".." / "log.csv"));
  EXPECT_TRUE(SameFile(scratch / "log.csv", scratch / "hard.csv"));
  EXPECT_TRUE(SameFile(scratch / "log.csv", scratch / "soft.csv"));
  // one side missing: the canonical spelling decides
  EXPECT_TRUE(SameFile(scratch / "new.csv", scratch / "sub" / ".." / "new.csv"));
  EXPECT_FALSE(SameFile(scratch / "log.csv", scratch / "new.csv"));
  WriteFile(scratch / "copy.csv", "x");
  EXPECT_FALSE(SameFile(scratch / "log.csv", scratch / "copy.csv"));  // equal bytes, two files
}

TEST(CheckOutputsAreNotInputs, NamesBothFilesAndSkipsStandardOutput) {
  ScratchDir scratch;
  WriteFile(scratch / "m.json", "{}");
  const Status refused = CheckOutputsAreNotInputs({{"--output", scratch / "." / "m.json"}},
                                                  {{"MANIFEST", scratch / "m.json"}});
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(refused.message(), HasSubstr("--output"));
  EXPECT_THAT(refused.message(), HasSubstr("MANIFEST"));
  EXPECT_THAT(refused.message(), HasSubstr("refusing to write over an input"));
  EXPECT_TRUE(CheckOutputsAreNotInputs({{"--output", "-"}, {"--plot", ""}},
                                       {{"LOG", "-"}, {"MANIFEST", scratch / "m.json"}})
                  .ok());
}

TEST(TemporaryFile, TwoWritersOfOneOutputGetTheirOwnFiles) {
  ScratchDir scratch;
  const fs::path target = scratch / "out.csv";
  auto first = TemporaryFile::Create(target);
  auto second = TemporaryFile::Create(target);
  ASSERT_TRUE(first.ok()) << first.status().ToString();
  ASSERT_TRUE(second.ok()) << second.status().ToString();
  EXPECT_NE(first->path(), second->path());
  EXPECT_THAT(first->path().filename().string(),
              HasSubstr("out.csv.tmp." + std::to_string(getpid()) + "."));
  ASSERT_TRUE(first->Write("first").ok());
  ASSERT_TRUE(second->Write("second").ok());
  ASSERT_TRUE(first->Commit().ok());
  ASSERT_TRUE(second->Commit().ok());
  EXPECT_EQ(ReadFile(target), "second");
  EXPECT_EQ(FilesIn(scratch.path()), 1);
}

TEST(TemporaryFile, IsRemovedWhenNotCommitted) {
  ScratchDir scratch;
  const int live_before = LiveTemporaryFileCount();
  {
    auto temporary = TemporaryFile::Create(scratch / "out.csv");
    ASSERT_TRUE(temporary.ok());
    EXPECT_TRUE(fs::exists(temporary->path()));
    EXPECT_EQ(LiveTemporaryFileCount(), live_before + 1);
  }
  EXPECT_EQ(FilesIn(scratch.path()), 0);
  EXPECT_EQ(LiveTemporaryFileCount(), live_before);
}

// Ctrl-C (or a kill) while a command writes: the temporary file goes, and the process
// still dies of the signal (its parent sees SIGINT, as a shell expects).
TEST(TemporaryFile, IsRemovedOnSigintAndSigterm) {
  for (const int signal_number : {SIGINT, SIGTERM}) {
    ScratchDir scratch;
    WriteFile(scratch / "out.csv", "earlier output");
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      auto temporary = TemporaryFile::Create(scratch / "out.csv");
      if (!temporary.ok() || !temporary->Write("half a file").ok()) _exit(100);
      raise(signal_number);
      _exit(101);  // not reached: the signal's default action ends the process
    }
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status)) << "exit " << WEXITSTATUS(status);
    EXPECT_EQ(WTERMSIG(status), signal_number);
    EXPECT_EQ(FilesIn(scratch.path()), 1);
    EXPECT_EQ(ReadFile(scratch / "out.csv"), "earlier output");
  }
}

TEST(WriteFileAtomically, AFailedRenameCarriesTheSystemsReason) {
  ScratchDir scratch;
  fs::create_directories(scratch / "out.csv" / "inside");  // a folder where the file goes
  const Status written = WriteFileAtomically(scratch / "out.csv", "text");
  ASSERT_FALSE(written.ok());
  EXPECT_EQ(written.code(), StatusCode::kIo);
  EXPECT_THAT(written.message(), HasSubstr("cannot rename into place"));
  EXPECT_THAT(written.message(), HasSubstr("directory"));
  EXPECT_THAT(written.message(), Not(HasSubstr("Success")));
  EXPECT_EQ(FilesIn(scratch.path()), 1);  // no temporary file left
}

TEST(ReadWholeFile, TakesRegularFilesOnlyWithinALimit) {
  ScratchDir scratch;
  WriteFile(scratch / "small.txt", "12345");
  EXPECT_EQ(ReadWholeFile(scratch / "small.txt").value_or(""), "12345");
  const auto too_big = ReadWholeFile(scratch / "small.txt", 4);
  ASSERT_FALSE(too_big.ok());
  EXPECT_THAT(too_big.status().message(), HasSubstr("5 bytes; expected at most 4"));
  const auto device = ReadWholeFile("/dev/zero");
  ASSERT_FALSE(device.ok());
  EXPECT_EQ(device.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(device.status().message(), HasSubstr("not a regular file"));
  fs::create_symlink(scratch / "loop", scratch / "loop");
  const auto loop = ReadWholeFile(scratch / "loop");
  ASSERT_FALSE(loop.ok());
  EXPECT_THAT(loop.status().message(), HasSubstr("symbolic link loop"));
  EXPECT_EQ(ReadWholeFile(scratch / "missing").status().code(), StatusCode::kNotFound);
  EXPECT_EQ(kMaxWholeFileBytes, std::uintmax_t{1} << 30);  // docs/cli.md: 1 GiB
}

}  // namespace
}  // namespace liftoff
