// Runs the stereobench command line from a test and captures its exit code and output.
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

namespace sb::test {

struct CliRun {
  int code = -1;
  std::string out;  ///< stdout and stderr together
};

/// Runs a shell command line, capturing its exit code and stdout and stderr together.
inline CliRun run_shell(const std::string& command) {
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  CliRun r;
  std::array<char, 1024> buf{};
  while (pipe && std::fgets(buf.data(), buf.size(), pipe)) r.out += buf.data();
  const int status = pipe ? ::pclose(pipe) : -1;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

/// Runs `stereobench ARGS` (arguments as one shell-quoted string).
inline CliRun run_cli(const std::string& args) { return run_shell(std::string(SB_CLI_PATH) + " " + args); }

/// A path single-quoted for a shell command line (paths here hold no single quote).
inline std::string quoted(const std::filesystem::path& p) { return "'" + p.string() + "'"; }

}  // namespace sb::test
