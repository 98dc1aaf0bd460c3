// `stereobench render` and `stereobench pipelines`: render a stereo pair with one pipeline and
// write its images and statistics; list and describe the registered pipelines.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/render_output.hpp"
#include "renderer/memory.hpp"
#include "renderer/pipeline.hpp"
#include "renderer/stages/disocclusion.hpp"
#include "scenes/catalog.hpp"

namespace sb::cli {

namespace {

namespace fs = std::filesystem;

struct RenderArgs {
  std::string scene = "bistro";
  std::string pipeline = "plain-rt";
  std::vector<std::string> options;
  std::string scenes_dir;
  std::string out = "out/render";
  int threads = 0;
  std::optional<int> lights;
  std::vector<std::string> stereo{"anaglyph", "sbs"};
  RigCli rig;
};

void print_timings(const StereoResult& r) {
  const Timings& t = r.timings;
  for (const StageTime& s : t.stages())
    fmt::print("  {:<22} {:>10.2f} ms  {} eye{}\n", s.name, s.seconds * 1e3, stage_eye_name(s.eye),
               s.eye == StageEye::both ? "s" : "");
  fmt::print("  {:<22} {:>10.2f} ms\n", "total", t.total() * 1e3);
  const double left = t.eye_total(StageEye::left), right = t.eye_total(StageEye::right);
  const std::string shared =
      t.shared_stages().empty() ? "" : fmt::format(" ({:.2f} ms serve both eyes)", t.eye_total(StageEye::both) * 1e3);
  if (left > 0.0)
    fmt::print("  {:<22} {:.2f} / {:.2f} ms = {:.1f} %{}\n", "right eye / left eye", right * 1e3, left * 1e3,
               100.0 * right / left, shared);
  else
    fmt::print("  {:<22} -{}: no stage serves the left eye alone\n", "right eye / left eye", shared);
}

/// A share as a percentage with two decimals, or "-" where it is undefined (NaN).
std::string percent(double share) { return std::isnan(share) ? "-" : table_number(share, 2, 100.0) + " %"; }

void print_holes(const HoleAnalysis& h, size_t pixels) {
  fmt::print("  {:<22} recall {}, precision {} ({} pixels, {} of them truly disoccluded)\n", "not reprojected",
             percent(h.scores.recall), percent(h.scores.precision), h.scores.hole_pixels, h.scores.true_positives);
  fmt::print("  {:<22} {} = {:.3f} % of the right eye ({} outside the left frustum, {} hidden), {:.2f} ms\n",
             "true disocclusions", h.truth.count(), 100.0 * double(h.truth.count()) / double(pixels),
             h.truth.outside_frustum, h.truth.hidden, h.seconds * 1e3);
}

void run_render(const RenderArgs& a) {
  const RigOverrides overrides = a.rig.overrides();
  if (a.pipeline.find(',') != std::string::npos || a.pipeline == "all")
    throw InputError(fmt::format("--pipeline {}: render renders one pipeline; give one name, or measure several side "
                                 "by side with `stereobench validate` or `stereobench bench`",
                                 a.pipeline));
  const PipelineEntry entry = parse_pipeline_entry(a.pipeline);
  const Pipeline& pipeline = *entry.pipeline;
  const std::map<std::string, std::string> given = parse_key_values(a.options, "--option");
  // One pipeline, one value per option: a variant's own value and another by --option contradict.
  for (const auto& [key, value] : given)
    if (entry.fixes_otherwise(key, value))
      throw InputError(fmt::format("--option {}={}: the variant {} fixes {}={}; give the option once", key, value,
                                   entry.name, key, entry.fixed.at(key)));
  const PipelineOptions options = entry.options(given);
  const io::StereoViews views = io::StereoViews::from_names(split_list(a.stereo, "--stereo"), "--stereo");
  const Executor executor(checked_threads(a.threads));
  check_output_folder(a.out, "--out");
  const scenes::LoadedScene loaded = scenes::load_scene(a.scene, a.scenes_dir, a.lights);
  const Scene& scene = loaded.scene;
  const size_t lights_in_file = loaded.lights_in_file;
  const StereoRig rig = resolve_rig(scene, overrides);
  entry.check_rig(options, rig);
  // Made once the input is known to be good, and removed again if the run stops before writing
  // into it: a refused or failed run leaves no empty folder behind.
  in_output_folder(a.out, "--out", [&] {
    // Its outputs are <stem>.exr and <stem>_*: <stem>_left.png, ..., <stem>_stats.json, and the
    // earlier diagnostic images of the set it replaces.
    const std::string stem = fmt::format("{}_{}", scene.file_stem(), entry_file_stem(entry.name));
    io::check_no_folder_at(io::render_file_names(a.out, stem, views).all(),
                           "give another --out");  // before the render, not after it
    refuse_replacing_inputs(loaded.file, scene, a.out, {stem + "_", stem + "."}, "render");
    const RenderScene prepared(scene);
    require_frame_memory(rig.params().width, rig.params().height, fmt::format("render {}", entry.name));
    warn_scene_far_from_origin(prepared);
    warn_geometry_before_near_plane(prepared, rig, executor);
    const StereoResult result = pipeline.render(prepared, rig, options, RenderContext{executor});
    warn_if_no_surface_seen(result.left, result.right, rig);
    // Scored against the true disocclusions outside the pipeline's timings.
    const std::optional<HoleAnalysis> holes = analyze_holes(prepared, rig, result.right, executor);
    nlohmann::json record = io::result_to_json(entry.name, prepared, rig, result, executor.threads(), options);
    if (holes) record["holes"] = io::holes_to_json(*holes);
    record["scene"]["lights"] = scene.lights.size();
    record["scene"]["lights_in_file"] = lights_in_file;
    const io::RenderFiles files =
        io::write_render_outputs(a.out, stem, result, record, holes ? &holes->overlay : nullptr, views, executor);
    fmt::print("{} on {} ({} triangles, {}), {}, {} threads\n", entry.name, scene.name, scene.triangle_count(),
               describe_lights(scene.lights.size(), lights_in_file), describe(rig), executor.threads());
    fmt::print("  {:<22} {:>10.2f} ms ({:.1f} MiB)\n", "bvh build (once)", prepared.bvh_build_seconds() * 1e3,
               prepared.rays().memory_bytes() / 1048576.0);
    print_timings(result);
    // Counters in one column, as wide as the longest name needs (hole_pixels_occluding_edge is 26).
    const auto counters = result.counters.snapshot();
    size_t width = 22;
    for (const auto& counter : counters) width = std::max(width, counter.first.size());
    for (const auto& [name, value] : counters) fmt::print("  {:<{}} {:>12}\n", name, width, value);
    if (holes) print_holes(*holes, result.right.pixel_count());
    const std::vector<fs::path> written = files.all();
    for (size_t i = 0; i < written.size(); ++i) fmt::print("{}{}\n", i == 0 ? "wrote " : "      ", written[i].string());
  });
}

void list_pipelines() {
  for (const Pipeline* p : pipelines()) {
    const PipelineInfo& i = p->info();
    fmt::print("{:<16} {}\n{:<16} source: {}, {}\n", i.name, i.summary, "", i.paper, i.section);
    for (const OptionSpec& o : i.options) fmt::print("{:<16}   --option {}={}: {}\n", "", o.name, o.default_value, o.help);
  }
  fmt::print(
      "\nA variant fixes options in the pipeline's name, NAME:KEY=VALUE[:KEY=VALUE...] (e.g.\n"
      "bidir-warp:occlusion=ztest): render, validate, bench, path and sweeps run it under that name,\n"
      "beside the pipeline itself where that is listed too.\n");
}

}  // namespace

void register_render_command(CLI::App& root) {
  auto a = std::make_shared<RenderArgs>();
  CLI::App* r = root.add_subcommand("render", "Render a stereo pair with one pipeline; write EXR, PNGs and stats");
  r->add_option("--scene,-s", a->scene, "Scene file (.gltf/.glb) or built-in scene name")->capture_default_str();
  r->add_option("--pipeline,-p", a->pipeline,
                "Pipeline name (see `stereobench pipelines`), or a variant with options fixed in its name,\n"
                "NAME:KEY=VALUE[:KEY=VALUE...] (files are named NAME@KEY=VALUE...)")
      ->capture_default_str();
  r->add_option("--option,-o", a->options,
                "Pipeline option NAME=VALUE (see `stereobench pipelines`); one a variant's name fixes may not be given "
                "another value");
  r->add_option("--threads,-t", a->threads, "Worker threads (0 = all cores)")->capture_default_str();
  r->add_option("--out", a->out, "Output folder")->capture_default_str();
  r->add_option("--stereo", a->stereo,
                "Viewable stereo images to write beside the eyes, comma-separated or repeated: anaglyph (Dubois\n"
                "red-cyan, <stem>_anaglyph.png), sbs (side by side, left eye on the left, <stem>_sbs.png), ou\n"
                "(over/under, left eye on top, <stem>_ou.png); none for none")
      ->capture_default_str();
  add_lights_option(*r, a->lights);
  add_scenes_dir_option(*r, a->scenes_dir);
  a->rig.add_to(*r);
  r->callback([a] { run_render(*a); });

  CLI::App* l = root.add_subcommand("pipelines", "List the registered pipelines with their sources and options");
  l->callback([] { list_pipelines(); });
}

}  // namespace sb::cli
