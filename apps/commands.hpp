// Registration of the stereobench subcommands; each lives in its own apps/cmd_*.cpp.
#pragma once

#include <CLI/CLI.hpp>

namespace sb::cli {

/// `stereobench scenes list|generate|info`.
void register_scenes_command(CLI::App& root);
/// `stereobench render` and `stereobench pipelines`.
void register_render_command(CLI::App& root);
/// `stereobench bench`.
void register_bench_command(CLI::App& root);

}  // namespace sb::cli
