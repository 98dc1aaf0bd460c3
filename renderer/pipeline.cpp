// Pipeline registry and option checking.
#include "renderer/pipeline.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <optional>
#include <string_view>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/text.hpp"

namespace sb {

namespace {

std::vector<std::unique_ptr<Pipeline>>& registry() {
  static std::vector<std::unique_ptr<Pipeline>> list;
  return list;
}

}  // namespace

PipelineRegistration::PipelineRegistration(std::unique_ptr<Pipeline> pipeline) {
  registry().push_back(std::move(pipeline));
}

std::vector<const Pipeline*> pipelines() {
  std::vector<const Pipeline*> out;
  for (const auto& p : registry()) out.push_back(p.get());
  std::sort(out.begin(), out.end(), [](const Pipeline* a, const Pipeline* b) { return a->info().name < b->info().name; });
  return out;
}

std::vector<std::string> pipeline_names() {
  std::vector<std::string> names;
  for (const Pipeline* p : pipelines()) names.push_back(p->info().name);
  return names;
}

std::vector<std::string> expand_all_pipelines(const std::vector<std::string>& names, const std::string& what) {
  std::vector<std::string> out;
  bool all = false;
  const auto listed = [&out](const std::string& name) { return std::find(out.begin(), out.end(), name) != out.end(); };
  for (const std::string& name : names) {
    if (name == "all") {
      if (all)
        throw InputError(what.empty() ? "'all' is named twice; name it once"
                                      : fmt::format("{} names 'all' twice; name it once", what));
      all = true;
      for (const std::string& n : pipeline_names())
        if (!listed(n)) out.push_back(n);
      continue;
    }
    if (all && listed(name))
      throw InputError(fmt::format("{}'{}' is one of the pipelines 'all' includes; drop one of them",
                                   what.empty() ? "" : what + ": ", name));
    out.push_back(name);
  }
  return out;
}

const Pipeline& find_pipeline(const std::string& name) {
  for (const Pipeline* p : pipelines())
    if (p->info().name == name) return *p;
  std::string names;
  for (const std::string& n : pipeline_names()) names += (names.empty() ? "" : ", ") + n;
  throw InputError(fmt::format("unknown pipeline '{}'; registered pipelines: {}", name, names));
}

std::string entry_pipeline_name(const std::string& entry) { return entry.substr(0, entry.find(':')); }

std::map<std::string, std::string> entry_fixed_options(const std::string& name) {
  std::map<std::string, std::string> fixed;
  for (size_t at = name.find(':'); at < name.size();) {  // name[at] is ':'
    const size_t next = std::min(name.find(':', at + 1), name.size());
    const std::string pair = name.substr(at + 1, next - at - 1);
    const size_t eq = pair.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InputError(
          fmt::format("pipeline entry '{}': '{}' is not KEY=VALUE; write a variant as "
                      "NAME:KEY=VALUE[:KEY=VALUE...], e.g. bidir-warp:occlusion=ztest",
                      name, pair));
    // A variant's name names its files: a blank in it would become part of them ("=_1").
    if (pair.find_first_of(" \t\n\r\v\f") != std::string::npos)
      throw InputError(fmt::format("pipeline entry '{}': '{}' holds a blank; write KEY=VALUE without spaces", name, pair));
    if (!fixed.emplace(pair.substr(0, eq), pair.substr(eq + 1)).second)
      throw InputError(
          fmt::format("pipeline entry '{}' fixes option {} twice; give each option once", name, pair.substr(0, eq)));
    at = next;
  }
  return fixed;
}

PipelineEntry parse_pipeline_entry(const std::string& name) {
  // The name is part of file names (entry_file_stem), beside a scene name, a provider, a suffix and
  // a temporary file's decoration, within the 255 bytes a file name may have.
  constexpr size_t kMaxEntry = 160;
  if (!name.empty() && (std::isspace(static_cast<unsigned char>(name.front())) != 0 ||
                        std::isspace(static_cast<unsigned char>(name.back())) != 0))
    throw InputError(fmt::format("pipeline entry '{}' has blanks around it; write pipeline names without blanks "
                                 "(e.g. plain-rt,ideal-copy)",
                                 name));
  if (name.size() > kMaxEntry)
    throw InputError(fmt::format("pipeline entry '{}...' is {} characters long; it names files, so keep it within {}",
                                 name.substr(0, 40), name.size(), kMaxEntry));
  return {name, &find_pipeline(entry_pipeline_name(name)), entry_fixed_options(name)};
}

namespace {

/// Runs `check`; an InputError it throws about a variant is rethrown naming the entry (the
/// pipeline's own message names a plain pipeline already).
template <class Check>
auto naming_the_entry(const PipelineEntry& entry, Check&& check) {
  try {
    return check();
  } catch (const InputError& error) {
    if (entry.fixed.empty()) throw;
    throw InputError(fmt::format("pipeline entry '{}': {}", entry.name, error.what()));
  }
}

}  // namespace

PipelineOptions PipelineEntry::options(const std::map<std::string, std::string>& given) const {
  std::map<std::string, std::string> values = given;
  for (const auto& [key, value] : fixed) values[key] = value;
  return naming_the_entry(*this, [&] { return PipelineOptions(pipeline->info(), values); });
}

void PipelineEntry::check_rig(const PipelineOptions& options, const StereoRig& rig) const {
  if (const auto check = pipeline->info().check_rig) naming_the_entry(*this, [&] { check(options, rig); });
}

std::string entry_file_stem(const std::string& entry) {
  std::string stem = entry;
  for (char& c : stem) {
    const bool kept = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      std::string_view("._-=+@").find(c) != std::string_view::npos;
    c = c == ':' ? '@' : kept ? c : '_';
  }
  return stem;
}

namespace {

/// A boolean option value: 1/true/on/yes or 0/false/off/no; nothing for any other text.
std::optional<bool> boolean_value(const std::string& v) {
  if (v == "1" || v == "true" || v == "on" || v == "yes") return true;
  if (v == "0" || v == "false" || v == "off" || v == "no") return false;
  return std::nullopt;
}

/// An option value as the pipeline reads it, for comparing spellings: a boolean option's (its
/// default is true or false) as true/false, a number as the shortest text of its double.
std::string canonical_value(const PipelineInfo& info, const std::string& key, const std::string& value) {
  const auto spec = std::find_if(info.options.begin(), info.options.end(), [&](const OptionSpec& o) { return o.name == key; });
  if (spec != info.options.end() && (spec->default_value == "true" || spec->default_value == "false")) {
    const std::optional<bool> b = boolean_value(value);
    return b ? (*b ? "true" : "false") : value;
  }
  double number = 0.0;
  const char* end = value.data() + value.size();
  const auto [at, ec] = std::from_chars(value.data(), end, number);
  if (ec == std::errc() && at == end && std::isfinite(number)) return fmt::format("{}", number);
  return value;
}

}  // namespace

bool PipelineEntry::same_variant(const PipelineEntry& other) const {
  if (pipeline != other.pipeline || fixed.size() != other.fixed.size()) return false;
  for (auto a = fixed.begin(), b = other.fixed.begin(); a != fixed.end(); ++a, ++b)
    if (a->first != b->first || canonical_value(pipeline->info(), a->first, a->second) !=
                                    canonical_value(pipeline->info(), b->first, b->second))
      return false;
  return true;
}

bool PipelineEntry::fixes_otherwise(const std::string& key, const std::string& value) const {
  const auto it = fixed.find(key);
  return it != fixed.end() &&
         canonical_value(pipeline->info(), key, it->second) != canonical_value(pipeline->info(), key, value);
}

std::optional<std::string> find_same_variant(const std::vector<PipelineEntry>& listed, const PipelineEntry& entry) {
  const auto at = std::find_if(listed.begin(), listed.end(), [&](const PipelineEntry& e) { return e.same_variant(entry); });
  if (at == listed.end()) return std::nullopt;
  return at->name;
}

std::vector<PipelineEntry> parse_pipeline_entries(const std::vector<std::string>& names, const std::string& what) {
  // A caller that places the message itself (a sweep file's line and key) passes no list name.
  const std::string prefix = what.empty() ? "" : what + ": ";
  std::vector<PipelineEntry> entries;
  std::map<std::string, std::string> stems;  // stem -> entry
  for (const std::string& name : names) {
    PipelineEntry entry = [&] {
      try {
        return parse_pipeline_entry(name);
      } catch (const InputError& e) {
        throw InputError(prefix + e.what());
      }
    }();
    // One variant under two names (its options in another order) would be rendered and measured
    // twice.
    if (const auto same = find_same_variant(entries, entry); same && *same != name)
      throw InputError(fmt::format("{}'{}' and '{}' name the same variant of {}; name it once", prefix, *same, name,
                                   entry.pipeline->info().name));
    entries.push_back(std::move(entry));
    const auto [it, fresh] = stems.emplace(entry_file_stem(name), name);
    if (fresh) continue;
    if (it->second == name)
      throw InputError(what.empty() ? fmt::format("'{}' is named twice; name each pipeline once", name)
                                    : fmt::format("{} names '{}' twice; name each pipeline once", what, name));
    throw InputError(
        fmt::format("{}'{}' and '{}' would write files of the same name ({}); write the variants "
                    "apart in letters, digits and ._-+",
                    prefix, it->second, name, it->first));
  }
  return entries;
}

PipelineOptions::PipelineOptions(const PipelineInfo& info, const std::map<std::string, std::string>& given)
    : pipeline_(info.name) {
  for (const OptionSpec& o : info.options) values_[o.name] = o.default_value;
  for (const auto& [key, value] : given) {
    if (!values_.count(key)) {
      std::string valid;
      for (const OptionSpec& o : info.options) valid += (valid.empty() ? "" : ", ") + o.name;
      throw InputError(fmt::format("pipeline '{}' has no option '{}' (its options: {})", info.name, key,
                                   valid.empty() ? "none" : valid));
    }
    values_[key] = value;
  }
  if (info.check_options) info.check_options(*this);
}

const std::string& PipelineOptions::get(const std::string& name) const {
  auto it = values_.find(name);
  if (it == values_.end()) throw std::logic_error(fmt::format("pipeline '{}' reads undeclared option '{}'", pipeline_, name));
  return it->second;
}

double PipelineOptions::get_double(const std::string& name) const {
  const std::optional<double> x = parse_finite(get(name));
  if (!x) throw InputError(fmt::format("pipeline '{}': option {}={} is not a finite number", pipeline_, name, get(name)));
  return *x;
}

int PipelineOptions::get_int(const std::string& name) const {
  const double x = get_double(name);
  if (x != std::floor(x))
    throw InputError(fmt::format("pipeline '{}': option {}={} is not a whole number", pipeline_, name, get(name)));
  if (std::fabs(x) > 1e9)
    throw InputError(fmt::format("pipeline '{}': option {}={} is beyond the ±1e9 an integer option takes", pipeline_,
                                 name, get(name)));
  return static_cast<int>(x);
}

bool PipelineOptions::get_bool(const std::string& name) const {
  const std::string& v = get(name);
  if (const std::optional<bool> b = boolean_value(v)) return *b;
  throw InputError(fmt::format("pipeline '{}': option {}={} is not a boolean: give true or false (also 1/0, on/off, yes/no)", pipeline_, name, v));
}

}  // namespace sb
