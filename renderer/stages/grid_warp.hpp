// Adaptive 3D grid warping of a source eye into the other eye (Wißmann et al. 2020, §3.1–3.3):
// a grid of 16x16-pixel cells over the source image, subdivided to native resolution where the
// binocular-parallax difference of a cell exceeds a threshold (and around such cells), its
// vertices reprojected with their source depth, rasterized with a depth test, coloured by a
// bilinear lookup into the source radiance, and fragments across depth discontinuities discarded.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "renderer/image.hpp"
#include "renderer/parallel.hpp"
#include "renderer/rig.hpp"

namespace sb {

/// Side of a grid cell in pixels.
inline constexpr int kGridCell = 16;

/// θ(z) = 2 atan(e / (2 z)): the binocular parallax (radians) of a point at linear depth z for an
/// interaxial e; 0 for z = infinity.
[[nodiscard]] double binocular_parallax(double interaxial, double depth);

/// θΔ = |θ(zmin) − θ(zmax)| in minutes of arc.
[[nodiscard]] double parallax_difference_arcmin(double interaxial, double zmin, double zmax);

/// The warping grid over a W x H source image. Cell (cx, cy) owns pixels [16 cx, 16 cx + 16) x
/// [16 cy, 16 cy + 16), clipped to the image (partial cells at the right and bottom). Its vertices are
/// pixel centres: the lattice columns x0(cx)..x1(cx) and rows y0(cy)..y1(cy), where x1 is the
/// first column of the next cell, so neighbouring cells share their edges. Around the image the
/// lattice has one more column and row on each side (-1 and W, -1 and H) that lie on the image's
/// edges and carry the border pixels' depth (extrapolated half a pixel outwards where the border
/// pixel and the next one inwards lie on one surface), so that the mesh covers the whole source image and
/// no more — no pixel centre is lost on its outer boundary — and the half pixel at the border
/// reads the border pixel, as a texture lookup clamped to the edge does. The depth range of a cell covers every pixel of its lattice
/// span, i.e. every depth its triangles interpolate between (a ring vertex's extrapolated depth
/// aside, which lies at most half a pixel's change of 1/z beyond its border pixel's).
struct WarpGrid {
  int width = 0;
  int height = 0;
  int cells_x = 0;
  int cells_y = 0;
  double threshold_arcmin = 1.0;
  std::vector<float> zmin;             ///< per cell, linear depth (+inf: background only)
  std::vector<float> zmax;             ///< per cell
  std::vector<float> parallax_arcmin;  ///< per cell, θΔ
  std::vector<uint8_t> flagged;        ///< θΔ above the threshold
  std::vector<uint8_t> opening;        ///< a gap opens in it (GridSettings::opening_px)
  std::vector<uint8_t> subdivided;     ///< flagged, a 4-neighbour of a flagged cell, or opening
  /// Per source pixel: 1/z (0 for background), and the excess opening of the gap between it and
  /// its right-hand neighbour in units of f e: warped to the other eye, the gap between pixels i and
  /// i+1 opens by d(i+1) - d(i) = f e (1/z(i) - 1/z(i+1)); its excess is how much more it opens than
  /// the smaller of the gaps beside it (folds count as no gap). On a plane 1/z is affine in screen
  /// space, so all gaps of a row are equal and the excess is 0; at a depth discontinuity it is the
  /// disparity step. A crease where a surface turns away counts too: from three samples it cannot
  /// be told from a small step behind a fold.
  std::vector<float> inverse_depth;
  std::vector<float> excess;

  [[nodiscard]] size_t cell(int cx, int cy) const { return static_cast<size_t>(cy) * cells_x + cx; }
  [[nodiscard]] int x0(int cx) const { return cx == 0 ? -1 : cx * kGridCell; }
  [[nodiscard]] int x1(int cx) const { return cx + 1 == cells_x ? width : cx * kGridCell + kGridCell; }
  [[nodiscard]] int y0(int cy) const { return cy == 0 ? -1 : cy * kGridCell; }
  [[nodiscard]] int y1(int cy) const { return cy + 1 == cells_y ? height : cy * kGridCell + kGridCell; }
  [[nodiscard]] uint64_t flagged_count() const;
  [[nodiscard]] uint64_t opening_count() const;
  [[nodiscard]] uint64_t subdivided_count() const;
};

/// What decides a cell's subdivision.
struct GridSettings {
  double interaxial = 0.064;      ///< m, the rig's
  double focal_px = 1.0;          ///< f, the rig's
  double threshold_arcmin = 1.0;  ///< θΔ above which a cell is flagged
  /// When positive, a cell is also subdivided where a gap between horizontal source neighbours
  /// opens this many pixels more than the gaps beside it (the discontinuity measure of
  /// WarpOptions::discontinuity_px). A step of disparity below the parallax threshold (at most
  /// f θ: 0.22 px at 960x540, 0.43 px at 1920x1080 for 1′) still uncovers surfaces the left eye
  /// does not see; disocclusion detection needs the native grid there to find them.
  double opening_px = 0.0;
};

/// Computes the per-cell depth range and parallax metric of a source depth plane (linear depth,
/// +inf for background) and decides which cells are subdivided. Throws InputError for a
/// threshold that is not positive and finite or a depth plane of the wrong size.
[[nodiscard]] WarpGrid build_warp_grid(std::span<const float> depth, int width, int height,
                                       const GridSettings& settings, const Executor& executor);

/// How the per-vertex discontinuity measure decides which fragments are discarded.
enum class DiscardRule : uint8_t {
  /// The paper's: the measure interpolated over each triangle, fragments above the threshold
  /// discarded. Parts of the triangles beside a gap go too.
  interpolated,
  /// A vertex is flagged where its measure exceeds the threshold; fragments where the flags
  /// interpolate to exactly 1 are discarded: inside triangles whose vertices are all flagged (those
  /// spanning a gap) and on edges between two flagged vertices.
  all_vertices,
};

/// Options of the warp.
struct WarpOptions {
  /// Disocclusion detection: discard fragments by `rule` (default: of grid triangles whose vertices
  /// all exceed `discontinuity_px`; the paper's rule interpolates the measure); off, the rubber
  /// sheets stay.
  bool detect_disocclusions = true;
  /// Threshold (pixels) on the vertex measure: the larger excess opening of the two source-row
  /// gaps beside the vertex, where the gap between neighbours x and x+1 is the disparity
  /// difference d(x+1) − d(x) = f e (1/z(x) − 1/z(x+1)) and its excess is how much it exceeds the
  /// smaller of the gaps beside it (0 on any plane, the disparity step at a discontinuity).
  /// Measured on the source eye's linear depth: independent of the near plane. Only subdivided
  /// cells discard; coarse cells are flat in parallax.
  double discontinuity_px = 0.05;
  DiscardRule rule = DiscardRule::all_vertices;
  /// Leave the occluding-edge band to the hole filler: the covered pixel just left of a surface
  /// that is nearer by more than this many pixels of disparity (see WarpPixel); 0 = off.
  double occluding_edge_px = 0.5;
  /// Where the reprojection moves nothing vertically (a horizontal baseline), warp and resolve each
  /// row of cells in one task while its target rows are in cache. Off, the whole grid is warped
  /// before any row is resolved, as for any other rig. The image is the same either way.
  bool resolve_per_cell_row = true;
};

/// What became of a target pixel.
enum class WarpPixel : uint8_t {
  uncovered = 0,  ///< no grid fragment reached it
  covered = 1,    ///< written by a kept fragment (source tag: reprojected)
  discarded = 2,  ///< nearest fragment discarded (a detected disocclusion)
  /// Covered, but just left of a nearer surface's warped image (by more than the discontinuity
  /// threshold in disparity): that surface's silhouette lies up to a pixel before its first source
  /// pixel centre, so the pixel may belong to it. A hole for the filler.
  occluding_edge = 3,
  /// Covered, but the target eye sees there a surface outside the source eye's frustum, which
  /// no grid triangle carries (found by mark_outside_source_frustum, not by grid_warp). A hole.
  outside_source = 4,
};

/// Counters of one warp.
struct WarpStats {
  uint64_t triangles = 0;         ///< grid triangles generated
  uint64_t triangles_culled = 0;  ///< folded over, degenerate or with a vertex that cannot be reprojected
  uint64_t fragments = 0;         ///< covered pixel centres
  uint64_t fragments_discarded = 0;
  uint64_t pixels_covered = 0;
  uint64_t pixels_discarded = 0;
  uint64_t pixels_occluding_edge = 0;
  uint64_t pixels_uncovered = 0;

  [[nodiscard]] bool operator==(const WarpStats&) const = default;
};

/// Warps `source` (an eye image with rgb, depth, normal, albedo and primid planes, seen by `from`)
/// into `target` (an eye image of the same size made by make_eye_image, seen by `to`; every sample
/// of every plane is written, so it may be made with PlaneInit::unset). Covered
/// pixels get the bilinear radiance at their source position, the reprojected depth, the nearest
/// source pixel's normal, albedo and primitive id, and source tag `reprojected`; the others are
/// written as holes (radiance 0, depth +inf, tag `hole`). Returns a WarpPixel per target pixel.
/// Deterministic for any thread count: per target pixel the nearest fragment wins, exact ties go to
/// the earlier grid triangle (cells row by row).
[[nodiscard]] std::vector<uint8_t> grid_warp(const WarpGrid& grid, const Image& source, const EyeCamera& from,
                                             const EyeCamera& to, double interaxial, const WarpOptions& options,
                                             const Executor& executor, Image& target, WarpStats& stats);

/// The grid drawn over the source radiance for viewing (the paper's Fig. 4): the image darkened,
/// cells that exceed the parallax threshold tinted red, the other subdivided cells (the flagged
/// cells' neighbours, and cells where a disocclusion gap opens) tinted orange (both at native
/// resolution), and the triangles of every coarse cell outlined: two, or beside a subdivided cell
/// the fan that closes its T-junctions (an edge per pixel of the shared side: a white wedge).
[[nodiscard]] Image grid_overlay(const WarpGrid& grid, const Image& source);

}  // namespace sb
