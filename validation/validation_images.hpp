// The images a validation writes (DESIGN §6, `stereobench validate`): the right eye, the ground
// truth, the difference and SSIM maps, the pixels not reprojected against the true
// disocclusions, and the true disocclusions themselves.
#pragma once

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "renderer/io/atomic_file.hpp"

#include "validation/validate.hpp"

namespace sb::validation {

/// The true disocclusions over the ground truth: every pixel the ground truth's sRGB colour at a
/// third of its brightness, disoccluded pixels outside the left frustum orange and hidden ones
/// red (75 % tint over the dimmed colour). InputError if the sizes differ.
[[nodiscard]] Srgb8Image disocclusion_image(const Srgb8Image& truth, const TrueDisocclusions& disocclusions);

/// Which image files a validation writes besides its PNGs, and how.
struct ImageFileOptions {
  bool exr = true;  ///< the EXR of the ground truth and of every right eye (large: every AOV)
  /// Where the files go: null, each in place as it is finished (on failure the set's files are
  /// removed, an earlier run's included); otherwise added to this set, which the caller commits,
  /// so that a failure before the commit leaves an earlier run's files as they were (files of the
  /// set not written again are retired with it).
  io::StagedFiles* staged = nullptr;
};

/// Writes the images shared by every pipeline of a target under `dir`: <stem>_truth-<provider>.exr
/// (unless options.exr is false) and .png, and <stem>_disocclusions.png. The files are encoded
/// side by side on the executor's threads (each file's bytes do not depend on it). Returns
/// {name: path}; on failure none of these files is left (an earlier run's included), unless
/// options.staged holds them.
nlohmann::json write_target_images(const std::filesystem::path& dir, const std::string& stem,
                                   const ValidationTarget& target, const Executor& executor,
                                   const ImageFileOptions& options = {});

/// Writes a pipeline's images under `dir`: <stem>_right.exr (every AOV; unless options.exr is
/// false) and _right.png, _diff.png (difference heat map), _ssim.png (SSIM map) and _holes.png
/// (the pixels not reprojected, as holes.not_reprojected scores them, against the true
/// disocclusions: green found, red missed, blue flagged needlessly),
/// and for a left eye synthesized in part (v.left) _left.png and _left_diff.png (its difference to
/// plain-rt's left eye), side by side on the executor's threads. Returns {name: path}; on failure
/// none of these files is left (an earlier run's included), unless options.staged holds them.
nlohmann::json write_pipeline_images(const std::filesystem::path& dir, const std::string& stem,
                                     const ValidationTarget& target, const PipelineValidation& v,
                                     const Executor& executor, const ImageFileOptions& options = {});

/// Writes the left eye shown beside every pipeline's right eye (anaglyph and side-by-side views):
/// the pipeline's own as <stem>_left.png (sRGB), or, where it synthesized part of it (v.left),
/// plain-rt's traced left eye, which it was measured against, as left-eye_plain-rt.png. Returns
/// its path.
std::filesystem::path write_left_image(const std::filesystem::path& dir, const std::string& stem,
                                       const ValidationTarget& target, const PipelineValidation& v);

}  // namespace sb::validation
