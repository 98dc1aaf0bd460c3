// Primary rays through pixel centres, in packets of up to 16, shaded by the shared shading function.
#include "renderer/stages/trace.hpp"

#include <atomic>
#include <cmath>

#include "renderer/shading.hpp"
#include "renderer/stages/eye_image.hpp"
#include "renderer/texture.hpp"

namespace sb {

namespace {

/// Traces one packet of up to 16 pixels and writes them.
class PacketTracer {
 public:
  PacketTracer(const RenderScene& scene, const EyeCamera& eye, Image& image)
      : scene_(scene), eye_(eye), writer_(image), width_(image.width()),
        tan_spread_(static_cast<float>(std::tan(ray_cone_spread(2.0 * std::atan(0.5 * eye.height / eye.f_px), eye.height)))),
        origin_(eye.origin), forward_(-eye.back) {}

  void trace(const uint32_t* pixels, int n, Source source, TraceCounts& counts) {
    RayQuery rays[kRayPacket];
    RayHit hits[kRayPacket];
    for (int i = 0; i < n; ++i) {
      const int x = static_cast<int>(pixels[i] % static_cast<uint32_t>(width_));
      const int y = static_cast<int>(pixels[i] / static_cast<uint32_t>(width_));
      rays[i].origin = vec3(origin_);
      rays[i].dir = vec3(eye_.ray_direction(x + 0.5, y + 0.5));
    }
    scene_.rays().intersect(std::span<const RayQuery>(rays, static_cast<size_t>(n)),
                            std::span<RayHit>(hits, static_cast<size_t>(n)));
    counts.primary_rays += static_cast<uint64_t>(n);
    SurfacePoint points[kRayPacket];
    vec3 albedo[kRayPacket];
    vec3 radiance[kRayPacket];
    float depth[kRayPacket];
    uint32_t where[kRayPacket];
    int m = 0;
    for (int i = 0; i < n; ++i) {
      if (hits[i].prim == kNoPrimitiveId) {
        writer_.background(pixels[i], scene_.scene().background, source);
        continue;
      }
      SurfacePoint& p = points[m];
      p = surface_at(scene_, hits[i].prim, hits[i].bary, vec3(origin_));
      const float cos_axis = glm::dot(rays[i].dir, vec3(forward_));
      const float width = primary_cone_width(hits[i].t, tan_spread_, cos_axis);
      albedo[m] = albedo_at(scene_, p, ray_cone_lod(scene_, p, width, rays[i].dir));
      depth[m] = hits[i].t * cos_axis;
      where[m] = pixels[i];
      ++m;
    }
    ShadeCounts sc;
    shade(scene_, std::span<const SurfacePoint>(points, static_cast<size_t>(m)),
          std::span<const vec3>(albedo, static_cast<size_t>(m)), std::span<vec3>(radiance, static_cast<size_t>(m)), sc);
    counts.shadow_rays += sc.shadow_rays;
    counts.pixels_shaded += sc.pixels_shaded;
    for (int k = 0; k < m; ++k) writer_.surface(where[k], points[k], radiance[k], albedo[k], depth[k], source);
  }

 private:
  const RenderScene& scene_;
  const EyeCamera& eye_;
  EyeWriter writer_;
  int width_;
  float tan_spread_;
  dvec3 origin_;
  dvec3 forward_;
};

/// Adds a task's counts into shared totals.
void accumulate(std::atomic<uint64_t>* totals, const TraceCounts& c) {
  totals[0] += c.primary_rays;
  totals[1] += c.shadow_rays;
  totals[2] += c.pixels_shaded;
}

}  // namespace

void trace_eye(const RenderScene& scene, const EyeCamera& eye, const Executor& executor, Image& image,
               TraceCounts& counts) {
  std::atomic<uint64_t> totals[3] = {0, 0, 0};
  const int w = image.width(), h = image.height();
  executor.for_tiles(w, h, 32, [&](const PixelRect& tile) {
    PacketTracer tracer(scene, eye, image);
    TraceCounts local;
    uint32_t block[kRayPacket];
    // 4x4 blocks keep the packets coherent.
    for (int by = tile.y0; by < tile.y1; by += 4)
      for (int bx = tile.x0; bx < tile.x1; bx += 4) {
        int n = 0;
        for (int y = by; y < std::min(by + 4, tile.y1); ++y)
          for (int x = bx; x < std::min(bx + 4, tile.x1); ++x) block[n++] = static_cast<uint32_t>(y * w + x);
        tracer.trace(block, n, Source::traced, local);
      }
    accumulate(totals, local);
  });
  counts.primary_rays += totals[0];
  counts.shadow_rays += totals[1];
  counts.pixels_shaded += totals[2];
}

void trace_pixels(const RenderScene& scene, const EyeCamera& eye, const Executor& executor,
                  std::span<const uint32_t> pixels, Image& image, TraceCounts& counts, Source source) {
  std::atomic<uint64_t> totals[3] = {0, 0, 0};
  const size_t packets = (pixels.size() + kRayPacket - 1) / kRayPacket;
  executor.for_range(packets, 64, [&](size_t begin, size_t end) {
    PacketTracer tracer(scene, eye, image);
    TraceCounts local;
    for (size_t k = begin; k < end; ++k) {
      const size_t first = k * kRayPacket;
      const int n = static_cast<int>(std::min<size_t>(kRayPacket, pixels.size() - first));
      tracer.trace(pixels.data() + first, n, source, local);
    }
    accumulate(totals, local);
  });
  counts.primary_rays += totals[0];
  counts.shadow_rays += totals[1];
  counts.pixels_shaded += totals[2];
}

void add_counts(Counters& counters, const TraceCounts& counts, const char* eye, bool traced) {
  counters.add("primary_rays", counts.primary_rays);
  counters.add("shadow_rays", counts.shadow_rays);
  counters.add(std::string("pixels_shaded_") + eye, counts.pixels_shaded);
  if (traced) counters.add(std::string("pixels_traced_") + eye, counts.primary_rays);
}

}  // namespace sb
