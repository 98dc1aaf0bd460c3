// The pipeline interface and registry. A pipeline is one file in renderer/pipelines/ that
// registers itself by name (SB_REGISTER_PIPELINE) and describes itself; the harness owns the
// loop, threads, timing and I/O.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "renderer/image.hpp"
#include "renderer/parallel.hpp"
#include "renderer/render_scene.hpp"
#include "renderer/rig.hpp"
#include "renderer/stats.hpp"

namespace sb {

class PipelineOptions;

/// One option a pipeline accepts, with its default and help.
struct OptionSpec {
  std::string name;
  std::string default_value;
  std::string help;
};

/// What a pipeline is: its source paper and section, its options, and the tolerance the
/// conformance test holds it to against plain-rt.
struct PipelineInfo {
  std::string name;
  std::string paper;     ///< e.g. "Al-Hagri 2012"
  std::string section;   ///< e.g. "3.1.1 (naive)"
  std::string summary;   ///< one line
  std::vector<OptionSpec> options;
  double min_psnr_left = 50.0;   ///< dB against plain-rt's left eye on the analytic scenes
  double min_psnr_right = 50.0;  ///< dB against plain-rt's right eye on the analytic scenes
  /// Checks option values (ranges, choices) the way render() reads them, throwing InputError naming
  /// the option; PipelineOptions calls it, so a bad value is refused before anything renders.
  void (*check_options)(const PipelineOptions&) = nullptr;
  /// Checks what the options cannot do with a rig (a buffer sized by the disparity, say), throwing
  /// InputError naming the option and what to change; callers run it for every chosen pipeline
  /// (PipelineEntry::check_rig) before any of them renders with that rig (a sweep: for every cell
  /// before the first runs).
  void (*check_rig)(const PipelineOptions&, const StereoRig&) = nullptr;
};

/// Options after checking: every key is one the pipeline declared (InputError otherwise, naming
/// the key and listing the valid ones), every value one the pipeline accepts (its check_options);
/// missing keys take their defaults.
class PipelineOptions {
 public:
  PipelineOptions() = default;
  PipelineOptions(const PipelineInfo& info, const std::map<std::string, std::string>& given);

  [[nodiscard]] const std::string& get(const std::string& name) const;
  [[nodiscard]] double get_double(const std::string& name) const;
  [[nodiscard]] int get_int(const std::string& name) const;
  [[nodiscard]] bool get_bool(const std::string& name) const;
  [[nodiscard]] const std::map<std::string, std::string>& values() const { return values_; }

 private:
  std::string pipeline_;
  std::map<std::string, std::string> values_;
};

/// The stage eye of a rendered eye's own work (StageEye::left or StageEye::right).
[[nodiscard]] inline StageEye stage_eye(Eye eye) { return eye == Eye::right ? StageEye::right : StageEye::left; }

/// A pipeline's output: both eyes with AOVs and source tags, per-stage timings and counters.
struct StereoResult {
  Image left;
  Image right;
  Timings timings;
  Counters counters;
  /// Diagnostic images a pipeline was asked for (e.g. "grid" for the warping-grid overlay), each
  /// with an "rgb" plane; `stereobench render` writes them as <stem>_<name>.png.
  std::vector<std::pair<std::string, Image>> extras;
};

/// What the harness hands a pipeline besides scene, rig and options.
struct RenderContext {
  const Executor& executor;
};

class Pipeline {
 public:
  virtual ~Pipeline() = default;
  [[nodiscard]] virtual const PipelineInfo& info() const = 0;
  [[nodiscard]] virtual StereoResult render(const RenderScene& scene, const StereoRig& rig,
                                            const PipelineOptions& options, const RenderContext& ctx) const = 0;
};

/// Every registered pipeline, sorted by name.
[[nodiscard]] std::vector<const Pipeline*> pipelines();
/// Their names, in the same order.
[[nodiscard]] std::vector<std::string> pipeline_names();
/// A list of pipeline entries with "all" replaced by every registered name the list has not named
/// before it. A name after "all" that "all" already includes is an InputError (`what` names the
/// list, e.g. "--pipelines"; empty for a caller that places the message itself, as a sweep file
/// does); other repeats are left to parse_pipeline_entries.
[[nodiscard]] std::vector<std::string> expand_all_pipelines(const std::vector<std::string>& names,
                                                            const std::string& what);
/// The pipeline of that name; InputError listing the registered names otherwise.
[[nodiscard]] const Pipeline& find_pipeline(const std::string& name);

/// A pipeline as commands name it (validate, bench, sweeps): a registered name, or a variant that
/// fixes some of its options in the name, "NAME:KEY=VALUE[:KEY=VALUE...]" (e.g.
/// "bidir-warp:occlusion=ztest"). A variant is run, timed and reported under its whole name, beside
/// the pipeline itself.
struct PipelineEntry {
  std::string name;  ///< as written
  const Pipeline* pipeline = nullptr;
  std::map<std::string, std::string> fixed;  ///< the options the name fixes

  /// The options it runs with: `given` (options given for its pipeline), the fixed ones over them,
  /// all checked by the pipeline; an InputError about a variant names the entry.
  [[nodiscard]] PipelineOptions options(const std::map<std::string, std::string>& given = {}) const;
  /// The pipeline's check_rig for `options` (made by options()) and `rig`; an InputError about a
  /// variant names the entry.
  void check_rig(const PipelineOptions& options, const StereoRig& rig) const;
  /// Whether `other` names the same variant: the same pipeline fixing the same options to the same
  /// values, in whatever order and spelling either name gives them (a boolean as yes/on/1/true, a
  /// number as 2 or 2.0). Entries that fix different options are different variants even where the
  /// values are the pipeline's defaults: options given for the pipeline (--option,
  /// [options.NAME]) apply under each entry's own.
  [[nodiscard]] bool same_variant(const PipelineEntry& other) const;
  /// Whether the entry fixes option `key` to a value other than `value`, compared as same_variant
  /// compares them (4 and 4.0 are one value).
  [[nodiscard]] bool fixes_otherwise(const std::string& key, const std::string& value) const;
};

/// The name of the entry of `listed` that names the same variant as `entry`, if there is one.
[[nodiscard]] std::optional<std::string> find_same_variant(const std::vector<PipelineEntry>& listed,
                                                           const PipelineEntry& entry);

/// Parses an entry: InputError for an unknown pipeline, a part that is not KEY=VALUE, a key fixed
/// twice, or a name longer than 160 characters (it names files). Option names and values are checked by
/// PipelineEntry::options.
[[nodiscard]] PipelineEntry parse_pipeline_entry(const std::string& name);

/// The registered pipeline an entry names: its text before the first ':'.
[[nodiscard]] std::string entry_pipeline_name(const std::string& entry);
/// The options an entry fixes, read from its text alone; InputError as parse_pipeline_entry.
[[nodiscard]] std::map<std::string, std::string> entry_fixed_options(const std::string& entry);

/// A file-name stem for an entry's images and records: the name with ':' written '@' and any
/// character other than letters, digits and "._-=+@" written '_'
/// ("bidir-warp:occlusion=ztest" -> "bidir-warp@occlusion=ztest"; a pipeline's own name is kept).
[[nodiscard]] std::string entry_file_stem(const std::string& entry);

/// Parses every entry and refuses one named twice (also as the same variant with its options in
/// another order), or two whose file stems coincide (InputError; `what` names the list, e.g.
/// "--pipelines", at the head of the message; "" for none).
[[nodiscard]] std::vector<PipelineEntry> parse_pipeline_entries(const std::vector<std::string>& names,
                                                                const std::string& what);

/// Adds a pipeline to the registry at static-initialisation time.
struct PipelineRegistration {
  explicit PipelineRegistration(std::unique_ptr<Pipeline> pipeline);
};

#define SB_REGISTER_PIPELINE(Type) \
  static const ::sb::PipelineRegistration sb_pipeline_registration_##Type{std::make_unique<Type>()}

}  // namespace sb
