// A file of lines written as results come in.
#include "renderer/io/line_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "renderer/error.hpp"

namespace sb::io {

namespace fs = std::filesystem;

LineFile::LineFile(fs::path partial) : path_(std::move(partial)) {
  fd_.reset(::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644));
  if (!fd_.valid())
    throw IoError(fmt::format("cannot write {}: {}; give a folder you can write, or make room there", path_.string(),
                              std::strerror(errno)));
}

void LineFile::append(const std::string& line) {
  const std::string text = line + "\n";
  for (size_t done = 0; done < text.size();) {
    const ssize_t n = ::write(fd_.get(), text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      throw IoError(fmt::format("cannot write {}: {}; check free disk space", path_.string(),
                                n < 0 ? std::strerror(errno) : "nothing written"));
    done += static_cast<size_t>(n);
  }
  ++lines_;
}

void LineFile::finish(const fs::path& final_path) {
  if (::fsync(fd_.get()) != 0)
    throw IoError(fmt::format("cannot flush {} to disk: {}; check free disk space", path_.string(), std::strerror(errno)));
  fd_.reset();
  std::error_code ec;
  fs::rename(path_, final_path, ec);
  if (ec)
    throw IoError(fmt::format("cannot rename {} to {}: {}", path_.string(), final_path.string(), ec.message()));
}

}  // namespace sb::io
