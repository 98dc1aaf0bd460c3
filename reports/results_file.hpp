// Reading a sweep's results file (JSON Lines, one finished cell per line; docs/sweeps.md): every
// line checked against the fields the report reads, errors naming the file, line and field.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace sb::reports {

/// The `kind` of a results line and the schema version this reader understands.
inline constexpr const char* kSweepCellKind = "stereobench.sweep_cell";
inline constexpr int kSweepCellSchemaVersion = 1;

/// One finished cell of a sweep as written to the results file.
struct CellLine {
  size_t line = 0;      ///< 1-based line number in the file
  nlohmann::json json;  ///< the whole record
};

/// A results file read and checked.
struct ResultsFile {
  std::filesystem::path path;          ///< as given
  std::vector<CellLine> cells;         ///< sorted by cell_index, then cell_id (not by finishing order)
  std::vector<std::string> warnings;   ///< "FILE:LINE: ..." for each line skipped (a torn last line)
};

/// Reads and checks `path`. A last line that is not valid JSON (a writer killed mid-line) is
/// skipped with a warning; any other malformed line, a line of another kind or a newer schema,
/// a field of the wrong type, a cell_id seen twice, or a file without a cell is an InputError
/// naming the file and line; an unreadable file is an IoError.
[[nodiscard]] ResultsFile read_results_file(const std::filesystem::path& path);

/// Checks one parsed line (see read_results_file); `where` ("FILE:LINE") prefixes the message.
void check_cell_line(const nlohmann::json& line, const std::string& where);

}  // namespace sb::reports
