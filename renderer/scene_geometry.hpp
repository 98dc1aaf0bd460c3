// Global triangle numbering over a scene's meshes and per-mesh facing rules, shared by the
// rasterizer and the ray tracer so that both report the same primitive ids.
#pragma once

#include <cstdint>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>

#include "renderer/parallel.hpp"
#include "renderer/scene.hpp"
#include "renderer/texture.hpp"

namespace sb {

/// Marks "no primitive" in primitive-id buffers.
constexpr uint32_t kNoPrimitiveId = 0xFFFFFFFFu;

/// The cut-out of a mesh whose material has glTF alphaMode MASK: its alpha is the base colour
/// factor's alpha times the base colour texture's alpha, and the surface exists where that is at
/// least the cutoff.
struct Cutout {
  const MipTexture* texture = nullptr;  ///< level 0 of the base colour texture, or null (factor alone)
  float factor_alpha = 1.0f;
  float cutoff = 0.5f;
};

/// Global triangle ids: mesh m's local triangle t has id first_triangle[m] + t.
struct SceneGeometry {
  const Scene* scene = nullptr;
  std::vector<uint32_t> first_triangle;  ///< size meshes + 1 (prefix sums)
  std::vector<uint8_t> single_sided;     ///< per mesh: 1 = back faces are culled (material not double-sided)
  /// Per mesh: index into `cutouts`, or -1 for a mesh that is opaque everywhere.
  std::vector<int32_t> cutout_of;
  std::vector<Cutout> cutouts;

  explicit SceneGeometry(const Scene& s);
  SceneGeometry(const SceneGeometry&) = delete;  // cutouts point into cutout_textures_
  SceneGeometry& operator=(const SceneGeometry&) = delete;
  [[nodiscard]] uint32_t triangle_count() const { return first_triangle.back(); }
  /// (mesh index, local triangle index) of a global triangle id.
  [[nodiscard]] std::pair<uint32_t, uint32_t> locate(uint32_t prim_id) const;
  /// Per mesh: 1 = double-sided, opaque everywhere, and closed and wound outwards as loaded
  /// (Mesh::is_closed): seen from outside, with no plane cutting it open, its front faces hide every
  /// back face, so culling them changes no image (Kim's redirection relies on that). Computed on
  /// the first call after construction or forget_closed() from the positions as they are then
  /// (meshes in parallel, a sort of each one's edges: about 1 s on 2 cores for 1e7 triangles); the
  /// other pipelines never pay for it. Not to be called from inside a loop of `executor`.
  [[nodiscard]] const std::vector<uint8_t>& closed(const Executor& executor) const;
  /// Drops the flags closed() found: the positions moved (a path's frame), and a frame's flags
  /// must not depend on the frame they were first found at (a node scaled to nothing at one frame
  /// has only collapsed triangles there).
  void forget_closed();
  /// Whether the mesh has a cut-out (alphaMode MASK).
  [[nodiscard]] bool has_cutout(uint32_t mesh) const { return cutout_of[mesh] >= 0; }
  /// Whether local triangle `tri` of `mesh` exists at barycentrics (b1, b2): always for an opaque
  /// mesh; for a cut-out, where its alpha reaches the cutoff. The texture's alpha is read by a
  /// bilinear lookup in level 0 at the interpolated texture coordinates, the same for rays and the
  /// rasterizer (and Blender's Linear lookup), so that coverage never depends on a level of detail.
  /// Without texture coordinates the alpha is the factor's alone, as for the albedo.
  [[nodiscard]] bool opaque_at(uint32_t mesh, uint32_t tri, vec2 bary) const;

 private:
  std::vector<MipTexture> cutout_textures_;  ///< level 0 of each texture a cut-out reads
  mutable std::mutex closed_mutex_;
  mutable std::optional<std::vector<uint8_t>> closed_;  ///< closed()'s flags, once found
};

/// A triangle is front-facing when its vertices appear counter-clockwise from the viewer
/// (glTF's convention): dot(cross(v1 - v0, v2 - v0), eye - v0) > 0. Both the rasterizer and the
/// ray tracer cull back faces of single-sided meshes by this one rule.
[[nodiscard]] inline bool front_facing(const dvec3& v0, const dvec3& v1, const dvec3& v2, const dvec3& eye) {
  return glm::dot(glm::cross(v1 - v0, v2 - v0), eye - v0) > 0.0;
}

}  // namespace sb
