// The results file of a sweep (docs/sweeps.md): JSON Lines, one line per finished cell, appended
// atomically, read back with every line checked (a torn last line tolerated), merged across
// shards, exported as CSV.
#pragma once

#include <filesystem>
#include <functional>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/io/unique_fd.hpp"

namespace sb::validation {

/// The `kind` and schema version of a results line.
inline constexpr const char* kSweepCellKind = "stereobench.sweep_cell";
inline constexpr int kSweepSchemaVersion = 1;

/// A copy of `value` with every non-finite float made JSON-safe: +inf "inf", -inf "-inf", NaN null.
[[nodiscard]] nlohmann::json finite_json(const nlohmann::json& value);

/// Appends one cell's line: the whole line (finite_json, no line breaks inside, '\n' at the end)
/// in one write under an exclusive flock on a file opened with O_APPEND, then fsync. A torn,
/// unterminated tail left by a killed writer is cut off first (under the same lock), so lines
/// never run together. Creates the file and its folder. IoError, calling the file `kind`, when it
/// cannot be written.
void append_result(const std::filesystem::path& file, const nlohmann::json& cell, const char* kind = "results file");

/// Creates the results file (and its folder) when it does not exist, empty; an existing one is left
/// as it is (another shard may be appending to it). IoError when it cannot be made.
void create_results_file(const std::filesystem::path& file, const char* kind = "results file");

/// Holds the cells a run may write into a results file while it lives: one byte per cell index,
/// locked for writing (an open-file-description lock) in a hidden lock file beside the results file
/// (".<name>.lock", found through links). A second run over any of the same cells would find them
/// unfinished and record each twice; it is refused with an InputError naming the file and a cell.
/// Shards of one sweep hold disjoint cells and run side by side. The locks go when the process
/// ends, however it ends.
class ResultsWriterLock {
 public:
  ResultsWriterLock(const std::filesystem::path& results, const std::vector<size_t>& cells);

 private:
  io::UniqueFd fd_;  ///< the lock file; closing it releases the locks
};

/// What was read from a results file.
struct ResultsFile {
  std::vector<nlohmann::json> cells;  ///< in file order
  std::vector<size_t> lines;          ///< the 1-based line of each cell
  std::vector<std::string> warnings;  ///< e.g. a torn last line skipped, naming file and line
};

/// The pipelines a results line validates, by name in the order the line holds them (sorted).
[[nodiscard]] std::vector<std::string> recorded_pipelines(const nlohmann::json& cell);

/// Reads a results file; every consumer (sweep resume, collect, gate, report) reads it here. A
/// missing file reads as empty. An unterminated last line (a writer killed mid-write) is skipped
/// with a warning naming the file and line. An InputError names the file and line for any other
/// line that is not JSON or not a sweep-cell record of this schema version (check_cell_record), a
/// cell_id or cell_index that appears twice, and a cell unlike the first line's: of another sweep
/// definition, with other pipelines or another cell count (a results file holds one definition's
/// cells as one build ran them), or measured on another content of a scene. IoError when it cannot
/// be read.
[[nodiscard]] ResultsFile read_results(const std::filesystem::path& file);

/// How much of its sweep a set of cell records holds: the distinct cell_index values and the
/// largest cell_count among them.
struct CellCoverage {
  uint64_t present = 0;
  uint64_t expected = 0;
};
/// The coverage of `cells` (records of one sweep); nothing when one of them does not say (a
/// cell_index or cell_count absent or not a non-negative integer).
[[nodiscard]] std::optional<CellCoverage> cell_coverage(const std::vector<const nlohmann::json*>& cells);

/// Checks one parsed results line against the fields its readers use: kind, schema version, the
/// cell's identity, scene, rig, baseline and, per pipeline, the metrics, hole figures and times
/// (types, and ranges no measurement leaves: SSIM in [-1, 1], fractions in [0, 1], times >= 0) and
/// image paths. `where` ("FILE:LINE") prefixes the InputError.
void check_cell_record(const nlohmann::json& line, const std::string& where);

/// Reads a JSON Lines file written by append_result: a missing file reads as empty; blank lines are
/// skipped; an unterminated last line (a writer killed while writing it) is skipped with the
/// warning "<file>:<n>: unterminated last line <torn_note>"; a line that is not JSON is an
/// InputError "<file>:<n>: not a JSON line (<parser message>); <parse_hint>". Every parsed line
/// goes to `take` with its 1-based number and its "<file>:<n>" position.
void read_json_lines(const std::filesystem::path& file, const std::string& torn_note, const std::string& parse_hint,
                     std::vector<std::string>& warnings,
                     const std::function<void(nlohmann::json&& line, size_t line_no, const std::string& where)>& take);

/// Remembers that `id` (the value of `key`) was read at line `line_no`; InputError
/// "<where>: <key> '<id>' appears twice (also on line <n>); <advice>" if it was read before.
void require_unique_id(std::map<std::string, size_t>& seen, const std::string& id, size_t line_no,
                       const std::string& where, const char* key, const std::string& advice);

/// Image paths of a results line are relative to its file's folder: rewrites those of a cell moved
/// from a file in folder `from` to a file in folder `to` so that they name the same files.
void rebase_image_paths(nlohmann::json& cell, const std::filesystem::path& from, const std::filesystem::path& to);

/// Merges the cells of several results files (shards) ordered by cell_index, for a merged file
/// written at `out`: every cell's image paths are rebased from its file's folder to out's. Identical
/// duplicates collapse; a cell_id recorded with different content is an InputError naming it and
/// both files, as are files written by different definitions (sweep name or definition_sha256),
/// and files whose cells read_results would refuse in one file (other pipelines, another cell
/// count, another content of a scene).
[[nodiscard]] std::vector<nlohmann::json> collect_results(const std::vector<std::filesystem::path>& files,
                                                          const std::filesystem::path& out,
                                                          std::vector<std::string>* warnings = nullptr);

/// The cells as JSON Lines text (one finite_json line each).
[[nodiscard]] std::string results_text(const std::vector<nlohmann::json>& cells);

/// The CSV header and one row per (cell, pipeline), the cells in cell_index order, RFC 4180
/// quoted, lines ending in CRLF.
/// Columns: see kCsvColumns.
[[nodiscard]] std::string results_csv(const std::vector<nlohmann::json>& cells);
inline constexpr const char* kCsvColumns[] = {
    "cell_index", "cell_id",    "sweep",          "scene",      "scene_params", "width",         "height",
    "interaxial_m", "max_disparity_px", "convergence_m", "lights", "frame",  "bvh_update_s", "truth",
    "pipeline",   "baseline",
    "psnr",       "ssim",       "mse",            "error_fraction", "hole_fraction", "recall", "precision",
    "median_s",   "speedup_median", "right_over_left_median"};

}  // namespace sb::validation
