// Test helpers for rendering: built-in scenes from a shared cache under the build tree, a pipeline
// run at a chosen resolution and thread count, and PSNR on sRGB-encoded 8-bit values.
#pragma once

#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <string>

#include "renderer/color.hpp"
#include "renderer/io/gltf_loader.hpp"
#include "renderer/pipeline.hpp"
#include "scenes/catalog.hpp"

namespace sb::test {

/// A built-in scene, generated once into the build tree and shared by the tests.
inline Scene load_builtin(const std::string& name) {
  const std::filesystem::path cache = std::filesystem::path(SB_BINARY_DIR) / "Testing" / "scenes-cache";
  return io::load_gltf(scenes::resolve_scene(name, cache));
}

/// The scene's default rig at another resolution, and at another convergence distance when given.
inline StereoRig rig_at(const Scene& scene, int width, int height, std::optional<double> convergence = std::nullopt) {
  RigOverrides o;
  o.width = width;
  o.height = height;
  o.convergence = convergence;
  return resolve_rig(scene, o);
}

/// The scene's rig at width x height with the interaxial given as the disparity at infinity (px).
inline StereoRig rig_with_disparity(const Scene& scene, int width, int height, double max_disparity_px) {
  RigOverrides o;
  o.width = width;
  o.height = height;
  o.max_disparity_px = max_disparity_px;
  return resolve_rig(scene, o);
}

inline StereoResult render_with(const std::string& pipeline, const RenderScene& scene, const StereoRig& rig,
                                int threads = 0, const std::map<std::string, std::string>& options = {}) {
  const Pipeline& p = find_pipeline(pipeline);
  const Executor executor(threads);
  return p.render(scene, rig, PipelineOptions(p.info(), options), RenderContext{executor});
}

/// A render's stages with the eye each serves, "stage=eye ..." in the order they started, on
/// box-wall at 200x120.
inline std::string stage_eyes_of(const std::string& pipeline, const std::map<std::string, std::string>& options = {}) {
  const Scene scene = load_builtin("box-wall");
  const RenderScene rs(scene);
  const StereoResult r = render_with(pipeline, rs, rig_at(scene, 200, 120), 0, options);
  std::string out;
  for (const StageTime& s : r.timings.stages()) out += (out.empty() ? "" : " ") + s.name + "=" + stage_eye_name(s.eye);
  return out;
}

}  // namespace sb::test
