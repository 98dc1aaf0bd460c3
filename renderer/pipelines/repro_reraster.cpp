// repro-reraster: as repro-rt, but the holes are filled by rasterizing the whole scene again from
// the right eye under a stencil of the hole pixels and shading only those (Wißmann et al. 2020,
// §3.5, "Repro ReRaster").
#include "renderer/pipeline.hpp"
#include "renderer/stages/lighting.hpp"
#include "renderer/stages/reprojection.hpp"

namespace sb {
namespace {

class ReproReraster final : public Pipeline {
 public:
  const PipelineInfo& info() const override {
    // Left eye as plain-raster (50 dB, see there). Right eye: 40 dB, the aim; lowest
    // measured 45.11 dB on the analytic scenes (textured-plane, 320x180).
    static const PipelineInfo i{"repro-reraster", "Wißmann et al. 2020", "3.5 (Repro ReRaster)",
                                "as repro-rt, but holes re-rasterized under a stencil mask: all geometry processed, only "
                                "masked pixels shaded",
                                grid_warp_option_specs(true), 50.0, 40.0,
                                [](const PipelineOptions& o) {
                                  (void)ReprojectionSettings::from("repro-reraster", o, true);
                                }};
    return i;
  }

  StereoResult render(const RenderScene& scene, const StereoRig& rig, const PipelineOptions& options,
                      const RenderContext& ctx) const override {
    StereoResult r;
    const ReprojectionSettings settings = ReprojectionSettings::from("repro-reraster", options, true);
    std::vector<uint8_t> states = warp_left_to_right(scene, rig, settings, ctx.executor, r);
    TraceCounts counts;
    RasterStats rs;
    {
      ScopedStage stage(r.timings, "hole_fill", StageEye::right);
      // The stencil: the warp marked covered pixels; the re-raster pass writes the others only.
      for (uint8_t& s : states) s = s == static_cast<uint8_t>(WarpPixel::covered) ? 0 : 1;
      RasterOptions ro = settings.raster;
      ro.write_mask = states.data();
      const EyeCamera right = rig.eye(Eye::right);
      const GBuffer g = rasterize(scene.geometry(), right, ctx.executor, ro, &rs);
      shade_gbuffer(scene, right, g, ctx.executor, r.right, counts, states.data(), Source::reshaded_raster);
    }
    add_counts(r.counters, counts, "right", false);
    r.counters.add("triangles_rasterized_right", rs.triangles_rasterized);
    r.counters.add("fragments_right", rs.fragments_tested);
    return r;
  }
};

SB_REGISTER_PIPELINE(ReproReraster);

}  // namespace
}  // namespace sb
