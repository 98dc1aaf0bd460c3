// Atomic output: every file the suite writes goes to a temporary name beside its final one and is
// renamed into place only when complete, so an interrupted run never leaves a partial file under
// the final name.
#pragma once

#include <filesystem>
#include <functional>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "renderer/parallel.hpp"

namespace sb::io {

/// Calls `write(tmp_path)` to produce the file under a temporary name in the same folder, then
/// flushes it to disk and renames it to `path`. Creates missing parent folders. On any failure
/// (including an exception from `write`) the temporary file is removed and IoError is thrown
/// naming `path`; an existing file at `path` is left untouched. A symbolic link at `path` is
/// followed (the file it names is replaced, the link stays). A device or pipe there, and a path
/// through a process's open files (/dev/stdout, /dev/fd/N, /proc/self/fd/N, also when the shell
/// redirected them into a file), is not replaced: the file is made in the temporary folder and its
/// bytes appended there; a write error is still IoError. A folder at `path` is an InputError.
/// The temporary file (.FILE.tmp-PID-N; for a stream, in the temporary folder and named after the
/// stream) is locked (flock) while the write runs; temporary files of the same name that no write
/// holds (left by a killed process) are removed first.
void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path& tmp_path)>& write);

/// Files written as one set. add() makes each file whole under its temporary name beside its
/// final one (as write_atomically does; a folder, device, pipe or open-file path is refused with an
/// InputError), commit() then renames them into place in the order they were added. Until commit
/// nothing at the final names changes, so a failure while adding (a full disk) leaves an earlier
/// set as it was; a set destroyed uncommitted removes its temporary files. add() may be called
/// from several threads at once (each file is written by the thread that adds it). The file added
/// last is the set's marker (a stats or summary file that says the set is complete): placed last,
/// and removed should the set end up half in place.
/// A file to write: its final path and the function that writes it to a given (temporary) path.
struct FileWriter {
  std::filesystem::path path;
  std::function<void(const std::filesystem::path&)> write;
};

class StagedFiles {
 public:
  StagedFiles();
  ~StagedFiles();
  StagedFiles(const StagedFiles&) = delete;
  StagedFiles& operator=(const StagedFiles&) = delete;

  /// Calls `write(tmp_path)` and flushes the file; on failure its temporary file is removed and
  /// the error passed on (IoError naming `path` for an untyped one).
  void add(const std::filesystem::path& path, const std::function<void(const std::filesystem::path& tmp_path)>& write);
  /// add() for every writer, side by side on `executor`'s threads (each file's bytes are its own
  /// writer's, whatever the thread). A failure cancels the writers not yet started and is passed on
  /// once the running ones have finished. Not for the marker, which is added alone, last.
  void add_side_by_side(std::span<const FileWriter> writers, const Executor& executor);
  /// An earlier file of the set: removed once the set is in place (best effort), never before,
  /// unless the set writes it again (added under the same path).
  void retire(const std::filesystem::path& path);
  /// Removes the earlier file of the marker (the file added last; its links followed) when the set
  /// has more than one file, then renames every file added into place, in order, the marker last,
  /// then removes the retired ones. So a set whose marker is in place is whole, whenever the run
  /// stopped. IoError when the marker's earlier file cannot be removed (nothing is replaced), or
  /// at the first rename that fails (the message says how many files are in place); the others'
  /// temporaries are removed with the set.
  void commit();

 private:
  struct Entry;
  std::mutex mutex_;  ///< guards entries_ while files are added side by side
  std::vector<Entry> entries_;
  std::vector<std::filesystem::path> retired_;
};

/// Whether write_atomically writes `path` in place (a device, pipe or socket, or a path through a
/// process's open files) rather than replacing a file there.
[[nodiscard]] bool written_in_place(const std::filesystem::path& path);

/// Removes the file an earlier run wrote at output path `path`: the regular file it names (its
/// links followed; the links stay), never a device, pipe or open-file path, which are written in
/// place. Whether there was one to remove; IoError when it could not be removed.
bool remove_output_file(const std::filesystem::path& path);

/// remove_output_file for each of the files a run wrote before it failed, best effort: one that
/// cannot be removed is skipped (the run's own error is the one to report).
void discard_output_files(std::span<const std::filesystem::path> paths) noexcept;

/// Removes the temporary files of the writes now in progress (interrupted, they would stay as
/// hidden .FILE.tmp-PID-N files until a later write of the same file). Async-signal-safe: called
/// by the handler of the ending signals (validation::install_stop_handler), which then lets the
/// signal end the process.
void remove_temporaries_on_signal() noexcept;

/// For the same handler: while a StagedFiles::commit runs, records `signal` to be raised again
/// when the commit ends and returns true (the handler returns at once); otherwise false.
/// Async-signal-safe.
[[nodiscard]] bool defer_signal_during_commit(int signal) noexcept;

/// The file a path names, its symbolic links followed (a dangling link gives the file it would
/// create); `path` itself when it is no link. IoError for a loop of links.
[[nodiscard]] std::filesystem::path follow_links(const std::filesystem::path& path);

/// Flushes a folder's entries to disk (the renames into it), best effort: a folder that cannot be
/// opened or flushed is passed over.
void sync_folder(const std::filesystem::path& folder) noexcept;

/// Writes bytes atomically (see write_atomically).
void write_file_atomically(const std::filesystem::path& path, std::span<const unsigned char> bytes);
/// Writes text atomically (see write_atomically).
void write_text_atomically(const std::filesystem::path& path, const std::string& text);

/// Makes `folder` (and its parents) and makes and removes a probe file in it, so that
/// permissions, a read-only mount or a pseudo file system show before work whose results go there,
/// not when the first is written. Why the folder cannot be written, or nothing.
[[nodiscard]] std::optional<std::string> unwritable_folder(const std::filesystem::path& folder);

/// Why `folder` could not be made or written, as unwritable_folder finds, leaving nothing behind:
/// the folders it makes for the probe are removed again. For a check before the work, so that a
/// run refused later leaves no empty folder; nothing when it can be.
[[nodiscard]] std::optional<std::string> folder_cannot_be_made(const std::filesystem::path& folder);

/// The first of a path's folders, from the outside in, that does not exist (what making the path
/// makes first); empty when the path exists.
[[nodiscard]] std::filesystem::path outermost_missing_folder(const std::filesystem::path& folder);

/// Removes `made`, a folder a run made, with the folders below it, when no file lies in it at any
/// depth (best effort): a run that stops before writing leaves no empty folder. Nothing for "".
void remove_if_no_file(const std::filesystem::path& made);

/// Reads a whole file, or a pipe to its end; InputError for a folder or a device (which may never
/// end), IoError naming the path if it cannot be read.
[[nodiscard]] std::string read_file(const std::filesystem::path& path);

}  // namespace sb::io
