// Helpers of the report and nightly tests: writing a text file, and the data a report embeds.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "support/scratch_dir.hpp"

namespace sb::test {

/// Writes `text` to `p`, creating its folder.
inline void write_text(const std::filesystem::path& p, const std::string& text) {
  std::filesystem::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
}

/// The data a report embeds (script#report-data of index.html); null when it has none.
inline nlohmann::json embedded_data(const std::filesystem::path& index) {
  const std::string html = read_text(index);
  const std::string open = "<script type=\"application/json\" id=\"report-data\">";
  const size_t a = html.find(open);
  const size_t b = html.find("</script>", a);
  if (a == std::string::npos || b == std::string::npos) return nullptr;
  return nlohmann::json::parse(html.substr(a + open.size(), b - a - open.size()));
}

}  // namespace sb::test
