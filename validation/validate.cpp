// Measuring a pipeline's right eye against ground truth (and a synthesized left eye against plain-rt's).
#include "validation/validate.hpp"

#include <chrono>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/io/render_output.hpp"
#include "renderer/memory.hpp"
#include "renderer/stages/trace.hpp"

namespace sb::validation {

using nlohmann::json;

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

RegionMask mask_of(int width, int height, std::vector<uint8_t> inside) {
  RegionMask m;
  m.width = width;
  m.height = height;
  m.inside = std::move(inside);
  return m;
}

}  // namespace

ValidationTarget prepare_target(const RenderScene& scene, const std::filesystem::path& scene_file,
                                const StereoRig& rig, const TruthProvider& provider, const TruthCache* cache,
                                const std::filesystem::path& work_dir, const Executor& executor,
                                bool prepare_on_cache_hit) {
  require_frame_memory(rig.params().width, rig.params().height, "validation");
  const TruthRequest request{scene, scene_file, rig, work_dir, executor.threads(), prepare_on_cache_hit};
  ValidationTarget t{scene, rig, resolve_truth(provider, request, cache), {}, {}, 0.0};
  const RigParams& p = rig.params();
  if (t.truth.render.right.width() != p.width || t.truth.render.right.height() != p.height)
    throw InputError(fmt::format("the '{}' ground truth is {}x{} but the rig is {}x{}", provider.name(),
                                 t.truth.render.right.width(), t.truth.render.right.height(), p.width, p.height));
  t.truth_srgb8 = encode_srgb8(t.truth.render.right, fmt::format("the '{}' ground truth", provider.name()));
  const auto start = std::chrono::steady_clock::now();
  const VisibleSurfaces right = trace_visible_surfaces(scene, rig.eye(Eye::right), executor);
  t.disocclusions = true_disocclusions(scene, rig, right, executor);
  t.disocclusion_seconds = seconds_since(start);
  return t;
}

PipelineValidation validate_pipeline(const ValidationTarget& target, const PipelineEntry& entry,
                                     const PipelineOptions& options, const Executor& executor,
                                     const MetricOptions& metric_options) {
  PipelineValidation v;
  v.pipeline = entry.name;
  v.options = options;
  v.result = entry.pipeline->render(target.scene, target.rig, options, RenderContext{executor});
  const auto start = std::chrono::steady_clock::now();
  const Image& right = v.result.right;
  const int w = right.width(), h = right.height();
  v.right_srgb8 = encode_srgb8(right, fmt::format("{}'s right eye", v.pipeline));
  v.holes = hole_statistics(right, v.result.counters, target.disocclusions);
  std::vector<uint8_t> reprojected(v.holes.not_reprojected.size());
  for (size_t i = 0; i < reprojected.size(); ++i) reprojected[i] = v.holes.not_reprojected[i] != 0 ? 0 : 1;
  std::vector<uint8_t> disoccluded(target.disocclusions.mask.size());
  for (size_t i = 0; i < disoccluded.size(); ++i) disoccluded[i] = target.disocclusions.mask[i] != 0 ? 1 : 0;
  const RegionMask masks[] = {mask_of(w, h, std::move(reprojected)), mask_of(w, h, v.holes.hole_mask),
                              mask_of(w, h, std::move(disoccluded))};
  const RegionMask* const regions[] = {nullptr, &masks[0], &masks[1], &masks[2]};
  const std::vector<ImageMetrics> metrics =
      compare_regions(v.right_srgb8, target.truth_srgb8, regions, metric_options, &v.ssim);
  v.whole = metrics[0];
  for (size_t r = 0; r < std::size(kRegionNames); ++r) v.regions.emplace_back(kRegionNames[r], metrics[r + 1]);
  // A left eye the pipeline did not render whole is measured too (against plain-rt's left eye):
  // one with pixels warped in, inpainted or left as holes. Pixels it rasterized or traced itself,
  // in its first pass or afterwards (bidir-warp-rt's traced holes), are rendered.
  const uint32_t* left_source = v.result.left.data_u32(planes::source);
  for (size_t i = 0; i < v.result.left.pixel_count(); ++i) {
    const auto s = static_cast<Source>(left_source[i]);
    v.left_synthesized += s != Source::rasterized && s != Source::traced && s != Source::reshaded_traced &&
                                  s != Source::reshaded_raster
                              ? 1
                              : 0;
  }
  double tracing = 0.0;  // the left reference's tracing, when this call did it (recorded apart)
  if (v.left_synthesized > 0) {
    LeftReference& reference = *target.left;
    std::call_once(reference.once, [&] {
      const auto traced = std::chrono::steady_clock::now();
      TraceCounts counts;
      reference.srgb8 =
          encode_srgb8(traced_eye(target.scene, target.rig.eye(Eye::left), executor, counts), "plain-rt's left eye");
      reference.seconds = seconds_since(traced);
      tracing = reference.seconds;
    });
    v.left_srgb8 = encode_srgb8(v.result.left, fmt::format("{}'s left eye", v.pipeline));
    v.left = compare_images(v.left_srgb8, reference.srgb8, nullptr, metric_options);
  }
  v.seconds_metrics = seconds_since(start) - tracing;
  return v;
}

json validation_record(const ValidationTarget& target, const PipelineValidation& v, int threads, const json& images) {
  json regions = json::object();
  for (const auto& [name, m] : v.regions) regions[name] = to_json(m);
  json counters = json::object();
  for (const auto& [name, value] : v.result.counters.snapshot()) counters[name] = value;
  const Scene& scene = target.scene.scene();
  const TruthRender& truth = target.truth.render;
  return {{"kind", "stereobench.validation"},
          {"schema_version", kValidationSchemaVersion},
          {"metrics_version", kMetricsVersion},
          {"pipeline", v.pipeline},
          {"options", v.options.values()},
          {"scene",
           {{"name", scene.name}, {"path", scene.path}, {"triangles", scene.triangle_count()},
            {"lights", scene.lights.size()}}},
          {"rig", io::rig_to_json(target.rig)},
          {"truth",
           {{"provider", truth.provider}, {"tool_version", truth.tool_version}, {"settings", truth.settings},
            {"command", truth.command}, {"seconds", truth.seconds}, {"cached", target.truth.cached},
            {"cache_key", target.truth.key}}},
          {"metrics", to_json(v.whole)},
          {"regions", regions},
          {"holes", to_json(v.holes)},
          {"left_eye", v.left ? json{{"reference", "plain-rt"},
                                     {"synthesized_pixels", v.left_synthesized},
                                     {"metrics", to_json(*v.left)}}
                              : json(nullptr)},
          {"timings_s", io::timings_to_json(v.result.timings)},
          {"stage_eyes", io::stage_eyes_to_json(v.result.timings)},
          {"total_s", v.result.timings.total()},
          {"counters", counters},
          {"threads", threads},
          {"analysis_s", v.left ? json{{"metrics", v.seconds_metrics},
                                       {"true_disocclusions", target.disocclusion_seconds},
                                       {"left_reference", target.left->seconds}}
                                : json{{"metrics", v.seconds_metrics},
                                       {"true_disocclusions", target.disocclusion_seconds}}},
          {"versions", io::versions_json()},
          {"images", images}};
}

}  // namespace sb::validation
