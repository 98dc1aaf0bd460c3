// Object-space mesh primitives and mesh helpers for the scene generators.
#include "scenes/primitives.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace sb::scenes {

namespace {

constexpr float kTwoPi = static_cast<float>(2.0 * kPi);

/// cos and sin of an angle, snapped to exact 0 and +-1 at quarter turns so that axis-aligned
/// parts stay exactly axis-aligned.
vec2 cos_sin(float a) {
  vec2 cs(std::cos(a), std::sin(a));
  for (int i = 0; i < 2; ++i)
    if (std::fabs(cs[i]) < 1e-6f) cs[i] = 0.0f;
    else if (std::fabs(std::fabs(cs[i]) - 1.0f) < 1e-6f) cs[i] = std::copysign(1.0f, cs[i]);
  return cs;
}

vec3 safe_normalize(const vec3& v, const vec3& fallback) {
  const float len = glm::length(v);
  return len > 1e-20f && std::isfinite(len) ? v / len : fallback;
}

/// Checks the common preconditions of a primitive's counts.
void require(bool ok, const char* what) {
  if (!ok) throw std::invalid_argument(fmt::format("scene primitive: {}", what));
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// MeshData

Bounds3 MeshData::bounds() const {
  Bounds3 b;
  for (const vec3& p : positions) b.extend(p);
  return b;
}

void MeshData::reserve(size_t vertices, size_t triangles) {
  positions.reserve(positions.size() + vertices);
  normals.reserve(normals.size() + vertices);
  uvs.reserve(uvs.size() + vertices);
  indices.reserve(indices.size() + 3 * triangles);
}

uint32_t MeshData::add_vertex(const vec3& position, const vec3& normal, const vec2& uv) {
  positions.push_back(position);
  normals.push_back(safe_normalize(normal, vec3(0.0f, 1.0f, 0.0f)));
  uvs.push_back(uv);
  return static_cast<uint32_t>(positions.size() - 1);
}

void MeshData::add_triangle(uint32_t a, uint32_t b, uint32_t c) {
  indices.push_back(a);
  indices.push_back(b);
  indices.push_back(c);
}

vec2 box_uv(const vec3& p, const vec3& n, float uv_per_meter) {
  const vec3 a = glm::abs(n);
  vec2 uv;
  if (a.y >= a.x && a.y >= a.z) uv = {p.x, p.z};
  else if (a.x >= a.z) uv = {p.z, -p.y};
  else uv = {p.x, -p.y};
  return uv * uv_per_meter;
}

void MeshData::add_quad(const vec3& p0, const vec3& p1, const vec3& p2, const vec3& p3, const vec3& normal,
                        float uv_per_meter) {
  const vec3 n = safe_normalize(normal, vec3(0.0f, 1.0f, 0.0f));
  // Take the corners in the order that makes the quad face along `normal`.
  if (glm::dot(glm::cross(p1 - p0, p2 - p0) + glm::cross(p2 - p0, p3 - p0), n) < 0.0f) {
    add_quad(p0, p3, p2, p1, n, uv_per_meter);
    return;
  }
  const uint32_t a = add_vertex(p0, n, box_uv(p0, n, uv_per_meter));
  const uint32_t b = add_vertex(p1, n, box_uv(p1, n, uv_per_meter));
  const uint32_t c = add_vertex(p2, n, box_uv(p2, n, uv_per_meter));
  const uint32_t d = add_vertex(p3, n, box_uv(p3, n, uv_per_meter));
  add_triangle(a, b, c);
  add_triangle(a, c, d);
}

// ---------------------------------------------------------------------------------------------
// Transforms and merging

void transform_mesh(MeshData& mesh, const mat4& m) {
  const mat3 nm = glm::transpose(glm::inverse(mat3(m)));
  for (vec3& p : mesh.positions) p = vec3(m * vec4(p, 1.0f));
  for (vec3& n : mesh.normals) n = safe_normalize(nm * n, vec3(0.0f, 1.0f, 0.0f));
  if (glm::determinant(mat3(m)) < 0.0f)
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);
}

MeshData transformed(MeshData mesh, const mat4& m) {
  transform_mesh(mesh, m);
  return mesh;
}

void append_mesh(MeshData& dst, const MeshData& src) {
  const bool keep_uvs = (dst.positions.empty() || dst.uvs.size() == dst.positions.size()) &&
                        src.uvs.size() == src.positions.size();
  const auto base = static_cast<uint32_t>(dst.positions.size());
  dst.positions.insert(dst.positions.end(), src.positions.begin(), src.positions.end());
  dst.normals.insert(dst.normals.end(), src.normals.begin(), src.normals.end());
  if (keep_uvs) dst.uvs.insert(dst.uvs.end(), src.uvs.begin(), src.uvs.end());
  else dst.uvs.clear();
  dst.indices.reserve(dst.indices.size() + src.indices.size());
  for (uint32_t i : src.indices) dst.indices.push_back(base + i);
}

void append_mesh(MeshData& dst, const MeshData& src, const mat4& m) { append_mesh(dst, transformed(src, m)); }

void compute_vertex_normals(MeshData& mesh) {
  std::vector<vec3> acc(mesh.positions.size(), vec3(0.0f));
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
    const vec3 n = glm::cross(mesh.positions[b] - mesh.positions[a], mesh.positions[c] - mesh.positions[a]);
    acc[a] += n;
    acc[b] += n;
    acc[c] += n;
  }
  mesh.normals.resize(mesh.positions.size());
  for (size_t i = 0; i < acc.size(); ++i) mesh.normals[i] = safe_normalize(acc[i], vec3(0.0f, 1.0f, 0.0f));
}

mat4 translation(const vec3& t) {
  mat4 m(1.0f);
  m[3] = vec4(t, 1.0f);
  return m;
}

mat4 rotation_y(float a) {
  const vec2 cs = cos_sin(a);
  mat4 m(1.0f);
  m[0] = vec4(cs.x, 0.0f, -cs.y, 0.0f);
  m[2] = vec4(cs.y, 0.0f, cs.x, 0.0f);
  return m;
}

mat4 rotation_x(float a) {
  const vec2 cs = cos_sin(a);
  mat4 m(1.0f);
  m[1] = vec4(0.0f, cs.x, cs.y, 0.0f);
  m[2] = vec4(0.0f, -cs.y, cs.x, 0.0f);
  return m;
}

mat4 rotation_z(float a) {
  const vec2 cs = cos_sin(a);
  mat4 m(1.0f);
  m[0] = vec4(cs.x, cs.y, 0.0f, 0.0f);
  m[1] = vec4(-cs.y, cs.x, 0.0f, 0.0f);
  return m;
}

mat4 scaling(const vec3& s) {
  mat4 m(1.0f);
  m[0][0] = s.x;
  m[1][1] = s.y;
  m[2][2] = s.z;
  return m;
}

mat4 placement(const vec3& t, float yaw, const vec3& s) { return translation(t) * rotation_y(yaw) * scaling(s); }

mat4 align_y_to(const vec3& direction) {
  const vec3 y = safe_normalize(direction, vec3(0.0f, 1.0f, 0.0f));
  const vec3 helper = std::fabs(y.z) < 0.9f ? vec3(0.0f, 0.0f, 1.0f) : vec3(1.0f, 0.0f, 0.0f);
  const vec3 x = glm::normalize(glm::cross(y, helper));
  const vec3 z = glm::cross(x, y);
  mat4 m(1.0f);
  m[0] = vec4(x, 0.0f);
  m[1] = vec4(y, 0.0f);
  m[2] = vec4(z, 0.0f);
  return m;
}

// ---------------------------------------------------------------------------------------------
// Boxes and planes

MeshData make_box(const vec3& lo, const vec3& hi, float uv_per_meter) {
  require(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z, "box with an empty extent");
  MeshData m;
  m.reserve(24, 12);
  const vec3 a = lo, b = hi;
  m.add_quad({a.x, a.y, b.z}, {b.x, a.y, b.z}, {b.x, b.y, b.z}, {a.x, b.y, b.z}, {0, 0, 1}, uv_per_meter);   // +Z
  m.add_quad({b.x, a.y, a.z}, {a.x, a.y, a.z}, {a.x, b.y, a.z}, {b.x, b.y, a.z}, {0, 0, -1}, uv_per_meter);  // -Z
  m.add_quad({b.x, a.y, b.z}, {b.x, a.y, a.z}, {b.x, b.y, a.z}, {b.x, b.y, b.z}, {1, 0, 0}, uv_per_meter);   // +X
  m.add_quad({a.x, a.y, a.z}, {a.x, a.y, b.z}, {a.x, b.y, b.z}, {a.x, b.y, a.z}, {-1, 0, 0}, uv_per_meter);  // -X
  m.add_quad({a.x, b.y, b.z}, {b.x, b.y, b.z}, {b.x, b.y, a.z}, {a.x, b.y, a.z}, {0, 1, 0}, uv_per_meter);   // +Y
  m.add_quad({a.x, a.y, a.z}, {b.x, a.y, a.z}, {b.x, a.y, b.z}, {a.x, a.y, b.z}, {0, -1, 0}, uv_per_meter);  // -Y
  return m;
}

MeshData make_box_centered(const vec3& size, float uv_per_meter) {
  return make_box(-0.5f * size, 0.5f * size, uv_per_meter);
}

MeshData make_plane(const vec2& size, const ivec2& divisions, float uv_per_meter) {
  require(divisions.x >= 1 && divisions.y >= 1 && size.x > 0 && size.y > 0, "plane with no extent");
  MeshData m;
  const int nx = divisions.x, nz = divisions.y;
  m.reserve(static_cast<size_t>((nx + 1) * (nz + 1)), static_cast<size_t>(2 * nx * nz));
  for (int j = 0; j <= nz; ++j)
    for (int i = 0; i <= nx; ++i) {
      const vec3 p((static_cast<float>(i) / nx - 0.5f) * size.x, 0.0f, (static_cast<float>(j) / nz - 0.5f) * size.y);
      m.add_vertex(p, {0, 1, 0}, vec2(p.x, p.z) * uv_per_meter);
    }
  const auto at = [nx](int i, int j) { return static_cast<uint32_t>(j * (nx + 1) + i); };
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i) {
      // Counter-clockwise seen from +Y: x to the right, z towards the viewer.
      m.add_triangle(at(i, j), at(i, j + 1), at(i + 1, j + 1));
      m.add_triangle(at(i, j), at(i + 1, j + 1), at(i + 1, j));
    }
  return m;
}

// ---------------------------------------------------------------------------------------------
// Grid surfaces

MeshData make_grid_surface(int nu, int nv, bool wrap_u, bool wrap_v, std::vector<vec3> positions,
                           const vec2& uv_scale) {
  require(nu >= 1 && nv >= 1, "grid surface without cells");
  const int cols = nu + 1, rows = nv + 1;
  require(positions.size() == static_cast<size_t>(cols) * static_cast<size_t>(rows),
          "grid surface with the wrong number of positions");
  const auto at = [cols](int i, int j) { return static_cast<size_t>(j) * static_cast<size_t>(cols) + static_cast<size_t>(i); };
  // Weld the seams exactly so that no crack can open between the first and last column/row.
  if (wrap_u)
    for (int j = 0; j < rows; ++j) positions[at(nu, j)] = positions[at(0, j)];
  if (wrap_v)
    for (int i = 0; i < cols; ++i) positions[at(i, nv)] = positions[at(i, 0)];

  MeshData m;
  m.positions = std::move(positions);
  m.normals.resize(m.positions.size());
  m.uvs.resize(m.positions.size());
  // Normals from central differences of neighbouring positions (one-sided at open edges).
  for (int j = 0; j < rows; ++j) {
    const int j0 = j > 0 ? j - 1 : (wrap_v ? nv - 1 : 0);
    const int j1 = j < nv ? j + 1 : (wrap_v ? 1 : nv);
    for (int i = 0; i < cols; ++i) {
      const int i0 = i > 0 ? i - 1 : (wrap_u ? nu - 1 : 0);
      const int i1 = i < nu ? i + 1 : (wrap_u ? 1 : nu);
      const vec3 du = m.positions[at(i1, j)] - m.positions[at(i0, j)];
      const vec3 dv = m.positions[at(i, j1)] - m.positions[at(i, j0)];
      m.normals[at(i, j)] = glm::cross(du, dv);
      m.uvs[at(i, j)] = vec2(static_cast<float>(i) / nu, static_cast<float>(j) / nv) * uv_scale;
    }
  }
  // Where a row collapses (a pole) the cross product vanishes: borrow the normal of the nearest
  // row along v that has one, else fall back to the cell normals.
  bool any_degenerate = false;
  for (vec3& n : m.normals) {
    const float len = glm::length(n);
    if (len > 1e-30f && std::isfinite(len)) n /= len;
    else {
      n = vec3(0.0f);
      any_degenerate = true;
    }
  }
  if (any_degenerate)
    for (int j = 0; j < rows; ++j)
      for (int i = 0; i < cols; ++i) {
        if (m.normals[at(i, j)] != vec3(0.0f)) continue;
        vec3 n(0.0f);
        for (int d = 1; d < rows && n == vec3(0.0f); ++d) {
          if (j - d >= 0 && m.normals[at(i, j - d)] != vec3(0.0f)) n = m.normals[at(i, j - d)];
          else if (j + d < rows && m.normals[at(i, j + d)] != vec3(0.0f)) n = m.normals[at(i, j + d)];
        }
        m.normals[at(i, j)] = n == vec3(0.0f) ? vec3(0.0f, 1.0f, 0.0f) : n;
      }

  m.indices.reserve(static_cast<size_t>(6) * static_cast<size_t>(nu) * static_cast<size_t>(nv));
  const auto add = [&m](size_t a, size_t b, size_t c) {
    if (m.positions[a] == m.positions[b] || m.positions[b] == m.positions[c] || m.positions[a] == m.positions[c]) return;
    m.add_triangle(static_cast<uint32_t>(a), static_cast<uint32_t>(b), static_cast<uint32_t>(c));
  };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      add(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      add(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  return m;
}

MeshData make_surface(int nu, int nv, bool wrap_u, bool wrap_v, const std::function<vec3(float, float)>& position,
                      const vec2& uv_scale) {
  require(nu >= 1 && nv >= 1, "surface without cells");
  std::vector<vec3> p;
  p.reserve(static_cast<size_t>(nu + 1) * static_cast<size_t>(nv + 1));
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) p.push_back(position(static_cast<float>(i) / nu, static_cast<float>(j) / nv));
  return make_grid_surface(nu, nv, wrap_u, wrap_v, std::move(p), uv_scale);
}

// ---------------------------------------------------------------------------------------------
// Round primitives

MeshData make_uv_sphere(float radius, int segments, int rings) {
  require(segments >= 3 && rings >= 2 && radius > 0.0f, "sphere needs >= 3 segments, >= 2 rings");
  MeshData m;
  m.reserve(static_cast<size_t>((segments + 1) * (rings - 1) + 2 * segments),
            static_cast<size_t>(2 * segments * (rings - 1)));
  // Interior rings 1..rings-1, each with a duplicated seam column for the UVs.
  for (int j = 1; j < rings; ++j) {
    const float theta = static_cast<float>(kPi) * static_cast<float>(j) / rings;
    for (int i = 0; i <= segments; ++i) {
      const float phi = kTwoPi * static_cast<float>(i % segments) / segments;
      const vec2 t = cos_sin(theta), f = cos_sin(phi);
      const vec3 n(t.y * f.y, t.x, t.y * f.x);
      m.add_vertex(radius * n, n, {static_cast<float>(i) / segments, static_cast<float>(j) / rings});
    }
  }
  const auto ring = [segments](int j, int i) { return static_cast<uint32_t>((j - 1) * (segments + 1) + i); };
  // One pole vertex per segment keeps the UVs sensible and no triangle degenerate.
  const auto top = static_cast<uint32_t>(m.positions.size());
  for (int i = 0; i < segments; ++i)
    m.add_vertex({0, radius, 0}, {0, 1, 0}, {(static_cast<float>(i) + 0.5f) / segments, 0.0f});
  const auto bottom = static_cast<uint32_t>(m.positions.size());
  for (int i = 0; i < segments; ++i)
    m.add_vertex({0, -radius, 0}, {0, -1, 0}, {(static_cast<float>(i) + 0.5f) / segments, 1.0f});
  for (int i = 0; i < segments; ++i) {
    m.add_triangle(top + static_cast<uint32_t>(i), ring(1, i), ring(1, i + 1));
    m.add_triangle(bottom + static_cast<uint32_t>(i), ring(rings - 1, i + 1), ring(rings - 1, i));
  }
  for (int j = 1; j < rings - 1; ++j)
    for (int i = 0; i < segments; ++i) {
      m.add_triangle(ring(j, i), ring(j + 1, i), ring(j + 1, i + 1));
      m.add_triangle(ring(j, i), ring(j + 1, i + 1), ring(j, i + 1));
    }
  return m;
}

namespace {

/// A disc fan at height y facing `up` (+Y) or down, following the given outline (closed: the
/// last point repeats the first).
void add_disc(MeshData& m, const std::vector<vec3>& outline, bool facing_up, float uv_per_meter) {
  const vec3 n = facing_up ? vec3(0, 1, 0) : vec3(0, -1, 0);
  vec3 c(0.0f);
  const size_t count = outline.size() - 1;
  for (size_t i = 0; i < count; ++i) c += outline[i];
  c /= static_cast<float>(count);
  const uint32_t centre = m.add_vertex(c, n, box_uv(c, n, uv_per_meter));
  const auto first = static_cast<uint32_t>(m.positions.size());
  for (const vec3& p : outline) m.add_vertex(p, n, box_uv(p, n, uv_per_meter));
  for (uint32_t i = 0; i < count; ++i) {
    // phi grows from +Z towards +X, which is counter-clockwise seen from +Y.
    if (facing_up) m.add_triangle(centre, first + i, first + i + 1);
    else m.add_triangle(centre, first + i + 1, first + i);
  }
}

}  // namespace

MeshData make_cylinder(float radius, float height, int segments, const CylinderOptions& o) {
  require(segments >= 3 && o.rings >= 1 && radius > 0.0f && height > 0.0f, "cylinder needs >= 3 segments");
  const float r_top = o.radius_top < 0.0f ? radius : o.radius_top;
  const int flutes = o.flutes;
  const float depth = o.flute_depth;
  auto outline_radius = [&](float u, float v) {
    float r = glm::mix(radius, r_top, v);
    if (flutes > 0) {
      // Concave semicircular flutes separated by narrow flat fillets; they die out near the ends
      // as on a real column shaft.
      const float local = u * static_cast<float>(flutes) - std::floor(u * static_cast<float>(flutes));
      const float t = (local - 0.08f) / 0.84f;
      float g = 0.0f;
      if (t > 0.0f && t < 1.0f) g = std::sqrt(std::max(0.0f, 1.0f - (2.0f * t - 1.0f) * (2.0f * t - 1.0f)));
      const float fade = std::min(1.0f, std::min(v, 1.0f - v) / 0.04f);
      r *= 1.0f - depth * g * std::max(0.0f, fade);
    }
    return r;
  };
  auto side_point = [&](float u, float v) {
    const float phi = kTwoPi * u;
    const float r = outline_radius(u, v);
    const vec2 cs = cos_sin(phi);
    return vec3(r * cs.y, v * height, r * cs.x);
  };
  const float circumference = kTwoPi * std::max(radius, r_top);
  MeshData m = make_surface(segments, o.rings, true, false, side_point,
                            vec2(std::max(1.0f, std::round(circumference * o.uv_per_meter)), height * o.uv_per_meter));
  if (o.caps) {
    std::vector<vec3> bottom, top;
    for (int i = 0; i <= segments; ++i) {
      const float u = static_cast<float>(i % segments) / segments;
      bottom.push_back(side_point(u, 0.0f));
      top.push_back(side_point(u, 1.0f));
    }
    if (r_top > 0.0f) add_disc(m, top, true, o.uv_per_meter);
    add_disc(m, bottom, false, o.uv_per_meter);
  }
  return m;
}

MeshData make_cone(float radius, float height, int segments, bool cap) {
  std::vector<vec2> profile;
  if (cap) profile.push_back({0.0f, 0.0f});
  profile.push_back({radius, 0.0f});
  profile.push_back({0.0f, height});
  return make_lathe(profile, segments, 40.0f);
}

MeshData make_torus(float major, float minor, int major_segments, int minor_segments) {
  require(major_segments >= 3 && minor_segments >= 3 && minor > 0.0f && major > minor, "torus needs >= 3 segments");
  return make_surface(
      major_segments, minor_segments, true, true,
      [&](float u, float v) {
        const float a = kTwoPi * u, b = kTwoPi * v;
        const float rr = major + minor * std::cos(b);
        return vec3(rr * std::sin(a), minor * std::sin(b), rr * std::cos(a));
      },
      vec2(std::max(1.0f, std::round(kTwoPi * major)), std::max(1.0f, std::round(kTwoPi * minor))));
}

MeshData make_lathe(const std::vector<vec2>& profile, int segments, float crease_degrees, float uv_per_meter) {
  require(profile.size() >= 2 && segments >= 3, "lathe needs >= 2 profile points and >= 3 segments");
  const size_t n = profile.size();
  // Outward normal of each profile segment in the (r, y) plane.
  std::vector<vec2> seg_normal(n - 1);
  for (size_t k = 0; k + 1 < n; ++k) {
    const vec2 d = profile[k + 1] - profile[k];
    require(glm::length(d) > 0.0f, "lathe profile repeats a point");
    seg_normal[k] = glm::normalize(vec2(d.y, -d.x));
  }
  const float cos_crease = std::cos(static_cast<float>(degrees_to_radians(crease_degrees)));
  float r_max = 0.0f;
  for (const vec2& p : profile) r_max = std::max(r_max, p.x);
  const float u_repeats = std::max(1.0f, std::round(kTwoPi * r_max * uv_per_meter));

  // Rings of vertices: a profile point becomes one ring (smooth) or two (crease).
  struct Ring {
    size_t point;
    vec2 normal;
    float v;
  };
  std::vector<std::vector<Ring>> rings_at(n);  // [point] -> rings (first = incoming side)
  float arc = 0.0f;
  for (size_t k = 0; k < n; ++k) {
    if (k > 0) arc += glm::length(profile[k] - profile[k - 1]);
    const float v = arc * uv_per_meter;
    if (k == 0) rings_at[k].push_back({k, seg_normal[0], v});
    else if (k == n - 1) rings_at[k].push_back({k, seg_normal[n - 2], v});
    else if (glm::dot(seg_normal[k - 1], seg_normal[k]) >= cos_crease)
      rings_at[k].push_back({k, glm::normalize(seg_normal[k - 1] + seg_normal[k]), v});
    else {
      rings_at[k].push_back({k, seg_normal[k - 1], v});
      rings_at[k].push_back({k, seg_normal[k], v});
    }
  }
  MeshData m;
  std::vector<std::vector<uint32_t>> first_index(n);
  for (size_t k = 0; k < n; ++k)
    for (const Ring& ring : rings_at[k]) {
      first_index[k].push_back(static_cast<uint32_t>(m.positions.size()));
      const vec2 p = profile[ring.point];
      for (int i = 0; i <= segments; ++i) {
        // On the axis use the half-segment angle so that fan vertices get distinct UVs.
        const float fi = p.x > 0.0f ? static_cast<float>(i) : static_cast<float>(i) + 0.5f;
        const float phi = kTwoPi * fi / segments;
        const vec2 cs = cos_sin(phi);
        const vec3 dir(cs.y, 0.0f, cs.x);
        const vec3 normal = dir * ring.normal.x + vec3(0.0f, ring.normal.y, 0.0f);
        const vec3 pos = dir * p.x + vec3(0.0f, p.y, 0.0f);
        m.add_vertex(i == segments && p.x > 0.0f ? vec3(0.0f, p.y, p.x) : pos, normal,
                     {fi / segments * u_repeats, ring.v});
      }
    }
  for (size_t k = 0; k + 1 < n; ++k) {
    const uint32_t a = first_index[k].back();       // outgoing ring of point k
    const uint32_t b = first_index[k + 1].front();  // incoming ring of point k+1
    const bool a_axis = profile[k].x <= 0.0f, b_axis = profile[k + 1].x <= 0.0f;
    require(!(a_axis && b_axis), "lathe profile runs along the axis");
    for (uint32_t i = 0; i < static_cast<uint32_t>(segments); ++i) {
      // Grid orientation u = phi, v = profile: fronts face dP/du x dP/dv, i.e. outward. A ring on
      // the axis collapses one triangle of each cell; its vertex i (at angle i + 1/2) is the apex.
      if (a_axis) m.add_triangle(a + i, b + i + 1, b + i);
      else if (b_axis) m.add_triangle(a + i, a + i + 1, b + i);
      else {
        m.add_triangle(a + i, a + i + 1, b + i + 1);
        m.add_triangle(a + i, b + i + 1, b + i);
      }
    }
  }
  return m;
}

// ---------------------------------------------------------------------------------------------
// Arches

MeshData make_arch_ring(float inner_radius, float outer_radius, float depth, int segments, float start, float end,
                        float uv_per_meter) {
  require(segments >= 1 && outer_radius > inner_radius && inner_radius > 0.0f && depth > 0.0f && end > start,
          "arch ring with no extent");
  MeshData m;
  const float z0 = -0.5f * depth, z1 = 0.5f * depth;
  const auto angle = [&](int i) { return start + (end - start) * static_cast<float>(i) / segments; };
  const auto radial = [&](int i) { return vec3(cos_sin(angle(i)), 0.0f); };
  // Front (+Z) and back (-Z) annular faces.
  for (int face = 0; face < 2; ++face) {
    const float z = face == 0 ? z1 : z0;
    const vec3 n = face == 0 ? vec3(0, 0, 1) : vec3(0, 0, -1);
    const auto base = static_cast<uint32_t>(m.positions.size());
    for (int i = 0; i <= segments; ++i) {
      const vec3 d = radial(i);
      const vec3 pi = d * inner_radius + vec3(0, 0, z), po = d * outer_radius + vec3(0, 0, z);
      m.add_vertex(pi, n, box_uv(pi, n, uv_per_meter));
      m.add_vertex(po, n, box_uv(po, n, uv_per_meter));
    }
    for (uint32_t i = 0; i < static_cast<uint32_t>(segments); ++i) {
      const uint32_t a = base + 2 * i, b = a + 1, c = a + 3, d = a + 2;  // inner, outer, outer', inner'
      if (face == 0) {
        m.add_triangle(a, b, c);
        m.add_triangle(a, c, d);
      } else {
        m.add_triangle(a, c, b);
        m.add_triangle(a, d, c);
      }
    }
  }
  // Intrados (facing the centre) and extrados (facing out).
  for (int side = 0; side < 2; ++side) {
    const float r = side == 0 ? inner_radius : outer_radius;
    const auto base = static_cast<uint32_t>(m.positions.size());
    for (int i = 0; i <= segments; ++i) {
      const vec3 d = radial(i);
      const vec3 n = side == 0 ? -d : d;
      const float u = r * (angle(i) - start) * uv_per_meter;
      m.add_vertex(d * r + vec3(0, 0, z1), n, {u, z1 * uv_per_meter});
      m.add_vertex(d * r + vec3(0, 0, z0), n, {u, z0 * uv_per_meter});
    }
    for (uint32_t i = 0; i < static_cast<uint32_t>(segments); ++i) {
      const uint32_t f0 = base + 2 * i, b0 = f0 + 1, f1 = f0 + 2, b1 = f0 + 3;
      if (side == 0) {
        m.add_triangle(f0, f1, b1);
        m.add_triangle(f0, b1, b0);
      } else {
        m.add_triangle(f0, b1, f1);
        m.add_triangle(f0, b0, b1);
      }
    }
  }
  // End faces where the ring is not closed.
  if (end - start < kTwoPi - 1e-4f) {
    const vec3 ds = radial(0), de = radial(segments);
    const vec3 ns = glm::cross(ds, vec3(0, 0, 1));  // against the direction of growing angle
    const vec3 ne = glm::cross(vec3(0, 0, 1), de);
    m.add_quad(ds * outer_radius + vec3(0, 0, z1), ds * inner_radius + vec3(0, 0, z1), ds * inner_radius + vec3(0, 0, z0),
               ds * outer_radius + vec3(0, 0, z0), ns, uv_per_meter);
    m.add_quad(de * inner_radius + vec3(0, 0, z1), de * outer_radius + vec3(0, 0, z1), de * outer_radius + vec3(0, 0, z0),
               de * inner_radius + vec3(0, 0, z0), ne, uv_per_meter);
  }
  return m;
}

MeshData make_arch_panel(float width, float height, float radius, float depth, int segments, float uv_per_meter) {
  require(segments >= 2 && radius > 0.0f && radius < 0.5f * width && radius < height && depth > 0.0f,
          "arch panel needs 0 < radius < width/2 and radius < height");
  MeshData m;
  const float hw = 0.5f * width, z0 = -0.5f * depth, z1 = 0.5f * depth;
  const float corner_angle = std::atan2(height, hw);  // angle of (hw, height); the other is pi - it
  const auto angle = [&](int i) { return static_cast<float>(kPi) * static_cast<float>(i) / segments; };
  // Where the ray from the arch centre at angle t meets the rectangle's outline.
  const auto outline = [&](float t) {
    const vec2 cs = cos_sin(t);
    const float c = cs.x, s = cs.y;
    float d = 1e30f;
    if (std::fabs(c) > 1e-7f) d = std::min(d, hw / std::fabs(c));
    if (s > 1e-7f) d = std::min(d, height / s);
    vec2 p(c * d, s * d);
    p.x = std::clamp(p.x, -hw, hw);
    p.y = std::clamp(p.y, 0.0f, height);
    return p;
  };

  // Front and back faces: per segment the polygon arc_i, outline_i, [corner], outline_i+1, arc_i+1.
  for (int face = 0; face < 2; ++face) {
    const float z = face == 0 ? z1 : z0;
    const vec3 n = face == 0 ? vec3(0, 0, 1) : vec3(0, 0, -1);
    const auto vert = [&](const vec2& p) { const vec3 q(p, z); return m.add_vertex(q, n, box_uv(q, n, uv_per_meter)); };
    const auto tri = [&](uint32_t a, uint32_t b, uint32_t c) {
      if (face == 0) m.add_triangle(a, b, c);
      else m.add_triangle(a, c, b);
    };
    std::vector<uint32_t> arc(static_cast<size_t>(segments) + 1), out(static_cast<size_t>(segments) + 1);
    for (int i = 0; i <= segments; ++i) {
      const float t = angle(i);
      arc[static_cast<size_t>(i)] = vert(cos_sin(t) * radius);
      out[static_cast<size_t>(i)] = vert(outline(t));
    }
    const uint32_t c_right = vert({hw, height}), c_left = vert({-hw, height});
    for (int i = 0; i < segments; ++i) {
      const float t0 = angle(i), t1 = angle(i + 1);
      const auto a0 = arc[static_cast<size_t>(i)], a1 = arc[static_cast<size_t>(i + 1)];
      const auto o0 = out[static_cast<size_t>(i)], o1 = out[static_cast<size_t>(i + 1)];
      std::vector<uint32_t> corners;
      const float eps = 1e-5f;
      if (t0 + eps < corner_angle && corner_angle < t1 - eps) corners.push_back(c_right);
      const float left_angle = static_cast<float>(kPi) - corner_angle;
      if (t0 + eps < left_angle && left_angle < t1 - eps) corners.push_back(c_left);
      // Fan around a0 over the outline chain o0 -> corners -> o1, then close with a1.
      uint32_t prev = o0;
      for (uint32_t c : corners) {
        tri(a0, prev, c);
        prev = c;
      }
      tri(a0, prev, o1);
      tri(a0, o1, a1);
    }
  }
  // Intrados: the curved underside of the arch, facing the opening.
  {
    const auto base = static_cast<uint32_t>(m.positions.size());
    for (int i = 0; i <= segments; ++i) {
      const float t = angle(i);
      const vec3 d(cos_sin(t), 0.0f);
      const float u = radius * t * uv_per_meter;
      m.add_vertex(d * radius + vec3(0, 0, z1), -d, {u, z1 * uv_per_meter});
      m.add_vertex(d * radius + vec3(0, 0, z0), -d, {u, z0 * uv_per_meter});
    }
    for (uint32_t i = 0; i < static_cast<uint32_t>(segments); ++i) {
      const uint32_t f0 = base + 2 * i, b0 = f0 + 1, f1 = f0 + 2, b1 = f0 + 3;
      m.add_triangle(f0, f1, b1);
      m.add_triangle(f0, b1, b0);
    }
  }
  // Top, sides and the two feet standing on the springing line.
  m.add_quad({-hw, height, z1}, {hw, height, z1}, {hw, height, z0}, {-hw, height, z0}, {0, 1, 0}, uv_per_meter);
  m.add_quad({hw, 0, z1}, {hw, 0, z0}, {hw, height, z0}, {hw, height, z1}, {1, 0, 0}, uv_per_meter);
  m.add_quad({-hw, 0, z0}, {-hw, 0, z1}, {-hw, height, z1}, {-hw, height, z0}, {-1, 0, 0}, uv_per_meter);
  m.add_quad({radius, 0, z0}, {hw, 0, z0}, {hw, 0, z1}, {radius, 0, z1}, {0, -1, 0}, uv_per_meter);
  m.add_quad({-hw, 0, z0}, {-radius, 0, z0}, {-radius, 0, z1}, {-hw, 0, z1}, {0, -1, 0}, uv_per_meter);
  return m;
}

// ---------------------------------------------------------------------------------------------
// Tubes and curves

MeshData make_tube(const std::vector<vec3>& path, const std::vector<float>& radii, int segments, bool caps) {
  require(path.size() >= 2 && radii.size() == path.size() && segments >= 3, "tube needs >= 2 points and a radius each");
  const size_t n = path.size();
  std::vector<vec3> tangent(n);
  for (size_t k = 0; k < n; ++k) {
    const vec3 d = path[std::min(k + 1, n - 1)] - path[k > 0 ? k - 1 : 0];
    tangent[k] = safe_normalize(d, vec3(0, 1, 0));
  }
  // Rotation-minimising frames by double reflection (Wang et al. 2008).
  std::vector<vec3> normal(n);
  {
    const vec3 t0 = tangent[0];
    const vec3 helper = std::fabs(t0.y) < 0.9f ? vec3(0, 1, 0) : vec3(1, 0, 0);
    normal[0] = glm::normalize(glm::cross(glm::cross(t0, helper), t0));
  }
  for (size_t k = 0; k + 1 < n; ++k) {
    const vec3 v1 = path[k + 1] - path[k];
    const float c1 = glm::dot(v1, v1);
    if (c1 < 1e-20f) {
      normal[k + 1] = normal[k];
      continue;
    }
    const vec3 r_l = normal[k] - (2.0f / c1) * glm::dot(v1, normal[k]) * v1;
    const vec3 t_l = tangent[k] - (2.0f / c1) * glm::dot(v1, tangent[k]) * v1;
    const vec3 v2 = tangent[k + 1] - t_l;
    const float c2 = glm::dot(v2, v2);
    const vec3 r = c2 < 1e-20f ? r_l : r_l - (2.0f / c2) * glm::dot(v2, r_l) * v2;
    normal[k + 1] = safe_normalize(r - glm::dot(r, tangent[k + 1]) * tangent[k + 1], normal[k]);
  }
  std::vector<vec3> pos;
  pos.reserve(n * static_cast<size_t>(segments + 1));
  for (size_t k = 0; k < n; ++k) {
    const vec3 b = glm::cross(tangent[k], normal[k]);
    for (int i = 0; i <= segments; ++i) {
      const float phi = kTwoPi * static_cast<float>(i % segments) / segments;
      pos.push_back(path[k] + radii[k] * (std::cos(phi) * normal[k] + std::sin(phi) * b));
    }
  }
  float length = 0.0f;
  for (size_t k = 1; k < n; ++k) length += glm::length(path[k] - path[k - 1]);
  MeshData m = make_grid_surface(segments, static_cast<int>(n) - 1, true, false, pos, vec2(1.0f, std::max(1.0f, length)));
  if (caps) {
    for (int end = 0; end < 2; ++end) {
      const size_t k = end == 0 ? 0 : n - 1;
      if (radii[k] <= 0.0f) continue;
      const vec3 nn = end == 0 ? -tangent[k] : tangent[k];
      const uint32_t centre = m.add_vertex(path[k], nn, {0.5f, 0.5f});
      const auto first = static_cast<uint32_t>(m.positions.size());
      for (int i = 0; i <= segments; ++i) {
        const float phi = kTwoPi * static_cast<float>(i % segments) / segments;
        m.add_vertex(pos[k * static_cast<size_t>(segments + 1) + static_cast<size_t>(i)], nn,
                     {0.5f + 0.5f * std::cos(phi), 0.5f + 0.5f * std::sin(phi)});
      }
      for (uint32_t i = 0; i < static_cast<uint32_t>(segments); ++i) {
        // The ring runs counter-clockwise about the tangent, so the end cap (facing +T) takes
        // (c, i, i+1) and the start cap the reverse.
        if (end == 1) m.add_triangle(centre, first + i, first + i + 1);
        else m.add_triangle(centre, first + i + 1, first + i);
      }
    }
  }
  return m;
}

std::vector<vec3> catmull_rom(const std::vector<vec3>& points, int samples_per_span) {
  require(points.size() >= 2 && samples_per_span >= 1, "spline needs >= 2 points");
  std::vector<vec3> out;
  const size_t n = points.size();
  out.reserve((n - 1) * static_cast<size_t>(samples_per_span) + 1);
  for (size_t k = 0; k + 1 < n; ++k) {
    const vec3 p0 = points[k > 0 ? k - 1 : 0], p1 = points[k], p2 = points[k + 1], p3 = points[std::min(k + 2, n - 1)];
    for (int s = 0; s < samples_per_span; ++s) {
      const float t = static_cast<float>(s) / samples_per_span;
      const float t2 = t * t, t3 = t2 * t;
      out.push_back(0.5f * ((2.0f * p1) + (-p0 + p2) * t + (2.0f * p0 - 5.0f * p1 + 4.0f * p2 - p3) * t2 +
                            (-p0 + 3.0f * p1 - 3.0f * p2 + p3) * t3));
    }
  }
  out.push_back(points.back());
  return out;
}

}  // namespace sb::scenes
