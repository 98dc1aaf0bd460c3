// Three-way agreement of the ground-truth providers (DESIGN §6.1): `full`, `blender` and `povray` render the right eye of every untextured built-in scene at
// 640x360, and each pair must agree to PSNR >= 45 dB (8-bit sRGB) with a mean absolute difference
// of at most 0.5 % of the mean over lit pixels. The textured plane is reported, not gated: the
// three filter textures differently (trilinear mip-mapping here, none in Cycles or POV-Ray).
// The tools are installed by the test command (ci/install-deps.sh blender povray); a missing tool
// fails these tests, it never skips them.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "renderer/io/image_io.hpp"
#include "renderer/render_scene.hpp"
#include "scenes/catalog.hpp"
#include "support/render_support.hpp"
#include "support/scratch_dir.hpp"
#include "validation/metric_images.hpp"
#include "validation/metrics.hpp"
#include "validation/truth.hpp"

namespace sb {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 640, kHeight = 360;
/// Lit pixels: the largest channel of either image above 1e-3 (linear radiance).
constexpr float kLitThreshold = 1e-3f;
// The required agreement, the same for every pair and scene. Measured (worst pair): spheres
// 47.25 dB / 0.066 %, dragon 50.19 dB / 0.032 % (full - blender; relative MAD at most 0.066 % on
// spheres, 0.044 % on dragon), the analytic scenes 68 dB and up / 0.018 %
// (docs/ground_truth.md).
constexpr double kMinPsnr = 45.0;          // dB, 8-bit sRGB
constexpr double kMaxRelativeMad = 0.005;  // mean |a - b| / mean(b) over lit pixels

const std::array<const char*, 3> kProviders = {"full", "blender", "povray"};

struct PairAgreement {
  std::string a, b;
  double psnr = 0.0;
  double relative_mad = 0.0;
  size_t error_pixels = 0;
  double mean_ratio = 0.0;  ///< mean radiance of b / mean radiance of a, over the whole image
};

/// Every provider's right eye of a scene, and the agreement of each pair; images of the renders
/// and their differences are written into `dir`.
std::vector<PairAgreement> agreement(const std::string& name, const fs::path& dir) {
  const fs::path cache = fs::path(SB_BINARY_DIR) / "Testing" / "scenes-cache";
  const fs::path file = scenes::resolve_scene(name, cache);
  const Scene scene = io::load_gltf(file);
  const RenderScene prepared(scene);
  const StereoRig rig = test::rig_at(scene, kWidth, kHeight);
  std::map<std::string, validation::TruthRender> renders;
  for (const char* p : kProviders) {
    const std::unique_ptr<validation::TruthProvider> provider = validation::make_truth_provider(p);
    if (const auto why = provider->unavailable_reason())
      ADD_FAILURE() << p << " is unavailable: " << *why << " (the test command installs it: ci/install-deps.sh)";
    else
      renders.emplace(p, provider->render({prepared, file, rig, dir / name / p, 2}));
  }
  std::vector<PairAgreement> out;
  for (size_t i = 0; i < kProviders.size(); ++i)
    for (size_t j = i + 1; j < kProviders.size(); ++j) {
      const std::string a = kProviders[i], b = kProviders[j];
      if (!renders.count(a) || !renders.count(b)) continue;
      const Image& ia = renders.at(a).right;
      const Image& ib = renders.at(b).right;
      const validation::Srgb8Image a8 = validation::encode_srgb8(ia, a), b8 = validation::encode_srgb8(ib, b);
      const validation::ImageMetrics m = validation::compare_images(a8, b8);
      const validation::RegionMask lit = validation::lit_mask(ia, ib, kLitThreshold);
      const validation::LinearDifference d = validation::linear_difference(ia, ib, &lit);
      double sum_a = 0.0, sum_b = 0.0;
      for (const float v : ia.plane(planes::rgb).f32()) sum_a += v;
      for (const float v : ib.plane(planes::rgb).f32()) sum_b += v;
      out.push_back({a, b, m.psnr, d.relative, m.error_pixels, sum_b / sum_a});
      validation::write_png(dir / fmt::format("{}_{}-vs-{}_diff.png", name, a, b), validation::difference_image(a8, b8));
    }
  for (const auto& [p, r] : renders) io::write_png_preview(dir / fmt::format("{}_{}.png", name, p), r.right);
  for (const PairAgreement& g : out)
    std::printf(
        "%-14s %-7s vs %-7s PSNR %6.2f dB  relative MAD %.4f %%  %zu pixels off by more than 2/255  mean ratio "
        "%.5f\n",
        name.c_str(), g.a.c_str(), g.b.c_str(), g.psnr, 100.0 * g.relative_mad, g.error_pixels, g.mean_ratio);
  return out;
}

/// Where the images go: $SB_AGREEMENT_IMAGES if set (to look at them), else a scratch folder kept
/// only when the test fails.
fs::path image_dir(const test::ScratchDir& scratch) {
  if (const char* keep = std::getenv("SB_AGREEMENT_IMAGES")) return keep;
  return scratch.path();
}

class ThreeWay : public ::testing::TestWithParam<const char*> {};

TEST_P(ThreeWay, EveryPairAgreesOnUntexturedScene) {
  const test::ScratchDir scratch;
  for (const PairAgreement& g : agreement(GetParam(), image_dir(scratch))) {
    EXPECT_GE(g.psnr, kMinPsnr) << g.a << " vs " << g.b;
    EXPECT_LE(g.relative_mad, kMaxRelativeMad) << g.a << " vs " << g.b;
    RecordProperty(g.a + "_" + g.b + "_psnr", fmt::format("{:.2f}", g.psnr));
  }
}

INSTANTIATE_TEST_SUITE_P(Untextured, ThreeWay,
                         ::testing::Values("lit-plane", "slanted-plane", "box-wall", "thin-pole", "spheres", "dragon"),
                         [](const ::testing::TestParamInfo<const char*>& scene) {
                           std::string n = scene.param;
                           for (char& c : n) c = c == '-' ? '_' : c;
                           return n;
                         });

TEST(ThreeWayTextured, TexturedPlaneIsReportedNotGated) {
  const test::ScratchDir scratch;
  const std::vector<PairAgreement> pairs = agreement("textured-plane", image_dir(scratch));
  // Reported only (the numbers are printed): texture filtering differs between the providers.
  EXPECT_EQ(pairs.size(), 3u);
  // Per pixel the filtering differs (`full`: trilinear mip-mapping; POV-Ray and Cycles: one
  // bilinear sample per pixel without mip-mapping, so distant texels alias). The texture's
  // colour and the light units must still agree on average: a texture decoded wrongly (sRGB twice
  // or not at all), a lost base colour factor or a missing light would move the mean by far more.
  // Measured mean radiance ratio to `full` at 640x360: blender 1.00000, povray 0.99999 (blender vs
  // povray 0.99999), while the relative MAD is 21.7 %: the aliasing errors cancel on average. 2 %
  // leaves room for the aliasing of distant texels at other sizes.
  for (const PairAgreement& g : pairs) {
    if (g.a != "full") continue;
    RecordProperty(g.b + "_mean_ratio", fmt::format("{:.5f}", g.mean_ratio));
    EXPECT_NEAR(g.mean_ratio, 1.0, 0.02) << g.b << " vs full";
  }
}

}  // namespace
}  // namespace sb
