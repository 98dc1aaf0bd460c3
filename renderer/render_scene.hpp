// A scene prepared for rendering: global triangle ids, the Embree BVH and the textures' mip chains,
// built once and shared by every pipeline and every repetition.
#pragma once

#include <span>
#include <vector>

#include "renderer/embree/ray_scene.hpp"
#include "renderer/scene.hpp"
#include "renderer/scene_geometry.hpp"
#include "renderer/texture.hpp"

namespace sb {

class RenderScene {
 public:
  /// Prepares `scene`, which must outlive this object. With `refittable`, the BVH is built for
  /// update_geometry() to refit it (animated scenes). InputError when the scene's geometry reaches
  /// beyond ±kMaxSceneCoordinate (loaders check their files first, naming the node).
  explicit RenderScene(const Scene& scene, bool refittable = false);
  RenderScene(const RenderScene&) = delete;
  RenderScene& operator=(const RenderScene&) = delete;

  [[nodiscard]] const Scene& scene() const { return *scene_; }
  [[nodiscard]] const SceneGeometry& geometry() const { return geometry_; }
  [[nodiscard]] const RayScene& rays() const { return rays_; }
  [[nodiscard]] const MipTexture& texture(int index) const { return textures_[static_cast<size_t>(index)]; }
  /// Seconds spent building the BVH and the mip chains.
  [[nodiscard]] double bvh_build_seconds() const { return rays_.build_seconds(); }
  [[nodiscard]] double texture_build_seconds() const { return texture_seconds_; }
  /// A length below the float resolution of the scene's coordinates times a safety factor: the
  /// offset of shadow-ray origins.
  [[nodiscard]] float ray_epsilon() const { return ray_epsilon_; }

  /// After the vertex positions and normals of meshes `moved` changed in place (rigid animation:
  /// same meshes and topology, see renderer/animation.hpp): updates their BVH data, refits or
  /// rebuilds the BVH and sets the ray offset from the moved bounds, as a scene prepared at the
  /// new positions has it; returns the seconds taken. Materials, textures and lights are read from
  /// the scene as they are. InputError when the moved geometry leaves the range a scene may span
  /// (kMaxSceneCoordinate).
  double update_geometry(std::span<const size_t> moved);

 private:
  float ray_epsilon_;  ///< first: computed from the range-checked bounds before the BVH is built
  const Scene* scene_;
  SceneGeometry geometry_;
  RayScene rays_;
  std::vector<MipTexture> textures_;
  double texture_seconds_ = 0.0;
};

}  // namespace sb
