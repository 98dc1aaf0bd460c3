// plain-rt: both eyes fully ray traced (Al-Hagri's naive stereo ray tracer); also the built-in
// ground truth.
#include "renderer/pipeline.hpp"
#include "renderer/stages/trace.hpp"

namespace sb {
namespace {

class PlainRt final : public Pipeline {
 public:
  const PipelineInfo& info() const override {
    static const PipelineInfo i{
        "plain-rt", "Al-Hagri 2012", "4.1 (naive ray tracer, the baseline)",
        "trace primary rays for each eye and shade them; the built-in ground truth", {}, 200.0, 200.0};
    return i;
  }

  StereoResult render(const RenderScene& scene, const StereoRig& rig, const PipelineOptions&,
                      const RenderContext& ctx) const override {
    StereoResult r;
    for (Eye e : {Eye::left, Eye::right}) {
      const char* name = eye_name(e);
      TraceCounts counts;
      {
        ScopedStage stage(r.timings, std::string(name) + "_trace", stage_eye(e));
        (e == Eye::left ? r.left : r.right) = traced_eye(scene, rig.eye(e), ctx.executor, counts);
      }
      add_counts(r.counters, counts, name, true);
    }
    r.counters.set("hole_pixels", 0);
    return r;
  }
};

SB_REGISTER_PIPELINE(PlainRt);

}  // namespace
}  // namespace sb
