// plain-raster: each eye rasterized into a G-buffer and shaded by the deferred lighting pass
// (Wißmann's "Plain Stereo", Kim's "2-Pass").
#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/pipeline.hpp"
#include "renderer/stages/raster_eye.hpp"

namespace sb {
namespace {

class PlainRaster final : public Pipeline {
 public:
  const PipelineInfo& info() const override {
    // Against plain-rt: visibility differs only on a few silhouette pixels, and the two texture-LOD
    // rules pick the same level; the lowest of the analytic scenes is textured-plane (a checker at
    // grazing angles) at 76.24 / 76.93 dB (left / right, 320x180, measured). The default 50 dB holds.
    static const PipelineInfo i{
        "plain-raster", "Wißmann et al. 2020; Kim", "Plain Stereo; 2-Pass",
        "rasterize a G-buffer and run the lighting pass for each eye",
        {tile_option_spec()}, 50.0, 50.0,
        [](const PipelineOptions& o) { (void)raster_options("plain-raster", o); }};
    return i;
  }

  StereoResult render(const RenderScene& scene, const StereoRig& rig, const PipelineOptions& options,
                      const RenderContext& ctx) const override {
    StereoResult r;
    const RasterOptions ro = raster_options("plain-raster", options);
    r.left = raster_eye(scene, rig, Eye::left, ro, ctx.executor, r);
    r.right = raster_eye(scene, rig, Eye::right, ro, ctx.executor, r);
    r.counters.set("hole_pixels", 0);
    return r;
  }
};

SB_REGISTER_PIPELINE(PlainRaster);

}  // namespace
}  // namespace sb
