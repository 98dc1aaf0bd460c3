// Crack removal after forward warping (Kim §3.2 "Crack Removal"): narrow runs of hole pixels
// along a row, with warped pixels on both sides, are filled by linear interpolation between those
// two pixels; wider holes and holes at the image border stay holes and are counted.
#pragma once

#include <cstdint>
#include <string>

#include "renderer/image.hpp"
#include "renderer/parallel.hpp"
#include "renderer/pipeline.hpp"

namespace sb {

/// Default widest run of hole pixels that counts as a crack.
inline constexpr int kDefaultCrackWidth = 2;

/// What a crack fill found and did. A run is a maximal sequence of hole pixels in one row.
struct CrackFillStats {
  uint64_t hole_pixels = 0;    ///< hole pixels before filling
  uint64_t cracks = 0;         ///< runs filled (at most max_width long, non-hole pixels on both sides)
  uint64_t pixels_filled = 0;  ///< pixels in them (tag `inpainted`)
  uint64_t large_holes = 0;    ///< runs longer than max_width with non-hole pixels on both sides
  uint64_t large_hole_pixels = 0;
  uint64_t border_holes = 0;   ///< runs that touch the left or right image edge, of any length
  uint64_t border_hole_pixels = 0;
  uint64_t cracks_unfilled = 0;  ///< runs of crack width counted but left as holes (CrackMode::count)
  uint64_t crack_pixels_unfilled = 0;

  /// Hole pixels left after filling.
  [[nodiscard]] uint64_t holes_left() const { return large_hole_pixels + border_hole_pixels + crack_pixels_unfilled; }
};

/// Whether fill_cracks interpolates the runs of crack width, or only counts them (a pipeline that
/// traces its cracks instead).
enum class CrackMode { fill, count };

/// Fills the cracks of an eye image (planes rgb, depth, normal, albedo, primid, source; holes are
/// the pixels tagged `hole`). For a run of n <= max_width hole pixels between non-hole pixels L
/// (left) and R (right) of the same row, pixel k = 1..n of the run takes t = k / (n + 1) and
///  - radiance (L.rgb) (1 − t) + (R.rgb) t, per channel in linear light;
///  - depth: the same interpolation when both depths are finite, otherwise +inf (a crack beside the
///    background shows the background);
///  - normal, albedo and primitive id of the farther of L and R (larger depth; L on a tie): a
///    crack that is not a stretched surface is a sliver of disocclusion, which shows the surface
///    behind;
///  - tag `inpainted`.
/// Every other pixel is left untouched. Rows run in parallel; each row reads and writes only
/// itself, so the result does not depend on the thread count. max_width 0 fills nothing.
/// InputError for a negative max_width or a missing plane. With CrackMode::count the image is not
/// changed: the runs of at most max_width pixels are counted as cracks_unfilled.
CrackFillStats fill_cracks(Image& image, int max_width, const Executor& executor, CrackMode mode = CrackMode::fill);

/// Kim's crack detection by depth (§3.2: a crack shows a surface farther than the pixels around
/// it). In a composed image a narrow sliver of a farther surface can show through where the
/// nearer surface warped in from the other eye leaves a gap. Per row, a run of at most max_width
/// pixels, each a hole or deeper than `depth_ratio` times the depth of both pixels bounding the
/// run, with at least one such deeper non-hole pixel, between two non-hole pixels of finite depth,
/// is turned into holes (radiance 0, depth +inf, tag `hole`) for fill_cracks to fill. Runs are
/// found left to right; a run's right bound may be the next run's left bound. Every other
/// pixel is left as it is. Rows run in parallel, each reading and writing only itself. Returns the
/// pixels turned into holes. InputError for a negative max_width, a depth_ratio below 1 or a
/// missing plane.
uint64_t mark_depth_cracks(Image& image, int max_width, double depth_ratio, const Executor& executor);

/// The "max_crack" option of the pipelines that fill cracks, checked (0..64; InputError naming
/// the pipeline otherwise).
[[nodiscard]] int max_crack_option(const std::string& pipeline, const PipelineOptions& options);

/// Adds a crack fill's counts to a pipeline's counters: pixels_filled_crack, holes_left,
/// cracks_filled, large_holes (+ _pixels) and border_holes (+ _pixels).
void add_crack_counters(Counters& counters, const CrackFillStats& stats);

}  // namespace sb
