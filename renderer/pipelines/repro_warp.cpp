// repro-warp: the left eye rasterized, warped into the right with the adaptive grid, and nothing
// done about disocclusions: the rubber sheets stay (Wißmann et al. 2020, Fig. 6a).
#include "renderer/pipeline.hpp"
#include "renderer/stages/reprojection.hpp"

namespace sb {
namespace {

class ReproWarp final : public Pipeline {
 public:
  const PipelineInfo& info() const override {
    // Right eye against plain-rt on the analytic scenes: the rubber sheets stay where surfaces are
    // disoccluded; lowest measured 26.73 dB (textured-plane, 320x180). Hence 26 dB.
    static const PipelineInfo i{"repro-warp", "Wißmann et al. 2020", "3.1-3.2, Fig. 6a (grid warp only)",
                                "left eye rasterized, adaptive grid warp to the right eye, no hole handling (rubber sheets)",
                                grid_warp_option_specs(false), 50.0, 26.0,
                                [](const PipelineOptions& o) {
                                  (void)ReprojectionSettings::from("repro-warp", o, false);
                                }};
    return i;
  }

  StereoResult render(const RenderScene& scene, const StereoRig& rig, const PipelineOptions& options,
                      const RenderContext& ctx) const override {
    StereoResult r;
    (void)warp_left_to_right(scene, rig, ReprojectionSettings::from("repro-warp", options, false), ctx.executor, r);
    return r;
  }
};

SB_REGISTER_PIPELINE(ReproWarp);

}  // namespace
}  // namespace sb
