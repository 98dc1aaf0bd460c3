// A file of lines written one at a time as results come in (one JSON line per frame), under a name
// that says it is unfinished until the last line is in.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

#include <sys/types.h>

#include "renderer/io/unique_fd.hpp"

namespace sb::io {

class LineFile {
 public:
  /// Creates (or empties) `partial` and holds an exclusive lock on it while this object lives:
  /// InputError when another run holds it (it is writing the same file), IoError naming it when it
  /// cannot be made.
  explicit LineFile(std::filesystem::path partial);
  /// Removes the partial file when no line reached it (a run that failed before its first result).
  ~LineFile();
  LineFile(const LineFile&) = delete;
  LineFile& operator=(const LineFile&) = delete;

  /// Writes `line` and a newline, whole, before returning; IoError naming the file (a full disk),
  /// the part of the line written before the failure cut off again.
  void append(const std::string& line);
  /// Lines appended so far.
  [[nodiscard]] size_t lines() const { return lines_; }
  /// Flushes the file to disk and renames it to `final_path`, replacing a file there; a link at
  /// `final_path` is followed (the file it names is replaced, the link kept).
  void finish(const std::filesystem::path& final_path);

 private:
  std::filesystem::path path_;
  UniqueFd fd_;
  size_t lines_ = 0;
  off_t end_ = 0;  ///< the file's size after its last whole line
  bool torn_ = false;  ///< a failed line could not be cut off again: no line may follow it
  bool finished_ = false;
};

}  // namespace sb::io
