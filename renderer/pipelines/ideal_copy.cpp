// ideal-copy: the left eye traced, the right eye a copy of it (Al-Hagri's "imaginary ideal" stereo
// ray tracer): the speed limit of any reprojection scheme and a floor for its quality.
#include "renderer/pipeline.hpp"
#include "renderer/stages/trace.hpp"

namespace sb {
namespace {

class IdealCopy final : public Pipeline {
 public:
  const PipelineInfo& info() const override {
    // The right eye is the left one: its PSNR against the true right eye is whatever the
    // disparity makes it, so the conformance test checks only the left eye.
    static const PipelineInfo i{
        "ideal-copy", "Al-Hagri 2012", "4.1 (imaginary ideal ray tracer)",
        "trace the left eye and copy it to the right: the speed limit and a quality floor", {}, 200.0, 0.0};
    return i;
  }

  StereoResult render(const RenderScene& scene, const StereoRig& rig, const PipelineOptions&,
                      const RenderContext& ctx) const override {
    StereoResult r;
    TraceCounts counts;
    {
      ScopedStage stage(r.timings, "left_trace", StageEye::left);
      r.left = traced_eye(scene, rig.eye(Eye::left), ctx.executor, counts);
    }
    add_counts(r.counters, counts, "left", true);
    {
      ScopedStage stage(r.timings, "right_copy", StageEye::right);
      r.right = r.left;
      // Every right pixel is the left pixel at the same position: a zero-disparity reprojection.
      Plane& source = r.right.plane(planes::source);
      source.fill(static_cast<uint32_t>(Source::reprojected));
    }
    r.counters.set("pixels_reprojected_right", static_cast<uint64_t>(r.right.pixel_count()));
    r.counters.set("hole_pixels", 0);
    return r;
  }
};

SB_REGISTER_PIPELINE(IdealCopy);

}  // namespace
}  // namespace sb
