// The history file of nightly runs (docs/nightly.md): JSON Lines, one line per finished run with
// per-pipeline medians over the run's cells and the gate's verdict counts, appended atomically and
// read back for the report's trend charts.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/io/file_lock.hpp"
#include "validation/gate.hpp"

namespace sb::validation {

/// The `kind` and schema version of a history line.
inline constexpr const char* kHistoryKind = "stereobench.nightly_run";
inline constexpr int kHistorySchemaVersion = 1;

/// What identifies one nightly run.
struct NightlyRun {
  std::string run_id;             ///< the run folder's name, "20261121T200000Z"
  std::string date;               ///< UTC start, ISO 8601 "2026-11-21T20:00:00Z"
  std::string host;               ///< the machine that ran it
  std::string git_revision;       ///< `git rev-parse --short HEAD`, or "unknown"
  std::string sweep;              ///< the definition's name
  std::string definition;         ///< its path as given
  std::string definition_sha256;  ///< of its bytes
  std::string results;            ///< the results file, relative to the history file's folder
};

/// The history line of a run: `run` plus, per pipeline (by name), the medians over the run's cells
/// of PSNR ("inf" when infinite), SSIM, hole fraction, time (median_s) and speed-up over the
/// baseline, with the number of cells; and the gate's verdict ("pass", "warn", "fail") and counts
/// per verdict. A value no cell has is null.
[[nodiscard]] nlohmann::json history_entry(const NightlyRun& run, const std::vector<nlohmann::json>& cells,
                                           const GateReport& gate);

/// The verdict of a whole gate run as a word: "pass" (exit 0, skipped checks included), "warn" (1)
/// or "fail" (2).
[[nodiscard]] const char* gate_verdict(const GateReport& gate) noexcept;

/// Checks one parsed history line; InputError prefixed with `where` ("FILE:LINE") naming the field.
void check_history_line(const nlohmann::json& line, const std::string& where);

/// Reads a history file: a missing file reads as empty; an unterminated last line (a writer killed
/// mid-write) is skipped with a warning; any other line that is not valid JSON or not a history
/// line of this schema, or a run_id seen twice, is an InputError naming the file and line.
struct HistoryFile {
  std::vector<nlohmann::json> runs;   ///< in file order
  std::vector<std::string> warnings;  ///< "FILE:LINE: ..." for a skipped torn last line
};
[[nodiscard]] HistoryFile read_history(const std::filesystem::path& file);

/// The runs of one sweep in a history file (a history may be shared by several sweeps; trends are
/// drawn per sweep), and, when it leaves runs out, how many and of which file ("trends leave out 3
/// runs of other sweeps in FILE"; empty when none).
struct SweepRuns {
  nlohmann::json runs = nlohmann::json::array();
  std::string left_out;
  /// The same for the report's page, naming the file by its name alone: the page names no folder
  /// of this machine.
  std::string left_out_on_page;
};
[[nodiscard]] SweepRuns runs_of_sweep(const HistoryFile& history, const std::string& sweep,
                                      const std::filesystem::path& file);

/// Appends one run's line atomically (append_result: one write under a lock, fsync). The line is
/// checked first (check_history_line).
void append_history(const std::filesystem::path& file, const nlohmann::json& entry);

/// Runs that share a history file take turns at it: the lock file FILE.lock is held while a run
/// chooses its id (reading the history under it) and while it appends its line, so that two runs
/// started in the same second never take one id. Waits while another run holds it (briefly).
[[nodiscard]] io::FileLock lock_history(const std::filesystem::path& file);

/// The claim file of run id `run_id` in history FILE: FILE.claims/ID.
[[nodiscard]] std::filesystem::path run_claim_path(const std::filesystem::path& file, const std::string& run_id);

/// The claim of run `run_id` on its id in history FILE: the file FILE.claims/ID, locked by the run
/// while it lives (a killed run's claim is free again, for the run's resume). Call under
/// lock_history. nullopt when another live run holds it.
[[nodiscard]] std::optional<io::FileLock> claim_run_id(const std::filesystem::path& file, const std::string& run_id);

/// Whether an id has a claim file in history FILE, held or not: a run in progress, or one that was
/// killed and may be resumed; a new run takes another id. Call under lock_history.
[[nodiscard]] bool run_id_claimed(const std::filesystem::path& file, const std::string& run_id);

/// Removes the claim file of a finished run (its line is in the history, which keeps its id taken),
/// and the claims folder when it is left empty, and lets the claim go. Best effort: a claim file left behind only keeps an id already taken.
void drop_run_claim(const std::filesystem::path& file, io::FileLock& claim) noexcept;

}  // namespace sb::validation
