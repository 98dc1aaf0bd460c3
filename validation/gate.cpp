// The CI quality gate: gate.toml parsing, results reading, threshold and time-regression checks.
#include "validation/gate.hpp"

#include <fnmatch.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>
#include <string_view>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <toml++/toml.h>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/json_text.hpp"
#include "renderer/pipeline.hpp"
#include "renderer/text.hpp"
#include "scenes/catalog.hpp"
#include "validation/results_file.hpp"
#include "validation/slurm.hpp"
#include "validation/sweep_run.hpp"

namespace sb::validation {

namespace {

using nlohmann::json;
namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr const char* kToleranceKey = "regression_tolerance";

// ---------------------------------------------------------------------------------------------
// gate.toml

/// Every threshold key of [defaults] and [[rule]], in kMetricChecks order.
std::vector<std::string> threshold_keys() {
  std::vector<std::string> keys;
  for (const MetricCheck& c : kMetricChecks) {
    keys.emplace_back(c.fail_key);
    keys.emplace_back(c.warn_key);
  }
  return keys;
}

/// The warning level of `c`, both levels set, lies beyond its failure level: a value would fail
/// before it could warn.
bool warn_level_looser(const MetricCheck& c, const ThresholdValues& values) {
  const auto f = values.find(c.fail_key);
  const auto w = values.find(c.warn_key);
  if (f == values.end() || w == values.end() || !f->second || !w->second) return false;
  return c.direction == Direction::at_least ? *w->second < *f->second : *w->second > *f->second;
}

[[noreturn]] void config_error(const std::string& source, const toml::source_region& where, const std::string& what) {
  throw InputError(fmt::format("{}:{}: {}", source, where.begin.line, what));
}

/// A config value as the file gives it, for messages: a string quoted, a number or boolean as
/// written, an array or table by its kind.
std::string toml_text(const toml::node& node) {
  if (node.is_array()) return "an array";
  if (node.is_table()) return "a table";
  if (const auto* s = node.as_string()) return fmt::format("\"{}\"", printable(s->get()));
  std::ostringstream out;
  node.visit([&](auto&& value) { out << value; });
  return out.str();
}

/// A TOML number as a double: an integer too large to be one exactly is rounded to the nearest
/// (toml++'s own conversion gives none for it); nullopt for any other kind of value.
std::optional<double> number_of(const toml::node& node) {
  if (node.is_integer()) return static_cast<double>(node.as_integer()->get());
  if (node.is_floating_point()) return node.as_floating_point()->get();
  return std::nullopt;
}

/// A threshold value: a non-negative finite number, or `false` to turn the check off.
std::optional<double> threshold_value(const toml::node& node, const std::string& key, const std::string& source) {
  if (node.is_boolean()) {
    if (*node.value<bool>())
      config_error(source, node.source(),
                   fmt::format("{} = true is not a limit; give a number, or false to turn the check off", key));
    return std::nullopt;
  }
  if (!node.is_number())
    config_error(source, node.source(),
                 fmt::format("{} = {} must be a number (or false to turn the check off)", key, toml_text(node)));
  const double v = *number_of(node);
  if (!std::isfinite(v) || v < 0.0)
    config_error(source, node.source(),
                 fmt::format("{} = {} is not a non-negative finite number", key, toml_text(node)));
  return v;
}

/// Reads the threshold keys of one table; `extra` are further keys the caller handles itself.
ThresholdValues read_thresholds(const toml::table& table, const std::string& table_name, const std::string& source,
                                const std::set<std::string>& extra) {
  const std::vector<std::string> keys = threshold_keys();
  ThresholdValues values;
  for (auto&& [key, node] : table) {
    const std::string k(key.str());
    if (extra.count(k)) continue;
    if (std::find(keys.begin(), keys.end(), k) == keys.end()) {
      std::vector<std::string> known = keys;
      known.insert(known.end(), extra.begin(), extra.end());
      config_error(source, key.source(),
                   fmt::format("unknown key '{}' in {}; known keys: {}", k, table_name, fmt::join(known, ", ")));
    }
    values[k] = threshold_value(node, k, source);
    for (const MetricCheck& c : kMetricChecks)
      if ((k == c.fail_key || k == c.warn_key) && values[k] && *values[k] > c.largest)
        config_error(source, node.source(),
                     fmt::format("{} = {} is above {:g}, the largest {}; {}", k, *values[k], c.largest, c.label,
                                 c.direction == Direction::at_least ? "no cell could pass"
                                                                    : "the limit could never be reached"));
  }
  // A warning level must be reached before the failure level.
  for (const MetricCheck& c : kMetricChecks)
    if (warn_level_looser(c, values))
      config_error(source, table[c.warn_key].node()->source(),
                   fmt::format("{} = {} is looser than {} = {} in {}; the warning level must lie between the "
                               "failure level and the expected value",
                               c.warn_key, *values[c.warn_key], c.fail_key, *values[c.fail_key], table_name));
  return values;
}

RegressionSettings read_regression(const toml::table& table, const std::string& source) {
  RegressionSettings r;
  for (auto&& [key, node] : table) {
    const std::string k(key.str());
    if (k == "tolerance" || k == "alpha") {
      const std::optional<double> v = number_of(node);
      if (!v || !std::isfinite(*v) || *v < 0.0)
        config_error(source, node.source(),
                     fmt::format("[regression] {} = {} must be a non-negative number", k, toml_text(node)));
      if (k == "alpha" && !(*v > 0.0 && *v < 1.0))
        config_error(source, node.source(), fmt::format("[regression] alpha = {} must lie in (0, 1)", *v));
      (k == "tolerance" ? r.tolerance : r.alpha) = *v;
    } else if (k == "min_repetitions") {
      const std::optional<int64_t> v = node.is_integer() ? node.value<int64_t>() : std::nullopt;
      if (!v || *v < 1 || *v > 1000000)
        config_error(source, node.source(),
                     fmt::format("[regression] min_repetitions{} must be an integer from 1 to 1000000 (the timing "
                                 "samples per side the rank test needs; 3 is the least that can fail)",
                                 v ? fmt::format(" = {}", *v) : std::string()));
      r.min_repetitions = static_cast<int>(*v);
    } else {
      config_error(source, key.source(),
                   fmt::format("unknown key '{}' in [regression]; known keys: tolerance, alpha, min_repetitions", k));
    }
  }
  return r;
}

/// Why `pattern` would not match what it seems to say, or nothing. fnmatch takes a '[' whose set
/// is never closed as a literal '[' (and a trailing '\\' as itself), so a misspelt '[repro' rule
/// silently applies nowhere.
std::optional<std::string> glob_fault(const std::string& pattern) {
  for (size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] == '\\') {
      if (i + 1 == pattern.size()) return "it ends in a lone '\\'; write '\\\\' for a literal backslash";
      ++i;
    } else if (pattern[i] == '[') {
      size_t j = i + 1;
      if (j < pattern.size() && (pattern[j] == '!' || pattern[j] == '^')) ++j;
      if (j < pattern.size() && pattern[j] == ']') ++j;  // a ']' first in a set is a member
      const size_t close = pattern.find(']', j);
      if (close == std::string::npos)
        return fmt::format("the '[' at character {} opens a set that is never closed; close it, or write '\\[' for "
                           "a literal '['",
                           i + 1);
      i = close;
    }
  }
  return std::nullopt;
}

std::string glob_value(const toml::node& node, const std::string& key, const std::string& source) {
  const std::optional<std::string> v = node.value<std::string>();
  if (!v || v->empty())
    config_error(source, node.source(),
                 fmt::format("[[rule]] {} must be a non-empty string (a name or a glob such as 'repro-*')", key));
  if (const std::optional<std::string> fault = glob_fault(*v))
    config_error(source, node.source(), fmt::format("[[rule]] {} = '{}' is not a valid glob: {}", key, *v, *fault));
  return *v;
}

bool glob_matches(const std::string& pattern, const std::string& text) {
  return ::fnmatch(pattern.c_str(), text.c_str(), 0) == 0;
}

// ---------------------------------------------------------------------------------------------
// Record values

/// Formats a number for a command line: the shortest text that reads back to the same double.
std::string number_arg(double v) {
  return fmt::format("{}", v);
}


/// A number of a record: std::nullopt when absent, NaN for null, +-inf for "inf"/"-inf";
/// InputError for any other type.
std::optional<double> record_number(const json& entry, const char* pointer, const std::string& where) {
  const json::json_pointer ptr(pointer);
  if (!entry.contains(ptr)) return std::nullopt;
  const json& v = entry.at(ptr);
  if (v.is_null()) return kNaN;
  if (v.is_number()) return v.get<double>();
  if (v.is_string()) {
    const std::string s = v.get<std::string>();
    if (s == "inf") return std::numeric_limits<double>::infinity();
    if (s == "-inf") return -std::numeric_limits<double>::infinity();
  }
  throw InputError(fmt::format("{}: {} is {}, not a number; the results file is damaged or from another tool", where,
                               pointer, v.dump()));
}

/// The timing samples of a pipeline entry, or empty when absent. Every cell the gate holds has
/// passed check_cell_record, which checks them as times in seconds.
std::vector<double> record_samples(const json& entry) {
  const json::json_pointer ptr("/timing/samples_s");
  return entry.contains(ptr) ? entry.at(ptr).get<std::vector<double>>() : std::vector<double>{};
}

/// Whether a check reads a time (the regression, or a metric of the record's "timing" block),
/// which `stereobench bench` re-measures, rather than an image measure of `validate`.
bool timed_check(std::string_view check) {
  const auto reads_timing = [&](const MetricCheck& m) {
    return check == m.name && std::string_view(m.pointer).starts_with("/timing/");
  };
  return check == kRegressionCheck || std::any_of(std::begin(kMetricChecks), std::end(kMetricChecks), reads_timing);
}

/// `v` with `places` decimals, or in exponent form where that would print more than a dozen
/// digits (a limit of 1e308 printed 309).
std::string decimals(double v, int places, bool sign = false) {
  const std::string plus = sign && !std::signbit(v) ? "+" : "";
  if (std::abs(v) >= 1e6) return plus + fmt::format("{:.4g}", v);
  return plus + fmt::format("{:.{}f}", v, places);
}

/// How a check's values are shown: scaled, with decimals (or significant digits, where `places` is
/// 0), a sign, and a unit.
struct Shown {
  double scale = 1.0;
  int places = 0;
  bool sign = false;
  const char* unit = "";
};
Shown shown_of(const std::string& check) {
  if (check == "psnr" || check == "left_psnr") return {1.0, 2, false, " dB"};
  if (check == "speedup") return {1.0, 2, false, "x"};
  if (check == "right_share") return {100.0, 1, false, " %"};
  if (check == kRegressionCheck) return {100.0, 1, true, " %"};
  return {};
}

std::string value_text(const std::string& check, double v) {
  if (std::isnan(v)) return "-";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  const Shown s = shown_of(check);
  if (s.places == 0) return fmt::format("{:.4g}", v);
  return decimals(s.scale * v, s.places, s.sign) + s.unit;
}

/// A measured value and a limit as the messages show them: at the check's own precision, or, where
/// they differ but would read alike ("PSNR 51.16 dB is below the minimum 51.16 dB"), with as many
/// significant digits as tell them apart.
std::pair<std::string, std::string> values_apart(const std::string& check, double v, double limit) {
  std::string a = value_text(check, v), b = value_text(check, limit);
  if (a != b || v == limit || !std::isfinite(v) || !std::isfinite(limit)) return {a, b};
  const Shown s = shown_of(check);
  const auto digits_of = [&s](double x, int digits) {
    return fmt::format("{}{:.{}g}{}", s.sign && !std::signbit(x) ? "+" : "", s.scale * x, digits, s.unit);
  };
  for (int digits = 6; digits <= 17; ++digits) {
    a = digits_of(v, digits);
    b = digits_of(limit, digits);
    if (a != b) break;
  }
  return {a, b};
}

json json_number(double v) {
  if (std::isnan(v)) return nullptr;
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return v;
}

json json_limit(const std::optional<double>& v) {
  return v ? json(*v) : json(nullptr);
}

}  // namespace

const char* to_string(Verdict v) noexcept {
  switch (v) {
    case Verdict::pass:
      return "pass";
    case Verdict::skip:
      return "skip";
    case Verdict::warn:
      return "warn";
    case Verdict::fail:
      return "fail";
  }
  return "?";
}

int exit_code(Verdict worst) noexcept {
  if (worst == Verdict::fail) return static_cast<int>(ExitCode::gate_failure);
  if (worst == Verdict::warn) return static_cast<int>(ExitCode::gate_warning);
  return 0;
}

namespace {

/// Whether `value` of threshold key `key` is a limit no measure can cross.
bool vacuous_limit(const std::string& key, double value) {
  for (const MetricCheck& m : kMetricChecks) {
    if (key != m.fail_key && key != m.warn_key) continue;
    return m.direction == Direction::at_least ? value <= m.smallest : value >= m.largest;
  }
  return false;
}

/// The vacuous limits of one table, as "KEY = VALUE (TABLE)".
void note_vacuous(const ThresholdValues& values, const std::string& table, std::vector<std::string>& out) {
  for (const auto& [key, value] : values)
    if (key != kToleranceKey && value && vacuous_limit(key, *value))
      out.push_back(fmt::format("{} = {} ({})", key, *value, table));
}

}  // namespace

bool GateConfig::sets_limits() const {
  const auto sets_limit = [](const ThresholdValues& values) {
    return std::any_of(values.begin(), values.end(), [](const auto& kv) {
      return kv.first != kToleranceKey && kv.second.has_value() && !vacuous_limit(kv.first, *kv.second);
    });
  };
  return sets_limit(defaults) ||
         std::any_of(rules.begin(), rules.end(), [&](const GateRule& r) { return sets_limit(r.values); });
}

GateConfig parse_gate_config(const std::string& text, const std::string& source) {
  toml::table root;
  try {
    root = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}:{}:{}: not valid TOML: {}; mend the syntax there (the format: docs/gate.md)",
                                 source, e.source().begin.line, e.source().begin.column, e.description()));
  }
  GateConfig config;
  config.source = source;
  for (auto&& [key, node] : root) {
    const std::string k(key.str());
    if (k == "defaults") {
      if (!node.is_table()) config_error(source, node.source(), "[defaults] must be a table");
      config.defaults = read_thresholds(*node.as_table(), "[defaults]", source, {});
    } else if (k == "regression") {
      if (!node.is_table()) config_error(source, node.source(), "[regression] must be a table");
      config.regression = read_regression(*node.as_table(), source);
      config.regression_table = true;
    } else if (k == "rule") {
      if (node.is_array() && node.as_array()->empty())
        config_error(source, node.source(), "rule = [] holds no rule; write each rule as a [[rule]] table");
      if (!node.is_array_of_tables())
        config_error(source, node.source(), "rule must be an array of tables: write each as [[rule]]");
      for (const toml::node& item : *node.as_array()) {
        const toml::table& t = *item.as_table();
        GateRule rule;
        rule.line = static_cast<int>(t.source().begin.line);
        if (const toml::node* n = t.get("pipeline")) rule.pipeline = glob_value(*n, "pipeline", source);
        if (const toml::node* n = t.get("scene")) rule.scene = glob_value(*n, "scene", source);
        if (const toml::node* n = t.get("cell")) rule.cell = glob_value(*n, "cell", source);
        rule.values = read_thresholds(t, fmt::format("[[rule]] (pipeline '{}', scene '{}')", rule.pipeline, rule.scene),
                                      source, {"pipeline", "scene", "cell", kToleranceKey});
        if (const toml::node* n = t.get(kToleranceKey))
          rule.values[kToleranceKey] = threshold_value(*n, kToleranceKey, source);
        config.rules.push_back(std::move(rule));
      }
    } else {
      config_error(source, key.source(),
                   fmt::format("unknown key '{}'; a gate config has [defaults], [regression] and [[rule]] tables", k));
    }
  }
  const bool rule_regression = std::any_of(config.rules.begin(), config.rules.end(), [](const GateRule& r) {
    const auto t = r.values.find(kToleranceKey);
    return t != r.values.end() && t->second.has_value();
  });
  note_vacuous(config.defaults, "[defaults]", config.vacuous);
  for (const GateRule& rule : config.rules)
    note_vacuous(rule.values, fmt::format("the [[rule]] at line {}", rule.line), config.vacuous);
  if (!config.sets_limits() && !config.regression_table && !rule_regression)
    throw InputError(fmt::format("{}: the gate config sets no threshold{}, no [regression] and no rule's {}: it would "
                                 "pass anything; give a limit a value in [defaults] or a [[rule]] (see docs/gate.md)",
                                 source,
                                 config.vacuous.empty()
                                     ? std::string()
                                     : fmt::format(" that a measure can cross (only {})", fmt::join(config.vacuous, ", ")),
                                 kToleranceKey));
  return config;
}

GateConfig load_gate_config(const std::filesystem::path& file) {
  if (!std::filesystem::exists(file))
    throw InputError(fmt::format("gate config {} does not exist; give the thresholds file (gate --config FILE, nightly "
                                 "--gate-config FILE; the shipped one is ci/gate.toml)",
                                 file.string()));
  return parse_gate_config(io::read_file(file), file.string());
}

ThresholdValues thresholds_for(const GateConfig& config, const std::string& pipeline, const std::string& scene,
                               const std::string& cell_id, std::vector<bool>* rule_used,
                               std::map<std::string, std::string>* origins, std::map<std::string, size_t>* set_by_out) {
  ThresholdValues values = config.defaults;
  // The [regression] tolerance applies everywhere only when the table is there.
  if (config.regression_table) values[kToleranceKey] = config.regression.tolerance;
  // Per key, the rule that set it last (none: [defaults]).
  std::map<std::string, size_t> set_by;
  for (size_t i = 0; i < config.rules.size(); ++i) {
    const GateRule& rule = config.rules[i];
    if (!glob_matches(rule.pipeline, pipeline) || !glob_matches(rule.scene, scene) || !glob_matches(rule.cell, cell_id))
      continue;
    for (const auto& [key, value] : rule.values) {
      values[key] = value;
      set_by[key] = i;
    }
    if (rule_used) (*rule_used)[i] = true;
  }
  if (origins != nullptr)
    for (const auto& entry : values) {
      const auto it = set_by.find(entry.first);
      (*origins)[entry.first] = it == set_by.end() ? std::string("[defaults]")
                                                   : fmt::format("the [[rule]] at line {}", config.rules[it->second].line);
    }
  if (set_by_out != nullptr) *set_by_out = std::move(set_by);
  return values;
}

std::vector<std::string> unreachable_warning_levels(const ThresholdValues& values,
                                                    const std::map<std::string, std::string>& origins,
                                                    const std::string& pipeline, const std::string& scene) {
  std::vector<std::string> out;
  const auto origin = [&origins](const char* key) {
    const auto it = origins.find(key);
    return it == origins.end() ? std::string("[defaults]") : it->second;
  };
  for (const MetricCheck& c : kMetricChecks)
    if (warn_level_looser(c, values))
      out.push_back(fmt::format(
          "for pipeline {} on scene {}, {} = {} ({}) is looser than {} = {} ({}): that warning can never be "
          "raised there, a value beyond {} fails at once; set {} in the same table as {}",
          pipeline, scene, c.warn_key, *values.at(c.warn_key), origin(c.warn_key), c.fail_key, *values.at(c.fail_key),
          origin(c.fail_key), c.fail_key, c.warn_key, c.fail_key));
  return out;
}

// ---------------------------------------------------------------------------------------------
// Results file

namespace {

/// The gate's view of cells that passed check_cell_record.
GateResults take_cells(const std::vector<json>& cells, std::vector<std::string> warnings,
                       const std::filesystem::path& file) {
  GateResults results;
  results.file = file;
  results.warnings = std::move(warnings);
  for (const json& record : cells)
    results.cells.push_back({record["cell_id"].get<std::string>(), record["cell"]["scene"].get<std::string>(), record});
  // In cell order, not the order parallel jobs finished them: the same cells give the same
  // JUnit and JSON bytes (cell_index is checked to be unique per file).
  std::stable_sort(results.cells.begin(), results.cells.end(), [](const GateCell& a, const GateCell& b) {
    return a.record["cell_index"].get<int64_t>() < b.record["cell_index"].get<int64_t>();
  });
  if (results.cells.empty())
    throw InputError(fmt::format(
        "{} holds no finished cell; run the sweep first (an empty results file is not a pass)", file.string()));
  return results;
}

}  // namespace

GateResults gate_results(const std::vector<json>& cells, std::vector<std::string> warnings,
                         const std::filesystem::path& file) {
  for (size_t i = 0; i < cells.size(); ++i)
    check_cell_record(cells[i], fmt::format("{}: cell {}", file.string(), i + 1));
  return take_cells(cells, std::move(warnings), file);
}

GateResults load_gate_results(const std::filesystem::path& file) {
  if (!std::filesystem::exists(file))
    throw InputError(
        fmt::format("results file {} does not exist; give --results with the results.jsonl a "
                    "`stereobench sweep` wrote",
                    file.string()));
  ResultsFile read = read_results(file);  // every line checked there
  return take_cells(read.cells, std::move(read.warnings), file);
}

// ---------------------------------------------------------------------------------------------
// Statistics

double median(std::vector<double> values) {
  if (values.empty()) return kNaN;
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  if (n % 2) return values[n / 2];
  // One infinite middle value (a PSNR of identical images beside a finite one): the finite one,
  // not their mean, which would call half the cells identical to the truth.
  const double a = values[n / 2 - 1], b = values[n / 2];
  if (std::isinf(a) != std::isinf(b)) return std::isinf(a) ? b : a;
  return 0.5 * (a + b);
}

RankTest mann_whitney_greater(std::span<const double> x, std::span<const double> y) {
  RankTest r;
  const size_t m = x.size(), n = y.size();
  if (m == 0 || n == 0) return r;
  // U: pairs with x above y, ties counted one half.
  bool ties = false;
  for (double a : x)
    for (double b : y) {
      if (a > b)
        r.u += 1.0;
      else if (a == b) {
        r.u += 0.5;
        ties = true;
      }
    }
  std::vector<double> all(x.begin(), x.end());
  all.insert(all.end(), y.begin(), y.end());
  std::sort(all.begin(), all.end());
  double tie_sum = 0.0;  // sum of t^3 - t over groups of equal values
  for (size_t i = 0; i < all.size();) {
    size_t j = i;
    while (j < all.size() && all[j] == all[i]) ++j;
    const double t = static_cast<double>(j - i);
    if (t > 1) ties = true;
    tie_sum += t * t * t - t;
    i = j;
  }
  const double mn = static_cast<double>(m * n);
  if (!ties && m + n <= 40) {
    // Exact: count[i][j][k] = orderings of i x's and j y's with U = k. The largest value is either
    // an x (above all j y's: U grows by j) or a y (U unchanged).
    const size_t kmax = m * n;
    std::vector<std::vector<std::vector<double>>> count(
        m + 1, std::vector<std::vector<double>>(n + 1, std::vector<double>(kmax + 1, 0.0)));
    for (size_t i = 0; i <= m; ++i)
      for (size_t j = 0; j <= n; ++j) {
        if (i == 0 || j == 0) {
          count[i][j][0] = 1.0;
          continue;
        }
        for (size_t k = 0; k <= i * j; ++k)
          count[i][j][k] = (k >= j ? count[i - 1][j][k - j] : 0.0) + count[i][j - 1][k];
      }
    double total = 0.0, tail = 0.0;
    const size_t u = static_cast<size_t>(r.u);
    for (size_t k = 0; k <= kmax; ++k) {
      total += count[m][n][k];
      if (k >= u) tail += count[m][n][k];
    }
    r.p = tail / total;
    r.exact = true;
    return r;
  }
  const double N = static_cast<double>(m + n);
  const double variance = mn / 12.0 * ((N + 1.0) - tie_sum / (N * (N - 1.0)));
  if (!(variance > 0.0)) {
    r.p = 1.0;  // every value equal: no evidence either way
    return r;
  }
  const double z = (r.u - mn / 2.0 - 0.5) / std::sqrt(variance);
  r.p = 0.5 * std::erfc(z / std::sqrt(2.0));
  return r;
}

// ---------------------------------------------------------------------------------------------
// Baseline update

std::vector<BaselineChange> update_baseline(Baseline& baseline, const GateResults& results,
                                            const BaselineSelection& selection) {
  const std::string name = results.file.string();
  if (selection.empty())
    throw InputError(
        "--update-baseline rewrites only what you name: give --only PIPELINE[,PIPELINE...] and/or --cells PATTERN "
        "(a glob over cell ids, e.g. 'spheres|*'); --cells '*' names every cell");
  if (const std::optional<std::string> fault = glob_fault(selection.cells))
    throw InputError(fmt::format("--cells '{}' is not a valid glob: {}", selection.cells, *fault));
  std::set<std::string> present;
  for (const GateCell& cell : results.cells)
    for (const auto& [pipeline, entry] : cell.record["pipelines"].items()) present.insert(pipeline);
  for (const std::string& p : selection.pipelines)
    if (!present.count(p))
      throw InputError(
          fmt::format("--only {}: no cell of {} has that pipeline (it has: {})", p, name, fmt::join(present, ", ")));
  std::vector<BaselineChange> changes;
  for (const GateCell& cell : results.cells) {
    if (!selection.cells.empty() && !glob_matches(selection.cells, cell.cell_id)) continue;
    for (const auto& [pipeline, entry] : cell.record["pipelines"].items()) {
      if (!selection.pipelines.empty() &&
          std::find(selection.pipelines.begin(), selection.pipelines.end(), pipeline) == selection.pipelines.end())
        continue;
      const std::string where = fmt::format("{}: cell '{}'", name, cell.cell_id);
      BaselineEntry e;
      e.samples_s = record_samples(entry);
      if (e.samples_s.empty())
        throw InputError(fmt::format("{} pipeline {} has no timing.samples_s to store as its baseline", where, pipeline));
      // The baseline's reader takes positive times only: a zero stored here would refuse every
      // later gate run.
      if (std::any_of(e.samples_s.begin(), e.samples_s.end(), [](double t) { return !(t > 0.0); }))
        throw InputError(fmt::format("{} pipeline {}: timing.samples_s holds a time of 0 s, which a baseline cannot "
                                     "hold (a ratio against it is undefined); run the cell again before storing it",
                                     where, pipeline));
      e.median_s = median(e.samples_s);
      e.recorded = cell.record.value("finished", json("")).is_string() ? cell.record.value("finished", "") : "";
      e.host = cell.record.value("host", json("")).is_string() ? cell.record.value("host", "") : "";
      if (const json threads = cell.record.value("threads", json()); threads.is_number_integer() &&
                                                                       threads.get<long long>() >= 1)
        e.threads = threads.get<int>();
      BaselineChange change{cell.cell_id, pipeline, false, 0.0, e.median_s, e.samples_s.size()};
      if (const BaselineEntry* old = baseline.find(cell.cell_id, pipeline)) {
        change.replaced = true;
        change.old_median_s = old->median_s;
      }
      baseline.cells[cell.cell_id][pipeline] = std::move(e);
      changes.push_back(change);
    }
  }
  if (changes.empty())
    throw InputError(
        fmt::format("the selection matches nothing in {}: --cells '{}' matches none of its {} cell "
                    "ids (e.g. '{}')",
                    name, selection.cells, results.cells.size(), results.cells.front().cell_id));
  return changes;
}

// ---------------------------------------------------------------------------------------------
// Evaluation

namespace {

/// Quoted arguments joined into one command line.
std::string join_args(const std::vector<std::string>& args) {
  std::string out;
  for (const std::string& a : args) out += (out.empty() ? "" : " ") + a;
  return out;
}

}  // namespace

ReproduceSettings registered_reproduce_settings() {
  ReproduceSettings settings;
  for (const Pipeline* p : pipelines())
    settings.pipeline_defaults[p->info().name] = PipelineOptions(p->info(), {}).values();
  return settings;
}

std::string reproduce_command(const GateCell& cell, const std::string& pipeline, const ReproduceSettings& settings,
                              Remeasure what) {
  const json& rec = cell.record;
  const json& c = rec.value("cell", json::object());
  const json& rig = rec.value("rig", json::object());
  const json& entry = rec["pipelines"].value(pipeline, json::object());
  const json& validation = entry.value("validation", json::object());
  auto num = [](const json& obj, const char* key) -> std::optional<double> {
    if (!obj.is_object() || !obj.contains(key) || !obj[key].is_number()) return std::nullopt;
    return obj[key].get<double>();
  };

  const bool timing = what == Remeasure::timing;
  std::vector<std::string> args{"stereobench", timing ? "bench" : "validate"};
  auto add = [&](const std::string& flag, const std::string& value) {
    args.push_back(flag);
    args.push_back(shell_quote(value));
  };
  // A frame of a path: only the sweep animates the scene to that frame, so run that one cell
  // again (cell_index % cell_count == cell_index selects it alone).
  if (c.contains("frame") && c["frame"].is_number() && rec.value("definition", json()).is_string() &&
      num(rec, "cell_index") && num(rec, "cell_count")) {
    args = {"stereobench", "sweep", "run"};
    args.push_back(shell_quote(rec["definition"].get<std::string>()));
    add("--out", "out/reproduce");
    add("--shard", fmt::format("{}/{}", static_cast<uint64_t>(*num(rec, "cell_index")),
                               static_cast<uint64_t>(*num(rec, "cell_count"))));
    return join_args(args);
  }
  // A parameterised scene is generated into a file of its own, and a glTF file is written in the
  // definition relative to the definition's folder: name the file the sweep loaded.
  std::string scene = cell.scene;
  const json& params = c.value("scene_params", json::object());
  if (((params.is_object() && !params.empty()) || scenes::is_scene_file_spec(cell.scene)) &&
      validation.contains("scene") && validation["scene"].is_object() &&
      validation["scene"].value("path", json()).is_string())
    scene = validation["scene"]["path"].get<std::string>();
  add("--scene", scene);
  add("--pipelines", pipeline);
  const std::string baseline = rec.value("baseline", json()).is_string() ? rec["baseline"].get<std::string>() : pipeline;
  if (timing) {
    add("--baseline", baseline);
    const json& t = entry.value("timing", json::object());
    if (const auto n = num(t, "repetitions"); n && *n >= 1)
      add("--repetitions", fmt::format("{}", static_cast<int>(*n)));
    // A sweep cell renders each pipeline once for its validation before timing, so its runs were
    // warm even with warmup = 0; bench times from cold unless it warms up: one round at least.
    if (const auto w = num(t, "warmup"); w && *w >= 0)
      add("--warmup", fmt::format("{}", std::max(1, static_cast<int>(*w))));
    if (const auto threads = num(rec, "threads"); threads && *threads >= 1)
      add("--threads", fmt::format("{}", static_cast<int>(*threads)));
  } else {
    std::string truth = "full";
    if (c.value("truth", json()).is_string()) truth = c["truth"].get<std::string>();
    add("--truth", truth);
  }
  if (c.value("resolution", json()).is_string())
    add("--resolution", c["resolution"].get<std::string>());
  else if (num(rig, "width") && num(rig, "height"))
    add("--resolution",
        fmt::format("{}x{}", static_cast<int>(*num(rig, "width")), static_cast<int>(*num(rig, "height"))));
  if (const auto d = num(c, "max_disparity_px"))
    add("--max-disparity", number_arg(*d));
  else if (const auto e = num(c, "interaxial_m") ? num(c, "interaxial_m") : num(rig, "interaxial_m"))
    add("--interaxial", number_arg(*e));
  if (const auto conv = num(c, "convergence_m") ? num(c, "convergence_m") : num(rig, "convergence_m"))
    add("--convergence", number_arg(*conv));
  // A cell may ask for more lights than its scene has, and keeps the scene's own; validate refuses
  // that count, so the command gives the count the cell used.
  if (const auto lights = num(c, "lights")) {
    const auto used = num(validation.value("scene", json::object()), "lights");
    const int count = static_cast<int>(used ? std::min(*used, *lights) : *lights);
    if (count > 0) add("--lights", fmt::format("{}", count));  // an unlit scene takes no --lights
  }
  if (const auto t = num(validation.value("metrics", json::object()), "error_threshold"); !timing && t && *t != 2.0)
    add("--error-threshold", fmt::format("{}", static_cast<int>(*t)));
  // The options that differ from the pipeline's defaults. validate applies --option NAME=VALUE to
  // the pipelines it measures; bench times the baseline beside the pipeline and takes
  // PIPELINE.NAME=VALUE, so it is given the baseline's options as well.
  const auto add_options = [&](const std::string& name, bool qualified) {
    const json& entry_options =
        rec["pipelines"].value(name, json::object()).value("validation", json::object()).value("options", json::object());
    if (!entry_options.is_object()) return;
    const std::string base = entry_pipeline_name(name);
    // A variant's name already fixes its own options.
    const auto defaults = settings.pipeline_defaults.find(base);
    std::map<std::string, std::string> fixed;
    try {
      fixed = entry_fixed_options(name);
    } catch (const InputError&) {  // not an entry this build reads: every option is written
    }
    for (const auto& [key, value] : entry_options.items()) {
      const std::string v = value.is_string() ? value.get<std::string>() : value.dump();
      if (const auto f = fixed.find(key); f != fixed.end() && f->second == v) continue;
      if (defaults != settings.pipeline_defaults.end()) {
        const auto d = defaults->second.find(key);
        if (d != defaults->second.end() && d->second == v) continue;
      }
      add("--option", (qualified ? base + "." : "") + key + "=" + v);
    }
  };
  add_options(pipeline, timing);
  if (timing && baseline != pipeline && entry_pipeline_name(baseline) != entry_pipeline_name(pipeline))
    add_options(baseline, true);
  return join_args(args);
}

namespace {

/// The shard I/N whose run wrote every record, when one did.
std::optional<std::pair<uint64_t, uint64_t>> shard_of(const std::vector<const json*>& records) {
  std::optional<std::pair<uint64_t, uint64_t>> shard;
  for (const json* r : records) {
    const json shard_record = r->value("shard", json::object());
    if (!shard_record.is_object()) return std::nullopt;
    const json index = shard_record.value("index", json()), count = shard_record.value("count", json());
    if (!index.is_number_integer() || !count.is_number_integer()) return std::nullopt;  // older lines
    const std::pair<uint64_t, uint64_t> mine{index.get<uint64_t>(), count.get<uint64_t>()};
    if (shard && *shard != mine) return std::nullopt;  // collected from several shards
    shard = mine;
  }
  return shard;
}

/// Whether the results hold every cell of their sweep: a results file left by a sweep that stopped
/// early (killed, a full disk) must not pass, nor one whose records do not say how many cells the
/// sweep has (a line without cell_count: edited, or of an older version). Nothing for no cells.
/// Its command to finish the sweep: sweep run with the recorded --out; for a shard's own results
/// file, that shard into that file; for a Slurm task's file, or the merged file of a folder
/// submitted to Slurm, the Slurm executor.
std::optional<GateCheck> completeness_check(const GateResults& results) {
  if (results.cells.empty()) return std::nullopt;
  std::vector<const json*> records;
  std::string definition, out;
  for (const GateCell& cell : results.cells) {
    records.push_back(&cell.record);
    if (definition.empty() && cell.record.value("definition", json()).is_string())
      definition = cell.record["definition"].get<std::string>();
    if (out.empty() && cell.record.value("out", json()).is_string()) out = cell.record["out"].get<std::string>();
  }
  // Lines from before "out" was recorded: the results file's folder, sweep run's default.
  if (out.empty()) out = results.file.parent_path().empty() ? "." : results.file.parent_path().string();
  const std::optional<CellCoverage> coverage = cell_coverage(records);
  // A Slurm task's results file lies in the Slurm folder of the sweep's --out; the sweep's own
  // results file there is the Slurm executor's merge once the folder was submitted.
  std::error_code ec;
  const SlurmLayout slurm = slurm_layout(out);
  const bool slurm_task = fs::weakly_canonical(fs::absolute(results.file).parent_path(), ec) ==
                          fs::weakly_canonical(fs::absolute(slurm.dir), ec);
  const bool sweeps_own = fs::weakly_canonical(fs::absolute(results.file), ec) ==
                          fs::weakly_canonical(fs::absolute(fs::path(out) / "results.jsonl"), ec);
  const bool slurm_merge = sweeps_own && fs::exists(slurm.submission, ec);
  // A shard's own file (--shard I/N --results FILE): shards sharing the sweep's file are not one.
  const std::optional<std::pair<uint64_t, uint64_t>> recorded_shard = shard_of(records);
  std::optional<std::pair<uint64_t, uint64_t>> shard = recorded_shard;
  if (shard && (shard->second < 2 || sweeps_own)) shard.reset();
  GateCheck check;
  check.check = kCompleteCheck;
  check.cell_id = "(all cells)";
  check.pipeline = "(all)";
  const std::string run = fmt::format("stereobench sweep run {} --out {}",
                                      definition.empty() ? "DEFINITION" : shell_quote(definition), shell_quote(out));
  if (slurm_task || slurm_merge) {
    check.reproduce = run + " --executor slurm --wait";
    // A submission continues only with its shard count (the default, one shard per cell, differs
    // from any other --shards it was made with): the submission's record, else the lines'.
    std::optional<uint64_t> shards;
    if (fs::is_regular_file(slurm.submission, ec)) try {
        const json submission = io::parse_json(io::read_file(slurm.submission));
        if (submission.is_object() && submission.value("shards", json()).is_number_unsigned())
          shards = submission["shards"].get<uint64_t>();
      } catch (const std::exception&) {
        // unreadable: the lines' count below
      }
    if (!shards && recorded_shard) shards = recorded_shard->second;
    if (shards) check.reproduce += fmt::format(" --shards {}", *shards);
  } else {
    check.reproduce = run;
    if (shard) check.reproduce += fmt::format(" --shard {}/{}", shard->first, shard->second);
    // sweep run resumes <out>/results.jsonl unless told otherwise.
    if (!sweeps_own) check.reproduce += " --results " + shell_quote(results.file.string());
  }
  if (!coverage) {
    check.measured = kNaN;
    check.verdict = Verdict::fail;
    check.message = fmt::format("{}: its lines do not say how many cells the sweep has (no cell_count: written by an "
                                "older version, or edited), so the gate cannot tell whether the sweep finished; run the "
                                "sweep afresh (delete the results file, or give another --out), whose lines record it",
                                results.file.string());
    return check;
  }
  const uint64_t expected = coverage->expected;
  check.measured = static_cast<double>(coverage->present);
  check.fail_limit = static_cast<double>(expected);
  if (coverage->present >= expected) {
    check.message = fmt::format("all {} cells of the sweep have results", expected);
    return check;
  }
  check.verdict = Verdict::fail;
  if (slurm_task) {
    check.message = fmt::format(
        "{} holds {} of the sweep's {} cells: it is the results file of {}, not the sweep's; gate {}, which the "
        "executor merges from every task once all have ended (the command below waits for them, submitting the "
        "cells left again)",
        results.file.string(), coverage->present, expected,
        recorded_shard ? fmt::format("Slurm task {} of {}", recorded_shard->first, recorded_shard->second)
                       : std::string("a Slurm task"),
        (fs::path(out) / "results.jsonl").string());
  } else if (shard) {
    const size_t in_shard = shard_cells(expected, {shard->first, shard->second}).size();
    check.message = fmt::format(
        "{} holds {} of the sweep's {} cells: it is the results file of shard {}/{}{}; merge every shard's results "
        "file with `stereobench sweep collect` and gate the merged file",
        results.file.string(), coverage->present, expected, shard->first, shard->second,
        coverage->present >= in_shard
            ? fmt::format(", which has all of its {} cells", in_shard)
            : fmt::format(", which holds {} of its {} cells: the command below finishes the shard",
                          coverage->present, in_shard));
  } else {
    check.message = fmt::format("{} holds {} of the sweep's {} cells: the sweep did not finish; run it again with the "
                                "same --out to resume it{}",
                                results.file.string(), coverage->present, expected,
                                slurm_merge ? " (it was submitted to Slurm: with the Slurm executor)" : "");
  }
  return check;
}

/// The scenes, pipelines and cell ids of a results file, for naming why a rule matches nothing.
struct ResultNames {
  std::set<std::string> scenes, pipelines, cells;
};

ResultNames result_names(const GateResults& results) {
  ResultNames n;
  for (const GateCell& cell : results.cells) {
    n.scenes.insert(cell.scene);
    n.cells.insert(cell.cell_id);
    for (const auto& item : cell.record["pipelines"].items()) n.pipelines.insert(item.key());
  }
  return n;
}

/// Why a rule applied to no (cell, pipeline) of the results: the first of its globs that matches
/// nothing there, or the combination.
std::string why_unused(const GateRule& rule, const ResultNames& names) {
  const auto any = [](const std::set<std::string>& items, const std::string& glob) {
    return std::any_of(items.begin(), items.end(), [&](const std::string& s) { return glob_matches(glob, s); });
  };
  if (!any(names.scenes, rule.scene))
    return fmt::format("scene '{}' matches none of its scenes ({})", rule.scene, fmt::join(names.scenes, ", "));
  if (!any(names.pipelines, rule.pipeline))
    return fmt::format("pipeline '{}' matches none of its pipelines ({})", rule.pipeline,
                       fmt::join(names.pipelines, ", "));
  if (!any(names.cells, rule.cell)) return fmt::format("cell '{}' matches none of its cell ids", rule.cell);
  return fmt::format("pipeline '{}', scene '{}' and cell '{}' each match, but never in the same cell", rule.pipeline,
                     rule.scene, rule.cell);
}

/// A rule that applies nowhere is a rule for another sweep or a misspelt glob whose limits would
/// pass silently: one note names them, grouped by the reason, with their lines.
std::optional<std::string> unused_rules_note(const GateConfig& config, const GateResults& results,
                                             const std::vector<bool>& rule_used) {
  const size_t count = static_cast<size_t>(std::count(rule_used.begin(), rule_used.end(), false));
  if (count == 0) return std::nullopt;
  const ResultNames names = result_names(results);
  std::vector<std::pair<std::string, std::vector<int>>> groups;  // reason, lines; in file order
  for (size_t i = 0; i < config.rules.size(); ++i) {
    if (rule_used[i]) continue;
    const std::string reason = why_unused(config.rules[i], names);
    auto it = std::find_if(groups.begin(), groups.end(), [&](const auto& g) { return g.first == reason; });
    if (it == groups.end()) it = groups.insert(groups.end(), {reason, {}});
    it->second.push_back(config.rules[i].line);
  }
  std::vector<std::string> parts;
  for (const auto& [reason, lines] : groups)
    parts.push_back(fmt::format("{} ({} {})", reason, lines.size() == 1 ? "line" : "lines", fmt::join(lines, ", ")));
  return fmt::format(
      "{}: {} [[rule]] table{} appl{} to no cell of {} (rules for another sweep, or misspelt globs), "
      "so {} limits are not checked: {}",
      config.source, count, count == 1 ? "" : "s", count == 1 ? "ies" : "y", results.file.string(),
      count == 1 ? "its" : "their", fmt::join(parts, "; "));
}

/// Limits of rules that match some cell but never make a check: overridden by a later rule
/// wherever they match, or on a measure no record they match carries (a left eye's for a pipeline
/// that renders its left eye, a speed-up of the baseline pipeline). `won` holds the keys each rule
/// gave the limit of some (cell, pipeline), `applied` those that then made a check. One note
/// names them with their rule's line; a key set to false (a check turned off) is none.
std::optional<std::string> unapplied_limits_note(const GateConfig& config, const std::vector<bool>& rule_used,
                                                 const std::vector<std::set<std::string>>& won,
                                                 const std::vector<std::set<std::string>>& applied) {
  std::vector<std::string> overridden, unmeasured;
  for (size_t i = 0; i < config.rules.size(); ++i) {
    if (!rule_used[i]) continue;  // unused_rules_note names it
    for (const auto& [key, value] : config.rules[i].values) {
      if (!value || applied[i].count(key)) continue;
      const std::string item = fmt::format("{} (line {})", key, config.rules[i].line);
      (won[i].count(key) ? unmeasured : overridden).push_back(item);
    }
  }
  if (overridden.empty() && unmeasured.empty()) return std::nullopt;
  std::vector<std::string> parts;
  if (!overridden.empty())
    parts.push_back(fmt::format("a later [[rule]] sets {} wherever {} rule matches: {}",
                                overridden.size() == 1 ? "it" : "them", overridden.size() == 1 ? "its" : "their",
                                fmt::join(overridden, ", ")));
  if (!unmeasured.empty())
    parts.push_back(fmt::format("no record {} rule matches has that measure (a left eye's for a pipeline that "
                                "renders its own, a speed-up of the baseline pipeline): {}",
                                unmeasured.size() == 1 ? "its" : "their", fmt::join(unmeasured, ", ")));
  return fmt::format("{}: [[rule]] limits that check nothing, so are not in force: {}", config.source,
                     fmt::join(parts, "; "));
}

/// The skipped checks, counted by (check, reason): every cell without a baseline entry is one line.
std::map<std::pair<std::string, std::string>, int> skip_reasons(const std::vector<GateCheck>& checks) {
  std::map<std::pair<std::string, std::string>, int> reasons;
  for (const GateCheck& c : checks)
    if (c.verdict == Verdict::skip) ++reasons[{c.check, c.message}];
  return reasons;
}

/// Why a gate measured nothing: its checks, all skipped, by reason.
std::string nothing_checked_message(const GateConfig& config, const GateResults& results,
                                    const std::vector<GateCheck>& checks) {
  std::vector<std::string> parts;
  for (const auto& [why, count] : skip_reasons(checks))
    parts.push_back(fmt::format("{} x {}: {}", count, why.first, why.second));
  const std::string why = parts.empty() ? "no limit of it applies to them (its rules turn them off, or name other "
                                           "pipelines, scenes or cells)"
                                         : fmt::format("every one was skipped ({})", fmt::join(parts, "; "));
  return fmt::format("{}: none of its checks applies to {} ({} cell{}): {}; a pass would say "
                     "nothing. Give limits the records carry in [defaults] or a [[rule]], or a baseline for "
                     "[regression] (gate --update-baseline stores one)",
                     config.source, results.file.string(), results.cells.size(), results.cells.size() == 1 ? "" : "s",
                     why);
}

}  // namespace

GateReport evaluate_gate(const GateConfig& config, const GateResults& results, const Baseline& baseline,
                         const ReproduceSettings& reproduce) {
  GateReport report;
  report.notes = results.warnings;
  const RegressionSettings& reg = config.regression;
  std::vector<bool> rule_used(config.rules.size(), false);
  // Per rule, the keys whose limit it gave somewhere, and those that then made a check.
  std::vector<std::set<std::string>> won(config.rules.size()), applied(config.rules.size());
  size_t regression_checks = 0, regression_with_entry = 0;
  std::set<std::string> level_notes;
  for (const GateCell& cell : results.cells) {
    const std::string where = fmt::format("{}: cell '{}'", results.file.string(), cell.cell_id);
    for (const auto& [pipeline, entry] : cell.record["pipelines"].items()) {
      std::map<std::string, std::string> origins;
      std::map<std::string, size_t> set_by;
      const ThresholdValues limits =
          thresholds_for(config, pipeline, cell.scene, cell.cell_id, &rule_used, &origins, &set_by);
      for (const auto& [key, rule] : set_by) won[rule].insert(key);
      const auto mark_applied = [&](const char* key) {
        if (key == nullptr) return;
        if (const auto it = set_by.find(key); it != set_by.end()) applied[it->second].insert(key);
      };
      for (const std::string& note : unreachable_warning_levels(limits, origins, pipeline, cell.scene))
        if (level_notes.insert(note).second) report.notes.push_back(fmt::format("{}: {}", config.source, note));
      const std::string quality_command = reproduce_command(cell, pipeline, reproduce, Remeasure::quality);
      const std::string timing_command = reproduce_command(cell, pipeline, reproduce, Remeasure::timing);
      auto limit = [&](const char* key) -> std::optional<double> {
        const auto it = limits.find(key);
        return it == limits.end() ? std::nullopt : it->second;
      };
      auto add = [&](GateCheck check) {
        check.cell_id = cell.cell_id;
        check.scene = cell.scene;
        check.pipeline = pipeline;
        check.reproduce = timed_check(check.check) ? timing_command : quality_command;
        report.checks.push_back(std::move(check));
      };
      // The baseline's speed-up over itself is 1 by definition: a minimum speed-up is for the others.
      const bool is_baseline = cell.record.value("baseline", json()) == json(pipeline);

      // Thresholds.
      for (const MetricCheck& mc : kMetricChecks) {
        if (is_baseline && mc.name == std::string_view("speedup")) continue;
        GateCheck check;
        check.check = mc.name;
        check.fail_limit = limit(mc.fail_key);
        check.warn_limit = limit(mc.warn_key);
        if (!check.fail_limit && !check.warn_limit) continue;
        if (mc.applies_unless_null != nullptr) {
          const json::json_pointer scope(mc.applies_unless_null);
          if (entry.contains(scope) && entry.at(scope).is_null()) continue;
        }
        mark_applied(mc.fail_key);
        mark_applied(mc.warn_key);
        const std::optional<double> value = record_number(entry, mc.pointer, where + ": pipelines." + pipeline);
        check.measured = value ? *value : kNaN;
        if (!value || std::isnan(*value)) {
          // Undefined for this image (its count of measured pixels is 0): nothing to check.
          bool undefined = false;
          if (value && mc.defined_by != nullptr) {
            const json::json_pointer count(mc.defined_by);
            undefined = entry.contains(count) && entry.at(count).is_number() && entry.at(count).get<double>() == 0.0;
          }
          check.verdict = mc.may_be_missing || undefined ? Verdict::skip : Verdict::fail;
          check.message = fmt::format(
              "no {} in the record ({} is {}){}", mc.label, mc.pointer, value ? "null" : "absent",
              undefined ? fmt::format(": undefined for this image ({} is 0)", mc.defined_by)
              : mc.may_be_missing ? ""
                                  : "; the record is damaged or of another version: run the cell again");
          add(std::move(check));
          continue;
        }
        const double v = *value;
        const bool at_least = mc.direction == Direction::at_least;
        auto beyond = [&](double lim) { return at_least ? v < lim : v > lim; };
        const char* side = at_least ? "below the minimum" : "above the maximum";
        if (check.fail_limit && beyond(*check.fail_limit)) {
          check.verdict = Verdict::fail;
          const auto [shown, bound] = values_apart(mc.name, v, *check.fail_limit);
          check.message = fmt::format("{} {} is {} {}", mc.label, shown, side, bound);
        } else if (check.warn_limit && beyond(*check.warn_limit)) {
          check.verdict = Verdict::warn;
          const auto [shown, bound] = values_apart(mc.name, v, *check.warn_limit);
          check.message = fmt::format("{} {} is {} warning level {}", mc.label, shown,
                                      at_least ? "below the" : "above the", bound);
        } else {
          check.verdict = Verdict::pass;
          const auto [shown, bound] =
              values_apart(mc.name, v, check.fail_limit ? *check.fail_limit : *check.warn_limit);
          check.message = fmt::format("{} {} within {} {}", mc.label, shown, at_least ? ">=" : "<=", bound);
        }
        add(std::move(check));
      }

      // Time regression against the baseline.
      const std::optional<double> tolerance = limit(kToleranceKey);
      if (!tolerance) continue;
      mark_applied(kToleranceKey);
      ++regression_checks;
      GateCheck check;
      check.check = kRegressionCheck;
      check.fail_limit = tolerance;
      check.measured = kNaN;
      const std::vector<double> samples = record_samples(entry);
      const BaselineEntry* base = baseline.find(cell.cell_id, pipeline);
      if (base) ++regression_with_entry;
      if (samples.empty() && base) {
        // A sweep writes them for every pipeline: the record is damaged, and a time the gate
        // cannot read must not pass.
        check.verdict = Verdict::fail;
        check.message = "no timing samples in the record (timing.samples_s), though the baseline has an entry for it: "
                        "the record is damaged or of another version; run the cell again";
      } else if (samples.empty()) {
        check.verdict = Verdict::skip;
        check.message = "no timing samples in the record";
      } else if (!base) {
        check.verdict = Verdict::skip;
        check.message = "no baseline";
      } else {
        const double now = median(samples), before = median(base->samples_s);
        check.measured = now / before - 1.0;
        const std::string change = fmt::format("median {:.4g} s vs baseline {:.4g} s ({:+.3g} %, tolerance {:.3g} %)",
                                               now, before, 100.0 * check.measured, 100.0 * *tolerance);
        const int n_now = static_cast<int>(samples.size()), n_base = static_cast<int>(base->samples_s.size());
        const json threads_now = cell.record.value("threads", json());
        if (base->threads && threads_now.is_number_integer() && threads_now.get<long long>() != *base->threads) {
          // Times of another thread count are no regression and no gain: a warning to store a
          // baseline of this machine, not a verdict on the time.
          check.verdict = Verdict::warn;
          check.message = fmt::format(
              "not comparable: the baseline was measured with {} threads, this cell with {}; {}; store a baseline "
              "measured as the sweep runs now (gate --update-baseline)",
              *base->threads, threads_now.get<long long>(), change);
        } else if (n_now < reg.min_repetitions || n_base < reg.min_repetitions) {
          check.verdict = Verdict::warn;
          check.message = fmt::format(
              "not enough repetitions for the rank test: {} now and {} in the baseline, "
              "{} needed; {}",
              n_now, n_base, reg.min_repetitions, change);
        } else {
          const RankTest test = mann_whitney_greater(samples, base->samples_s);
          const std::string rank =
              fmt::format("Mann-Whitney U = {:g}, one-sided p = {:.3g} ({}, alpha {:g}, {} vs {} samples)", test.u,
                          test.p, test.exact ? "exact" : "normal approximation", reg.alpha, n_now, n_base);
          if (check.measured > *tolerance) {
            check.verdict = test.p <= reg.alpha ? Verdict::fail : Verdict::warn;
            check.message = fmt::format("{}: slower beyond the tolerance, {}; {}", change,
                                        test.p <= reg.alpha ? "significant" : "not significant", rank);
          } else {
            check.verdict = Verdict::pass;
            check.message = fmt::format("{}; {}", change, rank);
          }
        }
      }
      add(std::move(check));
    }
  }
  // A gate whose every threshold and regression check was skipped measured nothing: its pass
  // would be as empty as an empty config's (e.g. only [regression], and no baseline to compare with).
  // An incomplete sweep is reported as such instead (a failure of the completeness check).
  const std::optional<GateCheck> complete = completeness_check(results);
  if (!results.cells.empty() && (!complete || complete->verdict == Verdict::pass) &&
      std::all_of(report.checks.begin(), report.checks.end(),
                  [](const GateCheck& c) { return c.verdict == Verdict::skip; }))
    throw InputError(nothing_checked_message(config, results, report.checks));
  if (complete) report.checks.push_back(*complete);
  if (std::optional<std::string> note = unused_rules_note(config, results, rule_used)) report.notes.push_back(*note);
  if (std::optional<std::string> note = unapplied_limits_note(config, rule_used, won, applied))
    report.notes.push_back(*note);
  if (!config.vacuous.empty())
    report.notes.push_back(fmt::format("{}: limits that no measure can cross, so they check nothing: {}; turn a check "
                                       "off with = false, or give a limit that can fail",
                                       config.source, fmt::join(config.vacuous, ", ")));
  // A baseline of another sweep (or of cells since renamed) skips every time check without a word.
  if (!baseline.empty() && regression_checks > 0 && regression_with_entry == 0)
    report.notes.push_back(fmt::format(
        "the baseline has no entry for any (cell, pipeline) of {} (its {} cell(s) include '{}'; the results', '{}'): "
        "every time check is skipped; give this sweep's baseline, or store one for these cells (gate "
        "--update-baseline)",
        results.file.string(), baseline.cells.size(), baseline.cells.begin()->first, results.cells.front().cell_id));
  for (const GateCheck& c : report.checks) {
    ++report.counts[c.verdict];
    report.worst = std::max(report.worst, c.verdict);
  }
  return report;
}

std::string format_gate_table(const GateReport& report) {
  std::ostringstream out;
  size_t cell_w = 4, pipe_w = 8, check_w = 5;
  for (const GateCheck& c : report.checks) {
    if (c.verdict != Verdict::warn && c.verdict != Verdict::fail) continue;
    cell_w = std::max(cell_w, c.cell_id.size());
    pipe_w = std::max(pipe_w, c.pipeline.size());
    check_w = std::max(check_w, c.check.size());
  }
  bool header = false;
  for (const Verdict level : {Verdict::fail, Verdict::warn})
    for (const GateCheck& c : report.checks) {
      if (c.verdict != level) continue;
      if (!header) {
        out << fmt::format("{:<7} {:<{}} {:<{}} {:<{}} {:>12}  {}\n", "verdict", "cell", cell_w, "pipeline", pipe_w,
                           "check", check_w, "measured", "limit");
        header = true;
      }
      const std::optional<double> lim = c.verdict == Verdict::fail || !c.warn_limit ? c.fail_limit : c.warn_limit;
      // A minimum (the completeness check's cell count, and the at-least metrics) or a maximum.
      const bool at_least = c.check == kCompleteCheck ||
                            std::any_of(std::begin(kMetricChecks), std::end(kMetricChecks), [&](const MetricCheck& m) {
                              return c.check == m.name && m.direction == Direction::at_least;
                            });
      const auto [measured, limit] = lim ? values_apart(c.check, c.measured, *lim)
                                         : std::pair{value_text(c.check, c.measured), std::string()};
      out << fmt::format("{:<7} {:<{}} {:<{}} {:<{}} {:>12}  {}\n", c.verdict == Verdict::fail ? "FAIL" : "WARN",
                         c.cell_id, cell_w, c.pipeline, pipe_w, c.check, check_w, measured,
                         lim ? fmt::format("{} {}", at_least ? ">=" : "<=", limit) : "-");
      out << "        " << c.message << "\n";
      if (!c.reproduce.empty()) out << "        reproduce: " << c.reproduce << "\n";
    }
  for (const auto& [key, n] : skip_reasons(report.checks))
    out << fmt::format("SKIP    {} x{}: {}\n", key.first, n, key.second);
  for (const std::string& note : report.notes) out << "note: " << note << "\n";
  auto count = [&](Verdict v) {
    const auto it = report.counts.find(v);
    return it == report.counts.end() ? 0 : it->second;
  };
  std::set<std::string> cells;
  for (const GateCheck& c : report.checks)
    if (c.check != kCompleteCheck) cells.insert(c.cell_id);
  out << fmt::format("gate: {} check{} over {} cell{}: {} pass, {} warn, {} fail, {} skipped -> {} (exit {})\n",
                     report.checks.size(), report.checks.size() == 1 ? "" : "s", cells.size(),
                     cells.size() == 1 ? "" : "s", count(Verdict::pass), count(Verdict::warn),
                     count(Verdict::fail), count(Verdict::skip),
                     report.worst == Verdict::fail   ? "FAIL"
                     : report.worst == Verdict::warn ? "WARN"
                                                     : "PASS",
                     exit_code(report.worst));
  return out.str();
}

json gate_report_json(const GateReport& report, const std::string& config_file, const std::string& results_file,
                      const std::string& baseline_file) {
  json checks = json::array();
  for (const GateCheck& c : report.checks) {
    json j = {{"cell_id", c.cell_id},
              {"scene", c.scene},
              {"pipeline", c.pipeline},
              {"check", c.check},
              {"verdict", to_string(c.verdict)},
              {"measured", json_number(c.measured)},
              {"fail_limit", json_limit(c.fail_limit)},
              {"warn_limit", json_limit(c.warn_limit)},
              {"message", c.message}};
    if (c.verdict == Verdict::fail || c.verdict == Verdict::warn) j["reproduce"] = c.reproduce;
    checks.push_back(std::move(j));
  }
  json counts = json::object();
  for (const Verdict v : {Verdict::pass, Verdict::skip, Verdict::warn, Verdict::fail}) {
    const auto it = report.counts.find(v);
    counts[to_string(v)] = it == report.counts.end() ? 0 : it->second;
  }
  return {{"kind", "stereobench.gate"},
          {"schema_version", 1},
          {"config", config_file},
          {"results", results_file},
          {"baseline", baseline_file},
          {"verdict", to_string(report.worst == Verdict::skip ? Verdict::pass : report.worst)},
          {"exit_code", exit_code(report.worst)},
          {"counts", counts},
          {"notes", report.notes},
          {"checks", checks}};
}

}  // namespace sb::validation
