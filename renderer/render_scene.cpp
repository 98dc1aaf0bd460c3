// Scene preparation shared by all pipelines.
#include "renderer/render_scene.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/memory.hpp"

namespace sb {

namespace {

/// The scene's bounds; InputError when a vertex is not a finite point (NaN positions would drop out
/// of the bounds and of every ray query, leaving an empty image that compares as perfect) or the
/// geometry reaches beyond the coordinate range rays can use.
Bounds3 checked_bounds(const Scene& scene) {
  Bounds3 b;
  for (const Mesh& m : scene.meshes)
    for (size_t i = 0; i < m.positions.size(); ++i) {
      const vec3& p = m.positions[i];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        throw InputError(fmt::format("scene '{}'{}: vertex {} of mesh '{}' is not a finite point ({}, {}, {}); check "
                                     "the scene's positions and its animation",
                                     scene.name, scene.path.empty() ? "" : " (" + scene.path + ")", i, m.name, p.x,
                                     p.y, p.z));
      b.extend(p);
    }
  if (b.empty() || (within_scene_range(b.lo) && within_scene_range(b.hi))) return b;
  throw InputError(fmt::format("scene '{}'{}: its geometry spans ({:g}, {:g}, {:g}) to ({:g}, {:g}, {:g}) m, beyond the "
                               "±{:g} m a scene may span; check its scale and units (and its animation)",
                               scene.name, scene.path.empty() ? "" : " (" + scene.path + ")", b.lo.x, b.lo.y, b.lo.z,
                               b.hi.x, b.hi.y, b.hi.z, kMaxSceneCoordinate));
}

/// Embree's peak while building, per triangle with its vertex and index buffers: 119-153 B
/// measured (bvh memory of `stereobench bench` on the built-in scenes and on complexity with 1e6
/// and 5e6 triangles), taken as 160 B plus 16 B per vertex for meshes with many vertices.
constexpr uint64_t kBvhBytesPerTriangle = 160;
constexpr uint64_t kBvhBytesPerVertex = 16;

/// Refuses a scene whose acceleration structure and texture mip chains (16 B per texel, 4/3 for
/// the chain) would not fit in memory, before any of them is built.
void require_scene_memory(const Scene& scene) {
  uint64_t triangles = 0, vertices = 0, texels = 0;
  for (const Mesh& m : scene.meshes) {
    triangles += m.triangle_count();
    vertices += m.positions.size();
  }
  for (const Texture& t : scene.textures) texels += static_cast<uint64_t>(t.width) * static_cast<uint64_t>(t.height);
  // A texture that cut-outs read is kept once more, level 0 alone (SceneGeometry); counted once
  // per material that reads it, an upper bound.
  for (const Material& m : scene.materials)
    if (m.alpha_mode == Material::AlphaMode::mask && m.base_color_texture >= 0 &&
        static_cast<size_t>(m.base_color_texture) < scene.textures.size()) {
      const Texture& t = scene.textures[static_cast<size_t>(m.base_color_texture)];
      texels += static_cast<uint64_t>(t.width) * static_cast<uint64_t>(t.height) * 3 / 4;  // 16 B each below
    }
  require_memory(kBvhBytesPerTriangle * triangles + kBvhBytesPerVertex * vertices + texels * 16 * 4 / 3,
                 fmt::format("preparing scene '{}' for rendering ({} triangles, {} texels of textures)", scene.name,
                             triangles, texels),
                 "use a smaller scene, or run on a machine with more memory");
}

/// The scene's bounds, once its range and size are checked.
Bounds3 checked_for_rendering(const Scene& scene) {
  require_scene_memory(scene);
  return checked_bounds(scene);
}

/// Shadow-ray offset: 2^-16 of the largest coordinate magnitude (about 128 float ulps), at least 1e-5 m.
float shadow_offset(const Bounds3& b) {
  float extent = 1.0f;
  if (!b.empty()) extent = std::max({std::fabs(b.lo.x), std::fabs(b.lo.y), std::fabs(b.lo.z), std::fabs(b.hi.x),
                                     std::fabs(b.hi.y), std::fabs(b.hi.z), 1.0f});
  return std::max(1e-5f, extent * 1.52588e-5f);
}

}  // namespace

// The range and memory checks come first (ray_epsilon_ is the first member), before Embree sees the
// geometry.
RenderScene::RenderScene(const Scene& scene, bool refittable)
    : ray_epsilon_(shadow_offset(checked_for_rendering(scene))), scene_(&scene), geometry_(scene),
      rays_(geometry_, refittable) {
  const auto t0 = std::chrono::steady_clock::now();
  textures_.reserve(scene.textures.size());
  for (const Texture& t : scene.textures) textures_.emplace_back(t);
  texture_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double RenderScene::update_geometry(std::span<const size_t> moved) {
  // The offset follows the moved bounds, as a scene prepared at this frame has it: a frame's image
  // must not depend on which frame the worker prepared first.
  ray_epsilon_ = shadow_offset(checked_bounds(*scene_));
  geometry_.forget_closed();
  return rays_.update(moved);
}

}  // namespace sb
