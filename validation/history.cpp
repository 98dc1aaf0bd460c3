// The history file of nightly runs: one line per run, built from a results file and a gate report.
#include "validation/history.hpp"

#include <cmath>
#include <ctime>
#include <limits>
#include <map>
#include <set>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/text.hpp"
#include "validation/results_file.hpp"

namespace sb::validation {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// A number as finite_json writes it: finite numbers as they are, "inf"/"-inf" as infinities;
/// nullopt for anything else (null, NaN written as null, another type).
std::optional<double> number_of(const json& v) {
  if (v.is_number()) return v.get<double>();
  if (v == "inf") return std::numeric_limits<double>::infinity();
  if (v == "-inf") return -std::numeric_limits<double>::infinity();
  return std::nullopt;
}

/// The number at `pointer` of a results line (number_of), nullopt when absent.
std::optional<double> number_at(const json& entry, const char* pointer) {
  const json::json_pointer ptr(pointer);
  return entry.contains(ptr) ? number_of(entry.at(ptr)) : std::nullopt;
}

/// The median as JSON: null for no values, "inf" for an infinite one (finite_json's convention).
json median_json(const std::vector<double>& values) {
  if (values.empty()) return nullptr;
  return finite_json(json(median(values)));
}

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Field {
  const char* key;      ///< in the history line
  const char* pointer;  ///< in a pipeline entry of a results line
  double lo, hi;        ///< the range every median of measurements lies in
  bool hi_included;     ///< whether hi itself is a value (SSIM 1, the infinite PSNR of identical images)
};
constexpr Field kFields[] = {
    {"psnr", "/validation/metrics/psnr", 0.0, kInf, true},
    {"ssim", "/validation/metrics/ssim", -1.0, 1.0, true},
    {"hole_fraction", "/validation/holes/hole_fraction", 0.0, 1.0, true},
    {"median_s", "/timing/median_s", 0.0, kInf, false},
    {"speedup", "/timing/speedup_median", 0.0, kInf, false},
};

/// A count: an integer >= 0.
bool is_count(const json& v) { return v.is_number_integer() && v.get<long long>() >= 0; }

constexpr const char* kRunStrings[] = {"run_id", "date", "host", "git_revision", "sweep", "definition",
                                        "definition_sha256", "results"};

}  // namespace

const char* gate_verdict(const GateReport& gate) noexcept {
  switch (exit_code(gate.worst)) {
    case 0: return "pass";
    case 1: return "warn";
    default: return "fail";
  }
}

json history_entry(const NightlyRun& run, const std::vector<json>& cells, const GateReport& gate) {
  std::map<std::string, std::map<std::string, std::vector<double>>> values;  // pipeline -> field -> values
  std::map<std::string, size_t> cell_counts;
  for (const json& cell : cells) {
    if (!cell.contains("pipelines") || !cell["pipelines"].is_object()) continue;
    for (const auto& [name, entry] : cell["pipelines"].items()) {
      ++cell_counts[name];
      auto& fields = values[name];
      for (const Field& f : kFields)
        if (const std::optional<double> v = number_at(entry, f.pointer); v && !std::isnan(*v))
          fields[f.key].push_back(*v);
    }
  }
  json pipelines = json::object();
  for (const auto& [name, count] : cell_counts) {
    json p{{"cells", count}};
    for (const Field& f : kFields) {
      const auto it = values[name].find(f.key);
      p[f.key] = it == values[name].end() ? json(nullptr) : median_json(it->second);
    }
    pipelines[name] = std::move(p);
  }
  json counts = json::object();
  for (const Verdict v : {Verdict::pass, Verdict::skip, Verdict::warn, Verdict::fail}) {
    const auto it = gate.counts.find(v);
    counts[to_string(v)] = it == gate.counts.end() ? 0 : it->second;
  }
  return json{{"kind", kHistoryKind},
              {"schema_version", kHistorySchemaVersion},
              {"run_id", run.run_id},
              {"date", run.date},
              {"host", run.host},
              {"git_revision", run.git_revision},
              {"sweep", run.sweep},
              {"definition", run.definition},
              {"definition_sha256", run.definition_sha256},
              {"results", run.results},
              {"cells", cells.size()},
              {"pipelines", std::move(pipelines)},
              {"gate", json{{"verdict", gate_verdict(gate)}, {"exit_code", exit_code(gate.worst)}, {"counts", counts}}}};
}

void check_history_line(const json& line, const std::string& where) {
  const auto bad = [&where](const std::string& what) {
    return InputError(fmt::format("{}: {}; a history file holds one nightly run per line (docs/nightly.md)", where, what));
  };
  if (!line.is_object() || line.value("kind", "") != kHistoryKind)
    throw bad(fmt::format("not a nightly run record (\"kind\" must be \"{}\")", kHistoryKind));
  if (!line.contains("schema_version") || line["schema_version"] != kHistorySchemaVersion)
    throw bad(fmt::format("schema_version {} is not {}, the version this stereobench reads",
                          line.value("schema_version", json(nullptr)).dump(), kHistorySchemaVersion));
  for (const char* key : kRunStrings)
    if (!line.contains(key) || !line[key].is_string()) throw bad(fmt::format("\"{}\" must be a string", key));
  // The trend charts place runs by date: the form nightly writes, YYYY-MM-DDTHH:MM:SSZ.
  std::tm tm{};
  const std::string date = line["date"].get<std::string>();
  const char* end = ::strptime(date.c_str(), kUtcTimeFormat, &tm);
  // strptime takes any day 1..31 of any month: the date must come back from the time it gives.
  std::tm back{};
  std::tm copy = tm;
  const std::time_t t = ::timegm(&copy);
  const bool real = end != nullptr && ::gmtime_r(&t, &back) != nullptr && back.tm_mday == tm.tm_mday &&
                    back.tm_mon == tm.tm_mon && back.tm_year == tm.tm_year && back.tm_hour == tm.tm_hour &&
                    back.tm_min == tm.tm_min && back.tm_sec == tm.tm_sec;
  if (end == nullptr || *end != '\0' || date.size() != 20 || !real)
    throw bad(fmt::format("\"date\" {} is not a UTC time of the form 2026-01-31T02:00:00Z", line["date"].dump()));
  if (!line.contains("cells") || !is_count(line["cells"])) throw bad("\"cells\" must be a count >= 0");
  if (!line.contains("pipelines") || !line["pipelines"].is_object())
    throw bad("\"pipelines\" must be an object of pipeline summaries");
  for (const auto& [name, p] : line["pipelines"].items()) {
    if (!p.is_object()) throw bad(fmt::format("pipelines.{} must be an object", name));
    if (!p.contains("cells") || !is_count(p["cells"]))
      throw bad(fmt::format("pipelines.{}.cells must be a count >= 0", name));
    for (const Field& f : kFields) {
      const json v = p.value(f.key, json(nullptr));
      if (v.is_null()) continue;
      const std::optional<double> x = number_of(v);
      if (!x)
        throw bad(fmt::format("pipelines.{}.{} must be a number, \"inf\" or null, not {}", name, f.key, v.dump()));
      if (!(*x >= f.lo && (f.hi_included ? *x <= f.hi : *x < f.hi)))
        throw bad(fmt::format("pipelines.{}.{} is {}, outside [{}, {}{} where every measurement lies", name, f.key,
                              v.dump(), f.lo, f.hi, f.hi_included ? "]" : ")"));
    }
  }
  const json gate = line.value("gate", json(nullptr));
  if (!gate.is_object() || !gate.contains("verdict") || !gate["verdict"].is_string() || !gate.contains("counts") ||
      !gate["counts"].is_object())
    throw bad("\"gate\" must be an object with a string \"verdict\" and \"counts\"");
  for (const auto& [verdict, n] : gate["counts"].items())
    if (!is_count(n)) throw bad(fmt::format("gate.counts.{} must be a count >= 0", verdict));
  // The verdict and its exit code, as the gate gives them (0 pass, 1 warn, 2 fail).
  const std::string verdict = gate["verdict"].get<std::string>();
  const int expected = verdict == "pass" ? 0 : verdict == "warn" ? 1 : verdict == "fail" ? 2 : -1;
  if (expected < 0)
    throw bad(fmt::format("gate.verdict {} is not \"pass\", \"warn\" or \"fail\"", gate["verdict"].dump()));
  if (!gate.contains("exit_code") || !gate["exit_code"].is_number_integer() ||
      gate["exit_code"].get<long long>() != expected)
    throw bad(fmt::format("gate.exit_code {} does not go with verdict \"{}\" (exit code {})",
                          gate.value("exit_code", json(nullptr)).dump(), verdict, expected));
}

HistoryFile read_history(const fs::path& file) {
  HistoryFile out;
  std::map<std::string, size_t> seen;  // run_id -> line
  read_json_lines(file, "(a run killed while writing it) skipped", "fix or remove the line", out.warnings,
                  [&](json&& run, size_t line_no, const std::string& where) {
                    check_history_line(run, where);
                    const std::string id = run["run_id"];
                    require_unique_id(seen, id, line_no, where, "run_id", "remove one of the lines");
                    out.runs.push_back(std::move(run));
                  });
  return out;
}

SweepRuns runs_of_sweep(const HistoryFile& history, const std::string& sweep, const fs::path& file) {
  SweepRuns out;
  for (const json& r : history.runs)
    if (r.value("sweep", "") == sweep) out.runs.push_back(r);
  if (out.runs.size() < history.runs.size()) {
    const auto left_out = [&](const std::string& named) {
      return fmt::format("trends leave out {} of other sweeps in {}",
                         counted(static_cast<long long>(history.runs.size() - out.runs.size()), "run"), named);
    };
    out.left_out = left_out(file.string());
    out.left_out_on_page = left_out(file.filename().string());
  }
  return out;
}

void append_history(const fs::path& file, const json& entry) {
  check_history_line(entry, "history line for " + file.string());
  append_result(file, entry, "history file");
}

fs::path run_claim_path(const fs::path& file, const std::string& run_id) {
  return fs::path(file.string() + ".claims") / run_id;
}

io::FileLock lock_history(const fs::path& file) { return io::FileLock::acquire(file.string() + ".lock"); }

std::optional<io::FileLock> claim_run_id(const fs::path& file, const std::string& run_id) {
  const fs::path claim = run_claim_path(file, run_id);
  std::error_code ec;
  fs::create_directories(claim.parent_path(), ec);
  if (ec)
    throw IoError(fmt::format("cannot create {}, the folder of the run claims of history {}: {}; give a history file "
                              "in a writable folder",
                              claim.parent_path().string(), file.string(), ec.message()));
  return io::FileLock::try_acquire(claim);
}

bool run_id_claimed(const fs::path& file, const std::string& run_id) {
  std::error_code ec;
  return fs::exists(run_claim_path(file, run_id), ec);
}

void drop_run_claim(const fs::path& file, io::FileLock& claim) noexcept {
  if (!claim.held()) return;
  try {
    const io::FileLock lock = lock_history(file);  // no run is opening claims meanwhile
    const fs::path folder = claim.path().parent_path();
    claim.remove_when_released();
    claim.release();
    std::error_code ec;
    fs::remove(folder, ec);  // the claims folder, when no other claim is left in it
  } catch (const std::exception&) {  // best effort: the claim file stays, and so does its id
  }
  claim.release();
}

}  // namespace sb::validation
