// `stereobench report`: the static HTML report of a sweep's results file (reports/, docs/report.md).
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>
#include <filesystem>
#include <memory>

#include <fmt/format.h>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "renderer/error.hpp"
#include "reports/report.hpp"
#include "validation/gate.hpp"
#include "validation/history.hpp"

namespace sb::cli {

namespace {

struct ReportArgs {
  std::string results;
  std::string out;
  std::string title;
  bool link_images = false;
  std::string history;
};

/// The median over the cells of one value of a pipeline, NaN when no cell has a number for it.
double cell_median(const nlohmann::json& cells, const std::string& pipeline, const char* key) {
  std::vector<double> values;
  for (const nlohmann::json& c : cells) {
    const auto p = c["pipelines"].find(pipeline);
    if (p == c["pipelines"].end() || !p->contains(key)) continue;
    const nlohmann::json& v = (*p)[key];
    if (v.is_number()) values.push_back(v.get<double>());
    if (v.is_string() && v.get<std::string>() == "inf") values.push_back(std::numeric_limits<double>::infinity());
  }
  return validation::median(std::move(values));
}

/// The report's "Summary per pipeline" on the terminal: medians over the cells.
void print_summary_table(const reports::ReportSummary& s) {
  if (!s.pipeline_names.is_array() || !s.cells.is_array() || s.cells.empty()) return;
  std::vector<std::string> names;
  for (const nlohmann::json& name : s.pipeline_names) names.push_back(name.get<std::string>());
  const size_t name_w = pipeline_column(names);
  fmt::print("\n{:<{}} {:>8} {:>8} {:>8} {:>11} {:>9} {:>13}   (medians over {} cell(s))\n", "pipeline", name_w,
             "PSNR dB", "SSIM", "holes %", "time ms", "speed-up", "right/left %", s.cells.size());
  for (const std::string& p : names) {
    const double speedup = cell_median(s.cells, p, "speedup");
    fmt::print("{:<{}} {:>8} {:>8} {:>8} {:>11} {:>9} {:>13}\n", p, name_w,
               table_number(cell_median(s.cells, p, "psnr"), 2), table_number(cell_median(s.cells, p, "ssim"), 4),
               table_number(cell_median(s.cells, p, "hole_fraction"), 3, 100.0),
               table_number(cell_median(s.cells, p, "time_s"), 2, 1000.0),
               std::isnan(speedup) ? std::string("-") : table_number(speedup, 2) + "x",
               table_number(cell_median(s.cells, p, "right_over_left"), 1, 100.0));
  }
  // Left eyes synthesized in part (bidir-warp's), as the page's "Left eyes" section has them.
  bool header = false;
  for (const std::string& p : names) {
    const double share = cell_median(s.cells, p, "left_synthesized_fraction");
    if (std::isnan(share)) continue;
    if (!header)
      fmt::print("\n{:<{}} {:>8} {:>8} {:>13}   (left eyes synthesized in part, against plain-rt's left eye)\n",
                 "pipeline", name_w, "PSNR dB", "SSIM", "synthesized %");
    header = true;
    fmt::print("{:<{}} {:>8} {:>8} {:>13}\n", p, name_w, table_number(cell_median(s.cells, p, "left_psnr"), 2),
               table_number(cell_median(s.cells, p, "left_ssim"), 4), table_number(share, 1, 100.0));
  }
  fmt::print("\n");
}

void run_report(const ReportArgs& a) {
  reports::ReportOptions options;
  options.out_dir = a.out;
  options.title = a.title;
  options.images = a.link_images ? reports::ImageMode::link : reports::ImageMode::copy;
  validation::HistoryFile h;
  if (!a.history.empty()) {
    if (!std::filesystem::exists(a.history))
      throw InputError(fmt::format("--history {}: file does not exist", a.history));
    h = validation::read_history(a.history);
    print_warnings(h.warnings);
  }
  const reports::ResultsFile results = reports::read_results_file(a.results);
  if (!a.history.empty()) {
    // The trends are the results' sweep's, as nightly draws them.
    validation::SweepRuns trends =
        validation::runs_of_sweep(h, results.cells.front().json.value("sweep", ""), a.history);
    if (!trends.left_out.empty()) {
      options.history_note = fmt::format("The {}.", trends.left_out_on_page);
      std::fprintf(stderr, "stereobench: note: the %s\n", trends.left_out.c_str());
    }
    options.history = std::move(trends.runs);
  }
  const reports::ReportSummary s = reports::write_report(results, options);
  print_warnings(s.warnings);
  print_summary_table(s);
  fmt::print("report of {} cell(s) x {} pipeline(s), {} image(s) {}{}\nwrote {}\n", s.cells.size(), s.pipeline_names.size(), s.images,
             a.link_images ? "linked" : "copied",
             s.paper_experiment.empty() ? "" : fmt::format(", beside the paper's numbers ({})", s.paper_experiment),
             s.index_html.string());
}

}  // namespace

void register_report_command(CLI::App& root) {
  auto a = std::make_shared<ReportArgs>();
  CLI::App* r = root.add_subcommand(
      "report",
      "Write a static HTML report of a sweep from its results file (never renders): summary tables,\n"
      "charts (speed-up vs resolution, PSNR/SSIM/MSE and holes vs interaxial, per-stage times), the\n"
      "paper's table beside ours for a preset sweep, and an image viewer per cell. The folder opens\n"
      "offline from disk (file://). See docs/report.md.");
  r->add_option("results", a->results, "The sweep's results file (results.jsonl)")->required();
  r->add_option("--out,-o", a->out, "Report folder (new, empty, or an earlier report to replace)")->required();
  r->add_option("--title", a->title, "Page title (default: \"stereobench report: <sweep>\")");
  r->add_flag("--link-images", a->link_images,
              "Refer to the cells' images by relative paths instead of copying them under OUT/images\n"
              "(smaller, but the report then needs the results folder where it was)");
  r->add_option("--history", a->history,
                "History file of nightly runs (docs/nightly.md): adds a Trends section, per pipeline PSNR\n"
                "and median time and the gate verdict per run");
  r->callback([a] { run_report(*a); });
}

}  // namespace sb::cli
