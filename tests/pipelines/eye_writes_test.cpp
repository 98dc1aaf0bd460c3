// Every pipeline writes every sample of every plane of both eyes it returns, so that the eyes and
// stages that allocate images with PlaneInit::unset (no fill pass) never leave a sample unset:
// rendered with every unset plane poisoned with a NaN no stage writes, no eye keeps any of it.
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "renderer/pipeline.hpp"
#include "renderer/stages/eye_image.hpp"
#include "support/poisoned_image.hpp"
#include "support/render_support.hpp"

namespace sb {
namespace {

class EyeWrites : public ::testing::TestWithParam<const char*> {};

/// Each pipeline on each of its paths: whole traced eyes (trace_eye), rasterized eyes
/// (shade_gbuffer without a mask), the parallel pixel reprojection's validate-copy plus
/// right_trace, the scan-line bands of rt-adelson and rt-es-isler, the grid, row and backward warps.
TEST_P(EyeWrites, EveryPipelineWritesEverySampleOfItsEyes) {
  const Scene scene = test::load_builtin(GetParam());
  const RenderScene prepared(scene);
  // 90 x 54: not a multiple of the 4x4 ray packets or the 16x16 grid cells, so clipped blocks and
  // partial cells are covered too.
  const StereoRig rig = test::rig_at(scene, 90, 54);
  const test::PoisonUnsetPlanes poison;
  ASSERT_NE(test::unwritten(make_eye_image(4, 4, PlaneInit::unset)), "") << "the poison is on";
  std::vector<std::pair<std::string, std::map<std::string, std::string>>> runs;
  for (const Pipeline* p : pipelines()) runs.push_back({p->info().name, {}});
  runs.push_back({"fw-warp", {{"warp", "rows"}}});
  for (const auto& [name, options] : runs) {
    const StereoResult r = test::render_with(name, prepared, rig, 2, options);
    const std::string what = name + (options.empty() ? "" : " (warp=rows)") + " on " + GetParam();
    EXPECT_EQ(test::unwritten(r.left), "") << "left eye of " << what;
    EXPECT_EQ(test::unwritten(r.right), "") << "right eye of " << what;
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, EyeWrites, ::testing::Values("spheres", "box-wall"));

}  // namespace
}  // namespace sb
