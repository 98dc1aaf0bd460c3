// Atomic file output (temporary name, fsync, rename).
#include "renderer/io/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <new>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "renderer/error.hpp"

namespace sb::io {

namespace fs = std::filesystem;

namespace {

fs::path temporary_name(const fs::path& path) {
  static std::atomic<unsigned> counter{0};
  return path.parent_path() /
         fmt::format(".{}.tmp-{}-{}", path.filename().string(), ::getpid(), counter++);
}

void sync_file(const fs::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) throw IoError(fmt::format("cannot reopen {} to flush it: {}", path.string(), std::strerror(errno)));
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  if (rc != 0) throw IoError(fmt::format("cannot flush {} to disk: {}", path.string(), std::strerror(err)));
}

/// Where a write to `path` lands. A symbolic link is followed to the file it names, so that the
/// file is replaced and the link stays a link; a link to a device or pipe (/dev/stdout) is kept as
/// given, for the kernel to follow when it is opened.
fs::path write_target(const fs::path& path) {
  std::error_code ec;
  if (!fs::is_symlink(fs::symlink_status(path, ec))) return path;
  const fs::file_status target = fs::status(path, ec);
  if (fs::exists(target)) {
    if (!fs::is_regular_file(target)) return path;
    const fs::path real = fs::canonical(path, ec);
    return ec ? path : real;
  }
  // A dangling link names the file to create.
  fs::path p = path;
  for (int hops = 0; hops < 40 && fs::is_symlink(fs::symlink_status(p, ec)); ++hops) {
    const fs::path next = fs::read_symlink(p, ec);
    if (ec) break;
    p = next.is_absolute() ? next : p.parent_path() / next;
  }
  return p;
}

/// A device, pipe or socket cannot be replaced by renaming a file over it: it is written in place.
bool is_stream(const fs::path& path) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  return fs::exists(st) && !fs::is_regular_file(st) && !fs::is_directory(st);
}

}  // namespace

void write_atomically(const fs::path& given, const std::function<void(const fs::path&)>& write) {
  const fs::path path = write_target(given);
  if (is_stream(path)) {
    try {
      write(path);
    } catch (const Error&) {
      throw;
    } catch (const std::exception& e) {
      throw IoError(fmt::format("writing {} failed: {}", given.string(), e.what()));
    }
    return;
  }
  std::error_code ec;
  const fs::path parent = path.parent_path();
  if (!parent.empty()) {
    fs::create_directories(parent, ec);
    if (ec)
      throw IoError(fmt::format("cannot create folder {} for {}: {}", parent.string(),
                                path.filename().string(), ec.message()));
  }
  const fs::path tmp = temporary_name(path);
  try {
    write(tmp);
    sync_file(tmp);
    fs::rename(tmp, path, ec);
    if (ec) throw IoError(fmt::format("cannot rename {} to {}: {}", tmp.string(), path.string(), ec.message()));
  } catch (const Error&) {
    fs::remove(tmp, ec);
    throw;
  } catch (const std::exception& e) {
    fs::remove(tmp, ec);
    throw IoError(fmt::format("writing {} failed: {}", path.string(), e.what()));
  }
}

void write_file_atomically(const fs::path& path, std::span<const unsigned char> bytes) {
  write_atomically(path, [&](const fs::path& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw IoError(fmt::format("cannot open {} for writing: {}", tmp.string(), std::strerror(errno)));
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    out.flush();
    if (!out)
      throw IoError(fmt::format("cannot write {} ({} bytes): {}; check free disk space", path.string(),
                                bytes.size(), std::strerror(errno)));
  });
}

void write_text_atomically(const fs::path& path, const std::string& text) {
  write_file_atomically(path, std::span(reinterpret_cast<const unsigned char*>(text.data()), text.size()));
}

std::string read_file(const fs::path& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec))
    throw InputError(fmt::format("{} is a folder, not a file; give the path of the file to read", path.string()));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(fmt::format("cannot read {}: {}", path.string(), std::strerror(errno)));
  // Read in blocks rather than through a stream buffer copy, which would swallow a failed
  // allocation and return the file cut short.
  const uintmax_t size = fs::file_size(path, ec);  // a stream without a size (a pipe) grows as read
  std::string text;
  try {
    if (!ec) text.reserve(static_cast<size_t>(size));
    std::vector<char> block(size_t{1} << 16);
    while (in.read(block.data(), static_cast<std::streamsize>(block.size())) || in.gcount() > 0)
      text.append(block.data(), static_cast<size_t>(in.gcount()));
  } catch (const std::bad_alloc&) {
    throw IoError(fmt::format("not enough memory to read {}{}; free memory or raise the process's memory limit",
                              path.string(), ec ? std::string() : fmt::format(" ({} bytes)", size)));
  }
  if (in.bad()) throw IoError(fmt::format("error while reading {}", path.string()));
  return text;
}

}  // namespace sb::io
