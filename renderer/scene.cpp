// Scene summaries.
#include "renderer/scene.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <limits>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "renderer/error.hpp"

namespace sb {

namespace {

/// The index k of the key interval [times[k], times[k+1]] holding t, and t's fraction u of it;
/// t outside the keys clamps to the first or the last key (k = n - 1, u = 0 for the last); t a few
/// float ulps before a key is at that key (u = 0).
std::pair<size_t, double> key_interval(const std::vector<double>& times, double t) {
  const size_t n = times.size();
  if (n == 1 || t <= times.front()) return {0, 0.0};
  if (t >= times.back()) return {n - 1, 0.0};
  const size_t k = static_cast<size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin()) - 1;
  // Key times are float32 in the file and frame times are computed in double: a frame meant to
  // fall on a key lands a few float ulps before it (1/24 s in double is below 1/24 s in float), and
  // a STEP change showed a frame late. A time within a few float ulps of the next key is at it.
  const double next = times[k + 1];
  if (next - t <= 4.0 * static_cast<double>(std::numeric_limits<float>::epsilon()) * std::max(std::fabs(next), 1e-3))
    return {k + 1, 0.0};
  return {k, (t - times[k]) / (next - times[k])};
}

/// Component c of key k's value (for a cubic spline: of its value, between the tangents).
double key_value(const NodeAnimation::Channel& ch, size_t k, int width, int c) {
  const size_t per_key = ch.interpolation == NodeAnimation::Interpolation::cubic_spline ? 3 : 1;
  const size_t slot = per_key == 3 ? 1 : 0;
  return ch.values[(k * per_key + slot) * static_cast<size_t>(width) + static_cast<size_t>(c)];
}

/// A channel's value at time t (glTF 2.0 §3.11 "Animations" and Appendix C: linear with slerp for
/// rotations, step, cubic Hermite spline): `width` numbers of the four.
std::array<double, 4> sample(const NodeAnimation::Channel& ch, double t, int width) {
  const auto [k, u] = key_interval(ch.times, t);
  std::array<double, 4> out{};
  const bool last = k + 1 >= ch.times.size() || u == 0.0;
  for (int c = 0; c < width; ++c) out[static_cast<size_t>(c)] = key_value(ch, k, width, c);
  if (last || ch.interpolation == NodeAnimation::Interpolation::step) return out;
  if (ch.interpolation == NodeAnimation::Interpolation::linear) {
    if (ch.property == NodeAnimation::Property::rotation) {
      // Keys made unit first: normalized integer keys (BYTE, SHORT) are unit only to their
      // quantization, and glm's slerp of longer ones is neither the rotation between them nor at
      // the right angle along the way.
      const auto unit = [](const dquat& q) {
        const double n = glm::length(q);
        return n > 0.0 ? q / n : q;
      };
      const dquat a = unit(dquat(key_value(ch, k, 4, 3), key_value(ch, k, 4, 0), key_value(ch, k, 4, 1),
                                 key_value(ch, k, 4, 2)));
      const dquat b = unit(dquat(key_value(ch, k + 1, 4, 3), key_value(ch, k + 1, 4, 0), key_value(ch, k + 1, 4, 1),
                                 key_value(ch, k + 1, 4, 2)));
      const dquat q = glm::slerp(a, glm::dot(a, b) < 0.0 ? -b : b, u);  // the shorter way round
      return {q.x, q.y, q.z, q.w};
    }
    for (int c = 0; c < width; ++c)
      out[static_cast<size_t>(c)] += u * (key_value(ch, k + 1, width, c) - out[static_cast<size_t>(c)]);
    return out;
  }
  // Cubic spline: per key the in-tangent a, the value v and the out-tangent b.
  const double td = ch.times[k + 1] - ch.times[k];
  const double u2 = u * u, u3 = u2 * u;
  const auto at = [&](size_t key, size_t slot, int c) {
    return ch.values[(key * 3 + slot) * static_cast<size_t>(width) + static_cast<size_t>(c)];
  };
  for (int c = 0; c < width; ++c)
    out[static_cast<size_t>(c)] = (2 * u3 - 3 * u2 + 1) * at(k, 1, c) + (u3 - 2 * u2 + u) * td * at(k, 2, c) +
                                  (-2 * u3 + 3 * u2) * at(k + 1, 1, c) + (u3 - u2) * td * at(k + 1, 0, c);
  return out;
}

}  // namespace

dmat4 NodeAnimation::Local::transform() const {
  if (matrix) return *matrix;
  dmat4 t(1.0), s(1.0);
  t[3] = dvec4(translation, 1.0);
  s[0][0] = scale.x;
  s[1][1] = scale.y;
  s[2][2] = scale.z;
  return t * dmat4(glm::mat3_cast(rotation)) * s;
}

void Light::place(const dmat4& world) {
  position = vec3(dvec3(world[3]));
  const dvec3 d = dvec3(world * dvec4(0.0, 0.0, -1.0, 0.0));
  direction = glm::length(d) > 0.0 ? vec3(glm::normalize(d)) : vec3(0.0f, 0.0f, -1.0f);
}

std::string NodeAnimation::clip_label(size_t clip) const {
  return clip < clips.size() && !clips[clip].empty() ? fmt::format("'{}'", clips[clip]) : fmt::format("#{}", clip);
}

std::string NodeAnimation::clip_list() const {
  std::string out;
  for (size_t c = 0; c < clips.size(); ++c) out += (c > 0 ? ", " : "") + clip_label(c);
  return out;
}

bool NodeAnimation::above(int ancestor, int node) const {
  for (int n = node; n >= 0 && static_cast<size_t>(n) < parent.size(); n = parent[static_cast<size_t>(n)])
    if (n == ancestor) return true;
  return false;
}

std::pair<double, double> NodeAnimation::time_range(const std::vector<int>& nodes) const {
  bool any = false;
  double lo = 0.0, hi = 0.0;
  for (const Channel& c : channels) {
    if (std::none_of(nodes.begin(), nodes.end(), [&](int node) { return above(c.node, node); })) continue;
    lo = any ? std::min(lo, c.times.front()) : c.times.front();
    hi = any ? std::max(hi, c.times.back()) : c.times.back();
    any = true;
  }
  return {lo, hi};
}

bool NodeAnimation::moves(int node) const {
  return std::any_of(channels.begin(), channels.end(), [&](const Channel& c) { return above(c.node, node); });
}

dmat4 NodeAnimation::local_at(int node, double time) const {
  Local l = local[static_cast<size_t>(node)];
  if (l.matrix) return *l.matrix;
  for (const Channel& c : channels) {
    if (c.node != node) continue;
    if (c.property == Property::rotation) {
      const std::array<double, 4> v = sample(c, time, 4);
      const dquat q(v[3], v[0], v[1], v[2]);
      const double len = glm::length(q);
      l.rotation = len > 0.0 ? q / len : dquat(1.0, 0.0, 0.0, 0.0);
    } else {
      const std::array<double, 4> v = sample(c, time, 3);
      (c.property == Property::translation ? l.translation : l.scale) = dvec3(v[0], v[1], v[2]);
    }
  }
  return l.transform();
}

dmat4 NodeAnimation::world(int node, double time) const {
  dmat4 w(1.0);
  for (int n = node; n >= 0; n = parent[static_cast<size_t>(n)]) w = local_at(n, time) * w;
  return w;
}

dmat4 NodeAnimation::rest_world(int node) const {
  dmat4 w(1.0);
  for (int n = node; n >= 0; n = parent[static_cast<size_t>(n)]) w = local[static_cast<size_t>(n)].transform() * w;
  return w;
}

size_t Scene::triangle_count() const {
  size_t n = 0;
  for (const Mesh& m : meshes) n += m.triangle_count();
  return n;
}

bool Mesh::is_closed() const {
  // Corners by position: vertices repeated along a seam (other normals or texture coordinates)
  // are one corner. Sorting the vertices by position numbers the distinct positions.
  const size_t n = positions.size();
  if (n == 0 || n >= (size_t{1} << 31)) return false;
  for (const vec3& p : positions)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return false;
  std::vector<uint32_t> order(n);
  for (size_t i = 0; i < n; ++i) order[i] = static_cast<uint32_t>(i);
  const auto less = [this](uint32_t a, uint32_t b) {
    const vec3 &p = positions[a], &q = positions[b];
    return p.x != q.x ? p.x < q.x : p.y != q.y ? p.y < q.y : p.z < q.z;
  };
  std::sort(order.begin(), order.end(), less);
  std::vector<uint32_t> corner(n);
  uint32_t distinct = 0;
  for (size_t k = 0; k < n; ++k) {
    if (k > 0 && less(order[k - 1], order[k])) ++distinct;
    corner[order[k]] = distinct;
  }
  // The triangles with three distinct corners (a collapsed one, as at a pole, covers nothing):
  // the faces, numbered in `triangle`'s order.
  if (indices.size() / 3 > std::numeric_limits<uint32_t>::max()) return false;
  const auto face_corner = [&](uint32_t t, int k) { return corner[indices[3 * size_t{t} + static_cast<size_t>(k)]]; };
  std::vector<uint32_t> triangle;
  triangle.reserve(indices.size() / 3);
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    if (indices[t] >= n || indices[t + 1] >= n || indices[t + 2] >= n) return false;
    const auto tri = static_cast<uint32_t>(t / 3);
    const uint32_t c0 = face_corner(tri, 0), c1 = face_corner(tri, 1), c2 = face_corner(tri, 2);
    if (c0 != c1 && c1 != c2 && c2 != c0) triangle.push_back(tri);
  }
  if (triangle.empty()) return false;
  // Every directed edge, keyed by its undirected edge (lower corner, higher corner) with its
  // direction in the lowest bit, beside the face it bounds.
  std::vector<std::pair<uint64_t, uint32_t>> edges;
  edges.reserve(3 * triangle.size());
  for (size_t f = 0; f < triangle.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const uint64_t a = face_corner(triangle[f], k), b = face_corner(triangle[f], (k + 1) % 3);
      edges.emplace_back((std::min(a, b) << 33) | (std::max(a, b) << 1) | (a > b ? 1u : 0u), static_cast<uint32_t>(f));
    }
  std::sort(edges.begin(), edges.end());
  // Closed: every edge is met as often in one direction as in the other (once each on a manifold
  // surface; closed parts that share an edge, as boxes of a wall standing edge to edge, meet it
  // twice each way). Parts: faces joined across the edges met once each way, so that parts that
  // only touch (at an edge met more often, or at a corner) stay apart.
  std::vector<uint32_t> part(triangle.size());
  for (size_t f = 0; f < triangle.size(); ++f) part[f] = static_cast<uint32_t>(f);
  const auto root = [&part](uint32_t f) {
    while (part[f] != f) f = part[f] = part[part[f]];
    return f;
  };
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    int64_t balance = 0;
    for (; j < edges.size() && (edges[j].first >> 1) == (edges[i].first >> 1); ++j)
      balance += (edges[j].first & 1u) != 0 ? 1 : -1;
    if (balance != 0) return false;
    if (j - i == 2) part[root(edges[i].second)] = root(edges[i + 1].second);
    i = j;
  }
  // Wound outwards, each part (triangles counter-clockwise seen from outside, as the positions and
  // indices of a mirrored mesh are too): an inside-out part shows only back faces from outside.
  // Six times each part's signed volume, summed about the first corner of the part's root face
  // (about the origin, the rounding of a small part far from it could flip the sign).
  const auto corner_of = [&](uint32_t f, int k) {
    return dvec3(positions[indices[3 * size_t{triangle[f]} + static_cast<size_t>(k)]]);
  };
  std::vector<double> volume6(triangle.size(), 0.0);
  for (size_t f = 0; f < triangle.size(); ++f) {
    const auto face = static_cast<uint32_t>(f);
    const uint32_t r = root(face);
    const dvec3 o = corner_of(r, 0);
    volume6[r] += glm::dot(corner_of(face, 0) - o, glm::cross(corner_of(face, 1) - o, corner_of(face, 2) - o));
  }
  for (size_t f = 0; f < triangle.size(); ++f)
    if (part[f] == f && !(volume6[f] > 0.0)) return false;
  return true;
}

bool Mesh::zero_area(size_t t) const {
  const dvec3 a(positions[indices[3 * t]]);
  const dvec3 b(positions[indices[3 * t + 1]]);
  const dvec3 c(positions[indices[3 * t + 2]]);
  const dvec3 n = glm::cross(b - a, c - a);
  return n.x == 0.0 && n.y == 0.0 && n.z == 0.0;
}

size_t Scene::zero_area_triangle_count() const {
  size_t n = 0;
  for (const Mesh& m : meshes)
    for (size_t t = 0; t < m.triangle_count(); ++t) n += m.zero_area(t);
  return n;
}

bool Scene::has_triangle_with_area() const {
  for (const Mesh& m : meshes)
    for (size_t t = 0; t < m.triangle_count(); ++t)
      if (!m.zero_area(t)) return true;
  return false;
}

bool Scene::has_cutouts() const {
  return std::any_of(materials.begin(), materials.end(),
                     [](const Material& m) { return m.alpha_mode == Material::AlphaMode::mask; });
}

size_t Scene::vertex_count() const {
  size_t n = 0;
  for (const Mesh& m : meshes) n += m.positions.size();
  return n;
}

Bounds3 Scene::bounds() const {
  Bounds3 b;
  for (const Mesh& m : meshes)
    for (const vec3& p : m.positions) b.extend(p);
  return b;
}

std::string Scene::file_stem() const {
  constexpr size_t kMaxStem = 64;
  std::string stem = (path.empty() ? name : std::filesystem::path(path).stem().string()).substr(0, kMaxStem);
  for (char& c : stem) {
    const bool kept = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                      c == '_' || c == '-' || c == '+';
    if (!kept) c = '_';
  }
  if (!stem.empty() && stem[0] == '.') stem[0] = '_';
  return stem.empty() ? "scene" : stem;
}

void keep_first_lights(Scene& scene, int count) {
  const size_t available = scene.lights.size();
  if (available == 0)
    throw InputError(fmt::format("--lights {}: scene '{}' ({}) has 0 lights; drop --lights", count, scene.name,
                                 scene.path));
  if (count < 1 || static_cast<size_t>(count) > available)
    throw InputError(fmt::format("--lights {}: scene '{}' ({}) has {} light{}; give 1..{}", count, scene.name,
                                 scene.path, available, available == 1 ? "" : "s", available));
  scene.lights.resize(static_cast<size_t>(count));
}

bool is_unlit(const Scene& scene) {
  if (scene.ambient > 0.0f) return false;
  for (const Light& l : scene.lights)
    if (l.intensity > 0.0f && (l.color.x > 0.0f || l.color.y > 0.0f || l.color.z > 0.0f)) return false;
  return true;
}

}  // namespace sb
