// Kim's bidirectional warping (§3): the scene split between the eyes by visibility redirection,
// each eye rasterizing and shading its share into a partial image, each partial image warped
// row-wise into the other eye where it competes by depth with that eye's own pixels (the
// composition), and cracks of up to a few pixels filled along the rows. Shared by bidir-warp and
// bidir-warp-rt.
#pragma once

#include "renderer/pipeline.hpp"
#include "renderer/raster/rasterizer.hpp"
#include "renderer/stages/crack_fill.hpp"
#include "renderer/stages/redirection.hpp"
#include "renderer/stages/row_warp.hpp"

namespace sb {

/// Settings of the bidirectional stages.
struct BidirSettings {
  RasterOptions raster;
  int max_crack = 2;
  double crack_depth_ratio = 1.01;  ///< mark_depth_cracks before the fill; 0 = off
  RowWarpOptions warp{256, false};  ///< partial images: only surfaces are warped
  bool keep_partials = false;       ///< add the partial images to the result's extras
  /// Fill the cracks by linear interpolation (Kim). Off, they stay holes (the depth cracks marked
  /// as such) for a caller that traces them.
  bool interpolate_cracks = true;
  /// Kim's §5 remedy for occlusion artifacts (his Fig. 14): both eyes rasterize every triangle
  /// (depth test over the whole scene); each eye shades the pixels whose nearest triangle is in its
  /// share, the background, and the pixels whose nearest triangle went to the other eye but is not
  /// the other eye's nearest where the point lands there. Each eye keeps its own pixels in the
  /// composition (RowWarpOptions::keep_native): they are the nearest surface by construction.
  bool ztest = false;
  /// Where a triangle both frusta clip goes (eq. (1) as published: one eye).
  ClippedRule clipped = ClippedRule::one;
  /// Cull the back faces of double-sided closed meshes that both eyes see from outside
  /// (culled_meshes), as those of single-sided ones.
  bool cull_closed = true;

  /// From the options of bidir_option_specs(); InputError for values out of range.
  static BidirSettings from(const std::string& pipeline, const PipelineOptions& options);
};

/// The options both bidirectional pipelines declare; `traced`: the pipeline traces its cracks
/// instead of interpolating them (the help says so).
[[nodiscard]] std::vector<OptionSpec> bidir_option_specs(bool traced = false);

/// Renders both eyes of `result` (stages redirect, left_gbuffer, left_shading, right_gbuffer,
/// right_shading, motion, warp, crack_fill; with ztest the G-buffers come first, then stage ztest,
/// then the shading). Pixels no partial image covers stay tagged `hole` (radiance 0, depth +inf)
/// for the caller to fill. Counts triangles sent left, right, both and to neither (culled), the
/// double-sided closed meshes culled (meshes_closed_culled), pixels warped into each eye,
/// the crack fill of each eye and, with ztest, each eye's pixels hidden from the other
/// (pixels_hidden_in_other_<eye>). With keep_partials, the partial
/// images go to result.extras as "left_partial" and "right_partial" (the paper's Fig. 3).
void render_bidirectional(const RenderScene& scene, const StereoRig& rig, const BidirSettings& settings,
                          const Executor& executor, StereoResult& result);

/// Gives the pixels still tagged `hole` the scene's background radiance (what a cleared render
/// target shows there) and keeps their tag, so that hole statistics still see them. Returns them.
uint64_t show_background_in_holes(const RenderScene& scene, Image& image);

/// Indices (ascending) of the pixels tagged `hole`.
[[nodiscard]] std::vector<uint32_t> hole_list(const Image& image);

}  // namespace sb
