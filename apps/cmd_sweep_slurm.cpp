// `stereobench sweep run --executor slurm`: submit a sweep as a Slurm job array, wait, merge.
#include "apps/cmd_sweep_slurm.hpp"

#include <cstdio>
#include <filesystem>
#include <utility>

#include <fmt/format.h>

#include "apps/cli_common.hpp"
#include "renderer/error.hpp"
#include "validation/slurm.hpp"
#include "validation/sweep.hpp"
#include "validation/sweep_run.hpp"

namespace sb::cli {

namespace fs = std::filesystem;
using namespace sb::validation;

void SweepSlurmCli::add_to(CLI::App& run) {
  options_.push_back(run.add_option("--shards", shards,
                                    "slurm: array tasks, each running the cells with cell_index % N == task\n"
                                    "(default: one task per cell, at most Slurm's default MaxArraySize)")
                         ->check(CLI::Range(size_t{1}, kMaxSlurmShards))
                         ->default_str(""));  // unset means one task per cell; 0 is not a value to give
  options_.push_back(run.add_option("--partition", partition, "slurm: partition to submit to (default: the cluster's)"));
  options_.push_back(run.add_option("--time-limit", time_limit,
                                    "slurm: time limit per task, HH:MM:SS (default: the partition's)"));
  options_.push_back(run.add_option("--max-running", max_running,
                                    "slurm: at most M array tasks running at once (the array's %M throttle)")
                         ->check(CLI::Range(size_t{1}, kMaxSlurmShards))
                         ->default_str(""));
  options_.push_back(run.add_option("--sbatch-arg", sbatch_args,
                                    "slurm: extra sbatch option, repeatable (e.g. --sbatch-arg=--mem=8G); written into the job script as an #SBATCH directive, so resubmitting the script by hand keeps it")
                         ->allow_extra_args(false));
  options_.push_back(run.add_flag("--wait", wait,
                                  "slurm: wait for every task, then merge the shards into the results file"));
}

void SweepSlurmCli::check_unused(const std::string& executor) const {
  for (const CLI::Option* o : options_)
    if (o->count() > 0)
      throw InputError(fmt::format("{} is an option of --executor slurm, not of --executor {}", o->get_name(),
                                   executor));
}

void run_sweep_slurm(const SweepSlurmCli& s, const SweepSlurmRequest& r) {
  if (r.shard != "0/1")
    throw InputError(fmt::format("--shard {} cannot be combined with --executor slurm, which gives every array task "
                                 "its shard; use --shards N",
                                 r.shard));
  if (r.jobs < 1 || r.jobs > 256) throw InputError(fmt::format("--jobs {} is outside 1..256", r.jobs));
  if (r.threads != 0) (void)checked_threads(r.threads);
  const SweepDefinition d = load_sweep(r.definition);
  print_warnings(d.warnings);
  const fs::path out = fs::absolute(r.out.empty() ? fs::path("out") / "sweeps" / d.name : fs::path(r.out));
  const fs::path results = fs::absolute(r.results.empty() ? out / "results.jsonl" : fs::path(r.results));
  const SlurmLayout layout = slurm_layout(out);
  // A results file written by the local executor (also after a submission: a sweep finished
  // locally) would be replaced by the merge of the shards, which know nothing of its cells.
  if (fs::exists(results) && !merged_from_shards(layout, results))
    throw InputError(fmt::format("{} exists and is not the file the slurm executor merged there (the local executor "
                                 "wrote it, or it changed since); merging the Slurm shards would replace it: use "
                                 "another --out (or --results), or remove it",
                                 results.string()));

  SlurmSweepOptions o;
  o.stereobench = fs::read_symlink("/proc/self/exe");
  o.out_dir = out;
  o.shards = s.shards;
  o.partition = s.partition;
  o.time_limit = s.time_limit;
  o.sbatch_args = s.sbatch_args;
  o.max_running = s.max_running;
  o.threads = r.threads;
  o.run_args = {"--jobs", std::to_string(r.jobs), "--cache", r.cache.empty() ? "" : fs::absolute(r.cache).string()};
  if (!r.scenes_dir.empty()) o.run_args.insert(o.run_args.end(), {"--scenes-dir", fs::absolute(r.scenes_dir).string()});
  o = resolve_slurm_options(d, std::move(o));
  (void)slurm_tool("sbatch");

  // Checked here once rather than in every task: truth providers available, built-in scenes generated.
  SweepRunOptions local;
  local.out_dir = out;
  local.results = results;
  local.scenes_dir = r.scenes_dir;
  const std::vector<SweepCell> cells = expand_cells(d);
  std::vector<size_t> all(cells.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  prepare_sweep(d, cells, all, local);

  const SlurmSubmission sub = submit_sweep(d, o);
  fmt::print("sweep {} ({}): {} cells × {} pipelines submitted to Slurm as job {}: {} array task{}, script {}\n",
             d.name, r.definition, cells.size(), d.pipelines.size(), sub.job_id, sub.shards,
             sub.shards == 1 ? "" : "s", layout.script.string());
  if (!s.wait) {
    fmt::print("follow it with `squeue -j {}`; task logs are {}/task-<I>.out and .err\n"
               "once every task has ended, merge the shards with\n"
               "  stereobench sweep collect {} {}/results-*.jsonl\n"
               "(or run this command again with --wait: the tasks find their cells done and merge)\n",
               sub.job_id, layout.dir.string(), results.string(), layout.dir.string());
    return;
  }
  std::fflush(stdout);

  const std::vector<SlurmTaskOutcome> outcomes =
      wait_for_array(sub, std::chrono::milliseconds(1000), [&sub](const SlurmArrayProgress& p) {
        fmt::print(stderr, "slurm job {}: {} pending, {} running, {}/{} tasks ended\n", sub.job_id, p.pending,
                   p.running, p.ended, p.total);
        std::fflush(stderr);
      });
  size_t failed = 0, input_failures = 0;
  for (const SlurmTaskOutcome& t : outcomes) {
    if (t.ok()) continue;
    ++failed;
    if (t.exit_code && *t.exit_code == static_cast<int>(ExitCode::bad_input)) ++input_failures;
  }
  if (failed > 0) {
    const std::string message = fmt::format(
        "{} of the {} tasks of Slurm job {} failed; {} not written.\n{}Finished cells are kept in {}/results-<I>.jsonl: "
        "run the same command again to resubmit, and the tasks continue where they stopped.",
        failed, sub.shards, sub.job_id, results.string(), describe_failed_tasks(sub, outcomes), layout.dir.string());
    if (input_failures == failed) throw InputError(message);
    throw ToolError(message);
  }
  std::vector<std::string> warnings;
  const size_t merged = collect_slurm_results(d, sub, results, &warnings);
  print_warnings(warnings);
  fmt::print("every task of job {} finished; wrote {}: {} cells from {} shard files\n", sub.job_id, results.string(),
             merged, sub.shards);
}

}  // namespace sb::cli
