// `stereobench report`: the static HTML report of a sweep's results file (reports/, docs/report.md).
#include <cstdio>
#include <memory>

#include <fmt/format.h>

#include "apps/commands.hpp"
#include "reports/report.hpp"

namespace sb::cli {

namespace {

struct ReportArgs {
  std::string results;
  std::string out;
  std::string title;
  bool link_images = false;
};

void run_report(const ReportArgs& a) {
  const reports::ResultsFile results = reports::read_results_file(a.results);
  reports::ReportOptions options;
  options.out_dir = a.out;
  options.title = a.title;
  options.images = a.link_images ? reports::ImageMode::link : reports::ImageMode::copy;
  const reports::ReportSummary s = reports::write_report(results, options);
  for (const std::string& w : s.warnings) std::fprintf(stderr, "stereobench: warning: %s\n", w.c_str());
  fmt::print("report of {} cell(s) x {} pipeline(s), {} image(s) {}{}\nwrote {}\n", s.cells, s.pipelines, s.images,
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
  r->callback([a] { run_report(*a); });
}

}  // namespace sb::cli
