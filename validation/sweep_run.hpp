// Running a sweep with the local executor: which cells are left (resumption, shards), one cell
// validated and timed into its results line, and a list of cells run by parallel workers that
// append each line as it finishes (docs/sweeps.md).
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "validation/sweep.hpp"

namespace sb::validation {

/// A shard: the cells with cell_index % count == index.
struct Shard {
  size_t index = 0;
  size_t count = 1;
};
/// Parses "I/N" (0 <= I < N); InputError otherwise.
[[nodiscard]] Shard parse_shard(const std::string& text);
/// The indices of a shard's cells among `cell_count`: those with index % N == I.
[[nodiscard]] std::vector<size_t> shard_cells(size_t cell_count, const Shard& shard);

/// Where and how a sweep runs.
struct SweepRunOptions {
  std::filesystem::path results;     ///< the results file
  std::filesystem::path out_dir;     ///< images under <out_dir>/cells/<NNNN>/, provider work under <out_dir>/work/
  std::filesystem::path scenes_dir;  ///< where built-in scenes are generated
  std::optional<std::filesystem::path> truth_cache;  ///< cache of external ground truths
  std::string definition_label;      ///< the definition's path as recorded in every line
  Shard shard;                       ///< the shard run, recorded in every line with out_dir
  int jobs = 1;                      ///< cells run at once
  int threads = 0;                   ///< threads per cell; 0: the machine's cores / jobs (at least 1)
};

/// What is left to do.
struct SweepPlan {
  std::vector<SweepCell> cells;     ///< every cell of the definition
  std::vector<size_t> todo;         ///< indices into `cells`: this shard's cells not yet finished
  size_t in_shard = 0;              ///< cells of this shard
  size_t finished = 0;              ///< of them, already in the results file
  std::vector<std::string> warnings;  ///< from reading the results file
};

/// Why cells already recorded for a sweep (`first`: the first line of their results file, which
/// read_results holds the file's other lines to) cannot be joined by cells of `definition` as this
/// build runs it: another sweep or version of the definition (definition_sha256), or the same
/// definition run with another set of pipelines, another baseline or another cell count (a
/// definition listing "all" pipelines follows the build that runs it). nullopt when they can.
[[nodiscard]] std::optional<std::string> why_not_resumable(const SweepDefinition& definition, size_t cell_count,
                                                           const nlohmann::json& first);

/// Reads the results file (if any) and lists the shard's cells not in it. InputError when its cells
/// cannot be joined by this definition's (why_not_resumable), or hold cell ids the definition does
/// not have.
[[nodiscard]] SweepPlan plan_sweep(const SweepDefinition& definition, const std::filesystem::path& results,
                                   const Shard& shard = {});

/// The folder name of a cell's images: its index zero-padded to at least 4 digits.
[[nodiscard]] std::string cell_dir_name(size_t index, size_t cell_count);

/// Checks what the cells need before any runs: every truth provider available (ToolError naming
/// it and why otherwise), the output folder writable and not another definition's (a marker file
/// gives it to this definition; InputError if it names another), every scene resolvable
/// (built-in scenes generated now, once), and, each scene loaded once, every cell's rig and a
/// path's spin possible for it (InputError naming the definition and the cell), and each scene's
/// content the one the results file's finished cells of it were measured on (InputError naming
/// the cell, the scene and both hashes when the file changed since).
void prepare_sweep(const SweepDefinition& definition, const std::vector<SweepCell>& cells,
                   const std::vector<size_t>& todo, const SweepRunOptions& options);

/// Whether `out_dir` may take the cells of `definition`: it has no sweep marker, or its marker
/// names this definition (name and content). prepare_sweep refuses a folder for which this is
/// false; a caller choosing among folders asks first.
[[nodiscard]] bool out_folder_is_for(const SweepDefinition& definition, const std::filesystem::path& out_dir);

/// Reported after each finished cell (serialised: one call at a time).
struct CellProgress {
  const SweepCell& cell;
  size_t finished = 0;  ///< cells finished in this run, this one included
  size_t total = 0;     ///< cells this run has to do
  double wall_s = 0.0;  ///< this cell's wall time
};

/// Runs the cells `todo` with `options.jobs` workers, appending each cell's line to the results
/// file as it finishes, and calls `progress` after each. The first error stops the workers from
/// taking new cells; cells in flight finish, then it is rethrown (finished cells stay recorded).
void run_cells(const SweepDefinition& definition, const std::vector<SweepCell>& cells,
               const std::vector<size_t>& todo, const SweepRunOptions& options,
               const std::function<void(const CellProgress&)>& progress = {});

/// Threads per cell for the options (see SweepRunOptions::threads).
[[nodiscard]] int threads_per_cell(const SweepRunOptions& options);

}  // namespace sb::validation
