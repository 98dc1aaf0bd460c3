// The part the grid-warp pipelines share (Wißmann et al. 2020, Fig. 2): the left eye rasterized and
// shaded, the adaptive grid's parallax metric, and the warp of the left eye into the right.
#pragma once

#include <cstdint>
#include <vector>

#include "renderer/pipeline.hpp"
#include "renderer/raster/rasterizer.hpp"
#include "renderer/stages/grid_warp.hpp"

namespace sb {

/// The options every grid-warp pipeline declares, with their defaults.
[[nodiscard]] std::vector<OptionSpec> grid_warp_option_specs(bool with_detection);

/// Settings of the shared stages.
struct ReprojectionSettings {
  double threshold_arcmin = 1.0;
  WarpOptions warp;
  bool grid_overlay = false;
  /// With detection: also find the right-eye pixels whose visible surface lies outside the left
  /// frustum (mark_outside_source_frustum) and leave them to the hole filler.
  bool source_frustum = true;
  RasterOptions raster;

  /// From checked pipeline options (see grid_warp_option_specs); InputError for values out of range.
  /// Messages name `pipeline`.
  static ReprojectionSettings from(const std::string& pipeline, const PipelineOptions& options, bool with_detection);
};

/// Renders result.left by rasterization and warps it into a new result.right (stages left_gbuffer,
/// left_shading, grid_metric, grid_warp, and source_frustum for the search for surfaces outside
/// the left frustum). Returns the WarpPixel state of every right pixel; counts
/// cells, grid triangles, fragments and hole pixels; adds the "grid" overlay to result.extras when
/// asked for.
std::vector<uint8_t> warp_left_to_right(const RenderScene& scene, const StereoRig& rig, const ReprojectionSettings& settings,
                                        const Executor& executor, StereoResult& result);

}  // namespace sb
