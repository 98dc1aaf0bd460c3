// Writes what `stereobench render` produces for one pipeline run: the EXR pair with every AOV,
// PNG previews of each eye, a Dubois anaglyph, a side-by-side image and a stats JSON.
#pragma once

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "renderer/pipeline.hpp"

namespace sb::io {

/// The rig as JSON: resolution, vfov, interaxial (m), convergence (m), f_px, max disparity (px).
[[nodiscard]] nlohmann::json rig_to_json(const StereoRig& rig);

/// Versions of stereobench and the libraries it renders with.
[[nodiscard]] nlohmann::json versions_json();

/// A run's record: pipeline, scene, rig, threads, per-stage timings, counters, versions.
[[nodiscard]] nlohmann::json result_to_json(const std::string& pipeline, const RenderScene& scene,
                                            const StereoRig& rig, const StereoResult& result, int threads,
                                            const PipelineOptions& options);

/// The files written for one run, under `dir` with names starting with `stem`.
struct RenderFiles {
  std::filesystem::path exr, left_png, right_png, anaglyph_png, side_by_side_png, stats_json;
};

/// Writes every output of a run (atomically, file by file) and returns their paths.
RenderFiles write_render_outputs(const std::filesystem::path& dir, const std::string& stem,
                                 const StereoResult& result, const nlohmann::json& record);

}  // namespace sb::io
