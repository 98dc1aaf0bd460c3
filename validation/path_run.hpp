// Validation along a path of frames (DESIGN §7, camera paths and animation): per
// frame the scene is animated, its BVH refit or rebuilt (timed as its own stage), the ground truth
// and true disocclusions computed, and every pipeline rendered and measured.
#pragma once

#include <filesystem>
#include <functional>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/animation.hpp"
#include "renderer/parallel.hpp"
#include "renderer/pipeline.hpp"
#include "validation/truth_cache.hpp"

namespace sb::validation {

struct PathRun {
  std::filesystem::path scene_file;  ///< for providers that import it
  RigParams rig;                     ///< resolution, interaxial, convergence, field of view
  CameraPose pose;                   ///< the centre camera when the path has no camera keys
  PathSpec path;
  std::vector<PipelineEntry> pipelines;  ///< pipelines or variants ("NAME:KEY=VALUE...")
  const TruthProvider* truth = nullptr;
  const TruthCache* cache = nullptr;
  std::filesystem::path work_dir;
  bool refit = true;  ///< refit the BVH per frame (else rebuild it)
};

/// Runs every frame of the path on `scene` (animated in place; left at the last frame) and calls
/// `on_frame` with each frame's record ("kind": "stereobench.path_frame"): frame and frames, the
/// scene, the frame's rig, the animation (camera keys, spin, BVH update), the truth's provider,
/// tool version and cache key, threads and versions; animate_s, bvh_update_s, bvh
/// ("build"/"refit"/"rebuild"/"static"), camera pose, truth seconds, true disocclusion fraction;
/// and per pipeline its options, total_s, timings_s, counters, the whole-image metrics (metrics
/// JSON of validation/metrics.hpp), hole fraction, recall and precision.
void run_path(Scene& scene, const PathRun& run, const Executor& executor,
              const std::function<void(const nlohmann::json& frame)>& on_frame);

/// The truth's check of `scene` as the path's last frame moves it (a copy is animated): what a
/// provider refuses only of a moved scene (Blender: a node whose primitives a spin moves apart)
/// is found before the first frame runs. Nothing to do for a path of one frame or one that moves
/// no geometry. InputError from the provider, or from the path itself.
void check_path_truth(const TruthProvider& truth, const Scene& scene, const PathSpec& path,
                      const std::filesystem::path& scene_file);

}  // namespace sb::validation
