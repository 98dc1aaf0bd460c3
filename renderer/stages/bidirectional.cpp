// The stages of Kim's bidirectional warping.
#include "renderer/stages/bidirectional.hpp"

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/raster/rasterizer.hpp"
#include "renderer/stages/lighting.hpp"
#include "renderer/stages/raster_eye.hpp"
#include "renderer/stages/redirection.hpp"

namespace sb {

namespace {

/// One eye's share of the scene, rasterized and shaded: pixels without a surface of the share are
/// holes, not background — the other eye's partial image may fill them.
Image partial_eye(const RenderScene& scene, const StereoRig& rig, Eye which, const std::vector<uint8_t>& bits,
                  const BidirSettings& settings, const Executor& executor, StereoResult& r) {
  const std::string name = eye_name(which);
  const EyeCamera cam = rig.eye(which);
  RasterOptions ro = settings.raster;
  ro.triangle_mask = bits.data();
  ro.triangle_bit = which == Eye::left ? kRedirectLeft : kRedirectRight;
  RasterStats rs;
  GBuffer g;
  {
    ScopedStage stage(r.timings, name + "_gbuffer");
    g = rasterize(scene.geometry(), cam, executor, ro, &rs);
  }
  Image image;
  TraceCounts counts;
  {
    ScopedStage stage(r.timings, name + "_shading");
    image = make_hole_image(cam.width, cam.height, executor);
    std::vector<uint8_t> covered(g.prim.size());
    for (size_t i = 0; i < covered.size(); ++i) covered[i] = g.prim[i] != kNoPrimitiveId ? 1 : 0;
    shade_gbuffer(scene, cam, g, executor, image, counts, covered.data(), Source::rasterized);
  }
  add_counts(r.counters, counts, name.c_str(), false);
  r.counters.add("triangles_rasterized_" + name, rs.triangles_rasterized);
  r.counters.add("fragments_" + name, rs.fragments_tested);
  return image;
}

}  // namespace

std::vector<OptionSpec> bidir_option_specs() {
  return {tile_option_spec(),
          {"max_crack", "2", "widest run of hole pixels in a row filled by linear interpolation after the composition"},
          {"crack_depth", "1.01",
           "a run of at most max_crack pixels deeper than this factor times the depth on both sides is a crack "
           "(a farther surface showing through the warped one) and is filled; 0 turns this off"},
          {"segment", "256", "target-row segment length of the row warp in pixels (the image does not depend on it)"},
          {"partials", "false", "also output each eye's partial image (<stem>_left_partial.png, <stem>_right_partial.png)"}};
}

BidirSettings BidirSettings::from(const std::string& pipeline, const PipelineOptions& options) {
  BidirSettings s;
  s.raster = raster_options(pipeline, options);
  s.max_crack = max_crack_option(pipeline, options);
  s.warp.segment = options.get_int("segment");
  s.keep_partials = options.get_bool("partials");
  if (s.warp.segment < 1)
    throw InputError(fmt::format("{}: option segment={} must be at least 1 pixel", pipeline, s.warp.segment));
  s.crack_depth_ratio = options.get_double("crack_depth");
  if (!(s.crack_depth_ratio == 0.0 || (s.crack_depth_ratio >= 1.0 && s.crack_depth_ratio <= 100.0)))
    throw InputError(fmt::format("{}: option crack_depth={} must be 0 (off) or lie in [1, 100]", pipeline,
                                 s.crack_depth_ratio));
  return s;
}

void render_bidirectional(const RenderScene& scene, const StereoRig& rig, const BidirSettings& settings,
                          const Executor& executor, StereoResult& r) {
  RedirectionCounts sent;
  std::vector<uint8_t> bits;
  {
    ScopedStage stage(r.timings, "redirect");
    bits = redirect_triangles(scene.geometry(), rig, executor, sent);
  }
  r.counters.set("triangles_to_left", sent.left);
  r.counters.set("triangles_to_right", sent.right);
  r.counters.set("triangles_to_both", sent.both);
  const Image left = partial_eye(scene, rig, Eye::left, bits, settings, executor, r);
  const Image right = partial_eye(scene, rig, Eye::right, bits, settings, executor, r);
  MotionField to_right, to_left;
  {
    ScopedStage stage(r.timings, "motion");
    to_right = disparity_motion_field(left, rig, Eye::left, settings.warp, executor);
    to_left = disparity_motion_field(right, rig, Eye::right, settings.warp, executor);
  }
  RowWarpStats into_right, into_left;
  {
    ScopedStage stage(r.timings, "warp");
    // Each eye's own partial pixels take part in the depth resolution of what the other warps in.
    r.right = right;
    into_right = row_warp(left, to_right, settings.warp, executor, r.right);
    r.left = left;
    into_left = row_warp(right, to_left, settings.warp, executor, r.left);
  }
  if (settings.keep_partials) {
    r.extras.emplace_back("left_partial", left);
    r.extras.emplace_back("right_partial", right);
  }
  r.counters.set("pixels_warped_right", into_right.written);
  r.counters.set("pixels_warped_left", into_left.written);
  CrackFillStats cracks_right, cracks_left;
  {
    ScopedStage stage(r.timings, "crack_fill");
    if (settings.crack_depth_ratio > 0.0) {
      r.counters.set("depth_cracks_right",
                     mark_depth_cracks(r.right, settings.max_crack, settings.crack_depth_ratio, executor));
      r.counters.set("depth_cracks_left",
                     mark_depth_cracks(r.left, settings.max_crack, settings.crack_depth_ratio, executor));
    }
    cracks_right = fill_cracks(r.right, settings.max_crack, executor);
    cracks_left = fill_cracks(r.left, settings.max_crack, executor);
  }
  r.counters.set("hole_pixels", cracks_right.hole_pixels);
  r.counters.set("hole_pixels_left", cracks_left.hole_pixels);
  r.counters.set("pixels_inpainted", cracks_right.pixels_filled);
  add_crack_counters(r.counters, cracks_right);
  r.counters.set("holes_left_in_left", cracks_left.holes_left());
}

uint64_t show_background_in_holes(const RenderScene& scene, Image& image) {
  float* rgb = image.data_f32(planes::rgb);
  const uint32_t* tag = image.data_u32(planes::source);
  const vec3 background = scene.scene().background;
  uint64_t n = 0;
  for (size_t i = 0; i < image.pixel_count(); ++i) {
    if (tag[i] != static_cast<uint32_t>(Source::hole)) continue;
    rgb[3 * i] = background.x;
    rgb[3 * i + 1] = background.y;
    rgb[3 * i + 2] = background.z;
    ++n;
  }
  return n;
}

std::vector<uint32_t> hole_list(const Image& image) {
  const uint32_t* tag = image.data_u32(planes::source);
  std::vector<uint32_t> out;
  for (size_t i = 0; i < image.pixel_count(); ++i)
    if (tag[i] == static_cast<uint32_t>(Source::hole)) out.push_back(static_cast<uint32_t>(i));
  return out;
}

}  // namespace sb
