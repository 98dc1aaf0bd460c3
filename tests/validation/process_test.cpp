// The process runner (validation/process.hpp): captured, merged and discarded output, exit status
// and signals, working folder and environment, missing programs, and time limits that stop the
// child's whole process group, grandchildren included.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "renderer/error.hpp"
#include "support/scoped_env.hpp"
#include "support/scratch_dir.hpp"
#include "validation/process.hpp"

namespace sb::validation {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// The state letter of /proc/<pid>/stat ('R', 'S', 'Z', ...), or 0 when there is no such process.
char process_state(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text;
  if (!std::getline(in, text)) return 0;
  const size_t paren = text.rfind(')');  // the command name may hold blanks and parentheses
  return paren != std::string::npos && paren + 2 < text.size() ? text[paren + 2] : 0;
}

/// Whether `pid` is alive: it exists and is not a zombie waiting for its parent.
bool is_alive(pid_t pid) {
  const char state = process_state(pid);
  return state != 0 && state != 'Z' && state != 'X';
}

/// Live processes whose process group is `pgid`.
std::vector<pid_t> live_group_members(pid_t pgid) {
  std::vector<pid_t> members;
  for (const fs::directory_entry& e : fs::directory_iterator("/proc")) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream in(e.path() / "stat");
    std::string text;
    if (!std::getline(in, text)) continue;
    const size_t paren = text.rfind(')');
    if (paren == std::string::npos) continue;
    std::istringstream fields(text.substr(paren + 2));
    char state = 0;
    long ppid = 0, pgrp = 0;
    if (fields >> state >> ppid >> pgrp && pgrp == pgid && state != 'Z' && state != 'X')
      members.push_back(static_cast<pid_t>(std::stol(name)));
  }
  return members;
}

/// Waits up to `limit` for `pid` to stop being alive.
bool dies_within(pid_t pid, std::chrono::milliseconds limit) {
  const auto end = Clock::now() + limit;
  while (is_alive(pid)) {
    if (Clock::now() > end) return false;
    std::this_thread::sleep_for(10ms);
  }
  return true;
}

/// The child is reaped (no zombie left) and nothing of its process group lives on. A killed
/// process closes its files (which ends the run) a moment before it becomes a zombie, so the
/// group gets a second to finish dying; one that was never stopped would sleep on for 100 s.
void expect_nothing_left(const ProcessResult& r) {
  ASSERT_GT(r.pid, 0);
  errno = 0;
  EXPECT_EQ(::waitpid(r.pid, nullptr, WNOHANG), -1) << "the child was not reaped";
  EXPECT_EQ(errno, ECHILD);
  const auto end = Clock::now() + 1s;
  std::vector<pid_t> left = live_group_members(r.pid);
  while (!left.empty() && Clock::now() < end) {
    std::this_thread::sleep_for(10ms);
    left = live_group_members(r.pid);
  }
  for (pid_t p : left)
    ADD_FAILURE() << "process " << p << " (state " << process_state(p) << ") of the child's group outlived the run";
}

ProcessResult run_shell(const std::string& script, ProcessOptions options = {}) {
  if (options.timeout.count() == 0) options.timeout = 60s;  // a hang fails the test instead of blocking it
  return run_process({"/bin/sh", "-c", script}, options);
}

// ---------------------------------------------------------------------------------------------
// Output and status.

TEST(ProcessRun, CapturesStdoutAndStderrApartAndTheExitCode) {
  const ProcessResult r = run_shell("echo to-out; echo to-err >&2; exit 3");
  EXPECT_EQ(r.out, "to-out\n");
  EXPECT_EQ(r.err, "to-err\n");
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_EQ(r.signal, 0);
  EXPECT_FALSE(r.timed_out);
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.describe(), "exited with code 3");
  expect_nothing_left(r);
  EXPECT_TRUE(run_shell("true").ok());
}

TEST(ProcessRun, DrainsMegabytesOnBothStreamsWithoutDeadlock) {
  // 2 MB on stderr first, then 3 MB on stdout: a reader that drained one pipe before the other
  // would leave the child blocked on a full pipe (64 KiB) forever.
  const auto start = Clock::now();
  const ProcessResult r = run_shell(
      "head -c 2000000 /dev/zero | tr '\\000' e >&2; head -c 3000000 /dev/zero | tr '\\000' o; "
      "head -c 1500000 /dev/zero | tr '\\000' E >&2");
  ASSERT_FALSE(r.timed_out) << "the run blocked for " << seconds_since(start) << " s";
  EXPECT_TRUE(r.ok()) << r.describe();
  ASSERT_EQ(r.out.size(), 3000000u);
  ASSERT_EQ(r.err.size(), 3500000u);
  EXPECT_EQ(r.out.find_first_not_of('o'), std::string::npos);
  EXPECT_EQ(r.err.find_first_not_of('e'), 2000000u);
  EXPECT_EQ(r.err.find_first_not_of('E', 2000000), std::string::npos);
}

TEST(ProcessRun, MergesOrDiscardsAStreamAndReadsStdinAsEmpty) {
  const auto run_with = [](ChildOutput out, ChildOutput err, const std::string& script) {
    ProcessOptions o;
    o.stdout_to = out;
    o.stderr_to = err;
    return run_shell(script, o);
  };
  const ProcessResult merged = run_with(ChildOutput::capture, ChildOutput::to_stdout, "echo 1; echo 2 >&2; echo 3");
  EXPECT_EQ(merged.out, "1\n2\n3\n") << "one pipe keeps the order of the writes";
  EXPECT_EQ(merged.err, "");
  const ProcessResult no_err = run_with(ChildOutput::capture, ChildOutput::discard,
                                        "echo kept; echo dropped >&2; if read line; then echo input; else echo eof; fi");
  EXPECT_EQ(no_err.out, "kept\neof\n");
  EXPECT_EQ(no_err.err, "");
  EXPECT_TRUE(no_err.ok());
  const ProcessResult no_out = run_with(ChildOutput::discard, ChildOutput::capture, "echo dropped; echo kept >&2");
  EXPECT_EQ(no_out.out, "");
  EXPECT_EQ(no_out.err, "kept\n");
}

TEST(ProcessRun, ReportsTheSignalThatEndedIt) {
  const ProcessResult r = run_shell("echo before; kill -KILL $$; echo after");
  EXPECT_EQ(r.signal, SIGKILL);
  EXPECT_EQ(r.exit_code, -1);
  EXPECT_FALSE(r.timed_out);
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.out, "before\n");
  EXPECT_NE(r.describe().find("signal 9"), std::string::npos) << r.describe();
  expect_nothing_left(r);
}

TEST(ProcessRun, TheChildDiesWithAProcessKilledOutright) {
  // A SIGKILL (the OOM killer, `kill -9`, a job's hard end) runs no handler: the child must still
  // go, or Blender renders on into a work folder no one reads.
  const test::ScratchDir dir;
  const fs::path pid_file = dir / "child.pid";
  const std::string script = "echo $$ > '" + pid_file.string() + ".tmp' && mv '" + pid_file.string() + ".tmp' '" +
                             pid_file.string() + "' && exec sleep 100";
  const pid_t caller = ::fork();
  ASSERT_GE(caller, 0);
  if (caller == 0) {
    try {
      (void)run_process({"/bin/sh", "-c", script});
    } catch (...) {
    }
    ::_exit(0);  // never on into the rest of the test program
  }
  const auto end = Clock::now() + 10s;
  while (!fs::exists(pid_file) && Clock::now() < end) std::this_thread::sleep_for(10ms);
  pid_t child = 0;
  std::ifstream(pid_file) >> child;
  ::kill(caller, SIGKILL);  // also where the child did not start: the caller is not left behind
  int status = 0;
  ASSERT_EQ(::waitpid(caller, &status, 0), caller);
  ASSERT_GT(child, 0) << "the child did not start";
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
  EXPECT_TRUE(dies_within(child, 2s)) << "the child " << child << " outlived the process that started it";
  if (is_alive(child)) ::kill(child, SIGKILL);
}

TEST(ProcessRun, AStandardStreamThisProcessHasClosedIsDevNullInTheTool) {
  // With this process's stderr closed, the tool's /dev/null for it gets that very number: it must
  // stay open across exec (it was opened close-on-exec, so the tool had no stderr, and the first
  // file it opened became its standard error).
  const test::ScratchDir dir;
  const fs::path seen = dir / "fd2";
  const pid_t caller = ::fork();
  ASSERT_GE(caller, 0);
  if (caller == 0) {
    ::close(2);
    std::string out;
    try {
      ProcessOptions o;
      o.stderr_to = ChildOutput::discard;
      o.timeout = 30s;
      out = run_process({"/bin/sh", "-c", "readlink /proc/self/fd/2 || echo closed"}, o).out;
    } catch (const std::exception& e) {
      out = std::string("error: ") + e.what();
    }
    std::ofstream(seen) << out;
    ::_exit(0);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(caller, &status, 0), caller);
  EXPECT_EQ(test::read_text(seen), "/dev/null\n");
}

TEST(ProcessRun, AFailedExecIsAToolErrorWithItsReason) {
  // A file that passes the executable check but cannot be exec'd (no #! line and not a binary).
  const test::ScratchDir dir;
  const fs::path bogus = dir / "bogus-tool";
  std::ofstream(bogus, std::ios::binary) << std::string("\x7f" "ELF\x01\x01garbage", 12);
  fs::permissions(bogus, fs::perms::owner_all);
  try {
    (void)run_process({bogus.string()});
    ADD_FAILURE() << "a file that is no program started";
  } catch (const ToolError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot start '" + bogus.string() + "'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("Exec format error"), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------------------------------------
// Program, folder and environment.

TEST(ProcessRun, MissingProgramIsAToolErrorNamingIt) {
  try {
    (void)run_process({"/nonexistent/sb-no-such-tool", "--version"});
    ADD_FAILURE() << "a missing program started";
  } catch (const ToolError& e) {
    EXPECT_EQ(e.code(), ExitCode::environment);
    EXPECT_NE(std::string(e.what()).find("/nonexistent/sb-no-such-tool"), std::string::npos) << e.what();
  }
  try {
    (void)run_process({"sb-no-such-tool-4711"});
    ADD_FAILURE() << "a program missing from PATH started";
  } catch (const ToolError& e) {
    EXPECT_NE(std::string(e.what()).find("'sb-no-such-tool-4711': not found on PATH"), std::string::npos) << e.what();
  }
  const test::ScratchDir dir;
  std::ofstream(dir / "not-executable") << "#!/bin/sh\necho hi\n";
  EXPECT_THROW((void)run_process({(dir / "not-executable").string()}), ToolError);
  EXPECT_FALSE(find_program((dir / "not-executable").string()).has_value());
  EXPECT_EQ(find_program("sh").value_or("").filename(), "sh");
}

TEST(ProcessRun, RunsInTheGivenFolderAndResolvesARelativeProgramFromHere) {
  const test::ScratchDir dir;
  fs::create_directories(dir / "elsewhere");
  const fs::path tool = dir / "tool.sh";
  std::ofstream(tool) << "#!/bin/sh\npwd\n";
  fs::permissions(tool, fs::perms::owner_all);
  ProcessOptions o;
  o.cwd = dir / "elsewhere";
  const fs::path relative = fs::relative(tool, fs::current_path());
  ASSERT_NE(relative.string().find('/'), std::string::npos) << relative;
  const ProcessResult r = run_process({relative.string()}, o);
  EXPECT_TRUE(r.ok()) << r.describe() << r.err;
  EXPECT_EQ(r.out, fs::canonical(dir / "elsewhere").string() + "\n");

  o.cwd = dir / "missing";
  try {
    (void)run_process({"/bin/pwd"}, o);
    ADD_FAILURE() << "started in a missing folder";
  } catch (const ToolError& e) {
    EXPECT_NE(std::string(e.what()).find((dir / "missing").string()), std::string::npos) << e.what();
  }
}

TEST(ProcessRun, PassesTheEnvironmentWithChanges) {
  const test::ScopedEnv inherited("SB_PROCESS_INHERITED", std::string("kept"));
  const test::ScopedEnv overridden("SB_PROCESS_OVERRIDDEN", std::string("old"));
  const test::ScopedEnv removed("SB_PROCESS_REMOVED", std::string("present"));
  ProcessOptions o;
  o.set_env = {{"SB_PROCESS_OVERRIDDEN", "new"}, {"SB_PROCESS_ADDED", "a value with blanks"}};
  o.unset_env = {"SB_PROCESS_REMOVED"};
  const ProcessResult r = run_shell(
      "printf '%s|%s|%s|%s\\n' \"$SB_PROCESS_INHERITED\" \"$SB_PROCESS_OVERRIDDEN\" \"$SB_PROCESS_ADDED\" "
      "\"${SB_PROCESS_REMOVED-unset}\"",
      o);
  EXPECT_EQ(r.out, "kept|new|a value with blanks|unset\n");
  EXPECT_STREQ(std::getenv("SB_PROCESS_OVERRIDDEN"), "old") << "this process's environment is left alone";
  EXPECT_STREQ(std::getenv("SB_PROCESS_REMOVED"), "present");
}

// ---------------------------------------------------------------------------------------------
// Time limits.

TEST(ProcessTimeout, StopsTheChildAndTheGrandchildItStarted) {
  ProcessOptions o;
  o.timeout = 1s;
  const auto start = Clock::now();
  const ProcessResult r = run_process({"/bin/sh", "-c", "sleep 100 & echo $!; sleep 100"}, o);
  const double seconds = seconds_since(start);
  EXPECT_TRUE(r.timed_out);
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.signal, SIGTERM) << "the shell ends on the SIGTERM of the limit";
  EXPECT_GE(seconds, 1.0);
  EXPECT_LT(seconds, 4.0) << "the limit is 1 s and SIGTERM ends both";
  EXPECT_NE(r.describe().find("time limit"), std::string::npos) << r.describe();
  const pid_t grandchild = static_cast<pid_t>(std::stol(r.out));
  ASSERT_GT(grandchild, 0) << r.out;
  EXPECT_TRUE(dies_within(grandchild, 2s)) << "the background sleep " << grandchild << " outlived the limit";
  expect_nothing_left(r);
}

TEST(ProcessTimeout, KillsWhatIgnoresSigterm) {
  ProcessOptions o;
  o.timeout = 500ms;
  o.kill_grace = 500ms;
  const auto start = Clock::now();
  // The ignored SIGTERM is inherited by the shell's sleep: only SIGKILL ends either.
  const ProcessResult r = run_process({"/bin/sh", "-c", "trap '' TERM; sleep 100 & echo $!; sleep 100"}, o);
  const double seconds = seconds_since(start);
  EXPECT_TRUE(r.timed_out);
  EXPECT_EQ(r.signal, SIGKILL);
  EXPECT_GE(seconds, 1.0) << "SIGKILL follows SIGTERM after the grace";
  EXPECT_LT(seconds, 4.0);
  EXPECT_TRUE(dies_within(static_cast<pid_t>(std::stol(r.out)), 2s));
  expect_nothing_left(r);
}

TEST(ProcessTimeout, WhatAFinishedChildLeftRunningIsStopped) {
  ProcessOptions o;
  o.kill_grace = 300ms;
  // The background sleep holds the output pipe open after the shell exits: the run waits the
  // grace for it, then kills it; the shell's own status is the result.
  auto start = Clock::now();
  ProcessResult r = run_process({"/bin/sh", "-c", "sleep 100 & echo $!; exit 5"}, o);
  EXPECT_LT(seconds_since(start), 3.0);
  EXPECT_EQ(r.exit_code, 5);
  EXPECT_FALSE(r.timed_out);
  EXPECT_TRUE(dies_within(static_cast<pid_t>(std::stol(r.out)), 2s));
  expect_nothing_left(r);
  // Without the pipe: the run ends with the shell, and the sleep goes with it.
  start = Clock::now();
  r = run_process({"/bin/sh", "-c", "sleep 100 >/dev/null 2>&1 & echo $!"}, o);
  EXPECT_LT(seconds_since(start), 3.0);
  EXPECT_TRUE(r.ok());
  EXPECT_TRUE(dies_within(static_cast<pid_t>(std::stol(r.out)), 2s));
  expect_nothing_left(r);
}

TEST(ProcessTimeout, AFastProgramIsUntouchedByItsLimit) {
  ProcessOptions o;
  o.timeout = 30s;
  const auto start = Clock::now();
  const ProcessResult r = run_process({"/bin/sh", "-c", "echo done"}, o);
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(r.out, "done\n");
  EXPECT_LT(seconds_since(start), 2.0);
}

// ---------------------------------------------------------------------------------------------
// $STEREOBENCH_TOOL_TIMEOUT.

TEST(ToolTimeout, ReadsSecondsFromTheEnvironment) {
  {
    const test::ScopedEnv unset(kToolTimeoutVariable, std::nullopt);
    EXPECT_EQ(tool_timeout(), std::chrono::milliseconds(kDefaultToolTimeout));
    EXPECT_EQ(format_limit(tool_timeout()), "30 min");
  }
  const std::vector<std::pair<std::string, long long>> good = {{"2", 2000}, {"0.5", 500}, {"3600", 3'600'000},
                                                                {"0", 0},   {"", 1'800'000}};
  for (const auto& [text, ms] : good) {
    const test::ScopedEnv env(kToolTimeoutVariable, text);
    EXPECT_EQ(tool_timeout().count(), ms) << text;
  }
  EXPECT_EQ(format_limit(2s), "2 s");
  EXPECT_EQ(format_limit(1500ms), "1.5 s");
}

TEST(ToolTimeout, AMalformedValueIsAnInputErrorNamingIt) {
  for (const std::string bad : {"soon", "-1", "10s", "10m", " 5", "nan", "inf", "1e30", "5 "}) {
    const test::ScopedEnv env(kToolTimeoutVariable, bad);
    try {
      (void)tool_timeout();
      ADD_FAILURE() << "'" << bad << "' was read as a time limit";
    } catch (const InputError& e) {
      EXPECT_EQ(e.code(), ExitCode::bad_input);
      EXPECT_NE(std::string(e.what()).find("STEREOBENCH_TOOL_TIMEOUT='" + bad + "'"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace sb::validation

namespace sb::validation {
namespace {

TEST(ToolOutput, ALowDiskIsNamedOnlyWhenTheRenderNeedsMoreThanIsFree) {
  const test::ScratchDir dir("low-disk");
  EXPECT_EQ(low_disk_note(dir.path(), 0), "");
  const std::string note = low_disk_note(dir.path(), UINTMAX_MAX);
  EXPECT_NE(note.find("the disk of " + dir.path().string() + " has "), std::string::npos) << note;
  EXPECT_NE(note.find("make room there"), std::string::npos) << note;
}

TEST(ToolOutput, AnUnwritableLogIsANoteAfterAFailedRenderAndAnErrorAfterAGoodOne) {
  const test::ScratchDir dir("tool-log");
  EXPECT_EQ(keep_tool_output(dir / "ok.log", "fine\n", true), "");
  EXPECT_EQ(test::read_text(dir / "ok.log"), "fine\n");
  std::filesystem::create_directories(dir / "blocked.log" / "inside");
  const std::string note = keep_tool_output(dir / "blocked.log", "Render failed\n", true);
  EXPECT_NE(note.find("its output could not be kept"), std::string::npos) << note;
  EXPECT_THROW((void)keep_tool_output(dir / "blocked.log", "fine\n", false), Error);
}

}  // namespace
}  // namespace sb::validation
