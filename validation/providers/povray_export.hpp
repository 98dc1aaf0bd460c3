// The scene and the right eye written as POV-Ray 3.7 scene description language (SDL) for the
// `povray` ground-truth provider (DESIGN §6.1): mesh2 objects, a perspective camera with the
// eye's off-axis window, lights calibrated to the shading of DESIGN §3, linear base colour
// textures as half-float EXR image maps. docs/truth_povray.md derives every constant.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/rig.hpp"
#include "renderer/scene.hpp"

namespace sb::validation::povray {

/// The export's revision: changes whenever the SDL written for a given scene and eye changes.
inline constexpr const char* kExportRevision = "povray-export-3";
/// max_trace_level of a scene with cut-outs: how many holes a camera or shadow ray may pass.
inline constexpr int kCutoutTraceLevel = 64;

/// Point lights fall off as 2 / (1 + (d / fd)^2) in POV-Ray 3.7 (fade_power 2); fd is this
/// fraction of the light's smallest distance to any triangle, so that the relative deviation from
/// 2 fd^2 / d^2 (the exact inverse square law) is at most kFadeFraction^2 = 1e-8 on every surface.
inline constexpr double kFadeFraction = 1e-4;
/// Smallest fade distance written (m): a light touching a surface still gets a valid fade.
inline constexpr double kMinFadeDistance = 1e-8;

/// One light as written.
struct ExportedLight {
  std::string name;
  std::string type;              ///< "point" or "directional"
  double colour[3] = {0, 0, 0};  ///< the light_source colour written
  double fade_distance = 0.0;    ///< point lights: fd (m)
  double min_distance = 0.0;     ///< point lights: smallest distance to a triangle (m)
  /// point lights: bound of |attenuation / (2 fd^2 / d^2) - 1| over the scene, (fd / d_min)^2
  double max_falloff_error = 0.0;
};

/// What export_scene wrote.
struct ExportResult {
  std::filesystem::path sdl_file;                  ///< the .pov file
  std::vector<std::filesystem::path> texture_files;  ///< one EXR per textured material, and a cut-out's coverage map
  std::size_t sdl_bytes = 0;
  std::size_t meshes = 0;     ///< mesh2 objects written (meshes without triangles, and cut-outs transparent everywhere, are skipped)
  std::size_t triangles = 0;
  std::vector<ExportedLight> lights;
  /// Differences from the shading of DESIGN §3 that the export cannot avoid (e.g. a clamped
  /// texture read outside [0, 1]); empty for an exact export.
  std::vector<std::string> warnings;
  /// The camera as written and the calibration constants, for TruthRender::settings.
  nlohmann::json settings = nlohmann::json::object();
};

/// InputError for a scene feature POV-Ray cannot render with the shading of DESIGN §3: a spot
/// light (named).
void check_exportable(const Scene& scene);

/// Writes `dir`/scene.pov and the texture files beside it (names relative to `dir`, so that
/// POV-Ray runs with `dir` as its working folder, the one its I/O restrictions allow). The camera
/// is `eye` exactly: pixel (i, j) of the render is the ray through EyeCamera pixel centre
/// (i + 0.5, j + 0.5). InputError as check_exportable, before anything is written; IoError when a file cannot be written.
[[nodiscard]] ExportResult export_scene(const Scene& scene, const EyeCamera& eye, const std::filesystem::path& dir);

/// Smallest distance from `p` to any triangle of the scene (infinity for a scene without
/// triangles).
[[nodiscard]] double min_distance_to_scene(const Scene& scene, const dvec3& p);

}  // namespace sb::validation::povray
