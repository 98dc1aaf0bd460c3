// Ray-traced shading of an eye's pixels: a whole image in 4x4 packets, or any list of pixels
// (the hole fillers), each traced from the eye through its pixel centre and shaded by shade().
#pragma once

#include <cstdint>
#include <span>

#include "renderer/image.hpp"
#include "renderer/parallel.hpp"
#include "renderer/render_scene.hpp"
#include "renderer/rig.hpp"
#include "renderer/stages/primary_rays.hpp"
#include "renderer/stats.hpp"

namespace sb {

/// Rays cast by a tracing stage.
struct TraceCounts {
  uint64_t primary_rays = 0;
  uint64_t shadow_rays = 0;
  uint64_t pixels_shaded = 0;
  uint64_t pixels_traced = 0;  ///< pixels written from a primary ray (surface or background)
};

/// Traces and shades every pixel of `image` (made by make_eye_image) from `eye`; source = traced.
/// Every sample of every plane is written.
void trace_eye(const RenderScene& scene, const EyeCamera& eye, const Executor& executor, Image& image,
               TraceCounts& counts);

/// A new eye image of `eye`'s size traced whole by trace_eye; made without a fill, since
/// trace_eye writes every sample.
[[nodiscard]] Image traced_eye(const RenderScene& scene, const EyeCamera& eye, const Executor& executor,
                               TraceCounts& counts);

/// Traces and shades the listed pixels (indices y * width + x) only; the others are left as they
/// are. The rays go in trace_eye's 4x4 blocks, each cast as one packet with only its listed lanes
/// active: a lane's closest hit does not depend on the lanes beside it, so every hit is
/// bit-identical to trace_eye's (the hole fillers' tests against plain-rt check this). Only the
/// listed pixels are shaded and written. InputError for an index outside the image.
void trace_pixels(const RenderScene& scene, const EyeCamera& eye, const Executor& executor,
                  std::span<const uint32_t> pixels, Image& image, TraceCounts& counts, Source source = Source::traced);

/// trace_pixels for the pixels whose entry in `states` (one byte per pixel, row-major, the image's
/// size) differs from `done`: the same packets and bits, the blocks gathered in parallel without a
/// pixel list. std::logic_error when `states` does not match the image.
void trace_unless(const RenderScene& scene, const EyeCamera& eye, const Executor& executor,
                  std::span<const uint8_t> states, uint8_t done, Image& image, TraceCounts& counts,
                  Source source = Source::traced);

/// trace_eye's work for one rectangle of pixels (4-aligned, as trace_eye's tiles are), in the
/// calling thread: the same packets and shading batches, so the same bits. `rays` are the eye's
/// primary rays, built once per eye and frame.
void trace_rect(const RenderScene& scene, const EyeCamera& eye, const PrimaryRays& rays, const PixelRect& rect,
                Image& image, TraceCounts& counts);

/// trace_pixels in the calling thread (for pipelines that are sequential by design, or that run
/// their own parallel loop around it).
void trace_pixels_here(const RenderScene& scene, const EyeCamera& eye, const PrimaryRays& rays,
                       std::span<const uint32_t> pixels, Image& image, TraceCounts& counts,
                       Source source = Source::traced);

/// Adds trace counts to a pipeline's counters: primary_rays and shadow_rays (totals) and
/// pixels_shaded_<eye>; with `traced` also pixels_traced_<eye> (pixels written from a primary ray).
void add_counts(Counters& counters, const TraceCounts& counts, const char* eye, bool traced);

}  // namespace sb
