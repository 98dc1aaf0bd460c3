// A scratch folder per running test under the build tree: removed when the test passes, kept for
// inspection when it fails.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace sb::test {

class ScratchDir {
 public:
  /// `tag` tells apart several scratch folders of one test.
  explicit ScratchDir(const std::string& tag = "") {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "." + info->name() + (tag.empty() ? "" : "." + tag);
    std::replace(name.begin(), name.end(), '/', '_');
    path_ = std::filesystem::path(SB_BINARY_DIR) / "Testing" / "scratch" / name;
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  ~ScratchDir() {
    std::error_code ec;
    if (!::testing::Test::HasFailure()) std::filesystem::remove_all(path_, ec);
  }
  [[nodiscard]] std::filesystem::path operator/(const std::string& file) const { return path_ / file; }
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// The bytes of a file (empty if it cannot be read).
inline std::vector<unsigned char> file_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// The text of a file (empty if it cannot be read).
inline std::string read_text(const std::filesystem::path& p) {
  const std::vector<unsigned char> b = file_bytes(p);
  return std::string(b.begin(), b.end());
}

}  // namespace sb::test
