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

/// How the marks of a search with every pixel a candidate compare with the true disocclusion
/// mask's outside_frustum pixels.
struct Comparison {
  size_t both = 0, only_marked = 0, only_true = 0, left_side = 0, right_side = 0;
  uint64_t true_outside = 0;
  Marked marked;
};

Comparison compare_with_truth(const RenderScene& rs, const StereoRig& rig) {
  const Executor executor(0);
  const TrueDisocclusions truth =
      true_disocclusions(rs, rig, trace_visible_surfaces(rs, rig.eye(Eye::right), executor), executor);
  Comparison c;
  c.marked = mark_all(rs, rig, 0);
  c.true_outside = truth.outside_frustum;
  const int w = rig.params().width;
  for (size_t i = 0; i < c.marked.states.size(); ++i) {
    const bool marked = c.marked.states[i] == kMark;
    const bool outside = truth.mask[i] == static_cast<uint8_t>(Disocclusion::outside_frustum);
    c.both += marked && outside ? 1 : 0;
    c.only_marked += marked && !outside ? 1 : 0;
    c.only_true += !marked && outside ? 1 : 0;
    if (marked) (static_cast<int>(i % static_cast<size_t>(w)) < w / 2 ? c.left_side : c.right_side)++;
  }
  return c;
}

void expect_exact(const Comparison& c) {
  EXPECT_EQ(c.only_marked, 0u);
  EXPECT_EQ(c.only_true, 0u);
  EXPECT_EQ(c.both, c.true_outside);
  EXPECT_EQ(c.marked.stats.pixels, c.both);
}

// Every pixel a candidate: the marks are exactly the pixels the true disocclusion test finds
// outside the left frustum — near surfaces entering at the right edge (rays restricted to the part
// in front of the left frustum) and surfaces beyond the left image at the left edge (rays that
// leave the left frustum again).
TEST_P(SourceFrustum, MarksExactlyTheTrueOutsideFrustumPixels) {
  const Scene scene = test::load_builtin(GetParam());
  const RenderScene rs(scene);
  const StereoRig rig = test::rig_at(scene, 480, 270);
  const Comparison c = compare_with_truth(rs, rig);
  std::printf("%-10s outside the left frustum: %zu marked (%zu left half, %zu right half), %llu rays for %zu pixels, "
              "%llu triangles clipped\n",
              GetParam().c_str(), c.both + c.only_marked, c.left_side, c.right_side,
              static_cast<unsigned long long>(c.marked.stats.rays), c.marked.states.size(),
              static_cast<unsigned long long>(c.marked.stats.triangles_near));
  expect_exact(c);
  // Both kinds occur in these scenes' default rigs (spheres and bistro have surfaces nearer than
  // the convergence distance at the right edge).
  EXPECT_GT(c.left_side, 0u);
  EXPECT_GT(c.right_side, 0u);
  // The clipping keeps the rays to a band at the image edges: measured 0.80 % of the pixels on
  // spheres and 0.93 % on bistro at 480x270, against 100 % without it.
  EXPECT_LT(static_cast<double>(c.marked.stats.rays), 0.03 * static_cast<double>(c.marked.states.size()));
}

// A near plane beyond the nearest surfaces: rays start at the eye, so the right eye sees surfaces
// in front of its near plane, which lie in front of the left eye's too (the same depth for the
// rig's parallel eyes) and so outside its frustum, anywhere in the image.
TEST(SourceFrustumNearPlane, SurfacesInFrontOfTheNearPlaneAreMarked) {
  const Scene scene = test::load_builtin("bistro");
  const RenderScene rs(scene);
  const StereoRig base = test::rig_at(scene, 480, 270);
  RigParams params = base.params();
  params.znear = 3.0;  // bistro's nearest visible surface is at about 1.7 m
  const StereoRig rig(base.pose(), params);
  const Comparison c = compare_with_truth(rs, rig);
  std::printf("bistro, znear 3 m: %llu pixels outside the left frustum, %zu marked, %llu rays\n",
              static_cast<unsigned long long>(c.true_outside), c.both + c.only_marked,
              static_cast<unsigned long long>(c.marked.stats.rays));
  expect_exact(c);
  EXPECT_GT(c.true_outside, 1000u);  // the case is there
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
