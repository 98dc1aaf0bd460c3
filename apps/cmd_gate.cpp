// `stereobench gate`: the CI quality gate. Applies ci/gate.toml's thresholds and the time-regression
// test against a stored baseline to a sweep's results file, prints the checks that did not pass,
// writes JUnit XML and JSON, and exits 0 (pass), 1 (warnings only) or 2 (any failure); bad input is 3.
// `--update-baseline` instead stores the timing samples of the named pipelines and cells.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>

#include <fmt/format.h>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/file_lock.hpp"
#include "renderer/io/json_text.hpp"
#include "validation/gate.hpp"
#include "validation/junit.hpp"

namespace sb::cli {

namespace {

namespace fs = std::filesystem;

struct GateArgs {
  std::string config = "ci/gate.toml";
  std::string results;
  std::string baseline;
  std::string junit;
  std::string json_out;
  bool update_baseline = false;
  std::vector<std::string> only;
  std::string cells;
};

/// Rewrites the entries of the baseline `file` that the selection names.
void run_update(const GateArgs& a, const fs::path& file) {
  const validation::BaselineSelection selection{split_list(a.only, "--only"), a.cells};
  // The rank test's minimum comes from the gate config the baseline will be checked with (the
  // default's when that file is not here).
  const bool has_config = fs::exists(a.config);
  const int min_repetitions = has_config ? validation::load_gate_config(a.config).regression.min_repetitions
                                         : validation::RegressionSettings{}.min_repetitions;
  const validation::GateResults results = validation::load_gate_results(a.results);
  print_warnings(results.warnings);
  // Updates of one baseline take turns: each reads the entries the one before it wrote (two at
  // once lost one's entries). The lock file goes with the lock.
  std::error_code ec;
  if (file.has_parent_path()) fs::create_directories(file.parent_path(), ec);  // else the lock names the problem
  io::FileLock lock = io::FileLock::acquire(file.string() + ".lock", [&] {
    fmt::print(stderr, "waiting for another update of {} to finish\n", file.string());
  });
  lock.remove_when_released();
  // Damaged entries are mended by rewriting them; one the update leaves alone stops it.
  std::vector<validation::DamagedEntry> damaged;
  validation::Baseline baseline = fs::exists(file) ? validation::load_baseline(file, &damaged) : validation::Baseline{};
  const std::vector<validation::BaselineChange> changes = validation::update_baseline(baseline, results, selection);
  for (const validation::DamagedEntry& d : damaged)
    if (std::none_of(changes.begin(), changes.end(), [&](const validation::BaselineChange& c) {
          return c.cell_id == d.cell_id && c.pipeline == d.pipeline;
        }))
      throw InputError(fmt::format("{} (this update does not rewrite it; the baseline is left as it was)", d.message));
  validation::save_baseline(file, baseline);
  for (const validation::BaselineChange& c : changes) {
    if (c.replaced)
      fmt::print("updated {} {}: median {:.4g} s -> {:.4g} s\n", c.cell_id, c.pipeline, c.old_median_s, c.new_median_s);
    else
      fmt::print("added   {} {}: median {:.4g} s\n", c.cell_id, c.pipeline, c.new_median_s);
  }
  fmt::print("wrote {} ({} entr{} from {}; every other entry unchanged)\n", file.string(), changes.size(),
             changes.size() == 1 ? "y" : "ies", a.results);
  // Too few samples store a baseline that every later time check can only warn about.
  size_t short_entries = 0, fewest = std::numeric_limits<size_t>::max();
  for (const validation::BaselineChange& c : changes)
    if (c.samples < static_cast<size_t>(min_repetitions)) {
      ++short_entries;
      fewest = std::min(fewest, c.samples);
    }
  if (short_entries > 0)
    print_warning(fmt::format(
               "{} of the {} stored entr{} hold{} fewer than the {} timing samples the rank test needs "
               "({}; the fewest: {}): every time check against {} will warn \"not enough repetitions\" and never "
               "pass or fail; set repetitions = {} or more in the [timing] table of the sweep's definition, "
               "run the sweep again and update",
               short_entries, changes.size(), changes.size() == 1 ? "y" : "ies", short_entries == 1 ? "s" : "",
               min_repetitions,
               has_config ? fmt::format("[regression] min_repetitions in {}", a.config)
                          : fmt::format("the default min_repetitions; {} is not here", a.config),
               fewest, short_entries == 1 ? "it" : "them", min_repetitions));
}

/// The baseline file a run reads: --baseline, or the default one.
std::string baseline_of(const GateArgs& a) { return a.baseline.empty() ? validation::kDefaultBaselineFile : a.baseline; }

/// Removes the --junit and --json files an earlier run left: exit 3 or 4 leaves none, whatever
/// refuses the run, so that an earlier green report never stands for this one. The inputs are
/// spared, the default baseline among them (a report written over ci/baseline.json would lose
/// the stored timings).
void discard_earlier_reports(const GateArgs& a) {
  const std::string baseline_path = baseline_of(a);
  remove_earlier_outputs_sparing({{"--results", &a.results}, {"--config", &a.config}, {"the baseline", &baseline_path}},
                                 {{"--junit", &a.junit}, {"--json", &a.json_out}});
}

void run_gate(const GateArgs& a) {
  const std::string baseline_path = baseline_of(a);
  discard_earlier_reports(a);
  if (a.update_baseline) {
    if (!a.junit.empty() || !a.json_out.empty())
      throw InputError(
          fmt::format("{} writes a gate run's checks; --update-baseline only rewrites the baseline {}: "
                      "drop {} or run the gate without --update-baseline",
                      !a.junit.empty() ? "--junit" : "--json", baseline_path, !a.junit.empty() ? "--junit" : "--json"));
    refuse_overwriting({{"--results", &a.results}, {"--config", &a.config}}, {{"the baseline", &baseline_path}});
    run_update(a, baseline_path);
    return;
  }
  if (!a.only.empty() || !a.cells.empty())
    throw InputError("--only and --cells select what --update-baseline rewrites; add --update-baseline or drop them");
  for (const auto& [option, path] : {std::pair{"--junit", &a.junit}, std::pair{"--json", &a.json_out}})
    if (*path == "-")
      throw InputError(fmt::format("{} -: the gate writes its report to a file (standard output shows the table); "
                                   "give a file name",
                                   option));
  refuse_overwriting({{"--results", &a.results}, {"--config", &a.config}, {"the baseline", &baseline_path}},
                     {{"--junit", &a.junit}, {"--json", &a.json_out}});
  prepare_output_file_folder(a.junit, "--junit");
  prepare_output_file_folder(a.json_out, "--json");
  const validation::GateConfig config = validation::load_gate_config(a.config);
  const validation::GateResults results = validation::load_gate_results(a.results);

  // The baseline: an explicit --baseline must exist; the default one may be absent.
  validation::Baseline baseline;
  std::string baseline_note;
  const fs::path baseline_file(baseline_path);
  if (!a.baseline.empty() || fs::exists(baseline_file))
    baseline = validation::load_baseline(baseline_file);
  else
    baseline_note = fmt::format(
        "no baseline file {}: time regressions not checked (store one with "
        "--update-baseline)",
        baseline_file.string());

  validation::GateReport report =
      validation::evaluate_gate(config, results, baseline, validation::registered_reproduce_settings());
  if (!baseline_note.empty()) report.notes.push_back(baseline_note);
  // The report files first: the table ends in the verdict and its exit code, which stand only once
  // they are written. Exit 4 leaves neither file: a JUnit file beside a failed run would read as
  // its verdict.
  try {
    write_all_or_none({{"--junit", &a.junit}, {"--json", &a.json_out}}, [&] {
      if (!a.junit.empty())
        write_option_file("--junit", a.junit, validation::junit_xml(report, "stereobench gate " + a.results));
      if (!a.json_out.empty())
        write_option_file("--json", a.json_out,
                          io::json_text(validation::gate_report_json(report, a.config, a.results,
                                                                     baseline_note.empty() ? baseline_file.string()
                                                                                           : ""),
                                        2) +
                              "\n");
    });
  } catch (const IoError&) {
    fmt::print("{}gate: the verdict above does not stand: its report files could not be written (exit 4)\n",
               validation::format_gate_table(report));
    throw;
  }
  fmt::print("{}", validation::format_gate_table(report));
  if (!a.junit.empty()) fmt::print("wrote {}\n", a.junit);
  if (!a.json_out.empty()) fmt::print("wrote {}\n", a.json_out);
  if (const int code = validation::exit_code(report.worst); code != 0) throw VerdictExit{code};
}

}  // namespace

void register_gate_command(CLI::App& root) {
  auto a = std::make_shared<GateArgs>();
  CLI::App* g = root.add_subcommand(
      "gate",
      "The CI quality gate: apply the thresholds of a gate config (min PSNR, SSIM, disocclusion recall,\n"
      "speed-up; max hole and error-pixel fractions, right eye's time over the left eye's; time\n"
      "regression against a stored baseline by median, tolerance and a Mann-Whitney rank test) to\n"
      "every pipeline of every cell of a sweep's results file. Exit 0 all pass, 1 warnings only,\n"
      "2 any failure, 3 bad input, 4 an output that cannot be written; on 3 and 4 no --junit or\n"
      "--json file is left (an earlier one is removed). Each failure comes with the command that\n"
      "re-measures it: `stereobench validate` for quality, `stereobench bench` for the speed-up, the\n"
      "right eye's share and the time regression. See docs/gate.md.");
  g->add_option("--config", a->config, "Gate thresholds (TOML)")->capture_default_str();
  g->add_option("--results", a->results, "A sweep's results.jsonl")->required();
  g->add_option("--baseline", a->baseline,
                fmt::format("Timing baseline (JSON); default {} (if absent, no regression check)",
                            validation::kDefaultBaselineFile));
  g->add_option("--junit", a->junit, "Write JUnit XML here (one testsuite per cell, one testcase per check)");
  g->add_option("--json", a->json_out, "Write every check as JSON here");
  g->add_flag("--update-baseline", a->update_baseline,
              "Store the results' timing samples as the baseline for what --only/--cells name, and exit");
  g->add_option("--only", a->only, "With --update-baseline: pipelines to store (comma-separated or repeated)");
  g->add_option("--cells", a->cells, "With --update-baseline: cells to store, a glob over cell ids ('*' for all)");
  g->callback([a] { run_gate(*a); });
}

void discard_gate_reports_after_usage_error(CLI::App& root) noexcept {
  try {
    const CLI::App* g = root.get_subcommand("gate");
    if (g->parsed() == 0) return;
    // The values as typed: a usage error may come before they reach GateArgs (CLI11 converts
    // and checks values after reading the whole line). An empty one (itself a usage error) stands
    // for the default, as run_gate reads it.
    const auto typed = [&](const char* name, std::string& into) {
      const CLI::Option* o = g->get_option_no_throw(name);
      if (o != nullptr && !o->results().empty() && !o->results().back().empty()) into = o->results().back();
    };
    GateArgs a;
    typed("--results", a.results);
    typed("--config", a.config);
    typed("--baseline", a.baseline);
    // Every value of a report option given more than once (itself the usage error): each names a
    // file an earlier run may have left.
    const auto every = [&](const char* name) {
      std::vector<std::string> values;
      if (const CLI::Option* o = g->get_option_no_throw(name))
        for (const std::string& v : o->results())
          if (!v.empty()) values.push_back(v);
      if (values.empty()) values.emplace_back();
      return values;
    };
    for (const std::string& junit : every("--junit"))
      for (const std::string& json_out : every("--json")) {
        a.junit = junit;
        a.json_out = json_out;
        discard_earlier_reports(a);
      }
  } catch (const std::exception& e) {
    print_warning(std::string("an earlier gate report may remain: ") + e.what());
  }
}

}  // namespace sb::cli
