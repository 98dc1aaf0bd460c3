// Kim's visibility redirection: the frustum comparison first, then the facing comparison, both
// eyes on exact ties; and the rasterizer's triangle mask that renders an eye's share.
#include <gtest/gtest.h>

#include <algorithm>

#include "renderer/raster/rasterizer.hpp"
#include "renderer/stages/redirection.hpp"
#include "support/render_support.hpp"

namespace sb {
namespace {

/// A rig at the origin looking down -Z: eyes at x = -/+0.032 m, 320x180, convergence 2 m.
StereoRig test_rig() {
  RigParams p;
  p.width = 320;
  p.height = 180;
  return StereoRig(CameraPose{}, p);
}

TEST(Redirection, TriangleFacingTheLeftEyeGoesLeft) {
  const StereoRig rig = test_rig();
  const EyeCamera l = rig.eye(Eye::left), r = rig.eye(Eye::right);
  // Inside both frusta, 1 m ahead, its normal turned towards -X: the left eye (at x = -0.032)
  // sees it more squarely than the right one.
  const dvec3 n = glm::normalize(dvec3(-1.0, 0.0, 1.0));
  const dvec3 up(0.0, 1.0, 0.0), side = glm::normalize(glm::cross(up, n));
  const dvec3 c(0.0, 0.0, -1.0);
  const dvec3 v0 = c - 0.05 * side - 0.05 * up, v1 = c + 0.05 * side - 0.05 * up, v2 = c + 0.05 * up;
  ASSERT_EQ(frustum_visibility(l, v0, v1, v2), 1.0);
  ASSERT_EQ(frustum_visibility(r, v0, v1, v2), 1.0);
  EXPECT_GT(facing_visibility(l, v0, v1, v2, false), facing_visibility(r, v0, v1, v2, false));
  EXPECT_EQ(redirect(l, r, v0, v1, v2, false), kRedirectLeft);
  // Mirrored about x = 0, it faces the right eye.
  const dvec3 m0(-v0.x, v0.y, v0.z), m1(-v1.x, v1.y, v1.z), m2(-v2.x, v2.y, v2.z);
  EXPECT_EQ(redirect(l, r, m0, m2, m1, false), kRedirectRight);
}

TEST(Redirection, TriangleLeavingTheRightFrustumGoesLeft) {
  const StereoRig rig = test_rig();
  const EyeCamera l = rig.eye(Eye::left), r = rig.eye(Eye::right);
  // A small triangle near the right border of the left image, 10 m away: beyond the convergence
  // distance its disparity is positive (about 6 px here), so the right eye sees it further right,
  // past its right border.
  const double depth = 10.0;
  const dvec3 p = l.unproject(317.0, 90.0, depth);
  const dvec3 v0 = p, v1 = p + dvec3(0.01, 0.0, 0.0), v2 = p + dvec3(0.0, 0.01, 0.0);
  ASSERT_EQ(frustum_visibility(l, v0, v1, v2), 1.0);
  EXPECT_LT(frustum_visibility(r, v0, v1, v2), frustum_visibility(l, v0, v1, v2));
  EXPECT_EQ(redirect(l, r, v0, v1, v2, false), kRedirectLeft);
}

TEST(Redirection, ExactTiesGoToBothEyes) {
  const StereoRig rig = test_rig();
  const EyeCamera l = rig.eye(Eye::left), r = rig.eye(Eye::right);
  // Symmetric about x = 0 and facing the rig squarely: same frustum and facing visibility.
  const dvec3 v0(-0.1, -0.1, -2.0), v1(0.1, -0.1, -2.0), v2(0.0, 0.1, -2.0);
  EXPECT_EQ(frustum_visibility(l, v0, v1, v2), frustum_visibility(r, v0, v1, v2));
  EXPECT_EQ(facing_visibility(l, v0, v1, v2, false), facing_visibility(r, v0, v1, v2, false));
  EXPECT_EQ(redirect(l, r, v0, v1, v2, false), kRedirectBoth);
}

TEST(Redirection, ATriangleReachingBehindTheEyesGoesToBoth) {
  const StereoRig rig = test_rig();
  const EyeCamera l = rig.eye(Eye::left), r = rig.eye(Eye::right);
  // A floor triangle 1 m below the eyes, from 20 m ahead to 5 m behind, wider on the left: its
  // projection reaches both eyes' image borders. With the vertices behind read as "not in the
  // frustum" in both eyes, the facing comparison sent it to one eye, and the other eye's border
  // strip, which the first does not see, stayed a hole.
  const dvec3 v0(-30.0, -1.0, 5.0), v1(10.0, -1.0, 5.0), v2(-5.0, -1.0, -20.0);
  EXPECT_EQ(redirect(l, r, v0, v1, v2, false), kRedirectBoth);
  EXPECT_EQ(redirect(l, r, v0, v1, v2, true), kRedirectBoth);
  // Wholly behind the eyes it is seen by neither, and ranked as before (its eye does not matter).
  const dvec3 b0(-1.0, -1.0, 1.0), b1(2.0, -1.0, 1.0), b2(0.0, -1.0, 3.0);
  EXPECT_NE(redirect(l, r, b0, b1, b2, false), kRedirectBoth);
}

TEST(Redirection, ATriangleBothFrustaClipGoesToOneEyeAsPublishedOrToBoth) {
  const StereoRig rig = test_rig();
  const EyeCamera l = rig.eye(Eye::left), r = rig.eye(Eye::right);
  // A wall 10 m away, wider than both images and reaching further past the right eye's right
  // border than past the left eye's left border: each eye sees an end of it the other does not.
  const dvec3 v0(-12.0, -4.0, -10.0), v1(16.0, -4.0, -10.0), v2(2.0, 8.0, -10.0);
  const double fl = frustum_visibility(l, v0, v1, v2), fr = frustum_visibility(r, v0, v1, v2);
  ASSERT_LT(fl, 1.0);
  ASSERT_LT(fr, 1.0);
  // Eq. (1): the eye that clips it less, here the left one.
  ASSERT_GT(fl, fr);
  EXPECT_EQ(redirect(l, r, v0, v1, v2, false), kRedirectLeft);
  EXPECT_EQ(redirect(l, r, v0, v1, v2, false, ClippedRule::one), redirect(l, r, v0, v1, v2, false));
  EXPECT_EQ(redirect(l, r, v0, v1, v2, false, ClippedRule::both), kRedirectBoth);
  EXPECT_EQ(redirect(l, r, v0, v1, v2, true, ClippedRule::both), kRedirectBoth);
  // A sliver reaching from 0.5 m to 100 m, just past the left image's right border: in front of
  // the convergence distance the right eye sees it further left, so only the right eye sees it,
  // and from 0.5 m it reaches less far past the right image's border than past the left's. Eq. (1)
  // gives it to the left eye, which sees none of it; under clipped=both it goes to the right eye.
  const dvec3 n0 = l.unproject(330.0, 80.0, 0.5), n1 = l.unproject(340.0, 100.0, 0.5), f0 = l.unproject(335.0, 90.0, 100.0);
  ASSERT_LT(frustum_visibility(r, n0, n1, f0), frustum_visibility(l, n0, n1, f0));
  ASSERT_GT(r.project(n0).x, 0.0);
  ASSERT_LT(r.project(n0).x, 320.0) << "the right eye sees a part of it";
  for (const dvec3& v : {n0, n1, f0}) ASSERT_GT(l.project(v).x, 320.0) << "the left eye sees none of it";
  EXPECT_EQ(redirect(l, r, n0, n1, f0, false), kRedirectLeft);
  EXPECT_EQ(redirect(l, r, n0, n1, f0, false, ClippedRule::both), kRedirectRight);
  // A triangle only one frustum clips is still ranked by eq. (1): inside the left image, 10 m
  // away, across the right image's right border (about 6 px further right there), where both
  // eyes see a part of it.
  const dvec3 s0 = l.unproject(312.0, 90.0, 10.0), s1 = l.unproject(316.0, 90.0, 10.0),
              s2 = l.unproject(314.0, 95.0, 10.0);
  ASSERT_EQ(frustum_visibility(l, s0, s1, s2), 1.0);
  ASSERT_LT(frustum_visibility(r, s0, s1, s2), 1.0);
  ASSERT_LT(r.project(s0).x, 320.0) << "the right eye sees a part of it";
  EXPECT_EQ(redirect(l, r, s0, s1, s2, false, ClippedRule::both), kRedirectLeft);
}

TEST(Redirection, EachEyeRasterizesOnlyItsShare) {
  const Scene scene = test::load_builtin("box-wall");
  const RenderScene prepared(scene);
  const StereoRig rig = test::rig_at(scene, 160, 90);
  const Executor executor(2);
  // As the materials say (every mesh double-sided: nothing culled), and with the closed box culled.
  for (const bool closed_too : {false, true}) {
    uint64_t closed_culled = 0;
    const std::vector<uint8_t> culled = culled_meshes(prepared.geometry(), rig, executor, closed_too, closed_culled);
    EXPECT_EQ(closed_culled, closed_too ? 1u : 0u);
    RedirectionCounts counts;
    const std::vector<uint8_t> bits = redirect_triangles(prepared.geometry(), rig, culled, executor, counts);
    ASSERT_EQ(bits.size(), prepared.geometry().triangle_count());
    EXPECT_EQ(counts.left + counts.right + counts.both + counts.culled, bits.size());
    EXPECT_EQ(counts.culled > 0, closed_too) << "the box's bottom faces neither eye";
    EXPECT_GT(counts.left, 0u);
    EXPECT_GT(counts.right, 0u);
    for (const Eye e : {Eye::left, Eye::right}) {
      RasterOptions o;
      o.triangle_mask = bits.data();
      o.triangle_bit = e == Eye::left ? kRedirectLeft : kRedirectRight;
      RasterStats stats;
      const GBuffer g = rasterize(prepared.geometry(), rig.eye(e), executor, o, &stats);
      EXPECT_EQ(stats.triangles_skipped, (e == Eye::left ? counts.right : counts.left) + counts.culled);
      for (const uint32_t prim : g.prim) {
        if (prim == kNoPrimitiveId) continue;
        ASSERT_NE(bits[prim] & o.triangle_bit, 0) << "triangle " << prim;
      }
    }
  }
}

/// The index of box-wall's box, the one closed mesh of the scene.
size_t closed_box(const SceneGeometry& geometry) {
  const std::vector<uint8_t>& closed = geometry.closed(Executor(2));
  const auto it = std::find(closed.begin(), closed.end(), uint8_t{1});
  EXPECT_EQ(std::count(closed.begin(), closed.end(), uint8_t{1}), 1);
  return static_cast<size_t>(it - closed.begin());
}

TEST(Redirection, AClosedDoubleSidedMeshIsCulledOnlyWhereNoEyeCanSeeItsInside) {
  const Scene scene = test::load_builtin("box-wall");  // the box: x and z within 0.4 m of (0, -2.5), y 0..0.8 m
  const Executor executor(2);
  const auto culled_box = [&](const StereoRig& rig) {
    const RenderScene prepared(scene);
    const size_t box = closed_box(prepared.geometry());
    uint64_t closed_culled = 0;
    const bool culled = culled_meshes(prepared.geometry(), rig, executor, true, closed_culled)[box] != 0;
    EXPECT_EQ(closed_culled, culled ? 1u : 0u);
    EXPECT_EQ(culled_meshes(prepared.geometry(), rig, executor, false, closed_culled)[box], 0) << "option off";
    return culled;
  };
  const auto rig_from = [](const dvec3& eye, const dvec3& target) {
    RigParams p;
    p.width = 64;
    p.height = 36;
    return StereoRig(CameraPose::look_at(eye, target), p);
  };
  EXPECT_TRUE(culled_box(test::rig_at(scene, 160, 90)));
  EXPECT_FALSE(culled_box(rig_from({0.0, 0.4, -2.5}, {0.0, 0.4, -5.0}))) << "the eyes inside the box";
  EXPECT_FALSE(culled_box(rig_from({0.0, 0.4, -2.07}, {0.0, 0.4, -5.0}))) << "the near plane (0.05 m) cuts the box";
  EXPECT_TRUE(culled_box(rig_from({0.0, 0.4, -2.0}, {0.0, 0.4, -5.0}))) << "0.1 m before its face";
  // The near-plane test keeps a relative margin of 1e-6 for the rasterizer's rounding: a face
  // 1e-7 beyond the plane is not culled, one 1e-5 beyond is.
  double front = -1e9;
  {
    const RenderScene prepared(scene);
    for (const vec3& p : scene.meshes[closed_box(prepared.geometry())].positions) front = std::max(front, double(p.z));
  }
  const double znear = RigParams{}.znear;
  EXPECT_FALSE(culled_box(rig_from({0.0, 0.4, front + znear * (1.0 + 1e-7)}, {0.0, 0.4, -5.0})));
  EXPECT_TRUE(culled_box(rig_from({0.0, 0.4, front + znear * (1.0 + 1e-5)}, {0.0, 0.4, -5.0})));
}

TEST(Redirection, ClosedFlagsFollowAFramesPositions) {
  // A path's frame moves positions in place; the flags are found again for the frame, so that they
  // do not depend on the frame first rendered (here the box collapses to a point: nothing closed).
  Scene scene = test::load_builtin("box-wall");
  RenderScene prepared(scene, true);
  const size_t box = closed_box(prepared.geometry());
  for (vec3& p : scene.meshes[box].positions) p = vec3(0.0f, 0.4f, -2.5f);
  const size_t moved[] = {box};
  (void)prepared.update_geometry(moved);
  EXPECT_EQ(prepared.geometry().closed(Executor(2))[box], 0);
}

TEST(Redirection, ATriangleGoesToTheEyeItFacesWhereTheFrustumRankingPicksTheOther) {
  const dvec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);  // counter-clockwise seen from +z
  EyeCamera front, behind;
  front.origin = dvec3(0.2, 0.2, 1.0);
  behind.origin = dvec3(0.2, 0.2, -1.0);
  EXPECT_EQ(facing_share(kRedirectBoth, a, b, c, front, behind), kRedirectLeft);
  EXPECT_EQ(facing_share(kRedirectLeft, a, b, c, front, behind), kRedirectLeft);
  EXPECT_EQ(facing_share(kRedirectRight, a, b, c, front, behind), kRedirectLeft) << "the eye it faces takes it";
  EXPECT_EQ(facing_share(kRedirectRight, a, b, c, front, front), kRedirectRight);
  EXPECT_EQ(facing_share(kRedirectBoth, a, b, c, front, front), kRedirectBoth);
  EXPECT_EQ(facing_share(kRedirectLeft, a, b, c, behind, behind), 0) << "facing neither eye";
}

TEST(Redirection, EveryTriangleOfAManyMeshSceneAsRedirectDecidesAtAnyThreadCount) {
  // The scene's pass projects each vertex once and compares triangles from the stored
  // projections, meshes and triangles in parallel: each decision must be redirect()'s for that
  // triangle alone. spheres: 1000 meshes whose vertices are shared by about six triangles each;
  // the close convergence puts triangles across both frusta's edges.
  const Scene scene = test::load_builtin("spheres");
  const RenderScene prepared(scene);
  const StereoRig rig = test::rig_at(scene, 160, 90, 3.0);
  const EyeCamera left = rig.eye(Eye::left), right = rig.eye(Eye::right);
  const SceneGeometry& geometry = prepared.geometry();
  // The spheres are double-sided and closed: the redirection culls them (those beyond both near
  // planes), the same at any thread count.
  uint64_t spheres_culled = 0;
  const std::vector<uint8_t> culled_by_one = culled_meshes(geometry, rig, Executor(1), true, spheres_culled);
  EXPECT_GT(spheres_culled, 900u);
  std::vector<uint8_t> expected(geometry.triangle_count()), expected_both(geometry.triangle_count());
  size_t by_frustum = 0, clipped_by_both = 0;
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const Mesh& mesh = scene.meshes[m];
    for (size_t t = 0; t < mesh.triangle_count(); ++t) {
      const dvec3 v0(mesh.positions[mesh.indices[3 * t]]), v1(mesh.positions[mesh.indices[3 * t + 1]]),
          v2(mesh.positions[mesh.indices[3 * t + 2]]);
      const bool single_sided = culled_by_one[m] != 0;
      // A culled mesh's triangle goes to no eye that sees its back.
      const auto facing = [&](uint8_t to) { return single_sided ? facing_share(to, v0, v1, v2, left, right) : to; };
      expected[geometry.first_triangle[m] + t] = facing(redirect(left, right, v0, v1, v2, single_sided));
      expected_both[geometry.first_triangle[m] + t] =
          facing(redirect(left, right, v0, v1, v2, single_sided, ClippedRule::both));
      by_frustum += frustum_visibility(left, v0, v1, v2) != frustum_visibility(right, v0, v1, v2) ? 1 : 0;
      clipped_by_both +=
          frustum_visibility(left, v0, v1, v2) < 1.0 && frustum_visibility(right, v0, v1, v2) < 1.0 ? 1 : 0;
    }
  }
  EXPECT_GT(by_frustum, 0u) << "some triangles decided by the frustum comparison";
  EXPECT_GT(clipped_by_both, 0u) << "some triangles clipped by both frusta";
  EXPECT_GT(std::count(expected.begin(), expected.end(), uint8_t{0}), 0) << "some triangles face neither eye";
  for (const int threads : {1, 2, 3}) {
    uint64_t closed_culled = 0;
    const std::vector<uint8_t> culled = culled_meshes(geometry, rig, Executor(threads), true, closed_culled);
    EXPECT_TRUE(culled == culled_by_one) << threads << " threads";
    EXPECT_EQ(closed_culled, spheres_culled) << threads << " threads";
    RedirectionCounts both_counts;
    EXPECT_TRUE(redirect_triangles(geometry, rig, culled, Executor(threads), both_counts, ClippedRule::both) ==
                expected_both)
        << threads << " threads, clipped=both";
    RedirectionCounts counts;
    const std::vector<uint8_t> bits = redirect_triangles(geometry, rig, culled, Executor(threads), counts);
    ASSERT_EQ(bits.size(), expected.size());
    size_t differ = 0;
    for (size_t i = 0; i < bits.size(); ++i) differ += bits[i] != expected[i] ? 1 : 0;
    EXPECT_EQ(differ, 0u) << threads << " threads";
    EXPECT_EQ(counts.left, static_cast<uint64_t>(std::count(expected.begin(), expected.end(), kRedirectLeft)));
    EXPECT_EQ(counts.right, static_cast<uint64_t>(std::count(expected.begin(), expected.end(), kRedirectRight)));
    EXPECT_EQ(counts.both, static_cast<uint64_t>(std::count(expected.begin(), expected.end(), kRedirectBoth)));
    EXPECT_EQ(counts.culled, static_cast<uint64_t>(std::count(expected.begin(), expected.end(), uint8_t{0})));
  }
}

}  // namespace
}  // namespace sb
