// Scene summaries.
#include "renderer/scene.hpp"

#include <fmt/format.h>

#include "renderer/error.hpp"

namespace sb {

size_t Scene::triangle_count() const {
  size_t n = 0;
  for (const Mesh& m : meshes) n += m.triangle_count();
  return n;
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
  std::string stem = name.substr(0, kMaxStem);
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
