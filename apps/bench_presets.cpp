// The benchmark presets and their runner: series of side-by-side benchmarks, one table each.
#include "apps/bench_presets.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>

#include <fmt/format.h>

#include "apps/cli_common.hpp"
#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/gltf_loader.hpp"
#include "renderer/io/json_text.hpp"
#include "renderer/io/render_output.hpp"
#include "renderer/text.hpp"
#include "scenes/catalog.hpp"
#include "scenes/generators.hpp"

namespace sb::cli {

namespace {

namespace fs = std::filesystem;

// The settings of Table 5: what the thesis keeps fixed while it sweeps one value.
constexpr double kFixedDisparityPx = 15.0;
constexpr int kFixedLights = 5;
constexpr int kDragonSide = 600;

/// Varying dimensions: every built-in non-analytic scene, square images 200² to 1500² in steps of 50².
BenchPreset dimensions_preset() {
  BenchPreset p{"al-hagri-dimensions",
                "every built-in non-analytic scene at 200x200 to 1500x1500 in steps of 50, e = 15 px, "
                "5 lights (a scene with fewer keeps all of its own)",
                {}};
  for (const scenes::GeneratorInfo& g : scenes::generators()) {
    if (g.analytic || !g.builtin) continue;
    PresetSeries s{g.name + " by image size", "size", fmt::format("e = {:g} px", kFixedDisparityPx), {}};
    for (int side = 200; side <= 1500; side += 50)
      s.rows.push_back({fmt::format("{}x{}", side, side), g.name, {}, side, side, kFixedDisparityPx, kFixedLights});
    p.series.push_back(std::move(s));
  }
  return p;
}

/// Varying interaxial distance: the dragon at 600x600, e = 10 to 100 px in steps of 10.
BenchPreset interaxial_preset() {
  BenchPreset p{"al-hagri-interaxial", "dragon at 600x600, e = 10 to 100 px in steps of 10, 5 lights", {}};
  PresetSeries s{"dragon by interaxial distance", "e px", fmt::format("{}x{}", kDragonSide, kDragonSide), {}};
  for (int e = 10; e <= 100; e += 10)
    s.rows.push_back({fmt::format("{}", e), "dragon", {}, kDragonSide, kDragonSide, double(e), kFixedLights});
  p.series.push_back(std::move(s));
  return p;
}

/// Varying number of lights: the dragon at 600x600, e = 15 px, 1 to 10 lights. The dragon is
/// generated once with its ten lights and each row keeps the first N, so the rows share one mesh
/// and the five-light row is the default dragon.
BenchPreset lights_preset() {
  BenchPreset p{"al-hagri-lights",
                "dragon at 600x600, e = 15 px, 1 to 10 lights (the dragon generated once with lights=10, "
                "the first N kept)",
                {}};
  PresetSeries s{"dragon by number of lights", "lights",
                 fmt::format("{}x{}, e = {:g} px, dragon with lights=10, first N kept", kDragonSide, kDragonSide,
                             kFixedDisparityPx),
                 {}};
  for (int n = 1; n <= 10; ++n)
    s.rows.push_back({fmt::format("{}", n), "dragon", {{"lights", 10.0}}, kDragonSide, kDragonSide,
                      kFixedDisparityPx, n});
  p.series.push_back(std::move(s));
  return p;
}

/// The scene of the rows being measured, kept while consecutive rows share it: loading and the
/// BVH build happen once per scene and light count, outside the timings.
class RowScene {
 public:
  /// The prepared scene for `path` with its first `lights` lights (all of them if it has fewer).
  const RenderScene& get(const fs::path& path, int lights) {
    if (!file_ || path != path_) {
      prepared_.reset();
      used_.reset();
      file_.reset();
      file_ = std::make_unique<Scene>(io::load_gltf(path));
      print_warnings(file_->warnings);
      path_ = path;
    }
    const size_t keep = std::min(static_cast<size_t>(std::max(lights, 0)), file_->lights.size());
    if (!prepared_ || used_->lights.size() != keep) {
      prepared_.reset();
      used_ = std::make_unique<Scene>(*file_);
      used_->lights.resize(keep);
      prepared_ = std::make_unique<RenderScene>(*used_);
      fmt::print(stderr, "prepared {} ({} triangles, {}): bvh build {:.1f} ms, {:.1f} MiB\n", used_->name,
                 used_->triangle_count(), describe_lights(keep, file_->lights.size()), prepared_->bvh_build_seconds() * 1e3,
                 prepared_->rays().memory_bytes() / 1048576.0);
    }
    return *prepared_;
  }
  [[nodiscard]] size_t lights_in_file() const { return file_ ? file_->lights.size() : 0; }

 private:
  fs::path path_;
  std::unique_ptr<Scene> file_;  ///< as loaded
  std::unique_ptr<Scene> used_;  ///< with the lights the rows use; prepared_ points into it
  std::unique_ptr<RenderScene> prepared_;
};

/// Whether every row of the series asks for the same number of lights.
bool lights_fixed(const PresetSeries& series) {
  return std::all_of(series.rows.begin(), series.rows.end(),
                     [&series](const PresetRow& r) { return r.lights == series.rows.front().lights; });
}

/// Column widths of a series table.
struct TableLayout {
  size_t first = 8;
  std::vector<size_t> time;  ///< per pipeline
  static constexpr size_t speedup = 9;
};

TableLayout table_layout(const PresetSeries& series, const std::vector<std::string>& pipelines) {
  TableLayout t;
  t.first = std::max<size_t>(8, series.swept.size());
  for (const PresetRow& r : series.rows) t.first = std::max(t.first, r.value.size());
  for (const std::string& p : pipelines) t.time.push_back(std::max<size_t>(10, p.size() + 3));
  return t;
}

void print_table_header(const TableLayout& t, const std::string& swept, const std::vector<std::string>& pipelines) {
  std::string line = fmt::format("{:<{}}", swept, t.first);
  for (size_t i = 0; i < pipelines.size(); ++i)
    line += fmt::format("  {:>{}} {:>{}}", pipelines[i] + " ms", t.time[i], "speed-up", TableLayout::speedup);
  fmt::print("{}\n", line);
}

void print_table_row(const TableLayout& t, const std::string& value, const BenchResult& r) {
  std::string line = fmt::format("{:<{}}", value, t.first);
  for (size_t i = 0; i < r.pipelines.size(); ++i) {
    const PipelineBench& b = r.pipelines[i];
    line += fmt::format("  {:>{}.2f} {:>{}}", summarize(b.total_seconds).median * 1e3, t.time[i],
                        fmt::format("{:.2f}x", b.speedup.median), TableLayout::speedup);
  }
  fmt::print("{}\n", line);
  std::fflush(stdout);  // a row at a time, for runs that take hours
}

}  // namespace

const std::vector<BenchPreset>& bench_presets() {
  static const std::vector<BenchPreset> list = {dimensions_preset(), interaxial_preset(), lights_preset(),
                                                kim_focal_preset(), kim_complexity_preset()};
  return list;
}

const BenchPreset& find_bench_preset(const std::string& name) {
  for (const BenchPreset& p : bench_presets())
    if (p.name == name) return p;
  std::string names;
  for (const BenchPreset& p : bench_presets()) names += (names.empty() ? "" : ", ") + p.name;
  throw InputError(fmt::format("unknown preset '{}' (presets: {})", name, names));
}

const std::vector<std::string>& preset_default_pipelines() {
  static const std::vector<std::string> names = {"plain-rt",    "ideal-copy", "rt-adelson",
                                                 "rt-es-isler", "rt-buffer",  "rt-atomic"};
  return names;
}

const std::vector<std::string>& preset_pipelines(const BenchPreset& preset) {
  return preset.pipelines.empty() ? preset_default_pipelines() : preset.pipelines;
}

std::string presets_help() {
  std::string text =
      "Presets (--preset NAME) reproduce the benchmark tables of Al-Hagri's thesis (Table 5) and of\n"
      "Kim's paper (Tables 2 and 3). Every number is measured in this run: in each repetition a row's\n"
      "pipelines run in turn, times are medians over the repetitions and speed-ups are paired per\n"
      "repetition against the baseline; --json writes every row (rewritten after each; a file, not\n"
      "'-'). In Al-Hagri's presets e is the disparity at infinity in pixels (--max-disparity); Kim's\n"
      "tables give it in millimetres (64 mm; the presets set it). --repetitions, --warmup, --threads,\n"
      "--option and --vfov apply to every row, --convergence where the preset leaves it open;\n"
      "--preset-rows K runs the first K rows of each series (a quick version).\n";
  const auto wrap = [&text](const std::string& words_text) {
    std::string line = "     ";
    std::stringstream words(words_text);
    for (std::string w; words >> w;) {
      if (line.size() + 1 + w.size() > 96) {
        text += line + "\n";
        line = "     ";
      }
      line += " " + w;
    }
    text += line + "\n";
  };
  for (const BenchPreset& p : bench_presets()) {
    size_t rows = 0;
    for (const PresetSeries& s : p.series) rows += s.rows.size();
    text += fmt::format("  {} ({} series, {} rows):\n", p.name, p.series.size(), rows);
    std::string pipelines;
    for (const std::string& name : preset_pipelines(p)) pipelines += (pipelines.empty() ? "" : ",") + name;
    std::string fixed;
    for (const std::string& o : p.fixed_options) fixed += (fixed.empty() ? "" : " ") + o;
    const bool stop = !p.summary.empty() && p.summary.back() == '.';
    wrap(fmt::format("{}{} Pipelines {}, baseline {}. Sets {} itself{}.", p.summary, stop ? "" : ".", pipelines,
                     p.baseline, fixed,
                     p.resolution_open ? "; --resolution replaces the image size" : ""));
  }
  return text;
}

std::string preset_overrides(const PresetRun& run) {
  const RigOverrides& o = run.overrides;
  std::vector<std::string> parts;
  if (o.width && o.height) parts.push_back(fmt::format("image size {}x{}", *o.width, *o.height));
  if (o.convergence) parts.push_back(fmt::format("convergence {:g} m", *o.convergence));
  if (o.vfov) {
    const double degrees = radians_to_degrees(*o.vfov);
    parts.push_back(fmt::format("vertical field of view {:g} degree{}", degrees, degrees == 1.0 ? "" : "s"));
  }
  return fmt::format("{}", fmt::join(parts, ", "));
}

void print_preset_summary(const PresetRun& run) {
  fmt::print("preset {}: {}\n", run.preset->name, run.preset->summary);
  if (const std::string given = preset_overrides(run); !given.empty())
    fmt::print("as run, replacing the preset's: {}\n", given);
}

nlohmann::json preset_json(const PresetRun& run, const Executor& executor) {
  return {{"kind", "stereobench.bench_preset"},
          {"schema_version", 1},
          {"preset", run.preset->name},
          {"summary", run.preset->summary},
          {"overrides", preset_overrides(run)},
          {"pipelines", run.config.pipelines},
          {"baseline", run.config.baseline},
          {"warmup", run.config.warmup},
          {"repetitions", run.config.repetitions},
          {"options", run.config.options},
          {"threads", executor.threads()},
          {"rows_per_series", run.rows_per_series},
          {"complete", false},
          {"rows", nlohmann::json::array()},
          {"versions", io::versions_json()}};
}

size_t rows_to_run(const PresetSeries& series, int rows_per_series) {
  return rows_per_series > 0 ? std::min(series.rows.size(), static_cast<size_t>(rows_per_series)) : series.rows.size();
}

void check_series_rigs(const PresetRun& run, const PresetSeries& series, size_t rows, const fs::path& loaded,
                       const Scene& scene, RowRig rig_of) {
  for (size_t i = 0; i < rows; ++i) {
    const PresetRow& row = series.rows[i];
    if (scenes::builtin_path(row.scene, row.scene_params, run.scenes_dir) != loaded) continue;
    // The frames' memory too: a series whose largest row cannot fit is refused before its first
    // row renders, naming that row.
    const auto where = [&](const char* what) {
      return fmt::format("{}, row {} = {}: {} (no row of the series has run)", series.name, series.swept, row.value, what);
    };
    try {
      check_bench(rig_of(scene, run, row), run.config);
    } catch (const InputError& e) {
      throw InputError(where(e.what()));
    } catch (const ResourceError& e) {
      throw ResourceError(where(e.what()));
    }
  }
}

namespace {

/// An Al-Hagri row's rig: its image size and disparity, the rest as the command line left it.
StereoRig speed_row_rig(const Scene& scene, const PresetRun& run, const PresetRow& row) {
  RigOverrides overrides = run.overrides;
  overrides.width = row.width;
  overrides.height = row.height;
  overrides.max_disparity_px = row.max_disparity_px;
  return resolve_rig(scene, overrides);
}

}  // namespace

void PresetRun::output_starts() const {
  if (json_cleared_) return;
  remove_earlier_output(json_out, "--json");
  json_cleared_ = true;
}

void run_bench_preset(const PresetRun& run, const Executor& executor) {
  const BenchPreset& preset = *run.preset;
  run.config.validate();  // before any scene is generated or loaded
  if (preset.kind == PresetKind::quality) {
    run_kim_focal(run, executor);
    return;
  }
  if (preset.kind == PresetKind::complexity) {
    run_kim_complexity(run, executor);
    return;
  }
  size_t total_rows = 0;
  for (const PresetSeries& s : preset.series) total_rows += rows_to_run(s, run.rows_per_series);

  std::string pipelines;
  for (const std::string& p : run.config.pipelines) pipelines += (pipelines.empty() ? "" : ", ") + p;
  print_preset_summary(run);
  fmt::print("{} series, {}; {}; baseline {}; {}, {} warm-up + {} per row\n", preset.series.size(),
             counted(static_cast<long long>(total_rows), "row"), pipelines, run.config.baseline,
             counted(executor.threads(), "thread"), run.config.warmup, counted(run.config.repetitions, "repetition"));
  if (const std::string given = given_options(run.config); !given.empty()) fmt::print("options: {}\n", given);
  fmt::print("speed-up = median over repetitions of {}'s total / the pipeline's total, paired per repetition\n",
             run.config.baseline);

  nlohmann::json out = preset_json(run, executor);
  const auto write_json = [&] {
    run.output_starts();
    if (!run.json_out.empty()) write_option_file("--json", run.json_out, io::json_text(out, 2) + "\n");
  };

  RowScene current;
  for (const PresetSeries& series : preset.series) {
    const size_t n = rows_to_run(series, run.rows_per_series);
    if (n == 0) continue;
    const TableLayout layout = table_layout(series, run.config.pipelines);
    bool header_printed = false;
    for (size_t i = 0; i < n; ++i) {
      const PresetRow& row = series.rows[i];
      const fs::path path = scenes::resolve_builtin(row.scene, row.scene_params, run.scenes_dir);
      const RenderScene& prepared = current.get(path, row.lights);
      const Scene& scene = prepared.scene();
      const size_t lights = scene.lights.size();
      // The series' rigs are checked before its header is printed: a refusal follows no empty table.
      if (i == 0) check_series_rigs(run, series, n, path, scene, speed_row_rig);
      if (!header_printed) {
        fmt::print("\n{}: {} ({} triangles), {}{}\n", series.name, scene.name, scene.triangle_count(), series.fixed,
                   lights_fixed(series) ? fmt::format(", {} light{}", lights, lights == 1 ? "" : "s") : "");
        if (lights < static_cast<size_t>(row.lights))
          fmt::print("note: {} has only {} light{}, all kept (the preset asks for {})\n", scene.name, lights,
                     lights == 1 ? "" : "s", row.lights);
        print_table_header(layout, series.swept, run.config.pipelines);
        header_printed = true;
      }
      const StereoRig rig = speed_row_rig(scene, run, row);
      run.output_starts();
      const BenchResult r = run_bench(prepared, rig, run.config, executor);
      print_table_row(layout, row.value, r);

      nlohmann::json median_ms = nlohmann::json::object(), speedup = nlohmann::json::object();
      for (const PipelineBench& b : r.pipelines) {
        median_ms[b.name] = summarize(b.total_seconds).median * 1e3;
        speedup[b.name] = b.speedup.median;
      }
      out["rows"].push_back({{"series", series.name},
                             {"swept", series.swept},
                             {"value", row.value},
                             {"scene",
                              {{"name", scene.name},
                               {"path", scene.path},
                               {"params", row.scene_params.empty() ? nlohmann::json::object() : nlohmann::json(row.scene_params)},
                               {"triangles", scene.triangle_count()},
                               {"lights", lights},
                               {"lights_requested", row.lights},
                               {"lights_in_file", current.lights_in_file()}}},
                             {"rig", io::rig_to_json(rig)},
                             {"bvh", {{"build_s", prepared.bvh_build_seconds()},
                                      {"memory_bytes", prepared.rays().memory_bytes()}}},
                             {"median_total_ms", median_ms},
                             {"speedup_median", speedup},
                             {"bench", bench_to_json(r)}});
      write_json();  // after every row, so an interrupted run keeps what it measured
    }
  }
  out["complete"] = true;
  write_json();
  if (!run.json_out.empty()) fmt::print("\nwrote {}\n", run.json_out);
}

}  // namespace sb::cli
