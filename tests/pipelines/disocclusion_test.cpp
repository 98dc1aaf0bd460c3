// The true disocclusion mask (DESIGN §6.3) against analytic planes and against an independent
// left-eye lookup on box-wall; trace_visible_surfaces against plain-rt; determinism across thread
// counts; hole masks from source tags, their scores and the overlay image.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <ostream>

#include "renderer/error.hpp"
#include "renderer/io/image_io.hpp"
#include "renderer/render_scene.hpp"
#include "renderer/stages/disocclusion.hpp"
#include "support/render_support.hpp"
#include "support/scratch_dir.hpp"

namespace sb {
namespace {

constexpr int kW = 320, kH = 180;

size_t index_of(int x, int y, int width) {
  return static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x);
}

Disocclusion kind_at(const TrueDisocclusions& truth, size_t i) { return static_cast<Disocclusion>(truth.mask[i]); }

/// The scene's rig at 320x180, at another convergence distance when one is given.
StereoRig rig_for(const Scene& scene, std::optional<double> convergence = std::nullopt) {
  RigOverrides o;
  o.width = kW;
  o.height = kH;
  o.convergence = convergence;
  return resolve_rig(scene, o);
}

TrueDisocclusions truth_for(const RenderScene& rs, const StereoRig& rig, const Executor& executor) {
  return true_disocclusions(rs, rig, trace_visible_surfaces(rs, rig.eye(Eye::right), executor), executor);
}

/// The counts of a TrueDisocclusions agree with its mask.
void expect_counts_match_mask(const TrueDisocclusions& truth) {
  const auto count = [&](Disocclusion k) {
    return static_cast<uint64_t>(std::count(truth.mask.begin(), truth.mask.end(), static_cast<uint8_t>(k)));
  };
  EXPECT_EQ(truth.outside_frustum, count(Disocclusion::outside_frustum));
  EXPECT_EQ(truth.hidden, count(Disocclusion::hidden));
  EXPECT_EQ(truth.count(), truth.outside_frustum + truth.hidden);
}

// ---------------------------------------------------------------------------------------------
// (a) Planes: the frustum test against the rig's disparity formula, occlusion by brute force.

/// What a ray meets, decided in double precision against every triangle of the scene; `unsure`
/// when it passes within 1e-6 (barycentric) of a triangle's edge without a clear hit.
enum class RayFate { hit, miss, unsure };

RayFate brute_force_fate(const Scene& scene, const dvec3& origin, const dvec3& dir) {
  constexpr double margin = 1e-6;
  bool close = false;
  for (const Mesh& m : scene.meshes)
    for (size_t t = 0; t < m.triangle_count(); ++t) {
      const dvec3 a(m.positions[m.indices[3 * t]]), b(m.positions[m.indices[3 * t + 1]]), c(m.positions[m.indices[3 * t + 2]]);
      const dvec3 e1 = b - a, e2 = c - a, p = glm::cross(dir, e2);
      const double det = glm::dot(e1, p);
      if (std::fabs(det) < 1e-18) continue;
      const dvec3 s = origin - a, q = glm::cross(s, e1);
      const double u = glm::dot(s, p) / det, v = glm::dot(dir, q) / det, dist = glm::dot(e2, q) / det;
      if (dist <= 0.0) continue;
      const double lo = std::min({u, v, 1.0 - u - v});
      if (lo >= margin) return RayFate::hit;
      if (lo > -margin) close = true;
    }
  return close ? RayFate::unsure : RayFate::miss;
}

struct PlaneCase {
  const char* label;
  const char* scene;
  std::optional<double> convergence;
  bool expect_outside;  ///< whether the rig puts some of the plane outside the left frustum
};

void PrintTo(const PlaneCase& c, std::ostream* os) { *os << c.label; }

class PlaneScenes : public ::testing::TestWithParam<PlaneCase> {};

/// A plane never hides itself, so the only hidden pixels are background pixels whose parallel ray
/// from the left eye hits the plane; a pixel is outside the left frustum exactly when
/// x_left = x_right - d(Z) (Z from intersecting the pixel's ray with the plane in double
/// precision; d(infinity) = max disparity for background) falls outside [0, W).
TEST_P(PlaneScenes, OutsideFrustumIsTheDisparityBandAndOnlyBackgroundIsHidden) {
  const PlaneCase& pc = GetParam();
  const Scene scene = test::load_builtin(pc.scene);
  const RenderScene rs(scene);
  const StereoRig rig = rig_for(scene, pc.convergence);
  const Executor executor;
  const VisibleSurfaces vs = trace_visible_surfaces(rs, rig.eye(Eye::right), executor);
  const TrueDisocclusions truth = true_disocclusions(rs, rig, vs, executor);
  const EyeCamera right = rig.eye(Eye::right), left = rig.eye(Eye::left);
  // Every triangle of these scenes lies in the plane of the first one.
  const Mesh& mesh = scene.meshes.at(0);
  const dvec3 v0(mesh.positions[mesh.indices[0]]), v1(mesh.positions[mesh.indices[1]]), v2(mesh.positions[mesh.indices[2]]);
  const dvec3 n = glm::normalize(glm::cross(v1 - v0, v2 - v0));
  size_t mismatches = 0, unsure = 0, hidden_surface = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const size_t i = index_of(x, y, kW);
      const dvec3 dir = right.ray_direction(x + 0.5, y + 0.5);
      Disocclusion expected = Disocclusion::visible;
      double disparity = rig.max_disparity_px();
      if (vs.prim[i] == kNoPrimitive) {
        const RayFate fate = brute_force_fate(scene, left.origin, dir);
        if (fate == RayFate::unsure) {
          ++unsure;
          continue;
        }
        if (fate == RayFate::hit) expected = Disocclusion::hidden;
      } else {
        const double t = glm::dot(n, v0 - right.origin) / glm::dot(n, dir);
        disparity = rig.disparity_px(t * glm::dot(dir, -right.back));
        if (kind_at(truth, i) == Disocclusion::hidden) ++hidden_surface;
      }
      const double x_left = x + 0.5 - disparity;
      if (std::fabs(x_left) < 1e-3 || std::fabs(x_left - kW) < 1e-3) {
        ++unsure;  // on the image border: float rounding decides
        continue;
      }
      if (x_left < 0.0 || x_left >= kW) expected = Disocclusion::outside_frustum;
      if (kind_at(truth, i) != expected && ++mismatches <= 5)
        ADD_FAILURE() << "pixel (" << x << ", " << y << "): got " << int(truth.mask[i]) << ", expected "
                      << int(expected) << " (x_left " << x_left << ")";
    }
  EXPECT_EQ(mismatches, 0u);
  EXPECT_EQ(hidden_surface, 0u) << "a plane hides none of its own points";
  EXPECT_LT(unsure, static_cast<size_t>(kW)) << "pixels the test could not decide";
  EXPECT_EQ(truth.outside_frustum > 0, pc.expect_outside);
  expect_counts_match_mask(truth);
  std::printf("%-22s outside %llu, hidden %llu (background), undecided %zu\n", pc.label,
              static_cast<unsigned long long>(truth.outside_frustum), static_cast<unsigned long long>(truth.hidden), unsure);
}

// lit-plane's default rig converges on the plane (no disparity, nothing disoccluded); at c = 2 m the
// plane at 4 m has d = +3.96 px (a left band). slanted-plane converges at 5 m; at c = 1 m every point
// has positive disparity, 5.5 to 14 px across the plane.
INSTANTIATE_TEST_SUITE_P(Analytic, PlaneScenes,
                         ::testing::Values(PlaneCase{"lit_plane", "lit-plane", std::nullopt, false},
                                           PlaneCase{"lit_plane_c2", "lit-plane", 2.0, true},
                                           PlaneCase{"slanted_plane", "slanted-plane", std::nullopt, false},
                                           PlaneCase{"slanted_plane_c1", "slanted-plane", 1.0, true}),
                         [](const ::testing::TestParamInfo<PlaneCase>& p) { return std::string(p.param.label); });

// ---------------------------------------------------------------------------------------------
// (b) box-wall: where the holes are, and an independent check through plain-rt's left eye.

/// Mesh index per pixel of an eye's primid plane; -1 where the eye sees the background.
std::vector<int> mesh_map(const RenderScene& rs, const Image& eye) {
  const std::span<const uint32_t> prim = eye.plane(planes::primid).u32();
  std::vector<int> meshes(prim.size(), -1);
  for (size_t i = 0; i < prim.size(); ++i)
    if (prim[i] != kNoPrimitive) meshes[i] = static_cast<int>(rs.geometry().locate(prim[i]).first);
  return meshes;
}

/// Whether pixel (x, y) is within 1 px of a boundary between meshes or between a mesh and the
/// background.
bool near_silhouette(const std::vector<int>& meshes, int x, int y) {
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int xx = std::clamp(x + dx, 0, kW - 1), yy = std::clamp(y + dy, 0, kH - 1);
      if (meshes[index_of(xx, yy, kW)] != meshes[index_of(x, y, kW)]) return true;
    }
  return false;
}

int mesh_named(const Scene& scene, const std::string& name) {
  for (size_t m = 0; m < scene.meshes.size(); ++m)
    if (scene.meshes[m].name == name) return static_cast<int>(m);
  ADD_FAILURE() << "no mesh named " << name;
  return -2;
}

/// The largest |disparity| in the right eye (background counts as max disparity), rounded up.
int disparity_band(const StereoRig& rig, const Image& right) {
  double most = rig.max_disparity_px();
  for (float z : right.plane(planes::depth).f32())
    if (std::isfinite(z)) most = std::max(most, std::fabs(rig.disparity_px(z)));
  return static_cast<int>(std::ceil(most));
}

/// What plain-rt's left eye shows where a right-eye pixel's point projects: outside_frustum when
/// the projection leaves the left image, hidden when the nearest left pixel sees another primitive
/// more than 2 % nearer (box-wall's occluders are metres in front of what they hide), visible
/// otherwise. Background pixels project as directions and are hidden when the left pixel sees
/// geometry. `unsure` is set when the projection lies within 1e-3 px of the image border.
Disocclusion left_lookup(const StereoRig& rig, const StereoResult& plain, int x, int y, ivec2& left_pixel, bool& unsure) {
  const EyeCamera right = rig.eye(Eye::right), left = rig.eye(Eye::left);
  const size_t i = index_of(x, y, kW);
  const uint32_t prim = plain.right.plane(planes::primid).u32()[i];
  const float depth = plain.right.plane(planes::depth).f32()[i];
  const dvec3 projected = prim == kNoPrimitive ? left.project(left.origin + right.ray_direction(x + 0.5, y + 0.5))
                                               : left.project(right.unproject(x + 0.5, y + 0.5, depth));
  unsure = std::fabs(projected.x) < 1e-3 || std::fabs(projected.x - kW) < 1e-3;
  if (projected.x < 0.0 || projected.x >= kW || projected.y < 0.0 || projected.y >= kH ||
      (prim != kNoPrimitive && projected.z <= left.znear))
    return Disocclusion::outside_frustum;
  left_pixel = ivec2(static_cast<int>(projected.x), static_cast<int>(projected.y));
  const size_t j = index_of(left_pixel.x, left_pixel.y, kW);
  const uint32_t left_prim = plain.left.plane(planes::primid).u32()[j];
  if (prim == kNoPrimitive) return left_prim == kNoPrimitive ? Disocclusion::visible : Disocclusion::hidden;
  if (left_prim == prim || left_prim == kNoPrimitive) return Disocclusion::visible;
  return plain.left.plane(planes::depth).f32()[j] < 0.98 * projected.z ? Disocclusion::hidden : Disocclusion::visible;
}

TEST(TrueDisocclusions, BoxWallHolesLieBesideTheBoxAndAtTheBorders) {
  const Scene scene = test::load_builtin("box-wall");
  const RenderScene rs(scene);
  const StereoRig rig = test::rig_at(scene, kW, kH);
  const StereoResult plain = test::render_with("plain-rt", rs, rig);
  const TrueDisocclusions truth = truth_for(rs, rig, Executor());
  EXPECT_GT(truth.outside_frustum, 0u);
  EXPECT_GT(truth.hidden, 0u);
  expect_counts_match_mask(truth);
  const std::vector<int> meshes = mesh_map(rs, plain.right);
  const int box = mesh_named(scene, "box"), band = disparity_band(rig, plain.right) + 1;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const Disocclusion k = kind_at(truth, index_of(x, y, kW));
      if (k == Disocclusion::outside_frustum) {
        EXPECT_TRUE(x < band || x >= kW - band) << "outside the left frustum away from the borders at " << x << ", " << y;
      }
      if (k != Disocclusion::hidden) continue;
      // Revealed background lies right of the box: walking left over disoccluded pixels ends on the box.
      int xx = x;
      while (xx >= 0 && truth.mask[index_of(xx, y, kW)] != 0) --xx;
      EXPECT_TRUE(xx >= 0 && meshes[index_of(xx, y, kW)] == box && x - xx <= band)
          << "hidden pixel (" << x << ", " << y << ") is not just right of the box";
    }
  std::printf("box-wall: %llu outside the left frustum, %llu hidden (disparity band %d px)\n",
              static_cast<unsigned long long>(truth.outside_frustum), static_cast<unsigned long long>(truth.hidden), band);
}

TEST(TrueDisocclusions, BoxWallAgreesWithALeftEyeLookupAwayFromSilhouettes) {
  const Scene scene = test::load_builtin("box-wall");
  const RenderScene rs(scene);
  const StereoRig rig = test::rig_at(scene, kW, kH);
  const StereoResult plain = test::render_with("plain-rt", rs, rig);
  const TrueDisocclusions truth = truth_for(rs, rig, Executor());
  const std::vector<int> right_meshes = mesh_map(rs, plain.right), left_meshes = mesh_map(rs, plain.left);
  size_t near_edges = 0, unexplained = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      ivec2 lp(-1);
      bool unsure = false;
      const Disocclusion expected = left_lookup(rig, plain, x, y, lp, unsure);
      const Disocclusion got = kind_at(truth, index_of(x, y, kW));
      if (got == expected) continue;
      const bool excused = unsure || near_silhouette(right_meshes, x, y) ||
                           (lp.x >= 0 && near_silhouette(left_meshes, lp.x, lp.y));
      if (excused) {
        ++near_edges;
      } else if (++unexplained <= 5) {
        ADD_FAILURE() << "pixel (" << x << ", " << y << "): mask " << int(got) << ", left-eye lookup " << int(expected);
      }
    }
  EXPECT_EQ(unexplained, 0u);
  std::printf("box-wall: mask and left-eye lookup differ on %zu pixels, all within 1 px of a silhouette\n", near_edges);
}

// ---------------------------------------------------------------------------------------------
// (c) and (d): the same rays as plain-rt, and the same results at any thread count.

TEST(VisibleSurfaces, EqualPlainRtDepthAndPrimitiveIdsBitForBit) {
  for (const char* name : {"box-wall", "slanted-plane", "spheres"}) {
    SCOPED_TRACE(name);
    const Scene scene = test::load_builtin(name);
    const RenderScene rs(scene);
    const StereoRig rig = test::rig_at(scene, kW, kH);
    const StereoResult plain = test::render_with("plain-rt", rs, rig);
    for (Eye e : {Eye::left, Eye::right}) {
      const Image& image = e == Eye::left ? plain.left : plain.right;
      const VisibleSurfaces vs = trace_visible_surfaces(rs, rig.eye(e), Executor());
      ASSERT_EQ(vs.width, kW);
      ASSERT_EQ(vs.height, kH);
      const std::span<const uint32_t> prim = image.plane(planes::primid).u32();
      const std::span<const float> depth = image.plane(planes::depth).f32();
      ASSERT_EQ(vs.prim.size(), prim.size());
      ASSERT_EQ(vs.depth.size(), depth.size());
      EXPECT_TRUE(std::equal(prim.begin(), prim.end(), vs.prim.begin())) << eye_name(e);
      EXPECT_EQ(std::memcmp(depth.data(), vs.depth.data(), depth.size_bytes()), 0) << eye_name(e);
    }
  }
}

TEST(TrueDisocclusions, IdenticalWithOneAndTwoThreads) {
  for (const char* name : {"box-wall", "spheres"}) {
    SCOPED_TRACE(name);
    const Scene scene = test::load_builtin(name);
    const RenderScene rs(scene);
    const StereoRig rig = test::rig_at(scene, 200, 120);
    const Executor one(1), two(2);
    const VisibleSurfaces a = trace_visible_surfaces(rs, rig.eye(Eye::right), one);
    const VisibleSurfaces b = trace_visible_surfaces(rs, rig.eye(Eye::right), two);
    EXPECT_TRUE(a.prim == b.prim);
    EXPECT_EQ(std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * sizeof(float)), 0);
    const TrueDisocclusions ta = true_disocclusions(rs, rig, a, one), tb = true_disocclusions(rs, rig, b, two);
    EXPECT_TRUE(ta.mask == tb.mask);
    EXPECT_EQ(ta.outside_frustum, tb.outside_frustum);
    EXPECT_EQ(ta.hidden, tb.hidden);
    EXPECT_GT(ta.count(), 0u);
  }
}

TEST(TrueDisocclusions, RefusesSurfacesOfAnotherSize) {
  const Scene scene = test::load_builtin("lit-plane");
  const RenderScene rs(scene);
  const Executor executor;
  const VisibleSurfaces small = trace_visible_surfaces(rs, test::rig_at(scene, 64, 36).eye(Eye::right), executor);
  EXPECT_THROW((void)true_disocclusions(rs, test::rig_at(scene, 65, 36), small, executor), InputError);
}

// ---------------------------------------------------------------------------------------------
// (e) Scores, hole masks from source tags, the overlay.

TEST(ScoreHoles, CountsAndRatiosOnHandMadeMasks) {
  const std::vector<uint8_t> holes{1, 1, 0, 0, 1, 0}, truth{1, 0, 1, 0, 2, 0};
  const HoleScores s = score_holes(holes, truth);
  EXPECT_EQ(s.hole_pixels, 3u);
  EXPECT_EQ(s.true_pixels, 3u);
  EXPECT_EQ(s.true_positives, 2u);
  EXPECT_DOUBLE_EQ(s.recall, 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(s.precision, 2.0 / 3.0);

  const std::vector<uint8_t> none(6, 0), all(6, 1);
  const HoleScores empty = score_holes(none, none);
  EXPECT_TRUE(std::isnan(empty.recall)) << "nothing disoccluded: recall undefined";
  EXPECT_TRUE(std::isnan(empty.precision)) << "nothing flagged: precision undefined, not perfect";
  const HoleScores missed = score_holes(none, truth);
  EXPECT_EQ(missed.recall, 0.0);
  EXPECT_TRUE(std::isnan(missed.precision));
  const HoleScores flag_all = score_holes(all, truth);
  EXPECT_EQ(flag_all.recall, 1.0);
  EXPECT_DOUBLE_EQ(flag_all.precision, 0.5);

  EXPECT_THROW((void)score_holes(std::vector<uint8_t>(5, 0), truth), InputError);

  // What is scored is every pixel not reprojected: rendered for the eye, filled, or a hole.
  Image tagged(5, 1);
  uint32_t* tag = tagged.add_plane(planes::source).data_u32();
  const Source tags[5] = {Source::reprojected, Source::traced, Source::rasterized, Source::hole,
                          Source::reshaded_traced};
  for (int i = 0; i < 5; ++i) tag[i] = static_cast<uint32_t>(tags[i]);
  EXPECT_EQ(not_reprojected_mask(tagged), (std::vector<uint8_t>{0, 1, 1, 1, 1}));
  EXPECT_EQ(hole_mask_from_sources(tagged), (std::vector<uint8_t>{0, 0, 0, 1, 1}));
}

/// A 7x1 image whose pixels carry each source tag once, in enum order, and radiance 2.0 (to be clamped).
Image image_with_every_source() {
  Image image(static_cast<int>(kSourceCount), 1);
  image.add_plane(planes::rgb).fill(2.0f);
  Plane& source = image.add_plane(planes::source);
  for (uint32_t s = 0; s < kSourceCount; ++s) source.at_u32(static_cast<int>(s), 0) = s;
  return image;
}

TEST(HoleMask, FromSourceTags) {
  const Image image = image_with_every_source();
  // hole, rasterized, traced, reprojected, reshaded_traced, reshaded_raster, inpainted
  EXPECT_EQ(hole_mask_from_sources(image), (std::vector<uint8_t>{1, 0, 0, 0, 1, 1, 1}));
  EXPECT_TRUE(has_reprojected_pixels(image));
  Image traced = image;
  traced.plane(planes::source).fill(static_cast<uint32_t>(Source::traced));
  EXPECT_FALSE(has_reprojected_pixels(traced));
  Image no_source(3, 1);
  EXPECT_THROW((void)hole_mask_from_sources(no_source), InputError);
}

TEST(HoleOverlay, TintsFoundMissedAndWastedPixels) {
  const Image image = image_with_every_source();
  const std::vector<uint8_t> holes{1, 0, 1, 0, 0, 0, 0}, truth{1, 1, 0, 0, 0, 0, 0};
  const Image overlay = hole_overlay(image, holes, truth);
  ASSERT_TRUE(overlay.has_plane(planes::rgb));
  const auto near = [](const std::array<float, 3>& a, const std::array<float, 3>& b) {
    return std::fabs(a[0] - b[0]) < 1e-6f && std::fabs(a[1] - b[1]) < 1e-6f && std::fabs(a[2] - b[2]) < 1e-6f;
  };
  // Radiance 2 clamps to 1: 25 % of it under a 75 % tint, 30 % of it untinted.
  EXPECT_TRUE(near(overlay.rgb_at(0, 0), {0.25f, 1.0f, 0.25f})) << "found: green";
  EXPECT_TRUE(near(overlay.rgb_at(1, 0), {1.0f, 0.25f, 0.25f})) << "missed: red";
  EXPECT_TRUE(near(overlay.rgb_at(2, 0), {0.25f, 0.25f + 0.75f * 0.35f, 1.0f})) << "wasted: blue";
  EXPECT_TRUE(near(overlay.rgb_at(3, 0), {0.3f, 0.3f, 0.3f})) << "neither: darkened";
  EXPECT_THROW((void)hole_overlay(image, std::vector<uint8_t>(6, 0), truth), InputError);
}

/// A fake reprojecting pipeline on box-wall: plain-rt's right eye tagged reprojected, with the
/// true disocclusions shifted one pixel to the right tagged as holes, so that some are found,
/// some missed and some flagged in vain.
TEST(HoleAnalysis, ScoresAFakeHoleMaskOnBoxWall) {
  const Scene scene = test::load_builtin("box-wall");
  const RenderScene rs(scene);
  const StereoRig rig = test::rig_at(scene, kW, kH);
  const Executor executor;
  const StereoResult plain = test::render_with("plain-rt", rs, rig);
  EXPECT_FALSE(analyze_holes(rs, rig, plain.right, executor)) << "nothing reprojected: no analysis";

  const TrueDisocclusions truth = truth_for(rs, rig, executor);
  Image fake = plain.right;
  Plane& source = fake.plane(planes::source);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const bool shifted = x > 0 && truth.mask[index_of(x - 1, y, kW)] != 0;
      source.at_u32(x, y) = static_cast<uint32_t>(shifted ? Source::hole : Source::reprojected);
    }
  const std::optional<HoleAnalysis> a = analyze_holes(rs, rig, fake, executor);
  ASSERT_TRUE(a);
  EXPECT_TRUE(a->truth.mask == truth.mask);
  // Only hole and reprojected tags: the pixels not reprojected are the hole mask.
  EXPECT_EQ(not_reprojected_mask(fake), hole_mask_from_sources(fake));
  const HoleScores expected = score_holes(not_reprojected_mask(fake), truth.mask);
  EXPECT_EQ(a->scores.hole_pixels, expected.hole_pixels);
  EXPECT_EQ(a->scores.true_positives, expected.true_positives);
  EXPECT_GT(a->scores.true_positives, 0u);
  EXPECT_LT(a->scores.recall, 1.0);
  EXPECT_LT(a->scores.precision, 1.0);
  EXPECT_GT(a->seconds, 0.0);
  EXPECT_EQ(a->overlay.width(), kW);
  test::ScratchDir dir;
  io::write_png_preview(dir / "box-wall_holes.png", a->overlay);  // kept for inspection if the test fails
  std::printf("box-wall fake mask: recall %.3f, precision %.3f (%llu flagged, %llu true)\n", a->scores.recall,
              a->scores.precision, static_cast<unsigned long long>(a->scores.hole_pixels),
              static_cast<unsigned long long>(a->scores.true_pixels));
}

}  // namespace
}  // namespace sb
