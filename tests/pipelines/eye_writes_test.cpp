// The stages that fill whole eye images made with PlaneInit::unset (trace_eye, shade_gbuffer
// without a mask, the parallel pixel reprojection's validate-copy plus right_trace, and the
// scan-line bands of rt-adelson and rt-es-isler) write every sample of every plane: an image
// poisoned with a NaN no stage writes keeps none of it. And every pipeline's eyes, rendered with
// every unset plane poisoned, keep none of it either.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "renderer/pipeline.hpp"
#include "renderer/raster/rasterizer.hpp"
#include "renderer/stages/eye_image.hpp"
#include "renderer/stages/lighting.hpp"
#include "renderer/stages/pixel_reprojection.hpp"
#include "renderer/stages/scanline_reprojection.hpp"
#include "renderer/stages/trace.hpp"
#include "support/poisoned_image.hpp"
#include "support/render_support.hpp"

namespace sb {
namespace {

/// An eye image whose every sample holds the sentinel.
Image poisoned_eye(int w, int h) {
  Image image = make_eye_image(w, h, PlaneInit::unset);
  test::poison(image);
  return image;
}

/// Samples of `image` that still hold the sentinel, per plane ("" when none).
std::string unwritten(const Image& image) {
  std::string out;
  for (const Plane& plane : image.planes())
    if (const size_t n = test::sentinel_count(plane); n > 0)
      out += std::string(plane.name()) + ": " + std::to_string(n) + " ";
  return out;
}

class EyeWrites : public ::testing::TestWithParam<const char*> {};

TEST_P(EyeWrites, WholeEyeStagesWriteEverySample) {
  const Scene scene = test::load_builtin(GetParam());
  const RenderScene prepared(scene);
  // 90 x 54: not a multiple of the 4x4 ray packets, so clipped blocks are covered too.
  const StereoRig rig = test::rig_at(scene, 90, 54);
  const Executor executor(2);
  const EyeCamera left = rig.eye(Eye::left), right = rig.eye(Eye::right);
  const int w = left.width, h = left.height;

  Image traced = poisoned_eye(w, h);
  TraceCounts counts;
  trace_eye(prepared, left, executor, traced, counts);
  EXPECT_EQ(unwritten(traced), "") << "trace_eye on " << GetParam();

  Image shaded = poisoned_eye(w, h);
  const GBuffer g = rasterize(prepared.geometry(), left, executor);
  shade_gbuffer(prepared, left, g, executor, shaded, counts);
  EXPECT_EQ(unwritten(shaded), "") << "shade_gbuffer on " << GetParam();

  // rt-atomic's right eye: the winning source column per right pixel, validated and copied, the
  // rest traced.
  const PixelReprojector reprojector(rig);
  RightSources sources{w, h, std::vector<int32_t>(static_cast<size_t>(w) * h, kNoSource)};
  const float* depth = traced.data_f32(planes::depth);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int32_t t = reprojector.target(x, y, depth[static_cast<size_t>(y) * w + x]);
      if (t != kNoSource) sources.column[sources.index(t, y)] = std::max(sources.column[sources.index(t, y)], x);
    }
  Image completed = poisoned_eye(w, h);
  const Validation v = validate_and_copy(prepared, reprojector, sources, traced, ValidationSettings{}, executor, completed);
  EXPECT_LT(v.missed + v.blocked, static_cast<uint64_t>(w) * h) << "some pixels are reprojected";
  trace_unless(prepared, right, executor, v.state, kApproved, completed, counts, Source::reshaded_traced);
  EXPECT_EQ(unwritten(completed), "") << "validate_and_copy + trace_unless on " << GetParam();

  // rt-adelson's and rt-es-isler's scan-line bands, both eyes.
  Image band_left = poisoned_eye(w, h), band_right = poisoned_eye(w, h);
  ScanlineCounts scan;
  for (int y0 = 0; y0 < h; y0 += kScanlineBand)
    scanline_band(prepared, reprojector, y0, std::min(y0 + kScanlineBand, h), band_left, band_right, scan);
  EXPECT_GT(scan.right.pixels_traced, 0u);
  EXPECT_EQ(unwritten(band_left), "") << "scanline_band's left eye on " << GetParam();
  EXPECT_EQ(unwritten(band_right), "") << "scanline_band's right eye on " << GetParam();
}

/// Turns poison_unset_planes on for its lifetime.
struct PoisonUnsetPlanes {
  PoisonUnsetPlanes() { poison_unset_planes(true); }
  ~PoisonUnsetPlanes() { poison_unset_planes(false); }
  PoisonUnsetPlanes(const PoisonUnsetPlanes&) = delete;
  PoisonUnsetPlanes& operator=(const PoisonUnsetPlanes&) = delete;
};

/// Every pipeline, on each of its paths, writes every sample of both eyes it returns: with every
/// plane made unset poisoned, none of the poison is left in its output. This covers the eyes
/// pipelines allocate unset themselves (bw-warp's backward warp, fw-warp's colour pass, ...).
TEST_P(EyeWrites, EveryPipelineWritesEverySampleOfItsEyes) {
  const Scene scene = test::load_builtin(GetParam());
  const RenderScene prepared(scene);
  const StereoRig rig = test::rig_at(scene, 90, 54);
  const PoisonUnsetPlanes poison;
  ASSERT_NE(unwritten(make_eye_image(4, 4, PlaneInit::unset)), "") << "the poison is on";
  std::vector<std::pair<std::string, std::map<std::string, std::string>>> runs;
  for (const Pipeline* p : pipelines()) runs.push_back({p->info().name, {}});
  runs.push_back({"fw-warp", {{"warp", "rows"}}});
  for (const auto& [name, options] : runs) {
    const StereoResult r = test::render_with(name, prepared, rig, 2, options);
    const std::string what = name + (options.empty() ? "" : " (warp=rows)") + " on " + GetParam();
    EXPECT_EQ(unwritten(r.left), "") << "left eye of " << what;
    EXPECT_EQ(unwritten(r.right), "") << "right eye of " << what;
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, EyeWrites, ::testing::Values("spheres", "box-wall"));

}  // namespace
}  // namespace sb
