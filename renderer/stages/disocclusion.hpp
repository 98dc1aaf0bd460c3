// True disocclusions of the right eye and the scoring of a mask of pixels against them (DESIGN
// §6.3): which right-eye pixels show a surface the left eye cannot see, how much of that a mask
// (a pipeline's hole mask, or every pixel it did not reproject) covers, and an overlay image to
// look at the difference. Shared by the pipelines,
// `stereobench render` and the validation layer.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include "renderer/image.hpp"
#include "renderer/parallel.hpp"
#include "renderer/render_scene.hpp"
#include "renderer/rig.hpp"

namespace sb {

/// What an eye's primary rays hit, per pixel (row-major, index y * width + x): the linear depth
/// (infinity where the ray misses) and the global primitive id (kNoPrimitive where it misses).
struct VisibleSurfaces {
  int width = 0;
  int height = 0;
  std::vector<float> depth;
  std::vector<uint32_t> prim;
};

/// Traces the primary rays of `eye` without shading: the same rays, in the same packets, as
/// trace_eye, so depth and primitive ids equal the depth and primid planes of a traced eye bit
/// for bit.
[[nodiscard]] VisibleSurfaces trace_visible_surfaces(const RenderScene& scene, const EyeCamera& eye,
                                                     const Executor& executor);

/// Why a right-eye pixel is disoccluded; the values of TrueDisocclusions::mask.
enum class Disocclusion : uint8_t {
  visible = 0,          ///< the left eye sees the same surface point (or background direction)
  outside_frustum = 1,  ///< the point projects outside the left image or to/behind its near plane
  hidden = 2,           ///< inside the left frustum, but occluded or turned away from the left eye
};

/// The true disocclusion mask of the right eye with respect to the left eye.
struct TrueDisocclusions {
  std::vector<uint8_t> mask;  ///< per right-eye pixel, a Disocclusion value; non-zero = disoccluded
  uint64_t outside_frustum = 0;
  uint64_t hidden = 0;

  /// Disoccluded pixels: outside_frustum + hidden.
  [[nodiscard]] uint64_t count() const { return outside_frustum + hidden; }
};

/// Classifies every right-eye pixel of `right` (trace_visible_surfaces of rig.eye(Eye::right))
/// by what the left eye sees of its surface point (DESIGN §6.3):
/// - A surface point is reconstructed exactly: the pixel's primary ray intersected in double
///   precision with the plane of the triangle it hit (the stored depth is only a fallback for
///   rays parallel to that plane). It is outside_frustum when its left-eye projection falls outside
///   [0, W) x [0, H) in continuous pixel coordinates or its left depth is at or below znear; hidden
///   when the left eye lies on the other side of (or in) the triangle's plane, i.e. sees its other
///   face, or when the left eye's own closest hit along the ray towards the point is nearer than
///   the point by more than a tolerance (16 ray epsilons or 1e-5 of the distance, whichever is
///   larger): a hit on a neighbouring triangle at the same distance is the same surface point.
///   The ray runs from the eye, so single-sided triangles are culled exactly as the left eye's own
///   primary rays cull them.
/// - A background pixel (no hit) is outside_frustum when its ray direction projects outside the
///   left image, and hidden when a ray from the left eye's origin along the same direction hits
///   geometry.
/// Visibility rays are cast in packets of 16 per 32-pixel tile; the result does not depend on the
/// executor's thread count. InputError if `right` does not have the rig's resolution.
[[nodiscard]] TrueDisocclusions true_disocclusions(const RenderScene& scene, const StereoRig& rig,
                                                   const VisibleSurfaces& right, const Executor& executor);

/// A pipeline's hole mask: 1 where the right eye's "source" plane is hole, reshaded_traced,
/// reshaded_raster or inpainted (the pixels the pipeline did not take from the left eye or its
/// own first pass), 0 elsewhere. InputError if the image has no "source" plane.
[[nodiscard]] std::vector<uint8_t> hole_mask_from_sources(const Image& right);

/// 1 where `eye`'s source tag is not `reprojected` (rendered for that eye, filled, or left as a
/// hole), 0 elsewhere: the mask scored against the true disocclusions (a reprojected pixel there
/// shows the wrong surface). For the pipelines that render nothing natively for the right eye it
/// is hole_mask_from_sources. InputError without a "source" plane.
[[nodiscard]] std::vector<uint8_t> not_reprojected_mask(const Image& eye);

/// Whether any pixel's source tag is `reprojected` (InputError without a "source" plane).
[[nodiscard]] bool has_reprojected_pixels(const Image& image);

/// Recall and precision of a mask against the true disocclusions.
struct HoleScores {
  uint64_t hole_pixels = 0;     ///< pixels the mask flags
  uint64_t true_pixels = 0;     ///< truly disoccluded pixels
  uint64_t true_positives = 0;  ///< flagged and truly disoccluded
  /// true_positives / true_pixels; NaN (undefined: null in records, "-" in tables) when nothing
  /// is disoccluded.
  double recall = std::numeric_limits<double>::quiet_NaN();
  /// true_positives / hole_pixels; NaN when nothing is flagged (a pipeline that flags nothing is
  /// not "precise").
  double precision = std::numeric_limits<double>::quiet_NaN();
};

/// Scores `holes` against `truth` (both per pixel, non-zero = set). InputError if the sizes differ.
[[nodiscard]] HoleScores score_holes(std::span<const uint8_t> holes, std::span<const uint8_t> truth);

/// An image for looking at a hole mask against the truth, with one "rgb" plane (linear):
/// every pixel starts as the right eye's radiance clamped to [0, 1] and darkened to 30 %;
/// pixels in both masks (holes found) are tinted green, true disocclusions the mask misses red,
/// and flagged pixels that are not disoccluded (wasted work) blue. A tinted pixel is
/// 25 % darkened radiance + 75 % tint colour, so the scene's structure stays visible under the tint.
/// InputError if `right` has no "rgb" plane or a mask is not one value per pixel.
[[nodiscard]] Image hole_overlay(const Image& right, std::span<const uint8_t> holes, std::span<const uint8_t> truth);

/// The whole hole analysis of a rendered right eye, as `stereobench render` runs it.
struct HoleAnalysis {
  TrueDisocclusions truth;
  HoleScores scores;
  Image overlay;         ///< hole_overlay of the right eye
  double seconds = 0.0;  ///< wall-clock time of the analysis (tracing included)
};

/// When the right eye has reprojected pixels: traces the rig's right eye (trace_visible_surfaces),
/// computes the true disocclusions, scores the pixels not reprojected (not_reprojected_mask, as
/// validation scores them) and draws the overlay of that mask.
/// Nothing when no pixel is reprojected: every pixel was rendered for that eye, so there are no
/// holes to score.
[[nodiscard]] std::optional<HoleAnalysis> analyze_holes(const RenderScene& scene, const StereoRig& rig,
                                                        const Image& right, const Executor& executor);

}  // namespace sb
