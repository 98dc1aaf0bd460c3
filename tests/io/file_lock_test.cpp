// io::FileLock: one holder at a time per path (also within one process), a folder locked itself,
// and a lock file removed on release without letting a waiter hold a file that is gone.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <future>

#include "renderer/error.hpp"
#include "renderer/io/file_lock.hpp"
#include "support/scratch_dir.hpp"

namespace sb::io {
namespace {

namespace fs = std::filesystem;

TEST(FileLock, OneHolderAtATime) {
  test::ScratchDir dir;
  const fs::path file = dir / "x.lock";
  std::optional<FileLock> first = FileLock::try_acquire(file);
  ASSERT_TRUE(first.has_value());
  EXPECT_TRUE(first->held());
  EXPECT_TRUE(fs::is_regular_file(file)) << "the lock file is made";
  EXPECT_FALSE(FileLock::try_acquire(file).has_value()) << "held by another open of the path";
  first->release();
  EXPECT_FALSE(first->held());
  EXPECT_TRUE(FileLock::try_acquire(file).has_value());
  EXPECT_TRUE(fs::exists(file)) << "kept unless asked to remove it";
}

TEST(FileLock, AFolderIsLockedItself) {
  test::ScratchDir dir;
  fs::create_directories(dir / "out");
  const FileLock held = FileLock::acquire(dir / "out");
  EXPECT_FALSE(FileLock::try_acquire(dir / "out").has_value());
  EXPECT_TRUE(fs::is_empty(dir / "out")) << "no file is made in it";
}

TEST(FileLock, AWaiterOfARemovedLockFileTakesTheNewOne) {
  test::ScratchDir dir;
  const fs::path file = dir / "id.lock";
  std::optional<FileLock> first = FileLock::try_acquire(file);
  ASSERT_TRUE(first.has_value());
  first->remove_when_released();
  std::future<FileLock> waiter = std::async(std::launch::async, [&] { return FileLock::acquire(file); });
  EXPECT_EQ(waiter.wait_for(std::chrono::milliseconds(200)), std::future_status::timeout) << "it waits";
  first->release();
  FileLock second = waiter.get();
  EXPECT_TRUE(second.held());
  ASSERT_TRUE(fs::exists(file)) << "it holds a lock file that is there";
  EXPECT_FALSE(FileLock::try_acquire(file).has_value()) << "and so no one else can take it";
}

TEST(FileLock, AFolderThatCannotBeWrittenIsNamed) {
  try {
    (void)FileLock::acquire("/proc/no-such/x.lock");
    FAIL() << "no error";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot open /proc/no-such/x.lock, the lock file"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace sb::io
