// Output files of a render run.
#include "renderer/io/render_output.hpp"

#include <fmt/format.h>

#include "renderer/embree/ray_scene.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/gltf_loader.hpp"
#include "renderer/io/image_io.hpp"
#include "renderer/stereo_output.hpp"
#include "sb_version.hpp"

namespace sb::io {

using nlohmann::json;

json rig_to_json(const StereoRig& rig) {
  const RigParams& p = rig.params();
  return {{"width", p.width},           {"height", p.height},       {"vfov_deg", radians_to_degrees(p.vfov)},
          {"interaxial_m", p.interaxial}, {"convergence_m", p.convergence}, {"focal_px", rig.focal_px()},
          {"max_disparity_px", rig.max_disparity_px()}, {"znear", p.znear}, {"zfar", p.zfar}};
}

json versions_json() {
  return {{"stereobench", SB_VERSION_STRING},
          {"embree", RayScene::version()},
          {"openimageio", oiio_version()},
          {"gltf", gltf_loader_version()}};
}

json result_to_json(const std::string& pipeline, const RenderScene& scene, const StereoRig& rig,
                    const StereoResult& result, int threads, const PipelineOptions& options) {
  json timings = json::object();
  for (const auto& [stage, seconds] : result.timings.stages()) timings[stage] = seconds;
  json counters = json::object();
  for (const auto& [name, value] : result.counters.snapshot()) counters[name] = value;
  return {{"pipeline", pipeline},
          {"options", options.values()},
          {"scene", {{"name", scene.scene().name}, {"path", scene.scene().path}, {"triangles", scene.scene().triangle_count()}}},
          {"rig", rig_to_json(rig)},
          {"threads", threads},
          {"timings_s", timings},
          {"total_s", result.timings.total()},
          {"counters", counters},
          {"bvh", {{"build_s", scene.bvh_build_seconds()}, {"memory_bytes", scene.rays().memory_bytes()}}},
          {"versions", versions_json()}};
}

RenderFiles write_render_outputs(const std::filesystem::path& dir, const std::string& stem,
                                 const StereoResult& result, const json& record) {
  RenderFiles f;
  f.exr = dir / (stem + ".exr");
  f.left_png = dir / (stem + "_left.png");
  f.right_png = dir / (stem + "_right.png");
  f.anaglyph_png = dir / (stem + "_anaglyph.png");
  f.side_by_side_png = dir / (stem + "_sbs.png");
  f.stats_json = dir / (stem + "_stats.json");
  ImageMetadata meta;
  meta["stereobench/record"] = record.dump();
  write_exr_stereo(f.exr, result.left, result.right, meta);
  write_png_preview(f.left_png, result.left);
  write_png_preview(f.right_png, result.right);
  write_png_preview(f.anaglyph_png, anaglyph_dubois(result.left, result.right));
  write_png_preview(f.side_by_side_png, side_by_side(result.left, result.right));
  write_text_atomically(f.stats_json, record.dump(2) + "\n");
  return f;
}

}  // namespace sb::io
