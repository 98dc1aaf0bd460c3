// Built-in scene cache: a scene is regenerated when its stamp (generator version, seed,
// parameters) no longer matches.
#include "scenes/catalog.hpp"

#include <cstdlib>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "sb_scenes_hash.hpp"
#include "sb_version.hpp"
#include "scenes/generators.hpp"

namespace sb::scenes {

namespace fs = std::filesystem;

namespace {

fs::path stamp_path(const fs::path& scene) { return fs::path(scene.string() + ".stamp"); }

std::string stamp_text(const std::string& name) {
  return fmt::format("stereobench {} generators {} scene {} seed 1 default parameters\n", SB_VERSION_STRING,
                     SB_SCENES_SOURCE_HASH, name);
}

}  // namespace

fs::path default_scenes_dir() {
  if (const char* env = std::getenv("STEREOBENCH_SCENES"); env && *env) return env;
  return fs::path("out") / "scenes";
}

fs::path resolve_scene(const std::string& spec, const fs::path& scenes_dir) {
  std::error_code ec;
  const fs::path as_path(spec);
  const std::string ext = as_path.extension().string();
  if (ext == ".gltf" || ext == ".glb" || spec.find('/') != std::string::npos) {
    if (!fs::exists(as_path, ec))
      throw InputError(fmt::format("{}: scene file does not exist; check the path, or give a built-in scene "
                                   "name (see `stereobench scenes list`)", spec));
    return as_path;
  }
  const GeneratorInfo* info = nullptr;
  for (const GeneratorInfo& g : generators())
    if (g.name == spec) info = &g;
  if (!info) {
    std::string names;
    for (const GeneratorInfo& g : generators()) names += (names.empty() ? "" : ", ") + g.name;
    throw InputError(fmt::format("unknown scene '{}': not a .gltf/.glb file and not a built-in scene ({})",
                                 spec, names));
  }
  const fs::path path = scenes_dir / info->file_name;
  if (fs::exists(path, ec) && fs::exists(stamp_path(path), ec)) {
    try {
      if (io::read_file(stamp_path(path)) == stamp_text(info->name)) return path;
    } catch (const IoError&) {
      // An unreadable stamp means the cached scene is regenerated below.
    }
  }
  return generate_builtin(info->name, scenes_dir).path;
}

GenerateResult generate_builtin(const std::string& name, const fs::path& scenes_dir) {
  const GeneratorInfo& info = find_generator(name);
  GenerateResult r = generate(info.name, GenerateOptions{}, scenes_dir / info.file_name);
  io::write_text_atomically(stamp_path(r.path), stamp_text(info.name));
  return r;
}

}  // namespace sb::scenes
