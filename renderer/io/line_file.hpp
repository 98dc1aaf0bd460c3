// A file of lines written one at a time as results come in (one JSON line per frame), under a name
// that says it is unfinished until the last line is in.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

#include "renderer/io/unique_fd.hpp"

namespace sb::io {

class LineFile {
 public:
  /// Creates (or empties) `partial`; IoError naming it when it cannot be made.
  explicit LineFile(std::filesystem::path partial);

  /// Writes `line` and a newline, whole, before returning; IoError naming the file (a full disk).
  void append(const std::string& line);
  /// Lines appended so far.
  [[nodiscard]] size_t lines() const { return lines_; }
  /// Flushes the file to disk and renames it to `final_path` (replacing a file there).
  void finish(const std::filesystem::path& final_path);

 private:
  std::filesystem::path path_;
  UniqueFd fd_;
  size_t lines_ = 0;
};

}  // namespace sb::io
