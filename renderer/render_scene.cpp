// Scene preparation shared by all pipelines.
#include "renderer/render_scene.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "renderer/error.hpp"

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

/// Shadow-ray offset: 2^-16 of the largest coordinate magnitude (about 128 float ulps), at least 1e-5 m.
float shadow_offset(const Bounds3& b) {
  float extent = 1.0f;
  if (!b.empty()) extent = std::max({std::fabs(b.lo.x), std::fabs(b.lo.y), std::fabs(b.lo.z), std::fabs(b.hi.x),
                                     std::fabs(b.hi.y), std::fabs(b.hi.z), 1.0f});
  return std::max(1e-5f, extent * 1.52588e-5f);
}

}  // namespace

// The range check comes first (ray_epsilon_ is the first member), before Embree sees the geometry.
RenderScene::RenderScene(const Scene& scene, bool refittable)
    : ray_epsilon_(shadow_offset(checked_bounds(scene))), scene_(&scene), geometry_(scene),
      rays_(geometry_, refittable) {
  const auto t0 = std::chrono::steady_clock::now();
  textures_.reserve(scene.textures.size());
  for (const Texture& t : scene.textures) textures_.emplace_back(t);
  texture_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double RenderScene::update_geometry() {
  (void)checked_bounds(*scene_);
  return rays_.update();
}

}  // namespace sb
