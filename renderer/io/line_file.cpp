// A file of lines written as results come in.
#include "renderer/io/line_file.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"

namespace sb::io {

namespace fs = std::filesystem;

LineFile::LineFile(fs::path partial) : path_(std::move(partial)) {
  fd_.reset(::open(path_.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0666));  // the umask decides
  if (!fd_.valid())
    throw IoError(fmt::format("cannot write {}: {}; give a folder you can write, or make room there", path_.string(),
                              std::strerror(errno)));
  if (::flock(fd_.get(), LOCK_EX | LOCK_NB) != 0 && errno == EWOULDBLOCK) {
    fd_.reset();
    throw InputError(fmt::format("{} is being written by another run; wait for it to end, or give another --out",
                                 path_.string()));
  }
  if (::ftruncate(fd_.get(), 0) != 0)
    throw IoError(fmt::format("cannot empty {}: {}", path_.string(), std::strerror(errno)));
}

LineFile::~LineFile() {
  if (finished_ || lines_ > 0) return;
  std::error_code ignored;
  fs::remove(path_, ignored);
}

void LineFile::append(const std::string& line) {
  if (torn_)
    throw IoError(fmt::format("cannot write {}: its last line was cut short by an earlier failed write", path_.string()));
  const std::string text = line + "\n";
  for (size_t done = 0; done < text.size();) {
    const ssize_t n = ::write(fd_.get(), text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string why = n < 0 ? std::strerror(errno) : "nothing written";
      // The part of the line that did go in is cut off again: the file holds whole lines only.
      const bool undone = ::ftruncate(fd_.get(), end_) == 0 && ::lseek(fd_.get(), end_, SEEK_SET) == end_;
      torn_ = !undone;
      throw IoError(fmt::format("cannot write {}: {}; check free disk space{}", path_.string(), why,
                                undone ? "" : " (its last line may be cut short)"));
    }
    done += static_cast<size_t>(n);
  }
  end_ += static_cast<off_t>(text.size());
  ++lines_;
}

void LineFile::finish(const fs::path& final_path) {
  if (::fsync(fd_.get()) != 0)
    throw IoError(fmt::format("cannot flush {} to disk: {}; check free disk space", path_.string(), std::strerror(errno)));
  const fs::path target = follow_links(final_path);
  std::error_code ec;
  fs::rename(path_, target, ec);
  if (ec)
    throw IoError(fmt::format("cannot rename {} to {}: {}", path_.string(), target.string(), ec.message()));
  finished_ = true;
  fd_.reset();  // the lock goes with the file's last descriptor
  sync_folder(target.parent_path());  // the rename itself on disk; best effort
}

}  // namespace sb::io
