// Appending, reading, merging and exporting sweep results files.
#include "validation/results_file.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <map>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"

namespace sb::validation {

namespace fs = std::filesystem;
using nlohmann::json;

json finite_json(const json& value) {
  if (value.is_number_float()) {
    const double v = value.get<double>();
    if (std::isnan(v)) return nullptr;
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    return value;
  }
  if (value.is_object()) {
    json out = json::object();
    for (auto it = value.begin(); it != value.end(); ++it) out[it.key()] = finite_json(it.value());
    return out;
  }
  if (value.is_array()) {
    json out = json::array();
    for (const json& item : value) out.push_back(finite_json(item));
    return out;
  }
  return value;
}

namespace {

std::string line_of(const json& cell) {
  return finite_json(cell).dump(-1, ' ', false, json::error_handler_t::replace) + "\n";
}

[[noreturn]] void io_fail(const fs::path& file, const char* what) {
  throw IoError(fmt::format("{}: cannot {} the results file: {}; check the folder's permissions and free space",
                            file.string(), what, std::strerror(errno)));
}

/// An open file descriptor, closed on every path out.
class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  [[nodiscard]] int get() const { return fd_; }

 private:
  int fd_;
};

/// Cuts an unterminated tail (a line torn by a killed writer) so that the next line starts on a
/// line of its own. The caller holds the exclusive lock.
void cut_torn_tail(int fd, const fs::path& file) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) io_fail(file, "inspect");
  off_t end = st.st_size;
  if (end == 0) return;
  char last = 0;
  if (::pread(fd, &last, 1, end - 1) != 1) io_fail(file, "read");
  if (last == '\n') return;
  // Scan back for the last line break.
  char buf[4096];
  off_t keep = 0;
  for (off_t pos = end; pos > 0 && keep == 0;) {
    const off_t start = std::max<off_t>(0, pos - static_cast<off_t>(sizeof buf));
    const ssize_t n = ::pread(fd, buf, static_cast<size_t>(pos - start), start);
    if (n != pos - start) io_fail(file, "read");
    for (ssize_t i = n - 1; i >= 0; --i)
      if (buf[i] == '\n') {
        keep = start + i + 1;
        break;
      }
    pos = start;
  }
  if (::ftruncate(fd, keep) != 0) io_fail(file, "truncate a torn line of");
}

std::string field(const json& v) {
  if (v.is_null()) return "";
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number_float()) return fmt::format("{}", v.get<double>());
  return v.dump();
}

std::string csv_quote(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

/// The value at a path of keys, or null when any is missing.
json at(const json& j, std::initializer_list<const char*> path) {
  const json* cur = &j;
  for (const char* key : path) {
    if (!cur->is_object() || !cur->contains(key)) return nullptr;
    cur = &(*cur)[key];
  }
  return *cur;
}

}  // namespace

void append_result(const fs::path& file, const json& cell) {
  const std::string line = line_of(cell);
  std::error_code ec;
  if (file.has_parent_path()) fs::create_directories(file.parent_path(), ec);
  const Fd fd(::open(file.c_str(), O_RDWR | O_APPEND | O_CREAT | O_CLOEXEC, 0644));
  if (fd.get() < 0) io_fail(file, "open");
  if (::flock(fd.get(), LOCK_EX) != 0) io_fail(file, "lock");
  cut_torn_tail(fd.get(), file);
  // One write of the whole line; a short write is completed, and a failed one (a full disk) is
  // undone, so that no part of the line stays behind.
  const off_t before = ::lseek(fd.get(), 0, SEEK_END);
  const auto fail = [&](const char* what) {
    const int saved = errno;
    if (before >= 0) (void)!::ftruncate(fd.get(), before);
    errno = saved;
    io_fail(file, what);
  };
  size_t done = 0;
  while (done < line.size()) {
    const ssize_t n = ::write(fd.get(), line.data() + done, line.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail("append to");
    done += static_cast<size_t>(n);
  }
  if (::fsync(fd.get()) != 0) fail("flush");
  (void)::flock(fd.get(), LOCK_UN);
}

void read_json_lines(const fs::path& file, const std::string& torn_note, const std::string& parse_hint,
                     std::vector<std::string>& warnings,
                     const std::function<void(json&& line, size_t line_no, const std::string& where)>& take) {
  std::error_code ec;
  if (!fs::exists(file, ec)) return;
  const std::string text = io::read_file(file);
  size_t start = 0, line_no = 0;
  while (start < text.size()) {
    ++line_no;
    const size_t nl = text.find('\n', start);
    if (nl == std::string::npos) {
      warnings.push_back(fmt::format("{}:{}: unterminated last line {}", file.string(), line_no, torn_note));
      break;
    }
    const std::string line = text.substr(start, nl - start);
    start = nl + 1;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::string where = fmt::format("{}:{}", file.string(), line_no);
    json parsed;
    try {
      parsed = json::parse(line);
    } catch (const json::parse_error& e) {
      throw InputError(fmt::format("{}: not a JSON line ({}); {}", where, e.what(), parse_hint));
    }
    take(std::move(parsed), line_no, where);
  }
}

ResultsFile read_results(const fs::path& file) {
  ResultsFile out;
  std::map<std::string, size_t> seen;  // cell_id -> line
  read_json_lines(
      file, "(a sweep killed while writing it) skipped; its cell runs again when the sweep resumes",
      "a results file holds one JSON object per line", out.warnings,
      [&](json&& cell, size_t line_no, const std::string& where) {
        if (!cell.is_object() || cell.value("kind", "") != kSweepCellKind)
          throw InputError(fmt::format("{}: not a sweep cell record (\"kind\" must be \"{}\")", where, kSweepCellKind));
        if (!cell.contains("schema_version") || cell["schema_version"] != kSweepSchemaVersion)
          throw InputError(fmt::format("{}: schema_version {} is not {}, the version this stereobench reads", where,
                                       cell.value("schema_version", json(nullptr)).dump(), kSweepSchemaVersion));
        if (!cell.contains("cell_id") || !cell["cell_id"].is_string() || !cell.contains("cell_index") ||
            !cell["cell_index"].is_number_unsigned())
          throw InputError(fmt::format("{}: a sweep cell record needs a string cell_id and a cell_index >= 0", where));
        const std::string id = cell["cell_id"];
        require_unique_id(seen, id, line_no, where, "cell_id",
                          "a results file holds each cell once — remove one of the lines");
        out.cells.push_back(std::move(cell));
      });
  return out;
}

namespace {

void rebase_strings(json& value, const fs::path& from, const fs::path& to) {
  if (value.is_object() || value.is_array()) {
    for (json& v : value) rebase_strings(v, from, to);
  } else if (value.is_string()) {
    const fs::path p = value.get<std::string>();
    if (!p.empty() && p.is_relative()) value = (from / p).lexically_normal().lexically_relative(to).generic_string();
  }
}

fs::path folder_of(const fs::path& file) { return fs::absolute(file).lexically_normal().parent_path(); }

}  // namespace

void require_unique_id(std::map<std::string, size_t>& seen, const std::string& id, size_t line_no,
                       const std::string& where, const char* key, const std::string& advice) {
  if (auto [it, fresh] = seen.emplace(id, line_no); !fresh)
    throw InputError(fmt::format("{}: {} '{}' appears twice (also on line {}); {}", where, key, id, it->second, advice));
}

void rebase_image_paths(json& cell, const fs::path& from, const fs::path& to) {
  const fs::path a = fs::absolute(from).lexically_normal(), b = fs::absolute(to).lexically_normal();
  if (a != b && cell.contains("images")) rebase_strings(cell["images"], a, b);
}

std::vector<json> collect_results(const std::vector<fs::path>& files, const fs::path& out,
                                  std::vector<std::string>* warnings) {
  struct Seen {
    json cell;
    fs::path file;
  };
  std::map<std::string, Seen> by_id;
  std::map<uint64_t, std::string> id_of_index;
  std::string sweep, sha;
  fs::path first;
  for (const fs::path& file : files) {
    std::error_code ec;
    if (!fs::exists(file, ec))
      throw InputError(fmt::format("{}: results file does not exist; give the shards' results.jsonl files",
                                   file.string()));
    ResultsFile r = read_results(file);
    if (warnings) warnings->insert(warnings->end(), r.warnings.begin(), r.warnings.end());
    for (json& cell : r.cells) {
      rebase_image_paths(cell, folder_of(file), folder_of(out));
      const std::string cell_sweep = cell.value("sweep", ""), cell_sha = cell.value("definition_sha256", "");
      if (first.empty()) {
        sweep = cell_sweep;
        sha = cell_sha;
        first = file;
      } else if (cell_sweep != sweep || cell_sha != sha) {
        throw InputError(fmt::format("{} holds cells of sweep '{}' (definition {}), {} of sweep '{}' (definition {}); "
                                     "collect only shards of one definition",
                                     file.string(), cell_sweep, cell_sha.substr(0, 12), first.string(), sweep,
                                     sha.substr(0, 12)));
      }
      const std::string id = cell["cell_id"];
      const uint64_t index = cell["cell_index"];
      if (auto it = by_id.find(id); it != by_id.end()) {
        if (it->second.cell != cell)
          throw InputError(fmt::format("cell_id '{}' is recorded differently in {} and {}; keep one of the two "
                                       "results (or rerun the cell) before collecting",
                                       id, it->second.file.string(), file.string()));
        continue;
      }
      if (auto [it, fresh] = id_of_index.emplace(index, id); !fresh)
        throw InputError(fmt::format("cell_index {} is both '{}' and '{}' ({}); the files come from different "
                                     "definitions",
                                     index, it->second, id, file.string()));
      by_id.emplace(id, Seen{std::move(cell), file});
    }
  }
  std::vector<json> cells;
  for (const auto& [index, id] : id_of_index) cells.push_back(by_id.at(id).cell);
  return cells;
}

std::string results_text(const std::vector<json>& cells) {
  std::string text;
  for (const json& cell : cells) text += line_of(cell);
  return text;
}

std::string results_csv(const std::vector<json>& cells) {
  std::string out;
  for (const char* column : kCsvColumns) out += (out.empty() ? "" : ",") + std::string(column);
  out += "\r\n";
  for (const json& cell : cells) {
    std::string params;
    const json scene_params = at(cell, {"cell", "scene_params"});
    if (scene_params.is_object())
      for (const auto& [key, value] : scene_params.items())
        params += (params.empty() ? "" : ";") + key + "=" + field(value);
    const json pipelines = at(cell, {"pipelines"});
    if (!pipelines.is_object()) continue;
    for (const auto& [name, p] : pipelines.items()) {
      const json row[] = {at(cell, {"cell_index"}),
                          at(cell, {"cell_id"}),
                          at(cell, {"sweep"}),
                          at(cell, {"cell", "scene"}),
                          params,
                          at(cell, {"rig", "width"}),
                          at(cell, {"rig", "height"}),
                          at(cell, {"rig", "interaxial_m"}),
                          at(cell, {"rig", "max_disparity_px"}),
                          at(cell, {"rig", "convergence_m"}),
                          at(p, {"validation", "scene", "lights"}),
                          at(cell, {"animation", "frame"}),
                          at(cell, {"animation", "bvh_update_s"}),
                          at(cell, {"cell", "truth"}),
                          name,
                          at(cell, {"baseline"}),
                          at(p, {"validation", "metrics", "psnr"}),
                          at(p, {"validation", "metrics", "ssim"}),
                          at(p, {"validation", "metrics", "mse"}),
                          at(p, {"validation", "metrics", "error_fraction"}),
                          at(p, {"validation", "holes", "hole_fraction"}),
                          at(p, {"validation", "holes", "not_reprojected", "recall"}),
                          at(p, {"validation", "holes", "not_reprojected", "precision"}),
                          at(p, {"timing", "median_s"}),
                          at(p, {"timing", "speedup_median"})};
      static_assert(std::size(row) == std::size(kCsvColumns));
      std::string line;
      for (size_t i = 0; i < std::size(row); ++i) line += (i ? "," : "") + csv_quote(field(row[i]));
      out += line + "\r\n";
    }
  }
  return out;
}

}  // namespace sb::validation
