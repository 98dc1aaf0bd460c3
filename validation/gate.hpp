// The CI quality gate (DESIGN §7): thresholds per (pipeline, scene) from ci/gate.toml applied to the
// cells of a sweep's results file, and a time-regression test against stored baseline samples.
// Numbers in, verdicts out: no rendering, no output files (junit.hpp and the CLI write those).
#pragma once

#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "validation/baseline.hpp"

namespace sb::validation {

/// A check's outcome. `skip` is a check that could not be made (no value, no baseline entry); it
/// does not change the exit code but is listed.
enum class Verdict { pass, skip, warn, fail };

[[nodiscard]] const char* to_string(Verdict v) noexcept;

/// Exit code of a whole gate run (DESIGN §2): 0 all pass (or skipped), 1 warnings only, 2 any failure.
[[nodiscard]] int exit_code(Verdict worst) noexcept;

/// Whether a metric must stay above (`at_least`) or below (`at_most`) its limit.
enum class Direction { at_least, at_most };

/// One threshold check on a number of a sweep cell's pipeline entry.
struct MetricCheck {
  const char* name;      ///< check name in reports and JUnit ("psnr")
  const char* fail_key;  ///< gate.toml key of the fail level ("min_psnr")
  const char* warn_key;  ///< gate.toml key of the warn level ("warn_psnr")
  Direction direction;
  const char* pointer;  ///< JSON pointer into the pipeline entry of a results line
  const char* label;    ///< what the number is, for messages ("PSNR")
  double largest = std::numeric_limits<double>::infinity();  ///< the largest value the metric takes
  /// A JSON pointer into the pipeline entry, or null: where the entry holds null there, the check
  /// does not apply to it (no check is made, none is listed): a pipeline that renders its left eye
  /// whole has `validation.left_eye` null, and nothing of its left eye to measure.
  const char* applies_unless_null = nullptr;
  /// Whether a record may lack the number (absent or null) for a reason of its own: a recall with
  /// nothing disoccluded is undefined, a cell timed without a baseline pipeline has no speed-up,
  /// a record written before left eyes were measured has no left-eye metrics.
  /// Such a check is skipped; any other check fails on a record without its number, which is
  /// damaged or of another version (a PSNR the gate cannot read must not pass).
  bool may_be_missing = false;
  /// A JSON pointer into the pipeline entry, or null: a count that is 0 where the metric is
  /// undefined for the image itself (SSIM of an image smaller than its 11x11 window). A null value
  /// with that count 0 is skipped, not failed.
  const char* defined_by = nullptr;
  /// The smallest value the metric takes: a minimum at or below it (a maximum at or above
  /// `largest`) can never be crossed, and checks nothing. PSNR of 8-bit images is at least 0 dB
  /// (the MSE at most 255^2); a speed-up is above 0.
  double smallest = 0.0;
};

/// Every threshold check, in report order. The time regression is separate (RegressionSettings).
inline constexpr MetricCheck kMetricChecks[] = {
    {"psnr", "min_psnr", "warn_psnr", Direction::at_least, "/validation/metrics/psnr", "PSNR"},
    {"ssim", "min_ssim", "warn_ssim", Direction::at_least, "/validation/metrics/ssim", "SSIM", 1.0, nullptr, false,
     "/validation/metrics/ssim_pixels", -1.0},
    {"error_fraction", "max_error_fraction", "warn_error_fraction", Direction::at_most,
     "/validation/metrics/error_fraction", "error-pixel fraction", 1.0},
    {"hole_fraction", "max_hole_fraction", "warn_hole_fraction", Direction::at_most, "/validation/holes/hole_fraction",
     "hole fraction", 1.0},
    {"disocclusion_recall", "min_recall", "warn_recall", Direction::at_least,
     "/validation/holes/not_reprojected/recall", "disocclusion recall", 1.0, nullptr, true},
    {"left_psnr", "min_left_psnr", "warn_left_psnr", Direction::at_least, "/validation/left_eye/metrics/psnr",
     "left eye's PSNR", std::numeric_limits<double>::infinity(), "/validation/left_eye", true},
    {"left_ssim", "min_left_ssim", "warn_left_ssim", Direction::at_least, "/validation/left_eye/metrics/ssim",
     "left eye's SSIM", 1.0, "/validation/left_eye", true, "/validation/left_eye/metrics/ssim_pixels", -1.0},
    {"speedup", "min_speedup", "warn_speedup", Direction::at_least, "/timing/speedup_median", "median speed-up",
     std::numeric_limits<double>::infinity(), nullptr, true},
    {"right_share", "max_right_share", "warn_right_share", Direction::at_most, "/timing/right_over_left_median",
     "right eye's time over the left eye's", std::numeric_limits<double>::infinity(), nullptr, true},
};

/// Name of the time-regression check.
inline constexpr const char* kRegressionCheck = "time_regression";
/// The check that the results hold every cell of the sweep (records carry cell_index and cell_count).
inline constexpr const char* kCompleteCheck = "sweep_complete";

/// Threshold values by gate.toml key; std::nullopt where a table turns a threshold off (`= false`).
using ThresholdValues = std::map<std::string, std::optional<double>>;

/// A `[[rule]]`: thresholds for the cells whose pipeline, scene and cell id match the glob patterns
/// (fnmatch; "*" when absent). Later rules override earlier ones key by key.
struct GateRule {
  std::string pipeline = "*";
  std::string scene = "*";
  std::string cell = "*";
  ThresholdValues values;
  int line = 0;  ///< where the rule starts in the config file
};

/// `[regression]`: the time regression against the baseline. The current samples regress when their
/// median exceeds the baseline median by more than `tolerance` (a fraction) AND a one-sided
/// Mann–Whitney U test finds them larger at level `alpha`; beyond the tolerance without
/// significance is a warning, as is a cell with fewer than `min_repetitions` samples on either side.
struct RegressionSettings {
  double tolerance = 0.10;
  double alpha = 0.05;
  int min_repetitions = 3;
};

/// A parsed ci/gate.toml.
struct GateConfig {
  std::string source;        ///< file name for messages
  ThresholdValues defaults;  ///< `[defaults]`
  std::vector<GateRule> rules;
  RegressionSettings regression;
  /// Whether the file has a [regression] table: time regressions are then checked for every
  /// (cell, pipeline); without it only where a [[rule]] sets regression_tolerance.
  bool regression_table = false;

  /// Whether some table gives a threshold a value; without one, only the time regressions that
  /// [regression] or a rule's regression_tolerance asks for are checked. A limit counts only when given a value: [[rule]]s without one, or keys
  /// all turned off (= false), would pass anything as surely as an empty file; so would limits no
  /// measure can cross (`vacuous`), which do not count either.
  [[nodiscard]] bool sets_limits() const;
  /// The limits no measure can cross (min_psnr = 0, max_hole_fraction = 1, min_speedup = 0), each
  /// as "KEY = VALUE (TABLE)": they check nothing; the gate notes them.
  std::vector<std::string> vacuous;
};

/// Parses gate.toml text. InputError naming `source`, the line and the key for a syntax error, an
/// unknown table or key, a value of the wrong type, a non-finite or negative limit, a warn level
/// looser than the fail level of the same table, or a malformed glob.
[[nodiscard]] GateConfig parse_gate_config(const std::string& text, const std::string& source);
/// Reads and parses a gate.toml; IoError if it cannot be read.
[[nodiscard]] GateConfig load_gate_config(const std::filesystem::path& file);

/// The thresholds in force for one (pipeline, scene, cell): the defaults with every matching rule
/// applied in file order; the regression tolerance under the key "regression_tolerance". With
/// `rule_used` (one flag per rule), the matching rules' flags are set; with `origins`, each key
/// gets the table that set it: "[defaults]" or "the [[rule]] at line N"; with `set_by`, each key a
/// rule set gets that rule's index (a key [defaults] set has none).
[[nodiscard]] ThresholdValues thresholds_for(const GateConfig& config, const std::string& pipeline,
                                             const std::string& scene, const std::string& cell_id,
                                             std::vector<bool>* rule_used = nullptr,
                                             std::map<std::string, std::string>* origins = nullptr,
                                             std::map<std::string, size_t>* set_by = nullptr);

/// Where the merged thresholds of one (pipeline, scene) put a warning level beyond its failure
/// level — e.g. warn_psnr = 35 from [defaults] under min_psnr = 40 from a rule — so that the
/// warning can never be raised there: one sentence per such check, naming both levels and the
/// tables that set them. parse_gate_config refuses the same within one table; across tables it
/// depends on which rules match, so the gate reports it as a note.
[[nodiscard]] std::vector<std::string> unreachable_warning_levels(const ThresholdValues& values,
                                                                  const std::map<std::string, std::string>& origins,
                                                                  const std::string& pipeline,
                                                                  const std::string& scene);

/// One finished cell of a sweep's results file, as the gate reads it.
struct GateCell {
  std::string cell_id;
  std::string scene;
  nlohmann::json record;  ///< the whole results line (docs/sweeps.md)
};

/// The cells of a sweep's results file (`results.jsonl`, read with read_results).
struct GateResults {
  std::filesystem::path file;
  std::vector<GateCell> cells;
  std::vector<std::string> warnings;  ///< e.g. a torn last line that was skipped
};

/// Checks the cells read from `file` with check_cell_record (results_file.hpp); InputError naming
/// the file and cell otherwise, and for no cell at all (an empty results file is bad input, never
/// a pass).
[[nodiscard]] GateResults gate_results(const std::vector<nlohmann::json>& cells, std::vector<std::string> warnings,
                                       const std::filesystem::path& file);
/// Reads a results file (read_results: a torn last line is skipped with a warning, every line is
/// checked, a cell id that appears twice is an error) and takes its cells with gate_results;
/// InputError when the file does not exist.
[[nodiscard]] GateResults load_gate_results(const std::filesystem::path& file);

/// The one-sided Mann–Whitney U (Wilcoxon rank-sum) test of H1: values of `x` tend to be larger than
/// values of `y`. `u` counts the pairs with x > y (ties count 1/2). The p-value P(U >= u | H0) is
/// exact (the permutation distribution) when there are no ties and n_x + n_y <= 40, and otherwise
/// the normal approximation with tie-corrected variance and continuity correction.
struct RankTest {
  double u = 0.0;
  double p = 1.0;
  bool exact = false;
};
[[nodiscard]] RankTest mann_whitney_greater(std::span<const double> x, std::span<const double> y);

/// The median (mean of the two middle values for an even count, or the finite one of them when
/// the other is infinite); NaN for no values.
[[nodiscard]] double median(std::vector<double> values);

/// Rewrites the baseline entries of the selected (cell, pipeline) pairs with the results' timing
/// samples (`timing.samples_s`), leaving every other entry as it was. InputError when the selection
/// is empty (say what to update: --only and/or --cells), names a pipeline that no cell has, matches
/// no (cell, pipeline) at all, or selects an entry without timing samples.
[[nodiscard]] std::vector<BaselineChange> update_baseline(Baseline& baseline, const GateResults& results,
                                                          const BaselineSelection& selection);

/// One check's outcome for one (cell, pipeline).
struct GateCheck {
  std::string cell_id;
  std::string scene;
  std::string pipeline;
  std::string check;  ///< a kMetricChecks name, kRegressionCheck or kCompleteCheck
  Verdict verdict = Verdict::pass;
  double measured = 0.0;             ///< NaN when there is no value
  std::optional<double> fail_limit;  ///< the limit in force (regression: the tolerance)
  std::optional<double> warn_limit;
  std::string message;    ///< one line: what was measured against what
  std::string reproduce;  ///< the command re-measuring the cell (reproduce_command)
};

/// Everything one gate run decided.
struct GateReport {
  std::vector<GateCheck> checks;  ///< per cell in file order, per pipeline by name, per check in order
  std::map<Verdict, int> counts;
  Verdict worst = Verdict::pass;
  std::vector<std::string> notes;  ///< e.g. reading warnings and a missing baseline
};

/// How the reproduce command is written: the default options of each pipeline by name (options in
/// a record that differ from them become `--option NAME=VALUE`; for a pipeline not listed, every
/// option of the record is written).
struct ReproduceSettings {
  std::map<std::string, std::map<std::string, std::string>> pipeline_defaults;
};
/// The settings for the pipelines this build registers.
[[nodiscard]] ReproduceSettings registered_reproduce_settings();

/// Applies the configuration to every pipeline of every cell. `baseline` may be empty (then every
/// time-regression check the configuration asks for is a skip, "no baseline"). InputError naming the file and line for a
/// record value of the wrong type.
[[nodiscard]] GateReport evaluate_gate(const GateConfig& config, const GateResults& results, const Baseline& baseline,
                                       const ReproduceSettings& reproduce = {});

/// What a reproduce command measures again.
enum class Remeasure {
  quality,  ///< `stereobench validate`: the images, for PSNR, SSIM, errors and holes
  timing,   ///< `stereobench bench`: the times, for the speed-up and the time regression
};

/// The command line that re-measures one pipeline of a cell: scene (a glTF file by the path the
/// sweep loaded it from), pipeline, resolution, interaxial (or max disparity), convergence, light
/// count and the pipeline options that differ from the defaults; for `quality` also the truth and
/// the error threshold, for `timing` the cell's baseline, repetitions, warm-up runs and threads.
/// A frame of a camera path is re-measured by running its sweep cell again.
[[nodiscard]] std::string reproduce_command(const GateCell& cell, const std::string& pipeline,
                                            const ReproduceSettings& settings, Remeasure what = Remeasure::quality);

/// The readable table: one row per check that did not pass, then the counts.
[[nodiscard]] std::string format_gate_table(const GateReport& report);

/// The report as JSON (`stereobench.gate`, schema 1): verdict, counts, notes and every check.
[[nodiscard]] nlohmann::json gate_report_json(const GateReport& report, const std::string& config_file,
                                              const std::string& results_file, const std::string& baseline_file);

}  // namespace sb::validation
