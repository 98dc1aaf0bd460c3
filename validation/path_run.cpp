// Per-frame validation along a path.
#include "validation/path_run.hpp"

#include <chrono>

#include "renderer/io/render_output.hpp"
#include "validation/validate.hpp"

namespace sb::validation {

using nlohmann::json;

namespace {

json vec_json(const dvec3& v) { return json::array({v.x, v.y, v.z}); }

}  // namespace

void run_path(Scene& scene, const PathRun& run, const Executor& executor,
              const std::function<void(const json& frame)>& on_frame) {
  SceneAnimator animator(scene, run.path);
  animator.apply(0);
  RenderScene prepared(scene, run.refit);
  for (int frame = 0; frame < animator.frames(); ++frame) {
    const auto t0 = std::chrono::steady_clock::now();
    animator.apply(frame);
    const double animate_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    // Frame 0's BVH is the one just built; later frames update it.
    const double bvh_s = frame == 0 ? prepared.bvh_build_seconds()
                                    : (animator.moves_geometry() ? prepared.update_geometry() : 0.0);
    const CameraPose pose = animator.camera_at(frame, run.pose);
    const StereoRig rig(pose, run.rig);
    const ValidationTarget target =
        prepare_target(prepared, run.scene_file, rig, *run.truth, run.cache, run.work_dir, executor);
    json pipelines = json::object();
    for (const PipelineEntry& entry : run.pipelines) {
      const PipelineValidation v = validate_pipeline(target, entry, entry.options(), executor);
      pipelines[v.pipeline] = {{"total_s", v.result.timings.total()},
                               {"timings_s", io::timings_to_json(v.result.timings)},
                               {"stage_eyes", io::stage_eyes_to_json(v.result.timings)},
                               {"counters", v.result.counters.snapshot()},
                               {"metrics", to_json(v.whole)},
                               {"hole_fraction", v.holes.hole_fraction},
                               {"recall", v.holes.scores.recall}};
    }
    const double pixels = static_cast<double>(rig.params().width) * rig.params().height;
    on_frame({{"frame", frame},
              {"animate_s", animate_s},
              {"bvh_update_s", bvh_s},
              {"bvh", frame == 0 ? "build" : (animator.moves_geometry() ? (run.refit ? "refit" : "rebuild") : "static")},
              {"camera", {{"position", vec_json(pose.position)}, {"back", vec_json(pose.back)}}},
              {"truth_s", target.truth.render.seconds},
              {"true_disocclusion_fraction", static_cast<double>(target.disocclusions.count()) / pixels},
              {"pipelines", pipelines}});
  }
}

}  // namespace sb::validation
