// Side-by-side timing of pipelines on one scene and rig: warm-up, then repetitions that run every
// pipeline in turn (so machine noise hits all alike), each repetition starting one pipeline further
// along (so none always runs first), summarised as median/min/max per stage and
// as speed-ups against a baseline measured in the same run (DESIGN §8).
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/pipeline.hpp"

namespace sb {

/// What an entry of BenchConfig::pipelines runs.
struct BenchEntry {
  PipelineEntry entry;
  PipelineOptions options;
};

struct BenchConfig {
  /// Entries, in report order: a registered pipeline's name, or a variant of it with options fixed
  /// in the entry, "NAME:KEY=VALUE[:KEY=VALUE...]" (e.g. "bidir-warp:occlusion=ztest").
  std::vector<std::string> pipelines;
  std::string baseline;  ///< one of `pipelines`
  int warmup = 1;
  int repetitions = 5;
  /// Per pipeline name; they apply to its variants too, under the variants' own options.
  std::map<std::string, std::map<std::string, std::string>> options;

  /// What each entry runs, in order: the entry parsed, and its options with those given for its
  /// pipeline merged in under its own. InputError for repetitions < 1, warm-up < 0, unknown
  /// pipelines, malformed variants or option values (naming the entry), an entry named twice, a
  /// baseline not benchmarked, or options for a pipeline not benchmarked.
  [[nodiscard]] std::vector<BenchEntry> entries() const;
  /// The checks of entries(), when only they are wanted.
  void validate() const { (void)entries(); }
};

/// The options given for the pipelines, as "PIPELINE.NAME=VALUE, ..." in order; empty when none.
[[nodiscard]] std::string given_options(const BenchConfig& config);

/// Median, minimum and maximum of a sample.
struct Summary {
  double median = 0.0, min = 0.0, max = 0.0;
};
[[nodiscard]] Summary summarize(std::vector<double> values);

struct PipelineBench {
  std::string name;
  std::vector<std::string> stage_order;
  std::map<std::string, std::vector<double>> stage_seconds;  ///< per repetition
  std::vector<double> total_seconds;
  /// Per repetition, the seconds of the stages that serve the left eye, the right eye and both
  /// (StageEye); left + right + both = total.
  std::vector<double> left_seconds, right_seconds, both_seconds;
  std::vector<std::string> shared_stages;  ///< the stages that serve both eyes, in order
  nlohmann::json stage_eyes = nlohmann::json::object();  ///< stage -> the eye it serves (io::stage_eyes_to_json)
  std::map<std::string, uint64_t> counters;  ///< of the last repetition (counters are deterministic)
  Summary speedup;  ///< baseline total / this total, paired per repetition
  std::map<std::string, std::string> options;  ///< every option's value, defaults included

  /// Right eye / left eye, paired per repetition and summarized: what a synthesized right eye
  /// costs beside the rendered left one. Nothing where no stage serves the left eye alone.
  [[nodiscard]] std::optional<Summary> right_over_left() const;
};

/// `base`'s total over `b`'s, paired per repetition (both of one run_bench) and summarized: the
/// speed-up of `b` over `base`.
[[nodiscard]] Summary paired_speedup(const PipelineBench& base, const PipelineBench& b);

struct BenchResult {
  std::vector<PipelineBench> pipelines;
  std::string baseline;
  int warmup = 0;
  int repetitions = 0;
  int threads = 0;
};

/// What run_bench checks before anything renders: the frames fit in memory (require_frame_memory)
/// and every entry can work with the rig (InputError, check_rig).
void check_bench(const StereoRig& rig, const BenchConfig& config);

/// Runs the benchmark. `progress` (may be empty) is called after every run with a short line.
[[nodiscard]] BenchResult run_bench(const RenderScene& scene, const StereoRig& rig, const BenchConfig& config,
                                    const Executor& executor,
                                    const std::function<void(const std::string&)>& progress = {});

/// The result as JSON (medians, min, max, raw samples, speed-ups, counters).
[[nodiscard]] nlohmann::json bench_to_json(const BenchResult& result);

}  // namespace sb
