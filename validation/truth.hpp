// Ground truth for the right eye (DESIGN §6.1): the providers that render it — `full` (this
// suite's own ray tracer), `blender` (Cycles) and `povray` — behind one interface, each exporting
// the scene, camera and lights itself and recording the version of the tool it ran.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/image.hpp"
#include "renderer/render_scene.hpp"
#include "renderer/rig.hpp"

namespace sb::validation {

/// What to render: the right eye of `rig` looking at `scene` (its lights as loaded, after any
/// --lights selection), with the shading of DESIGN §3.
struct TruthRequest {
  const RenderScene& scene;
  /// The glTF file the scene was loaded from (the Blender provider imports it; its meshes,
  /// materials and textures are those of `scene`, its lights are replaced by `scene`'s).
  std::filesystem::path scene_file;
  StereoRig rig;
  /// A folder for the provider's exports, scripts and raw tool output (created if missing; kept so
  /// that a surprising render can be inspected and re-run by hand).
  std::filesystem::path work_dir;
  int threads = 0;  ///< 0 = all cores
  /// For a truth served from the cache: make the provider's export and script ready in work_dir
  /// (TruthProvider::prepare) and give the command that renders it there, rather than the command
  /// of the run that rendered it (validate; a sweep's cells keep that command and write nothing).
  bool prepare_on_cache_hit = false;
};

/// A rendered right eye and how it was made.
struct TruthRender {
  /// The right eye with at least the "rgb" plane: linear radiance in the units of DESIGN §3
  /// (the provider's calibration constants already applied), W x H of the rig.
  Image right;
  std::string provider;      ///< "full", "blender", "povray"
  std::string tool_version;  ///< e.g. "stereobench 0.1.0", "Blender 3.4.1", "POV-Ray 3.7.0.10"
  /// The settings the tool was run with and the calibration constants applied (recorded in
  /// results and provenance files).
  nlohmann::json settings = nlohmann::json::object();
  std::string command;   ///< the external command line run, empty for `full`
  double seconds = 0.0;  ///< wall time of the render, export and tool start-up included
};

/// A ground-truth provider.
class TruthProvider {
 public:
  virtual ~TruthProvider() = default;
  [[nodiscard]] virtual std::string name() const = 0;
  /// One line for `--help` and listings.
  [[nodiscard]] virtual std::string description() const = 0;
  /// Empty when the provider can render here; otherwise why not and what to do (e.g. "blender not
  /// found on PATH; install it with `ci/install-deps.sh blender`").
  [[nodiscard]] virtual std::optional<std::string> unavailable_reason() const = 0;
  /// The tool's version as it reports it; ToolError when unavailable.
  [[nodiscard]] virtual std::string tool_version() const = 0;
  /// A string that changes whenever the provider's export, settings or calibration change, so
  /// that cached renders made by an older provider are not reused.
  [[nodiscard]] virtual std::string revision() const = 0;
  /// InputError naming what of `scene` (loaded from `scene_file`, its lights after any --lights
  /// selection) this provider cannot render faithfully: a light its tool cannot reproduce, nodes
  /// its importer would bring in besides the loaded scene. Checked before a cache lookup, so that a
  /// render an older provider made of such a scene is not served, and by sweeps before any cell
  /// runs. The default accepts every scene.
  virtual void check_scene(const Scene& scene, const std::filesystem::path& scene_file) const;
  /// Renders the right eye (check_scene first). ToolError when the tool is missing or fails (its
  /// output quoted), InputError for a scene feature the provider cannot export (named).
  [[nodiscard]] virtual TruthRender render(const TruthRequest& request) const = 0;
  /// Makes ready in request.work_dir what render() would run there (the export, scripts,
  /// configuration), without rendering, and returns the command that renders it there, as
  /// TruthRender::command gives it: for a truth served from the cache, whose recorded command
  /// names the work folder of the run that rendered it. Nothing for a provider without a command
  /// (the built-in one, the default).
  [[nodiscard]] virtual std::optional<std::string> prepare(const TruthRequest& request) const;
};

/// The image with its "rgb" plane only (what caches and references keep of a render);
/// InputError without an "rgb" plane.
[[nodiscard]] Image rgb_plane_only(const Image& image);

/// What a provider's settings say makes its truth differ from the scene (POV-Ray's
/// export_warnings, Blender's textures_wrapped_on_both_axes), as lines for the terminal; also for
/// a truth from the cache, whose settings are kept. And an over-exposed truth: where more than
/// kOverExposedFraction of its pixels clip (a channel at 1.0 or above, 255 in the 8-bit images the
/// metrics compare), no pipeline's error can show there, so a comparison would pass blind.
[[nodiscard]] std::vector<std::string> truth_warnings(const TruthRender& render);
inline constexpr double kOverExposedFraction = 0.25;

/// The fraction of the image's pixels whose "rgb" has a channel at 1.0 or above (NaN counts).
[[nodiscard]] double clipped_fraction(const Image& image);

/// The providers' names in their canonical order: full, blender, povray.
[[nodiscard]] std::vector<std::string> truth_provider_names();
/// A provider by name; InputError listing the names for an unknown one.
[[nodiscard]] std::unique_ptr<TruthProvider> make_truth_provider(std::string_view name);

}  // namespace sb::validation
