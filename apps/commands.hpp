// Registration of the stereobench subcommands; each lives in its own apps/cmd_*.cpp.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace sb::cli {

/// A verdict a subcommand ends with (gate warning 1, failure 2, missing tool 4), thrown from its
/// callback once everything it writes is complete; main() returns the code.
struct VerdictExit {
  int code = 0;
};

/// `stereobench scenes list|generate|info`.
void register_scenes_command(CLI::App& root);
/// `stereobench render` and `stereobench pipelines`.
void register_render_command(CLI::App& root);
/// `stereobench bench`.
void register_bench_command(CLI::App& root);
/// `stereobench compare A B`.
void register_compare_command(CLI::App& root);

/// `stereobench validate`.
void register_validate_command(CLI::App& root);
/// `stereobench sweep run|cells|csv|collect`.
void register_sweep_command(CLI::App& root);
/// `stereobench gate`.
void register_gate_command(CLI::App& root);
/// After a usage error on the command line (CLI11's, before any command ran): when it was the
/// gate's, removes the --junit and --json files an earlier run left, as the gate does on every
/// other exit 3, so that a green report never stands for a run that was refused. Best effort.
void discard_gate_reports_after_usage_error(CLI::App& root) noexcept;
/// `stereobench nightly`.
void register_nightly_command(CLI::App& root);

/// `stereobench path`.
void register_path_command(CLI::App& root);

/// `stereobench report RESULTS --out DIR`.
void register_report_command(CLI::App& root);

/// `stereobench reference generate|verify|update|list`; `command_line` is recorded in provenance.
void register_reference_command(CLI::App& root, const std::string& command_line);

}  // namespace sb::cli
