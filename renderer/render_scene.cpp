// Scene preparation shared by all pipelines.
#include "renderer/render_scene.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "renderer/error.hpp"

namespace sb {

namespace {

/// InputError when the scene's geometry reaches beyond the coordinate range rays can use.
void require_range(const Scene& scene) {
  const Bounds3 b = scene.bounds();
  if (b.empty() || (within_scene_range(b.lo) && within_scene_range(b.hi))) return;
  throw InputError(fmt::format("scene '{}'{}: its geometry spans ({:g}, {:g}, {:g}) to ({:g}, {:g}, {:g}) m, beyond the "
                               "±{:g} m a scene may span; check its scale and units (and its animation)",
                               scene.name, scene.path.empty() ? "" : " (" + scene.path + ")", b.lo.x, b.lo.y, b.lo.z,
                               b.hi.x, b.hi.y, b.hi.z, kMaxSceneCoordinate));
}

}  // namespace

RenderScene::RenderScene(const Scene& scene, bool refittable)
    : scene_((require_range(scene), &scene)), geometry_(scene), rays_(geometry_, refittable) {
  const auto t0 = std::chrono::steady_clock::now();
  textures_.reserve(scene.textures.size());
  for (const Texture& t : scene.textures) textures_.emplace_back(t);
  texture_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // Shadow-ray offset: 2^-16 of the largest coordinate magnitude (about 128 float ulps), at least 1e-5 m.
  const Bounds3 b = scene.bounds();
  float extent = 1.0f;
  if (!b.empty()) extent = std::max({std::fabs(b.lo.x), std::fabs(b.lo.y), std::fabs(b.lo.z), std::fabs(b.hi.x),
                                     std::fabs(b.hi.y), std::fabs(b.hi.z), 1.0f});
  ray_epsilon_ = std::max(1e-5f, extent * 1.52588e-5f);
}

double RenderScene::update_geometry() {
  require_range(*scene_);
  return rays_.update();
}

}  // namespace sb
