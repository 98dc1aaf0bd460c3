// Surfaces in front of an eye's near plane. The rasterizer cannot project them and clips them at
// znear, as every rasterizer does; rays and the ground truths (Blender's clip start is 1e-6 m,
// POV-Ray has none) see them. Where a scene's camera has its near plane beyond nearby geometry the
// rasterizing pipelines therefore differ from the ray-traced ones and from the truth for that
// reason alone, and the user should be told.
#pragma once

#include <cstdint>

#include "renderer/parallel.hpp"
#include "renderer/render_scene.hpp"
#include "renderer/rig.hpp"

namespace sb {

/// Pixels of `eye` whose primary ray hits a surface at a linear depth below the eye's znear.
[[nodiscard]] uint64_t pixels_before_near_plane(const RenderScene& scene, const EyeCamera& eye,
                                                const Executor& executor);

}  // namespace sb
