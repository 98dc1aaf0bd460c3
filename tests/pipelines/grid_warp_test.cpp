// The adaptive warping grid and the warp: the parallax metric and its subdivision rules on
// synthetic depth, exact pixel-centre warps of a fronto-parallel plane, no cracks on a slanted
// plane and on `spheres`, every target sample written, the per-row and whole-grid paths giving the
// same bits, the grid overlay, and option checks.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>

#include "renderer/error.hpp"
#include "renderer/stages/disocclusion.hpp"
#include "renderer/stages/eye_image.hpp"
#include "renderer/stages/grid_warp.hpp"
#include "support/lit_plane.hpp"
#include "support/poisoned_image.hpp"
#include "support/render_support.hpp"

namespace sb {
namespace {

constexpr double kInteraxial = 0.064;

GridSettings settings(double threshold_arcmin) {
  GridSettings s;
  s.interaxial = kInteraxial;
  s.focal_px = 1000.0;
  s.threshold_arcmin = threshold_arcmin;
  return s;
}

/// A w x h depth plane at `z` everywhere.
std::vector<float> flat(int w, int h, float z) { return std::vector<float>(static_cast<size_t>(w) * h, z); }

void fill_block(std::vector<float>& depth, int w, int x0, int y0, int x1, int y1, float z) {
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) depth[static_cast<size_t>(y) * w + x] = z;
}

TEST(GridMetric, ParallaxFollowsTheBinocularAngleFormula) {
  // θ(z) = 2 atan(e / 2z), in minutes of arc.
  const double expected = std::abs(2.0 * std::atan(kInteraxial / 4.0) - 2.0 * std::atan(kInteraxial / 6.0)) *
                          (180.0 * 60.0 / std::numbers::pi);
  EXPECT_NEAR(parallax_difference_arcmin(kInteraxial, 2.0, 3.0), expected, 1e-12);
  EXPECT_DOUBLE_EQ(binocular_parallax(kInteraxial, std::numeric_limits<double>::infinity()), 0.0);
  EXPECT_DOUBLE_EQ(parallax_difference_arcmin(kInteraxial, 7.0, 7.0), 0.0);
}

TEST(GridMetric, DepthEdgeIsSubdividedFlatWallIsNotNeighboursAre) {
  const int w = 80, h = 64;  // 5 x 4 cells
  std::vector<float> depth = flat(w, h, 10.0f);
  fill_block(depth, w, 36, 20, 44, 28, 2.0f);  // inside cell (2, 1)
  const Executor executor(2);
  const WarpGrid g = build_warp_grid(depth, w, h, settings(1.0), executor);
  ASSERT_EQ(g.cells_x, 5);
  ASSERT_EQ(g.cells_y, 4);
  EXPECT_TRUE(g.flagged[g.cell(2, 1)]);
  EXPECT_EQ(g.flagged_count(), 1u);
  for (const auto& [cx, cy] : {std::pair{1, 1}, {3, 1}, {2, 0}, {2, 2}}) {
    EXPECT_TRUE(g.subdivided[g.cell(cx, cy)]) << cx << "," << cy;
    EXPECT_FALSE(g.flagged[g.cell(cx, cy)]) << cx << "," << cy;
  }
  EXPECT_EQ(g.subdivided_count(), 5u);
  EXPECT_FALSE(g.subdivided[g.cell(1, 0)]);  // a diagonal neighbour
  EXPECT_FALSE(g.subdivided[g.cell(4, 3)]);  // the flat wall
  EXPECT_FLOAT_EQ(g.zmin[g.cell(2, 1)], 2.0f);
  EXPECT_FLOAT_EQ(g.zmax[g.cell(2, 1)], 10.0f);
}

TEST(GridMetric, PartialCellsCoverTheImageEdges) {
  const int w = 50, h = 35;  // 4 x 3 cells, the last ones 2 and 3 pixels wide
  std::vector<float> depth = flat(w, h, 10.0f);
  fill_block(depth, w, 49, 34, 50, 35, 1.0f);  // the bottom-right pixel
  const WarpGrid g = build_warp_grid(depth, w, h, settings(1.0), Executor(1));
  ASSERT_EQ(g.cells_x, 4);
  ASSERT_EQ(g.cells_y, 3);
  EXPECT_EQ(g.x1(3), w);
  EXPECT_EQ(g.y1(2), h);
  EXPECT_TRUE(g.flagged[g.cell(3, 2)]);
  EXPECT_EQ(g.flagged_count(), 1u);
}

TEST(GridMetric, ThresholdChangesTheCountAsTheFormulaPredicts) {
  // 8 x 4 cells; cell k holds a block at depth z_k inside a 5 m surround, with θΔ = 0.2 (k + 1)′.
  const int cx_n = 8, cy_n = 4, w = cx_n * kGridCell, h = cy_n * kGridCell;
  std::vector<float> depth = flat(w, h, 5.0f);
  std::vector<double> theta;
  const double arcmin = std::numbers::pi / (180.0 * 60.0);
  for (int k = 0; k < cx_n * cy_n; ++k) {
    const double target = 0.2 * (k + 1);
    const double angle = binocular_parallax(kInteraxial, 5.0) - target * arcmin;
    const auto z = static_cast<float>(kInteraxial / (2.0 * std::tan(0.5 * angle)));
    const int x0 = (k % cx_n) * kGridCell + 4, y0 = (k / cx_n) * kGridCell + 4;
    fill_block(depth, w, x0, y0, x0 + 8, y0 + 8, z);
    theta.push_back(parallax_difference_arcmin(kInteraxial, 5.0, z));
  }
  for (const double threshold : {0.5, 1.0, 1.9, 3.3, 7.0}) {
    const WarpGrid g = build_warp_grid(depth, w, h, settings(threshold), Executor(2));
    uint64_t expected = 0;
    for (const double t : theta) expected += t > threshold ? 1 : 0;
    EXPECT_EQ(g.flagged_count(), expected) << threshold;
    for (size_t k = 0; k < theta.size(); ++k) EXPECT_NEAR(g.parallax_arcmin[k], theta[k], 1e-3);
  }
  EXPECT_THROW((void)build_warp_grid(depth, w, h, settings(0.0), Executor(1)), InputError);
  EXPECT_THROW((void)build_warp_grid(std::vector<float>(10), w, h, settings(1.0), Executor(1)), InputError);
}

TEST(GridMetric, GapsOpeningBelowTheParallaxThresholdAreSubdividedForDetection) {
  // A 0.1 px disparity step (f e |1/z1 - 1/z2| with f = 1000) is far below 1′ of parallax.
  const int w = 64, h = 32;
  std::vector<float> depth = flat(w, h, 20.0f);
  const auto z_far = static_cast<float>(1.0 / (1.0 / 20.0 - 0.1 / (1000.0 * kInteraxial)));
  fill_block(depth, w, 40, 0, 64, 32, z_far);  // the far side right of x = 40: a gap opens there
  GridSettings s = settings(1.0);
  EXPECT_EQ(build_warp_grid(depth, w, h, s, Executor(1)).subdivided_count(), 0u);
  s.opening_px = 0.05;
  const WarpGrid g = build_warp_grid(depth, w, h, s, Executor(1));
  EXPECT_EQ(g.flagged_count(), 0u);
  EXPECT_EQ(g.opening_count(), 2u);  // cell column 2 (x 32..47) in both cell rows
  EXPECT_TRUE(g.subdivided[g.cell(2, 0)]);
  EXPECT_TRUE(g.subdivided[g.cell(2, 1)]);
}

using PlaneWarp = test::LitPlane;

TEST_F(PlaneWarp, ZeroDisparityReproducesTheLeftEye) {
  const StereoRig rig = rig_with_plane_disparity(0.0);  // converged on the plane
  const StereoResult r = test::render_with("repro-warp", *prepared_, rig, 2);
  EXPECT_EQ(r.counters.get("hole_pixels"), 0u);
  const float* left = r.left.data_f32(planes::rgb);
  const float* right = r.right.data_f32(planes::rgb);
  for (size_t i = 0; i < r.left.pixel_count() * 3; ++i)
    ASSERT_NEAR(right[i], left[i], 1e-5f * std::max(1.0f, left[i])) << "sample " << i;
}

TEST_F(PlaneWarp, IntegerDisparityShiftsByWholePixels) {
  const StereoRig rig = rig_with_plane_disparity(3.0);
  ASSERT_NEAR(rig.disparity_px(4.0), 3.0, 1e-9);
  const StereoResult r = test::render_with("repro-warp", *prepared_, rig, 2);
  const uint32_t* source = r.right.data_u32(planes::source);
  for (int y = 0; y < 180; ++y)
    for (int x = 0; x < 320; ++x) {
      const size_t i = static_cast<size_t>(y) * 320 + x;
      if (x < 3) {
        // Their source lies left of the left image: outside its frustum.
        EXPECT_EQ(source[i], static_cast<uint32_t>(Source::hole)) << x << "," << y;
        continue;
      }
      ASSERT_EQ(source[i], static_cast<uint32_t>(Source::reprojected)) << x << "," << y;
      for (int c = 0; c < 3; ++c) {
        const float expected = r.left.rgb_at(x - 3, y)[static_cast<size_t>(c)];
        ASSERT_NEAR(r.right.rgb_at(x, y)[static_cast<size_t>(c)], expected, 1e-5f * std::max(1.0f, expected))
            << x << "," << y;
      }
    }
}

TEST(GridWarp, AVanishingInteraxialReproducesTheLeftEyeAcrossDepthEdges) {
  // At 0.001 px of disparity no cell is subdivided, so coarse cells span the depth edges (box and
  // wall, columns and sky). Every warped point moves by at most a few thousandths of a pixel, so the
  // right eye is the left eye. Source positions interpolated perspective-correctly in the target's
  // inverse depth (as a texture coordinate would be) pulled each such cell's pixels towards its
  // near corners: box-wall came out at 24 dB against the left eye, with 40 % of its pixels off.
  // temple's camera is turned, so its warp weighs each vertex by its clip w ratio (the other path).
  for (const char* name : {"box-wall", "temple"}) {
    const Scene scene = test::load_builtin(name);
    const RenderScene prepared(scene);
    const StereoResult r = test::render_with("repro-warp", prepared, test::rig_with_disparity(scene, 128, 72, 1e-3), 2);
    ASSERT_EQ(r.counters.get("grid_cells_subdivided"), 0u) << name;
    float peak = 0.0f, worst = 0.0f;
    const float* left = r.left.data_f32(planes::rgb);
    const float* right = r.right.data_f32(planes::rgb);
    for (size_t i = 0; i < r.left.pixel_count() * 3; ++i) {
      peak = std::max(peak, left[i]);
      worst = std::max(worst, std::abs(right[i] - left[i]));
    }
    EXPECT_LT(worst, 0.01f * peak) << name << ": the largest difference to the left eye";
  }
}

/// repro-warp keeps every rubber sheet, so a watertight warped grid leaves a right-eye pixel
/// uncovered only where its surface lies outside the left image, or where the left eye does not
/// see it at all at the image border (a near surface's silhouette, up to a pixel wide, with nothing
/// warped beside it). Cracks between grid triangles show as uncovered pixels with covered pixels
/// on both sides in their row.
struct Coverage {
  uint64_t uncovered_visible = 0;  ///< uncovered although the left eye sees the surface
  uint64_t slivers = 0;            ///< uncovered between two covered pixels of the row
  uint64_t enclosed = 0;           ///< uncovered between the row's first and last covered pixels
};

/// repro-warp's coverage of a built-in scene's right eye under its default rig at `size` (or the
/// rig `overrides` give), with pipeline `options`.
Coverage coverage(const std::string& scene_name, RigOverrides overrides,
                  const std::map<std::string, std::string>& options = {}) {
  const Scene scene = test::load_builtin(scene_name);
  const RenderScene prepared(scene);
  const StereoRig rig = resolve_rig(scene, overrides);
  const StereoResult r = test::render_with("repro-warp", prepared, rig, 2, options);
  const Executor executor(2);
  const TrueDisocclusions truth =
      true_disocclusions(prepared, rig, trace_visible_surfaces(prepared, rig.eye(Eye::right), executor), executor);
  const uint32_t* source = r.right.data_u32(planes::source);
  const auto covered = [&](size_t i) { return source[i] == static_cast<uint32_t>(Source::reprojected); };
  const int width = r.right.width(), height = r.right.height();
  Coverage c;
  for (int y = 0; y < height; ++y) {
    const size_t row = static_cast<size_t>(y) * width;
    int first = width, last = -1;
    for (int x = 0; x < width; ++x)
      if (covered(row + x)) {
        first = std::min(first, x);
        last = x;
      }
    for (int x = 0; x < width; ++x) {
      const size_t i = row + x;
      if (covered(i)) continue;
      c.uncovered_visible += truth.mask[i] == static_cast<uint8_t>(Disocclusion::visible) ? 1 : 0;
      c.slivers += x > 0 && x + 1 < width && covered(i - 1) && covered(i + 1) ? 1 : 0;
      c.enclosed += x > first && x < last ? 1 : 0;
    }
  }
  return c;
}

Coverage coverage(const std::string& scene_name, int width, int height) {
  RigOverrides o;
  o.width = width;
  o.height = height;
  return coverage(scene_name, o);
}

TEST(GridWarp, NoCracksOnASlantedPlane) {
  const Coverage c = coverage("slanted-plane", 480, 270);
  EXPECT_EQ(c.uncovered_visible, 0u);
  EXPECT_EQ(c.slivers, 0u);
}

TEST(GridWarp, NoCracksOnSpheres) {
  const Coverage c = coverage("spheres", 1920, 1080);
  EXPECT_EQ(c.slivers, 0u);
}

/// plain-raster's eyes of a built-in scene at w x h under its default rig, and the warping grid of
/// the left eye (1′; with `opening_px`, cells where a gap opens that much are subdivided too).
struct LeftEyeGrid {
  StereoRig rig;
  StereoResult eyes;
  WarpGrid grid;
};

LeftEyeGrid left_eye_grid(const std::string& name, int width, int height, double opening_px = 0.0) {
  const Scene scene = test::load_builtin(name);
  const RenderScene prepared(scene);
  LeftEyeGrid g{test::rig_at(scene, width, height), {}, {}};
  g.eyes = test::render_with("plain-raster", prepared, g.rig, 2);
  const EyeCamera left = g.rig.eye(Eye::left);
  GridSettings gs = settings(1.0);
  gs.focal_px = left.f_px;
  gs.opening_px = opening_px;
  g.grid = build_warp_grid(g.eyes.left.plane(planes::depth).f32(), left.width, left.height, gs, Executor(2));
  return g;
}

/// repro-rt makes its right eye with unset samples (PlaneInit::unset), so grid_warp must write
/// every sample of every plane: on a target whose unset planes are poisoned none of the poison may
/// remain, with and without disocclusion detection (the pipeline-wide EyeWrites test sees repro-rt's
/// right eye only after its hole fill, which would hide holes the warp left unwritten).
TEST(GridWarp, WritesEverySampleOfTheTarget) {
  const LeftEyeGrid g = left_eye_grid("spheres", 240, 135);
  const EyeCamera left = g.rig.eye(Eye::left), right = g.rig.eye(Eye::right);
  const Executor executor(2);
  for (const bool detect : {false, true}) {
    Image target;
    {
      const test::PoisonUnsetPlanes poison;
      target = make_eye_image(right.width, right.height, PlaneInit::unset);
    }
    for (const Plane& p : target.planes()) ASSERT_EQ(test::sentinel_count(p), p.value_count()) << p.name();
    WarpOptions options;
    options.detect_disocclusions = detect;
    WarpStats stats;
    const std::vector<uint8_t> states =
        grid_warp(g.grid, g.eyes.left, left, right, kInteraxial, options, executor, target, stats);
    EXPECT_EQ(states.size(), target.pixel_count());
    EXPECT_GT(stats.pixels_covered, target.pixel_count() / 2);
    for (const Plane& plane : target.planes())
      EXPECT_EQ(test::sentinel_count(plane), 0u) << "plane " << plane.name() << ", detection " << detect;
  }
}

/// Warping and resolving each row of cells in one task (the horizontal rig's path) and warping the
/// whole grid before resolving (any rig's) give the same bits in every plane, the same pixel states
/// and the same counts, with and without disocclusion detection; on scenes with depth edges in
/// most cells (native cells and coarse fans alike) and an image height that is not a multiple of 16.
TEST(GridWarp, PerCellRowResolveGivesTheSameImage) {
  for (const char* name : {"temple", "box-wall"}) {
    const LeftEyeGrid g = left_eye_grid(name, 248, 141, 0.05);
    const EyeCamera left = g.rig.eye(Eye::left), right = g.rig.eye(Eye::right);
    const Executor executor(2);
    ASSERT_GT(g.grid.subdivided_count(), 0u);
    ASSERT_LT(g.grid.subdivided_count(), g.grid.subdivided.size());
    for (const bool detect : {false, true}) {
      Image image[2] = {make_eye_image(right.width, right.height), make_eye_image(right.width, right.height)};
      std::vector<uint8_t> states[2];
      WarpStats stats[2];
      for (const int k : {0, 1}) {
        WarpOptions options;
        options.detect_disocclusions = detect;
        options.resolve_per_cell_row = k == 0;
        states[k] = grid_warp(g.grid, g.eyes.left, left, right, kInteraxial, options, executor, image[k], stats[k]);
      }
      const std::string where = std::string(name) + (detect ? ", detection on" : ", detection off");
      EXPECT_EQ(states[0], states[1]) << where;
      EXPECT_GT(stats[0].pixels_covered, image[0].pixel_count() / 2) << where;
      EXPECT_TRUE(stats[0] == stats[1]) << where;
      if (detect) {
        EXPECT_GT(stats[0].pixels_discarded, 0u) << where;
      }
      for (const Plane& plane : image[0].planes())
        EXPECT_TRUE(plane == image[1].plane(plane.name())) << where << ", plane " << plane.name();
    }
  }
}

TEST(GridWarp, OverlayTintsFlaggedCells) {
  const int w = 64, h = 48;
  std::vector<float> depth = flat(w, h, 10.0f);
  fill_block(depth, w, 20, 20, 28, 28, 2.0f);  // inside cell (1, 1)
  const WarpGrid g = build_warp_grid(depth, w, h, settings(1.0), Executor(1));
  Image source(w, h);
  source.add_plane(planes::rgb).fill(0.0f);
  const Image overlay = grid_overlay(g, source);
  const auto inside = overlay.rgb_at(24, 17);  // flagged cell, off its coarse neighbours' edges
  EXPECT_GT(inside[0], 0.3f);
  EXPECT_LT(inside[1], 0.1f);
  const auto neighbour = overlay.rgb_at(40, 24);  // cell (2, 1): subdivided as a neighbour
  EXPECT_GT(neighbour[1], 0.1f);
}

TEST(GridWarp, NoCracksBesideAOnePixelWideEdgeCell) {
  // At 321 px the last cell column is 1 px wide and warped at native resolution without being
  // subdivided; the coarse cell beside it kept one long edge against its per-pixel vertices, a
  // T-junction: 52 uncovered pixels between covered ones on atrium with a coarse grid.
  RigOverrides o;
  o.width = 321;
  o.height = 180;
  o.interaxial = 0.3;
  o.convergence = 60.0;
  EXPECT_EQ(coverage("atrium", o, {{"threshold_arcmin", "400"}}).enclosed, 0u);
}

TEST(GridWarp, BorderCellsKeepTheDepthOfTheirSurface) {
  // The ring of lattice points on the image's edges took the border pixels' depth, half a pixel
  // inwards, and coarse border triangles 16.5 px long carried that error over 16 rows: +0.070 % on
  // box-wall's wall at 160x90 (row 0), falling to 0 at row 16. Extrapolated, it is rounding.
  const Scene scene = test::load_builtin("box-wall");
  const RenderScene prepared(scene);
  const StereoRig rig = test::rig_at(scene, 160, 90);
  const StereoResult warp = test::render_with("repro-warp", prepared, rig, 2);
  const StereoResult truth = test::render_with("plain-rt", prepared, rig, 2);
  const float* zw = warp.right.data_f32(planes::depth);
  const float* zt = truth.right.data_f32(planes::depth);
  const uint32_t* pw = warp.right.data_u32(planes::primid);
  const uint32_t* pt = truth.right.data_u32(planes::primid);
  float worst = 0.0f;
  size_t compared = 0;
  for (size_t i = 0; i < 16 * static_cast<size_t>(warp.right.width()); ++i)
    if (pw[i] == pt[i] && pt[i] != kNoPrimitiveId) {
      worst = std::max(worst, std::abs(zw[i] - zt[i]) / zt[i]);
      ++compared;
    }
  EXPECT_GT(compared, 1000u);
  EXPECT_LT(worst, 1e-5f) << "relative depth error in the top cell row";
}

TEST(GridWarp, OptionsAreChecked) {
  const Scene scene = test::load_builtin("lit-plane");
  const RenderScene prepared(scene);
  const StereoRig rig = test::rig_at(scene, 64, 36);
  for (const auto& [key, value] : std::vector<std::pair<std::string, std::string>>{
           {"threshold_arcmin", "0"}, {"threshold_arcmin", "-1"}, {"discontinuity_px", "0"},
           {"discard", "sometimes"}, {"occluding_edge_px", "-1"}, {"tile", "2"},
           // Blanks around a number: the trailing one was refused, the leading one read as 3.
           {"threshold_arcmin", " 3"}, {"threshold_arcmin", "3 "}, {"tile", " 16"}})
    EXPECT_THROW((void)test::render_with("repro-rt", prepared, rig, 1, {{key, value}}), InputError) << key << "=" << value;
  EXPECT_THROW((void)test::render_with("repro-warp", prepared, rig, 1, {{"discontinuity_px", "0.1"}}), InputError);
}

}  // namespace
}  // namespace sb
