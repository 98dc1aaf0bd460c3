// `stereobench sweep run --executor slurm`: the options of the Slurm executor and the run that
// submits a sweep as a job array, optionally waits for it and merges its shards (docs/slurm.md).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace sb::cli {

/// The options `sweep run` takes for --executor slurm.
struct SweepSlurmCli {
  size_t shards = 0;  ///< 0: one array task per cell
  std::string partition;
  std::string time_limit;
  std::vector<std::string> sbatch_args;
  size_t max_running = 0;  ///< 0: no throttle
  bool wait = false;

  /// Adds --shards, --partition, --time-limit, --max-running, --sbatch-arg and --wait to `run`.
  void add_to(CLI::App& run);
  /// InputError when one of these options was given with another executor.
  void check_unused(const std::string& executor) const;

 private:
  std::vector<CLI::Option*> options_;
};

/// The rest of what `sweep run` was asked, as its own options parsed it.
struct SweepSlurmRequest {
  std::string definition;
  std::string out;         ///< empty: out/sweeps/<name>
  std::string results;     ///< the merged results file; empty: <out>/results.jsonl
  std::string shard;       ///< must be "0/1": the executor shards the sweep itself
  std::string cache;       ///< forwarded to every task ('' disables the cache)
  std::string scenes_dir;  ///< forwarded to every task when set
  int jobs = 1;            ///< cells at once in each task
  int threads = 0;         ///< threads per cell; 0: the CPUs Slurm allocated to the task
};

/// Submits the sweep as a Slurm job array, prints the job id and how to follow and merge it; with
/// --wait, waits for every task, reports failed tasks with their log tails (ToolError, or
/// InputError when every failed task rejected its input) and merges the shards into the results file.
void run_sweep_slurm(const SweepSlurmCli& slurm, const SweepSlurmRequest& request);

}  // namespace sb::cli
