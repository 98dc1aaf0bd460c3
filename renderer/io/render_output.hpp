// Writes what `stereobench render` produces for one pipeline run: the EXR pair with every AOV,
// PNG previews of each eye, the viewable stereo images asked for (Dubois anaglyph, side-by-side,
// over/under), the hole overlay and the pipeline's diagnostic images when there are any, and a
// stats JSON.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/parallel.hpp"
#include "renderer/pipeline.hpp"
#include "renderer/stages/disocclusion.hpp"

namespace sb::io {

/// The rig as JSON: resolution, vfov, interaxial (m), convergence (m), f_px, max disparity (px).
[[nodiscard]] nlohmann::json rig_to_json(const StereoRig& rig);

/// Versions of stereobench and the libraries it renders with.
[[nodiscard]] nlohmann::json versions_json();

/// A run's stage timings, {"stage": seconds, ...}.
[[nodiscard]] nlohmann::json timings_to_json(const Timings& timings);
/// The eye each of a run's stages serves, {"stage": "left" | "right" | "both", ...}.
[[nodiscard]] nlohmann::json stage_eyes_to_json(const Timings& timings);

/// A run's record: pipeline, scene, rig, threads, per-stage timings, counters, versions.
[[nodiscard]] nlohmann::json result_to_json(const std::string& pipeline, const RenderScene& scene,
                                            const StereoRig& rig, const StereoResult& result, int threads,
                                            const PipelineOptions& options);

/// A hole analysis as the "holes" object of a run's record: not_reprojected_pixels (the mask
/// scored), true_disocclusions, outside_frustum, hidden, true_positives, recall, precision (null
/// where undefined), analysis_s.
[[nodiscard]] nlohmann::json holes_to_json(const HoleAnalysis& analysis);

/// The viewable stereo images a render writes beside the eyes (DESIGN §4.2).
struct StereoViews {
  bool anaglyph = true;      ///< <stem>_anaglyph.png: Dubois red-cyan
  bool side_by_side = true;  ///< <stem>_sbs.png: left eye on the left
  bool over_under = false;   ///< <stem>_ou.png: left eye on top

  /// From names among anaglyph, sbs and ou, or the one name "none"; InputError naming `option`
  /// and the name for an unknown name, a name given twice, or "none" beside another name.
  [[nodiscard]] static StereoViews from_names(const std::vector<std::string>& names, const std::string& option);
};

/// The files written for one run, under `dir` with names starting with `stem`.
struct RenderFiles {
  std::filesystem::path exr, left_png, right_png, stats_json;
  std::optional<std::filesystem::path> anaglyph_png, side_by_side_png, over_under_png;  ///< as StereoViews asks
  std::optional<std::filesystem::path> holes_png;  ///< <stem>_holes.png, when there was a hole overlay
  std::vector<std::filesystem::path> extras;       ///< <stem>_<name>.png per StereoResult::extras entry

  /// Every written file, in the order they were written.
  [[nodiscard]] std::vector<std::filesystem::path> all() const;
};

/// The paths of a render's outputs named <stem>... in `dir`: the EXR, the eyes' PNGs, the stereo
/// images `views` asks for, the stats JSON and <stem>_holes.png (holes_png set); extras are named
/// by write_render_outputs.
[[nodiscard]] RenderFiles render_file_names(const std::filesystem::path& dir, const std::string& stem,
                                            const StereoViews& views = {});

/// IoError (exit 4) when a folder stands where one of `files` is to be written: the names are
/// generated, so the way out is to remove the folder or write elsewhere (`where` says how, e.g.
/// "give another --out").
void check_no_folder_at(const std::vector<std::filesystem::path>& files, const std::string& where);

/// Writes every output of a run as one set (io::StagedFiles: all made whole, then all renamed
/// into place, the stats JSON last, which lists the set's files; the earlier set's files of the
/// stem that this one does not write are then removed) and returns their paths: the stereo images
/// `views` asks for, with `holes_overlay` also <stem>_holes.png, and a PNG preview of the "rgb"
/// plane of each of the result's extras. An extra's name must be lowercase letters, digits and '_'
/// and must not be one of the standard suffixes (left, right, anaglyph, sbs, ou, stats, holes)
/// nor appear twice; InputError otherwise, before anything is written. The images are encoded
/// side by side on `executor`'s threads (the bytes of each file do not depend on it).
RenderFiles write_render_outputs(const std::filesystem::path& dir, const std::string& stem,
                                 const StereoResult& result, const nlohmann::json& record,
                                 const Image* holes_overlay = nullptr, const StereoViews& views = {},
                                 const Executor& executor = Executor(1));

}  // namespace sb::io
