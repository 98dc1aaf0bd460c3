// Resolves a scene argument — a file path or the name of a built-in scene — to a glTF file,
// generating built-in scenes on first use into a cache folder.
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "renderer/scene.hpp"
#include "scenes/generators.hpp"

namespace sb::scenes {

/// The folder built-in scenes are generated into: $STEREOBENCH_SCENES if set, else out/scenes.
[[nodiscard]] std::filesystem::path default_scenes_dir();

/// Whether a scene argument names a glTF file (a .gltf/.glb extension, or a '/' in it) rather than
/// a built-in scene.
[[nodiscard]] bool is_scene_file_spec(const std::string& spec);

/// A path to an existing .gltf/.glb file is returned as is. A built-in scene name returns
/// `<scenes_dir>/<file>`, generated (with default seed and parameters) when missing or written by
/// another version of the generator
/// (the stamp beside it records a hash of the generator sources). Anything else is an InputError listing the built-in names.
[[nodiscard]] std::filesystem::path resolve_scene(const std::string& spec,
                                                  const std::filesystem::path& scenes_dir);

/// Generates a built-in scene with its default seed and parameters into `scenes_dir` and stamps it,
/// so that resolve_scene() reuses it until the generator's version changes.
GenerateResult generate_builtin(const std::string& name, const std::filesystem::path& scenes_dir);

/// The file name of a built-in scene generated with `seed` and these parameter overrides: the
/// generator's file name for the defaults, otherwise its stem, `_seed-<seed>` when the seed is not
/// 1, `_<param>-<value>` per override and the extension, e.g. `spheres_seed-35_count-500.glb`. A
/// variant never takes the default file's name, which commands naming the scene load.
[[nodiscard]] std::string variant_file_name(const GeneratorInfo& info, uint64_t seed,
                                            const std::map<std::string, double>& params);

/// A built-in scene with seed 1 and these parameter overrides (checked like `scenes generate
/// --param`), cached like the default one as `<scenes_dir>/<stem>_<param>-<value>....<ext>`, e.g.
/// `dragon_lights-10.glb`, beside a stamp of its own. Without overrides it is resolve_scene(name).
[[nodiscard]] std::filesystem::path resolve_builtin(const std::string& name,
                                                    const std::map<std::string, double>& params,
                                                    const std::filesystem::path& scenes_dir);

/// The file resolve_builtin(name, params, scenes_dir) reads or generates, without generating it.
[[nodiscard]] std::filesystem::path builtin_path(const std::string& name, const std::map<std::string, double>& params,
                                                 const std::filesystem::path& scenes_dir);

/// The stamp beside a generated scene file, which says what generated it (a scene file without
/// its stamp is generated again).
[[nodiscard]] std::filesystem::path stamp_path(const std::filesystem::path& scene);

/// A scene loaded for rendering, with what the command line chose of it.
struct LoadedScene {
  Scene scene;
  std::filesystem::path file;  ///< the glTF file it came from
  size_t lights_in_file = 0;   ///< lights before a --lights selection
};

/// resolve_scene + load_gltf, the loader's warnings printed to stderr, and with `lights` the
/// scene's first N lights kept (keep_first_lights).
[[nodiscard]] LoadedScene load_scene(const std::string& spec, const std::filesystem::path& scenes_dir,
                                     std::optional<int> lights = std::nullopt);

}  // namespace sb::scenes
