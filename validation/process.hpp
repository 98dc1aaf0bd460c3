// Runs external programs (Blender, POV-Ray, the Slurm client commands, git): an argv without a
// shell, stdin from /dev/null, stdout and stderr captured, merged or discarded,
// and a time limit after which the program's whole process group is stopped.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace sb::validation {

/// For SIGINT, SIGTERM, SIGHUP and SIGQUIT, where their action is still the default (an ignored
/// one stays ignored, as under nohup; another handler stays), installs once a handler that kills
/// the process group of every program running now, removes the temporary files of the writes in
/// progress (io::remove_temporaries_on_signal), and then lets the signal end the process; during
/// the renames of a set of files (io::StagedFiles::commit) it waits for them. Called by main and
/// before every program starts.
void install_stop_handler();

/// Where one of the child's output streams goes.
enum class ChildOutput {
  capture,    ///< into ProcessResult::out (stdout) or ProcessResult::err (stderr)
  to_stdout,  ///< stderr only: into the same pipe as stdout, interleaved as written
  discard,    ///< /dev/null
};

/// How a program runs.
struct ProcessOptions {
  std::filesystem::path cwd;                                ///< working folder; empty: this process's
  std::vector<std::pair<std::string, std::string>> set_env;  ///< variables added or overridden
  std::vector<std::string> unset_env;                        ///< variables removed
  ChildOutput stdout_to = ChildOutput::capture;
  ChildOutput stderr_to = ChildOutput::capture;
  /// Wall-clock limit; zero: none. When it passes, the process group gets SIGTERM, and SIGKILL
  /// `kill_grace` later if anything in it is still alive.
  std::chrono::milliseconds timeout{0};
  std::chrono::milliseconds kill_grace{2000};
};

/// The shell command that runs `argv` as run_process does with `options`, every word quoted: its
/// folder (cd), the variables it removes and sets (env -u, K=V), then the program and its
/// arguments. For records and messages that say how to run a tool again by hand.
[[nodiscard]] std::string shell_command(const std::vector<std::string>& argv, const ProcessOptions& options);

/// How a program ended and what it wrote.
struct ProcessResult {
  int exit_code = -1;      ///< the exit status; -1 when a signal ended it
  int signal = 0;          ///< the signal that ended it, or 0
  bool timed_out = false;  ///< stopped because ProcessOptions::timeout passed
  std::string out;         ///< captured stdout (with stderr when ChildOutput::to_stdout)
  std::string err;         ///< captured stderr
  double seconds = 0.0;    ///< wall-clock time from start to end
  int pid = -1;            ///< the child's process id (and process group id), reaped on return

  /// Exited by itself with status 0.
  [[nodiscard]] bool ok() const { return !timed_out && signal == 0 && exit_code == 0; }
  /// "exited with code 2", "was killed by signal 9 (Killed)", "did not finish within 30 s and
  /// was stopped".
  [[nodiscard]] std::string describe() const;
};

/// Runs `argv` (argv[0]: a path, or a name looked up on PATH) and waits for it, reading both
/// output pipes as they fill. The child leads its own process group; after it ends, whatever it
/// left running in that group is killed, so no descendant outlives the call (one that moved to
/// another group or session is out of reach). The child gets SIGKILL when this process dies,
/// even by a SIGKILL that no handler sees (the OOM killer, `kill -9`). If the call ends by an exception, the group is
/// killed and the child reaped before it propagates. ToolError when the program cannot be found
/// or started, or the working folder does not exist.
[[nodiscard]] ProcessResult run_process(const std::vector<std::string>& argv, const ProcessOptions& options = {});

/// `name` as a shell finds a command: itself when it holds a slash, else the first executable
/// regular file `<dir>/<name>` along $PATH (empty entries are skipped); nullopt when none.
[[nodiscard]] std::optional<std::filesystem::path> find_program(const std::string& name);

/// The last `count` non-empty lines of a tool's output, each on a line of its own as "  | LINE",
/// for quoting at the end of a message ("  | (no output)" when it printed nothing).
[[nodiscard]] std::string quoted_output(const std::string& text, std::size_t count);

/// Writes an external render's output to `log` (atomically). When the render failed, its own
/// failure is the error to report: a log that cannot be written (a full disk, which may be why it
/// failed) is then no error, and what is returned says so ("" when it was written). When it
/// succeeded, an unwritable log is an IoError as any output is.
[[nodiscard]] std::string keep_tool_output(const std::filesystem::path& log, const std::string& output,
                                           bool render_failed);

/// For the message about a failed external render: a note that the disk of `folder` has fewer than
/// `needed` bytes free (the render's images may not have fit), naming the free bytes and what to do;
/// "" when it has room or cannot be asked.
[[nodiscard]] std::string low_disk_note(const std::filesystem::path& folder, std::uintmax_t needed);

/// The environment variable that sets the time limit of one external ground-truth render.
inline constexpr const char* kToolTimeoutVariable = "STEREOBENCH_TOOL_TIMEOUT";
/// The limit without it: 30 minutes. Renders take seconds (Blender 3-24 s, POV-Ray 1-10 s at
/// 640x360 on a 2-core machine, docs/ground_truth.md); even 4K with many lights stays far below.
inline constexpr std::chrono::seconds kDefaultToolTimeout{30 * 60};

/// The limit of a short command: a tool asked for its version, a Slurm command talking to the
/// controller, git asked for the revision.
inline constexpr std::chrono::seconds kShortCommandTimeout{120};

/// The time limit of one external render: $STEREOBENCH_TOOL_TIMEOUT (seconds, a decimal number;
/// 0 turns the limit off), else kDefaultToolTimeout. InputError naming the variable and its value
/// when it is not a number of seconds >= 0.
[[nodiscard]] std::chrono::milliseconds tool_timeout();

/// The end of the message about a render that ran past tool_timeout(): how to allow it more.
[[nodiscard]] std::string tool_timeout_hint();

/// "30 min", "2 s", "1.5 s": a limit as a message shows it.
[[nodiscard]] std::string format_limit(std::chrono::milliseconds limit);

}  // namespace sb::validation
