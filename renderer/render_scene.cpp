// Scene preparation shared by all pipelines.
#include "renderer/render_scene.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace sb {

RenderScene::RenderScene(const Scene& scene, bool refittable)
    : scene_(&scene), geometry_(scene), rays_(geometry_, refittable) {
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

}  // namespace sb
