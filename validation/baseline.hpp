// Stored timing baselines for the gate's time-regression check: per (cell id, pipeline) the
// repetition samples of an accepted run, in a JSON file (default ci/baseline.json) of
// {cell_id: {pipeline: {samples_s, median_s, recorded, host}}}; other fields of an entry are kept.
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace sb::validation {

/// The timing baseline `stereobench gate` and `stereobench nightly` read unless told otherwise.
inline constexpr const char* kDefaultBaselineFile = "ci/baseline.json";

/// The accepted timing of one pipeline in one cell.
struct BaselineEntry {
  std::vector<double> samples_s;  ///< per repetition, seconds
  double median_s = 0.0;
  std::string recorded;  ///< when the samples were measured (the cell's `finished` time)
  std::string host;      ///< where they were measured
  /// The worker threads they were measured with (the cell's `threads`); none in an entry stored
  /// before it was recorded.
  std::optional<int> threads;
  /// Any other fields the file gives the entry (a note by hand), written back as they were while
  /// the entry is not rewritten.
  nlohmann::json other = nlohmann::json::object();
};

/// cell id -> pipeline -> entry.
struct Baseline {
  std::map<std::string, std::map<std::string, BaselineEntry>> cells;

  /// The entry, or nullptr.
  [[nodiscard]] const BaselineEntry* find(const std::string& cell_id, const std::string& pipeline) const;
  [[nodiscard]] bool empty() const noexcept { return cells.empty(); }
};

/// A malformed baseline entry: where, and what is wrong (the message, naming the file).
struct DamagedEntry {
  std::string cell_id;
  std::string pipeline;
  std::string message;
};

/// Parses baseline JSON; InputError naming `source` and the cell/pipeline for a malformed entry
/// (samples must be a non-empty array of positive finite seconds).
/// With `damaged` given, a malformed (cell, pipeline) entry is left out and listed there instead
/// (an update that rewrites it can mend the file).
[[nodiscard]] Baseline parse_baseline(const nlohmann::json& doc, const std::string& source,
                                      std::vector<DamagedEntry>* damaged = nullptr);
/// Reads a baseline file; IoError if it cannot be read, InputError if it is not valid JSON.
[[nodiscard]] Baseline load_baseline(const std::filesystem::path& file, std::vector<DamagedEntry>* damaged = nullptr);
/// The baseline as JSON, keys sorted.
[[nodiscard]] nlohmann::json baseline_json(const Baseline& baseline);
/// Writes the baseline atomically (the old file stays whole until the new one is complete).
void save_baseline(const std::filesystem::path& file, const Baseline& baseline);

/// What `--update-baseline` may rewrite: pipelines by name (empty: any) and cells by a glob over
/// the cell id (empty: any). At least one of the two must be given.
struct BaselineSelection {
  std::vector<std::string> pipelines;
  std::string cells;

  [[nodiscard]] bool empty() const noexcept { return pipelines.empty() && cells.empty(); }
};

/// One (cell, pipeline) an update wrote.
struct BaselineChange {
  std::string cell_id;
  std::string pipeline;
  bool replaced = false;  ///< an entry existed before
  double old_median_s = 0.0;
  double new_median_s = 0.0;
  size_t samples = 0;  ///< timing samples stored
};

}  // namespace sb::validation
