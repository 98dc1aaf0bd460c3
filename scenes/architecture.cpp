// Shared architectural parts for the building scenes.
#include "scenes/architecture.hpp"

#include <algorithm>
#include <cmath>

#include "scenes/procedural.hpp"

namespace sb::scenes {

namespace {

constexpr float kPiF = static_cast<float>(kPi);

/// Appends an arc of a profile: centre c, radius r, from angle a0 to a1 (radians, in the (r, y)
/// plane, 0 = outwards), `n` steps, skipping the first point.
void arc(std::vector<vec2>& profile, const vec2& c, float r, float a0, float a1, int n) {
  for (int i = 1; i <= n; ++i) {
    const float a = a0 + (a1 - a0) * static_cast<float>(i) / static_cast<float>(n);
    profile.push_back(c + r * vec2(std::cos(a), std::sin(a)));
  }
}

struct ColumnHeights {
  float plinth, base, capital, shaft;
};

ColumnHeights column_heights(const ColumnSpec& s) {
  ColumnHeights h{};
  h.plinth = s.plinth ? 0.3f * s.radius : 0.0f;
  h.base = 0.46f * s.radius;
  h.capital = s.capital == CapitalStyle::bell ? 1.0f * s.radius : 0.7f * s.radius;
  h.shaft = std::max(0.1f, s.height - h.plinth - h.base - h.capital);
  return h;
}

}  // namespace

float capital_half_width(const ColumnSpec& s) { return 1.45f * s.radius * std::max(s.taper, 0.8f); }

MeshData make_column(const ColumnSpec& s) {
  const ColumnHeights h = column_heights(s);
  const float r = s.radius, rt = s.radius * s.taper;
  const float uv = s.uv_per_meter;
  MeshData m;
  // Square plinth.
  if (s.plinth) append_mesh(m, make_box({-1.32f * r, 0.0f, -1.32f * r}, {1.32f * r, h.plinth, 1.32f * r}, uv));
  // Attic base: lower torus, scotia, upper torus.
  {
    const float y0 = h.plinth;
    std::vector<vec2> p = {{0.0f, y0}, {1.16f * r, y0}};
    arc(p, {1.16f * r, y0 + 0.12f * r}, 0.12f * r, -0.5f * kPiF, 0.5f * kPiF, 8);
    p.push_back({1.0f * r, y0 + 0.25f * r});
    arc(p, {1.0f * r, y0 + 0.31f * r}, 0.06f * r, -0.5f * kPiF, -1.3f * kPiF, 5);  // concave scotia
    p.push_back({1.06f * r, y0 + 0.36f * r});
    arc(p, {1.02f * r, y0 + 0.4f * r}, 0.06f * r, -0.5f * kPiF, 0.5f * kPiF, 6);
    p.push_back({0.0f, y0 + h.base});
    append_mesh(m, make_lathe(p, s.segments, 50.0f, uv));
  }
  // Shaft.
  {
    CylinderOptions o;
    o.radius_top = rt;
    o.rings = s.rings;
    // Capped, though the caps lie hidden in the base and the capital: the column is then a closed
    // solid, which lets Kim's redirection cull its back faces (culled_meshes).
    o.caps = true;
    o.flutes = s.flutes;
    o.flute_depth = s.flute_depth;
    o.uv_per_meter = uv;
    append_mesh(m, make_cylinder(r, h.shaft, s.segments, o), translation({0.0f, h.plinth + h.base, 0.0f}));
  }
  // Capital.
  const float yc = h.plinth + h.base + h.shaft;
  const float half = capital_half_width(s);
  const float abacus = s.capital == CapitalStyle::bell ? 0.3f * r : 0.2f * r;
  {
    std::vector<vec2> p = {{0.0f, yc - 0.02f * r}, {rt, yc - 0.02f * r}};
    arc(p, {rt, yc + 0.06f * r}, 0.06f * r, -0.5f * kPiF, 0.5f * kPiF, 6);  // astragal
    const float top = s.height - abacus;
    const float flare = s.capital == CapitalStyle::bell ? 1.05f * half : 0.95f * half;
    const int steps = 8;
    for (int i = 1; i <= steps; ++i) {
      const float t = static_cast<float>(i) / steps;
      // Echinus: convex (doric, ionic) or concave (bell) flare.
      const float shape = s.capital == CapitalStyle::bell ? t * t : std::sqrt(t);
      p.push_back({glm::mix(rt, flare, shape), glm::mix(yc + 0.12f * r, top, t)});
    }
    p.push_back({0.0f, top});
    append_mesh(m, make_lathe(p, s.segments, 40.0f, uv));
    append_mesh(m, make_box({-half, top, -half}, {half, s.height, half}, uv));
  }
  if (s.capital == CapitalStyle::ionic) {
    // Volutes: a spiral scroll on the front and the back at each side, joined by a bolster.
    const float vr = 0.36f * r, y = s.height - abacus - 0.3f * r;
    for (float side : {-1.0f, 1.0f}) {
      const float x = side * (half - 0.35f * r);
      for (float face : {-1.0f, 1.0f}) {
        std::vector<vec3> spiral;
        std::vector<float> radii;
        const int n = 40;
        for (int i = 0; i <= n; ++i) {
          const float t = static_cast<float>(i) / n;
          const float a = t * 4.0f * kPiF;  // two turns winding inwards
          const float rr = vr * (1.0f - 0.8f * t);
          spiral.push_back({x + side * rr * std::sin(a), y + rr * std::cos(a), face * (half - 0.05f * r)});
          radii.push_back(0.07f * r * (1.0f - 0.5f * t));
        }
        append_mesh(m, make_tube(spiral, radii, 10, true));
      }
      CylinderOptions o;
      o.uv_per_meter = uv;
      append_mesh(m, make_cylinder(0.8f * vr, 2.0f * half - 0.1f * r, 20, o),
                  translation({x, y, half - 0.05f * r}) * rotation_x(-0.5f * kPiF));
    }
  }
  return m;
}

MeshData make_baluster(float height, float radius, int segments) {
  const float h = height, r = radius;
  // Square-ish foot and head are left to the rails; the turned body is a vase with a neck.
  std::vector<vec2> p = {{0.0f, 0.0f},          {0.75f * r, 0.0f},     {0.75f * r, 0.06f * h}, {0.55f * r, 0.09f * h},
                         {0.8f * r, 0.2f * h},  {1.0f * r, 0.33f * h}, {0.92f * r, 0.45f * h}, {0.55f * r, 0.6f * h},
                         {0.35f * r, 0.72f * h}, {0.42f * r, 0.8f * h}, {0.6f * r, 0.86f * h}, {0.6f * r, 0.92f * h},
                         {0.75f * r, 0.94f * h}, {0.75f * r, h},        {0.0f, h}};
  return make_lathe(p, segments, 45.0f, 1.0f);
}

MeshData make_steps(int count, float width, float rise, float run, float landing, float uv_per_meter) {
  MeshData m;
  const float hw = 0.5f * width;
  for (int i = 0; i + 1 < count; ++i)
    append_mesh(m, make_box({-hw, 0.0f, -static_cast<float>(i + 1) * run}, {hw, static_cast<float>(i + 1) * rise, -static_cast<float>(i) * run},
                            uv_per_meter));
  const float top = static_cast<float>(count) * rise;
  const float z0 = -static_cast<float>(count - 1) * run;
  append_mesh(m, make_box({-hw, 0.0f, z0 - landing}, {hw, top, z0}, uv_per_meter));
  return m;
}

MeshData make_leaf_cluster(int leaves, float size, uint64_t seed, int segments) {
  Rng rng(seed, 3);
  MeshData m;
  const int nv = std::max(2, segments);
  for (int k = 0; k < leaves; ++k) {
    // Golden-angle azimuths; elevations from steep (inner leaves) to drooping (outer).
    const float azimuth = static_cast<float>(k) * 2.39996323f + rng.uniformf(-0.2, 0.2);
    const float t = (static_cast<float>(k) + 0.5f) / static_cast<float>(leaves);
    const float elevation = glm::mix(1.3f, 0.25f, t) + rng.uniformf(-0.1, 0.1);
    const float length = size * rng.uniformf(0.75, 1.15);
    const float width = 0.22f * length;
    const float droop = rng.uniformf(0.25, 0.55);
    const vec3 dir(std::sin(azimuth), 0.0f, std::cos(azimuth));
    const vec3 side(std::cos(azimuth), 0.0f, -std::sin(azimuth));
    const float fold = 0.15f * width;
    MeshData blade = make_surface(2, nv, false, false, [&](float u, float v) {
      const float along = v * length;
      const vec3 centre = dir * (along * std::cos(elevation)) +
                          vec3(0.0f, along * std::sin(elevation) - droop * length * v * v, 0.0f);
      const float w = width * std::sin(kPiF * (0.06f + 0.94f * v));
      const float across = (u - 0.5f) * 2.0f;
      return centre + side * (across * w) + vec3(0.0f, std::fabs(across) * fold * (1.0f - v), 0.0f);
    });
    blade.uvs.clear();
    append_mesh(m, blade);
  }
  return m;
}

}  // namespace sb::scenes
