// Global triangle numbering.
#include "renderer/scene_geometry.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "renderer/error.hpp"

namespace sb {

SceneGeometry::SceneGeometry(const Scene& s) : scene(&s) {
  first_triangle.reserve(s.meshes.size() + 1);
  first_triangle.push_back(0);
  uint64_t total = 0;
  for (const Mesh& m : s.meshes) {
    total += m.triangle_count();
    if (total >= kNoPrimitiveId)
      throw InputError(fmt::format("{}: more than {} triangles; primitive ids are 32-bit", s.path, kNoPrimitiveId - 1));
    first_triangle.push_back(static_cast<uint32_t>(total));
    const bool double_sided = m.material < 0 || s.materials[static_cast<size_t>(m.material)].double_sided;
    single_sided.push_back(double_sided ? 0 : 1);
  }
}

std::pair<uint32_t, uint32_t> SceneGeometry::locate(uint32_t prim_id) const {
  const auto it = std::upper_bound(first_triangle.begin(), first_triangle.end(), prim_id);
  const auto mesh = static_cast<uint32_t>(it - first_triangle.begin() - 1);
  return {mesh, prim_id - first_triangle[mesh]};
}

}  // namespace sb
