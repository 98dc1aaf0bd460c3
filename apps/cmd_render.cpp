// `stereobench render` and `stereobench pipelines`: render a stereo pair with one pipeline and
// write its images and statistics; list and describe the registered pipelines.
#include <filesystem>
#include <memory>

#include <fmt/format.h>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "renderer/io/gltf_loader.hpp"
#include "renderer/io/render_output.hpp"
#include "renderer/pipeline.hpp"
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
  RigCli rig;
};

void print_timings(const StereoResult& r) {
  for (const auto& [stage, s] : r.timings.stages()) fmt::print("  {:<22} {:>10.2f} ms\n", stage, s * 1e3);
  fmt::print("  {:<22} {:>10.2f} ms\n", "total", r.timings.total() * 1e3);
}

void run_render(const RenderArgs& a) {
  const RigOverrides overrides = a.rig.overrides();
  const Pipeline& pipeline = find_pipeline(a.pipeline);
  const PipelineOptions options(pipeline.info(), parse_key_values(a.options, "--option"));
  const Executor executor(checked_threads(a.threads));
  const fs::path path = scenes::resolve_scene(a.scene, a.scenes_dir);
  const Scene scene = io::load_gltf(path);
  for (const std::string& w : scene.warnings) fmt::print(stderr, "warning: {}\n", w);
  const StereoRig rig = resolve_rig(scene, overrides);
  const RenderScene prepared(scene);
  const StereoResult result = pipeline.render(prepared, rig, options, RenderContext{executor});
  const nlohmann::json record = io::result_to_json(pipeline.info().name, prepared, rig, result, executor.threads(), options);
  const std::string stem = fmt::format("{}_{}", scene.name, pipeline.info().name);
  const io::RenderFiles files = io::write_render_outputs(a.out, stem, result, record);
  fmt::print("{} on {} ({} triangles), {}, {} threads\n", pipeline.info().name, scene.name, scene.triangle_count(),
             describe(rig), executor.threads());
  fmt::print("  {:<22} {:>10.2f} ms ({:.1f} MiB)\n", "bvh build (once)", prepared.bvh_build_seconds() * 1e3,
             prepared.rays().memory_bytes() / 1048576.0);
  print_timings(result);
  for (const auto& [name, value] : result.counters.snapshot()) fmt::print("  {:<22} {:>12}\n", name, value);
  fmt::print("wrote {}\n      {}\n      {}\n      {}\n      {}\n      {}\n", files.exr.string(), files.left_png.string(),
             files.right_png.string(), files.anaglyph_png.string(), files.side_by_side_png.string(),
             files.stats_json.string());
}

void list_pipelines() {
  for (const Pipeline* p : pipelines()) {
    const PipelineInfo& i = p->info();
    fmt::print("{:<16} {}\n{:<16} source: {}, {}\n", i.name, i.summary, "", i.paper, i.section);
    for (const OptionSpec& o : i.options) fmt::print("{:<16}   --option {}={}: {}\n", "", o.name, o.default_value, o.help);
  }
}

}  // namespace

void register_render_command(CLI::App& root) {
  auto a = std::make_shared<RenderArgs>();
  CLI::App* r = root.add_subcommand("render", "Render a stereo pair with one pipeline; write EXR, PNGs and stats");
  r->add_option("--scene,-s", a->scene, "Scene file (.gltf/.glb) or built-in scene name")->capture_default_str();
  r->add_option("--pipeline,-p", a->pipeline, "Pipeline name (see `stereobench pipelines`)")->capture_default_str();
  r->add_option("--option,-o", a->options, "Pipeline option NAME=VALUE (see `stereobench pipelines`)");
  r->add_option("--threads,-t", a->threads, "Worker threads (0 = all cores)")->capture_default_str();
  r->add_option("--out", a->out, "Output folder")->capture_default_str();
  add_scenes_dir_option(*r, a->scenes_dir);
  a->rig.add_to(*r);
  r->callback([a] { run_render(*a); });

  CLI::App* l = root.add_subcommand("pipelines", "List the registered pipelines with their sources and options");
  l->callback([] { list_pipelines(); });
}

}  // namespace sb::cli
