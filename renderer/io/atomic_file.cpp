// Atomic file output (temporary name, fsync, rename).
#include "renderer/io/atomic_file.hpp"

#include <fcntl.h>
#include <limits.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <chrono>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <new>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/io/unique_fd.hpp"
#include "renderer/text.hpp"

namespace sb::io {

namespace fs = std::filesystem;

namespace {

/// How the temporary names of `path`'s writes begin: ".FILE.tmp-".
std::string temporary_prefix(const fs::path& path) { return fmt::format(".{}.tmp-", path.filename().string()); }

/// The folder `path` lies in ("." for a bare name).
fs::path folder_of(const fs::path& path) { return path.parent_path().empty() ? fs::path(".") : path.parent_path(); }

/// What a name in the folder of a file is to that file's writes.
enum class TemporaryKind {
  none,       ///< not one of its temporary names
  temporary,  ///< ".FILE.tmp-PID-N": a write's temporary file, locked while the write runs
  staging,    ///< ".FILE.tmp-PID-N.new": that file before it is locked and renamed (microseconds)
};

/// What `name` is to the writes of the file whose temporaries start with `prefix` (".FILE.tmp-").
TemporaryKind temporary_kind(const std::string& name, const std::string& prefix) {
  if (!name.starts_with(prefix)) return TemporaryKind::none;
  std::string_view rest = std::string_view(name).substr(prefix.size());
  const bool staging = rest.ends_with(".new");
  if (staging) rest.remove_suffix(4);
  const size_t dash = rest.find('-');
  const auto digits = [](std::string_view t) {
    return !t.empty() && std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  if (dash == std::string_view::npos || !digits(rest.substr(0, dash)) || !digits(rest.substr(dash + 1)))
    return TemporaryKind::none;
  return staging ? TemporaryKind::staging : TemporaryKind::temporary;
}

/// Removes the temporary files that earlier writes of `path` left behind when their process was
/// killed (SIGKILL, a job's time limit) before it could remove them. A write holds an exclusive
/// lock on its temporary file until it is renamed or removed, so a file whose lock can be taken
/// has no writer left, whichever machine or container made it; where locks are unavailable
/// (ENOLCK), nothing is removed. A staging name is locked and renamed within microseconds of its
/// creation: one a minute old, unlocked, was left by a kill in between. Best effort: errors leave
/// files where they are.
void remove_stale_temporaries(const fs::path& path) {
  const std::string prefix = temporary_prefix(path);
  const auto now = fs::file_time_type::clock::now();
  std::error_code ec;
  for (fs::directory_iterator it(folder_of(path), ec), end; !ec && it != end; it.increment(ec)) {
    const TemporaryKind kind = temporary_kind(it->path().filename().string(), prefix);
    if (kind == TemporaryKind::none) continue;
    std::error_code ignored;
    // A young staging file is not even opened: a lock taken here, between its writer's creation
    // and its own flock, would make the writer's flock fail and leave its write unlocked.
    if (kind == TemporaryKind::staging) {
      const auto made = fs::last_write_time(it->path(), ignored);
      if (ignored || now - made < std::chrono::minutes(1)) continue;
    }
    const UniqueFd fd{::open(it->path().c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK)};
    if (!fd.valid() || ::flock(fd.get(), LOCK_EX | LOCK_NB) != 0) continue;  // a running write, or not ours
    fs::remove(it->path(), ignored);
  }
}

/// Creates `tmp` and holds an exclusive lock on it while it exists (see remove_stale_temporaries);
/// the writer then opens and truncates the same file. The file is made and locked under a staging
/// name the cleanup lets be for a minute, then renamed to `tmp` (the lock goes with the file), so
/// that no other write can find it unlocked. The descriptor is closed with the object.
UniqueFd lock_temporary(const fs::path& tmp, const fs::path& path) {
  const fs::path staging = tmp.parent_path() / (tmp.filename().string() + ".new");
  // 0666 before the umask, as other tools create files.
  UniqueFd fd{::open(staging.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666)};
  if (!fd.valid())
    throw IoError(fmt::format("cannot write {}: cannot create a file in {} ({}); give a path in a folder you can "
                              "write, or make room there",
                              path.string(), folder_of(path).string(), std::strerror(errno)));
  (void)::flock(fd.get(), LOCK_EX | LOCK_NB);  // without locks (ENOLCK) the file is only never judged stale
  std::error_code ec;
  fs::rename(staging, tmp, ec);
  if (ec) {
    const std::string why = ec.message();
    fs::remove(staging, ec);
    throw IoError(fmt::format("cannot write {}: cannot rename a file in {} ({}); give a path in a folder you can "
                              "write",
                              path.string(), folder_of(path).string(), why));
  }
  return fd;
}

/// The temporary files of writes in progress, for remove_temporaries_on_signal: fixed slots of
/// lock-free flags and path bytes, so that a signal handler reads them without locks or the heap.
/// Untouched slots cost no memory; a write that finds none free is only not removed on a signal
/// (the next write of its file removes it as stale).
struct SignalSlot {
  std::atomic<bool> used{false};     ///< taken by a registration
  std::atomic<uint32_t> version{0};  ///< odd while `path` is copied in; changes with every name and release
  char path[PATH_MAX];
};
constexpr size_t kSignalSlots = 512;
SignalSlot g_signal_slots[kSignalSlots];

std::atomic<int> g_commits{0};          ///< commits of StagedFiles running now
std::atomic<int> g_deferred_signal{0};  ///< an ending signal that came during one

/// Keeps a temporary file's name in a slot for its lifetime (movable, one owner).
class SignalRegistration {
 public:
  explicit SignalRegistration(const fs::path& path) {
    const std::string& name = path.native();
    if (name.size() >= PATH_MAX) return;
    for (size_t i = 0; i < kSignalSlots; ++i) {
      bool free = false;
      SignalSlot& slot = g_signal_slots[i];
      if (!slot.used.compare_exchange_strong(free, true)) continue;
      slot.version.fetch_add(1, std::memory_order_acq_rel);  // odd: being written
      std::memcpy(slot.path, name.c_str(), name.size() + 1);
      slot.version.fetch_add(1, std::memory_order_acq_rel);  // even: whole
      slot_ = static_cast<int>(i);
      return;
    }
  }
  SignalRegistration(SignalRegistration&& o) noexcept : slot_(std::exchange(o.slot_, -1)) {}
  SignalRegistration& operator=(SignalRegistration&& o) noexcept {
    if (this != &o) {
      release();
      slot_ = std::exchange(o.slot_, -1);
    }
    return *this;
  }
  SignalRegistration(const SignalRegistration&) = delete;
  SignalRegistration& operator=(const SignalRegistration&) = delete;
  ~SignalRegistration() { release(); }

 private:
  void release() {
    if (slot_ < 0) return;
    SignalSlot& slot = g_signal_slots[slot_];
    // Two steps, so the version stays even (a registration makes it odd only while it copies a
    // name) and still changes: a handler copying the old name meanwhile sees it gone.
    slot.version.fetch_add(2, std::memory_order_acq_rel);
    slot.used.store(false, std::memory_order_release);
    slot_ = -1;
  }
  int slot_ = -1;
};

/// A write's temporary file for `path`, ".FILE.tmp-PID-N", locked: the stale temporaries of
/// earlier writes of `path` are removed first. Its name is registered for removal on a signal
/// until the object goes (by then it is renamed into place or removed).
struct Temporary {
  fs::path path;
  UniqueFd lock;
  SignalRegistration on_signal;
};
Temporary new_temporary(const fs::path& path) {
  remove_stale_temporaries(path);
  static std::atomic<unsigned> counter{0};
  fs::path tmp = path.parent_path() / fmt::format("{}{}-{}", temporary_prefix(path), ::getpid(), counter++);
  SignalRegistration on_signal(tmp);  // before the file exists: a signal on the way finds its name
  UniqueFd lock;
  {
    // So does the staging name lock_temporary makes first (a signal between its creation and its
    // rename left it behind).
    const SignalRegistration staging_on_signal(tmp.parent_path() / (tmp.filename().string() + ".new"));
    lock = lock_temporary(tmp, path);
  }
  return Temporary{std::move(tmp), std::move(lock), std::move(on_signal)};
}

void sync_file(const fs::path& path) {
  const UniqueFd fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
  if (!fd.valid()) throw IoError(fmt::format("cannot reopen {} to flush it: {}", path.string(), std::strerror(errno)));
  const int rc = ::fsync(fd.get());
  const int err = errno;
  if (rc != 0) throw IoError(fmt::format("cannot flush {} to disk: {}", path.string(), std::strerror(err)));
}

constexpr int kMaxLinkHops = 40;

/// The paths a symbolic link leads through: `path`, then each link's target in turn, ending at a
/// path that is no link (a missing one for a dangling link). IoError for a loop or an unreadable
/// link.
std::vector<fs::path> link_chain(const fs::path& path) {
  std::error_code ec;
  std::vector<fs::path> chain{path};
  while (fs::is_symlink(fs::symlink_status(chain.back(), ec))) {
    if (chain.size() > static_cast<size_t>(kMaxLinkHops))
      throw IoError(fmt::format("cannot write {}: too many levels of symbolic links (a loop?)", path.string()));
    const fs::path& p = chain.back();
    const fs::path next = fs::read_symlink(p, ec);
    if (ec)
      throw IoError(
          fmt::format("cannot write {}: cannot read the link {}: {}", path.string(), p.string(), ec.message()));
    chain.push_back(next.is_absolute() ? next : p.parent_path() / next);
  }
  return chain;
}

/// Whether a path, or a link on the way to its file (its link_chain), names an open file of a
/// process (/dev/stdout, /dev/fd/N, /proc/self/fd/N): such a file is the caller's stream, whatever
/// it is (a terminal, a pipe, or a file the shell redirected into), and is written in place, never
/// replaced.
bool names_open_file(const std::vector<fs::path>& chain) {
  return std::any_of(chain.begin(), chain.end(), [](const fs::path& p) {
    std::error_code ec;
    const std::string s = fs::absolute(p, ec).lexically_normal().string();
    if (s.rfind("/dev/fd/", 0) == 0) return true;
    // /proc/self/fd/N, /proc/thread-self/fd/N, /proc/PID/fd/N, /proc/PID/task/TID/fd/N; not any
    // other name under /proc, which is no folder a file can be written into.
    if (s.rfind("/proc/", 0) != 0) return false;
    const size_t fd = s.find("/fd/");
    if (fd == std::string::npos) return false;
    const std::string owner = s.substr(6, fd - 6);  // between "/proc/" and "/fd/"
    const auto digits = [](const std::string& t) {
      return !t.empty() && std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; });
    };
    const auto process = [&](const std::string& t) { return t == "self" || t == "thread-self" || digits(t); };
    const size_t task = owner.find("/task/");
    return task == std::string::npos ? process(owner)
                                     : process(owner.substr(0, task)) && digits(owner.substr(task + 6));
  });
}

/// A device, pipe or socket cannot be replaced by renaming a file over it: it is written in place.
bool is_stream(const fs::path& path) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  return fs::exists(st) && !fs::is_regular_file(st) && !fs::is_directory(st);
}

/// Runs `work`, which writes `tmp` on the way to `path`; on any failure `tmp` is removed and the
/// error passed on, typed errors as they are, others as an IoError naming `path`.
void with_temporary(const fs::path& tmp, const fs::path& path, const std::function<void()>& work) {
  std::error_code ec;
  try {
    work();
  } catch (const IoError& e) {
    // The writer names the file it was given, the hidden temporary one: the message names `path`.
    fs::remove(tmp, ec);
    throw IoError(replace_all(e.what(), tmp.string(), path.string()));
  } catch (const Error&) {
    fs::remove(tmp, ec);
    throw;
  } catch (const std::exception& e) {
    fs::remove(tmp, ec);
    throw IoError(fmt::format("writing {} failed: {}", path.string(), e.what()));
  }
}

/// Writes a stream in place: the file is made whole in the temporary folder first (a writer may
/// need to seek, as the EXR writer does), then its bytes are appended to the stream, which keeps
/// what a shell's `>>` put there before. The staged file is locked and cleaned up as a file's
/// temporary is.
void write_through(const fs::path& stream, const std::function<void(const fs::path&)>& write) {
  // $TMPDIR, or /tmp where it is unset or names no folder.
  std::error_code ec;
  fs::path folder = fs::temp_directory_path(ec);
  if (ec || folder.empty()) folder = "/tmp";
  const Temporary staged = new_temporary(folder / stream.filename());
  const fs::path& tmp = staged.path;
  with_temporary(tmp, stream, [&] {
    try {
      write(tmp);
    } catch (const IoError& e) {
      // The copy failed, not the stream: the message names the temporary folder (a full /tmp
      // while the stream's own disk has room).
      const std::string message = replace_all(e.what(), tmp.string(), "its copy in " + folder.string());
      throw IoError(fmt::format("cannot write {}: it is written through a copy made first in the temporary folder {}, "
                                "and that failed: {}; make room there, or set TMPDIR to a folder with room",
                                stream.string(), folder.string(), message));
    }
    const UniqueFd in{::open(tmp.c_str(), O_RDONLY | O_CLOEXEC)};
    const UniqueFd out{::open(stream.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC)};
    if (in.get() < 0 || out.get() < 0)
      throw IoError(
          fmt::format("cannot open {}: {}", in.get() < 0 ? tmp.string() : stream.string(), std::strerror(errno)));
    std::vector<char> block(size_t{1} << 16);
    for (;;) {
      const ssize_t n = ::read(in.get(), block.data(), block.size());
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) throw IoError(fmt::format("cannot read {}: {}", tmp.string(), std::strerror(errno)));
      if (n == 0) break;
      for (ssize_t done = 0; done < n;) {
        const ssize_t w = ::write(out.get(), block.data() + done, static_cast<size_t>(n - done));
        if (w < 0 && errno == EINTR) continue;
        if (w < 0) throw IoError(fmt::format("cannot write {}: {}", stream.string(), std::strerror(errno)));
        done += w;
      }
    }
    fs::remove(tmp, ec);
  });
}

/// Where a write of `given` goes: the file at the end of its links, or `given` itself when it is
/// written through (a stream, or a path through a process's open files); InputError for a folder.
struct Target {
  fs::path path;
  bool through = false;
};
Target target_of(const fs::path& given) {
  const std::vector<fs::path> chain = link_chain(given);
  const bool open_file = names_open_file(chain);
  Target t{open_file ? given : chain.back(), false};
  std::error_code ec;
  if (fs::is_directory(t.path, ec))
    throw InputError(fmt::format("{} is a folder; give the name of the file to write", given.string()));
  t.through = open_file || is_stream(t.path);
  return t;
}

}  // namespace

/// The temporary file StagedFiles::add is writing in this thread, if any: a writer that writes it
/// through write_atomically writes it in place.
static thread_local const fs::path* staging_path = nullptr;

struct StagedFiles::Entry {
  fs::path path;
  Temporary staged;
  bool placed = false;
};

StagedFiles::StagedFiles() = default;

StagedFiles::~StagedFiles() {
  std::error_code ec;
  for (const Entry& e : entries_)
    if (!e.placed) fs::remove(e.staged.path, ec);
}

void StagedFiles::add_side_by_side(std::span<const FileWriter> writers, const Executor& executor) {
  executor.for_each(writers.size(), [&](size_t i) { add(writers[i].path, writers[i].write); });
}

void StagedFiles::add(const fs::path& given, const std::function<void(const fs::path&)>& write) {
  const Target target = target_of(given);
  if (target.through)
    throw InputError(fmt::format("{} is not a file that can be replaced (a device, pipe or open file); give the path "
                                 "of a file in a folder",
                                 given.string()));
  const fs::path& path = target.path;
  const fs::path parent = path.parent_path();
  std::error_code ec;
  // The folders of a path as given are made; a link's target is where the link says, and a
  // missing folder there is not made up (a dangling link to /nowhere/x.json made /nowhere).
  if (!parent.empty() && path != given && !fs::is_directory(parent, ec))
    throw IoError(fmt::format("cannot write {}: it is a link to {}, whose folder does not exist; make that folder, "
                              "or give another path",
                              given.string(), path.string()));
  if (!parent.empty()) {
    fs::create_directories(parent, ec);
    if (ec)
      throw IoError(fmt::format("cannot write {}: cannot create its folder {} ({}); give a path you can write",
                                path.string(), parent.string(), ec.message()));
  }
  Temporary staged = new_temporary(path);
  with_temporary(staged.path, path, [&] {
    // A writer that writes atomically itself (write_exr, write_png_preview, ...) writes this file
    // in place: its lock stays, and no second temporary name is made.
    const fs::path* outer = staging_path;
    staging_path = &staged.path;
    try {
      write(staged.path);
    } catch (...) {
      staging_path = outer;
      throw;
    }
    staging_path = outer;
    sync_file(staged.path);
  });
  const std::lock_guard<std::mutex> lock(mutex_);
  entries_.push_back(Entry{path, std::move(staged)});
}

void StagedFiles::commit() {
  // An ending signal waits for the renames (a few), so that no set is left half in place by it.
  g_commits.fetch_add(1, std::memory_order_acq_rel);
  struct Resume {
    ~Resume() {
      if (g_commits.fetch_sub(1, std::memory_order_acq_rel) == 1)
        if (const int signal = g_deferred_signal.exchange(0)) ::raise(signal);
    }
  } resume;
  // The marker's earlier file goes before any file is replaced: a run that stops among the renames
  // (killed, or a rename refused) leaves a set without its marker, never new files beside an old
  // marker that lists them as one set.
  if (entries_.size() > 1) {
    try {
      (void)remove_output_file(entries_.back().path);
    } catch (const IoError& e) {
      throw IoError(fmt::format("{}; no file of the set was replaced", e.what()));
    }
  }
  for (size_t k = 0; k < entries_.size(); ++k) {
    Entry& e = entries_[k];
    std::error_code ec;
    fs::rename(e.staged.path, e.path, ec);
    if (!ec) {
      e.placed = true;
      continue;
    }
    const std::string failed =
        fmt::format("cannot write {}: the finished file cannot take its name ({})", e.path.string(), ec.message());
    if (entries_.size() == 1) throw IoError(failed + "; any earlier file of that name is left as it was");
    throw IoError(fmt::format("{}; {} of the set's {} files are in place and the others not, and {} is removed so "
                              "that the set does not look complete: write it again",
                              failed, k, entries_.size(), entries_.back().path.string()));
  }
  // The renames themselves on disk (each file was flushed before).
  std::vector<fs::path> folders;
  for (const Entry& e : entries_)
    if (const fs::path f = folder_of(e.path); std::find(folders.begin(), folders.end(), f) == folders.end())
      folders.push_back(f);
  for (const fs::path& f : folders) sync_folder(f);
  // A retired path the set wrote again stays, also where one of the two names is a link to the
  // other (an entry is placed at its link's target).
  std::vector<fs::path> gone;
  for (const fs::path& r : retired_)
    if (std::none_of(entries_.begin(), entries_.end(), [&](const Entry& e) {
          std::error_code ec;
          return e.path.lexically_normal() == r.lexically_normal() || fs::equivalent(e.path, r, ec);
        }))
      gone.push_back(r);
  discard_output_files(gone);
}

void sync_folder(const fs::path& folder) noexcept {
  const UniqueFd dir(::open(folder.empty() ? "." : folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (dir.valid()) (void)::fsync(dir.get());
}

void StagedFiles::retire(const fs::path& path) {
  const std::lock_guard<std::mutex> lock(mutex_);
  retired_.push_back(path);
}

void remove_temporaries_on_signal() noexcept {
  char name[PATH_MAX];
  for (SignalSlot& slot : g_signal_slots) {
    // A name copied while its slot kept one version (even: whole and registered) is a name some
    // write registered; one taken or released meanwhile is skipped.
    const uint32_t before = slot.version.load(std::memory_order_acquire);
    if ((before & 1u) != 0 || !slot.used.load(std::memory_order_acquire)) continue;
    size_t n = 0;
    while (n + 1 < sizeof name && slot.path[n] != '\0') {
      name[n] = slot.path[n];
      ++n;
    }
    name[n] = '\0';
    std::atomic_thread_fence(std::memory_order_acquire);
    if (slot.version.load(std::memory_order_relaxed) == before) (void)::unlink(name);
  }
}

bool defer_signal_during_commit(int signal) noexcept {
  if (g_commits.load(std::memory_order_acquire) == 0) return false;
  g_deferred_signal.store(signal, std::memory_order_release);
  return true;
}

fs::path follow_links(const fs::path& path) { return link_chain(path).back(); }

bool written_in_place(const fs::path& path) { return target_of(path).through; }

bool remove_output_file(const fs::path& path) {
  if (path.empty() || written_in_place(path)) return false;
  const fs::path file = follow_links(path);
  std::error_code ec;
  if (!fs::is_regular_file(fs::symlink_status(file, ec))) return false;
  if (!fs::remove(file, ec) || ec)
    throw IoError(fmt::format("cannot remove the earlier {}{}: {}; make its folder {} writable or give another path",
                              file.string(), file == path ? "" : fmt::format(" (named by {})", path.string()),
                              ec ? ec.message() : "not removed", folder_of(file).string()));
  return true;
}

void discard_output_files(std::span<const fs::path> paths) noexcept {
  for (const fs::path& p : paths) {
    try {
      (void)remove_output_file(p);
    } catch (const std::exception&) {
    }
  }
}

void write_atomically(const fs::path& given, const std::function<void(const fs::path&)>& write) {
  if (staging_path != nullptr && given == *staging_path) {
    write(given);  // the temporary file of a StagedFiles::add, made and locked there
    return;
  }
  if (target_of(given).through) {
    write_through(given, write);
    return;
  }
  StagedFiles one;
  one.add(given, write);
  one.commit();
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

std::optional<std::string> unwritable_folder(const fs::path& folder) {
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) return fmt::format("cannot create the folder ({})", ec.message());
  if (!fs::is_directory(folder, ec)) return "it is not a folder";
  // A name of its own (mkostemp): threads of one process probe a folder at once (sweep jobs), and
  // a probe a killed run left behind must not make the folder look unwritable.
  std::string probe = (folder / ".stereobench-probe-XXXXXX").string();
  if (!UniqueFd(::mkostemp(probe.data(), O_CLOEXEC)).valid())
    return fmt::format("cannot create a file in it ({})", std::strerror(errno));
  fs::remove(probe, ec);
  return std::nullopt;
}

fs::path outermost_missing_folder(const fs::path& folder) {
  std::error_code ec;
  fs::path missing;
  for (fs::path p = folder.lexically_normal(); !p.empty() && !fs::exists(fs::symlink_status(p, ec)); p = p.parent_path())
    missing = p;
  return missing;
}

void remove_if_no_file(const fs::path& made) {
  if (made.empty()) return;
  std::error_code ec;
  bool holds_a_file = false;
  for (fs::recursive_directory_iterator it(made, ec), end; !ec && it != end && !holds_a_file; it.increment(ec))
    holds_a_file = !it->is_directory(ec);
  if (!ec && !holds_a_file) fs::remove_all(made, ec);
}

std::optional<std::string> folder_cannot_be_made(const fs::path& folder) {
  // Tried, not guessed: an access check lets root pass /proc, where no folder can be made.
  const fs::path made = outermost_missing_folder(folder);
  std::optional<std::string> why = unwritable_folder(folder);
  remove_if_no_file(made);
  return why;
}

std::string read_file(const fs::path& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (fs::is_directory(status))
    throw InputError(fmt::format("{} is a folder, not a file; give the path of the file to read", path.string()));
  // A pipe is read to its end (process substitution, /dev/stdin redirected from a file); a device
  // may never end (/dev/zero) or wait for a terminal.
  if (fs::is_character_file(status) || fs::is_block_file(status) || fs::is_socket(status))
    throw InputError(fmt::format("{} is a device or socket, not a file; give the path of the file to read",
                                 path.string()));
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
