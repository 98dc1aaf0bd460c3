// One eye rendered by rasterization: the visibility G-buffer, then the deferred lighting pass.
// plain-raster runs it for both eyes, the reprojecting pipelines for their source eye.
#pragma once

#include "renderer/pipeline.hpp"
#include "renderer/raster/rasterizer.hpp"

namespace sb {

/// Rasterizes the G-buffer of `which` eye of the rig, timing the stage "<eye>_gbuffer" as work for
/// `serves` (the eye itself, or both eyes where its pixels are shared between them) and counting
/// rasterized triangles and fragments into `result`.
[[nodiscard]] GBuffer gbuffer_eye(const RenderScene& scene, const StereoRig& rig, Eye which, StageEye serves,
                                  const RasterOptions& options, const Executor& executor, StereoResult& result);

/// Rasterizes and shades `which` eye of the rig into a new eye image, timing the stages
/// "<eye>_gbuffer" and "<eye>_shading" and counting rays, shaded pixels, rasterized triangles and
/// fragments into `result`. The G-buffer is handed back through `gbuffer` when asked for.
[[nodiscard]] Image raster_eye(const RenderScene& scene, const StereoRig& rig, Eye which, const RasterOptions& options,
                               const Executor& executor, StereoResult& result, GBuffer* gbuffer = nullptr);

/// The "tile" option every rasterizing pipeline declares, and its value checked (8..1024;
/// InputError naming the pipeline otherwise).
[[nodiscard]] OptionSpec tile_option_spec();
[[nodiscard]] RasterOptions raster_options(const std::string& pipeline, const PipelineOptions& options);

}  // namespace sb
