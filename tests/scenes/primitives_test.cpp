// Tests of the mesh primitives: counts, unit normals that agree with the winding, closed solids
// with the right volume, and the transform and merge helpers.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>
#include <utility>

#include "renderer/scene.hpp"
#include "scenes/architecture.hpp"
#include "scenes/primitives.hpp"

namespace sb::scenes {
namespace {

constexpr double kPiD = 3.14159265358979323846;

/// Signed volume of a mesh (positive for a closed, outward-facing solid).
double signed_volume(const MeshData& m) {
  double v = 0.0;
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    const dvec3 a(m.positions[m.indices[t]]), b(m.positions[m.indices[t + 1]]), c(m.positions[m.indices[t + 2]]);
    v += glm::dot(a, glm::cross(b, c)) / 6.0;
  }
  return v;
}

/// Structural checks every primitive must pass; returns the fraction of triangles whose winding
/// agrees with their vertex normals.
double check_mesh(const MeshData& m, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_FALSE(m.indices.empty());
  EXPECT_EQ(m.indices.size() % 3, 0u);
  EXPECT_EQ(m.normals.size(), m.positions.size());
  EXPECT_TRUE(m.uvs.empty() || m.uvs.size() == m.positions.size());
  for (const vec3& n : m.normals) EXPECT_NEAR(glm::length(n), 1.0f, 1e-5f);
  size_t agree = 0, counted = 0;
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    const uint32_t a = m.indices[t], b = m.indices[t + 1], c = m.indices[t + 2];
    EXPECT_LT(a, m.positions.size());
    EXPECT_LT(b, m.positions.size());
    EXPECT_LT(c, m.positions.size());
    EXPECT_TRUE(a != b && b != c && a != c) << "triangle " << t / 3 << " repeats a vertex";
    const vec3 g = glm::cross(m.positions[b] - m.positions[a], m.positions[c] - m.positions[a]);
    if (glm::length(g) < 1e-12f) continue;
    ++counted;
    if (glm::dot(g, m.normals[a] + m.normals[b] + m.normals[c]) > 0.0f) ++agree;
  }
  return counted == 0 ? 0.0 : static_cast<double>(agree) / static_cast<double>(counted);
}

TEST(Primitives, BoxIsAClosedSolidWithFlatFaces) {
  const MeshData box = make_box({-1.0f, 0.0f, -2.0f}, {1.0f, 3.0f, 2.0f});
  EXPECT_EQ(box.triangle_count(), 12u);
  EXPECT_EQ(box.vertex_count(), 24u);
  EXPECT_EQ(check_mesh(box, "box"), 1.0);
  EXPECT_NEAR(signed_volume(box), 2.0 * 3.0 * 4.0, 1e-5);
  const Bounds3 b = box.bounds();
  EXPECT_EQ(b.lo, vec3(-1.0f, 0.0f, -2.0f));
  EXPECT_EQ(b.hi, vec3(1.0f, 3.0f, 2.0f));
}

/// A scene mesh of a generated one's positions and triangles.
Mesh as_scene_mesh(const MeshData& data) {
  Mesh m;
  m.positions = data.positions;
  m.indices = data.indices;
  return m;
}

/// A scene mesh of `outward`, and a box from `lo` to `hi` wound inside out beside it.
Mesh with_inside_out_box(const MeshData& outward, const vec3& lo, const vec3& hi) {
  Mesh m = as_scene_mesh(outward);
  const auto first = static_cast<uint32_t>(m.positions.size());
  const MeshData box = make_box(lo, hi);
  for (const vec3& p : box.positions) m.positions.push_back(p);
  for (size_t t = 0; t < box.indices.size(); t += 3)
    for (const size_t k : {0, 2, 1}) m.indices.push_back(first + box.indices[t + k]);
  return m;
}

TEST(Primitives, ClosedSolidsAreClosedAndOpenOrMiswoundMeshesAreNot) {
  // What decides whether an external truth's note on single-sided materials is due: a closed mesh
  // never shows a back face.
  EXPECT_TRUE(as_scene_mesh(make_box({-1.0f, 0.0f, -2.0f}, {1.0f, 3.0f, 2.0f})).is_closed());
  EXPECT_TRUE(as_scene_mesh(make_uv_sphere(0.37f, 24, 12)).is_closed()) << "the seam's repeated vertices count as one";
  EXPECT_FALSE(as_scene_mesh(make_plane({4.0f, 2.0f}, {4, 2}, 0.5f)).is_closed());
  Mesh open = as_scene_mesh(make_box({0.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 1.0f}));
  open.indices.resize(open.indices.size() - 6);  // one face gone
  EXPECT_FALSE(open.is_closed());
  Mesh flipped = as_scene_mesh(make_box({0.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 1.0f}));
  std::swap(flipped.indices[0], flipped.indices[1]);  // one triangle wound the other way
  EXPECT_FALSE(flipped.is_closed());
  Mesh inside_out = as_scene_mesh(make_box({0.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 1.0f}));
  for (size_t t = 0; t < inside_out.indices.size(); t += 3) std::swap(inside_out.indices[t + 1], inside_out.indices[t + 2]);
  EXPECT_FALSE(inside_out.is_closed()) << "closed, but only its back faces show from outside";
  EXPECT_FALSE(Mesh{}.is_closed());
  // Parts: two boxes standing edge to edge (the shared edge met twice each way) are closed; a box
  // beside a smaller inside-out one is not, though the volume of the two together is positive.
  MeshData pair = make_box({0.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 1.0f});
  append_mesh(pair, make_box({1.0f, 1.0f, 0.0f}, {2.0f, 2.0f, 1.0f}));
  EXPECT_TRUE(as_scene_mesh(pair).is_closed()) << "an edge shared by two closed parts";
  EXPECT_FALSE(with_inside_out_box(make_box({0.0f, 0.0f, 0.0f}, {2.0f, 2.0f, 2.0f}), {3.0f, 0.0f, 0.0f}, {3.5f, 0.5f, 0.5f})
                   .is_closed())
      << "one part inside out";
  // ... and so is one touching the other along an edge: parts join only across edges met once each way.
  EXPECT_FALSE(with_inside_out_box(make_box({0.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 1.0f}), {1.0f, 1.0f, 0.0f}, {1.5f, 1.5f, 1.0f})
                   .is_closed())
      << "an inside-out part sharing an edge with an outward one";
  EXPECT_FALSE(with_inside_out_box(make_box({0.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 1.0f}), {1.0f, 1.0f, 1.0f}, {1.5f, 1.5f, 1.5f})
                   .is_closed())
      << "an inside-out part sharing a corner with an outward one";
  Mesh not_finite = as_scene_mesh(make_box({0.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 1.0f}));
  not_finite.positions[0].x = std::nanf("");
  EXPECT_FALSE(not_finite.is_closed());
  Mesh out_of_range = as_scene_mesh(make_box({0.0f, 0.0f, 0.0f}, {1.0f, 1.0f, 1.0f}));
  out_of_range.indices[4] = static_cast<uint32_t>(out_of_range.positions.size());
  EXPECT_FALSE(out_of_range.is_closed());
}

TEST(Primitives, PlaneFacesUp) {
  const MeshData plane = make_plane({4.0f, 2.0f}, {4, 2}, 0.5f);
  EXPECT_EQ(plane.triangle_count(), 16u);
  EXPECT_EQ(plane.vertex_count(), 15u);
  EXPECT_EQ(check_mesh(plane, "plane"), 1.0);
  for (const vec3& n : plane.normals) EXPECT_EQ(n, vec3(0.0f, 1.0f, 0.0f));
  EXPECT_EQ(plane.bounds().lo, vec3(-2.0f, 0.0f, -1.0f));
}

TEST(Primitives, SphereHasExactCountsRadialNormalsAndVolume) {
  const MeshData s = make_uv_sphere(2.0f, 48, 24);
  EXPECT_EQ(s.triangle_count(), 2u * 48u * 23u);
  EXPECT_EQ(check_mesh(s, "sphere"), 1.0);
  for (size_t i = 0; i < s.positions.size(); ++i) {
    EXPECT_NEAR(glm::length(s.positions[i]), 2.0f, 1e-5f);
    EXPECT_GT(glm::dot(s.normals[i], s.positions[i]), 1.99f);
  }
  EXPECT_NEAR(signed_volume(s), 4.0 / 3.0 * kPiD * 8.0, 0.01 * 4.0 / 3.0 * kPiD * 8.0);
}

TEST(Primitives, CylinderAndConeVolumes) {
  const MeshData c = make_cylinder(0.5f, 2.0f, 64);
  EXPECT_EQ(c.triangle_count(), 2u * 64u + 2u * 64u);
  EXPECT_EQ(check_mesh(c, "cylinder"), 1.0);
  EXPECT_NEAR(signed_volume(c), kPiD * 0.25 * 2.0, 0.01 * kPiD * 0.25 * 2.0);
  EXPECT_EQ(c.bounds().lo.y, 0.0f);
  EXPECT_EQ(c.bounds().hi.y, 2.0f);

  const MeshData cone = make_cone(1.0f, 3.0f, 64);
  EXPECT_EQ(check_mesh(cone, "cone"), 1.0);
  EXPECT_NEAR(signed_volume(cone), kPiD * 3.0 / 3.0, 0.01 * kPiD);
}

TEST(Primitives, FlutedCylinderIsGroovedButClosed) {
  CylinderOptions o;
  o.flutes = 20;
  o.flute_depth = 0.08f;
  o.rings = 8;
  const MeshData c = make_cylinder(1.0f, 4.0f, 160, o);
  EXPECT_EQ(c.triangle_count(), 2u * 160u * 8u + 2u * 160u);
  EXPECT_GT(check_mesh(c, "fluted"), 0.999);
  const double plain = kPiD * 4.0;
  const double v = signed_volume(c);
  EXPECT_LT(v, plain);          // the flutes remove material
  EXPECT_GT(v, 0.9 * plain);
  // Mid-height, some vertices lie in a flute, some on a fillet at the full radius.
  float min_r = 2.0f, max_r = 0.0f;
  for (const vec3& p : c.positions)
    if (std::fabs(p.y - 2.0f) < 0.3f) {
      const float r = std::hypot(p.x, p.z);
      min_r = std::min(min_r, r);
      max_r = std::max(max_r, r);
    }
  EXPECT_NEAR(max_r, 1.0f, 1e-4f);
  EXPECT_NEAR(min_r, 0.92f, 0.01f);
}

TEST(Primitives, TorusCountAndVolume) {
  const MeshData t = make_torus(2.0f, 0.5f, 64, 32);
  EXPECT_EQ(t.triangle_count(), 2u * 64u * 32u);
  EXPECT_EQ(check_mesh(t, "torus"), 1.0);
  EXPECT_NEAR(signed_volume(t), 2.0 * kPiD * kPiD * 2.0 * 0.25, 0.01 * 2.0 * kPiD * kPiD * 2.0 * 0.25);
}

TEST(Primitives, LatheOfAClosedProfileIsASolid) {
  // A cylinder of radius 1 and height 2 drawn as a profile, with sharp corners.
  const MeshData m = make_lathe({{0, 0}, {1, 0}, {1, 2}, {0, 2}}, 96, 40.0f);
  EXPECT_EQ(check_mesh(m, "lathe"), 1.0);
  EXPECT_NEAR(signed_volume(m), 2.0 * kPiD, 0.01 * 2.0 * kPiD);
  // The side normals are horizontal (the corners are split, not smoothed).
  for (size_t i = 0; i < m.positions.size(); ++i) {
    if (m.positions[i].y > 0.0f && m.positions[i].y < 2.0f) {
      EXPECT_NEAR(m.normals[i].y, 0.0f, 1e-6f);
    }
  }
}

TEST(Primitives, ArchRingAndPanelVolumes) {
  const MeshData ring = make_arch_ring(1.0f, 1.5f, 0.5f, 64);
  EXPECT_EQ(check_mesh(ring, "arch ring"), 1.0);
  EXPECT_NEAR(signed_volume(ring), 0.5 * kPiD * (1.5 * 1.5 - 1.0) * 0.5, 0.01);

  const float w = 3.0f, h = 2.0f, r = 1.2f, d = 0.6f;
  const MeshData panel = make_arch_panel(w, h, r, d, 48);
  EXPECT_EQ(check_mesh(panel, "arch panel"), 1.0);
  const double expected = (w * h - 0.5 * kPiD * r * r) * d;
  EXPECT_NEAR(signed_volume(panel), expected, 0.005 * expected);
  EXPECT_EQ(panel.bounds().lo, vec3(-1.5f, 0.0f, -0.3f));
  EXPECT_EQ(panel.bounds().hi, vec3(1.5f, 2.0f, 0.3f));
  EXPECT_THROW((void)make_arch_panel(2.0f, 1.0f, 1.5f, 0.5f, 8), std::invalid_argument);
}

TEST(Primitives, TubeFollowsItsPathWithOutwardNormals) {
  std::vector<vec3> path;
  for (int i = 0; i <= 50; ++i) {
    const float t = static_cast<float>(i) / 50.0f;
    path.push_back({std::cos(3.0f * t), 2.0f * t, std::sin(3.0f * t)});
  }
  const MeshData tube = make_tube(path, std::vector<float>(path.size(), 0.1f), 16, true);
  EXPECT_GT(check_mesh(tube, "tube"), 0.999);
  EXPECT_GT(signed_volume(tube), 0.0);
  // Every ring vertex is one radius from its path point.
  for (size_t k = 0; k < path.size(); ++k)
    for (int i = 0; i < 16; ++i) EXPECT_NEAR(glm::length(tube.positions[k * 17 + static_cast<size_t>(i)] - path[k]), 0.1f, 1e-4f);
}

TEST(Primitives, GridSurfaceWeldsWrappedSeams) {
  const MeshData m = make_surface(12, 6, true, false, [](float u, float v) {
    return vec3(std::sin(6.2831853f * u), v, std::cos(6.2831853f * u));
  });
  for (int j = 0; j <= 6; ++j) {
    EXPECT_EQ(m.positions[static_cast<size_t>(j * 13)], m.positions[static_cast<size_t>(j * 13 + 12)]);
    EXPECT_EQ(m.normals[static_cast<size_t>(j * 13)], m.normals[static_cast<size_t>(j * 13 + 12)]);
  }
}

TEST(Primitives, TransformKeepsNormalsUnitAndFrontsOutward) {
  MeshData box = make_box({0, 0, 0}, {1, 1, 1});
  // A mirroring, non-uniform transform: the winding must flip to keep the solid outward.
  transform_mesh(box, translation({5, 0, 0}) * scaling({-2.0f, 1.0f, 3.0f}));
  EXPECT_EQ(check_mesh(box, "mirrored box"), 1.0);
  EXPECT_NEAR(signed_volume(box), 6.0, 1e-4);
  EXPECT_EQ(box.bounds().lo, vec3(3.0f, 0.0f, 0.0f));

  MeshData both = make_box({0, 0, 0}, {1, 1, 1});
  append_mesh(both, make_uv_sphere(0.5f, 8, 4), translation({3, 0, 0}));
  EXPECT_EQ(both.triangle_count(), 12u + 2u * 8u * 3u);
  EXPECT_EQ(check_mesh(both, "merged"), 1.0);
  EXPECT_EQ(both.uvs.size(), both.positions.size());
}

TEST(Primitives, QuarterTurnsAreExact) {
  const vec3 p = vec3(rotation_x(0.5f * static_cast<float>(kPiD)) * vec4(0.0f, 1.0f, 0.0f, 1.0f));
  EXPECT_EQ(p, vec3(0.0f, 0.0f, 1.0f));
  const vec3 q = vec3(rotation_y(static_cast<float>(kPiD)) * vec4(1.0f, 0.0f, 0.0f, 1.0f));
  EXPECT_EQ(q, vec3(-1.0f, 0.0f, 0.0f));
}

TEST(Architecture, PartsAreWellFormed) {
  for (CapitalStyle style : {CapitalStyle::doric, CapitalStyle::ionic, CapitalStyle::bell}) {
    ColumnSpec spec;
    spec.capital = style;
    spec.flutes = style == CapitalStyle::ionic ? 24 : 0;
    spec.segments = 96;
    const MeshData col = make_column(spec);
    EXPECT_GT(check_mesh(col, "column"), 0.99);
    EXPECT_NEAR(col.bounds().hi.y, spec.height, 1e-5f);
    EXPECT_NEAR(col.bounds().lo.y, 0.0f, 1e-6f);
    // The abacus on top is capital_half_width wide; nothing is wider than the plinth.
    float top_half = 0.0f;
    for (const vec3& p : col.positions)
      if (p.y == spec.height) top_half = std::max(top_half, std::fabs(p.x));
    EXPECT_NEAR(top_half, capital_half_width(spec), 1e-5f);
    EXPECT_LE(col.bounds().hi.x, 1.32f * spec.radius + 1e-5f);
  }
  EXPECT_EQ(check_mesh(make_baluster(0.8f, 0.07f, 16), "baluster"), 1.0);
  const MeshData steps = make_steps(4, 3.0f, 0.2f, 0.3f, 1.0f, 1.0f);
  EXPECT_NEAR(steps.bounds().hi.y, 0.8f, 1e-6f);
  EXPECT_GT(signed_volume(steps), 0.0);
  const MeshData leaves = make_leaf_cluster(30, 0.5f, 7);
  EXPECT_GT(check_mesh(leaves, "leaves"), 0.99);
  const MeshData again = make_leaf_cluster(30, 0.5f, 7);
  EXPECT_EQ(leaves.positions, again.positions);
}

}  // namespace
}  // namespace sb::scenes
