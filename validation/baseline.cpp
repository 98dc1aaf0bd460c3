// Stored timing baselines: reading, validating and atomically writing ci/baseline.json.
#include "validation/baseline.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/json_text.hpp"

namespace sb::validation {

namespace {

using nlohmann::json;

double median_of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

const BaselineEntry* Baseline::find(const std::string& cell_id, const std::string& pipeline) const {
  const auto c = cells.find(cell_id);
  if (c == cells.end()) return nullptr;
  const auto p = c->second.find(pipeline);
  return p == c->second.end() ? nullptr : &p->second;
}

Baseline parse_baseline(const json& doc, const std::string& source, std::vector<DamagedEntry>* damaged) {
  if (!doc.is_object())
    throw InputError(
        fmt::format("{}: a baseline is a JSON object {{cell_id: {{pipeline: {{samples_s, ...}}}}}}", source));
  Baseline b;
  for (const auto& [cell_id, pipes] : doc.items()) {
    if (!pipes.is_object())
      throw InputError(fmt::format("{}: entry '{}' is not an object of pipelines", source, cell_id));
    for (const auto& [pipeline, e] : pipes.items()) {
      const std::string where = fmt::format("{}: '{}' / {}", source, cell_id, pipeline);
      const auto refuse = [&](const std::string& why) {
        const std::string text =
            fmt::format("{}: {}; rewrite the entry with `stereobench gate --update-baseline --baseline {} --results "
                        "FILE --cells '{}' --only {}`, or remove it",
                        where, why, source, cell_id, pipeline);
        if (damaged == nullptr) throw InputError(text);
        damaged->push_back({cell_id, pipeline, text});
      };
      if (!e.is_object() || !e.contains("samples_s") || !e["samples_s"].is_array() || e["samples_s"].empty()) {
        refuse("samples_s must be a non-empty array of seconds");
        continue;
      }
      BaselineEntry entry;
      for (const json& s : e["samples_s"])
        if (s.is_number() && std::isfinite(s.get<double>()) && s.get<double>() > 0.0) entry.samples_s.push_back(s.get<double>());
      if (entry.samples_s.size() != e["samples_s"].size()) {
        refuse(fmt::format("samples_s holds {}, not only positive times in seconds", e["samples_s"].dump()));
        continue;
      }
      entry.median_s = median_of(entry.samples_s);
      if (e.contains("recorded") && e["recorded"].is_string()) entry.recorded = e["recorded"].get<std::string>();
      if (e.contains("host") && e["host"].is_string()) entry.host = e["host"].get<std::string>();
      if (e.contains("threads")) {
        const json& t = e["threads"];
        if (!t.is_number_integer() || t.get<long long>() < 1 || t.get<long long>() > 1 << 20) {
          refuse(fmt::format("threads is {}, not a count of worker threads", t.dump()));
          continue;
        }
        entry.threads = t.get<int>();
      }
      for (const auto& [key, value] : e.items())
        if (key != "samples_s" && key != "median_s" && key != "recorded" && key != "host" && key != "threads")
          entry.other[key] = value;
      b.cells[cell_id][pipeline] = std::move(entry);
    }
  }
  return b;
}

Baseline load_baseline(const std::filesystem::path& file, std::vector<DamagedEntry>* damaged) {
  if (!std::filesystem::exists(file))
    throw InputError(
        fmt::format("baseline {} does not exist; create it with `stereobench gate --update-baseline "
                    "--results FILE --baseline {} --cells '*'`",
                    file.string(), file.string()));
  const std::string text = io::read_file(file);
  json doc;
  try {
    doc = io::parse_json(text);
  } catch (const io::JsonTextError& e) {
    throw InputError(fmt::format("baseline {} is not valid JSON ({}); mend it, or store it again with gate "
                                 "--update-baseline",
                                 file.string(), e.what()));
  }
  return parse_baseline(doc, file.string(), damaged);
}

json baseline_json(const Baseline& baseline) {
  json doc = json::object();
  for (const auto& [cell_id, pipes] : baseline.cells)
    for (const auto& [pipeline, e] : pipes) {
      json entry = e.other.is_object() ? e.other : json::object();
      entry["samples_s"] = e.samples_s;
      entry["median_s"] = e.median_s;
      entry["recorded"] = e.recorded;
      entry["host"] = e.host;
      if (e.threads) entry["threads"] = *e.threads;
      doc[cell_id][pipeline] = std::move(entry);
    }
  return doc;
}

void save_baseline(const std::filesystem::path& file, const Baseline& baseline) {
  io::write_text_atomically(file, io::json_text(baseline_json(baseline), 2) + "\n");
}

}  // namespace sb::validation
