// Kim's warping stages and baselines: the row-wise 1-D forward warp (against a plain serial
// reference, for any segment length and thread count; minimum depth and the tie rules), crack
// filling, fw-warp and bw-warp on a fronto-parallel plane (exact whole-pixel shifts), fw-warp's
// atomic and row warps giving the same image, and both baselines against plain-raster on atrium.
#include <gtest/gtest.h>

#include <cstdio>
#include <limits>

#include "renderer/error.hpp"
#include "renderer/stages/crack_fill.hpp"
#include "renderer/stages/eye_image.hpp"
#include "renderer/stages/row_warp.hpp"
#include "support/image_metrics.hpp"
#include "support/lit_plane.hpp"
#include "support/render_support.hpp"

namespace sb {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

/// A small deterministic generator for synthetic images.
class Lcg {
 public:
  explicit Lcg(uint32_t seed) : state_(seed) {}
  uint32_t next() {
    state_ = state_ * 1664525u + 1013904223u;
    return state_ >> 8;
  }
  float uniform() { return static_cast<float>(next() & 0xFFFF) / 65536.0f; }

 private:
  uint32_t state_;
};

/// Sets pixel (x, y) of an eye image: a surface of depth z with a radiance that names it, the
/// background (z = inf, tag rasterized), or a hole.
void set_pixel(Image& image, int x, int y, float z, Source tag = Source::rasterized) {
  EyeWriter out(image);
  const size_t i = static_cast<size_t>(y) * image.width() + x;
  if (tag == Source::hole) {
    out.hole(i);
    return;
  }
  const vec3 rgb(static_cast<float>(x), static_cast<float>(y), std::isinf(z) ? -1.0f : z);
  out.copy(i, rgb, vec3(0.0f, 0.0f, 1.0f), vec3(0.5f), z, std::isinf(z) ? kNoPrimitive : static_cast<uint32_t>(x), tag);
}

/// A w x h image of random surfaces at a few depths (exact ties happen), background and holes.
Image random_image(int w, int h, uint32_t seed, double hole_fraction) {
  Image image = make_eye_image(w, h);
  Lcg rng(seed);
  const float depths[] = {1.0f, 1.5f, 2.0f, 3.0f, 8.0f, kInf};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (rng.uniform() < hole_fraction) {
        set_pixel(image, x, y, kInf, Source::hole);
        continue;
      }
      set_pixel(image, x, y, depths[rng.next() % 6]);
    }
  return image;
}

/// Random motion in [-range, range] px (a few values exactly on pixel edges), with row bounds.
MotionField random_motion(const Image& source, float range, uint32_t seed, bool background) {
  MotionField m;
  m.width = source.width();
  m.height = source.height();
  m.motion.resize(source.pixel_count());
  Lcg rng(seed);
  for (float& v : m.motion) v = rng.next() % 5 == 0 ? std::round(range * (2.0f * rng.uniform() - 1.0f)) + 0.5f
                                                    : range * (2.0f * rng.uniform() - 1.0f);
  compute_row_bounds(m, source, background, Executor(1));
  return m;
}

/// The row warp written the plain way: per target pixel, every candidate in turn.
Image reference_row_warp(const Image& source, const MotionField& m, bool background, const Image& target_in) {
  Image target = target_in;
  const int w = source.width(), h = source.height();
  const float* sd = source.data_f32(planes::depth);
  const uint32_t* st = source.data_u32(planes::source);
  const float* td = target_in.data_f32(planes::depth);
  const uint32_t* tt = target_in.data_u32(planes::source);
  EyeWriter out(target);
  for (int y = 0; y < h; ++y)
    for (int t = 0; t < w; ++t) {
      const size_t ti = static_cast<size_t>(y) * w + t;
      const bool native = takes_part(tt[ti], td[ti], background);
      float best = native ? td[ti] : kInf;
      int winner = -1;
      bool any = native;
      for (int x = 0; x < w; ++x) {
        const size_t i = static_cast<size_t>(y) * w + x;
        if (!takes_part(st[i], sd[i], background) || target_column(x, m.motion[i]) != t) continue;
        // Strictly nearer, or an exact tie with an earlier source (the larger x wins), or the first.
        if (!any || sd[i] < best || (sd[i] == best && winner >= 0)) {
          best = sd[i];
          winner = x;
          any = true;
        }
      }
      if (winner < 0) continue;
      const size_t s = static_cast<size_t>(y) * w + winner;
      const auto& rgb = source.rgb_at(winner, y);
      out.copy(ti, vec3(rgb[0], rgb[1], rgb[2]), vec3(0.0f, 0.0f, 1.0f), vec3(0.5f), sd[s],
               source.data_u32(planes::primid)[s], Source::reprojected);
    }
  return target;
}

TEST(RowWarp, TargetColumnIsTheNearestPixelCentre) {
  EXPECT_EQ(target_column(10, 0.0f), 10);
  EXPECT_EQ(target_column(10, 3.0f), 13);
  EXPECT_EQ(target_column(10, 0.49f), 10);
  EXPECT_EQ(target_column(10, 0.5f), 11);  // on the edge between 10 and 11: the right-hand pixel
  EXPECT_EQ(target_column(10, -0.5f), 10);
  EXPECT_EQ(target_column(10, -0.51f), 9);
  EXPECT_EQ(target_column(0, -1e30f), -1);
  EXPECT_EQ(target_column(0, std::numeric_limits<float>::quiet_NaN()), -1);
}

TEST(RowWarp, SameImageForEverySegmentLengthAndThreadCount) {
  const int w = 157, h = 9;
  for (const bool background : {true, false}) {
    SCOPED_TRACE(background);
    const Image source = random_image(w, h, 7, 0.1);
    Image native = random_image(w, h, 11, 0.8);  // a partial target: 80 % holes
    const MotionField m = random_motion(source, 23.0f, 3, background);
    const Image expected = reference_row_warp(source, m, background, native);
    RowWarpStats first;
    bool have_first = false;
    for (const int segment : {1, 7, 64, w, 100000})
      for (const int threads : {1, 2}) {
        SCOPED_TRACE(::testing::Message() << "segment " << segment << ", threads " << threads);
        Image target = native;
        RowWarpOptions o;
        o.segment = segment;
        o.warp_background = background;
        const RowWarpStats s = row_warp(source, m, o, Executor(threads), target);
        EXPECT_TRUE(target == expected);
        EXPECT_EQ(s.sources, s.landed + s.outside);
        EXPECT_EQ(s.landed, s.written + s.occluded);
        if (!have_first) {
          first = s;
          have_first = true;
        }
        EXPECT_EQ(s.sources, first.sources);
        EXPECT_EQ(s.outside, first.outside);
        EXPECT_EQ(s.written, first.written);
      }
    EXPECT_GT(first.occluded, 0u);
    EXPECT_GT(first.outside, 0u);
  }
}

TEST(RowWarp, NearestDepthWinsAndTiesAreDeterministic) {
  const int w = 16, h = 1;
  Image source = make_eye_image(w, h);
  Image target = make_hole_image(w, h, Executor(1));
  for (int x = 0; x < w; ++x) set_pixel(source, x, 0, kInf, Source::hole);
  MotionField m;
  m.width = w;
  m.height = h;
  m.motion.assign(static_cast<size_t>(w), 0.0f);
  // Target 8: x = 2 at 5 m, x = 4 at 2 m (wins, although its x lies between), x = 6 at 3 m.
  set_pixel(source, 2, 0, 5.0f);
  m.motion[2] = 6.0f;
  set_pixel(source, 4, 0, 2.0f);
  m.motion[4] = 4.2f;
  set_pixel(source, 6, 0, 3.0f);
  m.motion[6] = 1.9f;
  // Target 12: x = 9 and x = 11 both at 4 m: the larger x wins the exact tie.
  set_pixel(source, 9, 0, 4.0f);
  m.motion[9] = 3.0f;
  set_pixel(source, 11, 0, 4.0f);
  m.motion[11] = 1.0f;
  // Target 14: a native pixel at 4 m keeps an exact tie with x = 13 at 4 m.
  set_pixel(target, 14, 0, 4.0f, Source::traced);
  set_pixel(source, 13, 0, 4.0f);
  m.motion[13] = 1.0f;
  // Target 1: a native pixel at 6 m loses to x = 0 at 1 m.
  set_pixel(target, 1, 0, 6.0f, Source::traced);
  set_pixel(source, 0, 0, 1.0f);
  m.motion[0] = 1.0f;
  compute_row_bounds(m, source, true, Executor(1));
  const RowWarpStats s = row_warp(source, m, RowWarpOptions{}, Executor(1), target);
  const uint32_t* tag = target.data_u32(planes::source);
  EXPECT_EQ(target.rgb_at(8, 0)[0], 4.0f);
  EXPECT_EQ(target.plane(planes::depth).at_f32(8, 0), 2.0f);
  EXPECT_EQ(target.rgb_at(12, 0)[0], 11.0f);
  EXPECT_EQ(tag[14], static_cast<uint32_t>(Source::traced));
  EXPECT_EQ(target.rgb_at(14, 0)[0], 14.0f);
  EXPECT_EQ(target.rgb_at(1, 0)[0], 0.0f);
  EXPECT_EQ(tag[1], static_cast<uint32_t>(Source::reprojected));
  EXPECT_EQ(tag[0], static_cast<uint32_t>(Source::hole));  // untouched holes stay holes
  EXPECT_TRUE(std::isinf(target.plane(planes::depth).at_f32(0, 0)));
  EXPECT_EQ(s.sources, 7u);
  EXPECT_EQ(s.written, 3u);
  EXPECT_EQ(s.occluded, 4u);
}

TEST(RowWarp, KeptNativePixelsOnlyLetSourcesIntoHoles) {
  const int w = 8, h = 1;
  Image source = make_eye_image(w, h);
  for (int x = 0; x < w; ++x) set_pixel(source, x, 0, kInf, Source::hole);
  MotionField m;
  m.width = w;
  m.height = h;
  m.motion.assign(static_cast<size_t>(w), 2.0f);
  set_pixel(source, 0, 0, 1.0f);  // to 2: a native surface at 6 m
  set_pixel(source, 1, 0, 1.0f);  // to 3: the native background
  set_pixel(source, 2, 0, 1.0f);  // to 4: a hole
  compute_row_bounds(m, source, false, Executor(1));
  Image target = make_hole_image(w, h, Executor(1));
  set_pixel(target, 2, 0, 6.0f, Source::traced);
  set_pixel(target, 3, 0, kInf, Source::traced);
  RowWarpOptions options{256, false};
  // Without keep_native the nearer source wins the surface and takes the background too.
  Image plain = target;
  EXPECT_EQ(row_warp(source, m, options, Executor(1), plain).written, 3u);
  EXPECT_EQ(plain.rgb_at(2, 0)[0], 0.0f);
  EXPECT_EQ(plain.rgb_at(3, 0)[0], 1.0f);
  options.keep_native = true;
  const RowWarpStats s = row_warp(source, m, options, Executor(1), target);
  const uint32_t* tag = target.data_u32(planes::source);
  EXPECT_EQ(s.written, 1u);
  EXPECT_EQ(s.occluded, 2u);
  EXPECT_EQ(target.rgb_at(2, 0)[0], 2.0f);
  EXPECT_EQ(target.plane(planes::depth).at_f32(2, 0), 6.0f);
  EXPECT_EQ(tag[3], static_cast<uint32_t>(Source::traced));
  EXPECT_TRUE(std::isinf(target.plane(planes::depth).at_f32(3, 0)));
  EXPECT_EQ(target.rgb_at(4, 0)[0], 2.0f);
  EXPECT_EQ(tag[4], static_cast<uint32_t>(Source::reprojected));
}

TEST(RowWarp, ChecksItsInputs) {
  const Image source = random_image(8, 2, 1, 0.0);
  Image target = make_eye_image(8, 2);
  const MotionField m = random_motion(source, 2.0f, 1, true);
  RowWarpOptions o;
  o.segment = 0;
  EXPECT_THROW((void)row_warp(source, m, o, Executor(1), target), InputError);
  Image small = make_eye_image(4, 2);
  EXPECT_THROW((void)row_warp(source, m, RowWarpOptions{}, Executor(1), small), InputError);
  Image same = source;
  EXPECT_THROW((void)row_warp(same, m, RowWarpOptions{}, Executor(1), same), InputError);
}

TEST(CrackFill, FillsNarrowCracksAndCountsTheRest) {
  const int w = 30, h = 2;
  Image image = make_eye_image(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) set_pixel(image, x, y, 2.0f + 0.1f * static_cast<float>(x));
  // Row 0: a border run of 2 at the left, a 1-px crack at 5, a 10-px hole at 12..21.
  for (const int x : {0, 1, 5}) set_pixel(image, x, 0, kInf, Source::hole);
  for (int x = 12; x < 22; ++x) set_pixel(image, x, 0, kInf, Source::hole);
  // Row 1: a 2-px crack at 7..8 beside the background at 9, and a border run of 1 at the right.
  set_pixel(image, 7, 1, kInf, Source::hole);
  set_pixel(image, 8, 1, kInf, Source::hole);
  set_pixel(image, 9, 1, kInf);
  set_pixel(image, w - 1, 1, kInf, Source::hole);
  const Image before = image;

  const CrackFillStats s = fill_cracks(image, kDefaultCrackWidth, Executor(2));
  const uint32_t* tag = image.data_u32(planes::source);
  const float* depth = image.data_f32(planes::depth);
  // The 1-px crack: the mean of its neighbours, nearer depth interpolated, attributes of the farther.
  for (int c = 0; c < 3; ++c)
    EXPECT_FLOAT_EQ(image.rgb_at(5, 0)[static_cast<size_t>(c)],
                    0.5f * (before.rgb_at(4, 0)[static_cast<size_t>(c)] + before.rgb_at(6, 0)[static_cast<size_t>(c)]));
  EXPECT_EQ(tag[5], static_cast<uint32_t>(Source::inpainted));
  EXPECT_FLOAT_EQ(depth[5], 0.5f * (2.4f + 2.6f));
  EXPECT_EQ(image.data_u32(planes::primid)[5], 6u);
  // The 2-px crack next to the background: thirds of the way, depth +inf, the background's id.
  const size_t r1 = static_cast<size_t>(w);
  EXPECT_FLOAT_EQ(image.rgb_at(7, 1)[0], (2.0f * 6.0f + 9.0f) / 3.0f);
  EXPECT_FLOAT_EQ(image.rgb_at(8, 1)[0], (6.0f + 2.0f * 9.0f) / 3.0f);
  EXPECT_TRUE(std::isinf(depth[r1 + 7]));
  EXPECT_EQ(image.data_u32(planes::primid)[r1 + 8], kNoPrimitive);
  // The 10-px hole and the border runs are untouched.
  for (const int x : {0, 1, 12, 16, 21}) EXPECT_EQ(tag[x], static_cast<uint32_t>(Source::hole)) << x;
  EXPECT_EQ(tag[r1 + w - 1], static_cast<uint32_t>(Source::hole));
  EXPECT_EQ(image.rgb_at(16, 0), before.rgb_at(16, 0));
  EXPECT_EQ(s.hole_pixels, 3u + 10u + 3u);
  EXPECT_EQ(s.cracks, 2u);
  EXPECT_EQ(s.pixels_filled, 3u);
  EXPECT_EQ(s.large_holes, 1u);
  EXPECT_EQ(s.large_hole_pixels, 10u);
  EXPECT_EQ(s.border_holes, 2u);
  EXPECT_EQ(s.border_hole_pixels, 3u);
  EXPECT_EQ(s.holes_left(), 13u);

  // Parallel rows give the same image; max width 0 fills nothing.
  Image again = before;
  (void)fill_cracks(again, kDefaultCrackWidth, Executor(1));
  EXPECT_TRUE(again == image);
  Image none = before;
  EXPECT_EQ(fill_cracks(none, 0, Executor(1)).pixels_filled, 0u);
  EXPECT_TRUE(none == before);
  EXPECT_THROW((void)fill_cracks(none, -1, Executor(1)), InputError);

  // Counting only (a pipeline that traces its cracks): the image untouched, the two cracks
  // counted apart from the large hole and the border runs, every hole pixel still left.
  Image counted = before;
  const CrackFillStats c = fill_cracks(counted, kDefaultCrackWidth, Executor(2), CrackMode::count);
  EXPECT_TRUE(counted == before);
  EXPECT_EQ(c.cracks, 0u);
  EXPECT_EQ(c.pixels_filled, 0u);
  EXPECT_EQ(c.cracks_unfilled, 2u);
  EXPECT_EQ(c.crack_pixels_unfilled, 3u);
  EXPECT_EQ(c.large_holes, 1u);
  EXPECT_EQ(c.border_holes, 2u);
  EXPECT_EQ(c.holes_left(), c.hole_pixels);
}

TEST(CrackFill, DepthCracksAreFarSurfacesBetweenNearerPixels) {
  const int w = 24, h = 1;
  Image image = make_eye_image(w, h);
  for (int x = 0; x < w; ++x) set_pixel(image, x, 0, 2.0f);
  // x = 3: one pixel of a surface at 5 m between pixels at 2 m — a crack.
  set_pixel(image, 3, 0, 5.0f);
  // x = 7, 8: a hole and a far pixel between pixels at 2 m — one 2-px crack.
  set_pixel(image, 7, 0, kInf, Source::hole);
  set_pixel(image, 8, 0, 5.0f);
  // x = 12..14: three far pixels — wider than max_width 2, not a crack.
  for (int x = 12; x < 15; ++x) set_pixel(image, x, 0, 5.0f);
  // x = 17: only 0.5 % deeper than its neighbours — within the ratio 1.01, not a crack.
  set_pixel(image, 17, 0, 2.01f);
  // x = 20: deeper than its left neighbour but not than its right one (a step), not a crack.
  set_pixel(image, 20, 0, 4.0f);
  set_pixel(image, 21, 0, 6.0f);
  set_pixel(image, 22, 0, 6.0f);
  set_pixel(image, 23, 0, 6.0f);
  // x = 10: a plain hole between nearer pixels is left to fill_cracks, not counted here.
  set_pixel(image, 10, 0, kInf, Source::hole);
  const Image before = image;

  EXPECT_EQ(mark_depth_cracks(image, 2, 1.01, Executor(1)), 2u);
  const uint32_t* tag = image.data_u32(planes::source);
  for (int x = 0; x < w; ++x) {
    const bool hole = x == 3 || x == 7 || x == 8 || x == 10;
    EXPECT_EQ(tag[x] == static_cast<uint32_t>(Source::hole), hole) << x;
    if (!hole) {
      EXPECT_EQ(image.rgb_at(x, 0), before.rgb_at(x, 0)) << x;
    }
  }
  EXPECT_TRUE(std::isinf(image.plane(planes::depth).at_f32(3, 0)));
  // The fill then interpolates them from the nearer surface.
  const CrackFillStats s = fill_cracks(image, 2, Executor(1));
  EXPECT_EQ(s.pixels_filled, 4u);
  EXPECT_FLOAT_EQ(image.plane(planes::depth).at_f32(3, 0), 2.0f);

  // Larger widths and ratios behave as their definitions say; inputs are checked.
  Image wide = before;
  EXPECT_EQ(mark_depth_cracks(wide, 3, 1.01, Executor(2)), 2u + 3u);
  Image strict = before;
  EXPECT_EQ(mark_depth_cracks(strict, 2, 3.0, Executor(2)), 0u);
  EXPECT_THROW((void)mark_depth_cracks(strict, -1, 1.01, Executor(1)), InputError);
  EXPECT_THROW((void)mark_depth_cracks(strict, 2, 0.5, Executor(1)), InputError);
}

using KimPlane = test::LitPlane;

/// The right eye is the left eye shifted by `shift` whole pixels; the `shift` columns at the left
/// edge, whose sources lie outside the left image, are holes.
void expect_shifted(const StereoResult& r, int shift, const std::string& pipeline) {
  const int w = r.left.width(), h = r.left.height();
  const uint32_t* source = r.right.data_u32(planes::source);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      if (x < shift) {
        ASSERT_EQ(source[i], static_cast<uint32_t>(Source::hole)) << pipeline << " " << x << "," << y;
        continue;
      }
      ASSERT_EQ(source[i], static_cast<uint32_t>(Source::reprojected)) << pipeline << " " << x << "," << y;
      for (int c = 0; c < 3; ++c) {
        const float expected = r.left.rgb_at(x - shift, y)[static_cast<size_t>(c)];
        ASSERT_NEAR(r.right.rgb_at(x, y)[static_cast<size_t>(c)], expected, 1e-5f * std::max(1.0f, expected))
            << pipeline << " " << x << "," << y;
      }
    }
}

TEST_F(KimPlane, ZeroAndIntegerDisparityShiftByWholePixels) {
  for (const int shift : {0, 3}) {
    const StereoRig rig = rig_with_plane_disparity(shift);
    ASSERT_NEAR(rig.disparity_px(4.0), shift, 1e-9);
    for (const std::string pipeline : {"fw-warp", "bw-warp"}) {
      SCOPED_TRACE(pipeline + " shift " + std::to_string(shift));
      const StereoResult r = test::render_with(pipeline, *prepared_, rig, 2);
      expect_shifted(r, shift, pipeline);
      EXPECT_EQ(r.counters.get("holes_left"), static_cast<uint64_t>(shift) * 180u);
    }
    const StereoResult nearest = test::render_with("bw-warp", *prepared_, rig, 2, {{"filter", "nearest"}});
    expect_shifted(nearest, shift, "bw-warp filter=nearest");
  }
}

TEST(KimWarps, AtomicAndRowWarpsGiveTheSameImage) {
  const Scene scene = test::load_builtin("spheres");
  const RenderScene prepared(scene);
  const StereoRig rig = test::rig_at(scene, 320, 180);
  const StereoResult atomic = test::render_with("fw-warp", prepared, rig, 2);
  for (const std::string segment : {"7", "64", "320"}) {
    const StereoResult rows = test::render_with("fw-warp", prepared, rig, 2, {{"warp", "rows"}, {"segment", segment}});
    EXPECT_TRUE(rows.right == atomic.right) << "segment " << segment;
    EXPECT_EQ(rows.counters.get("overlapped"), atomic.counters.get("overlapped"));
  }
  EXPECT_GT(atomic.counters.get("overlapped"), 0u);
  EXPECT_GT(atomic.counters.get("pixels_inpainted"), 0u);
}

TEST(KimWarps, DeterministicAcrossThreadCounts) {
  const Scene scene = test::load_builtin("atrium");
  const RenderScene prepared(scene);
  const StereoRig rig = test::rig_at(scene, 240, 136);
  for (const std::string pipeline : {"fw-warp", "bw-warp"}) {
    const StereoResult a = test::render_with(pipeline, prepared, rig, 1);
    const StereoResult b = test::render_with(pipeline, prepared, rig, 2);
    EXPECT_TRUE(a.right == b.right) << pipeline;
    EXPECT_EQ(a.counters.snapshot(), b.counters.snapshot()) << pipeline;
  }
}

TEST(KimWarps, OptionsAreChecked) {
  const Scene scene = test::load_builtin("lit-plane");
  const RenderScene prepared(scene);
  const StereoRig rig = test::rig_at(scene, 64, 36);
  for (const auto& [key, value] : std::vector<std::pair<std::string, std::string>>{
           {"max_crack", "-1"}, {"warp", "splat"}, {"segment", "0"}, {"tile", "2"}})
    EXPECT_THROW((void)test::render_with("fw-warp", prepared, rig, 1, {{key, value}}), InputError) << key << "=" << value;
  for (const auto& [key, value] : std::vector<std::pair<std::string, std::string>>{
           {"iterations", "-1"}, {"start", "middle"}, {"filter", "cubic"}, {"max_crack", "-2"}})
    EXPECT_THROW((void)test::render_with("bw-warp", prepared, rig, 1, {{key, value}}), InputError) << key << "=" << value;
}

/// Kim's Table 2 setting: atrium (standing in for Crytek Sponza) at 960x540, e = 64 mm, focal
/// distance 6 m; the right eye of each baseline against plain-raster's ("2-Pass").
TEST(KimWarps, AtriumAgainstPlainRaster) {
  const Scene scene = test::load_builtin("atrium");
  const RenderScene prepared(scene);
  RigOverrides o;
  o.width = 960;
  o.height = 540;
  o.interaxial = 0.064;
  o.convergence = 6.0;
  const StereoRig rig = resolve_rig(scene, o);
  const StereoResult truth = test::render_with("plain-raster", prepared, rig, 2);
  // Floors just under the measured values: fw-warp 30.40 dB, SSIM 0.9573; bw-warp 31.98 dB, SSIM
  // 0.9717. Both lose most in the 8-px strip at the left edge that the left eye does not see
  // (a hole); fw-warp also in the disocclusions it leaves black, which bw-warp fills from the
  // background side.
  const std::vector<std::tuple<std::string, double, double>> floors = {{"fw-warp", 30.2, 0.955},
                                                                       {"bw-warp", 31.8, 0.970}};
  for (const auto& [pipeline, min_psnr, min_ssim] : floors) {
    const StereoResult r = test::render_with(pipeline, prepared, rig, 2);
    const double psnr = test::psnr_srgb8(r.right, truth.right);
    const double ssim = test::ssim_srgb8(r.right, truth.right);
    std::printf("%-8s atrium 960x540 c 6 m: right eye vs plain-raster PSNR %.2f dB, SSIM %.4f\n", pipeline.c_str(),
                psnr, ssim);
    EXPECT_GE(psnr, min_psnr) << pipeline;
    EXPECT_GE(ssim, min_ssim) << pipeline;
  }
}

}  // namespace
}  // namespace sb

namespace sb {
namespace {

/// Kim's Table 2 sweep, for the record (run with --gtest_also_run_disabled_tests): the right eye of
/// each baseline against plain-raster's on atrium at 960x540 for focal distances 6, 2 and 0.3 m.
TEST(DISABLED_KimMeasure, AtriumFocalDistances) {
  const Scene scene = test::load_builtin("atrium");
  const RenderScene prepared(scene);
  for (const double c : {6.0, 2.0, 0.3}) {
    RigOverrides o;
    o.width = 960;
    o.height = 540;
    o.interaxial = 0.064;
    o.convergence = c;
    const StereoRig rig = resolve_rig(scene, o);
    const StereoResult truth = test::render_with("plain-raster", prepared, rig, 2);
    for (const std::string pipeline : {"fw-warp", "bw-warp"}) {
      const StereoResult r = test::render_with(pipeline, prepared, rig, 2);
      std::printf("c %.1f m %-8s PSNR %6.2f dB SSIM %.4f hole_pixels %llu holes_left %llu\n", c, pipeline.c_str(),
                  test::psnr_srgb8(r.right, truth.right), test::ssim_srgb8(r.right, truth.right),
                  static_cast<unsigned long long>(r.counters.get("hole_pixels")),
                  static_cast<unsigned long long>(r.counters.get("holes_left")));
    }
  }
}

}  // namespace
}  // namespace sb
