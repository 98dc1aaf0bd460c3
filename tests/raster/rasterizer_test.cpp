// The software rasterizer against exact geometry: watertight coverage and the top-left rule,
// the depth test and its tie rule, perspective-correct barycentrics and UV derivatives, near-plane
// clipping, culling, the write mask, determinism, and agreement with brute-force ray casting.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "renderer/error.hpp"
#include "renderer/raster/raster_setup.hpp"
#include "renderer/raster/rasterizer.hpp"
#include "renderer/scene.hpp"

namespace sb {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---- Scenes and cameras built in code ----

/// A pinhole eye at the world origin looking down -Z.
EyeCamera make_eye(int width, int height, double f_px, double cx, double cy, double znear = 0.05) {
  EyeCamera eye;
  eye.width = width;
  eye.height = height;
  eye.f_px = f_px;
  eye.cx = cx;
  eye.cy = cy;
  eye.znear = znear;
  eye.zfar = 1000.0;
  return eye;
}

/// The same eye moved to `pose`.
EyeCamera with_pose(EyeCamera eye, const CameraPose& pose) {
  eye.origin = pose.position;
  eye.right = pose.right;
  eye.up = pose.up;
  eye.back = pose.back;
  return eye;
}

/// The world point seen at continuous pixel (x, y) at linear depth `depth`.
vec3 at(const EyeCamera& eye, double x, double y, double depth) { return vec3(eye.unproject(x, y, depth)); }

/// Appends a triangle mesh; material -1 is double-sided, 0 is the scene's single-sided material.
void add_mesh(Scene& scene, std::vector<vec3> positions, std::vector<uint32_t> indices, int material = -1,
              std::vector<vec2> uvs = {}) {
  Mesh m;
  m.name = "mesh" + std::to_string(scene.meshes.size());
  m.material = material;
  m.positions = std::move(positions);
  m.indices = std::move(indices);
  m.uvs = std::move(uvs);
  scene.meshes.push_back(std::move(m));
}

/// A scene whose material 0 is single-sided and material 1 double-sided.
Scene empty_scene() {
  Scene s;
  s.name = "raster-test";
  Material single;
  single.name = "single";
  single.double_sided = false;
  Material both;
  both.name = "double";
  both.double_sided = true;
  s.materials = {single, both};
  return s;
}

/// One triangle per mesh, each given in pixel coordinates at one depth.
void add_pixel_triangle(Scene& s, const EyeCamera& eye, dvec2 a, dvec2 b, dvec2 c, double depth, int material = -1) {
  add_mesh(s, {at(eye, a.x, a.y, depth), at(eye, b.x, b.y, depth), at(eye, c.x, c.y, depth)}, {0, 1, 2}, material);
}

/// Rasterizes with a fresh executor of `threads` threads.
GBuffer render(const Scene& scene, const EyeCamera& eye, int threads = 1, const RasterOptions& options = {},
               RasterStats* stats = nullptr) {
  const SceneGeometry geometry(scene);
  const Executor executor(threads);
  return rasterize(geometry, eye, executor, options, stats);
}

/// 1 where a pixel holds a primitive.
std::vector<int> coverage(const GBuffer& g) {
  std::vector<int> c(g.prim.size());
  for (size_t i = 0; i < c.size(); ++i) c[i] = g.prim[i] != kNoPrimitiveId ? 1 : 0;
  return c;
}

/// Renders every mesh of the scene on its own and sums the coverage.
std::vector<int> summed_coverage(const Scene& scene, const EyeCamera& eye) {
  std::vector<int> sum(static_cast<size_t>(eye.width) * eye.height, 0);
  for (const Mesh& m : scene.meshes) {
    Scene one = empty_scene();
    one.meshes = {m};
    const std::vector<int> c = coverage(render(one, eye));
    for (size_t i = 0; i < sum.size(); ++i) sum[i] += c[i];
  }
  return sum;
}

// ---- Brute-force reference: exact ray-triangle intersection in double at pixel centres ----

/// The reference at one pixel centre: nearest id, depth and Möller–Trumbore (u, v).
struct RefHit {
  uint32_t prim = kNoPrimitiveId;
  double depth = kInf;
  double b1 = 0.0, b2 = 0.0;
};

/// Nearest hit with depth >= znear, ties to the lower id, back faces of single-sided meshes skipped.
std::vector<RefHit> reference(const Scene& scene, const EyeCamera& eye) {
  const SceneGeometry geometry(scene);
  std::vector<RefHit> out(static_cast<size_t>(eye.width) * eye.height);
  for (int y = 0; y < eye.height; ++y)
    for (int x = 0; x < eye.width; ++x) {
      const dvec3 o = eye.origin;
      const dvec3 d = eye.unproject(x + 0.5, y + 0.5, 1.0) - o;  // t is then the view depth
      RefHit& best = out[static_cast<size_t>(y) * eye.width + x];
      for (size_t m = 0; m < scene.meshes.size(); ++m) {
        const Mesh& mesh = scene.meshes[m];
        for (size_t t = 0; t < mesh.triangle_count(); ++t) {
          const dvec3 v0(mesh.positions[mesh.indices[3 * t]]), v1(mesh.positions[mesh.indices[3 * t + 1]]),
              v2(mesh.positions[mesh.indices[3 * t + 2]]);
          if (geometry.single_sided[m] && !front_facing(v0, v1, v2, o)) continue;
          const dvec3 e1 = v1 - v0, e2 = v2 - v0, p = glm::cross(d, e2);
          const double det = glm::dot(e1, p);
          if (det == 0.0) continue;
          const dvec3 s = o - v0;
          const double u = glm::dot(s, p) / det;
          if (u < 0.0 || u > 1.0) continue;
          const dvec3 q = glm::cross(s, e1);
          const double v = glm::dot(d, q) / det;
          if (v < 0.0 || u + v > 1.0) continue;
          const double depth = glm::dot(e2, q) / det;
          if (depth < eye.znear) continue;
          const uint32_t id = geometry.first_triangle[m] + static_cast<uint32_t>(t);
          if (depth < best.depth || (depth == best.depth && id < best.prim)) best = {id, depth, u, v};
        }
      }
    }
  return out;
}

/// True when pixel (x, y) has an 8-neighbour whose value differs from its own.
template <class F>
bool near_change(int x, int y, int width, int height, F&& value) {
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int nx = x + dx, ny = y + dy;
      if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
      if (value(nx, ny) != value(x, y)) return true;
    }
  return false;
}

/// Compares primitive ids with the reference; returns the agreeing fraction and checks that every
/// disagreement sits on a silhouette of the reference.
double agreement(const GBuffer& g, const std::vector<RefHit>& ref) {
  size_t agree = 0;
  for (int y = 0; y < g.height; ++y)
    for (int x = 0; x < g.width; ++x) {
      const size_t i = g.index(x, y);
      if (g.prim[i] == ref[i].prim) {
        ++agree;
        if (ref[i].prim == kNoPrimitiveId) continue;
        EXPECT_NEAR(g.depth[i], ref[i].depth, 1e-5 * ref[i].depth) << "pixel " << x << "," << y;
        EXPECT_NEAR(g.bary[i].x, ref[i].b1, 1e-4) << "pixel " << x << "," << y;
        EXPECT_NEAR(g.bary[i].y, ref[i].b2, 1e-4) << "pixel " << x << "," << y;
        continue;
      }
      EXPECT_TRUE(near_change(x, y, g.width, g.height, [&](int px, int py) { return ref[g.index(px, py)].prim; }))
          << "pixel " << x << "," << y << " raster " << g.prim[i] << " reference " << ref[i].prim
          << " is not on a silhouette";
    }
  return static_cast<double>(agree) / static_cast<double>(g.prim.size());
}

/// ~count random triangles in front of the eye, 5-40 px across, in four meshes (two single-sided).
Scene random_scene(const EyeCamera& eye, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Scene s = empty_scene();
  for (int m = 0; m < 4; ++m) {
    std::vector<vec3> positions;
    std::vector<uint32_t> indices;
    for (int t = 0; t < count / 4; ++t) {
      const double depth = 2.0 + 8.0 * unit(rng);
      const dvec3 centre = eye.unproject(eye.width * unit(rng), eye.height * unit(rng), depth);
      const double size = depth * (3.0 + 18.0 * unit(rng)) / eye.f_px;  // 3-21 px from the centre
      for (int k = 0; k < 3; ++k) {
        const dvec3 dir = glm::normalize(dvec3(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5) + 1e-9);
        positions.emplace_back(centre + size * dir);
        indices.push_back(static_cast<uint32_t>(indices.size()));
      }
    }
    add_mesh(s, std::move(positions), std::move(indices), m < 2 ? -1 : 0);
  }
  return s;
}

/// A UV sphere of 2 * rings * segments triangles, counter-clockwise seen from outside.
void add_sphere(Scene& s, const dvec3& centre, double radius, int rings, int segments, int material) {
  std::vector<vec3> positions;
  std::vector<vec2> uvs;
  std::vector<uint32_t> indices;
  for (int r = 0; r <= rings; ++r)
    for (int k = 0; k <= segments; ++k) {
      const double theta = kPi * r / rings, phi = 2.0 * kPi * k / segments;
      positions.emplace_back(centre + radius * dvec3(std::sin(theta) * std::cos(phi), std::cos(theta),
                                                     -std::sin(theta) * std::sin(phi)));
      uvs.emplace_back(static_cast<float>(k) / segments, static_cast<float>(r) / rings);
    }
  const auto v = [&](int r, int k) { return static_cast<uint32_t>(r * (segments + 1) + k); };
  for (int r = 0; r < rings; ++r)
    for (int k = 0; k < segments; ++k) {
      indices.insert(indices.end(), {v(r, k), v(r + 1, k), v(r + 1, k + 1)});
      indices.insert(indices.end(), {v(r, k), v(r + 1, k + 1), v(r, k + 1)});
    }
  add_mesh(s, std::move(positions), std::move(indices), material, std::move(uvs));
}

/// Bit-identical G-buffers.
bool same_gbuffer(const GBuffer& a, const GBuffer& b) {
  const auto bytes_equal = [](const auto& x, const auto& y) {
    return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(x[0])) == 0;
  };
  return a.width == b.width && a.height == b.height && bytes_equal(a.depth, b.depth) &&
         bytes_equal(a.prim, b.prim) && bytes_equal(a.bary, b.bary) && bytes_equal(a.duv, b.duv);
}

// ---- Coverage and the fill rule ----

TEST(Rasterizer, FullScreenPairCoversEveryPixelExactlyOnce) {
  const EyeCamera eye = make_eye(64, 64, 64.0, 32.0, 32.0);
  // The shared diagonal runs through the pixel centres (i + 0.5, i + 0.5); one pair per winding.
  for (bool flip : {false, true}) {
    Scene s = empty_scene();
    add_pixel_triangle(s, eye, {0, 0}, flip ? dvec2{0, 64} : dvec2{64, 64}, flip ? dvec2{64, 64} : dvec2{0, 64}, 2.0);
    add_pixel_triangle(s, eye, {0, 0}, flip ? dvec2{64, 64} : dvec2{64, 0}, flip ? dvec2{64, 0} : dvec2{64, 64}, 2.0);
    const std::vector<int> sum = summed_coverage(s, eye);
    for (size_t i = 0; i < sum.size(); ++i) ASSERT_EQ(sum[i], 1) << "pixel " << i % 64 << "," << i / 64;
    const GBuffer both = render(s, eye);
    EXPECT_EQ(std::count(both.prim.begin(), both.prim.end(), kNoPrimitiveId), 0);
  }
}

TEST(Rasterizer, FanAroundAPixelCentreIsWatertight) {
  // Spokes from a pixel centre through pixel centres: horizontal, vertical, diagonal, slope 1/2.
  // Radius 20 exercises the row-span scan of wide triangles, radius 2 the per-pixel scan.
  const EyeCamera eye = make_eye(64, 64, 64.0, 32.0, 32.0);
  const dvec2 c{32.5, 32.5};
  const std::vector<dvec2> rim = {{2, 0},   {2, 1},   {2, 2},   {0, 2},  {-2, 2},
                                  {-2, 0}, {-2, -2}, {-1, -2}, {0, -2}, {2, -2}};
  for (double radius : {20.0, 2.0}) {
    Scene s = empty_scene();
    for (size_t k = 0; k < rim.size(); ++k) {
      const dvec2 a = c + 0.5 * radius * rim[k], b = c + 0.5 * radius * rim[(k + 1) % rim.size()];
      // Alternate windings: the rasterizer must not care.
      if (k % 2 == 0)
        add_pixel_triangle(s, eye, c, a, b, 3.0);
      else
        add_pixel_triangle(s, eye, c, b, a, 3.0);
    }
    const std::vector<int> sum = summed_coverage(s, eye);
    const std::vector<int> all = coverage(render(s, eye));
    for (size_t i = 0; i < sum.size(); ++i) {
      ASSERT_LE(sum[i], 1) << "radius " << radius << " pixel " << i % 64 << "," << i / 64 << " covered twice";
      ASSERT_EQ(sum[i], all[i]) << "radius " << radius << " pixel " << i % 64 << "," << i / 64;
    }
    // The centre pixel lies on every spoke and must still be covered once; so must the interior.
    EXPECT_EQ(sum[32 * 64 + 32], 1);
    const int r = static_cast<int>(radius);
    for (int y = 33 - r; y < 32 + r; ++y)
      for (int x = 33 - r; x < 32 + r; ++x) EXPECT_EQ(sum[static_cast<size_t>(y) * 64 + x], 1) << x << "," << y;
  }
}

TEST(Rasterizer, TopLeftRuleOnHorizontalAndVerticalEdges) {
  const EyeCamera eye = make_eye(40, 40, 40.0, 20.0, 20.0);
  // Upper-left half of the square [5.5, 20.5] x [10.5, 25.5]: its top edge (y = 10.5) and left
  // edge (x = 5.5) are covered, its hypotenuse (x + y = 31) is a right edge and is not.
  // The lower-right half has the hypotenuse as its left edge and bottom and right edges.
  for (bool flip : {false, true}) {
    Scene upper = empty_scene(), lower = empty_scene();
    if (flip) {
      add_pixel_triangle(upper, eye, {5.5, 10.5}, {5.5, 25.5}, {20.5, 10.5}, 2.0);
      add_pixel_triangle(lower, eye, {5.5, 25.5}, {20.5, 10.5}, {20.5, 25.5}, 2.0);
    } else {
      add_pixel_triangle(upper, eye, {5.5, 10.5}, {20.5, 10.5}, {5.5, 25.5}, 2.0);
      add_pixel_triangle(lower, eye, {5.5, 25.5}, {20.5, 25.5}, {20.5, 10.5}, 2.0);
    }
    const GBuffer gu = render(upper, eye), gl = render(lower, eye);
    for (int y = 0; y < 40; ++y)
      for (int x = 0; x < 40; ++x) {
        const bool in_upper = x >= 5 && y >= 10 && x + y < 30;
        const bool in_lower = x <= 19 && y <= 24 && x + y >= 30;
        EXPECT_EQ(gu.prim[gu.index(x, y)] != kNoPrimitiveId, in_upper) << "upper " << x << "," << y;
        EXPECT_EQ(gl.prim[gl.index(x, y)] != kNoPrimitiveId, in_lower) << "lower " << x << "," << y;
      }
  }
}

TEST(Rasterizer, DegenerateAndSubPixelTrianglesProduceNothing) {
  const EyeCamera eye = make_eye(32, 32, 32.0, 16.0, 16.0);
  Scene s = empty_scene();
  add_pixel_triangle(s, eye, {4.5, 4.5}, {20.5, 20.5}, {12.5, 12.5}, 2.0);  // collinear
  add_pixel_triangle(s, eye, {8.6, 8.6}, {9.4, 8.6}, {8.6, 9.4}, 2.0);     // between centres
  RasterStats stats;
  const GBuffer g = render(s, eye, 1, {}, &stats);
  EXPECT_EQ(std::count(g.prim.begin(), g.prim.end(), kNoPrimitiveId), 32 * 32);
  EXPECT_EQ(stats.triangles_submitted, 2u);
  EXPECT_EQ(stats.triangles_rasterized, 0u);
}

// ---- Depth ----

TEST(Rasterizer, DepthTestPicksTheNearerTriangleAndTiesGoToTheLowerId) {
  const EyeCamera eye = make_eye(48, 32, 40.0, 24.0, 16.0);
  for (bool near_first : {true, false}) {
    Scene s = empty_scene();
    const double d0 = near_first ? 2.0 : 3.0, d1 = near_first ? 3.0 : 2.0;
    add_pixel_triangle(s, eye, {-5, -5}, {60, -5}, {-5, 60}, d0);
    add_pixel_triangle(s, eye, {-5, -5}, {60, -5}, {-5, 60}, d1);
    const GBuffer g = render(s, eye);
    const uint32_t nearer = near_first ? 0u : 1u;
    for (size_t i = 0; i < g.prim.size(); ++i) {
      if (g.prim[i] == kNoPrimitiveId) continue;
      ASSERT_EQ(g.prim[i], nearer);
      ASSERT_NEAR(g.depth[i], 2.0, 2e-6);
    }
  }
  // Identical triangles in three meshes: equal depths everywhere, the lowest id wins.
  Scene ties = empty_scene();
  for (int k = 0; k < 3; ++k) add_pixel_triangle(ties, eye, {3.3, 2.1}, {44.7, 9.9}, {12.2, 30.8}, 2.5);
  // A farther triangle takes the lowest id: the nearer, tied ones must still win.
  add_mesh(ties, {at(eye, 0, 0, 9.0), at(eye, 48, 0, 9.0), at(eye, 0, 32, 9.0)}, {0, 1, 2});
  std::rotate(ties.meshes.begin(), ties.meshes.begin() + 3, ties.meshes.end());
  for (int threads : {1, 2}) {
    const GBuffer g = render(ties, eye, threads, RasterOptions{16, nullptr});
    size_t covered = 0;
    for (size_t i = 0; i < g.prim.size(); ++i)
      if (g.prim[i] != kNoPrimitiveId && g.depth[i] < 5.0) {
        ASSERT_EQ(g.prim[i], 1u) << "tie must go to the lowest of ids 1, 2, 3";
        ++covered;
      }
    EXPECT_GT(covered, 200u);
  }
}

TEST(Rasterizer, PerspectiveCorrectBarycentricsReconstructPointsOnTheEyeRay) {
  RigParams params;
  params.width = 160;
  params.height = 120;
  const StereoRig rig(CameraPose::look_at({0.4, 1.2, 2.5}, {-0.3, 0.1, -4.0}), params);
  const EyeCamera eye = rig.eye(Eye::left);
  // A strongly slanted triangle from 0.8 m to 30 m.
  Scene s = empty_scene();
  add_mesh(s, {at(eye, -40, 130, 0.8), at(eye, 200, 100, 1.5), at(eye, 70, -10, 30.0)}, {0, 1, 2});
  const GBuffer g = render(s, eye);
  const Mesh& m = s.meshes[0];
  size_t covered = 0;
  for (int y = 0; y < eye.height; ++y)
    for (int x = 0; x < eye.width; ++x) {
      const size_t i = g.index(x, y);
      if (g.prim[i] == kNoPrimitiveId) continue;
      ++covered;
      const dvec2 b(g.bary[i]);
      const dvec3 p = (1.0 - b.x - b.y) * dvec3(m.positions[0]) + b.x * dvec3(m.positions[1]) +
                      b.y * dvec3(m.positions[2]);
      const dvec3 rel = p - eye.origin;
      const dvec3 dir = eye.ray_direction(x + 0.5, y + 0.5);
      const double off_ray = glm::length(rel - glm::dot(rel, dir) * dir);
      ASSERT_LT(off_ray, 1e-4 * glm::length(rel)) << "pixel " << x << "," << y;
      const double view_depth = -glm::dot(rel, eye.back);
      ASSERT_NEAR(g.depth[i], view_depth, 1e-5 * view_depth) << "pixel " << x << "," << y;
    }
  EXPECT_GT(covered, 5000u);
}

// ---- Clipping and culling ----

TEST(Rasterizer, TriangleCrossingTheNearPlaneIsClipped) {
  const EyeCamera eye = make_eye(160, 90, 120.0, 80.0, 45.0, 0.5);
  Scene s = empty_scene();
  // One vertex behind the camera, one just in front of the near plane, one far away.
  add_mesh(s, {vec3(-0.6f, -0.3f, 1.0f), vec3(0.9f, -0.5f, -0.7f), vec3(0.1f, 0.8f, -6.0f)}, {0, 1, 2});
  RasterStats stats;
  const GBuffer g = render(s, eye, 2, {}, &stats);
  EXPECT_EQ(stats.clipped_near, 1u);
  EXPECT_GE(stats.triangles_rasterized, 1u);
  EXPECT_LE(stats.triangles_rasterized, 2u);
  const std::vector<RefHit> ref = reference(s, eye);
  size_t covered = 0, mismatched = 0;
  const Mesh& m = s.meshes[0];
  for (int y = 0; y < g.height; ++y)
    for (int x = 0; x < g.width; ++x) {
      const size_t i = g.index(x, y);
      const bool raster = g.prim[i] != kNoPrimitiveId, exact = ref[i].prim != kNoPrimitiveId;
      covered += raster ? 1 : 0;
      if (raster != exact) {
        ++mismatched;
        EXPECT_TRUE(near_change(x, y, g.width, g.height, [&](int px, int py) { return ref[g.index(px, py)].prim; }))
            << "pixel " << x << "," << y << " disagrees away from an edge";
      }
      if (!raster) continue;
      // Barycentrics refer to the original, unclipped vertices.
      EXPECT_GE(g.depth[i], eye.znear * (1.0 - 1e-6));
      const dvec2 b(g.bary[i]);
      const dvec3 p = (1.0 - b.x - b.y) * dvec3(m.positions[0]) + b.x * dvec3(m.positions[1]) +
                      b.y * dvec3(m.positions[2]);
      EXPECT_NEAR(-glm::dot(p - eye.origin, eye.back), g.depth[i], 1e-5 * g.depth[i]);
      const dvec3 px = eye.project(p);
      EXPECT_NEAR(px.x, x + 0.5, 1e-3);
      EXPECT_NEAR(px.y, y + 0.5, 1e-3);
    }
  EXPECT_GT(covered, 2000u);
  EXPECT_LT(mismatched, 40u);
}

TEST(Rasterizer, HugeTrianglesBeyondTheGuardBandMatchTheReference) {
  // A ground plane 2 km across seen from eye height, crossing the near plane: vertices project
  // far beyond the fixed-point guard band.
  const EyeCamera eye =
      with_pose(make_eye(160, 90, 100.0, 80.0, 45.0, 0.05), CameraPose::look_at({0.0, 1.7, 0.0}, {0.3, 1.2, -5.0}));
  Scene s = empty_scene();
  add_mesh(s, {vec3(-1000, 0, 1000), vec3(1000, 0, 1000), vec3(1000, 0, -1000), vec3(-1000, 0, -1000)},
           {0, 1, 2, 0, 2, 3}, 0);
  // A pole standing on it, to check depth ordering against the plane.
  add_mesh(s, {vec3(0.2f, -1, -4), vec3(0.5f, -1, -4), vec3(0.35f, 3, -4)}, {0, 1, 2});
  RasterStats stats;
  const GBuffer g = render(s, eye, 2, {}, &stats);
  EXPECT_EQ(stats.clipped_near, 2u);
  const std::vector<RefHit> ref = reference(s, eye);
  EXPECT_GE(agreement(g, ref), 0.995);
}

TEST(Rasterizer, VerticesBeyondTheGuardBandAreClippedExactly) {
  // In front of the near plane but projecting ~10^5 px off-screen: clipped to the guard band only.
  const EyeCamera eye = make_eye(160, 90, 100.0, 80.0, 45.0, 0.05);
  Scene s = empty_scene();
  add_mesh(s, {vec3(-100.0f, -0.05f, -0.1f), vec3(100.0f, -0.02f, -0.1f), vec3(0.3f, 0.6f, -4.0f)}, {0, 1, 2});
  const raster::VertexTransform transform(eye);
  for (const vec3& p : s.meshes[0].positions) {
    const uint32_t code = transform.project(p).outcode;
    EXPECT_EQ(code & raster::kOutNear, 0u);
    if (p.z > -1.0f) {
      EXPECT_NE(code & (raster::kOutGuardLeft | raster::kOutGuardRight), 0u);
    }
  }
  RasterStats stats;
  const GBuffer g = render(s, eye, 1, {}, &stats);
  EXPECT_EQ(stats.clipped_near, 0u);
  EXPECT_GE(stats.triangles_rasterized, 2u);  // the clipped polygon is a fan
  EXPECT_GE(agreement(g, reference(s, eye)), 0.995);
  EXPECT_GT(std::count(g.prim.begin(), g.prim.end(), 0u), 1000);
}

TEST(Rasterizer, TrianglesOutsideTheFrustumAreCulled) {
  const EyeCamera eye = make_eye(64, 48, 50.0, 32.0, 24.0, 0.1);
  Scene s = empty_scene();
  add_mesh(s, {vec3(-1, -1, -0.05f), vec3(1, -1, -0.08f), vec3(0, 1, 0.5f)}, {0, 1, 2});  // wholly behind znear
  add_pixel_triangle(s, eye, {-30, 5}, {-2, 10}, {-10, 40}, 2.0);                       // left of the image
  add_pixel_triangle(s, eye, {5, 50}, {60, 49}, {30, 90}, 2.0);                         // below the image
  add_pixel_triangle(s, eye, {10, 10}, {30, 10}, {10, 30}, 2.0);                        // visible
  RasterStats stats;
  const GBuffer g = render(s, eye, 1, {}, &stats);
  EXPECT_EQ(stats.triangles_submitted, 4u);
  EXPECT_EQ(stats.culled_frustum, 3u);
  EXPECT_EQ(stats.clipped_near, 0u);
  EXPECT_EQ(stats.triangles_rasterized, 1u);
  for (uint32_t p : g.prim) EXPECT_TRUE(p == kNoPrimitiveId || p == 3u);
}

TEST(Rasterizer, BackFacesAreCulledOnlyForSingleSidedMeshes) {
  const EyeCamera eye = make_eye(64, 48, 50.0, 32.0, 24.0);
  // Seen from the eye, (a, c, b) is counter-clockwise (front-facing) in y-up world terms.
  const dvec2 a{10, 10}, b{50, 12}, c{20, 40};
  for (int material : {-1, 0, 1}) {
    for (bool front : {true, false}) {
      Scene s = empty_scene();
      if (front)
        add_pixel_triangle(s, eye, a, c, b, 2.0, material);
      else
        add_pixel_triangle(s, eye, a, b, c, 2.0, material);
      const Mesh& m = s.meshes[0];
      ASSERT_EQ(front_facing(dvec3(m.positions[0]), dvec3(m.positions[1]), dvec3(m.positions[2]), eye.origin), front);
      RasterStats stats;
      const GBuffer g = render(s, eye, 1, {}, &stats);
      const bool culled = material == 0 && !front;
      const auto covered = std::count_if(g.prim.begin(), g.prim.end(), [](uint32_t p) { return p == 0u; });
      EXPECT_EQ(covered == 0, culled) << "material " << material << " front " << front;
      EXPECT_EQ(stats.culled_backface, culled ? 1u : 0u);
    }
  }
}

// ---- Attributes ----

TEST(Rasterizer, UvDerivativesMatchFiniteDifferences) {
  const EyeCamera eye =
      with_pose(make_eye(128, 96, 110.0, 70.0, 40.0), CameraPose::look_at({0.0, 1.0, 1.0}, {0.2, 0.0, -3.0}));
  Scene s = empty_scene();
  add_mesh(s, {vec3(-3, 0, 0), vec3(3, 0, 0.5f), vec3(0.5f, 0.2f, -9)}, {0, 1, 2}, -1,
           {vec2(0.0f, 0.0f), vec2(4.0f, 0.5f), vec2(1.0f, 7.0f)});
  add_mesh(s, {at(eye, 4, 4, 2.0), at(eye, 40, 4, 2.0), at(eye, 4, 30, 2.0)}, {0, 1, 2});  // no UVs
  const GBuffer g = render(s, eye);
  const Mesh& m = s.meshes[0];
  const auto uv_at = [&](size_t i) {
    const dvec2 b(g.bary[i]);
    return (1.0 - b.x - b.y) * dvec2(m.uvs[0]) + b.x * dvec2(m.uvs[1]) + b.y * dvec2(m.uvs[2]);
  };
  size_t checked = 0;
  EXPECT_GT(std::count(g.prim.begin(), g.prim.end(), 1u), 100);
  for (int y = 1; y + 1 < eye.height; ++y)
    for (int x = 1; x + 1 < eye.width; ++x) {
      const size_t i = g.index(x, y);
      if (g.prim[i] == 1u) {
        EXPECT_EQ(g.duv[i], vec4(0.0f));
        continue;
      }
      if (g.prim[i] != 0u || g.prim[g.index(x - 1, y)] != 0u || g.prim[g.index(x + 1, y)] != 0u ||
          g.prim[g.index(x, y - 1)] != 0u || g.prim[g.index(x, y + 1)] != 0u)
        continue;
      // Central differences of the reconstructed UVs. Along a row or column u = (a t + b) / (c t + d),
      // whose central difference is exactly u' / (1 - r^2) with r = (dQ/dt) / Q, Q = 1/depth; the
      // depth buffer gives r, so the comparison is exact up to rounding.
      const auto q_at = [&](int px, int py) { return 1.0 / g.depth[g.index(px, py)]; };
      const double rx = (q_at(x + 1, y) - q_at(x - 1, y)) / (2.0 * q_at(x, y));
      const double ry = (q_at(x, y + 1) - q_at(x, y - 1)) / (2.0 * q_at(x, y));
      const dvec2 ddx = 0.5 * (uv_at(g.index(x + 1, y)) - uv_at(g.index(x - 1, y))) * (1.0 - rx * rx);
      const dvec2 ddy = 0.5 * (uv_at(g.index(x, y + 1)) - uv_at(g.index(x, y - 1))) * (1.0 - ry * ry);
      const double tolerance = 1e-4 * (glm::length(ddx) + glm::length(ddy));
      const vec4 d = g.duv[i];
      EXPECT_NEAR(d.x, ddx.x, tolerance) << x << "," << y;
      EXPECT_NEAR(d.y, ddx.y, tolerance) << x << "," << y;
      EXPECT_NEAR(d.z, ddy.x, tolerance) << x << "," << y;
      EXPECT_NEAR(d.w, ddy.y, tolerance) << x << "," << y;
      ++checked;
    }
  EXPECT_GT(checked, 1000u);
}

TEST(Rasterizer, WriteMaskLeavesMaskedPixelsUntouched) {
  const EyeCamera eye = make_eye(96, 64, 80.0, 48.0, 32.0);
  const Scene s = random_scene(eye, 120, 7);
  std::vector<uint8_t> mask(96 * 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 96; ++x) mask[static_cast<size_t>(y) * 96 + x] = ((x / 5 + y / 3) % 2 == 0) ? 1 : 0;
  RasterStats full_stats, masked_stats;
  const GBuffer full = render(s, eye, 2, {}, &full_stats);
  const GBuffer masked = render(s, eye, 2, RasterOptions{16, mask.data()}, &masked_stats);
  for (size_t i = 0; i < mask.size(); ++i) {
    if (mask[i] == 0) {
      ASSERT_EQ(masked.prim[i], kNoPrimitiveId);
      ASSERT_TRUE(std::isinf(masked.depth[i]));
      ASSERT_EQ(masked.bary[i], vec2(0.0f));
      ASSERT_EQ(masked.duv[i], vec4(0.0f));
    } else {
      ASSERT_EQ(masked.prim[i], full.prim[i]);
      ASSERT_EQ(masked.depth[i], full.depth[i]);
      ASSERT_EQ(masked.bary[i], full.bary[i]);
    }
  }
  // Every triangle is still processed; only fragments are masked.
  EXPECT_EQ(masked_stats.triangles_rasterized, full_stats.triangles_rasterized);
  EXPECT_LT(masked_stats.fragments_tested, full_stats.fragments_tested);
}

// ---- Determinism and cameras ----

TEST(Rasterizer, BitIdenticalForAnyThreadCountAndTileSize) {
  const EyeCamera eye =
      with_pose(make_eye(301, 187, 200.0, 160.3, 90.1, 0.1), CameraPose::look_at({0.1, 0.2, 0.3}, {0.0, 0.0, -5.0}));
  Scene s = random_scene(eye, 2000, 11);
  // Coincident duplicates (exact depth ties) and a triangle crossing the near plane.
  s.meshes.push_back(s.meshes[0]);
  add_mesh(s, {vec3(-0.5f, -0.4f, 0.8f), vec3(0.7f, -0.2f, -0.5f), vec3(0.0f, 0.6f, -4.0f)}, {0, 1, 2});
  const GBuffer expected = render(s, eye, 1, RasterOptions{64, nullptr});
  for (int threads : {1, 2, 3})
    for (int tile : {16, 64, 128}) {
      RasterStats stats;
      const GBuffer g = render(s, eye, threads, RasterOptions{tile, nullptr}, &stats);
      EXPECT_TRUE(same_gbuffer(g, expected)) << threads << " threads, tile " << tile;
      EXPECT_EQ(stats.clipped_near, 1u);
    }
}

TEST(Rasterizer, OffAxisEyeMatchesProjectAndTheReference) {
  RigParams params;
  params.width = 160;
  params.height = 90;
  params.interaxial = 0.3;
  params.convergence = 1.5;
  const StereoRig rig(CameraPose::look_at({0.5, 0.5, 1.0}, {0.0, 0.0, -6.0}), params);
  for (Eye which : {Eye::left, Eye::right}) {
    const EyeCamera eye = rig.eye(which);
    ASSERT_GT(std::abs(eye.cx - 80.0), 5.0);
    // A small triangle lands where project() says it does.
    Scene one = empty_scene();
    const dvec3 centre = eye.unproject(30.5, 60.5, 3.0);
    add_mesh(one, {vec3(centre + dvec3(-0.05, -0.05, 0)), vec3(centre + dvec3(0.05, -0.05, 0)),
                   vec3(centre + dvec3(0, 0.05, 0))},
             {0, 1, 2});
    const GBuffer g1 = render(one, eye);
    EXPECT_EQ(g1.prim[g1.index(30, 60)], 0u);
    EXPECT_GE(agreement(g1, reference(one, eye)), 0.999);
    // A random scene agrees with exact ray casting.
    const Scene s = random_scene(eye, 200, which == Eye::left ? 3u : 4u);
    EXPECT_GE(agreement(render(s, eye, 2), reference(s, eye)), 0.995);
  }
}

TEST(Rasterizer, AgreesWithBruteForceRayCasting) {
  const EyeCamera eye = make_eye(160, 90, 100.0, 80.0, 45.0);
  for (unsigned seed : {1u, 2u}) {
    const Scene s = random_scene(eye, 200, seed);
    RasterStats stats;
    const GBuffer g = render(s, eye, 2, RasterOptions{16, nullptr}, &stats);
    const double fraction = agreement(g, reference(s, eye));
    EXPECT_GE(fraction, 0.995) << "seed " << seed;
    EXPECT_GT(stats.culled_backface, 10u);  // half of the single-sided triangles face away
    std::printf("[ raster   ] seed %u: %.4f %% of pixels agree with exact ray casting\n", seed, 100.0 * fraction);
  }
}

// ---- Errors ----

TEST(Rasterizer, RejectsBadOptionsAndIndices) {
  const EyeCamera eye = make_eye(16, 16, 16.0, 8.0, 8.0);
  Scene s = empty_scene();
  add_pixel_triangle(s, eye, {1, 1}, {10, 1}, {1, 10}, 2.0);
  EXPECT_THROW((void)render(s, eye, 1, RasterOptions{0, nullptr}), InputError);
  EyeCamera bad = eye;
  bad.width = 0;
  EXPECT_THROW((void)render(s, bad), InputError);
  s.meshes[0].indices[2] = 7;
  EXPECT_THROW((void)render(s, eye), InputError);
}

TEST(Rasterizer, NonFiniteVerticesDropTheirTriangles) {
  const EyeCamera eye = make_eye(16, 16, 16.0, 8.0, 8.0);
  Scene s = empty_scene();
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  add_mesh(s, {at(eye, 1, 1, 2.0), at(eye, 15, 1, 2.0), vec3(nan, 0.0f, -2.0f)}, {0, 1, 2});
  add_mesh(s, {at(eye, 1, 1, 2.0), vec3(0.0f, inf, -2.0f), at(eye, 1, 15, 2.0)}, {0, 1, 2});
  add_pixel_triangle(s, eye, {1, 1}, {15, 15}, {1, 15}, 3.0);
  RasterStats stats;
  const GBuffer g = render(s, eye, 2, {}, &stats);
  EXPECT_EQ(stats.culled_frustum, 2u);
  for (uint32_t p : g.prim) EXPECT_TRUE(p == kNoPrimitiveId || p == 2u);
}

// ---- Performance (printed, never asserted: DESIGN §8) ----

TEST(Rasterizer, MillionTrianglesAt1080p) {
  Scene s = empty_scene();
  add_sphere(s, {-1.5, 0.0, -5.0}, 1.8, 250, 500, 0);
  add_sphere(s, {1.6, 0.2, -6.0}, 2.0, 250, 500, 1);
  add_sphere(s, {0.0, 1.0, -8.5}, 2.6, 250, 500, 0);
  add_sphere(s, {0.2, -1.4, -4.2}, 1.1, 250, 500, -1);
  RigParams params;  // 1920x1080, 40 degrees
  const StereoRig rig(CameraPose::look_at({0.0, 0.0, 0.5}, {0.0, 0.0, -5.0}), params);
  const EyeCamera eye = rig.eye(Eye::left);
  const SceneGeometry geometry(s);
  ASSERT_EQ(geometry.triangle_count(), 1000000u);

  GBuffer first;
  for (int threads : {1, 2}) {
    const Executor executor(threads);
    double best = kInf;
    RasterStats stats;
    GBuffer g;
    for (int rep = 0; rep < 3; ++rep) {
      const auto t0 = std::chrono::steady_clock::now();
      g = rasterize(geometry, eye, executor, {}, &stats);
      best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    std::printf("[ raster   ] 1M triangles at 1920x1080, %d thread(s): %.1f ms (best of 3); %llu rasterized, "
                "%llu back faces culled, %llu fragments tested\n",
                threads, 1e3 * best, static_cast<unsigned long long>(stats.triangles_rasterized),
                static_cast<unsigned long long>(stats.culled_backface),
                static_cast<unsigned long long>(stats.fragments_tested));
    EXPECT_EQ(stats.triangles_submitted, 1000000u);
    if (threads == 1) {
      first = std::move(g);
      const auto covered =
          std::count_if(first.prim.begin(), first.prim.end(), [](uint32_t p) { return p != kNoPrimitiveId; });
      EXPECT_GT(covered, 1920 * 1080 / 4);
    } else {
      EXPECT_TRUE(same_gbuffer(g, first));
    }
  }
}

}  // namespace
}  // namespace sb
