// `stereobench validate`: render the right eye with each chosen pipeline and measure it against a
// ground-truth right eye (full ray tracing, Blender Cycles or POV-Ray): metrics, hole statistics,
// images and a result record per pipeline, and a table on the terminal.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/json_text.hpp"
#include "scenes/catalog.hpp"
#include "validation/truth_cache.hpp"
#include "validation/validation_images.hpp"

namespace sb::cli {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct ValidateArgs {
  std::string scene = "spheres";
  std::vector<std::string> pipelines{"all"};
  std::vector<std::string> options;
  std::string truth = "full";
  std::string scenes_dir;
  std::string out = "out/validate";
  std::string cache = "out/truth-cache";
  bool no_cache = false;
  int threads = 0;
  int error_threshold = 2;
  std::optional<int> lights;
  RigCli rig;
};

/// The pipelines named (comma-separated or repeated), "all" for every registered one, variants as
/// NAME:KEY=VALUE[:KEY=VALUE...]; a pipeline named twice (also beside "all") is refused, as bench,
/// path and sweeps refuse it.
std::vector<PipelineEntry> chosen_pipelines(const std::vector<std::string>& names) {
  return parse_pipeline_entries(expand_all_pipelines(split_list(names, "--pipelines"), "--pipelines"), "--pipelines");
}

/// An MSE for the table: three decimals, or two significant digits below 0.001, so that a
/// non-zero MSE (its PSNR finite) never reads 0.000.
std::string mse_text(double v) { return v > 0.0 && v < 0.001 ? fmt::format("{:.1e}", v) : table_number(v, 3); }

/// The records an earlier summary lists: none when there is no summary or it cannot be read (a
/// damaged summary is replaced; its records stay as they are).
json earlier_records(const fs::path& summary) {
  try {
    if (!fs::is_regular_file(summary)) return json::array();
    const json earlier = json::parse(io::read_file(summary));
    if (earlier.is_object() && earlier.contains("records") && earlier["records"].is_array()) return earlier["records"];
  } catch (const std::exception&) {
  }
  return json::array();
}

/// The records of `scene_stem` (scene and truth) among `earlier` (its earlier summary's) that this
/// run does not write, retired from `set` with the images of their own: this run replaces the
/// truth and disocclusion images they point to, so they would describe another truth (another rig,
/// another scene file of that name). The images of the records it writes again are retired too,
/// those it writes again kept by the set: an image an option asked for last time (partials,
/// grid_overlay) would be left beside the new record as if it showed this run. The names of the
/// pipelines whose records are retired.
std::vector<std::string> retire_earlier_records(io::StagedFiles& set, const fs::path& out, const json& earlier,
                                                const std::string& scene_stem, const std::vector<std::string>& names) {
  std::vector<std::string> retired;
  for (const json& r : earlier) {
    if (!r.is_object() || !r.contains("pipeline") || !r["pipeline"].is_string()) continue;
    const std::string pipeline = r["pipeline"].get<std::string>();
    const std::string own = fmt::format("{}_{}", scene_stem, entry_file_stem(pipeline));
    if (r.contains("images") && r["images"].is_object())
      for (const auto& [key, file] : r["images"].items())
        if (file.is_string()) {
          // Its own images only (the shared truth images are this run's): named after the record.
          const std::string name = fs::path(file.get<std::string>()).filename().string();
          if (name.rfind(own + "_", 0) == 0) set.retire(out / name);
        }
    if (std::find(names.begin(), names.end(), pipeline) != names.end()) continue;
    set.retire(out / (own + ".json"));
    retired.push_back(pipeline);
  }
  return retired;
}

/// Hex digits of the truth key that name a work folder after its scene and provider.
constexpr size_t work_key_digits = 12;

std::string work_folder_name(const std::string& scene_stem, const std::string& truth_key) {
  return fmt::format("{}_{}", scene_stem, truth_key.substr(0, work_key_digits));
}

/// Removes the work folders of `scene_stem` (`<scene_stem>_<key digits>`) other than `kept` whose
/// path the truth command of one of `earlier` (the records this run replaced) names: no record
/// names them any more. A folder no such record names (one another run into this --out is
/// rendering in) is left; one that cannot be removed is left with a warning.
void remove_earlier_work_folders(const fs::path& work, const std::string& scene_stem, const std::string& kept,
                                 const json& earlier) {
  std::error_code ec;
  if (earlier.empty() || !fs::is_directory(work, ec)) return;
  const std::string prefix = scene_stem + "_";
  const auto named = [&](const std::string& name) {
    return std::any_of(earlier.begin(), earlier.end(), [&](const json& r) {
      const json* truth = r.is_object() && r.contains("truth") && r["truth"].is_object() ? &r["truth"] : nullptr;
      return truth != nullptr && truth->contains("command") && (*truth)["command"].is_string() &&
             (*truth)["command"].get<std::string>().find("/" + name) != std::string::npos;
    });
  };
  std::vector<fs::path> replaced;
  for (const fs::directory_entry& entry : fs::directory_iterator(work, ec)) {
    const std::string name = entry.path().filename().string();
    if (name != kept && name.size() == prefix.size() + work_key_digits && name.rfind(prefix, 0) == 0 &&
        entry.is_directory(ec) && named(name))
      replaced.push_back(entry.path());
  }
  for (const fs::path& folder : replaced) {
    fs::remove_all(folder, ec);
    if (ec)
      print_warning(fmt::format("could not remove {}, the work folder of a truth this run replaced: {}",
                                folder.string(), ec.message()));
  }
}

void run_validate(const ValidateArgs& a) {
  const RigOverrides overrides = a.rig.overrides();
  const std::vector<PipelineEntry> chosen = chosen_pipelines(a.pipelines);
  const std::map<std::string, std::string> given = parse_key_values(a.options, "--option");
  // Checked before anything renders: an option applies to every chosen pipeline, under the options
  // a variant fixes.
  std::vector<PipelineOptions> options;
  for (const PipelineEntry& e : chosen) options.push_back(e.options(given));
  if (a.error_threshold < 0 || a.error_threshold > 255)
    throw InputError(fmt::format("--error-threshold {} is outside 0..255 (8-bit codes)", a.error_threshold));
  const std::unique_ptr<validation::TruthProvider> provider = validation::make_truth_provider(a.truth);
  if (auto why = provider->unavailable_reason())
    throw ToolError(fmt::format("--truth {}: the provider is unavailable: {}", a.truth, *why));
  const Executor executor(checked_threads(a.threads));
  check_output_folder(a.out, "--out");
  const scenes::LoadedScene loaded = scenes::load_scene(a.scene, a.scenes_dir, a.lights);
  const Scene& scene = loaded.scene;
  const size_t lights_in_file = loaded.lights_in_file;
  const StereoRig rig = resolve_rig(scene, overrides);
  // What a pipeline cannot do with this rig stops the run before any pipeline renders.
  for (size_t i = 0; i < chosen.size(); ++i) chosen[i].check_rig(options[i], rig);
  // What the ground truth's tool cannot render exactly is refused now too (resolve_truth checks again).
  provider->check_scene(scene, loaded.file);
  // Made once the input is known to be good, and removed again if the run stops before writing
  // into it: a refused or failed run leaves no empty folder behind.
  in_output_folder(a.out, "--out", [&] {
    const std::string scene_stem = fmt::format("{}_{}", scene.file_stem(), provider->name());
    // Before the truth renders (with Blender, hours): every file this run writes or retires is
    // named <scene_stem>_..., <stem>_truth-... or <stem>_disocclusions-....
    refuse_replacing_inputs(loaded.file, scene, a.out,
                            {scene_stem + "_", scene.file_stem() + "_truth-", scene.file_stem() + "_disocclusions-"},
                            "validation");
    const RenderScene prepared(scene);
    fmt::print("validating {} pipeline(s) on {} ({} triangles, {}), {}, {} threads, truth: {}\n", chosen.size(),
               scene.name, scene.triangle_count(), describe_lights(scene.lights.size(), lights_in_file),
               describe(rig), executor.threads(), provider->name());

    const fs::path out = a.out;
    const fs::path summary = out / fmt::format("{}_summary.json", scene_stem);
    const auto record_file = [&](const std::string& pipeline) {
      return out / fmt::format("{}_{}.json", scene_stem, entry_file_stem(pipeline));
    };
    const std::optional<validation::TruthCache> cache =
        a.no_cache || a.cache.empty() ? std::nullopt
                                      : std::optional<validation::TruthCache>(validation::TruthCache(a.cache));
    // A work folder per scene, provider and truth (its cache key: scene contents, rig, provider): the
    // command a record gives to render its truth again runs there. Another scene or rig validated
    // into the same --out works in a folder of its own, so a run that fails after its truth rendered
    // leaves the earlier records' commands rendering what they describe.
    // A truth from the cache was rendered in another run's work folder, which may be gone or hold
    // another render by now: the export and script are made ready in this one's, and the record gives
    // the command that renders the truth again there.
    // The built-in provider writes no files there: its scene is not hashed for a name it never uses.
    const std::string work_name =
        provider->name() == "full"
            ? scene_stem
            : work_folder_name(scene_stem,
                               validation::truth_key(*provider,
                                                     {prepared, loaded.file, rig, {}, executor.threads(), true}));
    const validation::ValidationTarget target =
        validation::prepare_target(prepared, loaded.file, rig, *provider, cache ? &*cache : nullptr,
                                   out / "work" / work_name, executor, /*prepare_on_cache_hit=*/true);
    fmt::print("truth: {} ({}), {}{:.2f} s; true disocclusions {:.3f} % of the image\n", provider->name(),
               target.truth.render.tool_version, target.truth.cached ? "from the cache, rendered in " : "",
               target.truth.render.seconds,
               100.0 * double(target.disocclusions.count()) / double(target.truth_srgb8.pixel_count()));
    print_warnings(validation::truth_warnings(target.truth.render));
    warn_scene_far_from_origin(prepared);
    warn_geometry_before_near_plane(prepared, rig, executor);

    // Every file is made whole under a temporary name, and all are renamed into place at the end,
    // the summary last: a run that stops on the way (an image it cannot write, a full disk) leaves an
    // earlier run's summary, records and images as they were.
    io::StagedFiles set;
    // The earlier summary's records: those this run does not write are retired with it, and the work
    // folders they named go once this run's set is in place.
    const json earlier = earlier_records(summary);
    std::vector<std::string> retired;  // pipelines of earlier records this run removes
    validation::ImageFileOptions image_options;
    image_options.staged = &set;
    {
      const json shared_images =
          validation::write_target_images(out, scene.file_stem(), target, executor, image_options);

      const validation::MetricOptions metric_options{a.error_threshold};
      json records = json::array();
      std::vector<std::string> left_lines;  // pipelines whose left eye is in part synthesized
      std::vector<std::string> names;
      for (const PipelineEntry& e : chosen) names.push_back(e.name);
      const size_t name_w = pipeline_column(names);
      fmt::print("\n{:<{}} {:>8} {:>7} {:>9} {:>7} {:>7} {:>7} {:>7} {:>10}\n", "pipeline", name_w, "PSNR dB", "SSIM",
                 "MSE", "err %", "holes %", "recall", "prec.", "time ms");
      for (size_t i = 0; i < chosen.size(); ++i) {
        const validation::PipelineValidation v =
            validation::validate_pipeline(target, chosen[i], options[i], executor, metric_options);
        const std::string stem = fmt::format("{}_{}", scene_stem, entry_file_stem(v.pipeline));
        json images = validation::write_pipeline_images(out, stem, target, v, executor, image_options);
        images.update(shared_images);
        const json record = validation::validation_record(target, v, executor.threads(), images);
        set.add(record_file(v.pipeline),
                [&](const fs::path& tmp) { io::write_text_atomically(tmp, io::json_text(record, 2) + "\n"); });
        records.push_back(record);
        const validation::HoleStatistics& h = v.holes;
        fmt::print("{:<{}} {:>8} {:>7} {:>9} {:>7} {:>7} {:>7} {:>7} {:>10.1f}\n", v.pipeline, name_w,
                   table_number(v.whole.psnr, 2), table_number(v.whole.ssim, 4), mse_text(v.whole.mse),
                   table_number(100.0 * v.whole.error_fraction, 3), table_number(100.0 * h.hole_fraction, 3),
                   table_number(h.scores.recall, 4), table_number(h.scores.precision, 4),
                   v.result.timings.total() * 1e3);
        if (v.left)
          left_lines.push_back(fmt::format(
              "{:<{}} {:>8} {:>7} {:>9} {:>7}  ({:.3f} % of its pixels not rendered by the left eye)", v.pipeline,
              name_w, table_number(v.left->psnr, 2), table_number(v.left->ssim, 4), mse_text(v.left->mse),
              table_number(100.0 * v.left->error_fraction, 3),
              100.0 * static_cast<double>(v.left_synthesized) / static_cast<double>(v.result.left.pixel_count())));
      }
      if (!left_lines.empty()) {
        fmt::print("\nleft eyes synthesized in part, against plain-rt's left eye:\n{:<{}} {:>8} {:>7} {:>9} {:>7}\n",
                   "pipeline", name_w, "PSNR dB", "SSIM", "MSE", "err %");
        for (const std::string& line : left_lines) fmt::print("{}\n", line);
      }
      retired = retire_earlier_records(set, out, earlier, scene_stem, names);
      const std::string summary_text =
          io::json_text(json{{"kind", "stereobench.validation_summary"}, {"records", records}}, 2) + "\n";
      set.add(summary, [&](const fs::path& tmp) { io::write_text_atomically(tmp, summary_text); });
    }
    set.commit();  // the summary, added last, is the set's marker
    remove_earlier_work_folders(out / "work", scene_stem, work_name, earlier);
    fmt::print("\nwrote {} (one record per pipeline beside it, images under {})\n", summary.string(), out.string());
    if (!retired.empty())
      fmt::print("removed the earlier records of {} with their images: not validated in this run, they described the "
                 "truth this run replaced (validate them together, or into another --out, to keep both)\n",
                 fmt::join(retired, ", "));
  });
}

}  // namespace

void register_validate_command(CLI::App& root) {
  auto a = std::make_shared<ValidateArgs>();
  CLI::App* v = root.add_subcommand(
      "validate",
      "Measure pipelines' right eyes against a ground-truth right eye: MSE, PSNR, SSIM, error pixels\n"
      "(whole image and per region: reprojected, filled, true disocclusions), hole statistics\n"
      "against the true disocclusions, and time. Writes a JSON record and images per pipeline\n"
      "(right eye, difference and SSIM maps, the pixels not reprojected against the true\n"
      "disocclusions) and prints a table. A pipeline that synthesizes part of its left eye too\n"
      "(bidir-warp, bidir-warp-rt) has its left eye measured against plain-rt's left eye, and\n"
      "writes that eye and its difference map. Schema: docs/results.md.");
  v->add_option("--scene,-s", a->scene, "Scene file (.gltf/.glb) or built-in scene name")->capture_default_str();
  v->add_option("--pipelines,-p", a->pipelines,
                "Pipelines to validate: names, comma-separated or repeated, or 'all' (see `stereobench pipelines`);\n"
                "a variant fixes options in its name, NAME:KEY=VALUE[:KEY=VALUE...] (e.g.\n"
                "bidir-warp:occlusion=ztest), and is measured beside the pipeline under that name")
      ->capture_default_str();
  v->add_option("--option,-o", a->options,
                "Pipeline option NAME=VALUE, applied to every chosen pipeline (each must declare it; see\n"
                "`stereobench pipelines`); a variant's own options win");
  v->add_option("--truth", a->truth,
                "Ground truth: full (this suite's ray tracer), blender (Cycles) or povray; an unavailable\n"
                "tool is an error (exit 4)")
      ->capture_default_str();
  v->add_option("--threads,-t", a->threads, "Worker threads (0 = all cores)")->capture_default_str();
  v->add_option("--out", a->out, "Output folder")->capture_default_str();
  v->add_option("--cache", a->cache,
                "Folder of cached external ground-truth renders, keyed by content hash ('' to disable)")
      ->capture_default_str();
  v->add_flag("--no-cache", a->no_cache,
              "Render the ground truth again and do not store it (beside --cache, --no-cache wins: the folder is "
              "neither read nor written)");
  v->add_option("--error-threshold", a->error_threshold,
                "Error pixel: largest channel difference above this many 8-bit codes")
      ->capture_default_str();
  add_lights_option(*v, a->lights);
  add_scenes_dir_option(*v, a->scenes_dir);
  a->rig.add_to(*v);
  v->callback([a] { run_validate(*a); });
}

}  // namespace sb::cli
