// Scene summaries.
#include "renderer/scene.hpp"

namespace sb {

size_t Scene::triangle_count() const {
  size_t n = 0;
  for (const Mesh& m : meshes) n += m.triangle_count();
  return n;
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

}  // namespace sb
