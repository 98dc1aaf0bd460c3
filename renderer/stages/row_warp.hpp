// Row-wise 1-D forward warping of an eye image into the other eye (Kim, §3.1–3.2): with the rig's
// horizontal baseline every pixel moves along its own row by its disparity, so overlaps are
// resolved per row by minimum depth, with no synchronisation between rows. Also the per-pixel
// rules (motion, target column, which pixels take part) that the atomic forward warp of fw-warp
// shares, so that both warps put every pixel in the same place.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "renderer/image.hpp"
#include "renderer/parallel.hpp"
#include "renderer/rig.hpp"

namespace sb {

/// Horizontal motion, in pixels, of a point of linear depth Z warped from eye `from` into the
/// other eye of the rig: +d(Z) = f e (1/c − 1/Z) from left to right, −d(Z) from right to left.
/// At Z = +inf (the background) it is ±f e / c, the largest disparity.
class DisparityMotion {
 public:
  /// InputError for Eye::center, which has no other eye.
  DisparityMotion(const StereoRig& rig, Eye from);

  [[nodiscard]] float operator()(float depth) const {
    const double inverse = std::isinf(depth) ? 0.0 : 1.0 / static_cast<double>(depth);
    return static_cast<float>(scale_ * (inverse_c_ - inverse));
  }

 private:
  double scale_ = 0.0;  ///< ±f e
  double inverse_c_ = 0.0;
};

/// How far left of a pixel edge a moved centre still goes to the right-hand pixel. A depth read
/// back from float carries a relative error near 1e-7, so a surface whose motion is exactly half a
/// pixel off a whole one (a wall at a distance where it is k + 0.5 px) gives motions a few 1e-7 px
/// either side of the edge: rounded as they come, neighbouring pixels of the wall went one pixel
/// apart or onto one pixel, opening gaps and overlaps all over it (thin-pole at 15 px of disparity:
/// 33.50 dB and 21 % holes for rt-atomic, against 48 dB at 14 px). 1e-4 px is far above that
/// noise and far below anything an image shows.
inline constexpr double kEdgeTolerance = 1e-4;

/// The target column of source pixel x moved by `motion`: the pixel whose centre is nearest to the
/// moved centre x + 0.5 + motion, i.e. floor(x + 0.5 + motion) — written round(x + 0.5 + motion) − 0.5
/// in centre coordinates. A moved centre on a pixel edge, or within kEdgeTolerance left of one,
/// goes to the right-hand pixel. Evaluated in double precision; the result is clamped to
/// [−1, 2^30] so that it always fits (a NaN motion gives −1: outside the image).
[[nodiscard]] inline int target_column(int x, float motion) {
  const double moved = std::floor(static_cast<double>(x) + 0.5 + static_cast<double>(motion) + kEdgeTolerance);
  if (!(moved >= -1.0)) return -1;
  return static_cast<int>(std::min(moved, 1073741824.0));
}

/// Whether a pixel of an eye image takes part in a forward warp as a source, or as a native pixel
/// of the target: it is not a hole (tag), and it sees a surface (depth finite and positive) or,
/// with `warp_background`, the background (depth +inf).
[[nodiscard]] inline bool takes_part(uint32_t source_tag, float depth, bool warp_background) {
  if (source_tag == static_cast<uint32_t>(Source::hole)) return false;
  if (depth > 0.0f && depth < std::numeric_limits<float>::infinity()) return true;
  return warp_background && depth == std::numeric_limits<float>::infinity();
}

/// Options of a row warp.
struct RowWarpOptions {
  /// Length in pixels of the target-row segments that run as independent tasks (>= 1; values
  /// above the width mean whole rows). The image does not depend on it, nor on the thread count.
  int segment = 256;
  /// Pixels that see the background (depth +inf, not tagged hole) are warped too, with the motion
  /// at infinity; they lose every overlap against a surface. Off, only surfaces are warped (for a
  /// partial image whose empty pixels are not tagged as holes).
  bool warp_background = true;
  /// Target pixels not tagged hole keep their values whatever lands on them (sources fill holes
  /// only): for a target whose own pixels are known to be the nearest surface there.
  bool keep_native = false;
};

/// The motion texture of a source image (Kim §3.1): per-pixel motion in pixels along the row,
/// and per row the smallest and largest motion of the pixels that take part, which bound which
/// source pixels can land in a target segment. Pixels that do not take part have motion 0 and are
/// not in the bounds; a row without any has the bounds 0, 0.
struct MotionField {
  int width = 0;
  int height = 0;
  std::vector<float> motion;   ///< width x height, row-major
  std::vector<float> row_min;  ///< per row
  std::vector<float> row_max;  ///< per row

  /// The row's largest |motion|: how far its segments reach past their ends.
  [[nodiscard]] float max_abs(int y) const {
    return std::max(std::abs(row_min[static_cast<size_t>(y)]), std::abs(row_max[static_cast<size_t>(y)]));
  }
};

/// The motion texture of `source` (an eye image with depth and source planes) warped from eye
/// `from` of the rig into the other eye (DisparityMotion), for the pixels that take part under
/// `options.warp_background`. InputError when the image size differs from the rig's.
[[nodiscard]] MotionField disparity_motion_field(const Image& source, const StereoRig& rig, Eye from,
                                                 const RowWarpOptions& options, const Executor& executor);

/// Recomputes the per-row bounds of a motion field from its motion and the pixels of `source`
/// that take part (for motion fields filled by other means, e.g. in tests).
void compute_row_bounds(MotionField& field, const Image& source, bool warp_background, const Executor& executor);

/// What a row warp did. Every source pixel that takes part is counted once.
struct RowWarpStats {
  uint64_t sources = 0;   ///< source pixels that took part
  uint64_t outside = 0;   ///< of them, moved outside the target row
  uint64_t landed = 0;    ///< of them, moved inside the target row
  uint64_t occluded = 0;  ///< landed but lost the pixel to a nearer source or native pixel
  uint64_t written = 0;   ///< target pixels written from a source (tag `reprojected`)
};

/// Forward-warps `source` along its rows into `target` (Kim §3.2, the 1-D warp).
///
/// Both are eye images of the same size with rgb, depth, normal, albedo, primid and source planes
/// (make_eye_image), and they must be different images: warping the two partial images of a
/// bidirectional pipeline into each other takes two calls, each reading an unchanged source.
/// Source pixel (x, y) that takes part (takes_part) moves to target column
/// target_column(x, motion(x, y)) of row y. Target pixels that take part are *native*: they enter
/// the same per-pixel resolution with their own depth. Per target pixel the candidate of minimum
/// linear depth wins; on an exact depth tie a native pixel wins over sources, and among sources the
/// larger source x wins. A pixel won by a source receives its radiance, depth, normal, albedo and
/// primitive id and the tag `reprojected`; every other target pixel is left as it was (a hole stays
/// a hole).
///
/// Each row is split into target segments of `options.segment` pixels; a segment reads exactly the
/// source pixels that can land in it, i.e. the segment widened by the row's motion bounds (an
/// overlap with its neighbours of about the row's largest |motion|), so segments run in parallel
/// without synchronisation and the image is bit-identical for any segment length and thread count.
/// InputError for mismatched sizes, a missing plane, the same image as source and target, or a
/// segment below 1.
RowWarpStats row_warp(const Image& source, const MotionField& motion, const RowWarpOptions& options,
                      const Executor& executor, Image& target);

/// A width x height eye image (make_eye_image) in which every pixel is a hole: radiance 0, depth
/// +inf, no primitive, tag `hole` — a fresh target for a forward warp.
[[nodiscard]] Image make_hole_image(int width, int height, const Executor& executor);

}  // namespace sb
