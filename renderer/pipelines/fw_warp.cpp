// fw-warp: Kim's FW baseline after Cichocki (2017): the left eye rasterized and shaded, the whole
// left image splatted into the right eye by per-pixel forward warping — an atomic minimum of a
// packed (depth, source column) key per right pixel, then a colour pass in which the winners write
// — and one-pixel cracks filled by linear interpolation along the row.
#include <atomic>
#include <bit>
#include <cstdint>
#include <limits>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/pipeline.hpp"
#include "renderer/stages/crack_fill.hpp"
#include "renderer/stages/eye_image.hpp"
#include "renderer/stages/raster_eye.hpp"
#include "renderer/stages/row_warp.hpp"

namespace sb {
namespace {

/// Tile side of the per-pixel passes.
constexpr int kWarpTile = 64;

/// No source reached the right pixel.
constexpr uint64_t kEmptyKey = std::numeric_limits<uint64_t>::max();

/// The key a source pixel competes with for a right pixel: the depth's bits in the high word
/// (positive floats and +inf order as their bit patterns), the complement of the source column in
/// the low word, so that the minimum is the nearest surface and, on an exact tie, the larger source
/// x — the rule of the row warp, whatever order the writes come in.
uint64_t pack_key(float depth, int x) {
  return (uint64_t{std::bit_cast<uint32_t>(depth)} << 32) | uint64_t{~static_cast<uint32_t>(x)};
}
int key_column(uint64_t key) { return static_cast<int>(~static_cast<uint32_t>(key & 0xFFFFFFFFu)); }

struct FwSettings {
  RasterOptions raster;
  int max_crack = kDefaultCrackWidth;
  bool rows = false;  ///< the row warp instead of the atomic per-pixel passes
  RowWarpOptions row;

  static FwSettings from(const PipelineOptions& options) {
    FwSettings s;
    s.raster = raster_options("fw-warp", options);
    s.max_crack = max_crack_option("fw-warp", options);
    const std::string& warp = options.get("warp");
    if (warp != "atomic" && warp != "rows")
      throw InputError(fmt::format("fw-warp: option warp={} is not one of atomic, rows", warp));
    s.rows = warp == "rows";
    s.row.segment = options.get_int("segment");
    if (s.row.segment < 1)
      throw InputError(fmt::format("fw-warp: option segment={} must be at least 1 pixel", s.row.segment));
    s.row.warp_background = options.get_bool("background");
    return s;
  }
};

/// What the per-pixel forward warp did.
struct SplatCounts {
  uint64_t landed = 0;   ///< source pixels that moved inside the right image
  uint64_t written = 0;  ///< right pixels that received one
};

/// Pass 1 (stage warp_depth): every left pixel that takes part atomically lowers the key of the
/// right pixel it lands on. Tiles of source pixels run in parallel and collide freely.
std::vector<uint64_t> splat_depth(const Image& left, const StereoRig& rig, bool background, const Executor& executor,
                                  uint64_t& landed) {
  const int w = left.width(), h = left.height();
  std::vector<uint64_t> keys(left.pixel_count(), kEmptyKey);
  const float* depth = left.data_f32(planes::depth);
  const uint32_t* tag = left.data_u32(planes::source);
  const DisparityMotion motion(rig, Eye::left);
  std::atomic<uint64_t> total{0};
  executor.for_tiles(w, h, kWarpTile, [&](const PixelRect& tile) {
    uint64_t count = 0;
    for (int y = tile.y0; y < tile.y1; ++y)
      for (int x = tile.x0; x < tile.x1; ++x) {
        const size_t i = static_cast<size_t>(y) * w + x;
        const float z = depth[i];
        if (!takes_part(tag[i], z, background)) continue;
        const int t = target_column(x, motion(z));
        if (t < 0 || t >= w) continue;
        ++count;
        const uint64_t key = pack_key(z, x);
        std::atomic_ref<uint64_t> slot(keys[static_cast<size_t>(y) * w + t]);
        uint64_t seen = slot.load(std::memory_order_relaxed);
        while (key < seen && !slot.compare_exchange_weak(seen, key, std::memory_order_relaxed)) {
        }
      }
    total += count;
  });
  landed = total;
  return keys;
}

/// Pass 2 (stage warp_color): every right pixel takes the values of the source its key names, or
/// becomes a hole.
uint64_t splat_color(const Image& left, const std::vector<uint64_t>& keys, const Executor& executor, Image& right) {
  const int w = left.width(), h = left.height();
  const EyeReader from(left);
  EyeWriter out(right);
  std::atomic<uint64_t> total{0};
  executor.for_tiles(w, h, kWarpTile, [&](const PixelRect& tile) {
    uint64_t count = 0;
    for (int y = tile.y0; y < tile.y1; ++y)
      for (int x = tile.x0; x < tile.x1; ++x) {
        const size_t i = static_cast<size_t>(y) * w + x;
        if (keys[i] == kEmptyKey) {
          out.hole(i);
          continue;
        }
        out.copy(i, from, static_cast<size_t>(y) * w + key_column(keys[i]), Source::reprojected);
        ++count;
      }
    total += count;
  });
  return total;
}

class FwWarp final : public Pipeline {
 public:
  const PipelineInfo& info() const override {
    // Left eye as plain-raster (50 dB, see there; measured 76.24 dB on textured-plane). Right eye
    // against plain-rt on the analytic scenes at 320x180: disocclusions wider than a crack and the
    // strip at the left edge that the left eye does not see stay holes (black), and one-pixel
    // disocclusions are filled with a blend of both sides. Lowest measured 26.12 dB (slanted-plane:
    // a stretching crack that touches the left edge, and the 2-px gap behind the plane's far edge
    // filled grey). Hence 26 dB.
    static const PipelineInfo i{
        "fw-warp", "Kim (FW baseline); Cichocki 2017", "Kim §3.2, Table 1-3 (FW)",
        "left eye rasterized, forward splat into the right eye with an atomic min-depth pass then a colour pass, "
        "cracks filled by linear interpolation along the row",
        {tile_option_spec(),
         {"max_crack", "2", "widest run of hole pixels in a row that is filled by linear interpolation (0 = none)"},
         {"warp", "atomic",
          "atomic: the per-pixel two-pass warp with an atomic min of (depth, source x) (Cichocki); rows: the row-wise "
          "1-D warp of Kim §3.2 (same image)"},
         {"segment", "256", "with warp=rows: target-row segment length in pixels (the image does not depend on it)"},
         {"background", "true", "warp the pixels that see the background, with the disparity at infinity"}},
        50.0, 26.0, [](const PipelineOptions& o) { (void)FwSettings::from(o); }};
    return i;
  }

  StereoResult render(const RenderScene& scene, const StereoRig& rig, const PipelineOptions& options,
                      const RenderContext& ctx) const override {
    const FwSettings settings = FwSettings::from(options);
    StereoResult r;
    r.left = raster_eye(scene, rig, Eye::left, settings.raster, ctx.executor, r);
    const int w = rig.params().width, h = rig.params().height;
    SplatCounts counts;
    if (settings.rows) {
      MotionField motion;
      {
        ScopedStage stage(r.timings, "motion", StageEye::right);
        motion = disparity_motion_field(r.left, rig, Eye::left, settings.row, ctx.executor);
      }
      ScopedStage stage(r.timings, "row_warp", StageEye::right);
      r.right = make_hole_image(w, h, ctx.executor);
      const RowWarpStats s = row_warp(r.left, motion, settings.row, ctx.executor, r.right);
      counts.landed = s.landed;
      counts.written = s.written;
    } else {
      std::vector<uint64_t> keys;
      {
        ScopedStage stage(r.timings, "warp_depth", StageEye::right);
        keys = splat_depth(r.left, rig, settings.row.warp_background, ctx.executor, counts.landed);
      }
      ScopedStage stage(r.timings, "warp_color", StageEye::right);
      // splat_color writes every pixel (a copy or a hole), so the eye needs no fill.
      r.right = make_eye_image(w, h, PlaneInit::unset);
      counts.written = splat_color(r.left, keys, ctx.executor, r.right);
    }
    CrackFillStats cracks;
    {
      ScopedStage stage(r.timings, "crack_fill", StageEye::right);
      cracks = fill_cracks(r.right, settings.max_crack, ctx.executor);
    }
    r.counters.set("pixels_reprojected_right", counts.written);
    r.counters.set("overlapped", counts.landed - counts.written);
    r.counters.set("hole_pixels", cracks.hole_pixels);
    r.counters.set("pixels_inpainted", cracks.pixels_filled);
    add_crack_counters(r.counters, cracks);
    return r;
  }
};

SB_REGISTER_PIPELINE(FwWarp);

}  // namespace
}  // namespace sb
