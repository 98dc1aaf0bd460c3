// Exclusive advisory locks on lock files and folders (see file_lock.hpp).
#include "renderer/io/file_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "renderer/error.hpp"

namespace sb::io {

namespace fs = std::filesystem;

std::optional<FileLock> FileLock::lock(const fs::path& path, bool wait) {
  for (;;) {
    std::error_code ec;
    const bool folder = fs::is_directory(path, ec);
    FileLock out;
    out.path_ = path;
    out.fd_.reset(folder ? ::open(path.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC)
                         : ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666));  // the umask decides
    if (!out.fd_.valid())
      throw IoError(fmt::format("cannot open {}, the lock {}: {}; every user of that folder must be able to write it "
                                "(check its permissions), or give a folder you can write",
                                path.string(), folder ? "folder" : "file", std::strerror(errno)));
    int err = 0;
    while (::flock(out.fd_.get(), LOCK_EX | (wait ? 0 : LOCK_NB)) != 0 && (err = errno) == EINTR) err = 0;
    if (err == EWOULDBLOCK) return std::nullopt;
    if (err != 0 && err != ENOLCK && err != EOPNOTSUPP)  // without locks (ENOLCK) it is taken as held
      throw IoError(fmt::format("cannot lock {}: {}; give a folder on a local file system", path.string(),
                                std::strerror(err)));
    // A lock file its holder removed (remove_when_released) while this one waited: lock the new one.
    struct stat held {}, named {};
    if (::stat(path.c_str(), &named) != 0) {
      if (errno == ENOENT) continue;
      return out;  // cannot tell; the file it opened is the one to hold
    }
    if (::fstat(out.fd_.get(), &held) != 0 || (held.st_dev == named.st_dev && held.st_ino == named.st_ino)) return out;
  }
}

FileLock& FileLock::operator=(FileLock&& other) noexcept {
  if (this != &other) {
    release();
    path_ = std::move(other.path_);
    fd_ = std::move(other.fd_);
    remove_ = other.remove_;
  }
  return *this;
}

void FileLock::release() noexcept {
  if (!fd_.valid()) return;
  if (remove_) (void)::unlink(path_.c_str());
  fd_.reset();
}

FileLock FileLock::acquire(const fs::path& path) { return *lock(path, true); }

FileLock FileLock::acquire(const fs::path& path, const std::function<void()>& on_wait) {
  if (std::optional<FileLock> now = lock(path, false)) return std::move(*now);
  on_wait();
  return *lock(path, true);
}

std::optional<FileLock> FileLock::try_acquire(const fs::path& path) { return lock(path, false); }

}  // namespace sb::io
