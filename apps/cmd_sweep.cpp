// `stereobench sweep run|cells|csv|collect`: run a sweep definition (ci/*.toml) with the local
// executor into a resumable results file, list its cells, export results as CSV, merge shards.
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include <fmt/format.h>

#include "apps/cli_common.hpp"
#include "apps/cmd_sweep_slurm.hpp"
#include "apps/commands.hpp"
#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "scenes/catalog.hpp"
#include "validation/results_file.hpp"
#include "validation/slurm.hpp"
#include "validation/sweep.hpp"
#include "validation/sweep_run.hpp"

namespace sb::cli {

namespace {

namespace fs = std::filesystem;
using namespace sb::validation;

struct SweepRunArgs {
  std::string definition;
  std::string out;
  std::string results;
  std::string cache = "out/truth-cache";
  std::string scenes_dir;
  std::string shard = "0/1";
  std::string executor = "local";
  int jobs = 1;
  int threads = 0;
  SweepSlurmCli slurm;  ///< options of --executor slurm
};

std::string clock_text(double seconds) {
  const long s = static_cast<long>(seconds + 0.5);
  if (s >= 3600) return fmt::format("{}:{:02}:{:02}", s / 3600, (s / 60) % 60, s % 60);
  return fmt::format("{}:{:02}", s / 60, s % 60);
}

/// Progress on stderr: a one-line bar redrawn in place on a terminal, otherwise one line per
/// finished cell (logs, CI). ETA = elapsed / cells finished × cells left.
class ProgressPrinter {
 public:
  explicit ProgressPrinter(size_t total) : total_(total), tty_(::isatty(STDERR_FILENO) == 1) {}

  void start() const {
    if (tty_) draw(0, "");
  }

  void finished(const CellProgress& p) const {
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double eta = p.finished > 0 ? elapsed / double(p.finished) * double(total_ - p.finished) : 0.0;
    if (tty_) {
      draw(p.finished, fmt::format("{} ({:.1f} s)", p.cell.id, p.wall_s));
      if (p.finished == total_) std::fputc('\n', stderr);
    } else {
      fmt::print(stderr, "[{}/{}] cell {} {} done in {:.1f} s; elapsed {}, ETA {}\n", p.finished, total_, p.cell.index,
                 p.cell.id, p.wall_s, clock_text(elapsed), clock_text(eta));
    }
    std::fflush(stderr);
  }

  /// Ends a bar left mid-line (on an error).
  void abandon() const {
    if (tty_) std::fputc('\n', stderr);
  }

 private:
  void draw(size_t done, const std::string& last) const {
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const std::string eta = done > 0 ? clock_text(elapsed / double(done) * double(total_ - done)) : "--:--";
    constexpr size_t kBar = 24;
    const size_t filled = total_ > 0 ? done * kBar / total_ : kBar;
    const std::string counts = fmt::format("{}/{} cells  elapsed {}  ETA {}", done, total_, clock_text(elapsed), eta);
    winsize ws{};
    const size_t width = ::ioctl(STDERR_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0 ? ws.ws_col : 100;
    // On a narrow terminal the bar goes first, so that the counts and the ETA stay; the last cell's
    // id is cut to the width, between characters (ids may hold any UTF-8 of scene file names).
    const std::string bar = fmt::format("[{}{}] ", std::string(filled, '#'), std::string(kBar - filled, '-'));
    std::string line = (bar.size() + counts.size() < width ? bar : std::string()) + counts + "  " + last;
    if (line.size() >= width) {
      size_t cut = width - 1;
      while (cut > 0 && (static_cast<unsigned char>(line[cut]) & 0xC0) == 0x80) --cut;
      line.resize(cut);
    }
    fmt::print(stderr, "\r{}\x1b[K", line);
  }

  size_t total_;
  bool tty_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

void run_sweep(const SweepRunArgs& a) {
  if (a.executor == "slurm")
    return run_sweep_slurm(a.slurm, {a.definition, a.out, a.results, a.shard, a.cache, a.scenes_dir, a.jobs, a.threads});
  if (a.executor != "local")
    throw InputError(fmt::format("--executor '{}' is not available; executors: local, slurm", a.executor));
  a.slurm.check_unused(a.executor);
  if (a.jobs < 1 || a.jobs > 256) throw InputError(fmt::format("--jobs {} is outside 1..256", a.jobs));
  const SweepDefinition d = load_sweep(a.definition);
  print_warnings(d.warnings);
  const Shard shard = parse_shard(a.shard);

  SweepRunOptions o;
  o.out_dir = a.out.empty() ? fs::path("out") / "sweeps" / d.name : fs::path(a.out);
  o.results = a.results.empty() ? o.out_dir / "results.jsonl" : fs::path(a.results);
  o.scenes_dir = a.scenes_dir;
  if (!a.cache.empty()) o.truth_cache = fs::path(a.cache);
  o.definition_label = a.definition;
  o.shard = shard;
  o.jobs = a.jobs;
  o.threads = checked_threads(a.threads);
  validation::refuse_local_run_of_slurm_folder(o.out_dir, o.results);

  // Held until the last cell is recorded: no other run may plan this shard's cells meanwhile.
  const ResultsWriterLock lock(o.results, shard_cells(expand_cells(d).size(), shard));
  const SweepPlan plan = plan_sweep(d, o.results, shard);
  print_warnings(plan.warnings);
  fmt::print("sweep {} ({}): {} cells × {} pipelines (baseline {}), {} warm-up + {} repetitions\n", d.name,
             a.definition, plan.cells.size(), d.pipelines.size(), d.baseline, d.warmup, d.repetitions);
  fmt::print("{}{} finished already, {} to run; {} job{} × {} threads; results {}\n",
             shard.count > 1 ? fmt::format("shard {}/{}: {} cells, ", shard.index, shard.count, plan.in_shard) : "",
             plan.finished, plan.todo.size(), o.jobs, o.jobs == 1 ? "" : "s", threads_per_cell(o), o.results.string());
  std::fflush(stdout);
  if (plan.todo.empty()) {
    // A shard with no cells (more shards than cells) still leaves its results file, empty, for
    // `sweep collect` over every shard's file.
    create_results_file(o.results);
    return;
  }

  prepare_sweep(d, plan.cells, plan.todo, o);
  const ProgressPrinter printer(plan.todo.size());
  printer.start();
  const auto start = std::chrono::steady_clock::now();
  try {
    run_cells(d, plan.cells, plan.todo, o, [&printer](const CellProgress& p) { printer.finished(p); });
  } catch (...) {
    printer.abandon();
    throw;
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  fmt::print("ran {} cell{} in {}; {} holds {} of {} cells{}\n", plan.todo.size(), plan.todo.size() == 1 ? "" : "s",
             clock_text(wall), o.results.string(), plan.finished + plan.todo.size(), plan.in_shard,
             shard.count > 1 ? fmt::format(" of shard {}/{}", shard.index, shard.count) : "");
}

void register_run(CLI::App& sweep) {
  auto a = std::make_shared<SweepRunArgs>();
  CLI::App* run = sweep.add_subcommand(
      "run",
      "Run the cells of a sweep definition not yet in its results file: every pipeline validated\n"
      "against the cell's ground truth and timed side by side; one JSON line per finished cell\n"
      "appended atomically (docs/sweeps.md). Interrupted runs resume where they stopped.");
  run->add_option("definition", a->definition, "Sweep definition (TOML), e.g. ci/smoke.toml")->required();
  run->add_option("--out", a->out, "Output folder: results.jsonl and cells/<NNNN>/ images (default out/sweeps/<name>)");
  run->add_option("--results", a->results, "Results file (default <out>/results.jsonl)");
  run->add_option("--jobs,-j", a->jobs,
                  "Cells run at once. Default 1: parallel cells compete for cores and memory bandwidth and\n"
                  "disturb each other's timings; use more for quality-only sweeps")
      ->capture_default_str();
  run->add_option("--threads,-t", a->threads, "Threads per cell (0 = the machine's cores / jobs)")->capture_default_str();
  run->add_option("--shard", a->shard, "Run only the cells with cell_index % N == I (I/N)")->capture_default_str();
  run->add_option("--cache", a->cache, "Folder of cached external ground-truth renders ('' to disable)")
      ->capture_default_str();
  run->add_option("--executor", a->executor,
                  "Where cells run: local (this machine) or slurm (a job array on a Slurm cluster, docs/slurm.md)")
      ->capture_default_str();
  a->slurm.add_to(*run);
  add_scenes_dir_option(*run, a->scenes_dir);
  run->callback([a] { run_sweep(*a); });
}

void register_cells(CLI::App& sweep) {
  struct Args {
    std::string definition;
    std::string shard = "0/1";
  };
  auto a = std::make_shared<Args>();
  CLI::App* cells = sweep.add_subcommand("cells", "List a definition's cells (index and cell_id), checking the definition file; the checks that "
                                             "need a cell's scene (a pipeline's rig limits, the disparity a rig gives) come when the sweep runs");
  cells->add_option("definition", a->definition, "Sweep definition (TOML)")->required();
  cells->add_option("--shard", a->shard, "Only the cells of shard I/N")->capture_default_str();
  cells->callback([a] {
    const SweepDefinition d = load_sweep(a->definition);
    print_warnings(d.warnings);
    const Shard shard = parse_shard(a->shard);
    const std::vector<SweepCell> list = expand_cells(d);
    size_t shown = 0;
    for (const SweepCell& c : list)
      if (c.index % shard.count == shard.index) {
        fmt::print("{}\t{}\n", c.index, c.id);
        ++shown;
      }
    fmt::print(stderr, "{}: {} cells ({} shown) × {} pipelines\n", d.name, list.size(), shown, d.pipelines.size());
  });
}

void register_csv(CLI::App& sweep) {
  struct Args {
    std::string results;
    std::string out;
  };
  auto a = std::make_shared<Args>();
  CLI::App* csv = sweep.add_subcommand(
      "csv", "Export a results file as CSV: one row per (cell, pipeline) with the rig, metrics, holes and times");
  csv->add_option("results", a->results, "Results file (results.jsonl)")->required();
  csv->add_option("--out,-o", a->out, "CSV file to write ('-' or none: standard output)");
  csv->callback([a] {
    if (!fs::exists(a->results)) throw InputError(fmt::format("{}: results file does not exist", a->results));
    refuse_overwriting({{"results", &a->results}}, {{"--out", &a->out}});
    const ResultsFile r = read_results(a->results);
    print_warnings(r.warnings);
    if (r.cells.empty())
      throw InputError(fmt::format("{}: holds no finished cell; run the sweep (stereobench sweep run) first, or give "
                                   "the results file it wrote",
                                   a->results));
    const std::string text = results_csv(r.cells);
    if (a->out.empty() || a->out == "-") {
      fmt::print("{}", text);
    } else {
      write_option_file("--out", a->out, text);
      fmt::print(stderr, "wrote {} ({} cells)\n", a->out, r.cells.size());
    }
  });
}

void register_collect(CLI::App& sweep) {
  struct Args {
    std::string out;
    std::vector<std::string> inputs;
  };
  auto a = std::make_shared<Args>();
  CLI::App* collect = sweep.add_subcommand(
      "collect", "Merge the results files of shards into one, ordered by cell_index (identical duplicates collapse)");
  collect->add_option("out", a->out,
                      "Merged results file to write ('-': standard output, image paths then relative to the current "
                      "folder)")
      ->required();
  collect->add_option("inputs", a->inputs, "Results files of the shards")->required();
  collect->callback([a] {
    std::vector<fs::path> inputs(a->inputs.begin(), a->inputs.end());
    for (const std::string& in : a->inputs) refuse_overwriting({{"the input", &in}}, {{"the output", &a->out}});
    std::vector<std::string> warnings;
    const std::vector<nlohmann::json> cells = collect_results(inputs, a->out, &warnings);
    print_warnings(warnings);
    if (cells.empty())
      throw InputError(fmt::format("the {} input file(s) hold no finished cell; {} not written (check that the shards "
                                   "ran, and their results paths)",
                                   inputs.size(), a->out));
    if (a->out == "-") {
      std::string text = results_text(cells);
      text.pop_back();  // print_to_stdout ends the last line
      print_to_stdout(text);
      fmt::print(stderr, "merged {} cells from {} files\n", cells.size(), inputs.size());
      return;
    }
    write_option_file("the merged results file", a->out, results_text(cells));
    // The shards of a Slurm submission merged into the sweep's results file (as the executor
    // advises when it does not wait): recorded as the executor's own merge, which a later run with
    // --wait may then merge again.
    const fs::path out_dir = fs::absolute(a->out).parent_path();
    const SlurmLayout layout = slurm_layout(out_dir);
    if (a->out != "-" && std::all_of(inputs.begin(), inputs.end(), [&](const fs::path& in) {
          return fs::absolute(in).lexically_normal().parent_path() == layout.dir.lexically_normal();
        }))
      record_merge(layout, a->out);
    fmt::print("wrote {}: {} cells from {} files\n", a->out, cells.size(), inputs.size());
  });
}

}  // namespace

void register_sweep_command(CLI::App& root) {
  CLI::App* sweep = root.add_subcommand(
      "sweep",
      "Sweeps (DESIGN §7): scenes × interaxial × convergence × resolution × lights × ground truth,\n"
      "every pipeline validated and timed in each cell. Definitions: ci/*.toml; format and results\n"
      "schema: docs/sweeps.md.");
  sweep->require_subcommand(1);
  register_run(*sweep);
  register_cells(*sweep);
  register_csv(*sweep);
  register_collect(*sweep);
}

}  // namespace sb::cli
