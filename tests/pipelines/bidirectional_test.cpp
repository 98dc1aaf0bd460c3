// Kim's bidirectional warping on atrium at 960x540: the right eye against plain-raster's (the
// 2-pass reference) at convergence 6 m, 2 m and 0.3 m, and its ordering against the two baselines,
// as published and with the z-test of Kim's §5; what the z-test guarantees of each eye's own pixels.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <tuple>

#include "renderer/error.hpp"

#include "support/image_metrics.hpp"
#include "support/render_support.hpp"

namespace sb {
namespace {

struct Quality {
  double psnr;
  double ssim;
};

Quality right_eye_quality(const std::string& pipeline, const RenderScene& scene, const StereoRig& rig,
                          const Image& reference, const std::map<std::string, std::string>& options = {}) {
  const StereoResult r = test::render_with(pipeline, scene, rig, 0, options);
  return {test::psnr_srgb8(r.right, reference), test::ssim_srgb8(r.right, reference)};
}

const std::map<std::string, std::string> kZtest{{"occlusion", "ztest"}};

/// Pixels of `image` tagged `rasterized` whose radiance differs from `reference`'s, and how many
/// are tagged so.
std::pair<size_t, size_t> rasterized_mismatches(const Image& image, const Image& reference) {
  const float* a = image.data_f32(planes::rgb);
  const float* b = reference.data_f32(planes::rgb);
  const uint32_t* tag = image.data_u32(planes::source);
  size_t differ = 0, rasterized = 0;
  for (size_t i = 0; i < image.pixel_count(); ++i) {
    if (tag[i] != static_cast<uint32_t>(Source::rasterized)) continue;
    ++rasterized;
    if (a[3 * i] != b[3 * i] || a[3 * i + 1] != b[3 * i + 1] || a[3 * i + 2] != b[3 * i + 2]) ++differ;
  }
  return {differ, rasterized};
}

class FocalDistance : public ::testing::TestWithParam<double> {};

/// SSIM floors of bidir-warp's right eye as published (occlusion=none), just under the values
/// measured here; the aim is 0.99 (the thesis: 0.994, 0.998, 0.995), which the z-test reaches
/// (below). Most of what it loses is Kim's Fig. 14: each eye's own pixels behind triangles sent to
/// the other eye (replacing only its own pixels by plain-raster's raised SSIM from 0.9674 to 0.9804
/// at 6 m). The rest: pixels moved to the nearest pixel centre on textured stone and cloth (no
/// resampling), silhouettes of warped surfaces off by up to half a pixel, and disocclusions wider
/// than the 2-px crack fill, which show the background colour. Linear resampling along the rows was
/// tried: it lowers the reprojected pixels' MSE (28.4 to 22.5 at 6 m) but blurs them, and SSIM
/// falls (0.9597 to 0.9553 there), so the warp moves whole pixels as Kim's does.
double ssim_floor(double convergence) {
  // Measured with crack_depth 1.01 (far surfaces showing through cracks are filled): 0.9675 at
  // 6 m, 0.9606 at 2 m, 0.9561 at 0.3 m (without: 0.9651, 0.9597, 0.9494).
  static const std::map<double, double> measured{{6.0, 0.967}, {2.0, 0.960}, {0.3, 0.955}};
  return measured.at(convergence);
}

TEST_P(FocalDistance, BidirWarpAgainstTwoPassAndBaselines) {
  const Scene scene = test::load_builtin("atrium");
  const RenderScene prepared(scene);
  const StereoRig rig = test::rig_at(scene, 960, 540, GetParam());
  const StereoResult reference = test::render_with("plain-raster", prepared, rig);
  const Quality bidir = right_eye_quality("bidir-warp", prepared, rig, reference.right);
  const Quality fw = right_eye_quality("fw-warp", prepared, rig, reference.right);
  const Quality bw = right_eye_quality("bw-warp", prepared, rig, reference.right);
  std::printf("atrium c = %.1f m: bidir-warp %.2f dB / %.4f, fw-warp %.2f dB / %.4f, bw-warp %.2f dB / %.4f\n",
              GetParam(), bidir.psnr, bidir.ssim, fw.psnr, fw.ssim, bw.psnr, bw.ssim);
  EXPECT_GE(bidir.ssim, ssim_floor(GetParam()));
  EXPECT_GT(bidir.ssim, fw.ssim);
  // At 6 m the disparities are small and few holes open; bw-warp's interpolated lookup then beats
  // the row warp's move to the nearest pixel centre (measured 0.9707 against 0.9675). From 2 m on,
  // bidir-warp is ahead of both, far ahead at 0.3 m (0.9561 against 0.8174 and 0.8068).
  if (GetParam() < 6.0) {
    EXPECT_GT(bidir.ssim, bw.ssim);
  }
  // With the z-test of Kim's §5 the aim holds: measured 0.9947, 0.9947 and 0.9932, ahead of both
  // baselines at every distance.
  const Quality ztest = right_eye_quality("bidir-warp", prepared, rig, reference.right, kZtest);
  std::printf("atrium c = %.1f m: bidir-warp occlusion=ztest %.2f dB / %.4f\n", GetParam(), ztest.psnr, ztest.ssim);
  EXPECT_GE(ztest.ssim, 0.99);
  EXPECT_GT(ztest.ssim, bw.ssim);
  EXPECT_GT(ztest.ssim, fw.ssim);
}

INSTANTIATE_TEST_SUITE_P(Atrium, FocalDistance, ::testing::Values(6.0, 2.0, 0.3));

/// Kim's Fig. 14: without occlusion, a partial image shows its own share where a triangle sent to
/// the other eye is nearer, and the other eye, which cannot see that triangle there, does not
/// bring it back. Under the z-test every pixel an eye renders itself is the nearest surface, the
/// same as plain-raster's pixel bit for bit, in both eyes, and the image does not depend on the
/// thread count.
TEST(BidirZtest, OwnPixelsAreTheNearestSurface) {
  const Scene scene = test::load_builtin("atrium");
  const RenderScene prepared(scene);
  const StereoRig rig = test::rig_at(scene, 480, 270, 2.0);
  const StereoResult reference = test::render_with("plain-raster", prepared, rig, 2);
  const StereoResult kim = test::render_with("bidir-warp", prepared, rig, 2);
  const auto [kim_differ, kim_rasterized] = rasterized_mismatches(kim.right, reference.right);
  std::printf("occlusion=none: %zu of %zu own right-eye pixels differ from plain-raster's\n", kim_differ,
              kim_rasterized);
  EXPECT_GT(kim_differ, 100u);

  const StereoResult z = test::render_with("bidir-warp", prepared, rig, 2, kZtest);
  for (const auto& [eye, ref, name] :
       {std::tuple{&z.left, &reference.left, "left"}, std::tuple{&z.right, &reference.right, "right"}}) {
    const auto [differ, rasterized] = rasterized_mismatches(*eye, *ref);
    EXPECT_EQ(differ, 0u) << name;
    EXPECT_GT(rasterized, eye->pixel_count() / 3) << name;
  }
  // Some pixels are the other eye's triangles hidden from it, rendered here.
  EXPECT_GT(z.counters.get("pixels_hidden_in_other_right"), 0u);
  EXPECT_GT(z.counters.get("pixels_hidden_in_other_left"), 0u);
  // Both eyes rasterize the whole scene, and each shades fewer pixels than the image has.
  EXPECT_EQ(z.counters.get("triangles_rasterized_right"), reference.counters.get("triangles_rasterized_right"));
  EXPECT_LT(z.counters.get("pixels_shaded_right"), reference.counters.get("pixels_shaded_right") * 3 / 4);

  const StereoResult one = test::render_with("bidir-warp", prepared, rig, 1, kZtest);
  EXPECT_TRUE(one.right == z.right);
  EXPECT_TRUE(one.left == z.left);
  EXPECT_EQ(one.counters.snapshot(), z.counters.snapshot());
}

TEST(BidirWarpRt, TracesItsCracksSoAVanishingDisparityReproducesTheTruth) {
  // At 0.001 px of disparity nothing moves: the right eye is plain-rt's but for the rasterizer's
  // own pixels (measured 53.63 dB). bidir-warp-rt used to interpolate its 1-2 px hole runs before
  // tracing, and a background gap between two spheres took the spheres' colour (25.22 dB). It now
  // traces them; bidir-warp, Kim's method, still interpolates.
  const Scene scene = test::load_builtin("spheres");
  const RenderScene prepared(scene);
  const StereoRig rig = test::rig_with_disparity(scene, 160, 90, 1e-3);
  const StereoResult truth = test::render_with("plain-rt", prepared, rig, 2);
  const StereoResult traced = test::render_with("bidir-warp-rt", prepared, rig, 2);
  const StereoResult kim = test::render_with("bidir-warp", prepared, rig, 2);
  EXPECT_GT(test::psnr_srgb8(traced.right, truth.right), 50.0);
  EXPECT_EQ(traced.counters.get("pixels_filled_crack"), 0u);
  EXPECT_GT(kim.counters.get("pixels_filled_crack"), 0u);
  EXPECT_EQ(traced.counters.get("pixels_traced_right"), traced.counters.get("hole_pixels"))
      << "every hole, cracks included, is traced";
  // ... so none is left, as its counters say (they kept the crack fill's count of the holes it left).
  const StereoResult wide = test::render_with("bidir-warp-rt", prepared, test::rig_at(scene, 160, 90), 2);
  EXPECT_GT(wide.counters.get("pixels_traced_right"), 0u);
  EXPECT_EQ(wide.counters.get("holes_left"), 0u);
  EXPECT_EQ(wide.counters.get("holes_left_in_left"), 0u);
}

/// The spheres are closed and double-sided, as many exported scenes have them. The redirection culls
/// their back faces all the same (cull_closed, the default): both eyes are bit for bit those of
/// the scene with every material made single-sided. Without it, an eye that rasterizes a sphere's
/// back triangles while the front ones went to the other eye shows the sphere's inside.
TEST(BidirCulling, DoubleSidedClosedMeshesRenderAsSingleSidedOnes) {
  const Scene doubled = test::load_builtin("spheres");
  Scene single = doubled;
  for (Material& m : single.materials) m.double_sided = false;
  const RenderScene a(single), b(doubled);
  const StereoRig rig = test::rig_at(single, 160, 90);
  const StereoResult truth = test::render_with("plain-rt", a, rig, 2);
  for (const std::string pipeline : {"bidir-warp", "bidir-warp-rt"}) {
    const StereoResult published = test::render_with(pipeline, a, rig, 2);
    const StereoResult culled = test::render_with(pipeline, b, rig, 2);
    const StereoResult kept = test::render_with(pipeline, b, rig, 2, {{"cull_closed", "false"}});
    EXPECT_TRUE(culled.right == published.right) << pipeline;
    EXPECT_TRUE(culled.left == published.left) << pipeline;
    EXPECT_EQ(culled.counters.get("meshes_closed_culled"), single.meshes.size()) << pipeline;
    EXPECT_EQ(published.counters.get("meshes_closed_culled"), 0u) << pipeline;
    EXPECT_EQ(culled.counters.get("triangles_culled"), published.counters.get("triangles_culled")) << pipeline;
    EXPECT_EQ(kept.counters.get("triangles_culled"), 0u) << pipeline;
    const double p_culled = test::psnr_srgb8(culled.right, truth.right);
    const double p_kept = test::psnr_srgb8(kept.right, truth.right);
    std::printf("%s: right eye %.2f dB with the back faces culled, %.2f dB without\n", pipeline.c_str(), p_culled,
                p_kept);
    EXPECT_GT(p_culled, p_kept + 1.0) << pipeline;
  }
}

/// box-wall's box through a 1-degree field of view: its front face's triangles reach past both
/// images, the left eye seeing more of their left end and the right eye more of their right end. As
/// published (clipped=one) one eye rasterizes each, and the other eye's border strip shows what
/// lies behind the face there: with the box's back faces culled (cull_closed) nothing, a hole that
/// bidir-warp leaves and bidir-warp-rt traces (78.05 dB); without, the box's inside (19.62 dB
/// for both here and at 320x180, a strip about 18 px wide there). With clipped=both both eyes
/// rasterize them and each eye is plain-raster's in 8 bits.
TEST(BidirClipped, AFaceWiderThanBothImagesIsWholeInBothEyesUnderClippedBoth) {
  const Scene scene = test::load_builtin("box-wall");
  const RenderScene prepared(scene);
  RigOverrides o;
  o.width = 160;
  o.height = 90;
  o.vfov = 1.0 * 3.14159265358979323846 / 180.0;
  const StereoRig rig = resolve_rig(scene, o);
  const StereoResult reference = test::render_with("plain-raster", prepared, rig, 2);
  for (const std::string pipeline : {"bidir-warp", "bidir-warp-rt"}) {
    const StereoResult published = test::render_with(pipeline, prepared, rig, 2);
    const StereoResult inside = test::render_with(pipeline, prepared, rig, 2, {{"cull_closed", "false"}});
    const StereoResult both = test::render_with(pipeline, prepared, rig, 2, {{"clipped", "both"}});
    const double p_published = test::psnr_srgb8(published.right, reference.right);
    const double p_inside = test::psnr_srgb8(inside.right, reference.right);
    const double p_both = test::psnr_srgb8(both.right, reference.right);
    const double l_both = test::psnr_srgb8(both.left, reference.left);
    std::printf("%s: right eye %.2f dB as published (%.2f dB without culling the box), %.2f dB with clipped=both "
                "(left %.2f dB)\n",
                pipeline.c_str(), p_published, p_inside, p_both, l_both);
    EXPECT_LT(p_inside, 30.0) << pipeline;
    if (pipeline == "bidir-warp")
      EXPECT_LT(p_published, 30.0) << "the strip is a hole";
    else
      EXPECT_GT(p_published, 50.0) << "the strip is a hole, traced";
    EXPECT_TRUE(std::isinf(p_both)) << pipeline << " " << p_both;
    EXPECT_TRUE(std::isinf(l_both)) << pipeline << " " << l_both;
    EXPECT_GT(both.counters.get("triangles_to_both"), published.counters.get("triangles_to_both")) << pipeline;
  }
}

TEST(BidirClipped, ClippedOptionIsChecked) {
  const Scene scene = test::load_builtin("lit-plane");
  const RenderScene prepared(scene);
  const StereoRig rig = test::rig_at(scene, 64, 36);
  for (const std::string pipeline : {"bidir-warp", "bidir-warp-rt"}) {
    try {
      (void)test::render_with(pipeline, prepared, rig, 1, {{"clipped", "two"}});
      ADD_FAILURE() << pipeline << " accepted clipped=two";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("clipped=two is not one of one, both"), std::string::npos) << e.what();
    }
  }
}

TEST(BidirZtest, OcclusionOptionIsChecked) {
  const Scene scene = test::load_builtin("lit-plane");
  const RenderScene prepared(scene);
  const StereoRig rig = test::rig_at(scene, 64, 36);
  for (const std::string pipeline : {"bidir-warp", "bidir-warp-rt"})
    EXPECT_THROW((void)test::render_with(pipeline, prepared, rig, 1, {{"occlusion", "zbuffer"}}), InputError)
        << pipeline;
}

}  // namespace
}  // namespace sb
