// `stereobench nightly`: one nightly run of a sweep definition: the sweep (resumable) into a run
// folder, the gate (JUnit and JSON beside the results), one line appended to the history file, and
// the report with trend charts over every run of the history (docs/nightly.md). Exits with the
// gate's code (0 pass, 1 warnings, 2 failures); 3 bad input, 4 missing tool.
#include <unistd.h>

#include <algorithm>
#include <optional>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <regex>
#include <utility>

#include <fmt/format.h>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/file_lock.hpp"
#include "renderer/io/json_text.hpp"
#include "renderer/text.hpp"
#include "reports/report.hpp"
#include "validation/gate.hpp"
#include "validation/history.hpp"
#include "validation/junit.hpp"
#include "validation/process.hpp"
#include "validation/results_file.hpp"
#include "validation/sweep.hpp"
#include "validation/sweep_run.hpp"

namespace sb::cli {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace sb::validation;

constexpr const char* kDefaultGateConfig = "ci/gate.toml";
/// Written last into a run folder: the run is complete (history line appended, report written).
constexpr const char* kRunDoneFile = "nightly.json";

struct NightlyArgs {
  std::string definition;
  std::string out;
  std::string history;
  std::string gate_config;  ///< empty: the definition's [gate] config, else kDefaultGateConfig
  std::string baseline;
  std::string cache = "out/truth-cache";
  std::string scenes_dir;
  int jobs = 1;
  int threads = 0;
};

/// Run folder names: the UTC start "YYYYMMDDTHHMMSSZ", with "-N" appended when a run of the same
/// second exists.
const std::regex kRunIdPattern(R"((\d{4})(\d{2})(\d{2})T(\d{2})(\d{2})(\d{2})Z(-\d+)?)");

/// "2026-11-21T20:00:00Z" from a run id.
std::string run_date(const std::string& run_id) {
  std::smatch m;
  if (!std::regex_match(run_id, m, kRunIdPattern)) return run_id;
  return fmt::format("{}-{}-{}T{}:{}:{}Z", m[1].str(), m[2].str(), m[3].str(), m[4].str(), m[5].str(), m[6].str());
}

std::string host_name() {
  std::array<char, 256> buf{};
  if (::gethostname(buf.data(), buf.size() - 1) != 0) return "unknown";
  return buf.data();
}

/// `git rev-parse --short HEAD` in `dir`, or "unknown" (no git, not a work tree, no answer).
std::string git_revision(const fs::path& dir) {
  ProcessOptions options;
  options.stderr_to = ChildOutput::discard;
  options.timeout = kShortCommandTimeout;
  ProcessResult r;
  try {
    r = run_process({"git", "-C", dir.string(), "rev-parse", "--short", "HEAD"}, options);
  } catch (const ToolError&) {
    return "unknown";  // no git to start
  }
  std::string out = std::move(r.out);
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  if (!r.ok() || out.empty() || out.find_first_not_of("0123456789abcdef") != std::string::npos) return "unknown";
  return out;
}

/// Whether a history holds a line of run `run_id`.
bool history_holds(const HistoryFile& history, const std::string& run_id) {
  return std::any_of(history.runs.begin(), history.runs.end(), [&](const json& r) { return r["run_id"] == run_id; });
}

/// The run folder chosen, with its claim on its id in the history (held for the run's life) and the
/// history as read while choosing.
struct ChosenRun {
  fs::path dir;
  bool resumed = false;
  io::FileLock claim;
  HistoryFile history;
};

/// The run folder: the newest unfinished run of this definition version (resumed), else a new one
/// whose id neither a folder in `out`, nor a line of the history, nor another run's claim on it has
/// (other sweeps, with other --out folders, may share the history). Chosen under the history's lock,
/// the history read again under it, so that runs started in the same second take different ids.
ChosenRun choose_run_dir(const fs::path& out, const SweepDefinition& d, const fs::path& history_file) {
  const io::FileLock lock = lock_history(history_file);  // the folders and the history read under it
  std::vector<std::string> ids;
  std::error_code ec;
  if (fs::is_directory(out, ec))
    for (const fs::directory_entry& e : fs::directory_iterator(out, ec)) {
      const std::string name = e.path().filename().string();
      if (e.is_directory(ec) && std::regex_match(name, kRunIdPattern)) ids.push_back(name);
    }
  std::sort(ids.begin(), ids.end(), [](const std::string& a, const std::string& b) {
    // "-N" suffixes order after the plain id of the same second, and numerically among themselves.
    const std::string sa = a.substr(0, 16), sb = b.substr(0, 16);
    if (sa != sb) return sa < sb;
    // Compared as digit strings (shorter is smaller), so that any length of suffix orders.
    const std::string na = a.size() > 17 ? a.substr(17) : "1", nb = b.size() > 17 ? b.substr(17) : "1";
    return na.size() != nb.size() ? na.size() < nb.size() : na < nb;
  });
  ChosenRun chosen;
  chosen.history = read_history(history_file);
  if (!ids.empty()) {
    const fs::path newest = out / ids.back();
    if (!fs::exists(newest / kRunDoneFile, ec)) {
      const ResultsFile r = read_results(newest / "results.jsonl");
      // A run stopped before its first cell was recorded holds no line to tell: its folder's
      // sweep marker (written before the first cell) does, when it has one. One whose cells this
      // build cannot join (another pipeline set, where the definition lists "all") is left too.
      const bool same =
          r.cells.empty()
              ? validation::out_folder_is_for(d, newest)
              : !validation::why_not_resumable(d, validation::expand_cells(d).size(), r.cells.front()).has_value();
      if (same) {
        std::optional<io::FileLock> claim = claim_run_id(history_file, ids.back());
        if (!claim)
          throw InputError(fmt::format("the unfinished run {} is being run by another nightly (it holds the claim {} "
                                       "on id {} in {}); wait for that run to end, or give another --out",
                                       newest.string(), run_claim_path(history_file, ids.back()).string(),
                                       ids.back(), history_file.string()));
        chosen.dir = newest;
        chosen.resumed = true;
        chosen.claim = std::move(*claim);
        return chosen;
      }
      fmt::print(stderr, "note: the unfinished run {} is not a run of {} as this build runs it (its results or its "
                 "sweep marker name another definition or another set of pipelines, or the marker is damaged); "
                 "starting a new run, and leaving that folder as it is\n",
                 newest.string(), d.file.string());
    }
  }
  const std::string base = utc_now("%Y%m%dT%H%M%SZ");
  std::string id = base;
  for (int n = 2;; id = fmt::format("{}-{}", base, n++)) {
    if (fs::exists(out / id, ec) || history_holds(chosen.history, id) || run_id_claimed(history_file, id)) continue;
    std::optional<io::FileLock> claim = claim_run_id(history_file, id);
    if (!claim) continue;  // made meanwhile by a process that does not take the history's lock
    chosen.claim = std::move(*claim);
    break;
  }
  fs::create_directories(out / id, ec);
  if (ec) throw IoError(fmt::format("cannot create the run folder {}: {}", (out / id).string(), ec.message()));
  chosen.dir = out / id;
  return chosen;
}

/// InputError when `history` holds run `run_id` of another results file than this run's: a
/// history shared between sweeps whose line took this id, so this run cannot be recorded there.
void refuse_foreign_run(const HistoryFile& history, const fs::path& history_file, const std::string& run_id,
                        const std::string& results_in_history, const fs::path& results, const fs::path& run_dir) {
  for (const json& r : history.runs)
    if (r["run_id"] == run_id && r.value("results", "") != results_in_history)
      throw InputError(fmt::format(
          "{} already holds a run {} of another results file ({}, sweep '{}'), so this run ({}) cannot be recorded "
          "there; give this sweep its own --history, or move the unfinished run folder {} away to start a new run",
          history_file.string(), run_id, r.value("results", "?"), r.value("sweep", "?"), results.string(),
          run_dir.string()));
}

/// The history file as messages name it: as the option that gave it, or as the default file.
std::string history_named(const fs::path& file, bool given) {
  return given ? fmt::format("--history {}", file.string()) : fmt::format("history file {}", file.string());
}

/// Makes sure the history line can be appended at the end of the run, before the sweep costs
/// anything: the history file's folder exists or is made, and the file, where it exists, is a
/// writable regular file. `given`: the path came from --history.
void check_history_writable(const fs::path& file, bool given) {
  const std::string named = history_named(file, given);
  const fs::path folder = file.has_parent_path() ? file.parent_path() : fs::path(".");
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec || !fs::is_directory(folder))
    throw IoError(fmt::format("{}: cannot make its folder {}: {}; give a history file in a writable folder", named,
                              folder.string(), ec ? ec.message() : "a file of that name is in the way"));
  const bool exists = fs::exists(file, ec);
  if (exists && !fs::is_regular_file(file, ec))
    throw InputError(fmt::format("{} is not a regular file; give the JSON Lines file the runs are appended to", named));
  if (::access(exists ? file.c_str() : folder.c_str(), W_OK) != 0)
    throw IoError(fmt::format("{}: {} is not writable ({}); give a history file in a writable folder", named,
                              exists ? "the file" : "its folder", std::strerror(errno)));
}

void run_nightly(const NightlyArgs& a) {
  if (a.jobs < 1 || a.jobs > 256) throw InputError(fmt::format("--jobs {} is outside 1..256", a.jobs));
  const int threads = checked_threads(a.threads);
  const SweepDefinition d = load_sweep(a.definition);
  print_warnings(d.warnings);
  const std::string gate_file = !a.gate_config.empty() ? a.gate_config
                                : d.gate_config        ? d.gate_config->string()
                                                       : std::string(kDefaultGateConfig);
  if (a.gate_config.empty() && d.gate_config && !fs::exists(*d.gate_config))
    throw InputError(fmt::format("{}: [gate] config names {}, which does not exist; fix the path (relative to the "
                                 "definition) or give --gate-config FILE",
                                 d.file.string(), d.gate_config->string()));
  const GateConfig gate_config = load_gate_config(gate_file);
  const fs::path out = a.out.empty() ? fs::path("out") / "nightly" / d.name : fs::path(a.out);
  const fs::path history_file = a.history.empty() ? out / "history.jsonl" : fs::path(a.history);
  // Read before any cell runs: a malformed history stops the run before it costs anything, and so
  // does a missing report asset (the report is written last).
  if (std::error_code ec; fs::is_directory(history_file, ec))
    throw InputError(fmt::format("{} is a folder; give the JSON Lines file the runs are appended to",
                                 history_named(history_file, !a.history.empty())));
  const HistoryFile history_before = read_history(history_file);
  reports::check_report_assets(reports::report_assets_dir());  // before the history's folder is made
  print_warnings(history_before.warnings);

  Baseline baseline;
  std::string baseline_note;
  const fs::path baseline_file = a.baseline.empty() ? fs::path(kDefaultBaselineFile) : fs::path(a.baseline);
  if (!a.baseline.empty() || fs::exists(baseline_file))
    baseline = load_baseline(baseline_file);
  else if (!gate_config.sets_limits())
    throw InputError(fmt::format("{} sets no threshold, only [regression], and there is no baseline file {}: the gate "
                                 "would check nothing; give thresholds, or --baseline FILE (gate --update-baseline "
                                 "stores one)",
                                 gate_file, baseline_file.string()));
  else
    baseline_note = fmt::format("no baseline file {}: time regressions not checked", baseline_file.string());
  // A gate of time regressions alone with a baseline that holds none of this sweep's cells would
  // check nothing either, found only once every cell has run.
  if (!gate_config.sets_limits() && baseline_note.empty()) {
    bool matches = false;
    for (const SweepCell& c : expand_cells(d))
      for (const std::string& p : d.pipelines) matches = matches || baseline.find(c.id, p) != nullptr;
    if (!matches)
      throw InputError(fmt::format("{} sets no threshold, only [regression], and the baseline {} holds no (cell, "
                                   "pipeline) of sweep '{}': the gate would check nothing; give thresholds, or a "
                                   "baseline of this sweep (gate --update-baseline stores one)",
                                   gate_file, baseline_file.string(), d.name));
  }

  // The folders are made once every argument is known to be good: a usage error leaves none.
  // The run folders go under --out: a folder that cannot be made is named as that option (the
  // default history file lies there too, and was blamed).
  // A --history elsewhere is checked before --out is made, so that its refusal leaves no empty
  // run folder behind; the default one lies in --out.
  if (const std::optional<std::string> why = io::folder_cannot_be_made(out))
    throw IoError(fmt::format("--out {}: {}; give a folder you can write", out.string(), *why));
  if (!a.history.empty()) check_history_writable(history_file, true);
  if (const std::optional<std::string> why = io::unwritable_folder(out))
    throw IoError(fmt::format("--out {}: {}; give a folder you can write", out.string(), *why));
  if (a.history.empty()) check_history_writable(history_file, false);

  // 1. The sweep, into the run folder.
  ChosenRun chosen = choose_run_dir(out, d, history_file);
  const fs::path& run_dir = chosen.dir;
  const bool resumed = chosen.resumed;
  const std::string run_id = run_dir.filename().string();
  SweepRunOptions o;
  o.out_dir = run_dir;
  o.results = run_dir / "results.jsonl";
  // The results file as the history line names it: relative to the history file's folder.
  const fs::path history_dir = history_file.has_parent_path() ? history_file.parent_path() : fs::path(".");
  const std::string results_in_history = fs::absolute(o.results)
                                             .lexically_normal()
                                             .lexically_relative(fs::absolute(history_dir).lexically_normal())
                                             .generic_string();
  const fs::path report_dir = run_dir / "report";
  const std::string report_name = fmt::format("the run's report folder {}", report_dir.string());
  reports::check_report_folder(report_dir, report_name);  // written last, checked first
  // A resumed run whose id a line of another run took meanwhile (a history shared between sweeps)
  // could not be recorded: stop before the sweep.
  refuse_foreign_run(chosen.history, history_file, run_id, results_in_history, o.results, run_dir);
  o.scenes_dir = a.scenes_dir;
  if (!a.cache.empty()) o.truth_cache = fs::path(a.cache);
  o.definition_label = a.definition;
  o.jobs = a.jobs;
  o.threads = threads;
  // Every cell, held through the gate, history and report.
  const ResultsWriterLock lock(o.results, shard_cells(expand_cells(d).size(), Shard{}));
  const SweepPlan plan = plan_sweep(d, o.results);
  print_warnings(plan.warnings);
  fmt::print("nightly {} run {} ({}): {} cells × {} pipelines, {} finished already, {} to run\n", d.name, run_id,
             resumed ? "resumed" : "new", plan.cells.size(), d.pipelines.size(), plan.finished, plan.todo.size());
  std::fflush(stdout);
  if (!plan.todo.empty()) {
    prepare_sweep(d, plan.cells, plan.todo, o);
    const auto start = std::chrono::steady_clock::now();
    run_cells(d, plan.cells, plan.todo, o, [](const CellProgress& p) {
      fmt::print(stderr, "[{}/{}] cell {} {} done in {:.1f} s\n", p.finished, p.total, p.cell.index, p.cell.id,
                 p.wall_s);
      std::fflush(stderr);
    });
    fmt::print("ran {} cells in {:.1f} s\n", plan.todo.size(),
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }

  // 2. The gate. Its files are written once the history and the report are, so that a run that
  // stops on the way (exit 3 or 4) leaves no verdict behind; those of an earlier attempt at this
  // run go first.
  const fs::path junit_file = run_dir / "gate-junit.xml", gate_json_file = run_dir / "gate.json";
  remove_earlier_output(junit_file, "gate JUnit");
  remove_earlier_output(gate_json_file, "gate JSON");
  const GateResults results = load_gate_results(o.results);
  GateReport gate =
      evaluate_gate(gate_config, results, baseline, registered_reproduce_settings());  // notes the read warnings
  if (!baseline_note.empty()) gate.notes.push_back(baseline_note);
  fmt::print("{}", format_gate_table(gate));

  // 3. The history line (once per run, also when a run killed after appending it is resumed).
  NightlyRun run;
  run.run_id = run_id;
  run.date = run_date(run_id);
  run.host = host_name();
  run.git_revision = git_revision(fs::absolute(d.file).parent_path());
  run.sweep = d.name;
  run.definition = a.definition;
  run.definition_sha256 = d.sha256;
  run.results = results_in_history;
  std::vector<json> cells;
  for (const GateCell& c : results.cells) cells.push_back(c.record);
  HistoryFile history;
  {
    // Checked again under the lock: the history may have taken lines since the run began.
    const io::FileLock history_lock = lock_history(history_file);
    history = read_history(history_file);
    refuse_foreign_run(history, history_file, run_id, results_in_history, o.results, run_dir);
    if (history_holds(history, run_id)) {
      fmt::print(stderr, "note: {} already holds run {}; not appended again\n", history_file.string(), run_id);
      // A resumed run gated anew (another gate config, changed thresholds): the line keeps what it
      // recorded, which the trends show; said, so that the files' disagreement is not a surprise.
      for (const json& r : history.runs)
        if (r["run_id"] == run_id) {
          const json recorded = r.value("gate", json::object());
          if (recorded.value("verdict", "") != gate_verdict(gate))
            print_warning(fmt::format(
                       "run {} is recorded in {} with the gate verdict '{}' (exit {}); this evaluation "
                       "gives '{}' (exit {}), which the run's gate files and nightly.json hold. A history line "
                       "is never rewritten: the trends keep the recorded verdict",
                       run_id, history_file.string(), recorded.value("verdict", "?"),
                       recorded.value("exit_code", -1), gate_verdict(gate), exit_code(gate.worst)));
        }
    } else {
      append_history(history_file, history_entry(run, cells, gate));
      history = read_history(history_file);
    }
  }

  // 4. The report with the trends.
  const reports::ResultsFile report_results = reports::read_results_file(o.results);
  reports::ReportOptions options;
  options.out_dir = report_dir;
  options.out_name = report_name;
  options.title = fmt::format("stereobench nightly: {} {}", d.name, run.date);
  // The trends are this sweep's: a history shared with other sweeps keeps their runs out.
  SweepRuns trends = runs_of_sweep(history, d.name, history_file);
  if (!trends.left_out.empty()) {
    options.history_note = fmt::format("The {}.", trends.left_out_on_page);
    fmt::print(stderr, "note: the {}\n", trends.left_out);
  }
  options.history = std::move(trends.runs);
  const reports::ReportSummary s = reports::write_report(report_results, options);
  print_warnings(s.warnings);

  // The verdict files and the done file stand together: a write that fails removes those written.
  const int code = exit_code(gate.worst);
  const std::string junit_path = junit_file.string(), gate_json_path = gate_json_file.string(),
                    done_path = (run_dir / kRunDoneFile).string();
  write_all_or_none({{"gate JUnit", &junit_path}, {"gate JSON", &gate_json_path}, {"nightly.json", &done_path}}, [&] {
    io::write_text_atomically(junit_file, junit_xml(gate, "stereobench nightly " + o.results.string()));
    io::write_text_atomically(gate_json_file,
                              io::json_text(gate_report_json(gate, gate_file, o.results.string(),
                                                             baseline_note.empty() ? baseline_file.string() : ""),
                                            2) +
                                  "\n");
    // The paths absolute: read by CI steps started in another folder.
    const json done = {{"run_id", run_id},
                       {"date", run.date},
                       {"gate_verdict", gate_verdict(gate)},
                       {"exit_code", code},
                       {"history", fs::absolute(history_file).lexically_normal().string()},
                       {"report", fs::absolute(s.index_html).lexically_normal().string()}};
    io::write_text_atomically(done_path, io::json_text(done, 2) + "\n");
  });
  drop_run_claim(history_file, chosen.claim);
  fmt::print("history {} ({} runs)\nreport {}\ngate verdict: {} (exit {})\n", history_file.string(),
             history.runs.size(), s.index_html.string(), gate_verdict(gate), code);
  if (code != 0) throw VerdictExit{code};
}

}  // namespace

void register_nightly_command(CLI::App& root) {
  auto a = std::make_shared<NightlyArgs>();
  CLI::App* n = root.add_subcommand(
      "nightly",
      "One nightly run: the sweep (resuming the newest unfinished run) into OUT/<UTC date-time>/, the\n"
      "gate (gate-junit.xml, gate.json there), one line appended to the history file, and the report\n"
      "(OUT/<run>/report/) with trend charts over the history. Exit: the gate's 0/1/2; 3 bad input,\n"
      "4 missing tool. See docs/nightly.md.");
  n->add_option("definition", a->definition, "Sweep definition (TOML), e.g. ci/nightly.toml")->required();
  n->add_option("--out", a->out, "Folder of the runs (default out/nightly/<sweep name>)");
  n->add_option("--history", a->history, "History file (JSON Lines; default <out>/history.jsonl)");
  n->add_option("--gate-config", a->gate_config,
                fmt::format("Gate thresholds (TOML); default the definition's [gate] config, else {}",
                            kDefaultGateConfig));
  n->add_option(
      "--baseline", a->baseline,
      fmt::format("Timing baseline (JSON); default {} (if absent, no regression check)", kDefaultBaselineFile));
  n->add_option("--jobs,-j", a->jobs, "Cells run at once (1 keeps timings undisturbed)")->capture_default_str();
  n->add_option("--threads,-t", a->threads, "Threads per cell (0 = the machine's cores / jobs)")->capture_default_str();
  n->add_option("--cache", a->cache, "Folder of cached external ground-truth renders ('' to disable)")
      ->capture_default_str();
  add_scenes_dir_option(*n, a->scenes_dir);
  n->callback([a] { run_nightly(*a); });
}

}  // namespace sb::cli
