// rt-buffer: Al-Hagri's buffer-based stereo ray tracer (thesis §3.1.2.1, Algorithms 2-3): every
// reprojected left pixel is stored with its source x in a w x h x t buffer at depth slot x mod t,
// the right pixel takes the entry with the largest source x, each reprojected right pixel is
// validated by a length-restricted ray, and missed or blocked pixels are traced.
#include <cmath>
#include <memory>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/memory.hpp"
#include "renderer/pipeline.hpp"
#include "renderer/stages/eye_image.hpp"
#include "renderer/stages/pixel_reprojection.hpp"

namespace sb {
namespace {

std::vector<OptionSpec> buffer_option_specs() {
  std::vector<OptionSpec> specs{
      {"depth", "0", "t, the buffer's depth per pixel; 0 = 2 x the max disparity in pixels (the thesis' 2e)"}};
  for (OptionSpec& o : validation_option_specs()) specs.push_back(std::move(o));
  return specs;
}

/// Largest reprojection buffer the pipeline allocates.
constexpr uint64_t kMaxBufferBytes = uint64_t{4} << 30;

class RtBuffer final : public Pipeline {
 public:
  const PipelineInfo& info() const override {
    // Right eye against plain-rt on the analytic scenes: reprojected pixels carry the colour of a
    // left pixel centre up to half a pixel away; the checker of textured-plane at grazing angles
    // turns that into 36.63 dB (measured at 320x180), the lowest of them. Hence 36 dB.
    static const PipelineInfo i{
        "rt-buffer", "Al-Hagri 2012", "3.1.2.1, 3.3.1 (Algorithms 2-3)",
        "per-pixel reprojection into a w x h x t buffer, rows in parallel (max source x wins), length-restricted "
        "validation rays, missed and blocked pixels traced",
        buffer_option_specs(), 200.0, 36.0,
        [](const PipelineOptions& o) {
          (void)ValidationSettings::from("rt-buffer", o);
          (void)depth_option(o);
        },
        [](const PipelineOptions& o, const StereoRig& rig) { (void)buffer_depth(depth_option(o), rig); }};
    return i;
  }

  StereoResult render(const RenderScene& scene, const StereoRig& rig, const PipelineOptions& options,
                      const RenderContext& ctx) const override {
    const ValidationSettings validation = ValidationSettings::from("rt-buffer", options);
    const int w = rig.params().width, h = rig.params().height;
    const int t = buffer_depth(depth_option(options), rig);
    // Before the left eye is traced, outside the stages' timings.
    require_memory(uint64_t{4} * static_cast<uint64_t>(t) * static_cast<uint64_t>(w) * static_cast<uint64_t>(h),
                   fmt::format("rt-buffer's {}x{}x{} reprojection buffer", w, h, t),
                   "set the option depth to a smaller t, or lower the resolution");
    StereoResult r;
    trace_left_eye(scene, rig, ctx.executor, r);
    const PixelReprojector reprojector(rig);
    const size_t slots = static_cast<size_t>(t);
    std::unique_ptr<int32_t[]> buffer;
    std::vector<uint64_t> collisions(static_cast<size_t>(h), 0);
    {
      ScopedStage stage(r.timings, "reproject", StageEye::right);
      // Uninitialised: each row task fills its own rows below (zeroing it first as well was a
      // serial pass over all w x h x t entries: dragon 600x600, t = 200, reproject 17.6 -> 11.4 ms).
      buffer = std::make_unique_for_overwrite<int32_t[]>(static_cast<size_t>(w) * h * slots);
      const float* depth = r.left.data_f32(planes::depth);
      // A row's reprojections stay in that row, so a task owns whole rows: no two tasks write one
      // entry, and within a row the writes go in source order.
      ctx.executor.for_range(static_cast<size_t>(h), 4, [&](size_t begin, size_t end) {
        for (size_t y = begin; y < end; ++y) {
          int32_t* row = buffer.get() + y * w * slots;
          std::fill(row, row + static_cast<size_t>(w) * slots, kNoSource);
          for (int x = 0; x < w; ++x) {
            const int32_t target = reprojector.target(x, static_cast<int>(y), depth[y * w + x]);
            if (target == kNoSource) continue;
            int32_t& entry = row[static_cast<size_t>(target) * slots + static_cast<size_t>(x) % slots];
            // A collision: a source t or more columns before reached the same pixel (t is below
            // Lemma 1's span). In source order the larger x replaces it, so the maximum survives;
            // the thesis's racing per-pixel writes could lose it.
            collisions[y] += entry != kNoSource ? 1 : 0;
            entry = x;
          }
        }
      });
    }
    RightSources sources{w, h, {}};
    {
      ScopedStage stage(r.timings, "right_resolve", StageEye::right);
      sources.column.resize(static_cast<size_t>(w) * h);
      ctx.executor.for_range(sources.column.size(), 4096, [&](size_t begin, size_t end) {
        for (size_t p = begin; p < end; ++p) {
          const int32_t* entries = buffer.get() + p * slots;
          sources.column[p] = *std::max_element(entries, entries + slots);
        }
      });
    }
    complete_right_eye(scene, rig, reprojector, sources, validation, ctx.executor, r);
    add_reprojection_counters(reprojector, rig, ctx.executor, r);
    uint64_t lost = 0;
    for (const uint64_t c : collisions) lost += c;
    r.counters.set("buffer_depth", static_cast<uint64_t>(t));
    r.counters.set("buffer_collisions", lost);
    return r;
  }

 private:
  static constexpr int kMaxDepth = 4096;

  /// The option depth, 0 (t = 2e, bounded by buffer_depth once the rig is known) or a fixed t.
  static int depth_option(const PipelineOptions& options) {
    const int option = options.get_int("depth");
    if (option < 0 || option > kMaxDepth)
      throw InputError(fmt::format("rt-buffer: option depth={} is out of range; use 0 (2 x max disparity) or 1..{}",
                                   option, kMaxDepth));
    return option;
  }

  static int buffer_depth(int option, const StereoRig& rig) {
    // The default t = 2e is computed in double and bounded before it becomes an int.
    const double automatic = std::max(1.0, std::ceil(2.0 * rig.max_disparity_px()));
    if (option == 0 && !(automatic <= kMaxDepth))
      throw InputError(fmt::format("rt-buffer: the default depth t = 2 x max disparity = {:g} exceeds {} entries per "
                                   "pixel; lower the interaxial (or raise the convergence distance), or set the "
                                   "option depth to a fixed t in 1..{}",
                                   automatic, kMaxDepth, kMaxDepth));
    const int t = option > 0 ? option : static_cast<int>(automatic);
    const uint64_t bytes = uint64_t{static_cast<uint64_t>(t)} * sizeof(int32_t) *
                           static_cast<uint64_t>(rig.params().width) * static_cast<uint64_t>(rig.params().height);
    if (bytes > kMaxBufferBytes)
      throw InputError(fmt::format("rt-buffer: a {}x{}x{} reprojection buffer needs {:.1f} GiB (limit 4 GiB); set "
                                   "the option depth to a smaller t or lower the resolution",
                                   rig.params().width, rig.params().height, t, bytes / double(uint64_t{1} << 30)));
    return t;
  }
};

SB_REGISTER_PIPELINE(RtBuffer);

}  // namespace
}  // namespace sb
