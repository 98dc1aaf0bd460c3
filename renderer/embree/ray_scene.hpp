// The Embree 3 backend: one BVH over the scene's triangles, built once and shared by every
// pipeline; closest-hit queries in packets of up to 16 rays and occlusion (shadow) queries.
// Only renderer/embree/*.cpp include Embree's headers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>

#include "renderer/math.hpp"
#include "renderer/scene_geometry.hpp"

namespace sb {

/// A ray segment [tnear, tfar] along origin + t * dir.
struct RayQuery {
  vec3 origin{0.0f};
  vec3 dir{0.0f, 0.0f, -1.0f};
  float tnear = 0.0f;
  float tfar = std::numeric_limits<float>::infinity();
};

/// The closest hit of a ray: prim is kNoPrimitiveId on a miss; bary follows Embree's (u, v).
struct RayHit {
  float t = std::numeric_limits<float>::infinity();
  uint32_t prim = kNoPrimitiveId;
  vec2 bary{0.0f};
};

/// The maximum number of rays in one query call.
constexpr int kRayPacket = 16;

/// The scene's BVH. Thread-safe for queries once constructed.
class RayScene {
 public:
  /// Builds the BVH. With `refittable`, the BVH is built so that update() refits it (Embree's
  /// dynamic scene and refit build quality) instead of rebuilding it.
  explicit RayScene(const SceneGeometry& geometry, bool refittable = false);
  ~RayScene();
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  /// Closest hits of up to 16 rays. Back faces of single-sided meshes are skipped (front_facing()).
  /// Only the lanes whose bit is set in `lanes` (bit i for ray i) are traced; the others' hits are
  /// left as they were.
  void intersect(std::span<const RayQuery> rays, std::span<RayHit> hits, uint32_t lanes = 0xFFFFu) const;
  /// Occlusion of up to 16 ray segments: blocked[i] = 1 when anything lies within [tnear, tfar].
  void occluded(std::span<const RayQuery> rays, std::span<uint8_t> blocked) const;

  /// After the vertex positions of meshes `moved` changed in place (same meshes, same topology):
  /// copies theirs into the BVH's buffers and refits (refittable) or rebuilds it; the other meshes'
  /// data is left as it is. Returns the seconds taken.
  double update(std::span<const size_t> moved);

  [[nodiscard]] double build_seconds() const { return build_seconds_; }
  /// Peak bytes Embree allocated for the scene (BVH and geometry buffers).
  [[nodiscard]] size_t memory_bytes() const { return memory_bytes_; }
  [[nodiscard]] static const char* version();

  struct Impl;  ///< Embree handles; defined in ray_scene.cpp

 private:
  std::unique_ptr<Impl> impl_;
  double build_seconds_ = 0.0;
  size_t memory_bytes_ = 0;
};

}  // namespace sb
