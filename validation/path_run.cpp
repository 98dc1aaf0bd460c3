// Per-frame validation along a path.
#include "validation/path_run.hpp"

#include <chrono>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/io/render_output.hpp"
#include "validation/validate.hpp"

namespace sb::validation {

using nlohmann::json;

namespace {

json vec_json(const dvec3& v) { return json::array({v.x, v.y, v.z}); }

/// What every frame of a path shares: the path itself (keys, spin, BVH update) and its frame count.
json animation_json(const PathRun& run) {
  json keys = json::array();
  for (const CameraKey& k : run.path.camera_keys)
    keys.push_back({{"position", vec_json(k.position)}, {"target", vec_json(k.target)}});
  json spin = nullptr;
  if (run.path.spin)
    spin = {{"axis", vec_json(run.path.spin->axis)},
            {"degrees_per_frame", run.path.spin->degrees_per_frame},
            {"mesh_prefix", run.path.spin->mesh_prefix},
            {"pivot", run.path.spin->pivot ? vec_json(*run.path.spin->pivot) : json(nullptr)}};
  return {{"frames", run.path.frames},
          {"camera_keys", keys},
          {"spin", spin},
          {"gltf_animation", run.path.gltf_animation},
          {"gltf_clip", run.path.gltf_clip.empty() ? json(nullptr) : json(run.path.gltf_clip)},
          {"bvh_update", run.refit ? "refit" : "rebuild"}};
}

}  // namespace

void run_path(Scene& scene, const PathRun& run, const Executor& executor,
              const std::function<void(const json& frame)>& on_frame) {
  SceneAnimator animator(scene, run.path);
  animator.apply(0);
  RenderScene prepared(scene, run.refit);
  const json animation = animation_json(run);
  const json scene_json = {{"name", scene.name},
                           {"path", scene.path},
                           {"triangles", scene.triangle_count()},
                           {"lights", scene.lights.size()}};
  for (int frame = 0; frame < animator.frames(); ++frame) {
    const auto t0 = std::chrono::steady_clock::now();
    animator.apply(frame);
    const double animate_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    // Frame 0's BVH is the one just built; later frames update it.
    double bvh_s = prepared.bvh_build_seconds();
    try {
      if (frame > 0) bvh_s = animator.moves_geometry() ? prepared.update_geometry(animator.moving_mesh_indices()) : 0.0;
    } catch (const InputError& e) {
      // Geometry the animation moves out of range: named with the frame that moved it there.
      throw InputError(fmt::format("frame {} of the path (animation time {:g} s): {}", frame, animator.time_of(frame),
                                   e.what()));
    }
    const CameraPose pose = animator.camera_at(frame, run.pose);
    const StereoRig rig(pose, run.rig);
    const ValidationTarget target =
        prepare_target(prepared, run.scene_file, rig, *run.truth, run.cache, run.work_dir, executor);
    json pipelines = json::object();
    for (const PipelineEntry& entry : run.pipelines) {
      const PipelineValidation v = validate_pipeline(target, entry, entry.options(), executor);
      pipelines[v.pipeline] = {{"options", v.options.values()},
                               {"total_s", v.result.timings.total()},
                               {"timings_s", io::timings_to_json(v.result.timings)},
                               {"stage_eyes", io::stage_eyes_to_json(v.result.timings)},
                               {"counters", v.result.counters.snapshot()},
                               {"metrics", to_json(v.whole)},
                               {"hole_fraction", v.holes.hole_fraction},
                               {"recall", v.holes.scores.recall},
                               {"precision", v.holes.scores.precision}};
    }
    const double pixels = static_cast<double>(rig.params().width) * rig.params().height;
    const TruthRender& truth = target.truth.render;
    on_frame({{"kind", "stereobench.path_frame"},
              {"frame", frame},
              {"frames", animator.frames()},
              {"scene", scene_json},
              {"rig", io::rig_to_json(rig)},
              {"animation", animation},
              {"truth",
               {{"provider", truth.provider},
                {"tool_version", truth.tool_version},
                {"cached", target.truth.cached},
                {"cache_key", target.truth.key}}},
              {"threads", executor.threads()},
              {"versions", io::versions_json()},
              {"animate_s", animate_s},
              {"animation_time_s", run.path.gltf_animation ? json(animator.time_of(frame)) : json(nullptr)},
              {"bvh_update_s", bvh_s},
              {"bvh", frame == 0 ? "build" : (animator.moves_geometry() ? (run.refit ? "refit" : "rebuild") : "static")},
              {"camera", {{"position", vec_json(pose.position)}, {"back", vec_json(pose.back)}}},
              {"truth_s", target.truth.render.seconds},
              {"true_disocclusion_fraction", static_cast<double>(target.disocclusions.count()) / pixels},
              {"pipelines", pipelines}});
  }
}

void check_path_truth(const TruthProvider& truth, const Scene& scene, const PathSpec& path,
                      const std::filesystem::path& scene_file) {
  if (path.frames < 2) return;
  Scene last = scene;
  SceneAnimator animator(last, path);
  if (!animator.moves_geometry()) return;
  animator.apply(path.frames - 1);
  truth.check_scene(last, scene_file);
}

}  // namespace sb::validation
