// Runs the stereobench command line from a test and captures its exit code and output.
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace sb::test {

struct CliRun {
  int code = -1;
  std::string out;  ///< stdout and stderr together
};

/// Runs `stereobench ARGS` (arguments as one shell-quoted string).
inline CliRun run_cli(const std::string& args) {
  const std::string cmd = std::string(SB_CLI_PATH) + " " + args + " 2>&1";
  FILE* pipe = ::popen(cmd.c_str(), "r");
  CliRun r;
  std::array<char, 1024> buf{};
  while (pipe && std::fgets(buf.data(), buf.size(), pipe)) r.out += buf.data();
  const int status = pipe ? ::pclose(pipe) : -1;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

}  // namespace sb::test
