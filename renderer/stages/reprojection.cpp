// Left eye, grid metric and grid warp of the repro-* pipelines.
#include "renderer/stages/reprojection.hpp"

#include <cstring>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/stages/eye_image.hpp"
#include "renderer/stages/raster_eye.hpp"
#include "renderer/stages/source_frustum.hpp"

namespace sb {

std::vector<OptionSpec> grid_warp_option_specs(bool with_detection) {
  std::vector<OptionSpec> specs{
      {"threshold_arcmin", "1.0",
       "binocular-parallax difference (minutes of arc) above which a 16x16 cell is subdivided to native resolution"},
      {"grid_overlay", "false", "also output the warping grid drawn over the left eye (<stem>_grid.png; render, validate and sweep cells write it)"},
      tile_option_spec()};
  if (with_detection) {
    specs.push_back({"discontinuity_px", "0.05",
                     "disocclusion detection: a grid vertex is flagged where a source-row gap beside it opens this many "
                     "pixels more than its neighbouring gaps (a disparity step)"});
    specs.push_back({"occluding_edge_px", "0.5",
                     "also fill the pixel just left of a surface that is nearer than its left neighbour by more than "
                     "this many pixels of disparity (its silhouette may reach it); 0 = off"});
    specs.push_back({"source_frustum", "true",
                     "also fill the right-eye pixels that see a surface outside the left frustum (near objects "
                     "entering at the right edge), found with rays restricted to the part of each pixel ray the left "
                     "eye cannot see"});
    specs.push_back({"discard", "triangle",
                     "which warped fragments are discarded: 'triangle' (grid triangles whose vertices are all flagged) "
                     "or 'interpolated' (the paper's: the measure interpolated, fragments above the threshold)"});
  }
  return specs;
}

ReprojectionSettings ReprojectionSettings::from(const std::string& pipeline, const PipelineOptions& options,
                                                bool with_detection) {
  ReprojectionSettings s;
  s.threshold_arcmin = options.get_double("threshold_arcmin");
  if (!(s.threshold_arcmin > 0.0))
    throw InputError(fmt::format("{}: option threshold_arcmin={} must be positive (1.0 is the paper's value)", pipeline,
                                 s.threshold_arcmin));
  s.grid_overlay = options.get_bool("grid_overlay");
  s.raster = raster_options(pipeline, options);
  s.warp.detect_disocclusions = with_detection;
  if (with_detection) {
    s.warp.discontinuity_px = options.get_double("discontinuity_px");
    if (!(s.warp.discontinuity_px > 0.0))
      throw InputError(
          fmt::format("{}: option discontinuity_px={} must be positive", pipeline, s.warp.discontinuity_px));
    s.warp.occluding_edge_px = options.get_double("occluding_edge_px");
    if (!(s.warp.occluding_edge_px >= 0.0))
      throw InputError(fmt::format("{}: option occluding_edge_px={} must be 0 (off) or positive", pipeline,
                                   s.warp.occluding_edge_px));
    s.source_frustum = options.get_bool("source_frustum");
    const std::string& rule = options.get("discard");
    if (rule == "triangle") {
      s.warp.rule = DiscardRule::all_vertices;
    } else if (rule == "interpolated") {
      s.warp.rule = DiscardRule::interpolated;
    } else {
      throw InputError(
          fmt::format("{}: option discard={} is not a rule; use 'triangle' or 'interpolated'", pipeline, rule));
    }
  }
  return s;
}

std::vector<uint8_t> warp_left_to_right(const RenderScene& scene, const StereoRig& rig, const ReprojectionSettings& settings,
                                        const Executor& executor, StereoResult& r) {
  r.left = raster_eye(scene, rig, Eye::left, settings.raster, executor, r);
  const EyeCamera left = rig.eye(Eye::left), right = rig.eye(Eye::right);
  const double e = rig.params().interaxial;
  WarpGrid grid;
  {
    ScopedStage stage(r.timings, "grid_metric", StageEye::right);
    GridSettings gs;
    gs.interaxial = e;
    gs.focal_px = left.f_px;
    gs.threshold_arcmin = settings.threshold_arcmin;
    gs.opening_px = settings.warp.detect_disocclusions ? settings.warp.discontinuity_px : 0.0;
    grid = build_warp_grid(r.left.plane(planes::depth).f32(), left.width, left.height, gs, executor);
  }
  WarpStats ws;
  SourceFrustumStats frustum;
  std::vector<uint8_t> states;
  {
    ScopedStage stage(r.timings, "grid_warp", StageEye::right);
    // grid_warp writes every pixel of every plane.
    r.right = make_eye_image(right.width, right.height, PlaneInit::unset);
    states = grid_warp(grid, r.left, left, right, e, settings.warp, executor, r.right, ws);
  }
  if (settings.warp.detect_disocclusions && settings.source_frustum) {
    // Not the paper's: timed apart, so that grid_warp compares with its grid rendering.
    ScopedStage stage(r.timings, "source_frustum", StageEye::right);
    frustum = mark_outside_source_frustum(scene, left, right, executor, states,
                                          static_cast<uint8_t>(WarpPixel::covered),
                                          static_cast<uint8_t>(WarpPixel::outside_source));
    EyeWriter out(r.right);
    // The marked pixels are few (a strip at an image edge, if any): memchr finds them.
    const uint8_t* const first = states.data();
    const uint8_t* const end = first + states.size();
    for (const void* at = std::memchr(first, static_cast<int>(WarpPixel::outside_source), states.size()); at != nullptr;) {
      const auto* p = static_cast<const uint8_t*>(at);
      out.hole(static_cast<size_t>(p - first));
      at = std::memchr(p + 1, static_cast<int>(WarpPixel::outside_source), static_cast<size_t>(end - p - 1));
    }
    ws.pixels_covered -= frustum.pixels;
  }
  r.counters.set("grid_cells", static_cast<uint64_t>(grid.flagged.size()));
  r.counters.set("grid_cells_flagged", grid.flagged_count());
  r.counters.set("grid_cells_opening", grid.opening_count());
  r.counters.set("grid_cells_subdivided", grid.subdivided_count());
  r.counters.set("grid_triangles", ws.triangles);
  r.counters.set("grid_triangles_culled", ws.triangles_culled);
  r.counters.set("grid_fragments", ws.fragments);
  r.counters.set("grid_fragments_discarded", ws.fragments_discarded);
  r.counters.set("pixels_reprojected_right", ws.pixels_covered);
  r.counters.set("hole_pixels", ws.pixels_discarded + ws.pixels_uncovered + ws.pixels_occluding_edge + frustum.pixels);
  r.counters.set("hole_pixels_discarded", ws.pixels_discarded);
  r.counters.set("hole_pixels_occluding_edge", ws.pixels_occluding_edge);
  r.counters.set("hole_pixels_uncovered", ws.pixels_uncovered);
  if (settings.warp.detect_disocclusions && settings.source_frustum) {
    r.counters.set("hole_pixels_outside_frustum", frustum.pixels);
    r.counters.set("frustum_triangles_near", frustum.triangles_near);
    r.counters.set("frustum_rays", frustum.rays);
  }
  if (settings.grid_overlay) r.extras.emplace_back("grid", grid_overlay(grid, r.left));
  return states;
}

}  // namespace sb
