// Al-Hagri's reprojecting ray tracers: the scan-line pair and the parallel pair agree with each
// other, writes per right pixel stay within Lemma 1's bound, the right eyes of dragon and spheres
// at 600x600 and e = 15 px hold measured PSNR floors against plain-rt (below 38 dB: reasons at
// psnr_floor) with every traced pixel bit-identical to it, and a thin pole's gap is retraced rather
// than smeared.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>

#include "renderer/error.hpp"
#include "renderer/scene.hpp"
#include "renderer/stages/pixel_reprojection.hpp"
#include "renderer/stages/primary_rays.hpp"
#include "support/image_metrics.hpp"
#include "support/render_support.hpp"
#include "support/scene_lists.hpp"

namespace sb {
namespace {

/// A scene's default rig at w x h with the interaxial given as a max disparity in pixels.
StereoRig rig_with_disparity(const Scene& scene, int w, int h, double max_disparity_px) {
  RigOverrides o;
  o.width = w;
  o.height = h;
  o.max_disparity_px = max_disparity_px;
  return resolve_rig(scene, o);
}

bool planes_equal(const Image& a, const Image& b) {
  for (const Plane& p : a.planes())
    if (!(p == b.plane(p.name()))) return false;
  return true;
}

/// Right pixels tagged `tag` whose planes (the source tag aside) differ from `truth`'s.
size_t differing_pixels(const Image& image, const Image& truth, Source tag) {
  const uint32_t* source = image.data_u32(planes::source);
  size_t differ = 0;
  for (size_t i = 0; i < image.pixel_count(); ++i) {
    if (source[i] != static_cast<uint32_t>(tag)) continue;
    for (const Plane& p : image.planes()) {
      if (p.name() == planes::source) continue;
      const Plane& q = truth.plane(p.name());
      const size_t n = static_cast<size_t>(p.channels());
      const bool same = p.type() == PlaneType::f32
                            ? std::memcmp(p.data_f32() + i * n, q.data_f32() + i * n, n * sizeof(float)) == 0
                            : std::memcmp(p.data_u32() + i * n, q.data_u32() + i * n, n * sizeof(uint32_t)) == 0;
      if (!same) {
        ++differ;
        break;
      }
    }
  }
  return differ;
}

class PairAgreement : public ::testing::TestWithParam<std::string> {};

TEST_P(PairAgreement, ScanlineAndParallelVariantsGiveIdenticalRightEyes) {
  const Scene scene = test::load_builtin(GetParam());
  const RenderScene prepared(scene);
  const StereoRig rig = rig_with_disparity(scene, 240, 180, 15.0);
  const StereoResult adelson = test::render_with("rt-adelson", prepared, rig, 1);
  const StereoResult es_isler = test::render_with("rt-es-isler", prepared, rig, 2);
  EXPECT_TRUE(planes_equal(adelson.right, es_isler.right)) << GetParam();
  EXPECT_TRUE(planes_equal(adelson.left, es_isler.left)) << GetParam();
  const StereoResult buffer = test::render_with("rt-buffer", prepared, rig, 2);
  const StereoResult atomic = test::render_with("rt-atomic", prepared, rig, 2);
  ASSERT_EQ(buffer.counters.get("buffer_collisions"), 0u) << GetParam() << ": Lemma 1's bound exceeded t";
  EXPECT_TRUE(planes_equal(buffer.right, atomic.right)) << GetParam();
  // Lemma 1: writes per right pixel stay within f e / z_min (+1 for rounding).
  for (const StereoResult* r : {&adelson, &atomic}) {
    EXPECT_GT(r->counters.get("writes_bound"), 0u);
    EXPECT_LE(r->counters.get("writes_max"), r->counters.get("writes_bound")) << GetParam();
  }
}

INSTANTIATE_TEST_SUITE_P(AnalyticScenes, PairAgreement, ::testing::ValuesIn(test::analytic_scenes()), test::param_name);

TEST(Lemma1Bound, IsFOverZTimesEAndSaturatesWhereItDoesNotFit) {
  const Scene scene = test::load_builtin("box-wall");
  RigOverrides o;
  o.width = 160;
  o.height = 90;
  const StereoRig rig = resolve_rig(scene, o);
  const double f_e = rig.focal_px() * rig.params().interaxial;
  EXPECT_EQ(lemma1_bound(rig, 2.0), static_cast<uint64_t>(std::ceil(f_e / 2.0)) + 1);
  // A field of view of 1e-8 degrees (f some 5e11 px, near the largest a rig may have) and a 1e9 m
  // interaxial converged 1e15 m away: f e / z is about 9e19 px at 6 m, beyond 64 bits (it once
  // wrapped to 1).
  o.vfov = 1e-8 * 3.14159265358979 / 180.0;
  o.interaxial = 1e9;
  o.convergence = 1e15;
  const StereoRig narrow = resolve_rig(scene, o);
  ASSERT_GT(narrow.focal_px() * narrow.params().interaxial / 6.0, 2e19);
  EXPECT_EQ(lemma1_bound(narrow, 6.0), uint64_t{9'000'000'000'000'000'000u});
}

/// The right eye's PSNR against plain-rt that a scene must reach at 600x600, e = 15 px. The aim is
/// 38 dB; measured below it:
/// - dragon 36.32 dB (scan-line pair) and 36.56 dB (parallel pair); spheres 31.79 and 32.17 dB. A
///   reprojected pixel carries the colour of a left pixel centre that lands up to half a pixel from
///   the right pixel centre (the thesis rounds x, §2.2.2): on the dragon's scales and the spheres'
///   facets and shadow edges that is another surface sample. And a reprojection that lands just
///   past a silhouette is not caught by the restricted ray, which only looks for occluders in front.
/// - With confirm=true (a second short ray requiring the surface to be there; not in the thesis):
///   37.80 dB on dragon, 35.99 dB on spheres.
/// - The rounding alone bounds what any validation can reach: of rt-atomic's squared error, the
///   reprojected pixels that do show the right surface (depth within 1 %, same albedo as plain-rt's
///   pixel) carry 41.5 % on spheres and 74.3 % on dragon; were every other pixel exact, the right
///   eyes would measure 35.99 dB and 37.85 dB (8-bit sRGB). confirm=true reaches that bound on
///   spheres.
/// - Spheres lost 0.6 dB (1.6 dB confirmed), dragon 0.15 dB, when the shading normal was turned to the viewer
///   (renderer/shading.cpp, so that Blender and POV-Ray shade like us): a silhouette pixel of a
///   smooth sphere can be shaded differently by the two eyes, and the reprojection keeps the left's.
struct PsnrFloor {
  double scanline;
  double parallel;
  double confirmed;
};

PsnrFloor psnr_floor(const std::string& scene) {
  return scene == "dragon" ? PsnrFloor{36.0, 36.3, 37.5} : PsnrFloor{31.5, 31.9, 35.7};
}

class AgainstPlainRt : public ::testing::TestWithParam<std::string> {};

TEST_P(AgainstPlainRt, RightEyeAgainstPlainRtAndTracedPixelsAreExact) {
  const Scene scene = test::load_builtin(GetParam());
  const RenderScene prepared(scene);
  const StereoRig rig = rig_with_disparity(scene, 600, 600, 15.0);
  const StereoResult truth = test::render_with("plain-rt", prepared, rig);
  const PsnrFloor floor = psnr_floor(GetParam());
  for (const std::string pipeline : {"rt-adelson", "rt-es-isler", "rt-buffer", "rt-atomic", "rt-atomic+confirm"}) {
    const bool confirm = pipeline == "rt-atomic+confirm";
    const StereoResult r = confirm ? test::render_with("rt-atomic", prepared, rig, 0, {{"confirm", "true"}})
                                   : test::render_with(pipeline, prepared, rig);
    EXPECT_TRUE(planes_equal(r.left, truth.left)) << pipeline << " left eye on " << GetParam();
    const double psnr = test::psnr_srgb8(r.right, truth.right);
    const bool scanline = pipeline == "rt-adelson" || pipeline == "rt-es-isler";
    const double min_psnr = confirm ? floor.confirmed : scanline ? floor.scanline : floor.parallel;
    EXPECT_GE(psnr, min_psnr) << pipeline << " on " << GetParam();
    EXPECT_EQ(differing_pixels(r.right, truth.right, Source::reshaded_traced), 0u) << pipeline << " on " << GetParam();
    EXPECT_LE(r.counters.get("writes_max"), r.counters.get("writes_bound")) << pipeline;
    std::printf("%-8s %-12s right eye %.2f dB, traced %llu, reprojected %llu, bad %llu, missed %llu\n",
                GetParam().c_str(), pipeline.c_str(), psnr,
                static_cast<unsigned long long>(r.counters.get("pixels_traced_right")),
                static_cast<unsigned long long>(r.counters.get("pixels_reprojected_right")),
                static_cast<unsigned long long>(r.counters.get("bad")),
                static_cast<unsigned long long>(r.counters.get("missed")));
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, AgainstPlainRt, ::testing::Values("dragon", "spheres"), test::param_name);

TEST(ThinPole, GapBesideThePoleIsRetracedNotSmeared) {
  const Scene scene = test::load_builtin("thin-pole");
  const RenderScene prepared(scene);
  const StereoRig rig = rig_with_disparity(scene, 480, 270, 20.0);
  const StereoResult truth = test::render_with("plain-rt", prepared, rig);
  const auto is_pole = [&](uint32_t prim) {
    if (prim == kNoPrimitive) return false;
    return scene.meshes[prepared.geometry().locate(prim).first].name == "pole";
  };
  const uint32_t* expected = truth.right.data_u32(planes::primid);
  for (const std::string pipeline : {"rt-adelson", "rt-es-isler", "rt-buffer", "rt-atomic"}) {
    const StereoResult r = test::render_with(pipeline, prepared, rig);
    EXPECT_GT(r.counters.get("bad") + r.counters.get("missed"), 0u) << pipeline;
    const uint32_t* prim = r.right.data_u32(planes::primid);
    size_t smeared = 0, pole = 0;
    for (size_t i = 0; i < r.right.pixel_count(); ++i) {
      pole += is_pole(expected[i]) ? 1 : 0;
      smeared += is_pole(prim[i]) != is_pole(expected[i]) ? 1 : 0;
    }
    EXPECT_GT(pole, 0u);
    EXPECT_EQ(smeared, 0u) << pipeline << ": pixels show the pole where plain-rt shows what lies behind it, or not";
  }
}

TEST(ScanlineReprojection, AHitLeftOfTheImageOpensTheGapUpToTheNextLanding) {
  // spheres at 400x400 and 100 px of disparity, right row 106: left pixels 7..18 (a sphere at
  // 10.8 m) land on columns 29..39; left pixels 65..116 (a sphere at 3.5 m) land left of the
  // image, and 117 lands on 135. Algorithm 1 moves oldR with every hit inside w, the ones left of
  // the image too, so that landing opens the gap 0..134, and the farther sphere at 29..39 is
  // traced again: the right eye sees the nearer sphere (4.8 m) there. Passing over the hits left
  // of the image left the farther sphere in place (287 such pixels in this image).
  const Scene scene = test::load_builtin("spheres");
  const RenderScene prepared(scene);
  const StereoRig rig = rig_with_disparity(scene, 400, 400, 100.0);
  const StereoResult truth = test::render_with("plain-rt", prepared, rig);
  const float* z_truth = truth.right.data_f32(planes::depth);
  for (const std::string pipeline : {"rt-adelson", "rt-es-isler"}) {
    const StereoResult r = test::render_with(pipeline, prepared, rig);
    const float* z = r.right.data_f32(planes::depth);
    size_t behind = 0;
    for (int x = 29; x <= 39; ++x) {
      const size_t i = 106 * 400 + static_cast<size_t>(x);
      behind += z[i] > 1.02f * z_truth[i] ? 1 : 0;
    }
    EXPECT_EQ(behind, 0u) << pipeline << ": pixels of row 106 show a surface behind the one the right eye sees";
  }
}

TEST(ScanlineCounts, ABadGapLiesBetweenReprojectionsOfAdjacentPixels) {
  // At a disparity of a thousandth of a pixel every surface pixel reprojects onto its own column:
  // no two adjacent pixels land apart, so nothing is a bad gap. The sky between spheres is not
  // reprojected; its columns are missed. (They were counted bad: the gap test bridged the sky,
  // 3600 of 160x90's pixels.) At 0.3 px rounding opens real gaps of one column.
  const Scene scene = test::load_builtin("spheres");
  const RenderScene prepared(scene);
  for (const std::string pipeline : {"rt-adelson", "rt-es-isler"}) {
    const StereoResult still = test::render_with(pipeline, prepared, rig_with_disparity(scene, 160, 90, 0.001));
    EXPECT_EQ(still.counters.get("bad"), 0u) << pipeline;
    EXPECT_GT(still.counters.get("missed"), 1000u) << pipeline << ": the sky is missed";
    const StereoResult moving = test::render_with(pipeline, prepared, rig_with_disparity(scene, 160, 90, 0.3));
    EXPECT_GT(moving.counters.get("bad"), 0u) << pipeline;
    EXPECT_LT(moving.counters.get("bad"), 200u) << pipeline;
  }
}

TEST(PrimaryRays, SameBitsAsPrimaryRayAndDepthRaysEndAtTheirDepth) {
  // Off-axis eyes of an odd-sized image.
  const Scene scene = test::load_builtin("spheres");
  const StereoRig rig = rig_with_disparity(scene, 203, 117, 15.0);
  for (const Eye e : {Eye::left, Eye::right}) {
    const EyeCamera eye = rig.eye(e);
    const PrimaryRays whole(eye);
    size_t differ = 0;
    for (int y = 0; y < eye.height; ++y)
      for (int x = 0; x < eye.width; ++x) {
        const RayQuery a = primary_ray(eye, x, y);
        const RayQuery b = whole(x, y);
        differ += std::memcmp(&a.dir, &b.dir, sizeof a.dir) != 0 || std::memcmp(&a.origin, &b.origin, sizeof a.origin) != 0;
        // The depth ray points the same way and its parameter is the linear depth.
        const RayQuery d = whole.depth_ray(x, y);
        EXPECT_NEAR(glm::dot(d.dir, vec3(-eye.back)), 1.0f, 1e-6f);
        EXPECT_NEAR(glm::dot(glm::normalize(d.dir), a.dir), 1.0f, 1e-6f);
      }
    EXPECT_EQ(differ, 0u) << "pixels whose precomputed ray differs from primary_ray";
  }
}

TEST(PixelReprojection, BadOptionsAreRejected) {
  const Scene scene = test::load_builtin("lit-plane");
  const RenderScene prepared(scene);
  const StereoRig rig = test::rig_at(scene, 64, 36);
  EXPECT_THROW((void)test::render_with("rt-atomic", prepared, rig, 1, {{"margin", "1"}}), InputError);
  EXPECT_THROW((void)test::render_with("rt-buffer", prepared, rig, 1, {{"margin", "-0.1"}}), InputError);
  // A confirming ray in an empty segment finds no surface: every reprojected pixel was traced again.
  for (const char* pipeline : {"rt-atomic", "rt-buffer"}) {
    try {
      (void)test::render_with(pipeline, prepared, rig, 1, {{"margin", "0"}, {"confirm", "true"}});
      ADD_FAILURE() << pipeline << ": confirm=true with margin=0 was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("confirm=true needs margin > 0"), std::string::npos) << e.what();
    }
    EXPECT_NO_THROW((void)test::render_with(pipeline, prepared, rig, 1, {{"margin", "0"}}));
  }
  EXPECT_THROW((void)test::render_with("rt-buffer", prepared, rig, 1, {{"depth", "-1"}}), InputError);
  EXPECT_THROW((void)test::render_with("rt-buffer", prepared, rig, 1, {{"depth", "5000"}}), InputError);
  // The default depth 2e for a disparity the rig accepts (up to 1e6 px) but the buffer cannot
  // hold: rejected before it is converted to an int.
  try {
    (void)test::render_with("rt-buffer", prepared, rig_with_disparity(scene, 64, 36, 1e5), 1, {});
    ADD_FAILURE() << "a 2e5-entry buffer depth was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("exceeds 4096"), std::string::npos) << e.what();
  }
  // An absurd one (it overflowed the int depth to 1 once) is refused by the rig itself.
  EXPECT_THROW((void)rig_with_disparity(scene, 64, 36, 1.2e10), InputError);
}

}  // namespace
}  // namespace sb
