// The stages of Kim's bidirectional warping.
#include "renderer/stages/bidirectional.hpp"

#include <atomic>
#include <tuple>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/raster/rasterizer.hpp"
#include "renderer/stages/lighting.hpp"
#include "renderer/stages/raster_eye.hpp"
#include "renderer/stages/redirection.hpp"

namespace sb {

namespace {

/// The redirection bit of `which` eye's share.
uint8_t share_bit(Eye which) { return which == Eye::left ? kRedirectLeft : kRedirectRight; }

/// The lighting pass of a partial image, timed as "<eye>_shading": the pixels `mask` selects (every
/// pixel with a surface when it is null) shaded into a new image whose other pixels are holes — the
/// other eye's partial image may fill them.
Image shade_partial(const RenderScene& scene, const StereoRig& rig, Eye which, const GBuffer& g, const uint8_t* mask,
                    const Executor& executor, StereoResult& r) {
  const std::string name = eye_name(which);
  Image image;
  TraceCounts counts;
  {
    ScopedStage stage(r.timings, name + "_shading", StageEye::both);
    image = make_hole_image(g.width, g.height, executor);
    std::vector<uint8_t> covered;
    if (mask == nullptr) {
      covered.resize(g.prim.size());
      for (size_t i = 0; i < covered.size(); ++i) covered[i] = g.prim[i] != kNoPrimitiveId ? 1 : 0;
      mask = covered.data();
    }
    shade_gbuffer(scene, rig.eye(which), g, executor, image, counts, mask, Source::rasterized);
  }
  add_counts(r.counters, counts, name.c_str(), false);
  return image;
}

/// One eye's share of the scene, rasterized and shaded into its partial image.
Image partial_eye(const RenderScene& scene, const StereoRig& rig, Eye which, const std::vector<uint8_t>& bits,
                  const BidirSettings& settings, const Executor& executor, StereoResult& r) {
  RasterOptions ro = settings.raster;
  ro.triangle_mask = bits.data();
  ro.triangle_bit = share_bit(which);
  return shade_partial(scene, rig, which, gbuffer_eye(scene, rig, which, StageEye::both, ro, executor, r), nullptr, executor, r);
}

/// The pixels an eye shades under the z-test: those whose nearest triangle is in its share, those
/// that see the background, and those whose nearest triangle went to the other eye only but did not
/// win the other eye's depth test where the point lands there (target_column, as the row warp moves
/// it): the other eye shows another triangle in front of it or beside it, so its partial image
/// would not bring the point back. Counts the last kind in `hidden`.
std::vector<uint8_t> ztest_mask(const GBuffer& own, const GBuffer& other, const std::vector<uint8_t>& bits,
                                uint8_t own_bit, const DisparityMotion& motion, const Executor& executor,
                                uint64_t& hidden) {
  const int w = own.width;
  std::vector<uint8_t> mask(own.prim.size());
  std::atomic<uint64_t> total{0};
  executor.for_range(static_cast<size_t>(own.height), 4, [&](size_t begin, size_t end) {
    uint64_t n = 0;
    for (size_t y = begin; y < end; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t i = y * static_cast<size_t>(w) + x;
        const uint32_t prim = own.prim[i];
        if (prim == kNoPrimitiveId || (bits[prim] & own_bit) != 0) {
          mask[i] = 1;
          continue;
        }
        const int t = target_column(x, motion(own.depth[i]));
        const bool seen = t >= 0 && t < w && other.prim[y * static_cast<size_t>(w) + t] == prim;
        mask[i] = seen ? 0 : 1;
        n += seen ? 0 : 1;
      }
    total += n;
  });
  hidden = total;
  return mask;
}

/// Both partial images under the z-test (BidirSettings::ztest).
std::pair<Image, Image> ztest_partials(const RenderScene& scene, const StereoRig& rig, const std::vector<uint8_t>& bits,
                                       const BidirSettings& settings, const Executor& executor, StereoResult& r) {
  const Eye eyes[2] = {Eye::left, Eye::right};
  GBuffer g[2];
  for (int k = 0; k < 2; ++k) g[k] = gbuffer_eye(scene, rig, eyes[k], StageEye::both, settings.raster, executor, r);
  std::vector<uint8_t> mask[2];
  uint64_t hidden[2] = {0, 0};
  {
    ScopedStage stage(r.timings, "ztest", StageEye::both);
    for (int k = 0; k < 2; ++k)
      mask[k] =
          ztest_mask(g[k], g[1 - k], bits, share_bit(eyes[k]), DisparityMotion(rig, eyes[k]), executor, hidden[k]);
  }
  Image image[2];
  for (int k = 0; k < 2; ++k) {
    image[k] = shade_partial(scene, rig, eyes[k], g[k], mask[k].data(), executor, r);
    r.counters.set(std::string("pixels_hidden_in_other_") + eye_name(eyes[k]), hidden[k]);
  }
  return {std::move(image[0]), std::move(image[1])};
}

}  // namespace

std::vector<OptionSpec> bidir_option_specs(bool traced) {
  return {tile_option_spec(),
          {"max_crack", "2",
           traced ? "widest run of pixels in a row that crack_depth can make a crack (cracks are traced, not "
                    "interpolated)"
                  : "widest run of hole pixels in a row filled by linear interpolation after the composition"},
          {"crack_depth", "1.01",
           std::string("a run of at most max_crack pixels deeper than this factor times the depth on both sides is a "
                       "crack (a farther surface showing through the warped one) and is ") +
               (traced ? "traced" : "filled") +
               "; 0 turns this off (off under occlusion=ztest, where each eye's own pixels are its nearest surfaces)"},
          {"segment", "256", "target-row segment length of the row warp in pixels (the image does not depend on it)"},
          {"occlusion", "none",
           "none: each eye rasterizes only its share (Kim's method as published); ztest: both eyes rasterize every "
           "triangle for depth, and each shades its share where it is the nearest surface plus the other eye's share "
           "where the other eye does not show that triangle at the point's place (the z-test Kim's §5 proposes "
           "against occlusion artifacts)"},
          {"clipped", "one",
           "a triangle both eyes' frusta clip: one (Kim's eq. (1) as published: the eye that clips it less rasterizes "
           "it; the other eye shows what lies behind it where only that eye sees it, as beside a wall wider than both "
           "images, and a sliver near a border can go to the eye that sees none of it) or both (each eye whose image "
           "it reaches rasterizes it)"},
          {"cull_closed", "true",
           "true: a double-sided mesh that is closed and wound outwards, with every vertex beyond both eyes' near "
           "planes, has its back faces culled like a single-sided one's (they are hidden in a full render; Kim's "
           "redirection assumes culling, and an eye that rasterizes such a mesh's back triangles shows its inside); "
           "false: only single-sided materials are culled"},
          {"partials", "false",
           "also output each eye's partial image (<stem>_left_partial.png, <stem>_right_partial.png; render, validate and "
           "sweep cells write them)"}};
}

BidirSettings BidirSettings::from(const std::string& pipeline, const PipelineOptions& options) {
  BidirSettings s;
  s.raster = raster_options(pipeline, options);
  s.max_crack = max_crack_option(pipeline, options);
  s.warp.segment = options.get_int("segment");
  s.keep_partials = options.get_bool("partials");
  s.cull_closed = options.get_bool("cull_closed");
  if (s.warp.segment < 1)
    throw InputError(fmt::format("{}: option segment={} must be at least 1 pixel", pipeline, s.warp.segment));
  const std::string& occlusion = options.get("occlusion");
  if (occlusion == "ztest")
    s.ztest = true;
  else if (occlusion != "none")
    throw InputError(fmt::format("{}: option occlusion={} is not one of none, ztest", pipeline, occlusion));
  s.warp.keep_native = s.ztest;
  const std::string& clipped = options.get("clipped");
  if (clipped == "both")
    s.clipped = ClippedRule::both;
  else if (clipped != "one")
    throw InputError(fmt::format("{}: option clipped={} is not one of one, both", pipeline, clipped));
  s.crack_depth_ratio = options.get_double("crack_depth");
  if (!(s.crack_depth_ratio == 0.0 || (s.crack_depth_ratio >= 1.0 && s.crack_depth_ratio <= 100.0)))
    throw InputError(fmt::format("{}: option crack_depth={} must be 0 (off) or lie in [1, 100]", pipeline,
                                 s.crack_depth_ratio));
  // Under the z-test each eye's own pixels are its nearest surfaces, so a deeper pixel between
  // nearer ones is what that eye sees, not a crack. Marking only the warped ones was measured too:
  // atrium 960x540 SSIM 0.9944 / 0.9929 at 6 / 0.3 m against 0.9946 / 0.9931 without marking.
  if (s.ztest) s.crack_depth_ratio = 0.0;
  return s;
}

void render_bidirectional(const RenderScene& scene, const StereoRig& rig, const BidirSettings& settings,
                          const Executor& executor, StereoResult& r) {
  RedirectionCounts sent;
  std::vector<uint8_t> bits;
  // Which meshes are closed is a property of the scene, found once for every render of it (as its
  // BVH is built once) and outside the stage timings.
  if (settings.cull_closed) (void)scene.geometry().closed(executor);
  {
    ScopedStage stage(r.timings, "redirect", StageEye::both);
    uint64_t closed_culled = 0;
    const std::vector<uint8_t> culled =
        culled_meshes(scene.geometry(), rig, executor, settings.cull_closed, closed_culled);
    bits = redirect_triangles(scene.geometry(), rig, culled, executor, sent, settings.clipped);
    r.counters.set("meshes_closed_culled", closed_culled);
  }
  r.counters.set("triangles_to_left", sent.left);
  r.counters.set("triangles_to_right", sent.right);
  r.counters.set("triangles_to_both", sent.both);
  r.counters.set("triangles_culled", sent.culled);
  Image left, right;
  if (settings.ztest) {
    std::tie(left, right) = ztest_partials(scene, rig, bits, settings, executor, r);
  } else {
    left = partial_eye(scene, rig, Eye::left, bits, settings, executor, r);
    right = partial_eye(scene, rig, Eye::right, bits, settings, executor, r);
  }
  MotionField to_right, to_left;
  {
    ScopedStage stage(r.timings, "motion", StageEye::both);
    to_right = disparity_motion_field(left, rig, Eye::left, settings.warp, executor);
    to_left = disparity_motion_field(right, rig, Eye::right, settings.warp, executor);
  }
  RowWarpStats into_right, into_left;
  {
    ScopedStage stage(r.timings, "warp", StageEye::both);
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
    ScopedStage stage(r.timings, "crack_fill", StageEye::both);
    if (settings.crack_depth_ratio > 0.0) {
      r.counters.set("depth_cracks_right",
                     mark_depth_cracks(r.right, settings.max_crack, settings.crack_depth_ratio, executor));
      r.counters.set("depth_cracks_left",
                     mark_depth_cracks(r.left, settings.max_crack, settings.crack_depth_ratio, executor));
    }
    // Without interpolation the runs are only counted (cracks of up to max_crack pixels apart from
    // larger holes): every hole stays for the caller.
    const CrackMode mode = settings.interpolate_cracks ? CrackMode::fill : CrackMode::count;
    cracks_right = fill_cracks(r.right, settings.max_crack, executor, mode);
    cracks_left = fill_cracks(r.left, settings.max_crack, executor, mode);
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
