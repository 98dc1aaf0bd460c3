// Typed errors thrown by library code; the command line maps them to exit codes (DESIGN §2).
#pragma once

#include <cstdio>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace sb {

/// Exit codes of the command-line tool.
enum class ExitCode : int {
  ok = 0,
  gate_warning = 1,
  gate_failure = 2,
  bad_input = 3,      ///< malformed input, impossible parameters, usage errors
  environment = 4,    ///< missing external tool or I/O failure
};

/// Base of every error the library throws. The message says what was wrong and what to do.
class Error : public std::runtime_error {
 public:
  Error(ExitCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
  [[nodiscard]] ExitCode code() const noexcept { return code_; }

 private:
  ExitCode code_;
};

/// Bad input: a malformed file, an out-of-range parameter, an unknown name.
class InputError : public Error {
 public:
  explicit InputError(const std::string& message) : Error(ExitCode::bad_input, message) {}
};

/// An I/O failure: unreadable or unwritable file, full disk.
class IoError : public Error {
 public:
  explicit IoError(const std::string& message) : Error(ExitCode::environment, message) {}
};

/// An external tool (Blender, POV-Ray, ...) that is needed but absent or failing.
class ToolError : public Error {
 public:
  explicit ToolError(const std::string& message) : Error(ExitCode::environment, message) {}
};

/// The machine cannot hold the work asked for (memory), found before it is allocated.
class ResourceError : public Error {
 public:
  explicit ResourceError(const std::string& message) : Error(ExitCode::environment, message) {}
};

/// Prints a warning on standard error as the command line prints its errors:
/// "stereobench: warning: TEXT".
inline void print_warning(std::string_view text) {
  std::fprintf(stderr, "stereobench: warning: %.*s\n", static_cast<int>(text.size()), text.data());
}

/// print_warning for each of `warnings`, in order.
inline void print_warnings(const std::vector<std::string>& warnings) {
  for (const std::string& w : warnings) print_warning(w);
}

}  // namespace sb
