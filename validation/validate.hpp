// One validation: a pipeline's right eye measured against a ground-truth right eye (DESIGN §6) —
// metrics over the whole image and per region, hole statistics against the true disocclusions,
// the left eye too where the pipeline synthesized part of it, and the result record. `stereobench validate` runs it per pipeline; sweeps run it per cell.
#pragma once

#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
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

/// The left eye a pipeline that synthesizes part of its left eye is measured against: this
/// suite's ray tracer's, plain-rt's, traced once per target when first needed (whatever provider
/// gives the right eye's truth: the external ones render the right eye only).
struct LeftReference {
  std::once_flag once;
  Srgb8Image srgb8;
  double seconds = 0.0;
};

/// What every pipeline of one (scene, rig, provider) is measured against, prepared once.
struct ValidationTarget {
  const RenderScene& scene;
  StereoRig rig;
  ResolvedTruth truth;
  Srgb8Image truth_srgb8;
  TrueDisocclusions disocclusions;
  double disocclusion_seconds = 0.0;
  std::shared_ptr<LeftReference> left = std::make_shared<LeftReference>();
};

/// Renders (or loads from the cache) the ground truth and computes the true disocclusions.
/// ToolError when the provider is unavailable; InputError when its image has another size.
[[nodiscard]] ValidationTarget prepare_target(const RenderScene& scene, const std::filesystem::path& scene_file,
                                              const StereoRig& rig, const TruthProvider& provider,
                                              const TruthCache* cache, const std::filesystem::path& work_dir,
                                              const Executor& executor, bool prepare_on_cache_hit = false);

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
  /// With the masks it scored: the hole overlay (holes.png) draws holes.not_reprojected against
  /// the true disocclusions, so that picture and numbers agree.
  HoleStatistics holes;
  SsimMap ssim;
  double seconds_metrics = 0.0;  ///< time to measure (not part of the pipeline's timings)
  /// Left-eye pixels the pipeline did not render itself (tagged other than rasterized, traced,
  /// reshaded_traced or reshaded_raster: bidir-warp's, warped in from the right eye's share,
  /// filled or left as holes).
  uint64_t left_synthesized = 0;
  /// With left_synthesized > 0: the left eye's metrics against plain-rt's left eye, and the left
  /// eye in sRGB (empty otherwise).
  std::optional<ImageMetrics> left;
  Srgb8Image left_srgb8;
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
