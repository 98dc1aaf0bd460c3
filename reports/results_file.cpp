// Reading and checking a sweep's results file.
#include "reports/results_file.hpp"

#include <algorithm>
#include <limits>
#include <map>
#include <string_view>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"

namespace sb::reports {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// What a field may hold.
enum class Kind { object, object_or_null, string, integer, number, metric, number_or_null, integer_or_null, string_or_null };

const char* describe(Kind k) {
  switch (k) {
    case Kind::object: return "an object";
    case Kind::object_or_null: return "an object or null";
    case Kind::string: return "a string";
    case Kind::integer: return "an integer";
    case Kind::number: return "a number";
    case Kind::metric: return "a number, \"inf\" or null";
    case Kind::number_or_null: return "a number or null";
    case Kind::integer_or_null: return "an integer or null";
    case Kind::string_or_null: return "a string or null";
  }
  return "?";
}

bool matches(const json& v, Kind k) {
  switch (k) {
    case Kind::object: return v.is_object();
    case Kind::object_or_null: return v.is_object() || v.is_null();
    case Kind::string: return v.is_string();
    case Kind::integer: return v.is_number_integer();
    case Kind::number: return v.is_number();
    case Kind::metric: return v.is_number() || v.is_null() || (v.is_string() && (v == "inf" || v == "-inf"));
    case Kind::number_or_null: return v.is_number() || v.is_null();
    case Kind::integer_or_null: return v.is_number_integer() || v.is_null();
    case Kind::string_or_null: return v.is_string() || v.is_null();
  }
  return false;
}

/// The value at a dotted path ("cell.scene"), or nullptr when a step is missing.
const json* find(const json& root, std::string_view dotted) {
  const json* at = &root;
  while (!dotted.empty()) {
    const size_t dot = dotted.find('.');
    const std::string key(dotted.substr(0, dot));
    if (!at->is_object()) return nullptr;
    const auto it = at->find(key);
    if (it == at->end()) return nullptr;
    at = &*it;
    dotted = dot == std::string_view::npos ? std::string_view() : dotted.substr(dot + 1);
  }
  return at;
}

/// Checks a field; `prefix` names the enclosing object for the message ("pipelines.repro-rt.").
void require(const json& root, const std::string& where, const std::string& prefix, std::string_view dotted,
             Kind kind, bool optional = false) {
  const json* v = find(root, dotted);
  if (v == nullptr) {
    if (optional) return;
    throw InputError(fmt::format("{}: field '{}{}' is missing; the line is not a sweep cell record (docs/sweeps.md)",
                                 where, prefix, dotted));
  }
  if (!matches(*v, kind))
    throw InputError(fmt::format("{}: field '{}{}' is {} but must be {}", where, prefix, dotted,
                                 v->dump().substr(0, 80), describe(kind)));
}

/// Checks that a numeric field, where present, lies in [lo, hi] (a metric or time no measurement
/// gives marks a damaged or hand-edited line). Strings such as "inf" are left to `require`.
void require_within(const json& root, const std::string& where, const std::string& prefix, std::string_view dotted,
                    double lo, double hi) {
  const json* v = find(root, dotted);
  if (v == nullptr || !v->is_number()) return;
  const double x = v->get<double>();
  if (!(x >= lo && x <= hi))
    throw InputError(fmt::format("{}: field '{}{}' is {}, outside [{}, {}] where every measurement lies; the line is "
                                 "damaged or edited by hand",
                                 where, prefix, dotted, v->dump(), lo, hi));
}

/// A file name for messages: the path as given.
std::string shown(const fs::path& p) { return p.string(); }

}  // namespace

void check_cell_line(const json& line, const std::string& where) {
  if (!line.is_object())
    throw InputError(fmt::format("{}: a results line must be a JSON object, not {}", where, line.type_name()));
  require(line, where, "", "kind", Kind::string);
  if (line["kind"] != kSweepCellKind)
    throw InputError(fmt::format("{}: kind is {} but a results file holds \"{}\" records", where,
                                 line["kind"].dump(), kSweepCellKind));
  require(line, where, "", "schema_version", Kind::integer);
  const long long version = line["schema_version"].get<long long>();
  if (version > kSweepCellSchemaVersion)
    throw InputError(fmt::format("{}: schema_version {} is newer than this stereobench reads ({}); use the "
                                 "stereobench that wrote the file",
                                 where, version, kSweepCellSchemaVersion));
  if (version != kSweepCellSchemaVersion)
    throw InputError(fmt::format("{}: schema_version {} is not a known version (expected {})", where, version,
                                 kSweepCellSchemaVersion));
  require(line, where, "", "sweep", Kind::string);
  require(line, where, "", "cell_id", Kind::string);
  if (line["cell_id"].get<std::string>().empty()) throw InputError(fmt::format("{}: cell_id is empty", where));
  require(line, where, "", "cell_index", Kind::integer);
  if (line["cell_index"].get<long long>() < 0)
    throw InputError(fmt::format("{}: cell_index {} is negative; cells are numbered from 0", where,
                                 line["cell_index"].dump()));
  require(line, where, "", "cell", Kind::object);
  require(line, where, "", "cell.scene", Kind::string);
  require(line, where, "", "cell.resolution", Kind::string);
  require(line, where, "", "cell.truth", Kind::string);
  require(line, where, "", "cell.lights", Kind::integer_or_null, true);
  require(line, where, "", "rig", Kind::object);
  require(line, where, "", "rig.width", Kind::integer);
  require(line, where, "", "rig.height", Kind::integer);
  if (line["rig"]["width"].get<long long>() <= 0 || line["rig"]["height"].get<long long>() <= 0)
    throw InputError(fmt::format("{}: rig.width and rig.height must be positive, not {}x{}", where,
                                 line["rig"]["width"].dump(), line["rig"]["height"].dump()));
  require(line, where, "", "rig.interaxial_m", Kind::number);
  require(line, where, "", "rig.convergence_m", Kind::number);
  require(line, where, "", "rig.max_disparity_px", Kind::number);
  require(line, where, "", "scene.triangles", Kind::integer_or_null, true);
  require(line, where, "", "baseline", Kind::string);
  require(line, where, "", "pipelines", Kind::object);
  const json& pipelines = line["pipelines"];
  if (pipelines.empty()) throw InputError(fmt::format("{}: 'pipelines' is empty; a cell validates at least one", where));
  if (!pipelines.contains(line["baseline"].get<std::string>()))
    throw InputError(fmt::format("{}: baseline {} is not among the cell's pipelines", where, line["baseline"].dump()));
  for (const auto& [name, p] : pipelines.items()) {
    const std::string prefix = "pipelines." + name + ".";
    if (!p.is_object()) throw InputError(fmt::format("{}: field 'pipelines.{}' must be an object", where, name));
    require(p, where, prefix, "validation", Kind::object);
    for (const char* m : {"psnr", "ssim", "mse", "error_fraction"})
      require(p, where, prefix, std::string("validation.metrics.") + m, Kind::metric);
    require(p, where, prefix, "validation.holes.hole_fraction", Kind::number_or_null, true);
    require(p, where, prefix, "validation.holes.not_reprojected.recall", Kind::number_or_null, true);
    require(p, where, prefix, "validation.holes.not_reprojected.precision", Kind::number_or_null, true);
    require(p, where, prefix, "validation.total_s", Kind::number_or_null, true);
    require(p, where, prefix, "validation.timings_s", Kind::object, true);
    require(p, where, prefix, "validation.scene.triangles", Kind::integer_or_null, true);
    require(p, where, prefix, "timing", Kind::object, true);
    constexpr double kMax = std::numeric_limits<double>::max();
    require_within(p, where, prefix, "validation.metrics.ssim", -1.0, 1.0);
    require_within(p, where, prefix, "validation.metrics.mse", 0.0, kMax);
    for (const char* f : {"validation.metrics.error_fraction", "validation.holes.hole_fraction",
                          "validation.holes.not_reprojected.recall", "validation.holes.not_reprojected.precision"})
      require_within(p, where, prefix, f, 0.0, 1.0);
    require_within(p, where, prefix, "validation.total_s", 0.0, kMax);
    if (p.contains("timing")) {
      for (const char* t : {"median_s", "min_s", "max_s", "speedup_median"}) {
        require(p, where, prefix, std::string("timing.") + t, Kind::number_or_null, true);
        require_within(p, where, prefix, std::string("timing.") + t, 0.0, kMax);
      }
      require(p, where, prefix, "timing.repetitions", Kind::integer, true);
      require(p, where, prefix, "timing.stages_median_s", Kind::object, true);
    }
  }
  require(line, where, "", "images", Kind::object_or_null, true);  // null: a sweep without images
  if (line.contains("images") && line["images"].is_object()) {
    for (const char* key : {"left_png", "truth_png", "disocclusions_png"})
      require(line, where, "", std::string("images.") + key, Kind::string_or_null, true);
    require(line, where, "", "images.pipelines", Kind::object, true);
    if (line["images"].contains("pipelines"))
      for (const auto& [name, imgs] : line["images"]["pipelines"].items()) {
        if (!imgs.is_object()) throw InputError(fmt::format("{}: field 'images.pipelines.{}' must be an object", where, name));
        for (const auto& [key, v] : imgs.items())
          if (!v.is_string() && !v.is_null())
            throw InputError(fmt::format("{}: field 'images.pipelines.{}.{}' must be a path (string) or null", where,
                                         name, key));
      }
  }
}

ResultsFile read_results_file(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec))
    throw InputError(fmt::format("results file {} does not exist; give the results.jsonl a sweep wrote", shown(path)));
  if (fs::is_directory(path, ec))
    throw InputError(fmt::format("{} is a folder; give the results.jsonl file inside it", shown(path)));
  const std::string text = io::read_file(path);

  ResultsFile out;
  out.path = path;
  std::map<std::string, size_t> seen;  // cell_id -> line
  std::map<long long, size_t> seen_index;  // cell_index -> line
  size_t line_no = 0;
  size_t pos = 0;
  while (pos < text.size()) {
    const size_t end = text.find('\n', pos);
    const bool terminated = end != std::string::npos;
    const std::string_view line(text.data() + pos, (terminated ? end : text.size()) - pos);
    pos = terminated ? end + 1 : text.size();
    ++line_no;
    const std::string where = fmt::format("{}:{}", shown(path), line_no);
    if (line.find_first_not_of(" \t\r") == std::string_view::npos) continue;
    json parsed;
    try {
      parsed = json::parse(line);
    } catch (const json::parse_error& e) {
      const bool last = text.find_first_not_of(" \t\r\n", pos) == std::string::npos;
      if (last && !terminated) {
        out.warnings.push_back(where + ": skipped an incomplete last line (a sweep stopped while writing it)");
        break;
      }
      throw InputError(fmt::format("{}: not a JSON line: {}", where, e.what()));
    }
    check_cell_line(parsed, where);
    // One sweep per file: the report's summary, charts and cell numbers are those of one definition.
    if (!out.cells.empty()) {
      const json& first = out.cells.front().json;
      if (parsed["sweep"] != first["sweep"] ||
          parsed.value("definition_sha256", "") != first.value("definition_sha256", ""))
        throw InputError(fmt::format(
            "{}: a cell of sweep '{}' (definition sha256 {}), but line {} is of sweep '{}' (sha256 {}); a report "
            "covers one sweep: give one sweep's results file (the shards of one definition merge with `stereobench "
            "sweep collect`)",
            where, parsed["sweep"].get<std::string>(), parsed.value("definition_sha256", "?").substr(0, 12),
            out.cells.front().line, first["sweep"].get<std::string>(),
            first.value("definition_sha256", "?").substr(0, 12)));
    }
    const std::string id = parsed["cell_id"].get<std::string>();
    const auto [it, fresh] = seen.emplace(id, line_no);
    if (!fresh)
      throw InputError(fmt::format("{}: cell_id '{}' appears again (first on line {}); a results file holds each cell "
                                   "once — merge shards with `stereobench sweep collect`",
                                   where, id, it->second));
    const auto [at, new_index] = seen_index.emplace(parsed["cell_index"].get<long long>(), line_no);
    if (!new_index)
      throw InputError(fmt::format("{}: cell_index {} is also the index of line {}, a different cell; the file is "
                                   "damaged or was joined by hand — rerun the sweep or merge with `stereobench sweep "
                                   "collect`",
                                   where, parsed["cell_index"].dump(), at->second));
    out.cells.push_back({line_no, std::move(parsed)});
  }
  if (out.cells.empty())
    throw InputError(fmt::format("{} holds no finished cell; run the sweep (or let it finish a cell) first", shown(path)));
  std::stable_sort(out.cells.begin(), out.cells.end(), [](const CellLine& a, const CellLine& b) {
    const auto ia = a.json["cell_index"].get<long long>(), ib = b.json["cell_index"].get<long long>();
    if (ia != ib) return ia < ib;
    return a.json["cell_id"].get<std::string>() < b.json["cell_id"].get<std::string>();
  });
  return out;
}

}  // namespace sb::reports
