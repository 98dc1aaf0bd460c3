// `stereobench bench`: time pipelines side by side on one scene and rig; medians, min/max per stage,
// ray throughput and speed-ups against a baseline from the same run. With --preset, a series of
// such runs (apps/bench_presets.hpp).
#include <sys/resource.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <optional>

#include <fmt/format.h>

#include "apps/bench_presets.hpp"
#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/json_text.hpp"
#include "renderer/io/render_output.hpp"
#include "renderer/text.hpp"
#include "scenes/catalog.hpp"
#include "validation/benchmark.hpp"

namespace sb::cli {

namespace {

struct BenchArgs {
  std::string scene = "bistro";
  std::vector<std::string> pipelines;
  std::string baseline = "plain-raster";
  int repetitions = 5;
  int warmup = 1;
  int threads = 0;
  std::vector<std::string> options;
  std::string json_out;
  std::string scenes_dir;
  std::optional<int> lights;
  std::string preset;
  int preset_rows = 0;
  RigCli rig;
};

double peak_rss_mib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024.0;
}

/// Pipelines, baseline, repetitions and options from the command line, checked, and --json's
/// folder made: all before any scene is loaded.
BenchConfig bench_config(const BenchArgs& a, const std::vector<std::string>& default_pipelines) {
  BenchConfig config;
  config.pipelines = expand_all_pipelines(split_list(a.pipelines, "--pipelines"), "--pipelines");
  if (config.pipelines.empty()) config.pipelines = default_pipelines;
  // The baseline is timed with the others; listed under another spelling of the same variant
  // (its options in another order), it is that entry.
  const std::vector<PipelineEntry> listed = parse_pipeline_entries(config.pipelines, "--pipelines");
  const PipelineEntry base = [&] {
    try {
      PipelineEntry entry = parse_pipeline_entry(a.baseline);
      (void)entry.options();  // the options a variant fixes, checked here to be named as the baseline's
      return entry;
    } catch (const InputError& e) {
      throw InputError(fmt::format("--baseline: {}", e.what()));
    }
  }();
  const std::optional<std::string> same = find_same_variant(listed, base);
  config.baseline = same.value_or(a.baseline);
  if (!same) config.pipelines.insert(config.pipelines.begin(), config.baseline);
  config.repetitions = a.repetitions;
  config.warmup = a.warmup;
  for (const auto& [key, value] : parse_key_values(a.options, "--option")) {
    const size_t dot = key.find('.');
    if (dot == std::string::npos || dot == 0 || dot + 1 == key.size())
      throw InputError(fmt::format("--option {}={}: name it PIPELINE.OPTION=VALUE, e.g. plain-raster.tile=32", key, value));
    config.options[key.substr(0, dot)][key.substr(dot + 1)] = value;
  }
  config.validate();
  prepare_output_file_folder(a.json_out, "--json");
  return config;
}

void run_preset_command(const BenchArgs& a) {
  PresetRun run;
  run.preset = &find_bench_preset(a.preset);
  if (a.preset_rows < 0)
    throw InputError(fmt::format("--preset-rows {} must not be negative (0 = every row)", a.preset_rows));
  std::error_code ec;
  const bool not_a_file =
      std::filesystem::exists(a.json_out, ec) && !std::filesystem::is_regular_file(a.json_out, ec);
  if (a.json_out == "-" || not_a_file)
    throw InputError(fmt::format("--json {} with --preset: the file is rewritten after every row, which {} cannot be; "
                                 "give a file name",
                                 a.json_out, a.json_out == "-" ? "standard output" : "a device or pipe"));
  run.overrides = a.rig.overrides();
  run.config = bench_config(a, preset_pipelines(*run.preset));
  // The JSON is rewritten after every row: it must not be a scene file a row reads (or its stamp,
  // whose loss has the scene generated again).
  for (const PresetSeries& series : run.preset->series)
    for (size_t i = 0; i < rows_to_run(series, a.preset_rows); ++i) {
      const PresetRow& row = series.rows[i];
      const std::filesystem::path path = scenes::builtin_path(row.scene, row.scene_params, a.scenes_dir);
      const std::string file = path.string(), stamp = scenes::stamp_path(path).string();
      refuse_overwriting({{"a scene file of the preset", &file}, {"a scene file's stamp", &stamp}},
                         {{"--json", &a.json_out}});
    }
  // An earlier --json file is removed as the first row's timing starts or the JSON is first written
  // (PresetRun::output_starts).
  run.rows_per_series = a.preset_rows;
  run.scenes_dir = a.scenes_dir;
  run.json_out = a.json_out;
  const Executor executor(checked_threads(a.threads));
  run_bench_preset(run, executor);
}

void run_bench_command(const BenchArgs& a) {
  // With --json - the JSON goes to standard output, and the tables to standard error.
  std::FILE* const out = a.json_out == "-" ? stderr : stdout;
  const RigOverrides overrides = a.rig.overrides();
  const BenchConfig config = bench_config(a, pipeline_names());
  const Executor executor(checked_threads(a.threads));
  const scenes::LoadedScene loaded = scenes::load_scene(a.scene, a.scenes_dir, a.lights);
  const std::string scene_file = loaded.file.string(), stamp = scenes::stamp_path(loaded.file).string();
  refuse_overwriting({{"the scene file", &scene_file}, {"the scene file's stamp", &stamp}}, {{"--json", &a.json_out}});
  const Scene& scene = loaded.scene;
  const size_t lights_in_file = loaded.lights_in_file;
  const StereoRig rig = resolve_rig(scene, overrides);
  check_bench(rig, config);
  // From here the run's own --json, or none: an earlier one is not left to be read as this run's.
  remove_earlier_output(a.json_out, "--json");
  const RenderScene prepared(scene);
  fmt::print(out, "scene {} ({} triangles, {}), {}, {}, {} warm-up + {}\n", scene.name, scene.triangle_count(),
             describe_lights(scene.lights.size(), lights_in_file), describe(rig), counted(executor.threads(), "thread"),
             a.warmup, counted(a.repetitions, "repetition"));
  if (const std::string given = given_options(config); !given.empty()) fmt::print(out, "options: {}\n", given);
  fmt::print(out, "bvh build {:.1f} ms, {:.1f} MiB\n", prepared.bvh_build_seconds() * 1e3,
             prepared.rays().memory_bytes() / 1048576.0);
  const BenchResult r = run_bench(prepared, rig, config, executor,
                                  [](const std::string& line) { fmt::print(stderr, "  {}\n", line); });
  warn_scene_far_from_origin(prepared);
  warn_geometry_before_near_plane(prepared, rig, executor);

  std::vector<std::string> names;
  for (const PipelineBench& b : r.pipelines) names.push_back(b.name);
  const size_t name_w = pipeline_column(names);
  fmt::print(out, "\n{:<{}} {:>11} {:>11} {:>11} {:>9} {:>13} {:>13}\n", "pipeline", name_w, "median ms", "min ms", "max ms",
             "speed-up", "Mrays/s", "Mprimary/s");
  for (const PipelineBench& b : r.pipelines) {
    const Summary t = summarize(b.total_seconds);
    auto counter = [&](const char* n) { auto it = b.counters.find(n); return it == b.counters.end() ? 0.0 : double(it->second); };
    // Every ray the pipeline asked Embree for: primary, shadow, the length-restricted validation
    // rays of pixel reprojection and the source-frustum rays of the grid warp.
    const double primary = counter("primary_rays");
    const double all = primary + counter("shadow_rays") + counter("restricted_rays") + counter("frustum_rays");
    fmt::print(out, "{:<{}} {:>11.2f} {:>11.2f} {:>11.2f} {:>8.2f}x {:>13.2f} {:>13.2f}\n", b.name, name_w, t.median * 1e3,
               t.min * 1e3, t.max * 1e3, b.speedup.median, all / t.median * 1e-6, primary / t.median * 1e-6);
  }
  fmt::print(out, "\nper-stage medians (min..max), ms\n");
  for (const PipelineBench& b : r.pipelines) {
    fmt::print(out, "{}\n", b.name);
    for (const std::string& st : b.stage_order) {
      const Summary s = summarize(b.stage_seconds.at(st));
      fmt::print(out, "  {:<22} {:>10.2f} ({:.2f}..{:.2f})\n", st, s.median * 1e3, s.min * 1e3, s.max * 1e3);
    }
  }
  fmt::print(out, "\nper-eye medians, ms: the stages of each eye, and those that serve both\n");
  fmt::print(out, "{:<{}} {:>11} {:>11} {:>11}  {}\n", "pipeline", name_w, "left eye", "right eye", "both", "right / left");
  for (const PipelineBench& b : r.pipelines) {
    const std::optional<Summary> share = b.right_over_left();
    const std::string ratio =
        share ? fmt::format("{:.1f} % ({:.1f}..{:.1f})", share->median * 100.0, share->min * 100.0, share->max * 100.0)
              : "-";
    const std::string shared = b.shared_stages.empty() ? "" : fmt::format("; both: {}", fmt::join(b.shared_stages, ", "));
    fmt::print(out, "{:<{}} {:>11.2f} {:>11.2f} {:>11.2f}  {}{}\n", b.name, name_w, summarize(b.left_seconds).median * 1e3,
               summarize(b.right_seconds).median * 1e3, summarize(b.both_seconds).median * 1e3, ratio, shared);
  }
  fmt::print(out, "\nspeed-up = median over repetitions of {}'s total / the pipeline's total, paired per repetition\n",
             r.baseline);
  fmt::print(out, "right / left = median (min..max) over repetitions of the right eye's stages / the left eye's, paired per "
             "repetition\n");
  fmt::print(out, "Mrays/s = the rays of one render (primary, shadow, restricted, frustum) / the median total; Mprimary/s "
             "the primary rays alone\n");
  fmt::print(out, "peak resident memory {:.0f} MiB\n", peak_rss_mib());
  if (!a.json_out.empty()) {
    nlohmann::json j = bench_to_json(r);
    j["scene"] = {{"name", scene.name},
                  {"path", scene.path},
                  {"triangles", scene.triangle_count()},
                  {"lights", scene.lights.size()},
                  {"lights_in_file", lights_in_file}};
    j["rig"] = io::rig_to_json(rig);
    j["bvh"] = {{"build_s", prepared.bvh_build_seconds()}, {"memory_bytes", prepared.rays().memory_bytes()}};
    j["peak_rss_mib"] = peak_rss_mib();
    j["versions"] = io::versions_json();
    if (a.json_out == "-") {
      print_to_stdout(io::json_text(j, 2));
    } else {
      write_option_file("--json", a.json_out, io::json_text(j, 2) + "\n");
      fmt::print(out, "wrote {}\n", a.json_out);
    }
  }
}

}  // namespace

void register_bench_command(CLI::App& root) {
  auto a = std::make_shared<BenchArgs>();
  CLI::App* b = root.add_subcommand("bench", "Time pipelines side by side: medians per stage, throughput, speed-ups, and the right eye's time beside the left eye's");
  b->add_option("--scene,-s", a->scene, "Scene file (.gltf/.glb) or built-in scene name")->capture_default_str();
  b->add_option("--pipelines,-p", a->pipelines,
                "Pipelines to time, comma-separated, 'all' for every registered one (default: all; with --preset, "
                "the preset's); NAME:KEY=VALUE[:KEY=VALUE...] times a variant with those options, beside NAME "
                "itself where that is listed too (e.g. bidir-warp,bidir-warp:occlusion=ztest)");
  CLI::Option* baseline = b->add_option("--baseline,-b", a->baseline,
                                        "Pipeline the speed-ups are measured against (with --preset: the preset's)")
                              ->capture_default_str();
  b->add_option("--repetitions,-n", a->repetitions, "Timed repetitions per pipeline")->capture_default_str();
  b->add_option("--warmup,-w", a->warmup, "Untimed warm-up runs per pipeline")->capture_default_str();
  b->add_option("--threads,-t", a->threads, "Worker threads (0 = all cores)")->capture_default_str();
  b->add_option("--option,-o", a->options,
                "Pipeline option PIPELINE.NAME=VALUE (for PIPELINE and its variants, under a variant's own)");
  b->add_option("--json", a->json_out,
                "Also write the results (with raw samples) to this JSON file ('-': standard output, the tables then "
                "go to standard error); an earlier file there is removed when the timing starts, so a run that stops "
                "leaves none (a preset's is rewritten after every row, \"complete\": false until the last)");
  add_scenes_dir_option(*b, a->scenes_dir);
  add_lights_option(*b, a->lights);
  CLI::Option* preset =
      b->add_option("--preset", a->preset, "Run a benchmark table of Al-Hagri's thesis or Kim's paper (see below)");
  CLI::Option* preset_rows =
      b->add_option("--preset-rows", a->preset_rows, "With --preset: only the first K rows of each series (0 = all)")
          ->capture_default_str();
  a->rig.add_to(*b);
  b->footer(presets_help());
  b->callback([a, b, baseline, preset, preset_rows] {
    if (preset->count() == 0) {
      if (preset_rows->count() > 0) throw InputError("--preset-rows needs --preset NAME");
      run_bench_command(*a);
      return;
    }
    // A preset sets the scene, rig and light count of each row itself, as far as it says.
    const BenchPreset& chosen = find_bench_preset(a->preset);
    std::string fixed;
    for (const std::string& o : chosen.fixed_options) fixed += (fixed.empty() ? "" : ", ") + o;
    for (const std::string& name : chosen.fixed_options)
      if (b->count(name) > 0)
        throw InputError(fmt::format("--preset {} sets {} of every row itself; drop {} (or run without --preset)",
                                     a->preset, fixed, name));
    BenchArgs args = *a;
    if (baseline->count() == 0) args.baseline = chosen.baseline;
    run_preset_command(args);
  });
}

}  // namespace sb::cli
