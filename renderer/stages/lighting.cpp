// Deferred lighting over a G-buffer in 4x4 blocks (16 shadow rays per light per block).
#include "renderer/stages/lighting.hpp"

#include <atomic>

#include "renderer/shading.hpp"
#include "renderer/stages/eye_image.hpp"

namespace sb {

void shade_gbuffer(const RenderScene& scene, const EyeCamera& eye, const GBuffer& gbuffer, const Executor& executor,
                   Image& image, TraceCounts& counts, const uint8_t* mask, Source source) {
  std::atomic<uint64_t> shadow{0}, shaded{0};
  const int w = gbuffer.width, h = gbuffer.height;
  const vec3 origin(eye.origin);
  executor.for_tiles(w, h, 32, [&](const PixelRect& tile) {
    EyeWriter writer(image);
    ShadeCounts local;
    SurfacePoint points[kRayPacket];
    vec3 albedo[kRayPacket];
    vec3 radiance[kRayPacket];
    float depth[kRayPacket];
    uint32_t where[kRayPacket];
    for (int by = tile.y0; by < tile.y1; by += 4)
      for (int bx = tile.x0; bx < tile.x1; bx += 4) {
        int m = 0;
        for (int y = by; y < std::min(by + 4, tile.y1); ++y)
          for (int x = bx; x < std::min(bx + 4, tile.x1); ++x) {
            const size_t i = gbuffer.index(x, y);
            if (mask && !mask[i]) continue;
            if (gbuffer.prim[i] == kNoPrimitiveId) {
              writer.background(i, scene.scene().background, source);
              continue;
            }
            SurfacePoint& p = points[m];
            p = surface_at(scene, gbuffer.prim[i], gbuffer.bary[i], origin);
            albedo[m] = albedo_at(scene, p, derivative_lod(scene, p, gbuffer.duv[i]));
            depth[m] = gbuffer.depth[i];
            where[m] = static_cast<uint32_t>(i);
            ++m;
          }
        if (m == 0) continue;
        shade(scene, std::span<const SurfacePoint>(points, static_cast<size_t>(m)),
              std::span<const vec3>(albedo, static_cast<size_t>(m)), std::span<vec3>(radiance, static_cast<size_t>(m)),
              local);
        for (int k = 0; k < m; ++k) writer.surface(where[k], points[k], radiance[k], albedo[k], depth[k], source);
      }
    shadow += local.shadow_rays;
    shaded += local.pixels_shaded;
  });
  counts.shadow_rays += shadow;
  counts.pixels_shaded += shaded;
}

}  // namespace sb
