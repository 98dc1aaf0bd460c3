// mark_outside_source_frustum: the right-eye pixels whose visible surface lies outside the left
// frustum, against the true disocclusion mask's outside_frustum pixels; only candidates are
// touched; the same marks on any thread count; few rays.
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "renderer/error.hpp"
#include "renderer/render_scene.hpp"
#include "renderer/stages/disocclusion.hpp"
#include "renderer/stages/source_frustum.hpp"
#include "support/render_support.hpp"

namespace sb {
namespace {

constexpr uint8_t kCandidate = 1, kMark = 4, kOther = 2;

struct Marked {
  std::vector<uint8_t> states;
  SourceFrustumStats stats;
};

Marked mark_all(const RenderScene& rs, const StereoRig& rig, int threads, uint8_t initial = kCandidate) {
  const Executor executor(threads);
  Marked m;
  m.states.assign(static_cast<size_t>(rig.params().width) * static_cast<size_t>(rig.params().height), initial);
  m.stats = mark_outside_source_frustum(rs, rig.eye(Eye::left), rig.eye(Eye::right), executor, m.states, kCandidate, kMark);
  return m;
}

class SourceFrustum : public ::testing::TestWithParam<std::string> {};

// Every pixel a candidate: the marks are exactly the pixels the true disocclusion test finds
// outside the left frustum — near surfaces entering at the right edge (rays restricted to the part
// in front of the left frustum) and surfaces beyond the left image at the left edge (rays that
// leave the left frustum again).
TEST_P(SourceFrustum, MarksExactlyTheTrueOutsideFrustumPixels) {
  const Scene scene = test::load_builtin(GetParam());
  const RenderScene rs(scene);
  const StereoRig rig = test::rig_at(scene, 480, 270);
  const Executor executor(0);
  const TrueDisocclusions truth =
      true_disocclusions(rs, rig, trace_visible_surfaces(rs, rig.eye(Eye::right), executor), executor);
  const Marked m = mark_all(rs, rig, 0);
  const int w = rig.params().width;
  size_t both = 0, only_marked = 0, only_true = 0, left_side = 0, right_side = 0;
  for (size_t i = 0; i < m.states.size(); ++i) {
    const bool marked = m.states[i] == kMark;
    const bool outside = truth.mask[i] == static_cast<uint8_t>(Disocclusion::outside_frustum);
    both += marked && outside ? 1 : 0;
    only_marked += marked && !outside ? 1 : 0;
    only_true += !marked && outside ? 1 : 0;
    if (marked) (static_cast<int>(i % static_cast<size_t>(w)) < w / 2 ? left_side : right_side)++;
  }
  std::printf("%-10s outside the left frustum: %zu marked (%zu left half, %zu right half), %llu rays for %zu pixels, "
              "%llu triangles clipped\n",
              GetParam().c_str(), both + only_marked, left_side, right_side,
              static_cast<unsigned long long>(m.stats.rays), m.states.size(),
              static_cast<unsigned long long>(m.stats.triangles_near));
  EXPECT_EQ(only_marked, 0u);
  EXPECT_EQ(only_true, 0u);
  EXPECT_EQ(both, truth.outside_frustum);
  EXPECT_EQ(m.stats.pixels, both);
  // Both kinds occur in these scenes' default rigs (spheres and bistro have surfaces nearer than
  // the convergence distance at the right edge).
  EXPECT_GT(left_side, 0u);
  EXPECT_GT(right_side, 0u);
  // The clipping keeps the rays to a band at the image edges: measured 0.80 % of the pixels on
  // spheres and 0.93 % on bistro at 480x270, against 100 % without it.
  EXPECT_LT(static_cast<double>(m.stats.rays), 0.03 * static_cast<double>(m.states.size()));
}

INSTANTIATE_TEST_SUITE_P(Scenes, SourceFrustum, ::testing::Values("spheres", "bistro"));

TEST(SourceFrustumStates, OnlyCandidatesAreTestedAndMarked) {
  const Scene scene = test::load_builtin("spheres");
  const RenderScene rs(scene);
  const StereoRig rig = test::rig_at(scene, 320, 180);
  const Marked none = mark_all(rs, rig, 0, kOther);
  EXPECT_EQ(none.stats.rays, 0u);
  EXPECT_EQ(none.stats.pixels, 0u);
  for (const uint8_t s : none.states) ASSERT_EQ(s, kOther);
}

TEST(SourceFrustumStates, IdenticalWithOneAndTwoThreads) {
  const Scene scene = test::load_builtin("spheres");
  const RenderScene rs(scene);
  const StereoRig rig = test::rig_at(scene, 320, 180);
  const Marked a = mark_all(rs, rig, 1), b = mark_all(rs, rig, 2);
  EXPECT_EQ(a.states, b.states);
  EXPECT_EQ(a.stats.rays, b.stats.rays);
  EXPECT_EQ(a.stats.triangles_near, b.stats.triangles_near);
  EXPECT_GT(a.stats.pixels, 0u);
}

TEST(SourceFrustumStates, RefusesStatesOfAnotherSize) {
  const Scene scene = test::load_builtin("spheres");
  const RenderScene rs(scene);
  const StereoRig rig = test::rig_at(scene, 320, 180);
  std::vector<uint8_t> states(10, kCandidate);
  EXPECT_THROW((void)mark_outside_source_frustum(rs, rig.eye(Eye::left), rig.eye(Eye::right), Executor(1), states,
                                                 kCandidate, kMark),
               InputError);
}

}  // namespace
}  // namespace sb
