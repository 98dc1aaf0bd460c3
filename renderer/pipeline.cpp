// Pipeline registry and option checking.
#include "renderer/pipeline.hpp"

#include <algorithm>
#include <cmath>

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

const Pipeline& find_pipeline(const std::string& name) {
  for (const Pipeline* p : pipelines())
    if (p->info().name == name) return *p;
  std::string names;
  for (const Pipeline* p : pipelines()) names += (names.empty() ? "" : ", ") + p->info().name;
  throw InputError(fmt::format("unknown pipeline '{}'; registered pipelines: {}", name, names));
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
  if (v == "1" || v == "true" || v == "on" || v == "yes") return true;
  if (v == "0" || v == "false" || v == "off" || v == "no") return false;
  throw InputError(fmt::format("pipeline '{}': option {}={} is not a boolean (true/false)", pipeline_, name, v));
}

}  // namespace sb
