// Reading a sweep's results file for the report.
#include "reports/results_file.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "validation/results_file.hpp"

namespace sb::reports {

namespace fs = std::filesystem;

ResultsFile read_results_file(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec))
    throw InputError(
        fmt::format("results file {} does not exist; give the results.jsonl a sweep wrote", path.string()));
  if (fs::is_directory(path, ec))
    throw InputError(fmt::format("{} is a folder; give the results.jsonl file inside it", path.string()));
  validation::ResultsFile read = validation::read_results(path);
  if (read.cells.empty())
    throw InputError(
        fmt::format("{} holds no finished cell; run the sweep (or let it finish a cell) first", path.string()));
  ResultsFile out;
  out.path = path;
  out.warnings = std::move(read.warnings);
  for (size_t i = 0; i < read.cells.size(); ++i) out.cells.push_back({read.lines[i], std::move(read.cells[i])});
  // cell_index is unique within a file (read_results), so this order is total.
  std::sort(out.cells.begin(), out.cells.end(), [](const CellLine& a, const CellLine& b) {
    return a.json["cell_index"].get<long long>() < b.json["cell_index"].get<long long>();
  });
  return out;
}

}  // namespace sb::reports
