// Al-Hagri's pixel reprojection (thesis §2.2.2, §3.1): each traced left-eye pixel moves along its
// scan-line to the right-eye pixel its hit projects into (x rounded to the pixel), the pixel that
// wins an overlap is the one with the larger source x (the nearer surface when the right eye sits
// to the right), and what reprojection cannot vouch for is traced. Shared by rt-adelson,
// rt-es-isler, rt-buffer and rt-atomic.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "renderer/image.hpp"
#include "renderer/pipeline.hpp"
#include "renderer/parallel.hpp"
#include "renderer/render_scene.hpp"
#include "renderer/rig.hpp"
#include "renderer/stages/eye_image.hpp"
#include "renderer/stages/primary_rays.hpp"
#include "renderer/stages/row_warp.hpp"
#include "renderer/stages/trace.hpp"
#include "renderer/stats.hpp"

namespace sb {

/// No reprojection reached the pixel (or the source pixel saw nothing).
inline constexpr int32_t kNoSource = -1;
/// PixelReprojector::column of a miss (every other value, negative ones included, is a column).
inline constexpr int32_t kMissColumn = std::numeric_limits<int32_t>::min();

/// Whether a left pixel's linear depth is the background's (a miss), which is not reprojected.
[[nodiscard]] inline bool is_miss(float depth) { return !(depth > 0.0f) || !std::isfinite(depth); }

/// Where left-eye hits land in the right eye.
class PixelReprojector {
 public:
  explicit PixelReprojector(const StereoRig& rig);

  /// The right-eye column that the hit of left pixel (x, y) at linear depth `depth` reprojects to:
  /// the right pixel containing the hit's projection (x rounded to the pixel, y unchanged by the
  /// rig's horizontal baseline); kNoSource for a miss (infinite depth) or a column outside the image.
  /// With the rig's parallel, equally shifted eyes the projection moves by the disparity
  /// f·e·(1/c − 1/z) along the row, so the column is target_column(x, disparity) of the row warp.
  [[nodiscard]] int32_t target(int x, int y, float depth) const {
    const int32_t c = column(x, y, depth);
    return c >= 0 && c < width_ ? c : kNoSource;
  }

  /// target() without the image's edges: a column >= the width for a hit beyond the right edge,
  /// a negative one for a hit left of the image (Algorithm 1 takes note of both); kMissColumn for
  /// a miss.
  [[nodiscard]] int32_t column(int x, int /*y*/, float depth) const {
    if (is_miss(depth)) return kMissColumn;
    return target_column(x, motion_(depth));
  }

  [[nodiscard]] const EyeCamera& left() const { return left_; }
  [[nodiscard]] const EyeCamera& right() const { return right_; }
  /// Each eye's primary rays, for every pixel.
  [[nodiscard]] const PrimaryRays& left_rays() const { return left_rays_; }
  [[nodiscard]] const PrimaryRays& right_rays() const { return right_rays_; }

 private:
  EyeCamera left_;
  EyeCamera right_;
  PrimaryRays left_rays_;
  PrimaryRays right_rays_;
  DisparityMotion motion_;
  int width_ = 0;
};

/// The right eye of a parallel reprojection: per right pixel, the source column in the same row
/// that won it (kNoSource: missed).
struct RightSources {
  int width = 0;
  int height = 0;
  std::vector<int32_t> column;
  [[nodiscard]] size_t index(int x, int y) const { return static_cast<size_t>(y) * width + x; }
};

/// How reprojected right pixels are validated.
struct ValidationSettings {
  double margin = 0.01;          ///< the restricted ray stops this fraction short of the surface's depth
  bool confirm_surface = false;  ///< also require a hit within the margin beyond (not in the thesis)

  /// From the options of validation_option_specs(); InputError for values out of range.
  static ValidationSettings from(const std::string& pipeline, const PipelineOptions& options);
};

/// The validation options rt-buffer and rt-atomic declare.
[[nodiscard]] std::vector<OptionSpec> validation_option_specs();

/// Validation::state of a right pixel written from its source.
inline constexpr uint8_t kApproved = 1;

/// Outcome of the validation of the reprojected right pixels.
struct Validation {
  std::vector<uint8_t> state;  ///< per right pixel: kApproved, or to be traced (missed or blocked)
  uint64_t missed = 0;         ///< no reprojection reached them
  uint64_t blocked = 0;        ///< traced although reprojected: bad (occluded) or absent
  uint64_t absent = 0;         ///< with confirm_surface: no surface within the margin beyond
  uint64_t restricted_rays = 0;
};

/// Validates every reprojected right pixel with a length-restricted ray (thesis §3.1.3): from the
/// right eye through the pixel centre up to (1 - margin) of the distance at which it reaches the
/// source pixel's linear depth. A ray that hits anything marks the pixel for full tracing; the
/// others are written from their source pixel (radiance, normal, albedo, primitive id, depth; tag
/// `reprojected`). Missed pixels are marked for tracing too. With confirm_surface, a second ray
/// over the segment from there to (1 + margin) of the distance must hit something, or the pixel is
/// traced as well. Rays go in 4x4-pixel packets.
[[nodiscard]] Validation validate_and_copy(const RenderScene& scene, const PixelReprojector& reprojector,
                                           const RightSources& sources, const Image& left,
                                           const ValidationSettings& settings, const Executor& executor, Image& right);

/// The left eye of the parallel pipelines: traced whole into a new result.left (stage
/// "left_trace"), counted.
void trace_left_eye(const RenderScene& scene, const StereoRig& rig, const Executor& executor, StereoResult& result);

/// The write histogram of the parallel pipelines' reprojection (add_write_counters) and
/// "overlapped": writes onto a right pixel beyond its first. Outside every timed stage.
void add_reprojection_counters(const PixelReprojector& reprojector, const StereoRig& rig, const Executor& executor,
                               StereoResult& result);

/// The right eye of the parallel pipelines (rt-buffer, rt-atomic) from the winning sources:
/// validate_and_copy into a new result.right (stage "validate"), then the missed and blocked
/// pixels traced in full with trace_unless, tag `reshaded_traced` (stage "right_trace"). Counts
/// missed, bad (blocked) and traced pixels, restricted rays, and the usual ray counters.
void complete_right_eye(const RenderScene& scene, const StereoRig& rig, const PixelReprojector& reprojector,
                        const RightSources& sources, const ValidationSettings& settings, const Executor& executor,
                        StereoResult& result);


/// How many left pixels reproject to each right pixel, as a histogram: entry k counts the right
/// pixels written k times (DESIGN §4.2, Lemma 1). For the counters; not part of any timed stage.
[[nodiscard]] std::vector<uint64_t> reprojection_writes(const PixelReprojector& reprojector, const Image& left,
                                                        const Executor& executor);

/// Lemma 1's bound on the writes to one right pixel for the nearest depth `z_min`: the disparity
/// range f e / z_min in pixels, rounded up, plus one for rounding the reprojected columns.
/// Saturates at 9e18 where the bound does not fit (a rig with a vanishing field of view).
[[nodiscard]] uint64_t lemma1_bound(const StereoRig& rig, double z_min);

/// Adds the write histogram to the counters: writes_max, writes_bound (Lemma 1 for the left eye's
/// nearest depth) and writes_per_pixel_<k> for every k that occurs.
void add_write_counters(Counters& counters, const std::vector<uint64_t>& histogram, const StereoRig& rig,
                        const Image& left);


}  // namespace sb
