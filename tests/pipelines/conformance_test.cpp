// Every registered pipeline, iterated from the registry: determinism across thread counts and
// both eyes against plain-rt on the analytic scenes within the pipeline's own tolerance; and
// raster/ray-traced visibility agreement on every built-in scene.
#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <string>

#include "renderer/render_scene.hpp"
#include "scenes/generators.hpp"
#include "renderer/io/image_io.hpp"
#include "support/image_metrics.hpp"
#include "support/render_support.hpp"
#include "support/scene_lists.hpp"
#include "support/scratch_dir.hpp"

namespace sb {
namespace {

using test::analytic_scenes;
using test::builtin_scenes;
using test::param_name;
using test::registered_pipelines;

class Conformance : public ::testing::TestWithParam<std::string> {};

TEST_P(Conformance, BothEyesAgreeWithPlainRtOnAnalyticScenes) {
  const Pipeline& p = find_pipeline(GetParam());
  for (const std::string& name : analytic_scenes()) {
    SCOPED_TRACE(name);
    const Scene scene = test::load_builtin(name);
    const RenderScene rs(scene);
    const StereoRig rig = test::rig_at(scene, 320, 180);
    const StereoResult truth = test::render_with("plain-rt", rs, rig);
    const StereoResult r = test::render_with(p.info().name, rs, rig);
    ASSERT_EQ(r.left.width(), 320);
    ASSERT_EQ(r.right.height(), 180);
    const double pl = test::psnr_srgb8(r.left, truth.left), pr = test::psnr_srgb8(r.right, truth.right);
    EXPECT_GE(pl, p.info().min_psnr_left) << p.info().name << " left eye on " << name;
    EXPECT_GE(pr, p.info().min_psnr_right) << p.info().name << " right eye on " << name;
    std::printf("%-14s %-15s left %.2f dB, right %.2f dB\n", p.info().name.c_str(), name.c_str(), pl, pr);
    EXPECT_GT(r.timings.total(), 0.0);
    EXPECT_TRUE(r.counters.snapshot().count("hole_pixels")) << "every pipeline reports hole pixels";
  }
}

TEST_P(Conformance, BitIdenticalWithOneAndTwoThreads) {
  for (const std::string name : {"box-wall", "spheres"}) {
    SCOPED_TRACE(name);
    const Scene scene = test::load_builtin(name);
    const RenderScene rs(scene);
    const StereoRig rig = test::rig_at(scene, 200, 120);
    const StereoResult a = test::render_with(GetParam(), rs, rig, 1);
    const StereoResult b = test::render_with(GetParam(), rs, rig, 2);
    EXPECT_TRUE(a.left == b.left) << GetParam() << " left eye differs between 1 and 2 threads";
    EXPECT_TRUE(a.right == b.right) << GetParam() << " right eye differs between 1 and 2 threads";
  }
}

/// The eye each pipeline's stages serve (bench's per-eye table rests on it), stage by stage as
/// "stage=eye", in the order the stages start. A reprojecting pipeline's right eye is every stage
/// after its left eye's; bidirectional warping shares its work. The parallel scan-lines share
/// theirs too, and report it as rt-adelson's stages, the pass's wall time shared out.
TEST_P(Conformance, StagesSayWhichEyeTheyServe) {
  static const std::map<std::string, std::string> expected = {
      {"plain-raster", "left_gbuffer=left left_shading=left right_gbuffer=right right_shading=right"},
      {"plain-rt", "left_trace=left right_trace=right"},
      {"ideal-copy", "left_trace=left right_copy=right"},
      {"repro-warp", "left_gbuffer=left left_shading=left grid_metric=right grid_warp=right"},
      {"repro-rt", "left_gbuffer=left left_shading=left grid_metric=right grid_warp=right source_frustum=right hole_fill=right"},
      {"repro-reraster", "left_gbuffer=left left_shading=left grid_metric=right grid_warp=right source_frustum=right hole_fill=right"},
      {"rt-adelson", "allocate=both left_trace=left reproject=right right_trace=right"},
      {"rt-es-isler", "allocate=both left_trace=left reproject=right right_trace=right"},
      {"rt-buffer", "left_trace=left reproject=right right_resolve=right validate=right right_trace=right"},
      {"rt-atomic", "left_trace=left reproject=right validate=right right_trace=right"},
      {"fw-warp", "left_gbuffer=left left_shading=left warp_depth=right warp_color=right crack_fill=right"},
      {"bw-warp", "left_gbuffer=left left_shading=left backward_warp=right crack_fill=right"},
      {"bidir-warp",
       "redirect=both left_gbuffer=both left_shading=both right_gbuffer=both right_shading=both motion=both warp=both "
       "crack_fill=both background=both"},
      {"bidir-warp-rt",
       "redirect=both left_gbuffer=both left_shading=both right_gbuffer=both right_shading=both motion=both warp=both "
       "crack_fill=both hole_fill=both"},
  };
  const auto it = expected.find(GetParam());
  ASSERT_NE(it, expected.end()) << GetParam() << " is registered but its stages' eyes are not listed here";
  EXPECT_EQ(test::stage_eyes_of(GetParam()), it->second);
}

/// The same for the option values that run other stages: fw-warp's row warp, the z-test of
/// bidirectional warping.
TEST(StageEyes, OptionsThatRunOtherStagesSayWhichEyeTheyServe) {
  EXPECT_EQ(test::stage_eyes_of("fw-warp", {{"warp", "rows"}}),
            "left_gbuffer=left left_shading=left motion=right row_warp=right crack_fill=right");
  const std::string ztest =
      "redirect=both left_gbuffer=both right_gbuffer=both ztest=both left_shading=both right_shading=both motion=both "
      "warp=both crack_fill=both ";
  EXPECT_EQ(test::stage_eyes_of("bidir-warp", {{"occlusion", "ztest"}}), ztest + "background=both");
  EXPECT_EQ(test::stage_eyes_of("bidir-warp-rt", {{"occlusion", "ztest"}}), ztest + "hole_fill=both");
}

INSTANTIATE_TEST_SUITE_P(Registry, Conformance, ::testing::ValuesIn(registered_pipelines()),
                         param_name);

class Visibility : public ::testing::TestWithParam<std::string> {};

/// plain-raster and plain-rt see the same primitive on >= 99.9 % of pixels at 480x270, the
/// disagreements on silhouettes, and their shaded right eyes agree to >= 50 dB.
TEST_P(Visibility, RasterAndRayTracingAgree) {
  const Scene scene = test::load_builtin(GetParam());
  const RenderScene rs(scene);
  const StereoRig rig = test::rig_at(scene, 480, 270);
  const StereoResult rt = test::render_with("plain-rt", rs, rig);
  const StereoResult ra = test::render_with("plain-raster", rs, rig);
  for (Eye e : {Eye::left, Eye::right}) {
    const Image& a = e == Eye::left ? rt.left : rt.right;
    const Image& b = e == Eye::left ? ra.left : ra.right;
    const uint32_t* pa = a.data_u32(planes::primid);
    const uint32_t* pb = b.data_u32(planes::primid);
    const int w = a.width(), h = a.height();
    size_t differ = 0, off_silhouette = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const size_t i = static_cast<size_t>(y) * w + x;
        if (pa[i] == pb[i]) continue;
        ++differ;
        // A silhouette pixel has a neighbour that sees another primitive.
        bool silhouette = false;
        for (int dy = -1; dy <= 1 && !silhouette; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int xx = x + dx, yy = y + dy;
            if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
            if (pa[static_cast<size_t>(yy) * w + xx] != pa[i]) silhouette = true;
          }
        if (!silhouette) ++off_silhouette;
      }
    const double agree = 1.0 - double(differ) / double(a.pixel_count());
    if (agree < 0.999) {
      // Keep a picture of where they disagree (white) over the ray-traced eye, for inspection.
      test::ScratchDir dir(std::string("disagreement-") + eye_name(e));
      std::vector<uint8_t> rgb(a.pixel_count() * 3);
      const float* c = a.data_f32(planes::rgb);
      for (size_t i = 0; i < a.pixel_count(); ++i)
        for (int k = 0; k < 3; ++k)
          rgb[i * 3 + k] = pa[i] != pb[i] ? (k == 0 ? 255 : 0) : linear_to_srgb8(c[i * 3 + k]);
      io::write_png_rgb8(dir / "disagreement.png", rgb, w, h);
      ADD_FAILURE() << "disagreement picture: " << (dir / "disagreement.png").string();
    }
    EXPECT_GE(agree, 0.999) << GetParam() << " " << eye_name(e) << ": " << differ << " pixels see another primitive";
    EXPECT_EQ(off_silhouette, 0u) << GetParam() << " " << eye_name(e);
    std::printf("%-15s %-5s primitive ids agree on %.4f %% (%zu differ)\n", GetParam().c_str(), eye_name(e), 100.0 * agree, differ);
  }
  const double psnr = test::psnr_srgb8(ra.right, rt.right);
  // The specification's 50 dB on every scene. Measured at 480x270: textured-plane 75.07 dB (the
  // mip-level stress scene: its full-contrast checker at grazing angles shows any difference
  // between the raster's derivative LOD and the ray cone's, which the TextureLod test measures at
  // 0.000 levels), bistro 65.56, atrium 60.69, spheres 59.45, temple 67.24, the others above 90 dB.
  EXPECT_GE(psnr, 50.0) << GetParam();
  std::printf("%-15s right eye plain-raster vs plain-rt: %.2f dB\n", GetParam().c_str(), psnr);
}

INSTANTIATE_TEST_SUITE_P(BuiltinScenes, Visibility, ::testing::ValuesIn(builtin_scenes()),
                         param_name);

}  // namespace
}  // namespace sb
