// The software rasterizer: multi-threaded tile binning, near-plane clipping, top-left fill rule,
// perspective-correct barycentrics, depth test; writes a visibility G-buffer for one eye.
#pragma once

#include <cstdint>
#include <vector>

#include "renderer/math.hpp"
#include "renderer/parallel.hpp"
#include "renderer/rig.hpp"
#include "renderer/scene_geometry.hpp"

namespace sb {

/// Visibility at pixel centres (x + 0.5, y + 0.5) in the eye's pixel coordinates (EyeCamera).
struct GBuffer {
  int width = 0;
  int height = 0;
  std::vector<float> depth;     ///< linear view depth (distance along -Z); +inf where nothing is visible
  std::vector<uint32_t> prim;   ///< global triangle id (SceneGeometry), kNoPrimitiveId where empty
  std::vector<vec2> bary;       ///< perspective-correct (b1, b2): p = (1-b1-b2) v0 + b1 v1 + b2 v2
  std::vector<vec4> duv;        ///< (du/dx, dv/dx, du/dy, dv/dy) of the mesh UVs per pixel; 0 without UVs

  [[nodiscard]] size_t index(int x, int y) const { return static_cast<size_t>(y) * width + x; }
};

/// What the rasterizer did, for the pipeline counters.
struct RasterStats {
  uint64_t triangles_submitted = 0;
  uint64_t culled_backface = 0;       ///< back faces of single-sided meshes (front_facing())
  uint64_t culled_frustum = 0;        ///< wholly outside one image border, behind the near plane, or non-finite
  uint64_t clipped_near = 0;          ///< triangles that crossed the near plane and were clipped
  uint64_t triangles_rasterized = 0;  ///< triangles (after clipping) that reached the tiles
  uint64_t fragments_tested = 0;      ///< covered pixel centres that reached the depth test (write mask passed)
  uint64_t fragments_written = 0;     ///< fragments that passed the depth test when tested
  uint64_t triangles_skipped = 0;     ///< left out by the triangle mask
};

struct RasterOptions {
  int tile = 64;  ///< tile side in pixels, 4..1024; the image does not depend on it
  /// When set (width*height entries), only pixels whose mask is non-zero are written: the stencil
  /// of re-rasterized hole filling. Every triangle is still processed.
  const uint8_t* write_mask = nullptr;
  /// When set (one entry per global triangle id), only triangles whose entry has `triangle_bit`
  /// set are rasterized: an eye's share of the scene (Kim's visibility redirection).
  const uint8_t* triangle_mask = nullptr;
  uint8_t triangle_bit = 0;
};

/// Rasterizes every triangle of the scene from `eye`. Deterministic for any thread count: the
/// nearest depth wins, exact depth ties go to the lower triangle id.
[[nodiscard]] GBuffer rasterize(const SceneGeometry& geometry, const EyeCamera& eye, const Executor& executor,
                                const RasterOptions& options = {}, RasterStats* stats = nullptr);

}  // namespace sb
