// `blender`: the right eye rendered by Blender Cycles, headless on the CPU (DESIGN §6.1). Blender's
// glTF importer brings in the meshes; a generated script (validation/providers/blender_script.cpp
// plus the numbers of the in-memory scene) replaces lights, materials, world and camera and renders
// one EXR per light; the passes are summed here. docs/truth_blender.md derives every constant.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <system_error>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/image_io.hpp"
#include "renderer/text.hpp"
#include "validation/process.hpp"
#include "validation/providers/blender_script.hpp"
#include "validation/providers/providers.hpp"

namespace sb::validation {
namespace {

namespace fs = std::filesystem;

/// Bumped whenever the export, the script or the settings change.
constexpr const char* kRevision = "blender-export-8";
/// Cut-out holes a camera or shadow ray may pass in Cycles (transparent bounces); ours pass any.
constexpr int kTransparentBounces = 64;
/// Environment variable naming the Blender executable (a path, or a name looked up on PATH).
constexpr const char* kExecutableVariable = "STEREOBENCH_BLENDER";

// Calibration (docs/truth_blender.md). A Cycles point light of power P watts and radius 0 has
// radiant intensity P / (4 pi) W/sr; a sun of strength S gives irradiance S W/m^2 on a surface
// facing it. Both verified to float precision by the BlenderCalibration tests (tests/blender).
constexpr double kPointPowerPerIntensity = 4.0 * kPi;
constexpr double kSunStrengthPerIrradiance = 1.0;
/// Sensor height of the exported camera; any value works, the lens is scaled with it.
constexpr double kSensorHeightMm = 24.0;
/// Box filter width in pixels (Blender's minimum): the single sample lands within 0.005 px of the
/// pixel centre (measured: 0.0005 px, see docs/truth_blender.md).
constexpr double kFilterWidthPx = 0.01;
constexpr int kSeed = 0;
/// Our tracer clips nothing; Blender's camera needs a positive near and a finite far plane.
constexpr double kClipStart = 1e-6;
constexpr double kClipEnd = 1e9;
/// Lines of Blender's output quoted in an error message.
constexpr size_t kQuotedLines = 25;

/// Where the Blender executable is, or why it cannot be found.
struct Located {
  fs::path executable;
  std::string problem;  ///< empty when found
};

Located locate_blender() {
  const char* configured = std::getenv(kExecutableVariable);
  const std::string name = configured != nullptr && *configured != '\0' ? configured : "blender";
  const std::string origin =
      configured != nullptr && *configured != '\0' ? fmt::format(" (from ${})", kExecutableVariable) : "";
  const std::optional<fs::path> found = find_program(name);
  if (name.find('/') != std::string::npos) {
    if (found) return {fs::absolute(*found), ""};
    return {{}, fmt::format("the Blender executable '{}'{} does not exist or is not executable; point ${} at "
                            "Blender 3.4 or unset it and install Blender with `ci/install-deps.sh blender`",
                            name, origin, kExecutableVariable)};
  }
  if (found) return {*found, ""};
  return {{}, fmt::format("'{}'{} not found on PATH; install Blender with `ci/install-deps.sh blender` or set "
                          "${} to the Blender executable",
                          name, origin, kExecutableVariable)};
}

/// PATH without the folders of Python environments: $VIRTUAL_ENV/bin, $CONDA_PREFIX/bin, pyenv's
/// shims and any folder beside a pyvenv.cfg (a virtual environment's bin, activated or not). Blender looks for a Python executable on PATH and takes
/// its prefix, so such a python3 would replace the modules its glTF importer needs (numpy).
std::string path_without_python_environments() {
  const char* path = std::getenv("PATH");
  std::vector<std::string> drop;
  for (const char* var : {"VIRTUAL_ENV", "CONDA_PREFIX"})
    if (const char* v = std::getenv(var); v != nullptr && *v != '\0') drop.push_back((fs::path(v) / "bin").string());
  std::string kept;
  std::istringstream in(path != nullptr ? path : "");
  for (std::string dir; std::getline(in, dir, ':');) {
    std::error_code ec;
    const bool environment = std::find(drop.begin(), drop.end(), dir) != drop.end() ||
                             dir.find("/.pyenv/shims") != std::string::npos ||
                             (!dir.empty() && fs::exists(fs::path(dir).parent_path() / "pyvenv.cfg", ec));
    if (!environment) kept += (kept.empty() ? "" : ":") + dir;
  }
  return kept;
}

/// How Blender runs: its output merged, its Python kept to the system's (PATH without Python
/// environments, and none of the variables that point Python elsewhere).
ProcessOptions blender_options(std::chrono::milliseconds timeout) {
  ProcessOptions options;
  options.stderr_to = ChildOutput::to_stdout;
  options.timeout = timeout;
  options.set_env = {{"PATH", path_without_python_environments()}};
  options.unset_env = {"VIRTUAL_ENV", "PYTHONHOME", "PYTHONPATH", "PYTHONSTARTUP", "PYTHONUSERBASE", "CONDA_PREFIX"};
  return options;
}

/// The first line of `blender --version`, e.g. "Blender 3.4.1", cached per executable.
std::string query_version(const fs::path& executable) {
  static std::mutex mutex;
  static std::map<std::string, std::string> cache;
  const std::lock_guard lock(mutex);
  if (auto it = cache.find(executable.string()); it != cache.end()) return it->second;
  const ProcessResult r =
      run_process({executable.string(), "--factory-startup", "--version"}, blender_options(kShortCommandTimeout));
  std::istringstream in(r.out);
  std::string version;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("Blender ", 0) == 0) {
      version = line;
      break;
    }
  }
  while (!version.empty() && std::isspace(static_cast<unsigned char>(version.back()))) version.pop_back();
  if (!r.ok() || version.empty()) {
    const char* configured = std::getenv(kExecutableVariable);
    const std::string remedy =
        configured != nullptr && *configured != '\0'
            ? fmt::format("${}='{}' names it: point ${} at Blender 3.4, or unset it to use blender from PATH "
                          "(`ci/install-deps.sh blender` installs it)",
                          kExecutableVariable, configured, kExecutableVariable)
            : std::string("check the Blender installation (`ci/install-deps.sh blender`)");
    throw ToolError(fmt::format("'{} --version' failed (it {}){}; {}", executable.string(), r.describe(),
                                quoted_output(r.out, kQuotedLines), remedy));
  }
  cache.emplace(executable.string(), version);
  return version;
}

nlohmann::json vec_json(const vec3& v) { return {double(v.x), double(v.y), double(v.z)}; }
nlohmann::json vec_json(const dvec3& v) { return {v.x, v.y, v.z}; }

/// The nodes a path's frame has moved from where the scene file places them, each with the world
/// transform (glTF space, 16 numbers column by column) that takes it there from the file's
/// placement (Mesh::moved). Blender imports the file and moves a node's object as a whole, so
/// InputError for a node whose primitives moved apart (a spin's mesh prefix naming some of them) or
/// that no transform places (scaled to nothing in the file).
nlohmann::json export_moved_nodes(const Scene& scene) {
  nlohmann::json moved = nlohmann::json::array();
  std::map<int, const Mesh*> seen;  // node -> its first mesh
  for (const Mesh& m : scene.meshes) {
    const double* v = glm::value_ptr(m.moved);
    if (!std::all_of(v, v + 16, [](double x) { return std::isfinite(x); }))
      throw InputError(fmt::format("scene '{}': node {} (mesh '{}') is scaled to nothing where the file places it, so "
                                   "the blender provider, which imports the file, cannot move it to this frame's "
                                   "pose; use the full or povray provider",
                                   scene.name, m.node, m.name));
    const auto [first, fresh] = seen.emplace(m.node, &m);
    if (!fresh) {
      if (first->second->moved != m.moved)
        throw InputError(fmt::format("scene '{}': meshes '{}' and '{}' of node {} move apart in this frame (a spin's "
                                     "mesh prefix names only some of them?); Blender imports a node's primitives as "
                                     "one object and moves them together: choose a prefix that names all of them, or "
                                     "use the full or povray provider",
                                     scene.name, first->second->name, m.name, m.node));
      continue;
    }
    if (m.moved != dmat4(1.0) && m.skinned)
      throw InputError(fmt::format("scene '{}': node {} (mesh '{}') is skinned and moves in this frame; Blender would "
                                   "move its object while its armature stays, which deforms it otherwise than the "
                                   "rigid move this suite renders: use the full or povray provider",
                                   scene.name, m.node, m.name));
    if (m.moved != dmat4(1.0)) moved.push_back({{"node", m.node}, {"matrix", std::vector<double>(v, v + 16)}});
  }
  return moved;
}

/// The EXT_mesh_gpu_instancing instances of each node, each transform column by column (glTF
/// space, in the node's space): Blender 3.4's importer does not read the extension and draws the
/// node's mesh once where the node stands, so the script puts a copy at each instance instead.
nlohmann::json export_instances(const Scene& scene) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& [node, transforms] : scene.instances) {
    nlohmann::json matrices = nlohmann::json::array();
    for (const dmat4& t : transforms) {
      const double* v = glm::value_ptr(t);
      matrices.push_back(std::vector<double>(v, v + 16));
    }
    out.push_back({{"node", node}, {"matrices", matrices}});
  }
  return out;
}

/// Lights that contribute (positive intensity), with their Blender parameters: a spot is a point
/// light whose emission the script shapes with the cone. InputError for a negative colour.
nlohmann::json export_lights(const Scene& scene) {
  nlohmann::json lights = nlohmann::json::array();
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& l = scene.lights[i];
    const std::string label = l.name.empty() ? fmt::format("#{}", i) : fmt::format("'{}' (#{})", l.name, i);
    const float max_colour = std::max({l.color.x, l.color.y, l.color.z});
    const float min_colour = std::min({l.color.x, l.color.y, l.color.z});
    if (!(l.intensity > 0.0f) || max_colour <= 0.0f) continue;  // lights nothing, here as in ours
    if (min_colour < 0.0f)
      throw InputError(fmt::format("scene {}: light {} has a negative colour, which Blender cannot represent",
                                   scene.path, label));
    nlohmann::json j = {{"name", l.name}, {"color", vec_json(l.color)}};
    if (l.type == Light::Type::point || l.type == Light::Type::spot) {
      j["type"] = "point";
      j["position"] = vec_json(l.position);
      j["power_w"] = kPointPowerPerIntensity * double(l.intensity);
      if (l.type == Light::Type::spot) {
        // KHR_lights_punctual's cone (DESIGN §3), in the float arithmetic of the shading core: the
        // script multiplies the point light's emission by clamp((cos - cos_outer) * scale, 0, 1)^2.
        const float cos_outer = std::cos(l.outer_cone), cos_inner = std::cos(l.inner_cone);
        j["spot"] = {{"direction", vec_json(glm::normalize(dvec3(l.direction)))},
                     {"cos_outer", double(cos_outer)},
                     {"scale", double(1.0f / std::max(0.001f, cos_inner - cos_outer))}};
      }
    } else {
      j["type"] = "directional";
      j["direction"] = vec_json(glm::normalize(l.direction));
      j["strength"] = kSunStrengthPerIrradiance * double(l.intensity);
    }
    lights.push_back(std::move(j));
  }
  return lights;
}

/// Writes the textures that materials use as linear float EXRs (RGB), so that Cycles reads exactly
/// the decoded values of the in-memory scene; a texture that a cut-out reads also gets its alpha as
/// a grey EXR of its own (`alpha_file`). Returns their PARAMS entries (null for unused ones).
nlohmann::json export_textures(const Scene& scene, const fs::path& work_dir) {
  std::vector<bool> used(scene.textures.size(), false), cut(scene.textures.size(), false);
  for (const Material& m : scene.materials)
    if (m.base_color_texture >= 0 && static_cast<size_t>(m.base_color_texture) < scene.textures.size()) {
      used[static_cast<size_t>(m.base_color_texture)] = true;
      if (m.alpha_mode == Material::AlphaMode::mask) cut[static_cast<size_t>(m.base_color_texture)] = true;
    }
  nlohmann::json textures = nlohmann::json::array();
  for (size_t t = 0; t < scene.textures.size(); ++t) {
    if (!used[t]) {
      textures.push_back(nullptr);
      continue;
    }
    const Texture& tex = scene.textures[t];
    // One EXR of channels 0-2, or of channel 3 in every channel.
    const auto write = [&](const fs::path& file, bool alpha) {
      Image image(tex.width, tex.height);
      float* rgb = image.add_plane(planes::rgb).data_f32();
      const size_t n = static_cast<size_t>(tex.width) * static_cast<size_t>(tex.height);
      for (size_t i = 0; i < n; ++i)
        for (size_t c = 0; c < 3; ++c) rgb[3 * i + c] = tex.rgba[4 * i + (alpha ? 3 : c)];
      io::write_exr(file, image);
    };
    const fs::path file = work_dir / fmt::format("texture_{}.exr", t);
    write(file, false);
    // Blender has one extension mode for both axes; a texture that repeats along one axis only is
    // repeated along both (reported as a known gap in docs/truth_blender.md).
    const bool repeat = tex.repeat_s || tex.repeat_t;
    textures.push_back({{"file", fs::absolute(file).string()},
                        {"extension", repeat ? "REPEAT" : "EXTEND"},
                        {"mixed_wrap", tex.repeat_s != tex.repeat_t}});
    if (cut[t]) {
      const fs::path alpha = work_dir / fmt::format("texture_{}_alpha.exr", t);
      write(alpha, true);
      textures.back()["alpha_file"] = fs::absolute(alpha).string();
    }
  }
  return textures;
}

nlohmann::json material_json(const Material& m, int texture_count) {
  const int texture = m.base_color_texture >= 0 && m.base_color_texture < texture_count ? m.base_color_texture : -1;
  nlohmann::json j = {{"name", m.name},
                      {"base_color", {double(m.base_color.x), double(m.base_color.y), double(m.base_color.z)}},
                      {"texture", texture},
                      {"texcoord", m.texcoord},
                      {"uv_transform", nullptr},
                      {"cutout", nullptr}};
  // Blender imports the file's own texture coordinates: the transform the loader applied to ours
  // goes into its material.
  if (texture >= 0 && m.has_uv_transform()) j["uv_transform"] = m.uv_transform;
  // A cut-out: opaque where factor alpha x texture alpha >= cutoff (SceneGeometry::opaque_at).
  if (m.alpha_mode == Material::AlphaMode::mask)
    j["cutout"] = {{"factor_alpha", double(m.base_color.w)}, {"cutoff", double(m.alpha_cutoff)}};
  return j;
}

/// The Cycles and colour-management settings the script applies (recorded in TruthRender).
nlohmann::json cycles_settings(int threads) {
  return {{"engine", "CYCLES"},
          {"device", "CPU"},
          {"samples", 1},
          {"adaptive_sampling", false},
          {"denoising", false},
          {"seed", kSeed},
          {"max_bounces", 0},
          {"diffuse_glossy_transmission_volume_transparent_bounces", 0},
          {"direct_light_sampling_type", "NEXT_EVENT_ESTIMATION"},
          {"light_sampling_threshold", 0.0},
          {"sample_clamp_direct", 0.0},
          {"sample_clamp_indirect", 0.0},
          {"path_guiding", false},
          {"pixel_filter_type", "BOX"},
          {"filter_width_px", kFilterWidthPx},
          {"film_transparent", false},
          {"film_exposure", 1.0},
          {"view_transform", "Standard"},
          {"look", "None"},
          {"exposure", 0.0},
          {"gamma", 1.0},
          {"output", "OPEN_EXR RGBA 32-bit float, ZIP"},
          {"threads", threads > 0 ? nlohmann::json(threads) : nlohmann::json("auto")},
          {"materials", "Diffuse BSDF roughness 0 of the albedo in light passes; Emission of albedo x ambient, no BSDF, in the ambient pass; a cut-out mixes in a Transparent BSDF where factor alpha x texture alpha (Linear) is below its cutoff"},
          {"lights", "point: POINT radius 0, power 4 pi I; spot: the same, its emission times KHR_lights_punctual's cone factor from the light-space Normal; directional: SUN angle 0, strength E"},
          {"transparent_bounces", "64 (min 64: no Russian roulette) when a material is a cut-out, else 0"},
          {"world", "Background visible to camera rays only (Light Path 'Is Camera Ray'), sampling_method NONE"},
          {"importer", "import_scene.gltf import_shading=NORMALS (glTF normals as custom split normals) merge_vertices=False"},
          {"shadow_terminator_offsets", 0.0},
          {"texture_interpolation", "Linear (bilinear, no mip-mapping)"},
          {"pass_plan", "ambient term alone (if nonzero), then one render per light; background in the first; summed in that order"}};
}

class BlenderProvider final : public TruthProvider {
 public:
  std::string name() const override { return "blender"; }
  std::string description() const override {
    return "Blender Cycles on the CPU, headless: glTF import plus a generated script, direct light only, one "
           "sample at the pixel centre, one render per light";
  }
  std::optional<std::string> unavailable_reason() const override {
    const Located found = locate_blender();
    if (!found.problem.empty()) return found.problem;
    std::string version;
    try {  // an executable that is not Blender fails here, before anything renders
      version = query_version(found.executable);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    // The script drives the glTF importer of Blender 3.4 (Debian 12's) and later; an older one
    // fails only inside the render with an importer error.
    int major = 0, minor = 0;
    if (std::sscanf(version.c_str(), "Blender %d.%d", &major, &minor) == 2 && (major < 3 || (major == 3 && minor < 4)))
      return fmt::format("{} ({}) is older than Blender 3.4, which the export script needs; install 3.4 or later "
                         "(`ci/install-deps.sh blender`), or point ${} at one",
                         version, found.executable.string(), kExecutableVariable);
    return std::nullopt;
  }
  std::string tool_version() const override { return query_version(executable()); }
  std::string revision() const override { return kRevision; }

  void check_scene(const Scene& scene, const fs::path& scene_file) const override {
    (void)export_lights(scene);  // InputError for a negative light colour
    (void)export_moved_nodes(scene);  // InputError for a node a path's frame cannot place
    if (scene_file.empty() || !fs::is_regular_file(scene_file))
      throw InputError(fmt::format("the blender provider imports the scene's glTF file, but '{}' is not a file; "
                                   "render a scene loaded from a .gltf/.glb file",
                                   scene_file.string()));
    // Blender merges a glTF mesh's primitives into one mesh, whose UV map then covers every
    // primitive: one without the texture coordinates its material reads gets (0, 0) there, where
    // ours takes the factor alone (albedo and a cut-out's coverage).
    for (size_t b = 0; b < scene.meshes.size(); ++b) {
      const Mesh& without = scene.meshes[b];
      if (!without.uvs.empty() || without.material < 0 ||
          scene.materials[static_cast<size_t>(without.material)].base_color_texture < 0)
        continue;
      const int set = scene.materials[static_cast<size_t>(without.material)].texcoord;
      for (const Mesh& with : scene.meshes)
        if (&with != &without && with.node == without.node && !with.uvs.empty() &&
            (with.material < 0 ? 0 : scene.materials[static_cast<size_t>(with.material)].texcoord) == set)
          throw InputError(fmt::format(
              "scene '{}': mesh '{}' (node {}) has a primitive without TEXCOORD_{} beside one with it; Blender "
              "merges them and gives the first coordinates (0, 0), where its textured material (albedo, cut-out) "
              "takes the factor alone: add texture coordinates to that primitive, or use the full or povray provider",
              scene.name, without.name, without.node, set));
    }
    // A primitive whose file normals the loader dropped (some of length zero) is shaded with its
    // geometric normals here; Blender's importer smooths over such normals instead (measured on a
    // sphere with one zero normal: 43.66 dB against the full truth, 73.09 dB against POV-Ray's).
    for (const Mesh& m : scene.meshes)
      if (m.file_normals_dropped)
        throw InputError(fmt::format(
            "scene '{}': mesh '{}' (node {}) has vertex normals of length zero, so this suite shades it with its "
            "geometric normals, while Blender's importer would smooth it with the file's normals: give the "
            "primitive unit normals (or none), or use the full or povray provider",
            scene.name, m.name, m.node));
    // Blender's importer brings in every node of the file; the loaded scene is glTF scene 0 (or
    // `scene`) alone.
    if (scene.nodes_not_loaded > 0)
      throw InputError(fmt::format("the blender provider imports the whole of {}, which has {} node(s) with a mesh "
                                   "or light outside the scene that is loaded (in another glTF scene, or in none); "
                                   "Blender would render them too. Remove them from the file, or use the full or "
                                   "povray provider",
                                   scene_file.string(), scene.nodes_not_loaded));
  }

  std::optional<std::string> prepare(const TruthRequest& request) const override { return set_up(request).command; }

  TruthRender render(const TruthRequest& request) const override {
    const auto start = std::chrono::steady_clock::now();
    const Setup setup = set_up(request);
    const nlohmann::json& params = setup.params;
    const std::chrono::milliseconds limit = setup.limit;
    const std::string& version = setup.version;
    const EyeCamera& eye = setup.eye;
    const fs::path& work_dir = setup.work_dir;
    const std::vector<fs::path>& passes = setup.passes;
    const fs::path& script = setup.script;
    const std::string& command = setup.command;
    const double shift_x = setup.shift_x, shift_y = setup.shift_y;
    std::error_code ec;

    const ProcessResult run = run_process(setup.argv, blender_options(limit));
    const fs::path log = work_dir / "blender_output.txt";
    const bool failed = run.timed_out || !run.ok();
    const std::string log_note = keep_tool_output(log, run.out, failed);
    if (failed)  // a cut pass is no use to a rerun and may fill the disk the render failed on
      for (const fs::path& pass : passes) fs::remove(pass, ec);
    if (run.timed_out)
      throw ToolError(fmt::format("{} did not finish rendering {} within {} and was stopped; {}; the script is kept "
                                  "in {} and the output so far in {}{}; last lines of the output:{}",
                                  version, request.scene_file.string(), format_limit(limit), tool_timeout_hint(),
                                  script.string(), log.string(), log_note, quoted_output(run.out, kQuotedLines)));
    if (failed) {
      // Each pass is a float RGBA image, with room to spare.
      const std::uintmax_t needed =
          passes.size() * std::uintmax_t{16} * eye.width * eye.height + (std::uintmax_t{1} << 20);
      throw ToolError(fmt::format("{} {} rendering {}{}; the script is kept in {} and the full output in {}{}; "
                                  "last lines of the output:{}",
                                  version, run.describe(), request.scene_file.string(), low_disk_note(work_dir, needed),
                                  script.string(), log.string(), log_note, quoted_output(run.out, kQuotedLines)));
    }

    // Sum the passes in light order (the order in which our shading adds the lights).
    TruthRender out;
    out.provider = name();
    out.tool_version = version;
    out.right = Image(eye.width, eye.height);
    float* sum = out.right.add_plane(planes::rgb).data_f32();
    const size_t n = out.right.pixel_count() * 3;
    for (size_t k = 0; k < passes.size(); ++k) {
      if (!fs::is_regular_file(passes[k]))
        throw ToolError(fmt::format("{} exited normally but wrote no image {}; the script is kept in {}, its "
                                    "output in {}{}",
                                    version, passes[k].string(), script.string(), log.string(),
                                    quoted_output(run.out, kQuotedLines)));
      const Image pass = [&] {
        try {
          return io::read_exr(passes[k]);
        } catch (const Error& e) {
          throw ToolError(fmt::format("{} wrote {} but it cannot be read ({}); the script is kept in {}, its output in "
                                      "{}{}",
                                      version, passes[k].string(), e.what(), script.string(), log.string(),
                                      quoted_output(run.out, kQuotedLines)));
        }
      }();
      if (pass.width() != eye.width || pass.height() != eye.height || !pass.has_plane(planes::rgb))
        throw ToolError(fmt::format("{} wrote {} as {}x{} with planes [{}]; expected {}x{} with rgb", version,
                                    passes[k].string(), pass.width(), pass.height(), pass.plane_list(), eye.width,
                                    eye.height));
      const float* p = pass.data_f32(planes::rgb);
      if (k == 0) {
        std::copy(p, p + n, sum);
      } else {
        for (size_t i = 0; i < n; ++i) sum[i] += p[i];
      }
    }

    out.command = command;
    nlohmann::json mixed = nlohmann::json::array();
    for (size_t t = 0; t < params["textures"].size(); ++t)
      if (!params["textures"][t].is_null() && params["textures"][t]["mixed_wrap"].get<bool>())
        mixed.push_back(t);
    out.settings = cycles_settings(request.threads);
    out.settings["revision"] = kRevision;
    out.settings["script"] = script.string();
    out.settings["passes"] = params["passes"];
    out.settings["camera"] = {{"type", "PERSP"},
                              {"sensor_fit", "VERTICAL"},
                              {"sensor_height_mm", kSensorHeightMm},
                              {"lens_mm", params["camera"]["lens_mm"]},
                              {"shift_x", shift_x},
                              {"shift_y", shift_y},
                              {"shift_units", "image height (sensor_fit VERTICAL)"},
                              {"clip_start", kClipStart},
                              {"clip_end", kClipEnd},
                              {"axes", "Blender (x, y, z) = glTF (x, -z, y)"}};
    out.settings["calibration"] = {
        {"point_power_w_per_intensity_w_sr", kPointPowerPerIntensity},
        {"sun_strength_per_irradiance", kSunStrengthPerIrradiance},
        {"sample_offset_px", "about +0.0005 right and up (box filter 0.01 px; measured on lit-plane)"},
        {"ambient", "Emission of the albedo with strength = ambient (radiance = strength x colour)"}};
    if (!mixed.empty()) out.settings["textures_wrapped_on_both_axes"] = mixed;
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return out;
  }

 private:
  /// What a render runs, made ready in the request's work folder: the textures exported, the
  /// script written (its parameters above its fixed body), stale passes removed, and the command.
  struct Setup {
    nlohmann::json params;
    std::chrono::milliseconds limit{0};
    std::string version;
    EyeCamera eye;
    fs::path work_dir;
    std::vector<fs::path> passes;
    fs::path script;
    std::vector<std::string> argv;
    std::string command;
    double shift_x = 0.0, shift_y = 0.0;
  };
  Setup set_up(const TruthRequest& request) const {
    const std::chrono::milliseconds limit = tool_timeout();  // InputError for a malformed value
    const Scene& scene = request.scene.scene();
    check_scene(scene, request.scene_file);
    nlohmann::json params;
    params["lights"] = export_lights(scene);
    const fs::path blender = executable();
    const std::string version = query_version(blender);
    const EyeCamera eye = request.rig.eye(Eye::right);

    std::error_code ec;
    fs::create_directories(request.work_dir, ec);
    if (ec)
      throw IoError(fmt::format("cannot create the work folder {}: {}", request.work_dir.string(), ec.message()));
    const fs::path work_dir = fs::absolute(request.work_dir);

    // Everything the script needs, from the in-memory scene and rig.
    params["scene_file"] = fs::absolute(request.scene_file).string();
    params["moved_nodes"] = export_moved_nodes(scene);
    params["instances"] = export_instances(scene);
    params["textures"] = export_textures(scene, work_dir);
    params["materials"] = nlohmann::json::array();
    for (const Material& m : scene.materials)
      params["materials"].push_back(material_json(m, static_cast<int>(scene.textures.size())));
    Material white;
    white.name = "default";
    params["default_material"] = material_json(white, 0);
    params["background"] = vec_json(scene.background);
    params["ambient"] = double(scene.ambient);
    // A ray may pass through this many cut-out holes (camera and shadow rays alike).
    const bool cutouts = scene.has_cutouts();
    params["transparent_bounces"] = cutouts ? kTransparentBounces : 0;
    const double shift_x = (0.5 * eye.width - eye.cx) / eye.height;
    const double shift_y = (eye.cy - 0.5 * eye.height) / eye.height;
    params["camera"] = {{"origin", vec_json(eye.origin)},
                        {"right", vec_json(eye.right)},
                        {"up", vec_json(eye.up)},
                        {"back", vec_json(eye.back)},
                        {"sensor_height_mm", kSensorHeightMm},
                        {"lens_mm", eye.f_px * kSensorHeightMm / eye.height},
                        {"shift_x", shift_x},
                        {"shift_y", shift_y},
                        {"clip_start", kClipStart},
                        {"clip_end", kClipEnd}};
    params["width"] = eye.width;
    params["height"] = eye.height;
    params["threads"] = std::max(0, request.threads);
    params["seed"] = kSeed;
    params["filter_width"] = kFilterWidthPx;
    // The passes, summed in this order (the order in which our shading adds its terms): the
    // ambient term if any, then each light alone. The background goes with the first pass.
    struct Pass {
      int light = -1;  ///< index into params["lights"], -1 for none
      bool ambient = false;
    };
    std::vector<Pass> plan;
    if (scene.ambient != 0.0f) plan.push_back({-1, true});
    for (size_t k = 0; k < params["lights"].size(); ++k) plan.push_back({static_cast<int>(k), false});
    if (plan.empty()) plan.push_back({-1, false});  // the background alone
    std::vector<fs::path> passes;
    params["passes"] = nlohmann::json::array();
    for (size_t k = 0; k < plan.size(); ++k) {
      passes.push_back(work_dir / fmt::format("pass_{:03}.exr", k));
      fs::remove(passes.back(), ec);  // a stale image must never pass for a new one
      params["passes"].push_back({{"file", passes.back().string()},
                                  {"light", plan[k].light},
                                  {"ambient", plan[k].ambient},
                                  {"background", k == 0}});
    }

    // The script: PARAMS above the fixed body.
    const fs::path script = work_dir / "blender_render.py";
    const std::vector<std::string> argv = {blender.string(), "-b", "--factory-startup", "-noaudio",
                                           "--python-exit-code", "1", "--python", script.string()};
    // As it runs: words quoted, in the environment it is given (no Python environment's modules).
    const std::string command = shell_command(argv, blender_options(limit));
    std::string text;
    text += "# Generated by stereobench (validation/providers/blender.cpp, " + std::string(kRevision) + ").\n";
    text += "# Renders the right eye of a stereo rig with Blender Cycles; re-run it by hand with:\n";
    text += "#   " + printable(command) + "\n";  // a line break in a path would end the comment
    std::string params_text;
    try {
      params_text = params.dump(2);
    } catch (const nlohmann::json::type_error&) {
      throw InputError(fmt::format("the blender provider gives Blender its paths as JSON text, which holds UTF-8 only, "
                                   "and the scene file {} or the work folder {} has a name that is not UTF-8; rename "
                                   "it, or use the full or povray provider",
                                   printable(params["scene_file"].get<std::string>()), printable(work_dir.string())));
    }
    text += "import json\n\nPARAMS = json.loads(r\"\"\"" + params_text + "\"\"\")\n";
    text += blender_script_body();
    io::write_text_atomically(script, text);
    return Setup{std::move(params), limit, version, eye, work_dir, std::move(passes), script, argv, command,
                 shift_x, shift_y};
  }

  static fs::path executable() {
    Located found = locate_blender();
    if (!found.problem.empty()) throw ToolError("blender provider unavailable: " + found.problem);
    return found.executable;
  }
};

}  // namespace

std::unique_ptr<TruthProvider> make_blender_provider() { return std::make_unique<BlenderProvider>(); }

}  // namespace sb::validation
