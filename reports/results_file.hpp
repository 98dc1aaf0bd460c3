// A sweep's results file as the report reads it: validation::read_results (every line checked,
// errors naming the file, line and field), with the cells in cell order.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace sb::reports {

/// One finished cell of a sweep as written to the results file.
struct CellLine {
  size_t line = 0;      ///< 1-based line number in the file
  nlohmann::json json;  ///< the whole record
};

/// A results file read and checked.
struct ResultsFile {
  std::filesystem::path path;          ///< as given
  std::vector<CellLine> cells;         ///< sorted by cell_index (not by finishing order)
  std::vector<std::string> warnings;   ///< "FILE:LINE: ..." for each line skipped (a torn last line)
};

/// Reads `path` with validation::read_results. A missing file, a folder, or a file without a
/// finished cell is an InputError naming it; so is every line read_results refuses.
[[nodiscard]] ResultsFile read_results_file(const std::filesystem::path& path);

}  // namespace sb::reports
