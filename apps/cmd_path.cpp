// `stereobench path`: validate pipelines frame by frame along a camera path and/or a rigid
// animation (e.g. Al-Hagri's Animated Spheres turning about Y), with the BVH refit or rebuilt per
// frame and timed as its own stage; one JSON line per frame and a summary table.
#include <algorithm>
#include <cmath>
#include <limits>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "renderer/error.hpp"
#include "renderer/text.hpp"
#include "renderer/io/json_text.hpp"
#include "renderer/io/line_file.hpp"
#include "scenes/catalog.hpp"
#include "validation/path_run.hpp"

namespace sb::cli {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct PathArgs {
  std::string scene = "spheres";
  std::vector<std::string> pipelines{"plain-rt", "repro-rt"};
  std::string truth = "full";
  std::string scenes_dir;
  std::string out = "out/path";
  std::string cache = "out/truth-cache";
  int threads = 0;
  int frames = 10;
  std::optional<std::string> camera_keys;
  std::optional<double> spin_deg;
  bool gltf_animation = false;
  std::string gltf_clip;
  std::string spin_axis = "0,1,0";
  std::string spin_prefix;
  std::string bvh;  // empty: refit, and not given
  std::optional<int> lights;
  RigCli rig;
};

dvec3 parse_axis(const std::string& text) {
  dvec3 v;
  char c1 = 0, c2 = 0;
  std::stringstream in(text);
  if (!(in >> v.x >> c1 >> v.y >> c2 >> v.z) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof())
    throw InputError(fmt::format("--spin-axis '{}' is not x,y,z", text));
  return v;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// A PSNR for the table: two decimals, or "inf" for images identical to the truth.
std::string decibels(double db) { return std::isinf(db) ? std::string("inf") : fmt::format("{:.2f}", db); }

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(q * static_cast<double>(v.size() - 1) + 0.5))];
}

void run_path_command(const PathArgs& a) {
  // Nothing moves without a spin or an animation: a BVH update asked for would never be done.
  if (!a.bvh.empty() && !a.spin_deg && !a.gltf_animation && a.gltf_clip.empty())
    throw InputError("--bvh requires --spin-deg or --gltf-animation (nothing else moves the scene's meshes)");
  const std::string bvh = a.bvh.empty() ? "refit" : a.bvh;
  if (bvh != "refit" && bvh != "rebuild")
    throw InputError(fmt::format("--bvh '{}' is neither refit nor rebuild", bvh));
  validation::PathRun run;
  run.path.frames = a.frames;
  if (a.camera_keys) run.path.camera_keys = parse_camera_keys(*a.camera_keys);
  run.path.gltf_animation = a.gltf_animation || !a.gltf_clip.empty();
  run.path.gltf_clip = a.gltf_clip;
  if (a.spin_deg) run.path.spin = Spin{parse_axis(a.spin_axis), std::nullopt, *a.spin_deg, a.spin_prefix};
  run.path.validate();
  // Keys the path cannot reach are said, not passed over.
  if (const auto unshown = run.path.unshown_keys_warning("--frames")) print_warning(*unshown);
  const RigOverrides overrides = a.rig.overrides();
  run.pipelines =
      parse_pipeline_entries(expand_all_pipelines(split_list(a.pipelines, "--pipelines"), "--pipelines"), "--pipelines");
  for (const PipelineEntry& e : run.pipelines) (void)e.options();  // a variant's options, before any frame
  const std::unique_ptr<validation::TruthProvider> provider = validation::make_truth_provider(a.truth);
  if (auto why = provider->unavailable_reason())
    throw ToolError(fmt::format("--truth {}: the provider is unavailable: {}", a.truth, *why));
  const Executor executor(checked_threads(a.threads));
  check_output_folder(a.out, "--out");
  scenes::LoadedScene loaded = scenes::load_scene(a.scene, a.scenes_dir, a.lights);
  const StereoRig rig = resolve_rig(loaded.scene, overrides);
  for (const PipelineEntry& e : run.pipelines) e.check_rig(e.options(), rig);
  run.scene_file = loaded.file;
  run.rig = rig.params();
  run.pose = rig.pose();
  run.truth = provider.get();
  const validation::TruthCache cache(a.cache);
  run.cache = a.cache.empty() ? nullptr : &cache;
  run.work_dir = fs::path(a.out) / "work";
  run.refit = bvh == "refit";

  // The path checked against the scene before the first frame (run_path plays it on its own animator).
  const SceneAnimator animation(loaded.scene, run.path);
  if (!a.bvh.empty() && !animation.moves_geometry())
    throw InputError(fmt::format("--bvh {}: the path moves none of the scene's meshes ({}), so there is no BVH to "
                                 "update; drop --bvh",
                                 a.bvh,
                                 run.path.gltf_animation
                                     ? fmt::format("its glTF animation {} moves only cameras or lights", animation.clip())
                                     : "nothing turns"));
  provider->check_scene(loaded.scene, loaded.file);
  validation::check_path_truth(*provider, loaded.scene, run.path, loaded.file);
  // Made once the input is known to be good, and removed again if the run stops before writing
  // into it: a refused or failed run leaves no empty folder behind.
  in_output_folder(a.out, "--out", [&] {
    fmt::print("path on {} ({} triangles): {}, {}{}; {}, truth {}\n", loaded.scene.name,
               loaded.scene.triangle_count(), counted(a.frames, "frame"),
               run.path.camera_keys.empty() ? "the scene's camera" : fmt::format("{} camera key{}", run.path.camera_keys.size(), run.path.camera_keys.size() == 1 ? "" : "s"),
               a.spin_deg ? fmt::format(", meshes turning {} deg per frame (BVH {})", *a.spin_deg, bvh)
               : run.path.gltf_animation
                   ? fmt::format(", the scene's glTF animation ({}) from {:g} s to {:g} s, {} mesh(es) and {} light(s) "
                                 "moving (BVH {})",
                                 animation.clip(), animation.time_of(0), animation.time_of(a.frames - 1),
                                 animation.turning_meshes(), animation.moving_lights(), bvh)
                                  : "",
               describe(rig), provider->name());
    // The frames go to <stem>_path.jsonl.partial as they finish, renamed to the final name when
    // the last is in: a run stopped on the way leaves the frames it finished under a name that says
    // so, and no file under the final name (an earlier run's is removed before the first frame).
    const fs::path lines = fs::path(a.out) / fmt::format("{}_path.jsonl", loaded.scene.file_stem());
    const fs::path partial = fs::path(lines).concat(".partial");
    remove_earlier_output(lines, "path file");
    io::LineFile out(partial);
    std::map<std::string, std::vector<double>> frame_s, psnr;
    std::vector<double> bvh_s;
    try {
      validation::run_path(loaded.scene, run, executor, [&](const json& f) {
        out.append(io::json_text(f));
        // Frame 0 builds the BVH; later frames update it, unless the path moves no geometry ("static").
        if (f["frame"].get<int>() > 0 && f["bvh"] != "static") bvh_s.push_back(f["bvh_update_s"].get<double>());
        std::string line = fmt::format("frame {:>4}", f["frame"].get<int>());
        for (const auto& [name, p] : f["pipelines"].items()) {
          frame_s[name].push_back(p["total_s"].get<double>());
          // PSNR is a string ("inf") for a frame identical to the truth.
          const json& m = p["metrics"]["psnr"];
          const double db = m.is_number() ? m.get<double>() : std::numeric_limits<double>::infinity();
          psnr[name].push_back(db);
          line += fmt::format("  {} {:.1f} ms {} dB", name, 1e3 * p["total_s"].get<double>(), decibels(db));
        }
        fmt::print(stderr, "{}\n", line);
      });
    } catch (...) {
      if (out.lines() > 0)
        fmt::print(stderr, "stereobench: the {} finished before the error {} in {}\n", counted(out.lines(), "frame"),
                   out.lines() == 1 ? "is" : "are", partial.string());
      throw;
    }
    out.finish(lines);
    std::vector<std::string> names;
    for (const auto& entry : frame_s) names.push_back(entry.first);
    const size_t name_w = pipeline_column(names);
    fmt::print("\n{:<{}} {:>14} {:>14} {:>12}\n", "pipeline", name_w, "median ms", "95th pct ms", "median PSNR");
    for (const auto& [name, s] : frame_s)
      fmt::print("{:<{}} {:>14.2f} {:>14.2f} {:>12}\n", name, name_w, 1e3 * median(s), 1e3 * percentile(s, 0.95),
                 decibels(median(psnr[name])));
    if (!bvh_s.empty()) fmt::print("BVH {} per frame: median {:.2f} ms\n", bvh, 1e3 * median(bvh_s));
    fmt::print("wrote {}\n", lines.string());
  });
}

}  // namespace

void register_path_command(CLI::App& root) {
  auto a = std::make_shared<PathArgs>();
  CLI::App* p = root.add_subcommand(
      "path",
      "Validate pipelines frame by frame along a camera path and/or a rigid animation: per frame the\n"
      "scene moves, its BVH is refit (or rebuilt) and timed, and every pipeline is rendered and\n"
      "measured against the ground truth. Writes <out>/<scene>_path.jsonl (one line per frame, each\n"
      "naming its scene, rig, animation and truth; written to <scene>_path.jsonl.partial as frames\n"
      "finish and renamed after the last).");
  p->add_option("--scene,-s", a->scene, "Scene file (.gltf/.glb) or built-in scene name")->capture_default_str();
  p->add_option("--pipelines,-p", a->pipelines,
                "Pipelines to run each frame, comma-separated, 'all' for every registered one; a variant "
                "NAME:KEY=VALUE[:KEY=VALUE...] runs with those options")
      ->capture_default_str();
  p->add_option("--truth", a->truth, "Ground truth: full, blender or povray")->capture_default_str();
  p->add_option("--frames,-n", a->frames, "Number of frames")->capture_default_str();
  p->add_option("--camera-keys", a->camera_keys,
                "Camera key poses POSITION>TARGET;... in meters, e.g. '0,1.6,4>0,1,0;2,1.6,3>0,1,0';\n"
                "the camera moves linearly between them over the frames (without the option: the scene's camera)");
  CLI::Option* spin =
      p->add_option("--spin-deg", a->spin_deg, "Turn meshes by this many degrees per frame (rigid animation)");
  p->add_option("--spin-axis", a->spin_axis, "Axis of the turn, x,y,z")->capture_default_str()->needs(spin);
  p->add_option("--spin-prefix", a->spin_prefix, "Turn only meshes whose name starts with this (default: all)")
      ->needs(spin);
  p->add_flag("--gltf-animation", a->gltf_animation,
                                  "Play the scene file's own node animations over the frames, from their first key time "
                                  "to their last:\nanimated meshes and lights move with their nodes, an animated scene "
                                  "camera moves the rig (not with --camera-keys or --spin-deg)");
  p->add_option("--gltf-clip", a->gltf_clip,
                "Play only this glTF animation (clip) of the scene, by name or #index (implies --gltf-animation; "
                "without it every clip plays at once)");
  p->add_option("--bvh", a->bvh,
                "Per-frame BVH update of a moving scene (--spin-deg, --gltf-animation): refit (default) or rebuild");
  p->add_option("--threads,-t", a->threads, "Worker threads (0 = all cores)")->capture_default_str();
  p->add_option("--out", a->out, "Output folder")->capture_default_str();
  p->add_option("--cache", a->cache, "Folder of cached external ground-truth renders ('' to disable)")
      ->capture_default_str();
  add_lights_option(*p, a->lights);
  add_scenes_dir_option(*p, a->scenes_dir);
  a->rig.add_to(*p);
  p->callback([a] { run_path_command(*a); });
}

}  // namespace sb::cli
