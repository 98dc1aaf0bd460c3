// bidir-warp: Kim's single-pass stereo by bidirectional warping — each triangle rendered by the eye
// that sees it best, each partial image warped row-wise into the other eye and composed there by
// depth, cracks filled along the rows; what neither partial image covers shows the background.
#include "renderer/pipeline.hpp"
#include "renderer/stages/bidirectional.hpp"

namespace sb {
namespace {

class BidirWarp final : public Pipeline {
 public:
  const PipelineInfo& info() const override {
    // Against plain-rt on the analytic scenes: both eyes are composed from partial images moved to the nearest pixel centre (no
    // resampling), and holes neither partial image covers show the background. Lowest measured at
    // 320x180: left 38.04 dB (box-wall; 35.81 dB before the back faces of its closed box were
    // culled), right 29.21 dB (slanted-plane: the right eye's column 0, where no left pixel lands,
    // is a hole at the image border, which the crack fill leaves: the whole column shows the
    // background, 180 pixels). Hence 37.5 and 29 dB.
    static const PipelineInfo i{"bidir-warp", "Kim", "§3 (visibility redirection, 1-D warping, composition)",
                                "each triangle rendered by the eye that sees it best; the two partial images warped "
                                "row-wise into each other, composed by depth, cracks filled",
                                bidir_option_specs(), 37.5, 29.0,
                                [](const PipelineOptions& o) { (void)BidirSettings::from("bidir-warp", o); }};
    return i;
  }

  StereoResult render(const RenderScene& scene, const StereoRig& rig, const PipelineOptions& options,
                      const RenderContext& ctx) const override {
    StereoResult r;
    render_bidirectional(scene, rig, BidirSettings::from("bidir-warp", options), ctx.executor, r);
    {
      ScopedStage stage(r.timings, "background", StageEye::both);
      r.counters.set("holes_shown_as_background", show_background_in_holes(scene, r.right));
      (void)show_background_in_holes(scene, r.left);
    }
    return r;
  }
};

SB_REGISTER_PIPELINE(BidirWarp);

}  // namespace
}  // namespace sb
