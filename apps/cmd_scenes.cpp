// `stereobench scenes`: list the built-in scene generators, generate scenes, describe scene files.
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "renderer/error.hpp"
#include "renderer/io/gltf_loader.hpp"
#include "renderer/io/render_output.hpp"
#include "renderer/render_scene.hpp"
#include "renderer/rig.hpp"
#include "renderer/stages/primary_rays.hpp"
#include "renderer/text.hpp"
#include "scenes/catalog.hpp"
#include "scenes/generators.hpp"

namespace sb::cli {

namespace {

namespace fs = std::filesystem;

void list_generators() {
  fmt::print("{:<15} {:<20} {}\n", "scene", "file", "description");
  for (const scenes::GeneratorInfo& g : scenes::generators()) {
    fmt::print("{:<15} {:<20} {}{}{}\n", g.name, g.file_name, g.description, g.analytic ? " [analytic test scene]" : "",
               g.builtin ? "" : " [on demand: not in --all]");
    for (const scenes::GeneratorParam& p : g.params)
      fmt::print("{:<15}   --param {}={} ({} .. {}): {}\n", "", p.name, p.default_value, p.min_value, p.max_value, p.help);
  }
}

struct GenerateArgs {
  std::vector<std::string> names;
  bool all = false;
  std::string out_dir;
  uint64_t seed = 1;
  std::vector<std::string> params;
};

std::map<std::string, double> parse_params(const std::vector<std::string>& items) {
  std::map<std::string, double> out;
  for (const auto& [name, value] : parse_key_values(items, "--param")) {
    const std::optional<double> v = parse_finite(value);
    if (!v) throw InputError(fmt::format("--param {}: '{}' is not a finite decimal number", name, value));
    out[name] = *v == 0.0 ? 0.0 : *v;  // -0 is 0: one scene, one file name
  }
  return out;
}

void generate_scenes(const GenerateArgs& args) {
  std::vector<std::string> names = args.names;
  if (args.all) {
    if (!names.empty()) throw InputError("give scene names or --all, not both");
    for (const scenes::GeneratorInfo& g : scenes::generators())
      if (g.builtin) names.push_back(g.name);
  }
  if (names.empty()) throw InputError("name the scenes to generate, or give --all (see `stereobench scenes list`)");
  scenes::GenerateOptions opt;
  opt.seed = args.seed;
  opt.params = parse_params(args.params);
  if (!opt.params.empty() && names.size() != 1)
    throw InputError("--param applies to one scene; generate the scenes one at a time");
  // Names and parameters are checked before anything is written (the folder included).
  for (const std::string& n : names) (void)scenes::resolve_params(scenes::find_generator(n), opt.params);
  // So are the files: a folder where one is to go stops the run before the first scene is written.
  const bool builtin = opt.seed == 1 && opt.params.empty();
  const auto file_of = [&](const std::string& n) {
    const scenes::GeneratorInfo& g = scenes::find_generator(n);
    return fs::path(args.out_dir) / (builtin ? g.file_name : scenes::variant_file_name(g, opt.seed, opt.params));
  };
  std::vector<fs::path> files;
  for (const std::string& n : names) {
    files.push_back(file_of(n));
    if (builtin) files.push_back(scenes::stamp_path(files.back()));  // only the defaults are stamped
  }
  io::check_no_folder_at(files, "give another --out");
  // A scene refused once built leaves no empty folder this run made.
  in_output_folder(args.out_dir, "--out", [&] {
    bool header_printed = false;
    for (const std::string& n : names) {
      // Default scenes are stamped so that commands naming them reuse the file; another seed or
      // parameters get a file name of their own, so that they never stand in for the default.
      const scenes::GenerateResult r =
          builtin ? scenes::generate_builtin(n, args.out_dir) : scenes::generate(n, opt, file_of(n));
      // The table starts with its first row: a scene refused once built (too many triangles) is
      // reported without an empty table above it.
      if (!header_printed)
        fmt::print("{:<15} {:>12} {:>10} {:>7} {:>12} {:>9}  {}\n", "scene", "triangles", "vertices", "lights",
                   "bytes", "seconds", "file");
      header_printed = true;
      fmt::print("{:<15} {:>12} {:>10} {:>7} {:>12} {:>9.2f}  {}\n", n, r.triangles, r.vertices, r.lights, r.bytes,
                 r.seconds, r.path.string());
    }
  });
}

struct InfoArgs {
  std::vector<std::string> scenes;
  std::string scenes_dir;
  RigCli rig;
};

/// The linear depths the centre camera sees, from primary rays through the centres of every
/// `step`-th pixel in each direction (at most some 320 x 180 rays).
struct DepthRange {
  double nearest = 0.0, farthest = 0.0;
  size_t hits = 0, rays = 0;
  size_t before_near = 0;  ///< hits nearer than the near plane, which rasterizing pipelines clip
  int step = 1;
};

DepthRange visible_depth_range(const Scene& scene, const StereoRig& rig) {
  const RenderScene prepared(scene);
  const EyeCamera centre = rig.eye(Eye::center);
  const PrimaryRays primary(centre);
  DepthRange r;
  r.step = std::max(1, static_cast<int>(std::ceil(std::max(centre.width / 320.0, centre.height / 180.0))));
  r.nearest = std::numeric_limits<double>::infinity();
  std::vector<RayQuery> queries;
  const auto flush = [&] {
    std::vector<RayHit> hits(queries.size());
    prepared.rays().intersect(queries, hits, (1u << queries.size()) - 1u);
    for (size_t i = 0; i < queries.size(); ++i) {
      ++r.rays;
      if (hits[i].prim == kNoPrimitiveId) continue;
      const double z = static_cast<double>(hits[i].t) * cos_to_axis(centre, queries[i].dir);
      if (z < rig.params().znear) {
        ++r.before_near;
        continue;
      }
      r.nearest = std::min(r.nearest, z);
      r.farthest = std::max(r.farthest, z);
      ++r.hits;
    }
    queries.clear();
  };
  for (int y = r.step / 2; y < centre.height; y += r.step)
    for (int x = r.step / 2; x < centre.width; x += r.step) {
      queries.push_back(primary(x, y));
      if (queries.size() == static_cast<size_t>(kRayPacket)) flush();
    }
  if (!queries.empty()) flush();
  return r;
}

/// A disparity in pixels to the rig's scale: two decimals, more where the rig's largest disparity
/// `scale` is below 1 px (a tiny interaxial: three significant digits of it), and no minus sign on
/// a value that rounds to zero (a surface at the convergence distance, up to float noise).
std::string disparity_text(double px, double scale) {
  const int decimals =
      std::clamp(2 - static_cast<int>(std::floor(std::log10(std::max(scale, 1e-12)))), 2, 12);
  std::string text = fmt::format("{:.{}f}", px, decimals);
  if (text.find_first_not_of("-0.") == std::string::npos && text[0] == '-') text.erase(0, 1);
  return text;
}

void print_info(const InfoArgs& args) {
  const RigOverrides overrides = args.rig.overrides();  // check options before any work
  for (const std::string& spec : args.scenes) {
    const auto t0 = std::chrono::steady_clock::now();
    // As every command loads it: a damaged cached built-in scene is named with how to recover,
    // and the loader's warnings go to stderr.
    const scenes::LoadedScene loaded = scenes::load_scene(spec, args.scenes_dir, std::nullopt);
    const Scene& scene = loaded.scene;
    const fs::path& path = loaded.file;
    const double load_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const Bounds3 b = scene.bounds();
    size_t lights_by_type[3] = {0, 0, 0};
    for (const Light& l : scene.lights) ++lights_by_type[static_cast<int>(l.type)];
    size_t textured = 0;
    for (const Material& m : scene.materials) textured += m.base_color_texture >= 0;
    fmt::print("scene      {} ({})\n", scene.name, path.string());
    const size_t zero_area = scene.zero_area_triangle_count();
    fmt::print("geometry   {} triangles{}, {} vertices, {} meshes\n", scene.triangle_count(),
               zero_area ? fmt::format(" ({} of zero area)", zero_area) : std::string(), scene.vertex_count(),
               scene.meshes.size());
    fmt::print("materials  {} ({} textured), {} textures\n", scene.materials.size(), textured, scene.textures.size());
    fmt::print("lights     {} point, {} directional, {} spot\n", lights_by_type[0], lights_by_type[1], lights_by_type[2]);
    // Each light with the values the shading reads (DESIGN §3 units), so that a file's light units
    // can be checked; a long list is cut short.
    constexpr size_t kLightsListed = 16;
    for (size_t i = 0; i < std::min(scene.lights.size(), kLightsListed); ++i) {
      const Light& l = scene.lights[i];
      const std::string colour = fmt::format("colour ({:.3g}, {:.3g}, {:.3g})", l.color.x, l.color.y, l.color.z);
      if (l.type == Light::Type::directional)
        fmt::print("           directional '{}': irradiance {:.4g} W/m², {}, towards ({:.3f}, {:.3f}, {:.3f})\n", l.name,
                   l.intensity, colour, l.direction.x, l.direction.y, l.direction.z);
      else
        fmt::print("           {} '{}': intensity {:.4g} W/sr, {}, at ({:.3f}, {:.3f}, {:.3f}) m{}\n",
                   l.type == Light::Type::spot ? "spot" : "point", l.name, l.intensity, colour, l.position.x,
                   l.position.y, l.position.z,
                   l.type == Light::Type::spot ? fmt::format(", cone {:.1f}..{:.1f} deg", radians_to_degrees(l.inner_cone),
                                                             radians_to_degrees(l.outer_cone))
                                               : std::string());
    }
    if (scene.lights.size() > kLightsListed)
      fmt::print("           ... and {} more\n", scene.lights.size() - kLightsListed);
    fmt::print("bounds     [{:.3f}, {:.3f}, {:.3f}] .. [{:.3f}, {:.3f}, {:.3f}] m\n", b.lo.x, b.lo.y, b.lo.z, b.hi.x,
               b.hi.y, b.hi.z);
    fmt::print("cameras    {}\n", scene.cameras.empty() ? std::string("none (rig frames the bounds)") : scene.cameras.front().name);
    const StereoRig rig = resolve_rig(scene, overrides);
    fmt::print("rig        {}\n", describe(rig));
    const DepthRange range = visible_depth_range(scene, rig);
    const std::string before_near =
        fmt::format("hit a surface nearer than the near plane ({:g} m), which rasterizing pipelines clip (ray tracing "
                    "and the ground truths show it)",
                    rig.params().znear);
    const double scale = std::max({std::abs(rig.disparity_px(range.nearest)),
                                   std::abs(rig.disparity_px(range.farthest)), rig.max_disparity_px()});
    if (range.hits > 0)
      fmt::print("disparity  {} px at the nearest visible surface ({:.3f} m) .. {} px at the farthest "
                 "({:.3f} m), over {} of {} rays (every {} px){}{}\n",
                 disparity_text(rig.disparity_px(range.nearest), scale), range.nearest,
                 disparity_text(rig.disparity_px(range.farthest), scale), range.farthest, range.hits, range.rays, range.step,
                 range.hits + range.before_near < range.rays ? "; the rest see the sky" : "",
                 range.before_near > 0 ? fmt::format("; {} {}", range.before_near, before_near) : std::string());
    else if (range.before_near > 0)
      fmt::print("disparity  none: {} of {} rays {}{}\n", range.before_near, range.rays, before_near,
                 range.before_near < range.rays ? "; the rest see the sky" : "");
    else
      fmt::print("disparity  none: the centre camera sees no surface (no ray through every {} px hits one)\n",
                 range.step);
    fmt::print("loaded in  {:.3f} s\n", load_s);
    fmt::print("\n");
  }
}

}  // namespace

void register_scenes_command(CLI::App& root) {
  CLI::App* scenes = root.add_subcommand("scenes", "List, generate and describe scenes");
  scenes->require_subcommand(0, 1);
  scenes->callback([scenes] {
    if (scenes->get_subcommands().empty())
      throw InputError("`stereobench scenes` needs a subcommand: list, generate or info (see --help)");
  });

  CLI::App* list = scenes->add_subcommand("list", "List the built-in scene generators and their parameters");
  list->callback([] { list_generators(); });

  auto gen = std::make_shared<GenerateArgs>();
  gen->out_dir = scenes::default_scenes_dir().string();
  CLI::App* g = scenes->add_subcommand("generate", "Generate built-in scenes as glTF (seeded, deterministic)");
  g->add_option("names", gen->names, "Scenes to generate (see `scenes list`)");
  std::vector<std::string> on_demand;
  for (const scenes::GeneratorInfo& info : scenes::generators())
    if (!info.builtin) on_demand.push_back(info.name);
  g->add_flag("--all", gen->all,
              fmt::format("Generate every built-in scene with default parameters, but for those marked on demand in "
                          "`scenes list` ({}), which a command naming them generates",
                          fmt::join(on_demand, ", ")));
  g->add_option("--out,-o", gen->out_dir, "Output folder")->capture_default_str();
  g->add_option("--seed", gen->seed,
                "Random seed; same seed, same file. With another seed than 1 or a --param the file is named\n"
                "after them (spheres_seed-35_count-500.glb); commands naming the scene load the default file")
      ->check(CLI::Validator(
          [](const std::string& v) {
            // Decimal digits only, and within 64 bits: the parser would saturate 2^64 and above.
            uint64_t parsed = 0;
            const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), parsed);
            return v.empty() || ec != std::errc() || end != v.data() + v.size()
                       ? "a seed is a whole number from 0 to 18446744073709551615, not " + v
                       : std::string();
          },
          "", "non-negative"))
      ->capture_default_str();
  g->add_option("--param,-p", gen->params, "Generator parameter NAME=VALUE (see `scenes list`)");
  g->callback([gen] { generate_scenes(*gen); });

  auto info = std::make_shared<InfoArgs>();
  CLI::App* i = scenes->add_subcommand("info", "Load scenes and print their contents and default stereo rig");
  i->add_option("scenes", info->scenes, "Scene files (.gltf/.glb) or built-in scene names")->required();
  add_scenes_dir_option(*i, info->scenes_dir);
  info->rig.add_to(*i);
  i->callback([info] { print_info(*info); });
}

}  // namespace sb::cli
