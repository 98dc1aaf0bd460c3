// A rasterized eye: G-buffer and lighting pass, timed and counted.
#include "renderer/stages/raster_eye.hpp"

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/stages/eye_image.hpp"
#include "renderer/stages/lighting.hpp"

namespace sb {

GBuffer gbuffer_eye(const RenderScene& scene, const StereoRig& rig, Eye which, StageEye serves,
                    const RasterOptions& options, const Executor& executor, StereoResult& result) {
  const std::string name = eye_name(which);
  RasterStats rs;
  GBuffer g;
  {
    ScopedStage stage(result.timings, name + "_gbuffer", serves);
    g = rasterize(scene.geometry(), rig.eye(which), executor, options, &rs);
  }
  result.counters.add("triangles_rasterized_" + name, rs.triangles_rasterized);
  result.counters.add("fragments_" + name, rs.fragments_tested);
  return g;
}

Image raster_eye(const RenderScene& scene, const StereoRig& rig, Eye which, const RasterOptions& options,
                 const Executor& executor, StereoResult& result, GBuffer* gbuffer) {
  const std::string name = eye_name(which);
  const EyeCamera cam = rig.eye(which);
  GBuffer g = gbuffer_eye(scene, rig, which, stage_eye(which), options, executor, result);
  Image image;
  TraceCounts counts;
  {
    ScopedStage stage(result.timings, name + "_shading", stage_eye(which));
    image = make_eye_image(cam.width, cam.height, PlaneInit::unset);  // shade_gbuffer writes every pixel
    shade_gbuffer(scene, cam, g, executor, image, counts);
  }
  add_counts(result.counters, counts, name.c_str(), false);
  if (gbuffer != nullptr) *gbuffer = std::move(g);
  return image;
}

OptionSpec tile_option_spec() { return {"tile", "64", "rasterizer tile size in pixels (the image does not depend on it)"}; }

RasterOptions raster_options(const std::string& pipeline, const PipelineOptions& options) {
  RasterOptions ro;
  ro.tile = options.get_int("tile");
  if (ro.tile < 8 || ro.tile > 1024)
    throw InputError(fmt::format("{}: option tile={} is out of range 8..1024", pipeline, ro.tile));
  return ro;
}

}  // namespace sb
