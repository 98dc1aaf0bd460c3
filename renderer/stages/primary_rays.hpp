// Primary rays through pixel centres and the packet order they are traced in, shared by every
// stage that traces an eye's pixels, so that they all cast bit-identical rays in identical packets
// and see exactly the same primitives.
#pragma once

#include <algorithm>
#include <cstdint>

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

/// Cosine between a primary ray's direction and the eye's optical axis: a hit at distance t has
/// linear depth t * cos_to_axis.
[[nodiscard]] inline float cos_to_axis(const EyeCamera& eye, const vec3& dir) {
  return glm::dot(dir, vec3(-eye.back));
}

/// Calls block(pixels, n) for each 4x4 block of `tile` (partial at its right and bottom edges),
/// blocks and the pixels inside a block in row-major order; pixels are indices y * width + x.
/// 4x4 blocks keep the packets of 16 rays coherent.
template <class F>
void for_pixel_blocks(const PixelRect& tile, int width, F&& block) {
  uint32_t pixels[kRayPacket];
  for (int by = tile.y0; by < tile.y1; by += 4)
    for (int bx = tile.x0; bx < tile.x1; bx += 4) {
      int n = 0;
      for (int y = by; y < std::min(by + 4, tile.y1); ++y)
        for (int x = bx; x < std::min(bx + 4, tile.x1); ++x) pixels[n++] = static_cast<uint32_t>(y * width + x);
      block(static_cast<const uint32_t*>(pixels), n);
    }
}

}  // namespace sb
