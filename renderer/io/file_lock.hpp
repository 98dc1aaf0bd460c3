// An exclusive advisory lock (flock) on a lock file or a folder, held while its owner lives, so
// that runs in other processes that use the same path take turns (or one is refused).
#pragma once

#include <filesystem>
#include <functional>
#include <optional>

#include "renderer/io/unique_fd.hpp"

namespace sb::io {

/// Held from acquisition until the object goes (or release()). The lock belongs to this open of the
/// path: another FileLock on the same path, in this process or another, does not get it meanwhile.
/// A process that is killed lets its locks go with it. On a file system without locks (ENOLCK,
/// EOPNOTSUPP) the lock is taken as held.
class FileLock {
 public:
  FileLock() = default;
  FileLock(FileLock&& other) noexcept = default;
  FileLock& operator=(FileLock&& other) noexcept;
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;
  ~FileLock() { release(); }

  /// Locks `path`, waiting while another holds it: a folder that exists is locked itself, anything
  /// else is a lock file, created (empty) when missing. IoError naming the path when it cannot be
  /// opened or locked.
  [[nodiscard]] static FileLock acquire(const std::filesystem::path& path);
  /// The same, calling `on_wait` once before waiting when another holds the lock (to say what the
  /// run waits for).
  [[nodiscard]] static FileLock acquire(const std::filesystem::path& path, const std::function<void()>& on_wait);
  /// The same without waiting: nullopt when another holds the lock.
  [[nodiscard]] static std::optional<FileLock> try_acquire(const std::filesystem::path& path);

  [[nodiscard]] bool held() const { return fd_.valid(); }
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  /// Makes release() remove the lock file (still locked, so that no one takes the lock of a file
  /// that is gone: acquire checks that the path still names the file it locked, and else opens the
  /// new one), for a lock file per name that should not stay behind.
  void remove_when_released() { remove_ = true; }
  /// Lets the lock go (nothing when none is held).
  void release() noexcept;

 private:
  static std::optional<FileLock> lock(const std::filesystem::path& path, bool wait);

  std::filesystem::path path_;
  UniqueFd fd_;
  bool remove_ = false;
};

}  // namespace sb::io
