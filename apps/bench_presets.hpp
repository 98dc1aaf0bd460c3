// Benchmark presets of `stereobench bench --preset`: the performance series of Al-Hagri's thesis
// (Table 5) as tables of benchmark rows, each row timed side by side like a plain `bench` run.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "renderer/parallel.hpp"
#include "renderer/rig.hpp"
#include "validation/benchmark.hpp"

namespace sb::cli {

/// One row of a series: a built-in scene and the rig and light count it is timed with.
struct PresetRow {
  std::string value;                           ///< the swept value as the table shows it: "200x200", "40", "3"
  std::string scene;                           ///< built-in scene name
  std::map<std::string, double> scene_params;  ///< generator parameters; empty = the default scene
  int width = 0;
  int height = 0;
  double max_disparity_px = 0.0;  ///< the thesis' "interaxial distance e in pixels"
  int lights = 0;                 ///< the scene's first `lights` lights; a scene with fewer keeps all of its own
};

/// One table: rows that sweep one setting while the others stay fixed.
struct PresetSeries {
  std::string name;   ///< e.g. "dragon by image size"
  std::string swept;  ///< heading of the swept column: "size", "e px", "lights"
  std::string fixed;  ///< what stays fixed, e.g. "600x600, e = 15 px"
  std::vector<PresetRow> rows;
};

/// A named set of series.
struct BenchPreset {
  std::string name;
  std::string summary;  ///< for --help
  std::vector<PresetSeries> series;
};

/// The presets: al-hagri-dimensions, al-hagri-interaxial, al-hagri-lights.
[[nodiscard]] const std::vector<BenchPreset>& bench_presets();
/// The preset of that name; InputError listing the presets otherwise.
[[nodiscard]] const BenchPreset& find_bench_preset(const std::string& name);
/// The pipelines a preset times unless --pipelines says otherwise: the thesis' five ray tracers
/// (naive, ideal copy, Es-Isler, buffer-based, atomic-based) plus Adelson-Hodges reprojection.
[[nodiscard]] const std::vector<std::string>& preset_default_pipelines();
/// A few lines describing every preset, for `bench --help`.
[[nodiscard]] std::string presets_help();

/// How to run a preset.
struct PresetRun {
  const BenchPreset* preset = nullptr;
  BenchConfig config;        ///< pipelines, baseline, warm-up, repetitions, options: applied to every row
  int rows_per_series = 0;   ///< run only the first N rows of each series; 0 = all
  RigOverrides overrides;    ///< rig settings the preset leaves open (convergence, vertical field of view)
  std::string scenes_dir;
  std::string json_out;      ///< rewritten after every row; empty = none
};

/// Runs every series, printing one table per series (a row as soon as it is measured).
void run_bench_preset(const PresetRun& run, const Executor& executor);

}  // namespace sb::cli
