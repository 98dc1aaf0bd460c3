// Files written as one set: nothing changes before the commit, retired files go only once the set
// is in place, and the marker (the file added last), whose earlier version would say a mix of old
// and new files is complete, goes before any file is replaced.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "support/scratch_dir.hpp"

namespace sb::io {
namespace {

namespace fs = std::filesystem;

void write(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

/// Adds `text` as `path` to the set.
void add(StagedFiles& set, const fs::path& path, const std::string& text) {
  set.add(path, [&](const fs::path& tmp) { write_text_atomically(tmp, text); });
}

/// Regular files in `dir`, temporaries included.
size_t files_in(const fs::path& dir) {
  size_t n = 0;
  for (const fs::directory_entry& e : fs::directory_iterator(dir)) n += e.is_regular_file() ? 1 : 0;
  return n;
}

TEST(StagedFiles, ACommittedSetReplacesTheEarlierOneAndRetiresWhatItDoesNotWrite) {
  test::ScratchDir dir("staged");
  write(dir / "a.txt", "old a");
  write(dir / "gone.png", "old diagnostic image");
  write(dir / "set.json", "old marker");
  {
    StagedFiles set;
    add(set, dir / "a.txt", "new a");
    add(set, dir / "set.json", "new marker");
    set.retire(dir / "gone.png");
    EXPECT_EQ(test::read_text(dir / "a.txt"), "old a") << "a file changed before the commit";
    EXPECT_TRUE(fs::exists(dir / "gone.png")) << "a retired file went before the commit";
    set.commit();
  }
  EXPECT_EQ(test::read_text(dir / "a.txt"), "new a");
  EXPECT_EQ(test::read_text(dir / "set.json"), "new marker");
  EXPECT_FALSE(fs::exists(dir / "gone.png"));
  EXPECT_EQ(files_in(dir.path()), 2u);
}

TEST(StagedFiles, ARenameThatFailsLeavesNoMarker) {
  test::ScratchDir dir("staged-fail");
  const auto earlier = [&] {
    write(dir / "a.txt", "old a");
    write(dir / "gone.png", "old diagnostic image");
    write(dir / "set.json", "old marker");
  };
  // A folder appears at a file's name after the set was made: its rename fails.
  for (const bool first : {true, false}) {
    earlier();
    {
      StagedFiles set;
      add(set, dir / "a.txt", "new a");
      add(set, dir / "b.txt", "new b");
      add(set, dir / "set.json", "new marker");
      set.retire(dir / "gone.png");
      const fs::path blocked = dir / (first ? "a.txt" : "b.txt");
      fs::remove(blocked);
      fs::create_directories(blocked / "inside");
      try {
        set.commit();
        ADD_FAILURE() << "a rename onto a folder succeeded";
      } catch (const IoError& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("cannot write " + blocked.string()), std::string::npos) << msg;
        EXPECT_NE(msg.find(fmt::format("{} of the set's 3 files are in place and the others not, and {} is removed",
                                       first ? 0 : 1, (dir / "set.json").string())),
                  std::string::npos)
            << msg;
      }
    }
    EXPECT_TRUE(fs::exists(dir / "gone.png")) << "retired although the set is not in place";
    // The earlier marker went before the first rename: a run stopped anywhere among the renames
    // (killed, or a rename refused) leaves no marker that calls the mix one set.
    EXPECT_FALSE(fs::exists(dir / "set.json")) << "the earlier marker stands beside a set not in place";
    if (first) {
      EXPECT_EQ(files_in(dir.path()), 1u) << "temporaries left";  // gone.png
    } else {
      EXPECT_EQ(test::read_text(dir / "a.txt"), "new a");
      EXPECT_EQ(files_in(dir.path()), 2u) << "temporaries left";  // gone.png and the new a.txt
    }
    fs::remove_all(dir / (first ? "a.txt" : "b.txt"));
  }
}

}  // namespace
}  // namespace sb::io
