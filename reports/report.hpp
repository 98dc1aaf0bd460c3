// The static HTML report of a sweep (DESIGN §7, docs/report.md): reads a results file only, never
// renders. Writes index.html with the data embedded as JSON, the page assets (report.js,
// report.css, Chart.js bundled from npm at build time) and the cells' images, so that the folder
// opens offline from disk (file://).
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "reports/results_file.hpp"

namespace sb::reports {

/// How the report refers to the cells' images.
enum class ImageMode {
  copy,  ///< copied under OUT/images/: the report folder stands alone and can be moved
  link,  ///< referenced by paths relative to OUT: no copies, but the results folder must stay beside it
};

struct ReportOptions {
  std::filesystem::path out_dir;  ///< written: index.html, assets/, images/ (copy mode)
  /// How a message names out_dir; empty: "--out DIR", the report command's option.
  std::string out_name;
  std::string title;              ///< empty: "stereobench report: <sweep>"
  ImageMode images = ImageMode::copy;
  /// Folder holding report.js, report.css, report.html, papers.json and chart.umd.min.js; empty:
  /// $STEREOBENCH_REPORT_ASSETS, else the build tree's copy (report_assets_dir()).
  std::filesystem::path assets_dir;
  /// The nightly runs of a history file (validation/history.hpp, one object per run in file order);
  /// an array, even an empty one, adds data.history and the page's Trends section. Null: none.
  nlohmann::json history;
  /// A note shown with the trends (e.g. how many runs of other sweeps sharing the history file
  /// they leave out); empty: none.
  std::string history_note;
};

/// What write_report produced.
struct ReportSummary {
  std::filesystem::path index_html;
  size_t images = 0;                  ///< images referenced (copied or linked)
  std::string paper_experiment;       ///< "kim-table2", ... or empty when the sweep is no paper preset
  std::vector<std::string> warnings;  ///< skipped lines, missing images
  /// The page data's pipeline names (baseline first) and cells (each with "pipelines": name ->
  /// psnr, ssim, hole_fraction, time_s, speedup, ...): what the report counts, and a summary on
  /// the terminal.
  nlohmann::json pipeline_names;
  nlohmann::json cells;
};

/// The page assets folder: $STEREOBENCH_REPORT_ASSETS when set, else the one configured at build
/// time (the build tree's report-assets/, where the build copies reports/assets and Chart.js).
[[nodiscard]] std::filesystem::path report_assets_dir();

/// ToolError naming the first page asset missing from `assets` and how to get it back. write_report
/// checks this itself; a long run that ends in a report checks it before it starts.
void check_report_assets(const std::filesystem::path& assets);

/// InputError when `out` cannot take a report: it is a file, or a folder that is not empty and holds
/// no stereobench report (write_report replaces an earlier report only). `named` names it in the
/// message ("--out DIR"). write_report checks this itself; a long run that ends in a report checks
/// it before it starts.
void check_report_folder(const std::filesystem::path& out, const std::string& named);

/// The paper experiment a sweep reproduces, by its name: "wissmann-table2", "kim-table2",
/// "kim-table3", "al-hagri" (any "al-hagri-*"), or empty.
[[nodiscard]] std::string paper_experiment(const std::string& sweep_name);

/// The data the page renders (schema "stereobench.report 1", docs/report.md): one entry per cell
/// with its axes, per-pipeline metrics, hole statistics, timings and image paths (as given by
/// `image_path`: the results file's relative path mapped to what index.html should load; it
/// returns an empty string for an image it could not provide, which becomes null), plus the
/// paper's numbers for a preset. `papers` is the content of papers.json.
[[nodiscard]] nlohmann::json report_data(
    const ResultsFile& results, const std::string& title, const nlohmann::json& papers,
    const std::function<std::string(const std::string& relative_path, const std::string& name)>& image_path);

/// Writes the report of `results` into options.out_dir. The folder must be new, empty, or hold an
/// earlier stereobench report (then its index.html, assets/ and images/ are replaced): InputError
/// otherwise.
/// ToolError (exit 4) when the assets folder lacks a file (Chart.js comes from `npm ci` in ci/,
/// run by ci/install-deps.sh chromium); IoError when writing fails. The report is written whole
/// into a hidden folder inside out_dir first and then moved into place, index.html last, so a
/// folder with an index.html holds a complete report, and a report that cannot be written (a
/// full disk) leaves the earlier one as it was.
ReportSummary write_report(const ResultsFile& results, const ReportOptions& options);

}  // namespace sb::reports
