// Primary rays through pixel centres and the packet order they are traced in, shared by every
// stage that traces an eye's pixels, so that they all cast bit-identical rays in identical packets
// and see exactly the same primitives.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "renderer/embree/ray_scene.hpp"
#include "renderer/parallel.hpp"
#include "renderer/rig.hpp"

namespace sb {

/// Side of the square tiles a whole-eye trace is split into (one task per tile).
inline constexpr int kTraceTile = 32;

/// The primary ray through the centre of pixel (x, y): from the eye's origin along its unit
/// direction, both rounded to float; tnear 0, tfar infinite.
[[nodiscard]] inline RayQuery primary_ray(const EyeCamera& eye, int x, int y) {
  RayQuery q;
  q.origin = vec3(eye.origin);
  q.dir = vec3(eye.ray_direction(x + 0.5, y + 0.5));
  return q;
}

/// The primary rays of an eye through its pixel centres, with the per-column and per-row terms of
/// EyeCamera::ray_direction computed once: the same operations in the same order, so the same bits
/// as primary_ray, for two divisions fewer per ray in loops that cast one per pixel.
class PrimaryRays {
 public:
  explicit PrimaryRays(const EyeCamera& eye) : origin_(eye.origin), back_(eye.back) {
    column_.reserve(static_cast<size_t>(eye.width));
    for (int x = 0; x < eye.width; ++x) column_.push_back((x + 0.5 - eye.cx) / eye.f_px * eye.right);
    row_.reserve(static_cast<size_t>(eye.height));
    for (int y = 0; y < eye.height; ++y) row_.push_back((eye.cy - (y + 0.5)) / eye.f_px * eye.up);
  }

  /// primary_ray(eye, x, y) for a pixel of the image.
  [[nodiscard]] RayQuery operator()(int x, int y) const {
    RayQuery q;
    q.origin = vec3(origin_);
    q.dir = vec3(glm::normalize(axial(x, y)));
    return q;
  }

  /// The same ray with its direction left unnormalized, its component along the optical axis 1:
  /// the ray parameter is the linear depth (for queries that end at a depth, not for hits).
  [[nodiscard]] RayQuery depth_ray(int x, int y) const {
    RayQuery q;
    q.origin = vec3(origin_);
    q.dir = vec3(axial(x, y));
    return q;
  }

 private:
  [[nodiscard]] dvec3 axial(int x, int y) const {
    return column_[static_cast<size_t>(x)] + row_[static_cast<size_t>(y)] - back_;
  }
  dvec3 origin_, back_;
  std::vector<dvec3> column_, row_;
};

/// Cosine between a primary ray's direction and the eye's optical axis: a hit at distance t has
/// linear depth t * cos_to_axis.
[[nodiscard]] inline float cos_to_axis(const EyeCamera& eye, const vec3& dir) {
  return glm::dot(dir, vec3(-eye.back));
}

/// One 4x4 block of pixels (fewer at the image's right and bottom edges), row-major: each lane's
/// index y * width + x and its coordinates.
struct PixelBlock {
  uint32_t index[kRayPacket];
  int x[kRayPacket];
  int y[kRayPacket];
  int n = 0;
};

/// Calls block(const PixelBlock&) for each 4x4 block of `tile` (partial at its right and bottom
/// edges), blocks and the pixels inside a block in row-major order. 4x4 blocks keep the packets of
/// 16 rays coherent.
template <class F>
void for_pixel_blocks(const PixelRect& tile, int width, F&& block) {
  PixelBlock b;
  for (int by = tile.y0; by < tile.y1; by += 4)
    for (int bx = tile.x0; bx < tile.x1; bx += 4) {
      b.n = 0;
      for (int y = by; y < std::min(by + 4, tile.y1); ++y)
        for (int x = bx; x < std::min(bx + 4, tile.x1); ++x) {
          b.index[b.n] = static_cast<uint32_t>(y * width + x);
          b.x[b.n] = x;
          b.y[b.n++] = y;
        }
      block(static_cast<const PixelBlock&>(b));
    }
}

}  // namespace sb
