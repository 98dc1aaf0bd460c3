// Options shared by several subcommands (rig, scene folder), declared once with their help.
#pragma once

#include <cstdio>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "renderer/image.hpp"
#include "renderer/parallel.hpp"
#include "renderer/render_scene.hpp"
#include "renderer/rig.hpp"
#include "renderer/scene.hpp"

namespace sb::cli {

/// The stereo-rig options (--interaxial, --max-disparity, --convergence, --resolution, --vfov).
struct RigCli {
  std::optional<double> interaxial;
  std::optional<double> max_disparity;
  std::optional<double> convergence;
  std::optional<std::string> resolution;
  std::optional<double> vfov_deg;

  void add_to(CLI::App& app);
  /// Checks the values (positive, finite, in range) and converts them; InputError otherwise.
  [[nodiscard]] RigOverrides overrides() const;
};

/// The width of a terminal table's pipeline column: 16, or the longest name (a variant's,
/// "NAME:KEY=VALUE...", may be longer).
[[nodiscard]] size_t pipeline_column(const std::vector<std::string>& names);

/// --scenes-dir: where built-in scenes are generated and cached.
void add_scenes_dir_option(CLI::App& app, std::string& dir);

/// --lights N: render the scene with its first N lights only (see scenes::load_scene).
CLI::Option* add_lights_option(CLI::App& app, std::optional<int>& lights);

/// "5 lights", or "first 3 of 5 lights" when some were dropped.
[[nodiscard]] std::string describe_lights(size_t used, size_t in_file);

/// A number for a terminal table: `v` times `scale` with `decimals` decimals, "-" where it is
/// undefined (NaN: absent, or a recall with nothing disoccluded) and "inf" where it is infinite
/// (the PSNR of identical images).
[[nodiscard]] std::string table_number(double v, int decimals, double scale = 1.0);

/// Parses NAME=VALUE items (--option) into a map; InputError for an item without '='.
[[nodiscard]] std::map<std::string, std::string> parse_key_values(const std::vector<std::string>& items,
                                                                  const char* option);

/// The entries of a list option given comma-separated and/or repeated ("a,b" or "a" "b"), in
/// order. InputError naming the option and the item for an empty entry (a doubled, leading or
/// trailing comma, or an empty item), which would otherwise drop a name the user meant to give.
[[nodiscard]] std::vector<std::string> split_list(const std::vector<std::string>& items, const char* option);

/// A file named on the command line: the option or argument that names it, and its path.
struct NamedPath {
  const char* name;
  const std::string* path;
};

/// Refuses an output that would overwrite an input or another output: the same file by path, by
/// another spelling of it, or through a link. Empty paths and "-" (standard output) are skipped.
void refuse_overwriting(std::initializer_list<NamedPath> inputs, std::initializer_list<NamedPath> outputs);

/// Refuses, before any work, an output folder named by `option` that cannot be made or written
/// (io::folder_cannot_be_made, which leaves nothing made): prepare_output_folder makes it once the
/// input is known to be good, so that a refused run leaves no empty folder. IoError as there.
void check_output_folder(const std::string& folder, const char* option);

/// Makes an output folder named by `option` (and its parents) and checks that files can be
/// created in it, before any rendering: a folder that cannot be written fails at once, not after
/// the work. IoError naming the option, the folder and the reason.
void prepare_output_folder(const std::string& folder, const char* option);

/// Refuses (InputError) a run into `out` whose outputs would replace or remove its scene file or a
/// file the scene reads (a texture or buffer beside it named like an output), by name or through a
/// link either way: every entry of `out` whose name starts with one of `prefixes` (the names the
/// run writes, and the earlier files of those names it replaces or removes) is compared with them.
/// Called before the work, which may take hours; `run` names the run in the message ("render").
void refuse_replacing_inputs(const std::filesystem::path& scene_file, const Scene& scene,
                             const std::filesystem::path& out, const std::vector<std::string>& prefixes,
                             const std::string& run);

/// prepare_output_folder, then `work`. When `work` throws, the folders this call made are removed
/// again if nothing was written into them (no file at any depth), and the error passed on: a run
/// that stops (a full disk, an input refused once read) leaves no empty output folder behind.
void in_output_folder(const std::string& folder, const char* option, const std::function<void()>& work);

/// Removes what an earlier run left at an output path before this run writes anything, so that a
/// run stopped on the way leaves no output that looks like its own (a CI step publishing a JUnit
/// file finds none; records do not sit beside an earlier run's summary). `what` names the output
/// in the message ("--junit", "summary"). Only the regular file the path names is removed (see
/// io::remove_output_file: a device, pipe or /dev/stdout stays). IoError when it cannot be removed;
/// nothing for an empty path or "-".
void remove_earlier_output(const std::filesystem::path& path, const std::string& what);

/// remove_earlier_output for each output; one that cannot be removed does not keep the others:
/// all are tried, then the first error is thrown.
void remove_earlier_outputs(std::initializer_list<NamedPath> outputs);

/// remove_earlier_outputs for the outputs that name no input file (by refuse_overwriting's rule):
/// run before any check, so that a refused run leaves no earlier output behind, while an output
/// that names an input (refused afterwards) keeps that input.
void remove_earlier_outputs_sparing(std::initializer_list<NamedPath> inputs, std::initializer_list<NamedPath> outputs);

/// Removes what a failing run wrote at these output paths (best effort; as remove_earlier_output:
/// regular files only, "" and "-" skipped), so that none is left beside its error.
void discard_outputs(std::initializer_list<NamedPath> outputs) noexcept;

/// Runs `write`, which writes several output files one after another, all or none: when it throws,
/// those of `outputs` already written are removed (discard_outputs) before the error goes on, so
/// that a run stopped on the way leaves none of them behind (a JUnit file without its JSON would
/// read as the run's verdict).
void write_all_or_none(std::initializer_list<NamedPath> outputs, const std::function<void()>& write);

/// Runs `write`, which writes the output file an option names; an IoError it throws is given the
/// option's name and what to do, e.g. "--json: cannot open /proc/x.json: ...; give --json a path
/// you can write".
void write_for_option(const std::string& option, const std::function<void()>& write);

/// Writes an output file an option names (io::write_text_atomically, through write_for_option).
void write_option_file(const std::string& option, const std::string& path, const std::string& text);

/// Writes `text` and a newline to standard output and flushes it: IoError (exit 4) when it cannot
/// take them (a full disk behind a redirection, a closed pipe), so that "--json -" never ends in
/// success with the JSON lost.
void print_to_stdout(const std::string& text);

/// Writes `text` as it is to `stream` (standard output or error) and flushes it: IoError (exit 4)
/// when the stream cannot take it.
void print_to(std::FILE* stream, const std::string& text);

/// Checks, before the work, that the folder of an output file named by `option` (a --json written
/// after a long benchmark) can be written: a missing one is made, probed and removed again (the
/// file's write makes it for good), so a run refused later leaves no empty folder. IoError naming
/// the option and the reason; nothing for "" (no file), "-" (standard output) or a bare file name.
void prepare_output_file_folder(const std::string& file, const char* option);

/// Warns on standard error when either eye sees geometry in front of its near plane
/// (pixels_before_near_plane): the rasterizing pipelines clip it, ray tracing and the ground
/// truths show it, so their images differ there for the camera's sake, not the pipeline's.
void warn_geometry_before_near_plane(const RenderScene& scene, const StereoRig& rig, const Executor& executor);
/// Warns when the scene lies so far from the origin for its size that float positions cost
/// shadows and detail (the shadow-ray offset beyond a thousandth of its size).
void warn_scene_far_from_origin(const RenderScene& scene);
/// Warns when both eyes of a render show background only (a rig of another scale than the
/// scene's, a camera looking away).
void warn_if_no_surface_seen(const Image& left, const Image& right, const StereoRig& rig);

/// Checks a --threads value: 0 (all cores) or 1..1024; more than the cores is taken as the
/// cores, with a note (the scheduler would run no more, yet the results would record them).
[[nodiscard]] int checked_threads(int threads);

}  // namespace sb::cli
