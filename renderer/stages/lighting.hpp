// The deferred lighting pass: shades a rasterized G-buffer with the shared shading function.
#pragma once

#include <cstdint>

#include "renderer/image.hpp"
#include "renderer/parallel.hpp"
#include "renderer/raster/rasterizer.hpp"
#include "renderer/render_scene.hpp"
#include "renderer/rig.hpp"
#include "renderer/stages/trace.hpp"

namespace sb {

/// Shades every pixel of `gbuffer` seen from `eye` into `image` (made by make_eye_image; without a
/// mask every sample is written, so the image may be made with PlaneInit::unset);
/// source = rasterized. With `mask`, only pixels whose mask is non-zero are shaded and written
/// (source = `source`), the others are left untouched.
void shade_gbuffer(const RenderScene& scene, const EyeCamera& eye, const GBuffer& gbuffer, const Executor& executor,
                   Image& image, TraceCounts& counts, const uint8_t* mask = nullptr,
                   Source source = Source::rasterized);

}  // namespace sb
