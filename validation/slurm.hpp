// The Slurm executor of sweeps (DESIGN §7, docs/slurm.md): a sweep becomes one job array on an
// existing Slurm cluster; array task I runs `stereobench sweep run` on the cells with
// cell_index % N == I into its own results file, and the files are merged once every task is done.
// Only the Slurm client commands (sbatch, squeue, scontrol) are used; no accounting database.
#pragma once

#include <chrono>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "validation/sweep.hpp"

namespace sb::validation {

/// Where a submission keeps its files: `<out_dir>/slurm/`.
struct SlurmLayout {
  std::filesystem::path dir;         ///< <out_dir>/slurm
  std::filesystem::path script;      ///< sweep.sbatch, the job array script
  std::filesystem::path submission;  ///< submission.json: job id, shards, definition hash

  [[nodiscard]] std::filesystem::path results(size_t task) const;  ///< results-<task>.jsonl
  [[nodiscard]] std::filesystem::path out_log(size_t task) const;  ///< task-<task>.out (stdout)
  [[nodiscard]] std::filesystem::path err_log(size_t task) const;  ///< task-<task>.err (stderr)
  [[nodiscard]] std::filesystem::path status(size_t task) const;   ///< task-<task>.status: exit code
};
[[nodiscard]] SlurmLayout slurm_layout(const std::filesystem::path& out_dir);

/// Refuses a run of the local executor into `out_dir` that writes `results` outside the folder's
/// Slurm log folder, when the folder was submitted to Slurm: its tasks may still be writing the
/// same cells, and the next merge refuses a results file it did not write (docs/slurm.md).
/// InputError naming the job and the way on. A Slurm task (its results in the log folder) passes.
/// So is a run whose `out_dir` is itself the log folder of a submitted sweep's folder.
void refuse_local_run_of_slurm_folder(const std::filesystem::path& out_dir, const std::filesystem::path& results);

/// How a sweep is submitted.
struct SlurmSweepOptions {
  std::filesystem::path stereobench;  ///< the executable every task runs (made absolute)
  std::filesystem::path out_dir;      ///< the sweep's output folder (made absolute)
  std::filesystem::path workdir;      ///< the tasks' working directory; empty: the current one
  size_t shards = 0;                  ///< array tasks; 0: one per cell (at most kMaxSlurmShards)
  std::string partition;              ///< empty: the cluster's default partition
  std::string time_limit;             ///< per task, a Slurm time ("HH:MM:SS", "D-HH:MM", "MM"); empty: the partition's
  std::vector<std::string> sbatch_args;  ///< extra sbatch options, each one argument ("--mem=4G")
  /// At most this many tasks running at once (the array's "%M" throttle); 0: as many as Slurm runs.
  size_t max_running = 0;
  /// Options of `sweep run` every task gets after its shard options (--cache, --scenes-dir, --jobs).
  std::vector<std::string> run_args;
  /// Threads per cell in each task; 0: the CPUs Slurm allocated to the task.
  int threads = 0;
};

/// Slurm's default MaxArraySize is 1001: task ids 0..1000, 1001 tasks.
inline constexpr size_t kMaxSlurmShards = 1001;

/// Checks a Slurm time limit (MM, MM:SS, HH:MM:SS, D-HH, D-HH:MM, D-HH:MM:SS, or "infinite");
/// InputError naming the value otherwise.
void check_slurm_time_limit(const std::string& value);

/// The job array script: one task per shard, each running
/// `<stereobench> sweep run <definition> --out <out_dir> --shard $SLURM_ARRAY_TASK_ID/N
///  --results <out_dir>/slurm/results-$SLURM_ARRAY_TASK_ID.jsonl --threads T <run_args>`
/// with its stdout and stderr in <out_dir>/slurm/task-<I>.out/.err, and its exit code written to
/// task-<I>.status when it ends. `shards` must be resolved (> 0). InputError for values sbatch
/// directives cannot carry (paths with a double quote, a backslash, '%' or a control character;
/// blanks go in double quotes), a bad partition or time, and for an extra sbatch option that sets
/// what the executor relies on (the array, the task count, the log files, the working directory).
[[nodiscard]] std::string sbatch_script(const SweepDefinition& definition, const SlurmSweepOptions& options);

/// The options made complete and checked: paths absolute, the working directory set, `shards`
/// resolved (0: one per cell, at most kMaxSlurmShards) and at most the cell count, extra sbatch
/// options starting with '-', and everything the script's directives carry valid (sbatch_script).
/// InputError naming the option otherwise.
[[nodiscard]] SlurmSweepOptions resolve_slurm_options(const SweepDefinition& definition, SlurmSweepOptions options);

/// A submitted job array.
struct SlurmSubmission {
  std::string job_id;
  size_t shards = 0;
  SlurmLayout layout;
  std::vector<std::string> sbatch_command;  ///< as run, for messages
};

/// Full path of a Slurm client command found on PATH; ToolError naming `ci/install-deps.sh slurm`
/// and saying a Slurm cluster is needed otherwise.
[[nodiscard]] std::filesystem::path slurm_tool(const std::string& name);

/// Resolves the options (resolve_slurm_options), writes the script (atomically) and submits it
/// with `sbatch --parsable`, after checking that no
/// earlier array of this folder is still queued or running and that results of an earlier
/// submission were sharded the same way (their cells would otherwise be run twice). Logs and exit
/// codes of earlier tasks are removed; their results files stay, so the tasks resume.
/// ToolError when sbatch is missing or fails (with its message); InputError for bad options.
[[nodiscard]] SlurmSubmission submit_sweep(const SweepDefinition& definition, SlurmSweepOptions options);

/// How one array task ended.
struct SlurmTaskOutcome {
  size_t task = 0;
  std::optional<int> exit_code;  ///< from task-<I>.status, else from scontrol; none if unknown
  std::string state;             ///< COMPLETED, FAILED, TIMEOUT, CANCELLED, ..., or UNKNOWN
  std::string detail;            ///< why it counts as failed (empty when it succeeded)
  [[nodiscard]] bool ok() const { return detail.empty(); }
};

/// Counts reported while waiting (whenever they change).
struct SlurmArrayProgress {
  size_t pending = 0;
  size_t running = 0;
  size_t ended = 0;  ///< tasks no longer queued or running
  size_t total = 0;
};

/// Polls squeue every `poll` until no task of the array is queued or running, then reads each
/// task's exit code. ToolError when squeue keeps failing for `give_up` (the controller is gone).
[[nodiscard]] std::vector<SlurmTaskOutcome> wait_for_array(
    const SlurmSubmission& submission, std::chrono::milliseconds poll = std::chrono::milliseconds(1000),
    const std::function<void(const SlurmArrayProgress&)>& progress = {},
    std::chrono::seconds give_up = std::chrono::seconds(120));

/// The failed tasks, each with its state, exit code and the last `tail_lines` lines of its stderr
/// and stdout logs.
[[nodiscard]] std::string describe_failed_tasks(const SlurmSubmission& submission,
                                                const std::vector<SlurmTaskOutcome>& outcomes,
                                                size_t tail_lines = 15);

/// Whether `results` is, byte for byte, the file the last merge of the shards in `layout` wrote
/// (the submission record's `merged`, kept across resubmissions): a merge may replace only such a
/// file, not one the local executor (or anything else) wrote there.
[[nodiscard]] bool merged_from_shards(const SlurmLayout& layout, const std::filesystem::path& results);

/// Records in the submission of `layout` (when there is one) that `results` is a merge of its
/// shards: its path and sha256, which merged_from_shards checks. Called by collect_slurm_results,
/// and by `sweep collect` when it merges a layout's shard files.
void record_merge(const SlurmLayout& layout, const std::filesystem::path& results);

/// Merges the tasks' results files into `results` (atomically), checking that together they hold
/// every cell of the definition exactly once; the image paths of every line, relative to the folder
/// of its shard file, are rewritten relative to the folder of `results`, and the merge is recorded
/// (record_merge). Returns the number of cells. InputError naming the missing cells or conflicting
/// duplicates.
size_t collect_slurm_results(const SweepDefinition& definition, const SlurmSubmission& submission,
                             const std::filesystem::path& results, std::vector<std::string>* warnings = nullptr);

}  // namespace sb::validation
