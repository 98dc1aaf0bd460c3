// rt-es-isler: Es and Isler's parallelisation of the scan-line stereo ray tracer: Algorithm 1 per
// scan-line, scan-lines processed in parallel (here in bands of the ray packets' height).
#include <chrono>

#include "renderer/pipeline.hpp"
#include "renderer/stages/eye_image.hpp"
#include "renderer/stages/scanline_reprojection.hpp"

namespace sb {
namespace {

class RtEsIsler final : public Pipeline {
 public:
  const PipelineInfo& info() const override {
    // Right eye against plain-rt on the analytic scenes: reprojected pixels carry the colour of a
    // left pixel centre up to half a pixel away; the checker of textured-plane at grazing angles
    // turns that into 36.63 dB (measured at 320x180), the lowest of them. Hence 36 dB.
    static const PipelineInfo i{"rt-es-isler", "Al-Hagri 2012 (after Es and Isler 2007)", "2.2.2, 4.1",
                                "scan-line reprojection of a traced left eye with scan-lines in parallel; NoHit "
                                "pixels traced",
                                {}, 200.0, 36.0};
    return i;
  }

  StereoResult render(const RenderScene& scene, const StereoRig& rig, const PipelineOptions&,
                      const RenderContext& ctx) const override {
    StereoResult r;
    const int w = rig.params().width, h = rig.params().height;
    const PixelReprojector reprojector(rig);
    const size_t bands = static_cast<size_t>((h + kScanlineBand - 1) / kScanlineBand);
    std::vector<ScanlineCounts> per_band(bands);
    {
      ScopedStage stage(r.timings, "allocate", StageEye::both);
      // scanline_band writes every sample of both eyes.
      r.left = make_eye_image(w, h, PlaneInit::unset);
      r.right = make_eye_image(w, h, PlaneInit::unset);
    }
    const auto start = std::chrono::steady_clock::now();
    ctx.executor.for_each(bands, [&](size_t b) {
      const int y0 = static_cast<int>(b) * kScanlineBand;
      scanline_band(scene, reprojector, y0, std::min(y0 + kScanlineBand, h), r.left, r.right, per_band[b]);
    });
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ScanlineCounts counts;
    for (const ScanlineCounts& c : per_band) counts.add(c);
    // The scan-lines interleave both eyes' work on every thread: the pass's wall time is shared out
    // as rt-adelson's stages in proportion to the thread time each part took, so that the stages
    // still add up to the render's time and the right eye's share can be read beside the left's.
    const double busy = counts.left_seconds + counts.reproject_seconds + counts.right_seconds;
    const auto share = [&](double part) { return busy > 0.0 ? wall * part / busy : 0.0; };
    r.timings.add("left_trace", busy > 0.0 ? share(counts.left_seconds) : wall, StageEye::left);
    r.timings.add("reproject", share(counts.reproject_seconds), StageEye::right);
    r.timings.add("right_trace", share(counts.right_seconds), StageEye::right);
    add_scanline_counters(r, counts, rig);
    return r;
  }
};

SB_REGISTER_PIPELINE(RtEsIsler);

}  // namespace
}  // namespace sb
