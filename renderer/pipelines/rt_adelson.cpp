// rt-adelson: Adelson and Hodges' sequential stereo ray tracer as Al-Hagri's Algorithm 1 gives it:
// the left eye traced scan-line by scan-line, each hit reprojected left to right into the right
// eye, gaps of more than a pixel marked NoHit, NoHit pixels traced. One thread by design: the
// reference the parallel variants are checked against.
#include "renderer/pipeline.hpp"
#include "renderer/stages/eye_image.hpp"
#include "renderer/stages/scanline_reprojection.hpp"

namespace sb {
namespace {

class RtAdelson final : public Pipeline {
 public:
  const PipelineInfo& info() const override {
    // Right eye against plain-rt on the analytic scenes: reprojected pixels carry the colour of a
    // left pixel centre up to half a pixel away; the checker of textured-plane at grazing angles
    // turns that into 36.63 dB (measured at 320x180), the lowest of them. Hence 36 dB.
    static const PipelineInfo i{"rt-adelson", "Al-Hagri 2012 (after Adelson and Hodges 1993)", "2.2.2, Algorithm 1",
                                "sequential scan-line reprojection of a traced left eye; NoHit (missed and bad) pixels "
                                "traced; one thread",
                                {}, 200.0, 36.0};
    return i;
  }

  StereoResult render(const RenderScene& scene, const StereoRig& rig, const PipelineOptions&,
                      const RenderContext&) const override {
    StereoResult r;
    const int w = rig.params().width, h = rig.params().height;
    const PixelReprojector reprojector(rig);
    ScanlineCounts counts;
    {
      ScopedStage stage(r.timings, "allocate", StageEye::both);
      // scanline_band writes every sample of both eyes.
      r.left = make_eye_image(w, h, PlaneInit::unset);
      r.right = make_eye_image(w, h, PlaneInit::unset);
    }
    // Scan-lines in order, in this thread; the bands are the ray packets' height.
    for (int y0 = 0; y0 < h; y0 += kScanlineBand) scanline_band(scene, reprojector, y0, std::min(y0 + kScanlineBand, h), r.left, r.right, counts);
    r.timings.add("left_trace", counts.left_seconds, StageEye::left);
    r.timings.add("reproject", counts.reproject_seconds, StageEye::right);
    r.timings.add("right_trace", counts.right_seconds, StageEye::right);
    add_scanline_counters(r, counts, rig);
    return r;
  }
};

SB_REGISTER_PIPELINE(RtAdelson);

}  // namespace
}  // namespace sb
