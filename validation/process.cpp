// Runs external programs with clone (CLONE_VM | CLONE_VFORK, as posix_spawn does) and exec: the
// child leads its own process group and dies with the thread that started it, both output pipes
// are drained with poll(), and a time limit stops the whole group (SIGTERM, then SIGKILL).
#include "validation/process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <deque>
#include <mutex>
#include <string_view>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/unique_fd.hpp"
#include "renderer/text.hpp"

extern char** environ;

namespace sb::validation {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

/// Signals an ignoring parent would pass on through exec; the child gets their default actions
/// (SIGTERM must be able to stop it, SIGPIPE to end a writer whose reader is gone).
constexpr std::array kDefaultedSignals = {SIGPIPE, SIGINT,  SIGQUIT, SIGTERM, SIGHUP,  SIGALRM,
                                          SIGUSR1, SIGUSR2, SIGCHLD, SIGTSTP, SIGTTIN, SIGTTOU};

/// A pipe whose ends are close-on-exec (no other child started meanwhile inherits them) and
/// above 0..2, so that dup2 onto the child's stdout or stderr always makes a fresh descriptor.
void open_pipe(io::UniqueFd& read_end, io::UniqueFd& write_end, const std::string& program) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0)
    throw ToolError(fmt::format("cannot create a pipe to run {}: {}", program, std::strerror(errno)));
  read_end.reset(fds[0]);
  write_end.reset(fds[1]);
  for (io::UniqueFd* end : {&read_end, &write_end}) {
    if (end->get() > 2) continue;
    const int moved = ::fcntl(end->get(), F_DUPFD_CLOEXEC, 3);
    if (moved < 0) throw ToolError(fmt::format("cannot create a pipe to run {}: {}", program, std::strerror(errno)));
    end->reset(moved);
  }
}

/// The process groups of the children running now, one per slot (0: free), for the handler
/// below: a stereobench stopped by Ctrl-C, `kill` or a Slurm job's end takes its tools with it
/// instead of leaving Blender or POV-Ray rendering into a work folder no one reads.
std::array<std::atomic<pid_t>, 256> g_running{};
static_assert(std::atomic<pid_t>::is_always_lock_free, "the signal handler needs lock-free slots");

/// SIGINT, SIGTERM, SIGHUP, SIGQUIT: kill every running child's group and remove the temporary
/// files of the writes in progress, then end as the signal's default action would (the exit
/// status still says which signal it was). Async-signal-safe.
extern "C" void stop_children_and_end(int sig) {
  if (io::defer_signal_during_commit(sig)) return;  // raised again once the set is in place
  for (std::atomic<pid_t>& slot : g_running)
    if (const pid_t group = slot.load(); group > 0) ::kill(-group, SIGKILL);
  io::remove_temporaries_on_signal();
  ::signal(sig, SIG_DFL);
  ::raise(sig);  // delivered when the handler returns
}

/// The spawned child until it is reaped: an exception kills its group and reaps it. While it
/// runs, its group is listed for stop_children_and_end.
class ChildGuard {
 public:
  ChildGuard() = default;
  ChildGuard(const ChildGuard&) = delete;
  ChildGuard& operator=(const ChildGuard&) = delete;
  ~ChildGuard() {
    if (pid_ <= 0) return;
    ::kill(-pid_, SIGKILL);
    unlist();
    int status = 0;
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    pid_ = -1;
  }
  /// Takes charge of the child `pid`, the leader of its own process group.
  void adopt(pid_t pid) {
    pid_ = pid;
    for (std::atomic<pid_t>& slot : g_running) {
      pid_t free = 0;
      if (slot.compare_exchange_strong(free, pid)) return;
    }
  }
  /// Takes the child off the list for stop_children_and_end, before it is reaped: once reaped,
  /// its process group id may name another group.
  void unlist() {
    const int saved = errno;
    for (std::atomic<pid_t>& slot : g_running) {
      pid_t mine = pid_;
      if (mine > 0 && slot.compare_exchange_strong(mine, 0)) break;
    }
    errno = saved;
  }
  /// The child is lost (reaped by someone else): it is no longer listed or waited for.
  void forget() {
    unlist();
    pid_ = -1;
  }
  [[nodiscard]] pid_t pid() const { return pid_; }

 private:
  pid_t pid_ = -1;  ///< the child (and its process group), -1 once reaped
};

/// What the child does between its start and exec, all prepared before: the child shares this
/// process's memory until it execs (CLONE_VM), so it only makes system calls and touches no lock.
struct ChildSetup {
  const char* executable = nullptr;
  char* const* argv = nullptr;
  char* const* envp = nullptr;
  const char* cwd = nullptr;  ///< nullptr: stay in this process's folder
  int stdout_fd = -1;         ///< a pipe's write end, or -1 for /dev/null
  int stderr_fd = -1;         ///< a pipe's write end, -1 for /dev/null
  bool stderr_to_stdout = false;
  pid_t parent = 0;
  int error_fd = -1;  ///< close-on-exec: the errno of a failed step is written here
};

/// The child (started by clone with CLONE_VM | CLONE_VFORK, as posix_spawn starts one, so nothing
/// of this process's memory is copied): its own process group; SIGKILL when the thread that
/// started it ends, so a stereobench killed outright (SIGKILL, which no handler sees) does not
/// leave Blender or POV-Ray rendering on; every caught signal and the defaulted ones back to their
/// default action, then an empty mask; stdin from /dev/null and the output streams; the working
/// folder; then exec. Never returns: a failed step writes its errno to error_fd and exits 127.
int become_child(void* arg) {
  const ChildSetup& c = *static_cast<const ChildSetup*>(arg);
  const auto fail = [&c]() {
    const int step_errno = errno;
    [[maybe_unused]] const ssize_t w = ::write(c.error_fd, &step_errno, sizeof step_errno);
    ::_exit(127);
  };
  if (::setpgid(0, 0) != 0) fail();
  if (::prctl(PR_SET_PDEATHSIG, SIGKILL) != 0) fail();
  if (::getppid() != c.parent) ::_exit(127);  // the parent ended before the line above
  // Handlers first, then the mask (the parent blocked every signal around the start): a signal
  // held back must not run one of this process's handlers in the child, which shares its memory.
  struct sigaction defaulted {};
  defaulted.sa_handler = SIG_DFL;
  sigemptyset(&defaulted.sa_mask);
  for (int sig = 1; sig < NSIG; ++sig) {
    struct sigaction now {};
    if (::sigaction(sig, nullptr, &now) != 0) continue;  // a signal number the kernel does not use
    const bool caught = (now.sa_flags & SA_SIGINFO) != 0 || (now.sa_handler != SIG_DFL && now.sa_handler != SIG_IGN);
    if (caught) ::sigaction(sig, &defaulted, nullptr);
  }
  for (const int sig : kDefaultedSignals) ::sigaction(sig, &defaulted, nullptr);
  sigset_t none;
  sigemptyset(&none);
  if (::sigprocmask(SIG_SETMASK, &none, nullptr) != 0) fail();
  // /dev/null without close-on-exec: where this process runs with a standard descriptor closed,
  // open() returns that very number, and dup2 onto itself would leave the flag set.
  const auto null_onto = [&fail](int target, int flags) {
    const int fd = ::open("/dev/null", flags);
    if (fd < 0 || ::dup2(fd, target) < 0) fail();
    if (fd != target) ::close(fd);
  };
  null_onto(0, O_RDONLY);
  if (c.stdout_fd >= 0) {
    if (::dup2(c.stdout_fd, 1) < 0) fail();
  } else {
    null_onto(1, O_WRONLY);
  }
  if (c.stderr_fd >= 0) {
    if (::dup2(c.stderr_fd, 2) < 0) fail();
  } else if (c.stderr_to_stdout) {
    if (::dup2(1, 2) < 0) fail();
  } else {
    null_onto(2, O_WRONLY);
  }
  if (c.cwd != nullptr && ::chdir(c.cwd) != 0) fail();
  ::execve(c.executable, c.argv, c.envp);
  fail();
  return 127;  // not reached: fail() exits
}

/// The child's own stack while it shares this process's memory (it runs become_child on it until
/// exec): system calls only, so a little is plenty.
constexpr size_t kChildStackBytes = 64 * 1024;

/// Reads what the child wrote to its error pipe before exec: 0 when exec succeeded (the pipe
/// closed on exec), else the errno of the step that failed.
int child_start_error(int read_fd) {
  int err = 0;
  for (;;) {
    const ssize_t n = ::read(read_fd, &err, sizeof err);
    if (n < 0 && errno == EINTR) continue;
    return n == static_cast<ssize_t>(sizeof err) ? err : 0;
  }
}

/// This process's environment with `options`' changes applied, as "NAME=value" strings.
std::vector<std::string> child_environment(const ProcessOptions& options) {
  const auto changed = [&](std::string_view key) {
    return std::any_of(options.set_env.begin(), options.set_env.end(), [&](const auto& kv) { return kv.first == key; }) ||
           std::find(options.unset_env.begin(), options.unset_env.end(), key) != options.unset_env.end();
  };
  std::vector<std::string> env;
  for (char** e = environ; e != nullptr && *e != nullptr; ++e) {
    const std::string_view entry(*e);
    if (!changed(entry.substr(0, entry.find('=')))) env.emplace_back(entry);
  }
  for (const auto& [key, value] : options.set_env) {
    if (key.empty() || key.find('=') != std::string::npos)
      throw InputError(fmt::format("'{}' is not an environment variable name", key));
    env.push_back(key + "=" + value);
  }
  return env;
}

bool is_executable_file(const fs::path& p) {
  struct stat st {};
  return ::stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(p.c_str(), X_OK) == 0;
}

/// Whether the child has ended, without reaping it: the zombie keeps its process group id
/// reserved, so the group can still be signalled safely. ToolError when the child is gone (reaped
/// by someone else, e.g. under SIGCHLD ignored); the guard then forgets it.
bool has_ended(ChildGuard& child, const std::string& program) {
  siginfo_t info{};
  info.si_pid = 0;
  if (::waitid(P_PID, static_cast<id_t>(child.pid()), &info, WEXITED | WNOHANG | WNOWAIT) != 0) {
    if (errno == EINTR) return false;
    const pid_t pid = child.pid();
    child.forget();
    throw ToolError(fmt::format("lost track of {} (pid {}): {}", program, pid, std::strerror(errno)));
  }
  return info.si_pid != 0;
}

/// A descriptor that becomes readable when `pid` ends (Linux 5.3 and newer), or -1.
int open_pid_fd(pid_t pid) {
#ifdef SYS_pidfd_open
  const long fd = ::syscall(SYS_pidfd_open, pid, 0);
  if (fd >= 0) {
    ::fcntl(static_cast<int>(fd), F_SETFD, FD_CLOEXEC);
    return static_cast<int>(fd);
  }
#else
  (void)pid;
#endif
  return -1;
}

}  // namespace

void install_stop_handler() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (const int sig : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) {
      struct sigaction current {};
      if (::sigaction(sig, nullptr, &current) != 0 || (current.sa_flags & SA_SIGINFO) != 0 ||
          current.sa_handler != SIG_DFL)
        continue;
      struct sigaction stop {};
      stop.sa_handler = stop_children_and_end;
      sigemptyset(&stop.sa_mask);
      ::sigaction(sig, &stop, nullptr);
    }
  });
}


std::string ProcessResult::describe() const {
  if (timed_out) return "did not finish within its time limit and was stopped";
  if (signal != 0) return fmt::format("was killed by signal {} ({})", signal, ::strsignal(signal));
  return fmt::format("exited with code {}", exit_code);
}

std::optional<fs::path> find_program(const std::string& name) {
  if (name.empty()) return std::nullopt;
  if (name.find('/') != std::string::npos) {
    if (is_executable_file(name)) return fs::path(name);
    return std::nullopt;
  }
  const char* path_env = std::getenv("PATH");
  std::string_view path = path_env != nullptr ? path_env : "";
  while (!path.empty()) {
    const size_t colon = path.find(':');
    const std::string_view dir = path.substr(0, colon);
    if (!dir.empty()) {
      fs::path candidate = fs::path(std::string(dir)) / name;
      if (is_executable_file(candidate)) return candidate;
    }
    if (colon == std::string_view::npos) break;
    path.remove_prefix(colon + 1);
  }
  return std::nullopt;
}

std::string shell_command(const std::vector<std::string>& argv, const ProcessOptions& options) {
  std::string out;
  if (!options.cwd.empty()) out += "cd " + shell_quote(options.cwd.string()) + " && ";
  if (!options.unset_env.empty() || !options.set_env.empty()) {
    out += "env";
    for (const std::string& u : options.unset_env) out += " -u " + u;
    for (const auto& [k, v] : options.set_env) out += " " + k + "=" + shell_quote(v);
    out += " ";
  }
  for (size_t i = 0; i < argv.size(); ++i) out += (i > 0 ? " " : "") + shell_quote(argv[i]);
  return out;
}

ProcessResult run_process(const std::vector<std::string>& argv, const ProcessOptions& options) {
  if (argv.empty() || argv[0].empty()) throw InputError("run_process: no program to run");
  const std::string& program = argv[0];
  const std::optional<fs::path> found = find_program(program);
  if (!found)
    throw ToolError(program.find('/') != std::string::npos
                        ? fmt::format("cannot start '{}': it does not exist or is not an executable file", program)
                        : fmt::format("cannot start '{}': not found on PATH", program));
  // A relative path names a file relative to this process's folder, not the child's.
  std::error_code ec;
  const fs::path executable = options.cwd.empty() ? *found : fs::absolute(*found, ec);
  if (!options.cwd.empty() && !fs::is_directory(options.cwd, ec))
    throw ToolError(fmt::format("cannot start '{}' in '{}': no such folder", program, options.cwd.string()));
  if (options.stdout_to == ChildOutput::to_stdout)
    throw InputError("run_process: ChildOutput::to_stdout is for stderr only");

  std::vector<std::string> env_strings = child_environment(options);
  std::vector<char*> envp;
  envp.reserve(env_strings.size() + 1);
  for (std::string& s : env_strings) envp.push_back(s.data());
  envp.push_back(nullptr);
  std::vector<std::string> arg_strings = argv;
  std::vector<char*> args;
  args.reserve(arg_strings.size() + 1);
  for (std::string& a : arg_strings) args.push_back(a.data());
  args.push_back(nullptr);

  // Pipes: [0] stdout (with stderr when merged), [1] stderr.
  std::array<io::UniqueFd, 2> read_ends, write_ends;
  const bool capture_out = options.stdout_to == ChildOutput::capture;
  const bool merged = options.stderr_to == ChildOutput::to_stdout;
  const bool capture_err = options.stderr_to == ChildOutput::capture;
  if (capture_out) open_pipe(read_ends[0], write_ends[0], program);
  if (capture_err) open_pipe(read_ends[1], write_ends[1], program);

  const std::string cwd = options.cwd.string();
  io::UniqueFd error_read, error_write;  // the child's errno when a step before exec fails
  open_pipe(error_read, error_write, program);
  ChildSetup setup;
  setup.executable = executable.c_str();
  setup.argv = args.data();
  setup.envp = envp.data();
  setup.cwd = cwd.empty() ? nullptr : cwd.c_str();
  setup.stdout_fd = capture_out ? write_ends[0].get() : -1;
  setup.stderr_fd = capture_err ? write_ends[1].get() : -1;
  setup.stderr_to_stdout = merged;
  setup.parent = ::getpid();
  setup.error_fd = error_write.get();

  install_stop_handler();
  ChildGuard child;
  const Clock::time_point start = Clock::now();
  // Every signal waits while the child is made and listed: a stop signal in between would leave
  // it running unlisted, and any handler would run in the child, which shares this memory until
  // it execs. (The child defaults the handlers and unblocks before exec.)
  std::vector<char> child_stack(kChildStackBytes);
  sigset_t all_signals, before;
  sigfillset(&all_signals);
  ::pthread_sigmask(SIG_BLOCK, &all_signals, &before);
  // Returns once the child has exec'd or exited (CLONE_VFORK); the stack grows down from its end.
  const pid_t pid = ::clone(become_child, child_stack.data() + child_stack.size(), CLONE_VM | CLONE_VFORK | SIGCHLD,
                            &setup);
  const int fork_error = pid < 0 ? errno : 0;
  if (pid > 0) child.adopt(pid);
  ::pthread_sigmask(SIG_SETMASK, &before, nullptr);
  error_write.reset();
  // Returns once the child has exec'd (its copy of the pipe closes) or failed before: by then it
  // leads its own group, so the group may be signalled.
  const int spawn_error = pid > 0 ? child_start_error(error_read.get()) : fork_error;
  if (spawn_error != 0)
    throw ToolError(fmt::format("cannot start '{}'{}: {}", executable.string(),
                                cwd.empty() ? "" : fmt::format(" in '{}'", cwd), std::strerror(spawn_error)));
  for (io::UniqueFd& w : write_ends) w.reset();  // the child holds its own copies: EOF comes when it closes them
  const io::UniqueFd pid_fd(open_pid_fd(pid));

  ProcessResult result;
  result.pid = pid;
  std::array<std::string*, 2> sinks{&result.out, &result.err};
  std::array<pollfd, 3> fds{pollfd{read_ends[0].get(), POLLIN, 0}, pollfd{read_ends[1].get(), POLLIN, 0},
                            pollfd{pid_fd.get(), POLLIN, 0}};
  std::array<char, 65536> buffer{};
  // A moment not (yet) set is kNever.
  constexpr Clock::time_point kNever = Clock::time_point::max();
  const Clock::time_point deadline = options.timeout.count() > 0 ? start + options.timeout : kNever;
  Clock::time_point kill_at = kNever;     // SIGKILL after the SIGTERM of a timeout
  Clock::time_point linger_end = kNever;  // the child has ended: how long its pipes may stay open
  bool ended = false, killed = false;
  for (;;) {
    const Clock::time_point now = Clock::now();
    if (!ended && has_ended(child, program)) {
      ended = true;
      linger_end = now + options.kill_grace;
      fds[2].fd = -1;
    }
    const bool pipes_open = fds[0].fd >= 0 || fds[1].fd >= 0;
    // Done when the child has ended and its pipes are closed; a descendant that still holds
    // them open gets kill_grace to finish writing before the group is killed below.
    if (ended && (!pipes_open || now >= linger_end)) break;
    if (!ended && now >= deadline && !result.timed_out) {
      result.timed_out = true;
      ::kill(-pid, SIGTERM);
      kill_at = now + options.kill_grace;
    }
    if (!ended && now >= kill_at && !killed) {
      killed = true;
      ::kill(-pid, SIGKILL);
    }

    // Sleep until output arrives, the child ends, or the next deadline; without a pid fd the
    // end of the child is noticed by looking every 100 ms (10 ms once its pipes are closed).
    Clock::time_point wake = linger_end;
    if (!ended) {
      if (!result.timed_out) wake = std::min(wake, deadline);
      if (!killed) wake = std::min(wake, kill_at);
      if (pid_fd.get() < 0) wake = std::min(wake, now + std::chrono::milliseconds(pipes_open ? 100 : 10));
    }
    int wait_ms = -1;
    if (wake != kNever) {
      const auto ms = std::chrono::ceil<std::chrono::milliseconds>(wake - now).count();
      wait_ms = static_cast<int>(std::clamp<long long>(ms, 0, 60'000));
    }
    if (::poll(fds.data(), fds.size(), wait_ms) < 0) {
      if (errno == EINTR) continue;
      throw ToolError(fmt::format("cannot read the output of {}: poll failed: {}", program, std::strerror(errno)));
    }
    for (size_t i = 0; i < 2; ++i) {
      if (fds[i].fd < 0 || (fds[i].revents & (POLLIN | POLLHUP | POLLERR)) == 0) continue;
      const ssize_t n = ::read(fds[i].fd, buffer.data(), buffer.size());
      if (n > 0) {
        sinks[i]->append(buffer.data(), static_cast<size_t>(n));
      } else if (n == 0 || (errno != EINTR && errno != EAGAIN)) {
        read_ends[i].reset();
        fds[i].fd = -1;
      }
    }
  }

  // Whatever the child left running in its group goes with it; then the zombie is reaped.
  ::kill(-pid, SIGKILL);
  child.unlist();
  for (io::UniqueFd& r : read_ends) r.reset();
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      child.forget();
      throw ToolError(fmt::format("lost track of {} (pid {}): {}", program, pid, std::strerror(errno)));
    }
  }
  child.forget();
  result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (WIFEXITED(status)) {
    result.exit_code = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    result.signal = WTERMSIG(status);
  }
  return result;
}

std::chrono::milliseconds tool_timeout() {
  const char* value = std::getenv(kToolTimeoutVariable);
  if (value == nullptr || *value == '\0') return kDefaultToolTimeout;
  char* end = nullptr;
  errno = 0;
  const double seconds = std::strtod(value, &end);
  // At most ten years: beyond that the limit means nothing and milliseconds could overflow.
  constexpr double kMaxSeconds = 10.0 * 365 * 24 * 3600;
  if (end == value || *end != '\0' || errno != 0 || !std::isfinite(seconds) || seconds < 0.0 || seconds > kMaxSeconds ||
      std::isspace(static_cast<unsigned char>(*value)) || std::strpbrk(value, "xX") != nullptr)  // decimal only
    throw InputError(fmt::format("{}='{}' is not a time limit: give the seconds one external render may take (e.g. "
                                 "{}=3600), or 0 for no limit; unset it for the default of {}",
                                 kToolTimeoutVariable, value, kToolTimeoutVariable, format_limit(kDefaultToolTimeout)));
  if (seconds == 0.0) return std::chrono::milliseconds(0);
  return std::chrono::milliseconds(std::max(1LL, std::llround(seconds * 1000.0)));
}

std::string tool_timeout_hint() {
  const char* value = std::getenv(kToolTimeoutVariable);
  const std::string now = value != nullptr && *value != '\0' ? fmt::format("{}={}", kToolTimeoutVariable, value)
                                                               : fmt::format("the default, {} unset", kToolTimeoutVariable);
  return fmt::format("if it is only slow, allow more with {}=<seconds> (0: no limit; now {})", kToolTimeoutVariable,
                     now);
}

std::string format_limit(std::chrono::milliseconds limit) {
  const long long ms = limit.count();
  if (ms % 60'000 == 0 && ms >= 60'000) return fmt::format("{} min", ms / 60'000);
  if (ms % 1000 == 0) return fmt::format("{} s", ms / 1000);
  return fmt::format("{:g} s", static_cast<double>(ms) / 1000.0);
}

std::string keep_tool_output(const std::filesystem::path& log, const std::string& output, bool render_failed) {
  try {
    io::write_text_atomically(log, output);
    return "";
  } catch (const Error& e) {
    if (!render_failed) throw;
    return fmt::format(" (its output could not be kept: {})", e.what());
  }
}

std::string low_disk_note(const std::filesystem::path& folder, std::uintmax_t needed) {
  struct statvfs fs_info {};
  if (::statvfs(folder.c_str(), &fs_info) != 0) return "";
  const std::uintmax_t free_bytes = static_cast<std::uintmax_t>(fs_info.f_bavail) * fs_info.f_frsize;
  if (free_bytes >= needed) return "";
  return fmt::format("; the disk of {} has {} bytes free where the render needs about {}: make room there, or work on "
                     "another disk",
                     folder.string(), free_bytes, needed);
}

std::string quoted_output(const std::string& text, std::size_t count) {
  std::deque<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    lines.push_back(line);
    if (lines.size() > count) lines.pop_front();
  }
  std::string out;
  for (const std::string& l : lines) out += "\n  | " + l;
  return out.empty() ? "\n  | (no output)" : out;
}

}  // namespace sb::validation
