// The Slurm executor of sweeps: job array script, submission with sbatch, waiting with squeue,
// task outcomes from exit-code files (no accounting database needed), merging of the shards.
#include "validation/slurm.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <thread>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/json_text.hpp"
#include "renderer/text.hpp"
#include "validation/content_hash.hpp"
#include "validation/process.hpp"
#include "validation/results_file.hpp"
#include "validation/sweep_run.hpp"

namespace sb::validation {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

/// Runs a Slurm client command with stdout and stderr captured. These commands only talk to the
/// controller, so a short limit keeps an unreachable one from hanging the caller.
ProcessResult run_slurm_command(const fs::path& program, const std::vector<std::string>& args) {
  std::vector<std::string> argv{program.string()};
  argv.insert(argv.end(), args.begin(), args.end());
  ProcessOptions options;
  options.timeout = kShortCommandTimeout;
  return run_process(argv, options);
}

std::string trimmed(std::string s) {
  const auto not_space = [](unsigned char c) { return !std::isspace(c); };
  s.erase(s.begin(), std::find_if(s.begin(), s.end(), not_space));
  s.erase(std::find_if(s.rbegin(), s.rend(), not_space).base(), s.end());
  return s;
}

/// A path (and a file-name `pattern` of sbatch's inside it) as an #SBATCH directive's value: in
/// double quotes, which carry blanks (sbatch splits an unquoted value at them). A double quote, a
/// backslash, a '%' (sbatch expands '%' patterns in file names) or a control character cannot be
/// carried.
std::string directive_path(const fs::path& p, const std::string& what, const std::string& pattern = "") {
  const std::string s = p.string();
  if (has_control_character(s) || s.find_first_of("\"%\\") != std::string::npos)
    throw InputError(fmt::format("{} '{}' holds a double quote, backslash, '%' or control character, which #SBATCH "
                                 "directives cannot carry; choose a path without them",
                                 what, printable(s)));
  return "\"" + (pattern.empty() ? s : (p / pattern).string()) + "\"";
}

/// An extra sbatch option (--sbatch-arg) as an #SBATCH directive's text, so that the script
/// carries it and `sbatch sweep.sbatch` by hand submits the job as it was submitted. A value with
/// a blank, a single quote or a '#' (which sbatch's directive reader takes as a quote or a
/// comment) is written in double quotes (--comment="two words"); a double quote, a backslash or a
/// control character cannot be carried, nor those characters outside a --name=value option's value.
std::string sbatch_directive(const std::string& arg) {
  if (arg.empty() || arg[0] != '-')
    throw InputError(fmt::format("--sbatch-arg '{}' is not an sbatch option (it must start with '-', e.g. "
                                 "--sbatch-arg=--mem=4G)",
                                 printable(arg)));
  if (has_control_character(arg) || arg.find_first_of("\"\\") != std::string::npos)
    throw InputError(fmt::format("--sbatch-arg '{}' holds a double quote, backslash or control character, which "
                                 "#SBATCH directives cannot carry",
                                 printable(arg)));
  // The directives the executor writes itself: the merge reads task I's files for I < --shards,
  // and a user's directive after them would take their place (sbatch also takes a long option by
  // any unambiguous start, so a start of one is refused too).
  static const std::pair<const char*, char> owned[] = {
      {"array", 'a'}, {"ntasks", 'n'}, {"output", 'o'}, {"error", 'e'}, {"chdir", 'D'}};
  const std::string long_name = arg.starts_with("--") ? arg.substr(2, arg.find('=') - 2) : std::string();
  for (const auto& [name, letter] : owned) {
    const bool same = arg.starts_with("--") ? long_name.size() >= 2 && std::string_view(name).starts_with(long_name)
                                            : arg.size() >= 2 && arg[1] == letter;
    if (same)
      throw InputError(fmt::format(
          "--sbatch-arg '{}' sets --{}, which the sweep's job script sets itself (the array has one task per shard, "
          "with its own log files and working directory); {}",
          printable(arg), name,
          std::string_view(name) == "array" ? "to run fewer tasks at once, give --max-running M (the array's %M)"
                                            : "leave it out"));
  }
  const size_t special = arg.find_first_of(" \t'#");
  if (special == std::string::npos) return arg;
  const size_t equals = arg.find('=');
  if (!arg.starts_with("--") || equals == std::string::npos || equals > special)
    throw InputError(fmt::format("--sbatch-arg '{}' holds a blank, a single quote or a '#' outside an option's "
                                 "value; give one option per --sbatch-arg, as --name=value (e.g. "
                                 "--sbatch-arg=--mem=4G)",
                                 arg));
  return arg.substr(0, equals + 1) + "\"" + arg.substr(equals + 1) + "\"";
}

/// The last `n` lines of a text file ("(missing)" / "(empty)" when there are none).
std::string tail_of(const fs::path& file, size_t n) {
  std::ifstream in(file);
  if (!in) return "(missing)";
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    lines.push_back(line);
    if (lines.size() > n) lines.erase(lines.begin());
  }
  if (lines.empty()) return "(empty)";
  std::string out;
  for (const std::string& l : lines) out += "    " + l + "\n";
  return out;
}

/// Array task ids of the job still in the queue (pending, running, completing, ...), with their
/// states; std::nullopt when squeue failed (its message in `error`).
std::optional<std::map<size_t, std::string>> queued_tasks(const fs::path& squeue, const std::string& job_id,
                                                          std::string& error) {
  // -r: one line per array task, pending ones included; %K: the array task id; %T: the state.
  const ProcessResult r = run_slurm_command(squeue, {"--noheader", "--array", "--jobs=" + job_id, "--format=%K %T"});
  std::map<size_t, std::string> tasks;
  if (r.timed_out) {
    error = fmt::format("squeue did not answer within {} and was stopped", format_limit(kShortCommandTimeout));
    return std::nullopt;
  }
  if (r.exit_code != 0) {
    // A job the controller has already forgotten (MinJobAge passed) is no longer queued.
    if (r.err.find("Invalid job id") != std::string::npos) return tasks;
    error = trimmed(r.err.empty() ? r.out : r.err);
    if (error.empty()) error = r.describe();
    return std::nullopt;
  }
  std::istringstream in(r.out);
  for (std::string line; std::getline(in, line);) {
    std::istringstream words(line);
    std::string id, state;
    if (!(words >> id >> state)) continue;
    if (id.find_first_not_of("0123456789") != std::string::npos) continue;
    tasks[std::stoul(id)] = state;
  }
  return tasks;
}

/// `scontrol show job -o JOB_TASK` fields JobState and ExitCode, when the controller still knows it.
struct ControllerView {
  std::string state;
  std::optional<int> exit_code;
};
std::optional<ControllerView> controller_view(const std::string& job_id, size_t task) {
  fs::path scontrol;
  try {
    scontrol = slurm_tool("scontrol");
  } catch (const ToolError&) {
    return std::nullopt;
  }
  const ProcessResult r =
      run_slurm_command(scontrol, {"--oneliner", "show", "job", fmt::format("{}_{}", job_id, task)});
  if (r.exit_code != 0) return std::nullopt;
  ControllerView v;
  std::smatch m;
  if (std::regex_search(r.out, m, std::regex(R"(JobState=([A-Z_]+))"))) v.state = m[1];
  if (std::regex_search(r.out, m, std::regex(R"(ExitCode=(\d+):(\d+))")))
    v.exit_code = std::stoi(m[2]) != 0 ? 128 + std::stoi(m[2]) : std::stoi(m[1]);
  if (v.state.empty()) return std::nullopt;
  return v;
}

std::optional<int> read_status(const fs::path& file) {
  std::ifstream in(file);
  int code = 0;
  if (in >> code) return code;
  return std::nullopt;
}

}  // namespace

fs::path SlurmLayout::results(size_t task) const { return dir / fmt::format("results-{}.jsonl", task); }
fs::path SlurmLayout::out_log(size_t task) const { return dir / fmt::format("task-{}.out", task); }
fs::path SlurmLayout::err_log(size_t task) const { return dir / fmt::format("task-{}.err", task); }
fs::path SlurmLayout::status(size_t task) const { return dir / fmt::format("task-{}.status", task); }

SlurmLayout slurm_layout(const fs::path& out_dir) {
  SlurmLayout l;
  l.dir = out_dir / "slurm";
  l.script = l.dir / "sweep.sbatch";
  l.submission = l.dir / "submission.json";
  return l;
}

void refuse_local_run_of_slurm_folder(const fs::path& out_dir, const fs::path& results) {
  const SlurmLayout l = slurm_layout(out_dir);
  std::error_code ec;
  // The Slurm folder of a submitted sweep is no sweep's --out: its tasks write results-I.jsonl
  // there, and a run into it would put cells/ and work/ beside them.
  const fs::path parent = fs::weakly_canonical(fs::absolute(out_dir), ec).parent_path();  // "x/slurm/" too
  if (const SlurmLayout above = slurm_layout(parent);
      fs::exists(above.submission, ec) &&
      fs::weakly_canonical(fs::absolute(out_dir), ec) == fs::weakly_canonical(above.dir, ec))
    throw InputError(fmt::format("{} is the Slurm folder of the sweep submitted into {} ({}); continue that sweep with "
                                 "`sweep run --executor slurm --out {}`, or give another --out",
                                 out_dir.string(), parent.string(), above.submission.string(), parent.string()));
  if (!fs::exists(l.submission, ec)) return;
  if (fs::weakly_canonical(fs::absolute(results).parent_path(), ec) == fs::weakly_canonical(fs::absolute(l.dir), ec))
    return;
  std::string job;
  try {
    job = io::parse_json(io::read_file(l.submission)).value("job_id", "");
  } catch (const std::exception&) {
    // Unreadable: the refusal below still holds, without the job's number.
  }
  throw InputError(fmt::format("{} was submitted to Slurm{} ({}); continue it with `sweep run --executor slurm`, which "
                               "merges its tasks' results, or give another --out",
                               out_dir.string(), job.empty() ? "" : " as job " + job, l.submission.string()));
}

fs::path slurm_tool(const std::string& name) {
  if (std::optional<fs::path> found = find_program(name)) return *found;
  throw ToolError(fmt::format(
      "'{}' not found on PATH: the slurm executor submits the sweep to a Slurm cluster, so it must run where the "
      "Slurm client commands (sbatch, squeue, scontrol) reach a running slurmctld; install them with "
      "`ci/install-deps.sh slurm` (a single-node cluster for trying it: tests/slurm/start_slurm.sh, "
      "docs/slurm.md), or use --executor local",
      name));
}

void check_slurm_time_limit(const std::string& value) {
  static const std::regex kTime(
      R"((\d+)|(\d+):(\d{1,2})|(\d+):(\d{1,2}):(\d{1,2})|(\d+)-(\d{1,2})(?::(\d{1,2})(?::(\d{1,2}))?)?)");
  if (value == "infinite" || value == "UNLIMITED") return;
  std::smatch m;
  if (std::regex_match(value, m, kTime)) {
    // sbatch refuses seconds and minutes past 59 after a larger field, and hours past 23 after days.
    const auto at_most = [&](int group, int limit) { return !m[group].matched || std::stoi(m[group].str()) <= limit; };
    if (at_most(3, 59) && at_most(5, 59) && at_most(6, 59) && at_most(8, 23) && at_most(9, 59) && at_most(10, 59))
      return;
  }
  throw InputError(fmt::format("--time-limit '{}' is not a Slurm time; use HH:MM:SS (e.g. 01:30:00), MM, MM:SS, "
                               "D-HH, D-HH:MM or D-HH:MM:SS",
                               value));
}

std::string sbatch_script(const SweepDefinition& d, const SlurmSweepOptions& o) {
  if (o.shards == 0) throw InputError("the number of Slurm array tasks (--shards) must be at least 1");
  const SlurmLayout l = slurm_layout(o.out_dir);
  const fs::path workdir = o.workdir.empty() ? fs::current_path() : o.workdir;
  const std::string output = directive_path(l.dir, "the Slurm log folder", "task-%a.out");
  const std::string error = directive_path(l.dir, "the Slurm log folder", "task-%a.err");
  const std::string chdir = directive_path(workdir, "the working directory");
  if (!o.partition.empty() && !std::regex_match(o.partition, std::regex(R"([A-Za-z0-9_.,-]+)")))
    throw InputError(fmt::format("--partition '{}' is not a Slurm partition name (letters, digits, '_', '.', '-')",
                                 o.partition));
  if (!o.time_limit.empty()) check_slurm_time_limit(o.time_limit);

  std::string job_name = "sb-sweep-" + d.name;
  for (char& c : job_name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') c = '_';

  const std::string n = std::to_string(o.shards);
  std::string s;
  s += "#!/bin/bash\n";
  s += fmt::format("# Sweep '{}' ({}) as a Slurm job array of {} task{}: task I runs the cells with\n",
                   printable(d.name), printable(fs::absolute(d.file).string()), n, o.shards == 1 ? "" : "s");
  s += fmt::format("# cell_index % {} == I into results-I.jsonl beside this script, its exit code into task-I.status.\n", n);
  s += "# Written and submitted by `stereobench sweep run --executor slurm` (docs/slurm.md), which with\n";
  s += "# --wait merges the shards into the sweep's results file once every task has ended.\n";
  s += "#SBATCH --job-name=" + job_name + "\n";
  if (o.max_running > 0)
    s += fmt::format("#SBATCH --array=0-{}%{}\n", o.shards - 1, o.max_running);
  else
    s += fmt::format("#SBATCH --array=0-{}\n", o.shards - 1);
  s += "#SBATCH --ntasks=1\n";
  s += "#SBATCH --output=" + output + "\n";
  s += "#SBATCH --error=" + error + "\n";
  s += "#SBATCH --chdir=" + chdir + "\n";
  if (!o.partition.empty()) s += "#SBATCH --partition=" + o.partition + "\n";
  if (!o.time_limit.empty()) s += "#SBATCH --time=" + o.time_limit + "\n";
  // After the directives above, so that a user's option overrides them as on sbatch's command line.
  for (const std::string& a : o.sbatch_args) s += "#SBATCH " + sbatch_directive(a) + "\n";
  s += "set -u\n";
  s += "task=${SLURM_ARRAY_TASK_ID:?this script runs as a task of a Slurm job array: submit it with sbatch}\n";
  if (o.threads > 0)
    s += fmt::format("threads={}\n", o.threads);
  else
    s += "threads=${SLURM_CPUS_PER_TASK:-${SLURM_CPUS_ON_NODE:-1}}  # the CPUs Slurm allocated to this task\n";
  s += "slurm_dir=" + shell_quote(l.dir.string(), true) + "\n";
  std::string cmd = shell_quote(fs::absolute(o.stereobench).string(), true) + " sweep run " +
                    shell_quote(fs::absolute(d.file).string(), true) + " --out " + shell_quote(o.out_dir.string(), true) +
                    " \\\n    --shard \"$task/" + n + "\" --results \"$slurm_dir/results-$task.jsonl\" --threads \"$threads\"";
  for (const std::string& a : o.run_args) cmd += " " + shell_quote(a, true);
  s += cmd + "\n";
  s += "code=$?\n";
  s += "printf '%d\\n' \"$code\" > \"$slurm_dir/task-$task.status.tmp\" && "
       "mv -f \"$slurm_dir/task-$task.status.tmp\" \"$slurm_dir/task-$task.status\"\n";
  s += "exit \"$code\"\n";
  return s;
}

SlurmSweepOptions resolve_slurm_options(const SweepDefinition& d, SlurmSweepOptions o) {
  o.out_dir = fs::absolute(o.out_dir).lexically_normal();
  o.stereobench = fs::absolute(o.stereobench);
  if (o.workdir.empty()) o.workdir = fs::current_path();
  const size_t cell_count = expand_cells(d).size();
  if (o.shards == 0) o.shards = std::min(cell_count, kMaxSlurmShards);
  if (o.shards > cell_count)
    throw InputError(fmt::format("--shards {} is more than the {} cells of sweep '{}'; use at most {}", o.shards,
                                 cell_count, d.name, cell_count));
  if (o.shards > kMaxSlurmShards)
    throw InputError(fmt::format("--shards {} is more than the {} tasks Slurm's default MaxArraySize ({}) allows "
                                 "in one array; use at most {} shards",
                                 o.shards, kMaxSlurmShards, kMaxSlurmShards, kMaxSlurmShards));
  (void)sbatch_script(d, o);  // refuses what the script cannot carry
  return o;
}

SlurmSubmission submit_sweep(const SweepDefinition& d, SlurmSweepOptions o) {
  const fs::path sbatch = slurm_tool("sbatch");
  const fs::path squeue = slurm_tool("squeue");
  o = resolve_slurm_options(d, std::move(o));
  const std::string script = sbatch_script(d, o);
  const SlurmLayout l = slurm_layout(o.out_dir);

  // An earlier submission into this folder: still running, or sharded another way. What it
  // merged stays recorded: a resubmission merges into that file again.
  json merged_before;
  if (fs::exists(l.submission)) {
    json before;
    try {
      before = io::parse_json(io::read_file(l.submission));
    } catch (const io::JsonTextError& e) {
      throw InputError(fmt::format("{}: unreadable ({}); remove it to submit again", l.submission.string(), e.what()));
    }
    const std::string job = before.value("job_id", "");
    std::string error;
    if (!job.empty()) {
      const auto queued = queued_tasks(squeue, job, error);
      if (!queued)
        throw ToolError(fmt::format("squeue cannot tell whether job {} of {} still runs: {}", job,
                                    l.submission.string(), error));
      if (!queued->empty())
        throw InputError(fmt::format("Slurm job {} of this sweep ({}) is still queued or running; wait for it "
                                     "(squeue -j {}) or cancel it (scancel {}) before submitting again",
                                     job, o.out_dir.string(), job, job));
    }
    bool has_results = false;
    const size_t cell_count = expand_cells(d).size();
    for (const auto& entry : fs::directory_iterator(l.dir)) {
      if (entry.path().filename().string().rfind("results-", 0) != 0 || fs::file_size(entry.path()) == 0) continue;
      has_results = true;
      // A shard's cells that this build could not join (another pipeline set, where the
      // definition lists "all") would stop its task at the start: refused here, before submitting.
      const ResultsFile shard = read_results(entry.path());
      if (!shard.cells.empty())
        if (const auto why = why_not_resumable(d, cell_count, shard.cells.front()))
          throw InputError(fmt::format("{} holds cells that this submission cannot continue: {}; use another --out",
                                       entry.path().string(), *why));
    }
    const size_t shards_before = before.value("shards", size_t{0});
    if (has_results && shards_before != o.shards)
      throw InputError(fmt::format("{} holds results of {} shards; submit with --shards {} to continue them, or "
                                   "use another --out",
                                   l.dir.string(), shards_before, shards_before));
    if (has_results && before.value("definition_sha256", "") != d.sha256)
      throw InputError(fmt::format("{} holds results of another version of {} (definition_sha256 differs); use "
                                   "another --out",
                                   l.dir.string(), d.file.string()));
    merged_before = before.value("merged", json());
  }

  fs::create_directories(l.dir);
  for (size_t t = 0; t < o.shards; ++t)
    for (const fs::path& stale : {l.out_log(t), l.err_log(t), l.status(t)}) fs::remove(stale);
  io::write_text_atomically(l.script, script);

  SlurmSubmission sub;
  sub.shards = o.shards;
  sub.layout = l;
  // The extra sbatch options are the script's directives, so a resubmission by hand keeps them.
  const std::vector<std::string> args{"--parsable", l.script.string()};
  sub.sbatch_command = {sbatch.string()};
  sub.sbatch_command.insert(sub.sbatch_command.end(), args.begin(), args.end());
  const ProcessResult r = run_slurm_command(sbatch, args);
  // --parsable prints "JOBID" or "JOBID;CLUSTER".
  const std::string first = trimmed(r.out.substr(0, r.out.find_first_of(";\n")));
  if (!r.ok() || first.empty() || first.find_first_not_of("0123456789") != std::string::npos) {
    std::string cmd;
    for (const std::string& a : sub.sbatch_command) cmd += (cmd.empty() ? "" : " ") + a;
    if (r.timed_out)
      throw ToolError(fmt::format("sbatch did not answer within {} and was stopped while submitting {}; the job may "
                                  "or may not have been queued: check `squeue --me` (cancel a stray job with scancel) "
                                  "and that the Slurm controller answers (`sinfo`)\n  command: {}",
                                  format_limit(kShortCommandTimeout), l.script.string(), cmd));
    throw ToolError(fmt::format("sbatch could not submit {} (exit code {}): {}\n  command: {}\n  check that a Slurm "
                                "controller answers (`sinfo`) and that the options are valid for this cluster",
                                l.script.string(), r.exit_code, trimmed(r.err + r.out), cmd));
  }
  sub.job_id = first;
  const json record = {{"job_id", sub.job_id},
                       {"shards", sub.shards},
                       {"sweep", d.name},
                       {"definition", fs::absolute(d.file).string()},
                       {"definition_sha256", d.sha256},
                       {"script", l.script.string()},
                       {"sbatch_command", sub.sbatch_command},
                       {"submitted", utc_now()}};
  json written = record;
  if (merged_before.is_object()) written["merged"] = merged_before;
  io::write_text_atomically(l.submission, io::json_text(written, 2) + "\n");
  return sub;
}

std::vector<SlurmTaskOutcome> wait_for_array(const SlurmSubmission& sub, std::chrono::milliseconds poll,
                                             const std::function<void(const SlurmArrayProgress&)>& progress,
                                             std::chrono::seconds give_up) {
  const fs::path squeue = slurm_tool("squeue");
  std::optional<SlurmArrayProgress> last;
  auto failing_since = std::chrono::steady_clock::time_point::max();
  while (true) {
    std::string error;
    const auto queued = queued_tasks(squeue, sub.job_id, error);
    const auto now = std::chrono::steady_clock::now();
    if (!queued) {
      if (failing_since == std::chrono::steady_clock::time_point::max()) failing_since = now;
      if (now - failing_since > give_up)
        throw ToolError(fmt::format("squeue has failed for {} s while waiting for Slurm job {}: {}; the tasks may "
                                    "still run: check `squeue -j {}` and collect later with `stereobench sweep "
                                    "collect`",
                                    give_up.count(), sub.job_id, error, sub.job_id));
      std::this_thread::sleep_for(poll);
      continue;
    }
    failing_since = std::chrono::steady_clock::time_point::max();
    SlurmArrayProgress p;
    p.total = sub.shards;
    for (const auto& [task, state] : *queued) (state == "PENDING" ? p.pending : p.running) += 1;
    p.ended = sub.shards - std::min(sub.shards, queued->size());
    if (progress && (!last || last->pending != p.pending || last->running != p.running || last->ended != p.ended))
      progress(p);
    last = p;
    if (queued->empty()) break;
    std::this_thread::sleep_for(poll);
  }

  std::vector<SlurmTaskOutcome> outcomes;
  for (size_t t = 0; t < sub.shards; ++t) {
    SlurmTaskOutcome o;
    o.task = t;
    o.exit_code = read_status(sub.layout.status(t));
    const std::optional<ControllerView> view = o.exit_code && *o.exit_code == 0 ? std::nullopt
                                                                                : controller_view(sub.job_id, t);
    if (o.exit_code) {
      o.state = *o.exit_code == 0 ? "COMPLETED" : (view ? view->state : "FAILED");
    } else if (view) {
      // No exit code file: the script was killed (time limit, cancellation, node failure), or the
      // file is not visible here yet on a shared file system; the controller still knows.
      o.state = view->state;
      if (view->state == "COMPLETED") o.exit_code = view->exit_code;
    } else {
      o.state = "UNKNOWN";
    }
    if (!o.exit_code)
      o.detail = fmt::format("ended as {} without writing its exit code to {} (killed by Slurm: time limit, "
                             "cancellation, memory or node failure)",
                             o.state, sub.layout.status(t).string());
    else if (*o.exit_code != 0)
      o.detail = fmt::format("`stereobench sweep run` exited with code {}", *o.exit_code);
    else if (!fs::exists(sub.layout.results(t)))
      o.detail = fmt::format("exited with code 0 but wrote no results file {}", sub.layout.results(t).string());
    outcomes.push_back(o);
  }
  return outcomes;
}

std::string describe_failed_tasks(const SlurmSubmission& sub, const std::vector<SlurmTaskOutcome>& outcomes,
                                  size_t tail_lines) {
  std::string out;
  for (const SlurmTaskOutcome& o : outcomes) {
    if (o.ok()) continue;
    out += fmt::format("task {} of job {} ({}): {}\n", o.task, sub.job_id, o.state, o.detail);
    out += fmt::format("  last lines of {}:\n{}", sub.layout.err_log(o.task).string(),
                       tail_of(sub.layout.err_log(o.task), tail_lines));
    if (out.back() != '\n') out += '\n';
    out += fmt::format("  last lines of {}:\n{}", sub.layout.out_log(o.task).string(),
                       tail_of(sub.layout.out_log(o.task), tail_lines));
    if (out.back() != '\n') out += '\n';
  }
  return out;
}

size_t collect_slurm_results(const SweepDefinition& d, const SlurmSubmission& sub, const fs::path& results,
                             std::vector<std::string>* warnings) {
  std::vector<fs::path> files;
  for (size_t t = 0; t < sub.shards; ++t) {
    if (!fs::exists(sub.layout.results(t)))
      throw ToolError(fmt::format("{}: results of task {} missing; the task did not finish (see its logs)",
                                   sub.layout.results(t).string(), t));
    files.push_back(sub.layout.results(t));
  }
  std::vector<json> cells = collect_results(files, results, warnings);
  std::set<std::string> have;
  for (const json& c : cells) have.insert(c.value("cell_id", ""));
  std::vector<std::string> missing;
  const std::vector<SweepCell> all = expand_cells(d);
  for (const SweepCell& c : all)
    if (!have.count(c.id)) missing.push_back(c.id);
  if (!missing.empty()) {
    std::string list;
    for (size_t i = 0; i < missing.size() && i < 10; ++i) list += "\n  " + missing[i];
    if (missing.size() > 10) list += fmt::format("\n  ... and {} more", missing.size() - 10);
    throw InputError(fmt::format("the results of the {} tasks in {} lack {} of the {} cells of sweep '{}':{}",
                                 sub.shards, sub.layout.dir.string(), missing.size(), all.size(),
                                 d.name, list));
  }
  io::write_text_atomically(results, results_text(cells));
  record_merge(sub.layout, results);
  return cells.size();
}

namespace {

/// The merged file as the record names it: absolute, and as its JSON text holds it (bytes that are
/// not UTF-8 replaced, as json_text writes them), so that the comparison sees what was written.
std::string merged_name(const fs::path& results) {
  return json::parse(io::json_text(json(fs::absolute(results).lexically_normal().string()))).get<std::string>();
}

}  // namespace

void record_merge(const SlurmLayout& layout, const fs::path& results) {
  std::error_code ec;
  if (!fs::exists(layout.submission, ec)) return;
  json record = io::parse_json(io::read_file(layout.submission));
  record["merged"] = {{"results", merged_name(results)}, {"sha256", hash_file(results)}};
  io::write_text_atomically(layout.submission, io::json_text(record, 2) + "\n");
}

bool merged_from_shards(const SlurmLayout& layout, const fs::path& results) {
  std::error_code ec;
  if (!fs::exists(layout.submission, ec)) return false;
  try {
    const json record = io::parse_json(io::read_file(layout.submission));
    const json merged = record.value("merged", json());
    return merged.is_object() && merged.value("results", "") == merged_name(results) &&
           merged.value("sha256", "") == hash_file(results);
  } catch (const std::exception&) {
    return false;  // unreadable: nothing shows the file is a merge
  }
}

}  // namespace sb::validation
