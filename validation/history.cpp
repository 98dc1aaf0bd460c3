// The history file of nightly runs: one line per run, built from a results file and a gate report.
#include "validation/history.hpp"

#include <cmath>
#include <limits>
#include <map>
#include <set>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "validation/results_file.hpp"

namespace sb::validation {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// A number of a results line: finite numbers as they are, "inf"/"-inf" as infinities; nullopt
/// for anything else (absent, null, NaN written as null).
std::optional<double> number_at(const json& entry, const char* pointer) {
  const json::json_pointer ptr(pointer);
  if (!entry.contains(ptr)) return std::nullopt;
  const json& v = entry.at(ptr);
  if (v.is_number()) return v.get<double>();
  if (v == "inf") return std::numeric_limits<double>::infinity();
  if (v == "-inf") return -std::numeric_limits<double>::infinity();
  return std::nullopt;
}

/// The median as JSON: null for no values, "inf" for an infinite one (finite_json's convention).
json median_json(const std::vector<double>& values) {
  if (values.empty()) return nullptr;
  return finite_json(json(median(values)));
}

struct Field {
  const char* key;      ///< in the history line
  const char* pointer;  ///< in a pipeline entry of a results line
};
constexpr Field kFields[] = {
    {"psnr", "/validation/metrics/psnr"},
    {"ssim", "/validation/metrics/ssim"},
    {"hole_fraction", "/validation/holes/hole_fraction"},
    {"median_s", "/timing/median_s"},
    {"speedup", "/timing/speedup_median"},
};

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
  if (!line.contains("pipelines") || !line["pipelines"].is_object())
    throw bad("\"pipelines\" must be an object of pipeline summaries");
  for (const auto& [name, p] : line["pipelines"].items()) {
    if (!p.is_object()) throw bad(fmt::format("pipelines.{} must be an object", name));
    for (const Field& f : kFields) {
      const json v = p.value(f.key, json(nullptr));
      if (!v.is_null() && !v.is_number() && v != "inf" && v != "-inf")
        throw bad(fmt::format("pipelines.{}.{} must be a number, \"inf\" or null, not {}", name, f.key, v.dump()));
    }
  }
  const json gate = line.value("gate", json(nullptr));
  if (!gate.is_object() || !gate.contains("verdict") || !gate["verdict"].is_string() || !gate.contains("counts") ||
      !gate["counts"].is_object())
    throw bad("\"gate\" must be an object with a string \"verdict\" and \"counts\"");
  for (const auto& [verdict, n] : gate["counts"].items())
    if (!n.is_number_integer() || n.get<long long>() < 0) throw bad(fmt::format("gate.counts.{} must be a count >= 0", verdict));
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

void append_history(const fs::path& file, const json& entry) {
  check_history_line(entry, "history line for " + file.string());
  append_result(file, entry);
}

}  // namespace sb::validation
