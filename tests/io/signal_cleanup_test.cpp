// The handler of the ending signals removes the temporary file of every write in progress, not
// only of the first one the process made.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "support/scratch_dir.hpp"

namespace sb::io {
namespace {

namespace fs = std::filesystem;

TEST(SignalCleanup, EveryWriteInProgressHasItsTemporaryRemoved) {
  // Each write takes a slot for its temporary's name and gives it back; the slot's version once
  // changed parity at every reuse, so from the second write on the handler took the name for one
  // still being copied in and left the file (a render stopped by SIGTERM kept its PNG temporaries).
  test::ScratchDir dir("signal-cleanup");
  for (int write = 0; write < 4; ++write) {
    fs::path seen;
    try {
      write_atomically(dir / "image.png", [&](const fs::path& tmp) {
        seen = tmp;
        std::ofstream(tmp) << "half an image";
        ASSERT_TRUE(fs::exists(tmp));
        remove_temporaries_on_signal();
      });
    } catch (const IoError&) {
      // Expected: the handler took the file the write was about to rename into place.
    }
    EXPECT_FALSE(seen.empty());
    EXPECT_FALSE(fs::exists(seen)) << "write " << write << " left " << seen;
  }
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

}  // namespace
}  // namespace sb::io
