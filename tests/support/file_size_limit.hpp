// A disk that fills at a given size, for one test scope: the process's file-size limit is set
// there, and the signal the kernel sends at the limit is ignored, so a write past it fails with
// EFBIG as one on a full disk fails with ENOSPC. Both are restored when the scope ends.
#pragma once

#include <sys/resource.h>

#include <csignal>
#include <cstdint>

namespace sb::test {

class FileSizeLimit {
 public:
  explicit FileSizeLimit(uintmax_t bytes) : old_handler_(std::signal(SIGXFSZ, SIG_IGN)) {
    ok_ = ::getrlimit(RLIMIT_FSIZE, &old_limit_) == 0;
    rlimit tight = old_limit_;
    tight.rlim_cur = static_cast<rlim_t>(bytes);
    ok_ = ok_ && ::setrlimit(RLIMIT_FSIZE, &tight) == 0;
  }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;
  ~FileSizeLimit() {
    (void)::setrlimit(RLIMIT_FSIZE, &old_limit_);
    std::signal(SIGXFSZ, old_handler_);
  }
  /// Whether the limit is in force.
  [[nodiscard]] bool ok() const { return ok_; }

 private:
  void (*old_handler_)(int);
  rlimit old_limit_{};
  bool ok_ = false;
};

}  // namespace sb::test
