// Images written by a validation.
#include "validation/validation_images.hpp"

#include <functional>
#include <vector>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/image_io.hpp"
#include "validation/metric_images.hpp"

namespace sb::validation {

using nlohmann::json;

Srgb8Image disocclusion_image(const Srgb8Image& truth, const TrueDisocclusions& disocclusions) {
  if (disocclusions.mask.size() != truth.pixel_count())
    throw InputError(fmt::format("a true disocclusion mask of {} pixels does not fit a {}x{} image",
                                 disocclusions.mask.size(), truth.width, truth.height));
  Srgb8Image out = truth;
  for (size_t i = 0; i < out.pixel_count(); ++i) {
    uint8_t* px = &out.rgb[3 * i];
    const auto kind = static_cast<Disocclusion>(disocclusions.mask[i]);
    const uint8_t tint[2][3] = {{255, 140, 0}, {230, 20, 20}};  // outside the frustum, hidden
    for (int c = 0; c < 3; ++c) {
      const int dimmed = px[c] / 3;
      px[c] = kind == Disocclusion::visible
                  ? static_cast<uint8_t>(dimmed)
                  : static_cast<uint8_t>((dimmed + 3 * tint[kind == Disocclusion::hidden ? 1 : 0][c]) / 4);
    }
  }
  return out;
}

namespace {

using io::FileWriter;

/// Runs the file writers side by side on the executor's threads. A failure cancels the writers
/// not yet started and is rethrown once the running ones have finished; each writes atomically,
/// so none leaves a partial file, and every file of `paths` (the set) is then removed. With
/// options.staged the files are added to that set instead and nothing at their names changes here.
void write_side_by_side(const std::vector<FileWriter>& writers, const std::vector<std::filesystem::path>& paths,
                        const Executor& executor, const ImageFileOptions& options) {
  if (options.staged != nullptr) {
    options.staged->add_side_by_side(writers, executor);
    return;
  }
  try {
    executor.for_each(writers.size(), [&](size_t i) { writers[i].write(writers[i].path); });
  } catch (...) {
    // The set is whole or gone: files of it written beside the one that failed (or left from an
    // earlier run under the same names) would read as this run's.
    io::discard_output_files(paths);
    throw;
  }
}

}  // namespace

json write_target_images(const std::filesystem::path& dir, const std::string& stem, const ValidationTarget& target,
                         const Executor& executor, const ImageFileOptions& options) {
  const std::string provider = target.truth.render.provider;
  const std::filesystem::path exr = dir / fmt::format("{}_truth-{}.exr", stem, provider);
  const std::filesystem::path png = dir / fmt::format("{}_truth-{}.png", stem, provider);
  // Per provider, as the truth it is drawn over: another provider's run into the folder leaves it.
  const std::filesystem::path dis = dir / fmt::format("{}_disocclusions-{}.png", stem, provider);
  json files = json::object();
  std::vector<FileWriter> writers = {
      {png, [&](const std::filesystem::path& to) { write_png(to, target.truth_srgb8); }},
      {dis, [&](const std::filesystem::path& to) {
         write_png(to, disocclusion_image(target.truth_srgb8, target.disocclusions));
       }}};
  std::vector<std::filesystem::path> paths = {png, dis};
  if (options.exr) {
    writers.push_back({exr, [&](const std::filesystem::path& to) { io::write_exr(to, target.truth.render.right); }});
    files["truth_exr"] = exr.string();
    paths.push_back(exr);
  }
  write_side_by_side(writers, paths, executor, options);
  files["truth_png"] = png.string();
  files["true_disocclusions_png"] = dis.string();
  return files;
}

json write_pipeline_images(const std::filesystem::path& dir, const std::string& stem, const ValidationTarget& target,
                           const PipelineValidation& v, const Executor& executor, const ImageFileOptions& options) {
  const auto path = [&](const char* suffix) { return dir / fmt::format("{}_{}", stem, suffix); };
  json files = json::object();
  using Path = std::filesystem::path;
  std::vector<FileWriter> writers = {
      {path("right.png"), [&](const Path& to) { write_png(to, v.right_srgb8); }},
      {path("diff.png"), [&](const Path& to) { write_png(to, difference_image(v.right_srgb8, target.truth_srgb8)); }},
      {path("ssim.png"), [&](const Path& to) { write_png(to, ssim_image(v.ssim)); }},
      {path("holes.png"), [&](const Path& to) {
         io::write_png_preview(to, hole_overlay(v.result.right, v.holes.not_reprojected, target.disocclusions.mask));
       }}};
  // A left eye synthesized in part (measured against plain-rt's): the pipeline's own left eye and
  // its difference to plain-rt's. They belong to the set either way: an earlier run's under these
  // names go on failure, and when this pipeline renders its left eye whole.
  const std::vector<std::filesystem::path> left_files = {path("left.png"), path("left_diff.png")};
  std::vector<std::filesystem::path> paths = {path("right.png"), path("diff.png"), path("ssim.png"), path("holes.png"),
                                              left_files[0], left_files[1]};
  if (v.left) {
    writers.push_back({left_files[0], [&](const Path& to) { write_png(to, v.left_srgb8); }});
    writers.push_back(
        {left_files[1], [&](const Path& to) { write_png(to, difference_image(v.left_srgb8, target.left->srgb8)); }});
    files["left_png"] = left_files[0].string();
    files["left_diff_png"] = left_files[1].string();
  } else if (options.staged != nullptr) {
    for (const std::filesystem::path& file : left_files) options.staged->retire(file);
  } else {
    io::discard_output_files(left_files);
  }
  if (options.exr) {
    writers.push_back({path("right.exr"), [&](const Path& to) { io::write_exr(to, v.result.right); }});
    files["right_exr"] = path("right.exr").string();
    paths.push_back(path("right.exr"));
  }
  // Diagnostic images an option asked for (repro-*'s grid_overlay=true, bidir-warp's
  // partials=true), as render writes them: <stem>_<name>.png, recorded as <name>_png.
  for (const auto& [name, image] : v.result.extras) {
    for (const char* taken : {"right", "diff", "ssim", "holes", "left", "left_diff"})
      if (name == taken)
        throw InputError(fmt::format("{}: its diagnostic image '{}' takes the name of a validation image", v.pipeline,
                                     name));
    const Path file = dir / fmt::format("{}_{}.png", stem, name);
    writers.push_back({file, [&image](const Path& to) { io::write_png_preview(to, image); }});
    files[name + "_png"] = file.string();
    paths.push_back(file);
  }
  write_side_by_side(writers, paths, executor, options);
  files["right_png"] = path("right.png").string();
  files["diff_png"] = path("diff.png").string();
  files["ssim_png"] = path("ssim.png").string();
  files["holes_png"] = path("holes.png").string();
  return files;
}

std::filesystem::path write_left_image(const std::filesystem::path& dir, const std::string& stem,
                                       const ValidationTarget& target, const PipelineValidation& v) {
  // A left eye the pipeline synthesized in part would show its warping errors beside every other
  // pipeline's right eye: plain-rt's traced left eye (the one it was measured against) stands in.
  if (v.left) {
    const std::filesystem::path png = dir / "left-eye_plain-rt.png";  // no <entry>_<suffix> name
    write_png(png, target.left->srgb8);
    return png;
  }
  const std::filesystem::path png = dir / fmt::format("{}_left.png", stem);
  write_png(png, encode_srgb8(v.result.left, fmt::format("{}'s left eye", v.pipeline)));
  return png;
}

}  // namespace sb::validation
