// The software rasterizer: parallel vertex stage, chunked setup and tile binning, then per-tile
// fixed-point rasterization with a deterministic depth test, resolved into the visibility G-buffer.
#include "renderer/raster/rasterizer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <utility>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/raster/raster_setup.hpp"
#include "renderer/scene.hpp"

namespace sb {
namespace {

using raster::RasterTriangle;

/// Triangles per setup chunk below which splitting further only adds binning overhead.
constexpr uint32_t kMinChunkTriangles = 16384;
/// How many binned triangles ahead a tile prefetches.
constexpr size_t kPrefetchDistance = 8;
/// Boxes up to this many pixels wide test every pixel centre; wider ones solve exact row spans.
constexpr int kPerPixelMaxWidth = 8;

/// The image's tiles, numbered row by row as Executor::for_tiles visits them.
struct TileGrid {
  int tile = 64;
  int tiles_x = 1;
  int tiles_y = 1;
  [[nodiscard]] size_t count() const { return static_cast<size_t>(tiles_x) * static_cast<size_t>(tiles_y); }
  [[nodiscard]] size_t index_of(const PixelRect& r) const {
    return static_cast<size_t>(r.y0 / tile) * static_cast<size_t>(tiles_x) + static_cast<size_t>(r.x0 / tile);
  }
};

/// A contiguous run of the triangle list: its set-up triangles (in id order) and per-tile bins in
/// compressed rows — tile t holds bin_items[bin_offsets[t] .. bin_offsets[t + 1]).
struct Chunk {
  std::vector<RasterTriangle> triangles;
  std::vector<size_t> bin_offsets;
  std::vector<uint32_t> bin_items;
  raster::SetupCounts counts;
};

/// Counting sort of a chunk's triangles into the tiles their pixel ranges overlap.
void bin_chunk(Chunk& chunk, const TileGrid& grid) {
  const int tile = grid.tile;
  std::vector<size_t>& offsets = chunk.bin_offsets;
  offsets.assign(grid.count() + 1, 0);
  for (const RasterTriangle& t : chunk.triangles)
    for (int ty = t.py0 / tile; ty <= t.py1 / tile; ++ty)
      for (int tx = t.px0 / tile; tx <= t.px1 / tile; ++tx) ++offsets[static_cast<size_t>(ty) * grid.tiles_x + tx + 1];
  for (size_t i = 1; i < offsets.size(); ++i) offsets[i] += offsets[i - 1];

  chunk.bin_items.resize(offsets.back());
  std::vector<size_t> cursor(offsets.begin(), offsets.end() - 1);
  for (size_t k = 0; k < chunk.triangles.size(); ++k) {
    const RasterTriangle& t = chunk.triangles[k];
    for (int ty = t.py0 / tile; ty <= t.py1 / tile; ++ty)
      for (int tx = t.px0 / tile; tx <= t.px1 / tile; ++tx)
        chunk.bin_items[cursor[static_cast<size_t>(ty) * grid.tiles_x + tx]++] = static_cast<uint32_t>(k);
  }
}

/// One tile's depth buffer and winning triangles. The tile owns its pixels: no locks, no atomics.
class TileRaster {
 public:
  TileRaster(const PixelRect& rect, int image_width, const uint8_t* write_mask, const raster::SetupInputs& inputs)
      : rect_(rect),
        tile_width_(rect.width()),
        image_width_(image_width),
        mask_(write_mask),
        inputs_(&inputs),
        depth_(static_cast<size_t>(rect.width()) * rect.height(), std::numeric_limits<float>::infinity()),
        winner_(depth_.size(), nullptr) {}

  /// Depth-tests the triangle at every pixel centre of the tile it covers.
  void draw(const RasterTriangle& t) {
    const int x_begin = std::max<int>(t.px0, rect_.x0), x_end = std::min<int>(t.px1, rect_.x1 - 1);
    const int y_begin = std::max<int>(t.py0, rect_.y0), y_end = std::min<int>(t.py1, rect_.y1 - 1);
    if (x_begin > x_end || y_begin > y_end) return;

    // Edge functions E_k(p) = (b - a) x (p - a) at the first pixel centre, biased by -1 on edges
    // that are neither top nor left so that "E >= 0" is the top-left fill rule.
    const int64_t cx = int64_t{x_begin} * raster::kSubpixelOne + raster::kSubpixelHalf;
    const int64_t cy = int64_t{y_begin} * raster::kSubpixelOne + raster::kSubpixelHalf;
    int64_t row[3], step_x[3], step_y[3];
    for (int k = 0; k < 3; ++k) {
      const int j = k == 2 ? 0 : k + 1;
      const int64_t dx = int64_t{t.x[j]} - t.x[k], dy = int64_t{t.y[j]} - t.y[k];
      const bool top_left = dy < 0 || (dy == 0 && dx > 0);
      row[k] = dx * (cy - t.y[k]) - dy * (cx - t.x[k]) - (top_left ? 0 : 1);
      step_x[k] = -dy * raster::kSubpixelOne;
      step_y[k] = dx * raster::kSubpixelOne;
    }

    // Scan the rows: narrow boxes test every pixel centre, wide ones (long slivers, large
    // triangles) first solve each row's exact covered span.
    const bool use_spans = x_end - x_begin + 1 > kPerPixelMaxWidth;
    for (int y = y_begin; y <= y_end; ++y, row[0] += step_y[0], row[1] += step_y[1], row[2] += step_y[2]) {
      const double q_row = t.inv_w.y * (y + 0.5) + t.inv_w.z;
      const size_t image_row = static_cast<size_t>(y) * image_width_;
      const size_t tile_row = static_cast<size_t>(y - rect_.y0) * tile_width_;
      if (use_spans) {
        int lo = 0, hi = x_end - x_begin;
        if (!covered_span(row, step_x, lo, hi)) continue;
        for (int x = x_begin + lo; x <= x_begin + hi; ++x) fragment(t, x, y, q_row, image_row, tile_row);
        continue;
      }
      int64_t e0 = row[0], e1 = row[1], e2 = row[2];
      for (int x = x_begin; x <= x_end; ++x, e0 += step_x[0], e1 += step_x[1], e2 += step_x[2])
        if ((e0 | e1 | e2) >= 0) fragment(t, x, y, q_row, image_row, tile_row);
    }
  }

  /// Writes the winners' depth, id, perspective-correct barycentrics and UV derivatives. The
  /// barycentric planes come from the original triangle's projected vertices, once per run of
  /// pixels with the same winner. The derivatives are the exact ones of the winner's plane at the
  /// pixel, not a GPU's finite differences over a 2x2 quad (DESIGN §3, Wißmann §3.4): the same
  /// quantity without the quad's error, and defined at a pixel whose quad neighbours show other
  /// triangles.
  void resolve(const raster::SetupInputs& in, GBuffer& g) const {
    const SceneGeometry& geometry = *in.geometry;
    const Scene& scene = *geometry.scene;
    uint32_t cached = kNoPrimitiveId;
    raster::TrianglePlanes planes;
    bool has_uvs = false;
    dvec2 uv_e1(0.0), uv_e2(0.0);
    for (int y = rect_.y0; y < rect_.y1; ++y)
      for (int x = rect_.x0; x < rect_.x1; ++x) {
        const size_t li = static_cast<size_t>(y - rect_.y0) * tile_width_ + static_cast<size_t>(x - rect_.x0);
        const RasterTriangle* t = winner_[li];
        if (t == nullptr) continue;
        if (t->prim != cached) {
          cached = t->prim;
          const Mesh& mesh = scene.meshes[t->mesh];
          const uint32_t* idx = &mesh.indices[3 * static_cast<size_t>(t->prim - geometry.first_triangle[t->mesh])];
          planes = planes_of(in, *t);
          has_uvs = !mesh.uvs.empty() && mesh.uvs.size() == mesh.positions.size();
          if (has_uvs) {
            const dvec2 uv0(mesh.uvs[idx[0]]);
            uv_e1 = dvec2(mesh.uvs[idx[1]]) - uv0;
            uv_e2 = dvec2(mesh.uvs[idx[2]]) - uv0;
          }
        }
        const size_t gi = g.index(x, y);
        const double xc = x + 0.5, yc = y + 0.5;
        const double q = t->inv_w.x * xc + (t->inv_w.y * yc + t->inv_w.z);
        const double inv_q = 1.0 / q;
        const auto [b1, b2] = barycentrics(planes, xc, yc, inv_q);
        g.depth[gi] = depth_[li];
        g.prim[gi] = t->prim;
        g.bary[gi] = vec2(static_cast<float>(b1), static_cast<float>(b2));
        if (!has_uvs) continue;

        // The planes' slopes give the exact derivatives: db/dx = (B_x - b Q_x) / Q with B = b/w, Q = 1/w.
        const double db1_dx = (planes.b1_w.x - b1 * t->inv_w.x) * inv_q;
        const double db1_dy = (planes.b1_w.y - b1 * t->inv_w.y) * inv_q;
        const double db2_dx = (planes.b2_w.x - b2 * t->inv_w.x) * inv_q;
        const double db2_dy = (planes.b2_w.y - b2 * t->inv_w.y) * inv_q;
        g.duv[gi] = vec4(static_cast<float>(uv_e1.x * db1_dx + uv_e2.x * db2_dx),
                         static_cast<float>(uv_e1.y * db1_dx + uv_e2.y * db2_dx),
                         static_cast<float>(uv_e1.x * db1_dy + uv_e2.x * db2_dy),
                         static_cast<float>(uv_e1.y * db1_dy + uv_e2.y * db2_dy));
      }
  }

  uint64_t tested = 0;
  uint64_t written = 0;

 private:
  /// Depth test of a covered pixel centre (x, y) of the tile; 1/w is evaluated from the absolute
  /// pixel centre so that the depth never depends on the tile size.
  void fragment(const RasterTriangle& t, int x, int y, double q_row, size_t image_row, size_t tile_row) {
    if (mask_ != nullptr && mask_[image_row + x] == 0) return;
    ++tested;
    const double q = t.inv_w.x * (x + 0.5) + q_row;
    if (!(q > 0.0)) return;
    const float d = static_cast<float>(1.0 / q);
    const size_t i = tile_row + static_cast<size_t>(x - rect_.x0);
    if (d < depth_[i] || (d == depth_[i] && winner_[i] != nullptr && t.prim < winner_[i]->prim)) {
      // A cut-out's transparent part writes nothing (the alpha test, after the depth test that
      // it would have passed: the same result, tested for fewer fragments).
      if (inputs_->geometry->has_cutout(t.mesh) && cut_away(t, x, y, q)) return;
      depth_[i] = d;
      winner_[i] = &t;
      ++written;
    }
  }

  /// Narrows [lo, hi] (pixel offsets from the row's first pixel) to the offsets n where every edge
  /// function e_k + s_k n is >= 0; false when none is. A double quotient gives each bound to within
  /// one pixel and exact integer tests settle it, so spans cover exactly the pixels the per-pixel
  /// test would.
  static bool covered_span(const int64_t e[3], const int64_t s[3], int& lo, int& hi) {
    for (int k = 0; k < 3; ++k) {
      const int64_t ek = e[k], sk = s[k];
      const auto inside = [ek, sk](int64_t n) { return ek + sk * n >= 0; };
      if (sk == 0) {
        if (ek < 0) return false;
      } else if (sk > 0) {
        if (ek >= 0) continue;             // inside from the first pixel on
        if (!inside(hi)) return false;     // still outside at the last one
        auto n = std::min<int64_t>(static_cast<int64_t>(-static_cast<double>(ek) / static_cast<double>(sk)), hi);
        while (n > 0 && inside(n - 1)) --n;
        while (!inside(n)) ++n;
        lo = std::max(lo, static_cast<int>(n));
      } else {
        if (ek < 0) return false;  // outside from the first pixel on
        if (inside(hi)) continue;  // inside up to the last one
        auto n = std::min<int64_t>(static_cast<int64_t>(static_cast<double>(ek) / static_cast<double>(-sk)), hi);
        while (inside(n + 1)) ++n;
        while (!inside(n)) --n;
        hi = std::min(hi, static_cast<int>(n));
      }
      if (lo > hi) return false;
    }
    return true;
  }

  /// The perspective-correct planes of the scene triangle that t is (a piece of). Set-up succeeded
  /// for it, so they exist.
  static raster::TrianglePlanes planes_of(const raster::SetupInputs& in, const RasterTriangle& t) {
    const SceneGeometry& geometry = *in.geometry;
    const uint32_t* idx =
        &geometry.scene->meshes[t.mesh].indices[3 * static_cast<size_t>(t.prim - geometry.first_triangle[t.mesh])];
    const raster::ProjectedVertex* v = in.vertices + in.vertex_base[t.mesh];
    raster::TrianglePlanes planes;
    (void)raster::triangle_planes(v[idx[0]], v[idx[1]], v[idx[2]], planes);
    return planes;
  }

  /// (b1, b2) at pixel centre (xc, yc), where 1/q is the depth: for the G-buffer and the alpha test.
  static std::pair<double, double> barycentrics(const raster::TrianglePlanes& p, double xc, double yc, double inv_q) {
    return {(p.b1_w.x * xc + p.b1_w.y * yc + p.b1_w.z) * inv_q, (p.b2_w.x * xc + p.b2_w.y * yc + p.b2_w.z) * inv_q};
  }

  /// Whether the cut-out triangle t is transparent at pixel centre (x, y), where 1/w is q: at the
  /// barycentrics resolve() stores for the G-buffer there.
  bool cut_away(const RasterTriangle& t, int x, int y, double q) {
    if (t.prim != cut_prim_) {
      cut_prim_ = t.prim;
      cut_planes_ = planes_of(*inputs_, t);
    }
    const auto [b1, b2] = barycentrics(cut_planes_, x + 0.5, y + 0.5, 1.0 / q);
    const SceneGeometry& geometry = *inputs_->geometry;
    return !geometry.opaque_at(t.mesh, t.prim - geometry.first_triangle[t.mesh],
                               vec2(static_cast<float>(b1), static_cast<float>(b2)));
  }

  PixelRect rect_;
  int tile_width_;
  int image_width_;
  const uint8_t* mask_;
  const raster::SetupInputs* inputs_;
  uint32_t cut_prim_ = kNoPrimitiveId;  ///< the triangle whose planes cut_planes_ holds
  raster::TrianglePlanes cut_planes_;
  std::vector<float> depth_;
  std::vector<const RasterTriangle*> winner_;
};

/// Fragment counts of one tile.
struct TileCounts {
  uint64_t tested = 0;
  uint64_t written = 0;
};

void validate(const SceneGeometry& geometry, const EyeCamera& eye, const RasterOptions& options) {
  if (geometry.scene == nullptr || geometry.single_sided.size() + 1 != geometry.first_triangle.size())
    throw InputError("rasterize: the scene geometry is not initialised; build it with SceneGeometry(scene)");
  if (eye.width < 1 || eye.width > kMaxImageSide || eye.height < 1 || eye.height > kMaxImageSide)
    throw InputError(fmt::format("rasterize: image size {}x{} is out of range; each side must be 1..{}", eye.width,
                                 eye.height, kMaxImageSide));
  if (!std::isfinite(eye.znear) || eye.znear <= 0.0)
    throw InputError(fmt::format("rasterize: znear {} must be positive and finite", eye.znear));
  if (!std::isfinite(eye.f_px) || eye.f_px <= 0.0)
    throw InputError(fmt::format("rasterize: focal length {} px must be positive and finite", eye.f_px));
  if (options.tile < 4 || options.tile > 1024)
    throw InputError(fmt::format("rasterize: tile size {} is out of range 4..1024 pixels", options.tile));
}

}  // namespace

GBuffer rasterize(const SceneGeometry& geometry, const EyeCamera& eye, const Executor& executor,
                  const RasterOptions& options, RasterStats* stats) {
  validate(geometry, eye, options);
  const Scene& scene = *geometry.scene;
  const int width = eye.width, height = eye.height;

  // Vertex stage: every vertex of every mesh to homogeneous pixel coordinates, once.
  std::vector<size_t> vertex_base(scene.meshes.size() + 1, 0);
  for (size_t m = 0; m < scene.meshes.size(); ++m)
    vertex_base[m + 1] = vertex_base[m] + scene.meshes[m].positions.size();
  const size_t vertex_count = vertex_base.back();
  const auto vertices = std::make_unique_for_overwrite<raster::ProjectedVertex[]>(vertex_count);
  const raster::VertexTransform transform(eye);
  const raster::SetupInputs inputs{&geometry,  &transform, vertices.get(), vertex_base.data(), eye.origin,
                                   options.triangle_mask, options.triangle_bit};
  executor.for_range(vertex_count, 8192,
                     [&](size_t begin, size_t end) { raster::project_vertices(inputs, begin, end, vertices.get()); });

  // Setup and binning: contiguous chunks of ids, each with its own bins; a tile later walks the
  // chunks in order, which concatenates its bins in triangle-id order.
  const int tile = options.tile;
  const TileGrid grid{tile, (width + tile - 1) / tile, (height + tile - 1) / tile};
  const uint32_t triangle_count = geometry.triangle_count();
  const size_t chunk_count = std::clamp<size_t>(triangle_count / kMinChunkTriangles, 1,
                                                4 * static_cast<size_t>(executor.threads()));
  std::vector<Chunk> chunks(chunk_count);
  // The G-buffer starts empty; its four arrays are filled by extra tasks beside the setup chunks
  // (the fill is memory-bound and would otherwise run alone).
  GBuffer g;
  g.width = width;
  g.height = height;
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  // The large buffers are reserved here, by the calling thread, and only filled by the tasks: a
  // block a worker thread allocates comes from its own malloc arena, which returns whole freed
  // heaps to the system, so every frame would fault its pages in afresh (about 8000 page faults
  // per eye at 1920x1080); the calling thread's heap keeps them (keep_freed_memory).
  g.depth.reserve(pixels);
  g.prim.reserve(pixels);
  g.bary.reserve(pixels);
  g.duv.reserve(pixels);
  // Chunk k holds triangle ids [first(k), first(k + 1)).
  const auto first = [&](size_t k) { return static_cast<uint32_t>(uint64_t{triangle_count} * k / chunk_count); };
  for (size_t k = 0; k < chunk_count; ++k) chunks[k].triangles.reserve(first(k + 1) - first(k));
  executor.for_each(chunk_count + 4, [&](size_t task) {
    if (task >= chunk_count) {
      switch (task - chunk_count) {
        case 0: g.depth.assign(pixels, std::numeric_limits<float>::infinity()); break;
        case 1: g.prim.assign(pixels, kNoPrimitiveId); break;
        case 2: g.bary.assign(pixels, vec2(0.0f)); break;
        default: g.duv.assign(pixels, vec4(0.0f)); break;
      }
      return;
    }
    Chunk& chunk = chunks[task];
    raster::setup_triangles(inputs, first(task), first(task + 1), chunk.triangles, chunk.counts);
    bin_chunk(chunk, grid);
  });

  // Tiles: each rasterizes its bins into a private depth buffer, then resolves its pixels.
  std::vector<TileCounts> tile_counts(grid.count());
  executor.for_tiles(width, height, tile, [&](const PixelRect& rect) {
    const size_t index = grid.index_of(rect);
    TileRaster raster(rect, width, options.write_mask, inputs);
    for (const Chunk& chunk : chunks) {
      const size_t begin = chunk.bin_offsets[index], end = chunk.bin_offsets[index + 1];
      for (size_t k = begin; k < end; ++k) {
        // Bins index scattered records: fetch a few ahead of use.
        if (k + kPrefetchDistance < end) __builtin_prefetch(&chunk.triangles[chunk.bin_items[k + kPrefetchDistance]]);
        raster.draw(chunk.triangles[chunk.bin_items[k]]);
      }
    }
    raster.resolve(inputs, g);
    tile_counts[index] = {raster.tested, raster.written};
  });

  // Counters: sums of per-chunk and per-tile counts, independent of scheduling.
  if (stats != nullptr) {
    *stats = RasterStats{};
    for (const Chunk& chunk : chunks) {
      stats->triangles_submitted += chunk.counts.submitted;
      stats->culled_backface += chunk.counts.culled_backface;
      stats->culled_frustum += chunk.counts.culled_frustum;
      stats->clipped_near += chunk.counts.clipped_near;
      stats->triangles_rasterized += chunk.counts.emitted;
      stats->triangles_skipped += chunk.counts.skipped;
    }
    for (const TileCounts& t : tile_counts) {
      stats->fragments_tested += t.tested;
      stats->fragments_written += t.written;
    }
  }
  return g;
}

}  // namespace sb
