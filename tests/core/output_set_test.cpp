// OutputSet: staged files appear only at commit, all together; a failure or a destroyed set leaves no file,
// no temporary and no folder it created behind.
#include "core/output_set.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/errors.h"
#include "tests/support/test_support.h"

namespace raysift {
namespace {

namespace fs = std::filesystem;

void write_text(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

std::size_t entry_count(const std::string& dir) {
  std::size_t n = 0;
  for (auto it = fs::recursive_directory_iterator(dir); it != fs::recursive_directory_iterator(); ++it) ++n;
  return n;
}

TEST(OutputSet, FilesAppearOnlyAtCommit) {
  const std::string dir = test::make_temp_dir("outset_commit");
  OutputSet set;
  const std::string a = set.stage(dir + "/a.png"), b = set.stage(dir + "/b.json");
  EXPECT_EQ(fs::path(a).extension(), ".png");  // writers pick the format from the extension
  EXPECT_EQ(fs::path(a).parent_path(), fs::path(dir));
  write_text(a, "A");
  write_text(b, "B");
  EXPECT_FALSE(fs::exists(dir + "/a.png"));
  set.commit();
  EXPECT_EQ(test::read_text(dir + "/a.png"), "A");
  EXPECT_EQ(test::read_text(dir + "/b.json"), "B");
  EXPECT_EQ(entry_count(dir), 2u);  // no temporary left
}

TEST(OutputSet, FailureBeforeCommitLeavesNothing) {
  const std::string dir = test::make_temp_dir("outset_fail");
  write_text(dir + "/old.png", "previous run");
  try {
    OutputSet set;
    set.make_directories(dir + "/new/sub");
    write_text(set.stage(dir + "/new/sub/x.exr"), "X");
    write_text(set.stage(dir + "/old.png"), "half");
    throw IoError("the third writer failed");
  } catch (const IoError&) {
  }
  EXPECT_FALSE(fs::exists(dir + "/new"));                   // the folders it made are gone
  EXPECT_EQ(test::read_text(dir + "/old.png"), "previous run");  // an existing target is untouched
  EXPECT_EQ(entry_count(dir), 1u);
}

TEST(OutputSet, StagingChecksTheTarget) {
  const std::string dir = test::make_temp_dir("outset_checks");
  OutputSet set;
  EXPECT_THROW(set.stage(dir + "/missing/x.png"), IoError);
  EXPECT_THROW(set.stage(dir), IoError);
  set.stage(dir + "/x.png");
  EXPECT_THROW(set.stage(dir + "/./x.png"), IoError);  // the same file twice
}

TEST(OutputSet, FileStagedButNeverWrittenFailsTheCommit) {
  const std::string dir = test::make_temp_dir("outset_unwritten");
  OutputSet set;
  write_text(set.stage(dir + "/a.txt"), "A");
  set.stage(dir + "/b.txt");
  EXPECT_THROW(set.commit(), IoError);
  EXPECT_FALSE(fs::exists(dir + "/a.txt"));  // checked before the first rename
}

}  // namespace
}  // namespace raysift
