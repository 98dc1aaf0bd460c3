// Commands started in the background, and a wait until one is held up by a lock the test holds:
// the way to put a second run at a known point of a race (it has checked nothing yet) without
// sleeping and hoping.
#pragma once

#include <sys/stat.h>
#include <sys/sysmacros.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include <fmt/format.h>

#include "support/run_cli.hpp"

namespace sb::test {

/// Starts `stereobench ARGS` in the background; its output goes to `log`, and its exit code is
/// written to `log` + ".rc" when it ends (see wait_for_background).
inline void start_cli_in_background(const std::string& args, const std::filesystem::path& log) {
  (void)run_shell("( " + std::string(SB_CLI_PATH) + " " + args + " > " + quoted(log) + " 2>&1; echo $? > " +
                  quoted(std::filesystem::path(log.string() + ".rc")) + " ) > /dev/null 2>&1 &");
}

/// Waits (up to `limit`) for a command of start_cli_in_background to end: its exit code and output,
/// code -1 when it did not end in time.
inline CliRun wait_for_background(const std::filesystem::path& log,
                                  std::chrono::seconds limit = std::chrono::seconds(300)) {
  const std::filesystem::path rc = log.string() + ".rc";
  const auto until = std::chrono::steady_clock::now() + limit;
  CliRun r;
  while (std::chrono::steady_clock::now() < until) {
    std::ifstream in(rc);
    if (int code = -1; in >> code) {
      r.code = code;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::ifstream out(log);
  r.out.assign(std::istreambuf_iterator<char>(out), std::istreambuf_iterator<char>());
  return r;
}

/// Waits (up to `limit`) until some process waits for a lock (flock) on `path`, which the test
/// holds: /proc/locks then shows a blocked request ("N: -> FLOCK ...") naming the file's device
/// and inode. False when none came.
inline bool wait_for_lock_waiter(const std::filesystem::path& path,
                                 std::chrono::seconds limit = std::chrono::seconds(120)) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return false;
  const std::string file = fmt::format(" {:02x}:{:02x}:{} ", major(st.st_dev), minor(st.st_dev), st.st_ino);
  const auto until = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < until) {
    std::ifstream locks("/proc/locks");
    for (std::string line; std::getline(locks, line);)
      if (line.find(" -> ") != std::string::npos && line.find(file) != std::string::npos) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

}  // namespace sb::test
