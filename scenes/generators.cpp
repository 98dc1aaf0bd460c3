// Registry of the procedural scene generators: lookup, parameter checking and timed generation.
#include "scenes/generators.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/io/gltf_loader.hpp"
#include "scenes/scene_generator.hpp"

namespace sb::scenes {

namespace {

/// Every generator entry, in the order `stereobench scenes list` shows them.
const std::vector<GeneratorEntry>& entries() {
  static const std::vector<GeneratorEntry> list = {
      spheres_generator(),   atrium_generator(),   bistro_generator(),         temple_generator(),
      dragon_generator(),    complexity_generator(), lit_plane_generator(),    box_wall_generator(),
      thin_pole_generator(), textured_plane_generator(), slanted_plane_generator(), fence_generator(),
  };
  return list;
}

const GeneratorEntry& find_entry(const std::string& name) {
  for (const GeneratorEntry& e : entries())
    if (e.info.name == name) return e;
  std::string known;
  for (const GeneratorEntry& e : entries()) known += (known.empty() ? "" : ", ") + e.info.name;
  throw InputError(fmt::format("unknown scene generator '{}' (known: {})", name, known));
}

std::string format_value(double v) {
  return v == std::floor(v) && std::fabs(v) < 1e15 ? fmt::format("{:.0f}", v) : fmt::format("{}", v);
}


}  // namespace

double GeneratorContext::param(const std::string& name) const {
  const auto it = params.find(name);
  if (it == params.end()) throw std::logic_error(fmt::format("scene generator reads undeclared parameter '{}'", name));
  return it->second;
}

int GeneratorContext::int_param(const std::string& name) const { return static_cast<int>(std::llround(param(name))); }

void set_default_view(GltfBuilder& builder, const DefaultView& view) {
  const CameraPose pose = CameraPose::look_at(dvec3(view.eye), dvec3(view.target));
  RigDefaults rig;
  rig.interaxial = 0.064;
  rig.convergence = view.convergence > 0.0 ? view.convergence : glm::length(dvec3(view.target) - dvec3(view.eye));
  rig.width = 1920;
  rig.height = 1080;
  builder.set_camera("camera", pose, degrees_to_radians(view.yfov_degrees), view.znear, view.zfar, rig);
}

const std::vector<GeneratorInfo>& generators() {
  static const std::vector<GeneratorInfo> list = [] {
    std::vector<GeneratorInfo> infos;
    for (const GeneratorEntry& e : entries()) infos.push_back(e.info);
    return infos;
  }();
  return list;
}

const GeneratorInfo& find_generator(const std::string& name) {
  const GeneratorEntry& entry = find_entry(name);
  for (const GeneratorInfo& info : generators())
    if (info.name == entry.info.name) return info;
  throw std::logic_error("scene generator registry out of step");
}

GenerateResult generate(const std::string& name, const GenerateOptions& options, const std::filesystem::path& out_path) {
  const auto start = std::chrono::steady_clock::now();
  const GeneratorEntry& entry = find_entry(name);
  GeneratorContext context;
  context.seed = options.seed;
  context.params = resolve_params(entry.info, options.params);

  // Check the output name before spending time on the geometry.
  std::string ext = out_path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext != ".glb" && ext != ".gltf")
    throw InputError(fmt::format("cannot write scene '{}' to '{}': the file name must end in .glb or .gltf", name,
                                 out_path.string()));

  GltfBuilder builder(name, options.seed, context.params);
  entry.build(context, builder);
  // Refused before anything is written: no file that nothing could load.
  if (builder.stats().triangles > io::kMaxSceneTriangles) {
    std::string given;
    for (const auto& [key, value] : options.params) given += fmt::format("{}{}={}", given.empty() ? "" : " ", key, value);
    throw InputError(fmt::format("scene '{}' with {} expands to {} triangles (instances counted), more than the {} a "
                                 "scene may hold; choose smaller parameters",
                                 name, given.empty() ? "its default parameters" : given, builder.stats().triangles,
                                 io::kMaxSceneTriangles));
  }

  GenerateResult result;
  result.path = out_path;
  result.bytes = builder.write(out_path);
  result.triangles = builder.stats().triangles;
  result.vertices = builder.stats().vertices;
  result.lights = builder.stats().lights;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

std::map<std::string, double> resolve_params(const GeneratorInfo& info, const std::map<std::string, double>& overrides) {
  std::map<std::string, double> values;
  for (const GeneratorParam& p : info.params) values[p.name] = p.default_value;
  for (const auto& [name, value] : overrides) {
    const GeneratorParam* param = nullptr;
    for (const GeneratorParam& p : info.params)
      if (p.name == name) param = &p;
    if (param == nullptr) {
      std::string known;
      for (const GeneratorParam& p : info.params) known += (known.empty() ? "" : ", ") + p.name;
      throw InputError(fmt::format("scene '{}' has no parameter '{}' (its parameters: {})", info.name, name,
                                   known.empty() ? "none" : known));
    }
    if (!(value >= param->min_value && value <= param->max_value))
      throw InputError(fmt::format("scene '{}': parameter '{}' = {} is out of range [{}, {}]", info.name, name,
                                   format_value(value), format_value(param->min_value), format_value(param->max_value)));
    if (param->integer && value != std::floor(value))
      throw InputError(fmt::format("scene '{}': parameter '{}' = {} must be a whole number in [{}, {}]", info.name, name,
                                   format_value(value), format_value(param->min_value), format_value(param->max_value)));
    values[name] = value;
  }
  return values;
}

}  // namespace sb::scenes
