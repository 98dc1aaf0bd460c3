// Sweep definitions (DESIGN §7): a TOML file naming scenes × interaxial values × convergence
// distances × resolutions × light counts × ground-truth providers, the pipelines validated and
// timed side by side in every cell, timing repetitions, pipeline options and what to write.
// Loading checks every key, type and name; expansion lists the cells in a fixed order with
// stable ids. The format is documented in docs/sweeps.md.
#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/animation.hpp"

namespace sb::validation {

/// One entry of the `scenes` axis: a built-in scene with optional generator parameters
/// ("complexity:triangles=1000000") or a glTF file (relative paths resolved against the folder of
/// the definition).
struct SweepScene {
  std::string label;                      ///< canonical text, used in cell ids: "complexity:triangles=1000000"
  bool builtin = true;
  std::string name;                       ///< built-in generator name, or the path as written
  std::filesystem::path file;             ///< glTF files only: the resolved path
  std::map<std::string, double> params;   ///< built-in generator parameters
};

/// A resolution as written and as parsed.
struct SweepResolution {
  std::string label;  ///< "WxH" (names like "hd" normalised)
  int width = 0;
  int height = 0;
};

/// The loaded, checked definition.
struct SweepDefinition {
  std::filesystem::path file;  ///< the TOML file as given
  std::string sha256;          ///< of its bytes
  std::string name;
  std::string description;

  std::vector<SweepScene> scenes;  ///< default: {spheres}
  /// Every pipeline validated and timed in each cell, sorted by name; the baseline is included.
  /// Entries as PipelineEntry reads them: a variant "NAME:KEY=VALUE..." runs beside its pipeline.
  std::vector<std::string> pipelines;
  std::string baseline = "plain-rt";
  bool baseline_listed = true;  ///< false when only added for the speed-ups

  /// Interaxial axis: meters or max disparity in px (at most one of them); an unset entry is the
  /// scene's default.
  std::vector<std::optional<double>> interaxial_m{std::nullopt};
  std::vector<std::optional<double>> max_disparity_px{std::nullopt};
  std::vector<std::optional<double>> convergence_m{std::nullopt};
  std::vector<std::optional<SweepResolution>> resolutions{std::nullopt};
  std::vector<std::optional<int>> lights{std::nullopt};  ///< unset: every light of the scene
  std::vector<std::string> truths{"full"};

  int repetitions = 3;
  int warmup = 1;
  /// Per pipeline name, checked; they apply to its variants too, under the variants' own options.
  std::map<std::string, std::map<std::string, std::string>> options;

  /// The `path` axis ([path]): every other combination runs once per frame, the scene animated
  /// and the camera moved to that frame. Unset: no animation, one cell per combination.
  std::optional<PathSpec> path;
  bool path_refit = true;  ///< per-frame BVH update: refit (true) or rebuild

  bool images = true;  ///< PNG images per cell
  bool exr = false;    ///< also the EXR of every right eye and ground truth

  /// `[gate] config`: the gate thresholds written for this sweep's cells (a path relative to the
  /// definition file), which `stereobench nightly` applies when no --gate-config is given.
  std::optional<std::filesystem::path> gate_config;

  /// What the definition asks that will not happen as it reads ("FILE:LINE: key: what"): camera
  /// keys of the path that no frame stands at. The sweep runs; its commands print these first.
  std::vector<std::string> warnings;
};

/// One cell: a combination of the axes. Every pipeline of the definition runs in it.
struct SweepCell {
  size_t index = 0;
  std::string id;  ///< stable and unique within the sweep, e.g. "spheres|e=0.064m|c=default|960x540|lights=all|full"
  SweepScene scene;
  std::optional<double> interaxial_m;
  std::optional<double> max_disparity_px;
  std::optional<double> convergence_m;
  std::optional<SweepResolution> resolution;
  std::optional<int> lights;
  std::string truth;
  std::optional<int> frame;  ///< the frame of the definition's path (set only with a [path])
};

/// Parses a definition. InputError naming the file, the key path and its line for unknown keys
/// (listing the valid ones), wrong types, empty or repeated axis values, values out of range,
/// both interaxial kinds, unknown pipelines, scenes, scene parameters, truth providers and
/// pipeline options. IoError when the file cannot be read.
[[nodiscard]] SweepDefinition load_sweep(const std::filesystem::path& file);
/// The same from text; `file` names it in messages and anchors relative scene paths.
[[nodiscard]] SweepDefinition parse_sweep(const std::string& text, const std::filesystem::path& file);

/// The most cells a definition may expand to (parse_sweep refuses more): a million cells take about
/// a gigabyte of memory as they are expanded, listed and merged.
inline constexpr size_t kMaxSweepCells = 1'000'000;

/// The cells in their fixed order: scenes outermost, then interaxial (or max disparity),
/// convergence, resolution, lights, truth and, with a [path], the frame innermost (frames of one
/// combination in order, "|frame=k" ending the id); `index` counts from 0 in that order.
[[nodiscard]] std::vector<SweepCell> expand_cells(const SweepDefinition& definition);

/// The cell's axes as written into results ("cell" of docs/sweeps.md).
[[nodiscard]] nlohmann::json cell_to_json(const SweepCell& cell);

/// Parses a built-in scene entry "name" or "name:key=value,key=value" and checks it against the
/// generator's parameters (name, range, whole numbers). InputError otherwise.
[[nodiscard]] SweepScene parse_builtin_scene(const std::string& text);

/// Shortest text that reads back as the same double ("0.064", "1e-05").
[[nodiscard]] std::string number_text(double value);

/// A built-in scene's canonical text: its name, then ":key=value,..." for its parameters.
[[nodiscard]] std::string scene_label(const std::string& name, const std::map<std::string, double>& params);

/// The id of a cell from its axes (expand_cells names cells with it):
/// "scene|e=…|c=…|resolution|lights=…|truth", "|frame=k" with a path.
[[nodiscard]] std::string cell_id(const SweepCell& cell);

/// The id that the axes of a results line's "cell" object (cell_to_json's fields) give, or
/// nothing when one of them is missing. InputError naming the field ("cell.interaxial_m is -1; it
/// must be ...") when one is of the wrong type or out of its range.
[[nodiscard]] std::optional<std::string> cell_id_from_json(const nlohmann::json& cell);

}  // namespace sb::validation
