// Kim's tables as benchmark presets: kim-focal (Table 2, SSIM/PSNR of the warped right eyes against
// the 2-pass reference at three focal distances, plus times) and kim-complexity (Table 3, rendering
// and warping time against the triangle count, with a memory check before every row).
#include <malloc.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <tuple>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "apps/bench_presets.hpp"
#include "apps/cli_common.hpp"
#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/gltf_loader.hpp"
#include "renderer/io/json_text.hpp"
#include "renderer/io/render_output.hpp"
#include "renderer/memory.hpp"
#include "renderer/text.hpp"
#include "scenes/catalog.hpp"
#include "validation/metrics.hpp"

namespace sb::cli {

namespace {

namespace fs = std::filesystem;

/// Kim's 2-pass reference, and the method of the crossover.
constexpr const char* kReference = "plain-raster";
constexpr const char* kBidirectional = "bidir-warp";
/// bidir-warp with the z-test Kim's §5 proposes against occlusion artifacts (his Fig. 14).
constexpr const char* kBidirectionalZtest = "bidir-warp:occlusion=ztest";
/// Kim's interpupillary distance, 64 mm.
constexpr double kKimInteraxial = 0.064;

/// Before the first row of kim-complexity has been measured its peak is estimated as the resident
/// memory before it plus 1 GiB (image buffers: 0.55 GiB measured at 1920x1080) plus 1 KiB per
/// triangle (about 4x the 265 B per triangle measured between 1e5 and 1e6 triangles at 1920x1080).
constexpr double kPriorFixedBytes = 1024.0 * 1024.0 * 1024.0;
constexpr double kPriorBytesPerTriangle = 1024.0;

constexpr double kMiB = 1024.0 * 1024.0;

/// What the process may allocate now, by the bound require_memory uses: a row that passes the
/// preset's check is not refused part-way by the loader or the BVH's own checks.
MemoryBudget budget_now() {
  const MemoryBudget budget = memory_budget(read_memory_sources());
  if (budget.bytes == UINT64_MAX)
    throw IoError("cannot read how much memory is available (/proc/meminfo), which kim-complexity needs to decide "
                  "whether a row fits; run it on Linux 3.14 or later");
  return budget;
}

/// Resets the process's peak resident size (VmHWM) to its current size, so that the next reading
/// is the peak of what follows (Linux 4.0+: "5" to /proc/self/clear_refs). False when refused.
bool reset_peak_resident() {
  std::ofstream out("/proc/self/clear_refs");
  out << "5";
  out.flush();
  return static_cast<bool>(out);
}

bool contains(const std::vector<std::string>& items, const std::string& name) {
  return std::find(items.begin(), items.end(), name) != items.end();
}

/// A Kim row's image size: --resolution's where the preset leaves it open and it was given, else
/// the row's own.
std::pair<int, int> row_size(const PresetRun& run, const PresetRow& row) {
  if (run.overrides.width && run.overrides.height && run.preset->resolution_open)
    return {*run.overrides.width, *run.overrides.height};
  return {row.width, row.height};
}

/// The rig of a Kim row: the preset's interaxial and convergence, the row's image size, and what
/// else the command line left open (--vfov, --convergence).
StereoRig row_rig(const Scene& scene, const PresetRun& run, const PresetRow& row) {
  RigOverrides o = run.overrides;
  std::tie(o.width, o.height) = row_size(run, row);
  o.max_disparity_px.reset();
  o.interaxial = row.interaxial;
  if (row.convergence) o.convergence = row.convergence;
  return resolve_rig(scene, o);
}

nlohmann::json scene_json(const Scene& scene, const PresetRow& row) {
  return {{"name", scene.name},
          {"path", scene.path},
          {"params", row.scene_params.empty() ? nlohmann::json::object() : nlohmann::json(row.scene_params)},
          {"triangles", scene.triangle_count()},
          {"vertices", scene.vertex_count()},
          {"lights", scene.lights.size()}};
}

void print_run_head(const PresetRun& run, const Executor& executor) {
  print_preset_summary(run);
  fmt::print("{}; baseline {}; {}, {} warm-up + {} per row\n", fmt::join(run.config.pipelines, ", "),
             run.config.baseline, counted(executor.threads(), "thread"), run.config.warmup,
             counted(run.config.repetitions, "repetition"));
  if (const std::string given = given_options(run.config); !given.empty()) fmt::print("options: {}\n", given);
  fmt::print("times: median over repetitions of each pipeline's total; speed-up = median over repetitions of {}'s "
             "total / the pipeline's total, paired per repetition\n",
             run.config.baseline);
}

std::string psnr_text(double psnr) { return std::isinf(psnr) ? std::string("inf") : fmt::format("{:.2f}", psnr); }

// ---- kim-focal ----

/// What one kim-focal row measured.
struct FocalRow {
  std::string value;
  std::vector<std::pair<std::string, validation::ImageMetrics>> quality;  ///< per method, in pipeline order
  BenchResult bench;
};

void print_focal_tables(const PresetSeries& series, const std::vector<FocalRow>& rows, const BenchConfig& config) {
  const size_t first = std::max<size_t>(8, series.swept.size());
  // Kim's Table 2: rows = distances, columns = methods, "SSIM/PSNR".
  fmt::print("\nSSIM/PSNR (dB) of each right eye against {}'s right eye (Kim, Table 2)\n", kReference);
  std::string head = fmt::format("{:<{}}", series.swept, first);
  for (const auto& [name, m] : rows.front().quality) head += fmt::format("  {:>{}}", name, std::max<size_t>(14, name.size()));
  fmt::print("{}\n", head);
  for (const FocalRow& r : rows) {
    std::string line = fmt::format("{:<{}}", r.value, first);
    for (const auto& [name, m] : r.quality)
      // SSIM is undefined below its 11x11 window (NaN), as compare says.
      line += fmt::format("  {:>{}}",
                          fmt::format("{}/{}", std::isnan(m.ssim) ? "undefined" : fmt::format("{:.4f}", m.ssim),
                                      psnr_text(m.psnr)),
                          std::max<size_t>(14, name.size()));
    fmt::print("{}\n", line);
  }
  // Times of the same rows.
  fmt::print("\nmedian total ms and speed-up against {}\n", config.baseline);
  head = fmt::format("{:<{}}", series.swept, first);
  for (const std::string& p : config.pipelines)
    head += fmt::format("  {:>{}} {:>9}", p + " ms", std::max<size_t>(10, p.size() + 3), "speed-up");
  fmt::print("{}\n", head);
  for (const FocalRow& r : rows) {
    std::string line = fmt::format("{:<{}}", r.value, first);
    for (const PipelineBench& b : r.bench.pipelines)
      line += fmt::format("  {:>{}.2f} {:>9}", summarize(b.total_seconds).median * 1e3, std::max<size_t>(10, b.name.size() + 3),
                          fmt::format("{:.2f}x", b.speedup.median));
    fmt::print("{}\n", line);
  }
  std::fflush(stdout);
}

// ---- kim-complexity ----

/// Medians of one pipeline's stage groups over the repetitions (each repetition's stages summed
/// by group first).
struct GroupTimes {
  double rendering_ms = 0.0, warping_ms = 0.0, other_ms = 0.0, total_ms = 0.0;
  std::vector<std::string> other_stages;
};

GroupTimes group_times(const PipelineBench& b) {
  const size_t reps = b.total_seconds.size();
  // Per repetition, the sums of the rendering, warping and other stages (indexed by StageGroup).
  std::array<std::vector<double>, 3> sums;
  for (std::vector<double>& v : sums) v.assign(reps, 0.0);
  GroupTimes g;
  for (const std::string& stage : b.stage_order) {
    const StageGroup group = stage_group(stage);
    if (group == StageGroup::other) g.other_stages.push_back(stage);
    std::vector<double>& into = sums[static_cast<size_t>(group)];
    const std::vector<double>& s = b.stage_seconds.at(stage);
    for (size_t i = 0; i < reps && i < s.size(); ++i) into[i] += s[i];
  }
  g.rendering_ms = summarize(sums[static_cast<size_t>(StageGroup::rendering)]).median * 1e3;
  g.warping_ms = summarize(sums[static_cast<size_t>(StageGroup::warping)]).median * 1e3;
  g.other_ms = summarize(sums[static_cast<size_t>(StageGroup::other)]).median * 1e3;
  g.total_ms = summarize(b.total_seconds).median * 1e3;
  return g;
}

/// Seconds since `start`.
double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// "1e7" from 10000000.
std::string power_of_ten(double n) {
  const double e = std::log10(n);
  return std::abs(e - std::round(e)) < 1e-9 ? fmt::format("1e{}", static_cast<int>(std::lround(e))) : fmt::format("{:g}", n);
}

constexpr const char* kComplexityHead = "{:<14} {:>10}  {:<14} {:>12} {:>10} {:>10} {:>9} {:>9}\n";

}  // namespace

BenchPreset kim_focal_preset() {
  BenchPreset p;
  p.name = "kim-focal";
  p.summary =
      "Kim's Table 2: atrium at 960x540, e = 64 mm, focal distance (convergence) 6 m, 2 m and 0.3 m; each method's "
      "right eye against plain-raster's by SSIM/PSNR, and every pipeline's median time and speed-up. bidir-warp runs "
      "as published and with the z-test Kim's §5 proposes (bidir-warp:occlusion=ztest).";
  p.kind = PresetKind::quality;
  p.pipelines = {kReference, kBidirectional, kBidirectionalZtest, "bw-warp", "fw-warp", "bidir-warp-rt"};
  p.baseline = kReference;
  p.fixed_options = {"--scene", "--interaxial", "--max-disparity", "--convergence", "--lights"};
  p.resolution_open = true;
  PresetSeries s{"atrium by focal distance", "DF mm", "e = 64 mm, every light of the scene", {}};
  for (const double c_mm : {6000.0, 2000.0, 300.0}) {
    PresetRow row;
    row.value = fmt::format("{:g}", c_mm);
    row.scene = "atrium";
    row.width = 960;
    row.height = 540;
    row.interaxial = kKimInteraxial;
    row.convergence = c_mm * 1e-3;
    s.rows.push_back(row);
  }
  p.series.push_back(std::move(s));
  return p;
}

BenchPreset kim_complexity_preset() {
  BenchPreset p;
  p.name = "kim-complexity";
  p.summary =
      "Kim's Table 3 (whose rows are 1e6 to 1e9 triangles; the generator's range is 1e5 to 1e8): the complexity scene "
      "with 1e5, 1e6, 1e7 and 1e8 triangles at 1920x1080 (FHD), e = 64 mm; median "
      "rendering and warping time of each of its methods (plain-raster, bidir-warp, bw-warp, fw-warp), peak memory per "
      "row, and the crossover where bidir-warp beats "
      "plain-raster. A row that would not fit in the memory left is skipped with the reason.";
  p.kind = PresetKind::complexity;
  // Table 3's four methods: 2-Pass, Ours, and the one-directional BW and FW baselines.
  p.pipelines = {kReference, kBidirectional, "bw-warp", "fw-warp"};
  p.baseline = kReference;
  p.fixed_options = {"--scene", "--interaxial", "--max-disparity", "--lights"};
  p.resolution_open = true;
  PresetSeries s{"complexity by triangle count", "triangles", "e = 64 mm, every light of the scene", {}};
  for (const double n : {1e5, 1e6, 1e7, 1e8}) {
    PresetRow row;
    row.value = power_of_ten(n);
    row.scene = "complexity";
    row.scene_params = {{"triangles", n}};
    row.width = 1920;
    row.height = 1080;
    row.interaxial = kKimInteraxial;
    s.rows.push_back(row);
  }
  p.series.push_back(std::move(s));
  return p;
}

void run_kim_focal(const PresetRun& run, const Executor& executor) {
  const BenchPreset& preset = *run.preset;
  const std::vector<BenchEntry> entries = run.config.entries();
  if (!contains(run.config.pipelines, kReference))
    throw InputError(fmt::format("--preset {} compares every right eye with {}'s; add {} to --pipelines", preset.name,
                                 kReference, kReference));
  print_run_head(run, executor);
  fmt::print("quality: each pipeline renders the row once more, untimed, and its right eye is compared with {}'s "
             "(8-bit sRGB, SSIM as scikit-image, PSNR over RGB)\n",
             kReference);

  nlohmann::json out = preset_json(run, executor);
  out["reference"] = kReference;
  out["metrics_version"] = validation::kMetricsVersion;
  const auto write_json = [&] {
    run.output_starts();
    if (!run.json_out.empty()) write_option_file("--json", run.json_out, io::json_text(out, 2) + "\n");
  };

  const RenderContext ctx{executor};
  fs::path loaded_path;
  std::unique_ptr<Scene> scene;
  std::unique_ptr<RenderScene> prepared;
  for (const PresetSeries& series : preset.series) {
    const size_t n = rows_to_run(series, run.rows_per_series);
    std::vector<FocalRow> measured;
    for (size_t i = 0; i < n; ++i) {
      const PresetRow& row = series.rows[i];
      const fs::path path = scenes::resolve_builtin(row.scene, row.scene_params, run.scenes_dir);
      if (!scene || path != loaded_path) {
        prepared.reset();
        scene = std::make_unique<Scene>(io::load_gltf(path));
        print_warnings(scene->warnings);
        prepared = std::make_unique<RenderScene>(*scene);
        loaded_path = path;
      }
      if (i == 0)
        fmt::print("\n{}: {} ({} triangles, {} lights), {}\n", series.name, scene->name, scene->triangle_count(),
                   scene->lights.size(), series.fixed);
      if (i == 0) check_series_rigs(run, series, n, path, *scene, row_rig);
      const StereoRig rig = row_rig(*scene, run, row);
      fmt::print("{} = {}: {}\n", series.swept, row.value, describe(rig));
      std::fflush(stdout);

      // Quality: one untimed render per pipeline; rendering is deterministic, so these are the
      // images the timed repetitions produce.
      std::vector<std::pair<std::string, validation::Srgb8Image>> right_eyes;
      for (const BenchEntry& e : entries) {
        const StereoResult r = e.entry.pipeline->render(*prepared, rig, e.options, ctx);
        right_eyes.emplace_back(e.entry.name, validation::encode_srgb8(r.right, e.entry.name + " right eye"));
      }
      const auto ref = std::find_if(right_eyes.begin(), right_eyes.end(), [](const auto& e) { return e.first == kReference; });
      FocalRow result;
      result.value = row.value;
      nlohmann::json quality = nlohmann::json::object();
      for (const auto& [name, image] : right_eyes) {
        if (name == kReference) continue;
        result.quality.emplace_back(name, validation::compare_images(image, ref->second));
        quality[name] = validation::to_json(result.quality.back().second);
      }
      run.output_starts();
      result.bench = run_bench(*prepared, rig, run.config, executor);

      nlohmann::json median_ms = nlohmann::json::object(), speedup = nlohmann::json::object();
      for (const PipelineBench& b : result.bench.pipelines) {
        median_ms[b.name] = summarize(b.total_seconds).median * 1e3;
        speedup[b.name] = b.speedup.median;
      }
      out["rows"].push_back({{"series", series.name},
                             {"swept", series.swept},
                             {"value", row.value},
                             {"focal_distance_m", rig.params().convergence},
                             {"scene", scene_json(*scene, row)},
                             {"rig", io::rig_to_json(rig)},
                             {"bvh", {{"build_s", prepared->bvh_build_seconds()},
                                      {"memory_bytes", prepared->rays().memory_bytes()}}},
                             {"reference", kReference},
                             {"quality", quality},
                             {"median_total_ms", median_ms},
                             {"speedup_median", speedup},
                             {"bench", bench_to_json(result.bench)}});
      measured.push_back(std::move(result));
      write_json();  // after every row, so an interrupted run keeps what it measured
    }
    if (!measured.empty()) print_focal_tables(series, measured, run.config);
  }
  out["complete"] = true;
  write_json();
  if (!run.json_out.empty()) fmt::print("\nwrote {}\n", run.json_out);
}

void run_kim_complexity(const PresetRun& run, const Executor& executor) {
  const BenchPreset& preset = *run.preset;
  run.config.validate();
  for (const char* needed : {kReference, kBidirectional})
    if (!contains(run.config.pipelines, needed))
      throw InputError(fmt::format("--preset {} compares {} with {}; add {} to --pipelines", preset.name, kBidirectional,
                                   kReference, needed));
  // The frames of a row at its size: checked for every row before any runs or an earlier --json
  // goes, since the estimate of a row's peak below (from the triangle count) leaves them out.
  for (const PresetSeries& series : preset.series)
    for (size_t i = 0; i < rows_to_run(series, run.rows_per_series); ++i) {
      const PresetRow& row = series.rows[i];
      const auto [width, height] = row_size(run, row);
      require_frame_memory(width, height,
                           fmt::format("--preset {}, row {} = {}: the benchmark", preset.name, series.swept, row.value));
    }
  const uint64_t base_rss = resident_bytes();
  print_run_head(run, executor);
  fmt::print(
      "rendering = stages redirect, ztest, *_gbuffer, *_shading, *_trace; warping = motion, warps, crack and hole "
      "filling, background; medians of each repetition's sums\n");
  const MemoryBudget start_budget = budget_now();
  fmt::print("memory: a row runs when its estimated peak minus the resident memory before it is at most {:.0f} % of "
             "the memory left ({} now, by {}); peak = VmHWM of the row\n",
             kMemoryUsableShare * 100.0, gib(start_budget.bytes), start_budget.bound);

  nlohmann::json out = preset_json(run, executor);
  out["memory_usable_share"] = kMemoryUsableShare;
  const auto write_json = [&] {
    run.output_starts();
    if (!run.json_out.empty()) write_option_file("--json", run.json_out, io::json_text(out, 2) + "\n");
  };

  for (const PresetSeries& series : preset.series) {
    const size_t n = rows_to_run(series, run.rows_per_series);
    if (n == 0) continue;
    fmt::print("\n{}: {}\n", series.name, series.fixed);
    bool header_printed = false;
    const auto print_header = [&header_printed, &series] {
      if (header_printed) return;
      fmt::print(kComplexityHead, series.swept, "vertices", "method", "rendering ms", "warping ms", "total ms",
                 "speed-up", "peak MiB");
      header_printed = true;
    };
    std::vector<MeasuredPeak> peaks;
    std::vector<std::string> measured_values, skipped;
    std::vector<double> measured_triangles;
    std::vector<double> bidir_speedups;
    for (size_t i = 0; i < n; ++i) {
      const PresetRow& row = series.rows[i];
      const double triangles = row.scene_params.at("triangles");

      // Memory check before anything of the row is generated or loaded.
      malloc_trim(0);
      const uint64_t rss_before = resident_bytes();
      const MemoryBudget budget = budget_now();
      // Before a row is measured, the prior by triangles and the row's frames; a measured row's
      // peak holds its frames already.
      const auto [width, height] = row_size(run, row);
      const uint64_t frames = peaks.empty() ? static_cast<uint64_t>(width) * static_cast<uint64_t>(height) * kFrameBytesPerPixel : 0;
      const uint64_t estimate =
          estimate_peak_bytes(peaks, base_rss, triangles, kPriorFixedBytes, kPriorBytesPerTriangle) + frames;
      std::string basis = fmt::format("prior (1 GiB + 1 KiB per triangle, and {} of frames at {}x{})", gib(frames),
                                      width, height);
      if (peaks.size() == 1) basis = "proportional to the " + measured_values.back() + " row";
      if (peaks.size() >= 2)
        basis = "line through the " + measured_values[measured_values.size() - 2] + " and " + measured_values.back() + " rows";
      const uint64_t extra = estimate > rss_before ? estimate - rss_before : 0;
      nlohmann::json memory = {{"estimated_peak_bytes", estimate},
                               {"estimate_basis", basis},
                               {"resident_before_bytes", rss_before},
                               {"budget_bytes", budget.bytes},
                               {"budget_bound", budget.bound}};
      if (!fits(extra, budget)) {
        const std::string reason =
            fmt::format("estimated peak {} ({}) needs {} more, over {:.0f} % of the {} left by {}", gib(estimate), basis,
                        gib(extra), kMemoryUsableShare * 100.0, gib(budget.bytes), budget.bound);
        print_header();
        fmt::print("{:<14} skipped: {}\n", row.value, reason);
        std::fflush(stdout);
        skipped.push_back(row.value);
        out["rows"].push_back({{"series", series.name},
                               {"swept", series.swept},
                               {"value", row.value},
                               {"triangles_requested", triangles},
                               {"skipped", true},
                               {"reason", reason},
                               {"memory", memory}});
        write_json();
        continue;
      }

      const bool peak_reset = reset_peak_resident();
      nlohmann::json row_json;
      double bidir_speedup = 0.0;
      {
        const auto resolve_start = std::chrono::steady_clock::now();
        const fs::path path = scenes::resolve_builtin(row.scene, row.scene_params, run.scenes_dir);
        const double resolve_s = seconds_since(resolve_start);
        const auto load_start = std::chrono::steady_clock::now();
        const Scene scene = io::load_gltf(path);
        print_warnings(scene.warnings);
        const double load_s = seconds_since(load_start);
        const RenderScene prepared(scene);
        fmt::print(stderr, "{}: scene ready in {:.1f} s (generated or cached), loaded in {:.1f} s, bvh {:.1f} s, {:.0f} MiB\n",
                   row.value, resolve_s, load_s, prepared.bvh_build_seconds(),
                   static_cast<double>(prepared.rays().memory_bytes()) / kMiB);
        const StereoRig rig = row_rig(scene, run, row);
        if (!header_printed) fmt::print("rig {}\n", describe(rig));
        print_header();
        run.output_starts();
        const BenchResult r = run_bench(prepared, rig, run.config, executor);
        const uint64_t peak = peak_resident_bytes();
        memory["peak_bytes"] = peak;
        memory["peak_reset"] = peak_reset;

        nlohmann::json groups = nlohmann::json::object(), median_ms = nlohmann::json::object(),
                       speedup = nlohmann::json::object();
        // The crossover is Table 3's, over plain-raster (2-pass), whichever --baseline the table's
        // speed-ups are against.
        bidir_speedup = speedup_between(r, kReference, kBidirectional);
        for (size_t k = 0; k < r.pipelines.size(); ++k) {
          const PipelineBench& b = r.pipelines[k];
          const GroupTimes g = group_times(b);
          const std::string label = k == 0 ? fmt::format("{} ({})", row.value, scene.triangle_count()) : "";
          const std::string vertices = k == 0 ? fmt::format("{}", scene.vertex_count()) : "";
          const std::string peak_text = k == 0 ? fmt::format("{:.0f}", static_cast<double>(peak) / kMiB) : "";
          fmt::print(kComplexityHead, label, vertices, b.name, fmt::format("{:.2f}", g.rendering_ms),
                     fmt::format("{:.2f}", g.warping_ms), fmt::format("{:.2f}", g.total_ms),
                     fmt::format("{:.2f}x", b.speedup.median), peak_text);
          if (!g.other_stages.empty())
            fmt::print("{:<14} note: {} has stages of neither group ({}), {:.2f} ms, in its total only\n", "", b.name,
                       fmt::join(g.other_stages, ", "), g.other_ms);
          groups[b.name] = {{"rendering_ms", g.rendering_ms},
                            {"warping_ms", g.warping_ms},
                            {"other_ms", g.other_ms},
                            {"other_stages", g.other_stages},
                            {"total_ms", g.total_ms}};
          median_ms[b.name] = g.total_ms;
          speedup[b.name] = b.speedup.median;
        }
        std::fflush(stdout);
        row_json = {{"series", series.name},
                    {"swept", series.swept},
                    {"value", row.value},
                    {"triangles_requested", triangles},
                    {"skipped", false},
                    {"scene", scene_json(scene, row)},
                    {"scene_resolve_s", resolve_s},
                    {"scene_load_s", load_s},
                    {"rig", io::rig_to_json(rig)},
                    {"bvh", {{"build_s", prepared.bvh_build_seconds()}, {"memory_bytes", prepared.rays().memory_bytes()}}},
                    {"memory", memory},
                    {"stage_groups", groups},
                    {"median_total_ms", median_ms},
                    {"speedup_median", speedup},
                    {"bench", bench_to_json(r)}};
        peaks.push_back({triangles, peak});
      }  // the row's scene is freed here, before the next row's memory check
      measured_values.push_back(row.value);
      measured_triangles.push_back(triangles);
      bidir_speedups.push_back(bidir_speedup);
      out["rows"].push_back(row_json);
      write_json();  // after every row, so an interrupted run keeps what it measured
    }

    // The crossover of Table 3: from which triangle count on bidir-warp is faster than 2-pass, and
    // (when that differs) the rows in which it is; by the paired speed-up over plain-raster as the
    // table prints it with the default baseline, so that the two never disagree (with another
    // --baseline the table's column is over that one, and the line says so).
    const std::optional<size_t> cross = crossover_row(bidir_speedups);
    std::vector<std::string> faster;
    for (size_t k = 0; k < measured_values.size(); ++k)
      if (speedup_above_one(bidir_speedups[k])) faster.push_back(measured_values[k]);
    std::string range = measured_values.empty() ? std::string("no row measured")
                        : measured_values.size() == 1
                            ? measured_values.front()
                            : measured_values.front() + " to " + measured_values.back();
    if (!skipped.empty()) range += fmt::format("; skipped for memory: {}", fmt::join(skipped, ", "));
    std::string line;
    if (cross) {
      line = fmt::format("crossover: {}'s speed-up over {} is above 1x from {} triangles on (measured: {})",
                         kBidirectional, kReference, measured_values[*cross], range);
    } else {
      line = fmt::format("crossover: none in the measured range ({}): {}'s speed-up over {} is above 1x {}", range,
                         kBidirectional, kReference,
                         faster.empty()
                             ? std::string("in no measured row")
                             : fmt::format("at {} but not in the largest measured row", fmt::join(faster, ", ")));
    }
    if (run.config.baseline != kReference)
      line += fmt::format(" (paired per repetition; the table's speed-ups are over --baseline {})",
                          run.config.baseline);
    fmt::print("\n{}\n", line);
    out["crossover"] = {{"triangles", cross ? nlohmann::json(measured_triangles[*cross]) : nlohmann::json()},
                        {"value", cross ? nlohmann::json(measured_values[*cross]) : nlohmann::json()},
                        {"faster_rows", faster},
                        {"text", line}};
  }
  out["complete"] = true;
  write_json();
  if (!run.json_out.empty()) fmt::print("\nwrote {}\n", run.json_out);
}

}  // namespace sb::cli
