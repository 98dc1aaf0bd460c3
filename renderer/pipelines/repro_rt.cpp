// repro-rt: the left eye rasterized, warped into the right with the adaptive grid, disocclusions
// detected, and only the hole pixels ray traced from the right eye with the shared shading
// (Wißmann et al. 2020, "Repro RT").
#include "renderer/pipeline.hpp"
#include "renderer/stages/reprojection.hpp"
#include "renderer/stages/trace.hpp"

namespace sb {
namespace {

class ReproRt final : public Pipeline {
 public:
  const PipelineInfo& info() const override {
    // Left eye as plain-raster (50 dB, see there). Right eye: 40 dB, the aim; lowest
    // measured 45.11 dB on the analytic scenes (textured-plane, 320x180).
    static const PipelineInfo i{"repro-rt", "Wißmann et al. 2020", "3.1-3.4 (Repro RT)",
                                "left eye rasterized, adaptive grid warp, disocclusion detection, holes ray traced",
                                grid_warp_option_specs(true), 50.0, 40.0,
                                [](const PipelineOptions& o) {
                                  (void)ReprojectionSettings::from("repro-rt", o, true);
                                }};
    return i;
  }

  StereoResult render(const RenderScene& scene, const StereoRig& rig, const PipelineOptions& options,
                      const RenderContext& ctx) const override {
    StereoResult r;
    const std::vector<uint8_t> states =
        warp_left_to_right(scene, rig, ReprojectionSettings::from("repro-rt", options, true), ctx.executor, r);
    TraceCounts counts;
    {
      ScopedStage stage(r.timings, "hole_fill", StageEye::right);
      trace_unless(scene, rig.eye(Eye::right), ctx.executor, states, static_cast<uint8_t>(WarpPixel::covered), r.right,
                   counts, Source::reshaded_traced);
    }
    add_counts(r.counters, counts, "right", true);
    return r;
  }
};

SB_REGISTER_PIPELINE(ReproRt);

}  // namespace
}  // namespace sb
