// Depth rays cut at the near plane, counted where they hit (see near_plane.hpp).
#include "renderer/stages/near_plane.hpp"

#include <atomic>

#include "renderer/stages/primary_rays.hpp"

namespace sb {

uint64_t pixels_before_near_plane(const RenderScene& scene, const EyeCamera& eye, const Executor& executor) {
  const PrimaryRays primary(eye);
  const auto znear = static_cast<float>(eye.znear);
  std::atomic<uint64_t> count{0};
  executor.for_tiles(eye.width, eye.height, kTraceTile, [&](const PixelRect& tile) {
    uint64_t tile_count = 0;
    for_pixel_blocks(tile, eye.width, [&](const PixelBlock& block) {
      RayQuery rays[kRayPacket];
      RayHit hits[kRayPacket];
      for (int i = 0; i < block.n; ++i) {
        // The depth ray's parameter is the linear depth: it ends at the near plane.
        rays[i] = primary.depth_ray(block.x[i], block.y[i]);
        rays[i].tfar = znear;
      }
      // Intersection, not occlusion: single-sided triangles seen from behind are culled, as the
      // rasterizer culls them.
      scene.rays().intersect(std::span<const RayQuery>(rays, static_cast<size_t>(block.n)),
                             std::span<RayHit>(hits, static_cast<size_t>(block.n)));
      for (int i = 0; i < block.n; ++i) tile_count += hits[i].prim != kNoPrimitiveId ? 1 : 0;
    });
    count += tile_count;
  });
  return count.load();
}

}  // namespace sb
