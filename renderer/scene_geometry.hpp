// Global triangle numbering over a scene's meshes and per-mesh facing rules, shared by the
// rasterizer and the ray tracer so that both report the same primitive ids.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "renderer/scene.hpp"

namespace sb {

/// Marks "no primitive" in primitive-id buffers.
constexpr uint32_t kNoPrimitiveId = 0xFFFFFFFFu;

/// Global triangle ids: mesh m's local triangle t has id first_triangle[m] + t.
struct SceneGeometry {
  const Scene* scene = nullptr;
  std::vector<uint32_t> first_triangle;  ///< size meshes + 1 (prefix sums)
  std::vector<uint8_t> single_sided;     ///< per mesh: 1 = back faces are culled (material not double-sided)

  explicit SceneGeometry(const Scene& s);
  [[nodiscard]] uint32_t triangle_count() const { return first_triangle.back(); }
  /// (mesh index, local triangle index) of a global triangle id.
  [[nodiscard]] std::pair<uint32_t, uint32_t> locate(uint32_t prim_id) const;
};

/// A triangle is front-facing when its vertices appear counter-clockwise from the viewer
/// (glTF's convention): dot(cross(v1 - v0, v2 - v0), eye - v0) > 0. Both the rasterizer and the
/// ray tracer cull back faces of single-sided meshes by this one rule.
[[nodiscard]] inline bool front_facing(const dvec3& v0, const dvec3& v1, const dvec3& v2, const dvec3& eye) {
  return glm::dot(glm::cross(v1 - v0, v2 - v0), eye - v0) > 0.0;
}

}  // namespace sb
