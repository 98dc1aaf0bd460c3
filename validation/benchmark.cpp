// Side-by-side pipeline benchmark.
#include "validation/benchmark.hpp"

#include <algorithm>
#include <functional>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/io/render_output.hpp"
#include "renderer/memory.hpp"

namespace sb {

Summary summarize(std::vector<double> v) {
  Summary s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  s.median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  s.min = v.front();
  s.max = v.back();
  return s;
}

std::optional<Summary> PipelineBench::right_over_left() const {
  std::vector<double> ratios;
  for (size_t i = 0; i < left_seconds.size() && i < right_seconds.size(); ++i)
    if (left_seconds[i] > 0.0) ratios.push_back(right_seconds[i] / left_seconds[i]);
  if (ratios.empty()) return std::nullopt;
  return summarize(std::move(ratios));
}

std::vector<BenchEntry> BenchConfig::entries() const {
  // The same bounds as a sweep's [timing].
  if (repetitions < 1 || repetitions > 10000)
    throw InputError(fmt::format("--repetitions {} is outside 1..10000", repetitions));
  if (warmup < 0 || warmup > 10000) throw InputError(fmt::format("--warmup {} is outside 0..10000", warmup));
  std::vector<BenchEntry> out;
  for (PipelineEntry& e : parse_pipeline_entries(pipelines, "--pipelines")) {
    const auto given = options.find(e.pipeline->info().name);
    PipelineOptions o = e.options(given == options.end() ? std::map<std::string, std::string>{} : given->second);
    out.push_back({std::move(e), std::move(o)});
  }
  if (std::find(pipelines.begin(), pipelines.end(), baseline) == pipelines.end())
    throw InputError(fmt::format("baseline '{}' is not among the benchmarked pipelines", baseline));
  // The options' values were checked with each entry above; options for no entry are a mistake.
  for (const auto& given : options) {
    const std::string& name = given.first;
    if (std::none_of(pipelines.begin(), pipelines.end(),
                     [&name](const std::string& entry) { return entry_pipeline_name(entry) == name; }))
      throw InputError(fmt::format("options given for pipeline '{}', which is not benchmarked", name));
  }
  return out;
}

std::string given_options(const BenchConfig& config) {
  std::string text;
  for (const auto& [pipeline, values] : config.options)
    for (const auto& [name, value] : values)
      text += fmt::format("{}{}.{}={}", text.empty() ? "" : ", ", pipeline, name, value);
  return text;
}

void check_bench(const StereoRig& rig, const BenchConfig& config) {
  require_frame_memory(rig.params().width, rig.params().height, "benchmark");
  for (const BenchEntry& e : config.entries()) e.entry.check_rig(e.options, rig);  // before any entry renders
}

BenchResult run_bench(const RenderScene& scene, const StereoRig& rig, const BenchConfig& config,
                      const Executor& executor, const std::function<void(const std::string&)>& progress) {
  const std::vector<BenchEntry> entries = config.entries();
  check_bench(rig, config);

  BenchResult result;
  result.baseline = config.baseline;
  result.warmup = config.warmup;
  result.repetitions = config.repetitions;
  result.threads = executor.threads();
  result.pipelines.resize(entries.size());
  for (size_t i = 0; i < entries.size(); ++i) {
    result.pipelines[i].name = entries[i].entry.name;
    result.pipelines[i].options = entries[i].options.values();
  }
  const RenderContext ctx{executor};
  const auto render = [&](size_t i) { return entries[i].entry.pipeline->render(scene, rig, entries[i].options, ctx); };
  for (int w = 0; w < config.warmup; ++w)
    for (size_t i = 0; i < entries.size(); ++i) {
      (void)render(i);
      if (progress) progress(fmt::format("warm-up {}/{} {}", w + 1, config.warmup, entries[i].entry.name));
    }
  // Each repetition starts one pipeline further along the list (a rotation), so that no pipeline
  // always runs first (every one runs in every place equally often when the repetitions are a
  // multiple of the pipelines; with fewer, the first few lead once each): the one run first was
  // measured up to 10 % slower in its first stage (bistro HD, five repetitions: plain-raster's
  // left_shading 1044 ms when first against repro-rt's 939 ms second for the same work, and
  // 1068 / 1088 ms with the order swapped), which favoured every pipeline listed after the baseline.
  for (int rep = 0; rep < config.repetitions; ++rep)
    for (size_t k = 0; k < entries.size(); ++k) {
      const size_t i = (k + static_cast<size_t>(rep)) % entries.size();
      const StereoResult r = render(i);
      PipelineBench& b = result.pipelines[i];
      for (const StageTime& s : r.timings.stages()) {
        if (!b.stage_seconds.count(s.name)) b.stage_order.push_back(s.name);
        b.stage_seconds[s.name].push_back(s.seconds);
      }
      b.total_seconds.push_back(r.timings.total());
      b.left_seconds.push_back(r.timings.eye_total(StageEye::left));
      b.right_seconds.push_back(r.timings.eye_total(StageEye::right));
      b.both_seconds.push_back(r.timings.eye_total(StageEye::both));
      b.shared_stages = r.timings.shared_stages();
      b.stage_eyes = io::stage_eyes_to_json(r.timings);
      b.counters = r.counters.snapshot();
      if (progress)
        progress(fmt::format("repetition {}/{} {} {:.1f} ms", rep + 1, config.repetitions, b.name, r.timings.total() * 1e3));
    }
  const size_t base = static_cast<size_t>(
      std::find(config.pipelines.begin(), config.pipelines.end(), config.baseline) - config.pipelines.begin());
  for (PipelineBench& b : result.pipelines) b.speedup = paired_speedup(result.pipelines[base], b);
  return result;
}

Summary paired_speedup(const PipelineBench& base, const PipelineBench& b) {
  std::vector<double> ratios;
  for (size_t rep = 0; rep < base.total_seconds.size() && rep < b.total_seconds.size(); ++rep)
    ratios.push_back(base.total_seconds[rep] / b.total_seconds[rep]);
  return summarize(ratios);
}

nlohmann::json bench_to_json(const BenchResult& r) {
  nlohmann::json out = {{"kind", "stereobench.bench"},   {"schema_version", 1},
                        {"baseline", r.baseline},          {"warmup", r.warmup},
                        {"repetitions", r.repetitions},    {"threads", r.threads}};
  auto summary = [](const Summary& s) { return nlohmann::json{{"median", s.median}, {"min", s.min}, {"max", s.max}}; };
  for (const PipelineBench& b : r.pipelines) {
    const std::optional<Summary> share = b.right_over_left();
    nlohmann::json stages = nlohmann::json::object();
    for (const std::string& st : b.stage_order) {
      stages[st] = summary(summarize(b.stage_seconds.at(st)));
      stages[st]["samples"] = b.stage_seconds.at(st);
    }
    out["pipelines"].push_back({{"name", b.name},
                                {"total_s", summary(summarize(b.total_seconds))},
                                {"total_samples_s", b.total_seconds},
                                {"stages_s", stages},
                                {"stage_order", b.stage_order},
                                {"stage_eyes", b.stage_eyes},
                                {"speedup_vs_baseline", summary(b.speedup)},
                                {"eyes_s",
                                 {{"left", summary(summarize(b.left_seconds))},
                                  {"right", summary(summarize(b.right_seconds))},
                                  {"both", summary(summarize(b.both_seconds))},
                                  {"shared_stages", b.shared_stages}}},
                                {"right_over_left", share ? summary(*share) : nlohmann::json(nullptr)},
                                {"options", b.options},
                                {"counters", b.counters}});
  }
  return out;
}

}  // namespace sb
