// Benchmark presets of `stereobench bench --preset`: the performance series of Al-Hagri's thesis
// (Table 5) and the quality and complexity tables of Kim's paper (Tables 2 and 3) as tables of
// benchmark rows, each row timed side by side like a plain `bench` run.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "renderer/error.hpp"
#include <nlohmann/json.hpp>

#include "renderer/memory.hpp"
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
  /// The scene's first `lights` lights (a scene with fewer keeps all of its own); unused by Kim's
  /// presets, which keep every light of the scene.
  int lights = 0;
  std::optional<double> interaxial = std::nullopt;   ///< meters; instead of max_disparity_px when set
  std::optional<double> convergence = std::nullopt;  ///< meters; unset = the scene's (or --convergence)
};

/// One table: rows that sweep one setting while the others stay fixed.
struct PresetSeries {
  std::string name;   ///< e.g. "dragon by image size"
  std::string swept;  ///< heading of the swept column: "size", "e px", "lights"
  std::string fixed;  ///< what stays fixed, e.g. "600x600, e = 15 px"
  std::vector<PresetRow> rows;
};

/// What a preset measures, and so how its rows are run and printed.
enum class PresetKind {
  speed,       ///< median totals and speed-ups per row (Al-Hagri, Table 5)
  quality,     ///< SSIM/PSNR of every right eye against the reference's, plus times (Kim, Table 2)
  complexity,  ///< rendering/warping split per triangle count, memory-checked rows, crossover (Kim, Table 3)
};

/// A named set of series.
struct BenchPreset {
  std::string name;
  std::string summary;  ///< for --help
  std::vector<PresetSeries> series;
  PresetKind kind = PresetKind::speed;
  std::vector<std::string> pipelines;  ///< timed unless --pipelines says otherwise; empty = preset_default_pipelines()
  std::string baseline = "plain-rt";   ///< speed-ups against it unless --baseline says otherwise
  /// Command-line options the preset sets itself in every row; giving one with it is an InputError.
  std::vector<std::string> fixed_options = {"--scene", "--resolution", "--interaxial", "--max-disparity", "--lights"};
  bool resolution_open = false;  ///< --resolution replaces the rows' image size
};

/// The presets: al-hagri-dimensions, al-hagri-interaxial, al-hagri-lights, kim-focal, kim-complexity.
[[nodiscard]] const std::vector<BenchPreset>& bench_presets();
/// The preset of that name; InputError listing the presets otherwise.
[[nodiscard]] const BenchPreset& find_bench_preset(const std::string& name);
/// The pipelines the Al-Hagri presets time unless --pipelines says otherwise: the thesis' five ray
/// tracers (naive, ideal copy, Es-Isler, buffer-based, atomic-based) plus Adelson-Hodges reprojection.
[[nodiscard]] const std::vector<std::string>& preset_default_pipelines();
/// The pipelines `preset` times unless --pipelines says otherwise.
[[nodiscard]] const std::vector<std::string>& preset_pipelines(const BenchPreset& preset);
/// A few lines describing every preset, for `bench --help`.
[[nodiscard]] std::string presets_help();

/// How to run a preset.
struct PresetRun {
  const BenchPreset* preset = nullptr;
  BenchConfig config;        ///< pipelines, baseline, warm-up, repetitions, options: applied to every row
  int rows_per_series = 0;   ///< run only the first N rows of each series; 0 = all
  /// Rig settings the preset leaves open (convergence, vertical field of view; the image size when
  /// the preset's resolution_open).
  RigOverrides overrides;
  std::string scenes_dir;
  std::string json_out;      ///< rewritten after every row; empty = none

  /// Called as a row's timing starts and before the JSON is written: the first call removes an
  /// earlier --json file, so that a run stopped from here on leaves none of another run's (one
  /// refused before, as a usage error or for memory, keeps it); later calls do nothing.
  void output_starts() const;

 private:
  mutable bool json_cleared_ = false;
};

/// How many rows of `series` a run takes: the first `rows_per_series` (PresetRun's), or all of
/// them for 0.
[[nodiscard]] size_t rows_to_run(const PresetSeries& series, int rows_per_series);

/// Runs every series, printing one table per series (a row as soon as it is measured).
void run_bench_preset(const PresetRun& run, const Executor& executor);

/// The rig of one row of a preset on its scene.
using RowRig = StereoRig (*)(const Scene& scene, const PresetRun& run, const PresetRow& row);

/// Before a series' first row runs: every row of the first `rows` of `series` whose scene is the
/// file `loaded` (the scene just loaded for the first row) has its rig checked by every timed
/// pipeline (PipelineEntry::check_rig), so that a rig a pipeline refuses (rt-buffer's depth
/// beyond its bound at a small field of view, say) stops the series before it measures anything,
/// not after its earlier rows. InputError naming the row.
void check_series_rigs(const PresetRun& run, const PresetSeries& series, size_t rows, const std::filesystem::path& loaded,
                       const Scene& scene, RowRig rig_of);

// ---- Kim's tables (apps/bench_presets_kim.cpp) ----

/// kim-focal: the atrium at 960x540, e = 64 mm, convergence 6 m, 2 m and 0.3 m (Kim's focal
/// distances 6000, 2000 and 300 mm).
[[nodiscard]] BenchPreset kim_focal_preset();
/// kim-complexity: the `complexity` scene with 1e5, 1e6, 1e7 and 1e8 triangles at 1920x1080 (FHD).
[[nodiscard]] BenchPreset kim_complexity_preset();
/// Runs kim-focal: per row, every pipeline's right eye once (untimed) for SSIM/PSNR against the
/// reference plain-raster's, then the side-by-side timing. Prints Kim's Table 2 layout and a time table.
void run_kim_focal(const PresetRun& run, const Executor& executor);
/// Runs kim-complexity: per row a memory check, the scene generated or loaded, the timing split
/// into rendering and warping stages, the measured peak resident memory; then the crossover.
void run_kim_complexity(const PresetRun& run, const Executor& executor);

// The decisions of kim-complexity below are pure and defined here, inline, so that the tests use
// them without the command-line application.

/// How a pipeline stage counts in Kim's Table 3.
enum class StageGroup {
  rendering,  ///< rasterization and shading: "redirect", "ztest", "*_gbuffer", "*_shading", "*_trace"
  warping,    ///< reprojection and its repairs: warps, motion, crack and hole filling, background
  other,      ///< a stage of neither kind (listed separately, never folded into either)
};
[[nodiscard]] inline StageGroup stage_group(std::string_view stage) {
  if (stage == "redirect" || stage == "ztest" || stage.ends_with("_gbuffer") || stage.ends_with("_shading") ||
      stage.ends_with("_trace"))
    return StageGroup::rendering;
  for (std::string_view w : {"motion", "warp", "warp_depth", "warp_color", "backward_warp", "row_warp", "reproject",
                             "crack_fill", "hole_fill", "background"})
    if (stage == w) return StageGroup::warping;
  return StageGroup::other;
}

/// The peak resident memory a measured row reached.
struct MeasuredPeak {
  double triangles = 0.0;
  uint64_t peak_bytes = 0;
};

/// Estimated peak resident bytes of a row with `triangles`, from the rows measured so far (in any
/// order) and the resident bytes `base_bytes` before the first row. With two or more rows: the
/// line through the two largest, its slope at least that of the largest row's share above the base
/// divided by ten (so noise cannot make it flat); with one: proportional to its share above the
/// base; with none: base + prior_fixed_bytes + prior_bytes_per_triangle * triangles.
[[nodiscard]] inline uint64_t estimate_peak_bytes(std::vector<MeasuredPeak> measured, uint64_t base_bytes,
                                                  double triangles, double prior_fixed_bytes,
                                                  double prior_bytes_per_triangle) {
  const double base = static_cast<double>(base_bytes);
  double estimate = base + prior_fixed_bytes + prior_bytes_per_triangle * triangles;
  if (!measured.empty()) {
    std::sort(measured.begin(), measured.end(),
              [](const MeasuredPeak& a, const MeasuredPeak& b) { return a.triangles < b.triangles; });
    const MeasuredPeak& top = measured.back();
    const double above = std::max(0.0, static_cast<double>(top.peak_bytes) - base);
    const double proportional = top.triangles > 0.0 ? above / top.triangles : 0.0;
    if (measured.size() == 1) {
      estimate = base + proportional * triangles;
    } else {
      const MeasuredPeak& next = measured[measured.size() - 2];
      const double dn = top.triangles - next.triangles;
      double slope = dn > 0.0 ? (static_cast<double>(top.peak_bytes) - static_cast<double>(next.peak_bytes)) / dn : 0.0;
      slope = std::max(slope, 0.1 * proportional);
      estimate = static_cast<double>(top.peak_bytes) + slope * (triangles - top.triangles);
    }
  }
  return static_cast<uint64_t>(std::max(estimate, base));
}

/// Whether a speed-up is above 1 as the tables print it (two decimals: 1.004 reads 1.00x).
[[nodiscard]] inline bool speedup_above_one(double speedup) { return std::round(speedup * 100.0) > 100.0; }

/// Index of the crossover row: the first row from which the method's speed-up over the baseline
/// (the median of the ratios paired per repetition, the figure the table prints) is above 1 in
/// that row and every later one (rows in increasing complexity); nullopt when there is none.
[[nodiscard]] inline std::optional<size_t> crossover_row(const std::vector<double>& speedups) {
  std::optional<size_t> first;
  for (size_t i = speedups.size(); i-- > 0;) {
    if (!speedup_above_one(speedups[i])) break;
    first = i;
  }
  return first;
}

/// The speed-up of `method` over `reference` in one row, paired per repetition, whichever baseline
/// the row's speed-ups were taken against (kim-complexity's crossover is over plain-raster). Both
/// must be among the row's pipelines (the preset checks its --pipelines).
[[nodiscard]] inline double speedup_between(const sb::BenchResult& row, std::string_view reference,
                                            std::string_view method) {
  const auto named = [&](std::string_view name) -> const sb::PipelineBench& {
    return *std::find_if(row.pipelines.begin(), row.pipelines.end(),
                         [&](const sb::PipelineBench& b) { return b.name == name; });
  };
  return sb::paired_speedup(named(reference), named(method)).median;
}

/// The head of a preset's JSON file (preset, pipelines, baseline, repetitions, threads, versions),
/// with "complete": false and no rows yet.
[[nodiscard]] nlohmann::json preset_json(const PresetRun& run, const Executor& executor);

/// What the run's rig options replace in the preset's rows ("image size 480x270, ..."), for the
/// header under the preset's summary, which speaks of the published setting; "" when nothing.
[[nodiscard]] std::string preset_overrides(const PresetRun& run);

/// Prints the preset's summary and, when the run replaces part of its setting, what it replaces.
void print_preset_summary(const PresetRun& run);

}  // namespace sb::cli
