// One validation: a pipeline's right eye measured against a ground-truth right eye (DESIGN §6) —
// metrics over the whole image and per region, hole statistics against the true disocclusions,
// and the result record. `stereobench validate` runs it per pipeline; sweeps run it per cell.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/parallel.hpp"
#include "renderer/pipeline.hpp"
#include "renderer/stages/disocclusion.hpp"
#include "validation/hole_stats.hpp"
#include "validation/metrics.hpp"
#include "validation/truth_cache.hpp"

namespace sb::validation {

/// What every pipeline of one (scene, rig, provider) is measured against, prepared once.
struct ValidationTarget {
  const RenderScene& scene;
  StereoRig rig;
  ResolvedTruth truth;
  Srgb8Image truth_srgb8;
  TrueDisocclusions disocclusions;
  double disocclusion_seconds = 0.0;
};

/// Renders (or loads from the cache) the ground truth and computes the true disocclusions.
/// ToolError when the provider is unavailable; InputError when its image has another size.
[[nodiscard]] ValidationTarget prepare_target(const RenderScene& scene, const std::filesystem::path& scene_file,
                                              const StereoRig& rig, const TruthProvider& provider,
                                              const TruthCache* cache, const std::filesystem::path& work_dir,
                                              const Executor& executor);

/// The regions every metric is also computed over (DESIGN §6.2), in this order.
inline constexpr const char* kRegionNames[] = {"reprojected", "filled", "true_disocclusions"};

/// A pipeline measured against the target.
struct PipelineValidation {
  std::string pipeline;  ///< the entry's name: a pipeline's, or a variant's "NAME:KEY=VALUE..."
  PipelineOptions options;
  StereoResult result;
  Srgb8Image right_srgb8;
  ImageMetrics whole;
  /// Metrics per region of kRegionNames: pixels tagged reprojected; pixels the pipeline did not
  /// take from a source image (hole_mask_from_sources); true disocclusions. An empty region has
  /// pixels = 0 and null metrics.
  std::vector<std::pair<std::string, ImageMetrics>> regions;
  std::vector<uint8_t> hole_mask;
  HoleStatistics holes;
  SsimMap ssim;
  double seconds_metrics = 0.0;  ///< time to measure (not part of the pipeline's timings)
};

/// Renders an entry (a pipeline or a variant of one) and measures its right eye, recorded under
/// the entry's name.
[[nodiscard]] PipelineValidation validate_pipeline(const ValidationTarget& target, const PipelineEntry& entry,
                                                   const PipelineOptions& options, const Executor& executor,
                                                   const MetricOptions& metric_options = {});

/// The result record of one pipeline (schema in docs/results.md): kind, schema version, metrics
/// version, inputs (scene, rig, pipeline and options, truth provider with tool version and cache
/// key), versions, metrics (whole and per region), hole statistics, timings, counters, and
/// `images` (name -> path as given).
[[nodiscard]] nlohmann::json validation_record(const ValidationTarget& target, const PipelineValidation& v,
                                               int threads, const nlohmann::json& images);

/// The record's schema version; bumped on any incompatible change to validation_record.
inline constexpr int kValidationSchemaVersion = 1;

}  // namespace sb::validation
