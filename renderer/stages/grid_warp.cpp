// The adaptive grid warp: parallax metric per cell, grid triangles per cell row, fixed-point
// rasterization of the warped grid in horizontal bands, and the resolve into the target eye.
#include "renderer/stages/grid_warp.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/stages/eye_image.hpp"

namespace sb {

namespace {

/// Sub-pixel bits of warped vertex positions (1/256 px). Every vertex goes through one snapping
/// function, so an edge shared by two grid triangles has identical end points in both and the
/// fill rule covers each pixel centre on it exactly once.
constexpr int kSubBits = 8;
constexpr int64_t kSubOne = int64_t{1} << kSubBits;
constexpr int64_t kSubHalf = kSubOne / 2;

constexpr double kArcminPerRadian = 180.0 * 60.0 / std::numbers::pi;

/// One warped grid vertex.
struct GridVertex {
  int32_t x = 0;  ///< target position, fixed point
  int32_t y = 0;
  float q = 0.0f;     ///< inverse target depth (0 at infinity)
  float r = 1.0f;     ///< the source clip w over the target clip w (1 / the scaled point's target w)
  float disc = 0.0f;  ///< discontinuity measure, px
  float sx = 0.0f;    ///< source position (pixel coordinates)
  float sy = 0.0f;
  bool valid = false;
};

/// 1/z of a linear depth; 0 for background (infinite depth).
float inverse_depth(float z) { return z > 0.0f && std::isfinite(z) ? 1.0f / z : 0.0f; }

/// Fills row j of the inverse-depth and excess-opening planes (see WarpGrid).
void gap_row(std::span<const float> depth, int width, int j, float* inv, float* excess) {
  const size_t row = static_cast<size_t>(j) * width;
  for (int i = 0; i < width; ++i) inv[row + i] = inverse_depth(depth[row + i]);
  // The gap between i and i+1 opens by d(i+1) - d(i) = f e (1/z(i) - 1/z(i+1)).
  // Gap i's excess opening over the smaller of its neighbours' (at the row's ends the missing
  // neighbour is the gap itself).
  const auto excess_of = [](float gap, float left, float right) {
    return std::max(0.0f, gap - std::max(0.0f, std::min(left, right)));
  };
  const float* v = inv + row;
  float* out = excess + row;
  if (width >= 2) out[0] = excess_of(v[0] - v[1], v[0] - v[1], width >= 3 ? v[1] - v[2] : v[0] - v[1]);
  // The gaps with both neighbours, in a loop without a branch.
  for (int i = 1; i + 2 < width; ++i) out[i] = excess_of(v[i] - v[i + 1], v[i - 1] - v[i], v[i + 1] - v[i + 2]);
  if (width >= 3) out[width - 2] = excess_of(v[width - 2] - v[width - 1], v[width - 3] - v[width - 2], v[width - 2] - v[width - 1]);
  out[width - 1] = 0.0f;
}

/// Reprojects source lattice vertices into the target eye with VP_to · VP_from⁻¹. The matrix is
/// applied to the source point scaled by its inverse depth, (x_c, y_c, −1, 1/z) in the source view
/// space — the same homogeneous point as the source NDC (x, y, z_ndc, 1) up to the factor z — so a
/// point at infinity needs no special case and the result does not depend on the near plane.
class Reprojector {
 public:
  Reprojector(const WarpGrid& grid, const EyeCamera& from, const EyeCamera& to, double interaxial)
      : grid_(grid),
        from_(from),
        to_w_(to.width),
        to_h_(to.height),
        step_scale_(from.f_px * interaxial),
        guard_(4.0 * std::max(to.width, to.height) + 64.0) {
    const dmat4 view_from = from.view_matrix();
    matrix_ = to.projection_matrix() * to.view_matrix() * glm::inverse(view_from);
    // The clip position M·(X, Y, −1, 1/z) is linear in X, Y and 1/z: a term per lattice column,
    // one per lattice row (with the −1), and 1/z times M's last column.
    column_.reserve(static_cast<size_t>(from.width) + 2);
    for (int i = -1; i <= from.width; ++i) column_.push_back((lattice_x(i) - from.cx) / from.f_px * matrix_[0]);
    row_.reserve(static_cast<size_t>(from.height) + 2);
    for (int j = -1; j <= from.height; ++j)
      row_.push_back((from.cy - lattice_y(j)) / from.f_px * matrix_[1] - matrix_[2]);
    // Eyes that look the same way give every point the same clip w. Where the matrix shows it
    // exactly (the terms of one kind all carry one w, and 1/z none: a rig whose camera is aligned
    // with the world axes, as spheres', atrium's and bistro's are), the reciprocal is taken once,
    // exactly as every vertex would take it. Rounding in the inverse of a turned camera's view
    // leaves a w term of 1e-15 or so (temple, dragon), and every vertex divides.
    const auto same_w = [](const std::vector<dvec4>& terms) {
      return std::all_of(terms.begin(), terms.end(), [&](const dvec4& t) { return t.w == terms.front().w; });
    };
    if (matrix_[3].w == 0.0 && same_w(column_) && same_w(row_)) {
      const double w = column_.front().w + row_.front().w;
      if (w > 0.0) fixed_inv_w_ = 1.0 / w;
    }
  }

  /// Target pixel position of lattice point (i, j) at inverse depth inv_z (0: infinity), or
  /// nothing when it lies behind the target eye; `inv_w` receives 1 / the clip w. The matrix
  /// product is split into the precomputed terms.
  [[nodiscard]] std::optional<dvec2> position(int i, int j, double inv_z, double* inv_w = nullptr) const {
    const dvec4 c = column_[static_cast<size_t>(i + 1)] + row_[static_cast<size_t>(j + 1)] + inv_z * matrix_[3];
    if (!(c.w > 0.0)) return std::nullopt;
    const double r = fixed_inv_w_ ? *fixed_inv_w_ : 1.0 / c.w;
    if (inv_w != nullptr) *inv_w = r;
    return dvec2((c.x * r + 1.0) * 0.5 * to_w_, (1.0 - c.y * r) * 0.5 * to_h_);
  }

  /// Whether every point has the same target clip w relative to its source clip w (eyes that look
  /// the same way): a warped triangle then maps onto its source triangle affinely.
  [[nodiscard]] bool uniform_w() const { return fixed_inv_w_.has_value(); }

  /// Source position of lattice column i / row j: pixel centres, and the extra ring outside the
  /// image on its edges.
  [[nodiscard]] double lattice_x(int i) const { return i < 0 ? 0.0 : i >= from_.width ? from_.width : i + 0.5; }
  [[nodiscard]] double lattice_y(int j) const { return j < 0 ? 0.0 : j >= from_.height ? from_.height : j + 0.5; }

  /// Inverse depth of lattice point (i, j), whose nearest pixel is (ci, cj): that pixel's; on the
  /// ring outside the image, the border pixel's extrapolated half a pixel outwards along each axis
  /// it lies beyond (1/z is affine in screen position on a plane), where the border pixel and the
  /// next one inwards differ by at most kRingSlope of it (one surface, not an edge or background).
  /// A ring point is a corner of coarse border triangles 16.5 px long: with the border pixel's own
  /// depth it tilted their depth by half a pixel's worth (+0.07 % on box-wall's wall at 160x90).
  [[nodiscard]] double lattice_inverse_depth(int i, int j, int ci, int cj) const {
    constexpr double kRingSlope = 0.1;
    const auto at = [&](int x, int y) {
      return static_cast<double>(grid_.inverse_depth[static_cast<size_t>(y) * grid_.width + static_cast<size_t>(x)]);
    };
    const double a = at(ci, cj);
    double out = a;
    const auto extend = [&](int x, int y) {
      const double b = at(x, y);
      if (a > 0.0 && b > 0.0 && std::abs(a - b) <= kRingSlope * a) out += 0.5 * (a - b);
    };
    if (grid_.width >= 2 && i < 0) extend(1, cj);
    if (grid_.width >= 2 && i >= grid_.width) extend(grid_.width - 2, cj);
    if (grid_.height >= 2 && j < 0) extend(ci, 1);
    if (grid_.height >= 2 && j >= grid_.height) extend(ci, grid_.height - 2);
    // Never nearer than the near plane, the nearest depth a pixel has (vertical_displacement_bound
    // relies on it).
    return std::min(out, 1.0 / from_.znear);
  }

  /// The warped vertex of source pixel centre (i, j).
  [[nodiscard]] GridVertex vertex(int i, int j) const {
    GridVertex v;
    v.sx = static_cast<float>(lattice_x(i));
    v.sy = static_cast<float>(lattice_y(j));
    const int ci = std::clamp(i, 0, grid_.width - 1), cj = std::clamp(j, 0, grid_.height - 1);
    const size_t p = static_cast<size_t>(cj) * grid_.width + static_cast<size_t>(ci);
    const double inv_z = lattice_inverse_depth(i, j, ci, cj);
    double inv_w = 1.0;
    const std::optional<dvec2> at = position(i, j, inv_z, &inv_w);
    // A vertex too far outside the target image cannot be rasterized in fixed point.
    if (!at || !(std::abs(at->x) < guard_ && std::abs(at->y) < guard_)) return v;
    v.x = static_cast<int32_t>(std::floor(at->x * kSubOne + 0.5));
    v.y = static_cast<int32_t>(std::floor(at->y * kSubOne + 0.5));
    v.q = static_cast<float>(inv_z * inv_w);
    v.r = static_cast<float>(inv_w);
    // The discontinuity measure: the larger excess opening of the two source gaps beside the vertex.
    const bool inside_row = i >= 0 && i < grid_.width;
    const float left_gap = inside_row && i > 0 ? grid_.excess[p - 1] : 0.0f;
    const float right_gap = inside_row ? grid_.excess[p] : 0.0f;
    v.disc = static_cast<float>(step_scale_ * std::max(left_gap, right_gap));
    v.valid = true;
    return v;
  }

 private:
  const WarpGrid& grid_;
  EyeCamera from_;
  int to_w_;
  int to_h_;
  double step_scale_;
  double guard_;
  dmat4 matrix_{1.0};
  std::vector<dvec4> column_;  ///< X·M[0] per lattice column i + 1
  std::vector<dvec4> row_;     ///< Y·M[1] − M[2] per lattice row j + 1
  std::optional<double> fixed_inv_w_;  ///< 1 / the clip w where it is the same for every point
};

/// Calls emit(i0, j0, i1, j1, i2, j2) for every triangle of cell (cx, cy), in source lattice
/// coordinates and positive orientation (clockwise on screen, y down). A subdivided cell (and one
/// too thin to have an interior) is split into native-resolution quads; a coarse cell is two
/// triangles, or, where a neighbour across one of its edges is subdivided, a fan from its centre
/// through every lattice point on those edges, so that the mesh has no T-junctions.
/// Whether cell (cx, cy) is warped at native resolution: subdivided, or too thin for an interior.
bool native_cell(const WarpGrid& g, int cx, int cy) {
  return g.subdivided[g.cell(cx, cy)] || g.x1(cx) - g.x0(cx) < 2 || g.y1(cy) - g.y0(cy) < 2;
}

template <class Emit>
void cell_triangles(const WarpGrid& g, int cx, int cy, Emit&& emit) {
  const int x0 = g.x0(cx), x1 = g.x1(cx), y0 = g.y0(cy), y1 = g.y1(cy);
  if (x1 <= x0 || y1 <= y0) return;
  if (native_cell(g, cx, cy)) {
    for (int j = y0; j < y1; ++j)
      for (int i = x0; i < x1; ++i) {
        emit(i, j, i + 1, j, i + 1, j + 1);
        emit(i, j, i + 1, j + 1, i, j + 1);
      }
    return;
  }
  // A neighbour warped at native resolution, subdivided or too thin (a 1-px partial cell at the
  // image's edge), puts a vertex at every lattice point of the shared edge.
  const bool fine_top = cy > 0 && native_cell(g, cx, cy - 1);
  const bool fine_right = cx + 1 < g.cells_x && native_cell(g, cx + 1, cy);
  const bool fine_bottom = cy + 1 < g.cells_y && native_cell(g, cx, cy + 1);
  const bool fine_left = cx > 0 && native_cell(g, cx - 1, cy);
  if (!fine_top && !fine_right && !fine_bottom && !fine_left) {
    emit(x0, y0, x1, y0, x1, y1);
    emit(x0, y0, x1, y1, x0, y1);
    return;
  }
  const int mi = (x0 + x1) / 2, mj = (y0 + y1) / 2;
  // Walk the border clockwise from the top-left corner; each edge contributes its start point and,
  // when fine, every lattice point before its end.
  int pi = x0, pj = y0;
  const auto step_to = [&](int ni, int nj) {
    emit(mi, mj, pi, pj, ni, nj);
    pi = ni;
    pj = nj;
  };
  for (int i = x0 + 1; i <= x1; ++i)
    if (fine_top || i == x1) step_to(i, y0);
  for (int j = y0 + 1; j <= y1; ++j)
    if (fine_right || j == y1) step_to(x1, j);
  for (int i = x1 - 1; i >= x0; --i)
    if (fine_bottom || i == x0) step_to(i, y1);
  for (int j = y1 - 1; j >= y0; --j)
    if (fine_left || j == y0) step_to(x0, j);
}

/// The target-side buffers of a warp for target rows [y0, y1), row-major from row y0: per pixel
/// the nearest kept fragment's inverse depth (-1 before any) and source position, and its
/// WarpPixel state. Fragments outside those rows are not drawn.
struct WarpTarget {
  int width = 0;
  int y0 = 0;
  int y1 = 0;
  float* q = nullptr;
  vec2* src = nullptr;
  uint8_t* state = nullptr;

  [[nodiscard]] size_t at(int x, int y) const {
    return static_cast<size_t>(y - y0) * static_cast<size_t>(width) + static_cast<size_t>(x);
  }
  /// The same buffers restricted to rows [r0, r1) (within [y0, y1)).
  [[nodiscard]] WarpTarget rows(int r0, int r1) const {
    const size_t skip = at(0, r0);
    return WarpTarget{width, r0, r1, q + skip, src + skip, state + skip};
  }
};

/// Rasterizes warped grid triangles into the target buffers and counts what it did.
class GridRasterizer {
 public:
  enum class Detect { off, interpolated, flags };

  /// `affine`: the reprojection keeps every point's clip w in proportion (Reprojector::uniform_w).
  GridRasterizer(const WarpTarget& target, const WarpOptions& options, bool affine)
      : t_(target),
        detect_(options.detect_disocclusions),
        rule_(options.rule),
        threshold_(options.discontinuity_px),
        affine_(affine) {}

  /// Rasterizes one grid triangle; `detect` enables disocclusion detection for it.
  void draw(const GridVertex& a, const GridVertex& b, const GridVertex& c, bool detect) {
    ++triangles;
    if (!a.valid || !b.valid || !c.valid) {
      ++culled;
      return;
    }
    const GridVertex* v[3] = {&a, &b, &c};
    const int64_t area = (int64_t{b.x} - a.x) * (int64_t{c.y} - a.y) - (int64_t{b.y} - a.y) * (int64_t{c.x} - a.x);
    // A warped triangle that turned over shows a surface the target eye sees from behind or that
    // lies hidden; the triangles in front of it cover its area.
    if (area <= 0) {
      ++culled;
      return;
    }
    // Pixel p's centre is at p * kSubOne + kSubHalf; the box holds every candidate centre.
    const int32_t min_x = std::min({a.x, b.x, c.x}), max_x = std::max({a.x, b.x, c.x});
    const int32_t min_y = std::min({a.y, b.y, c.y}), max_y = std::max({a.y, b.y, c.y});
    const auto first = [](int32_t lo) { return static_cast<int>((int64_t{lo} - kSubHalf + kSubOne - 1) >> kSubBits); };
    const auto last = [](int32_t hi) { return static_cast<int>((int64_t{hi} - kSubHalf) >> kSubBits); };
    const int px0 = std::max(first(min_x), 0), px1 = std::min(last(max_x), t_.width - 1);
    const int py0 = std::max(first(min_y), t_.y0), py1 = std::min(last(max_y), t_.y1 - 1);
    if (px0 > px1 || py0 > py1) return;

    int64_t ex[3], ey[3], e0[3], bias[3];
    const int64_t cx0 = int64_t{px0} * kSubOne + kSubHalf, cy0 = int64_t{py0} * kSubOne + kSubHalf;
    for (int k = 0; k < 3; ++k) {
      const int n = k == 2 ? 0 : k + 1;
      const int64_t dx = int64_t{v[n]->x} - v[k]->x, dy = int64_t{v[n]->y} - v[k]->y;
      // Fill rule: an edge is inclusive for exactly one of the two triangles that share it.
      bias[k] = (dy < 0 || (dy == 0 && dx > 0)) ? 0 : -1;
      e0[k] = dx * (cy0 - v[k]->y) - dy * (cx0 - v[k]->x);
      ex[k] = -dy * kSubOne;
      ey[k] = dx * kSubOne;
    }
    const double inv_area = 1.0 / static_cast<double>(area);
    Detect mode = Detect::off;
    if (detect && detect_) mode = rule_ == DiscardRule::all_vertices ? Detect::flags : Detect::interpolated;
    for (int y = py0; y <= py1; ++y) {
      int64_t e[3] = {e0[0], e0[1], e0[2]};
      for (int x = px0; x <= px1; ++x) {
        if (e[0] + bias[0] >= 0 && e[1] + bias[1] >= 0 && e[2] + bias[2] >= 0) fragment(v, e, inv_area, mode, x, y);
        for (int k = 0; k < 3; ++k) e[k] += ex[k];
      }
      for (int k = 0; k < 3; ++k) e0[k] += ey[k];
    }
  }

  /// The native quad (a, b, c, d) = ((i, j), (i+1, j), (i+1, j+1), (i, j+1)) when a and b lie
  /// exactly on a row of pixel centres (a reprojection without vertical motion): its two triangles
  /// cover pixel centres of that row only, on the top edge a-b, which the fill rule includes from a
  /// up to, not including, b — the half-open span [x_a, x_b). Drawn as that span, with the
  /// triangles' interpolation restricted to the edge (c's weight is 0 there). Returns false, and
  /// draws nothing, when a and b are not on one pixel-centre row.
  bool top_edge_span(const GridVertex& a, const GridVertex& b, bool detect) {
    if (a.y != b.y || !a.valid || !b.valid || ((int64_t{a.y} - kSubHalf) & (kSubOne - 1)) != 0) return false;
    const int64_t row = (int64_t{a.y} - kSubHalf) >> kSubBits;
    triangles += 2;
    if (b.x <= a.x) {
      ++culled;  // turned over: the triangle on this edge is culled
      return true;
    }
    if (row < t_.y0 || row >= t_.y1) return true;
    // Pixel centres p * kSubOne + kSubHalf in [a.x, b.x).
    const int p0 = std::max(static_cast<int>((int64_t{a.x} - kSubHalf + kSubOne - 1) >> kSubBits), 0);
    const int p1 = std::min(static_cast<int>((int64_t{b.x} - kSubHalf - 1) >> kSubBits), t_.width - 1);
    const double inv_len = 1.0 / static_cast<double>(int64_t{b.x} - a.x);
    const GridVertex* v[3] = {&a, &b, &a};
    const Detect mode = detect && detect_ ? (rule_ == DiscardRule::all_vertices ? Detect::flags : Detect::interpolated)
                                          : Detect::off;
    for (int p = p0; p <= p1; ++p) {
      const int64_t along = int64_t{p} * kSubOne + kSubHalf - a.x;
      // As edge-function weights: b's share of the edge, a's the rest, nothing for the third vertex.
      const int64_t e[3] = {0, int64_t{b.x} - a.x - along, along};
      fragment(v, e, inv_len, mode, p, static_cast<int>(row));
    }
    return true;
  }

  uint64_t triangles = 0;
  uint64_t culled = 0;
  uint64_t fragments = 0;
  uint64_t discarded = 0;

 private:
  void fragment(const GridVertex* const v[3], const int64_t e[3], double inv_area, Detect mode, int x, int y) {
    ++fragments;
    // The weight of vertex k is the edge function of the opposite edge over the area: the target
    // screen's barycentrics, in which the inverse target depth is linear.
    const double l0 = static_cast<double>(e[1]) * inv_area;
    const double l1 = static_cast<double>(e[2]) * inv_area;
    const double l2 = 1.0 - l0 - l1;
    // The source position of the triangle's plane seen here: the point's world barycentrics are
    // l_k / w_k (target clip w), and its source position weighs each vertex's by its source clip w,
    // so vertex k weighs l_k r_k with r_k = source w / target w. Eyes that look the same way give
    // every point one r: the source position is then affine in the target's (l_k), at any depths.
    double w0 = l0, w1 = l1, w2 = l2;
    if (!affine_) {
      const double p0 = l0 * v[0]->r, p1 = l1 * v[1]->r, p2 = l2 * v[2]->r;
      const double inv = 1.0 / (p0 + p1 + p2);
      w0 = p0 * inv;
      w1 = p1 * inv;
      w2 = p2 * inv;
    }
    const size_t o = t_.at(x, y);
    // The flags interpolate to exactly 1 where every vertex of non-zero weight is flagged; a
    // weight is zero exactly when the edge function of the opposite edge is.
    const bool discard =
        mode == Detect::flags
            ? (e[1] == 0 || v[0]->disc > threshold_) && (e[2] == 0 || v[1]->disc > threshold_) &&
                  (e[0] == 0 || v[2]->disc > threshold_)
            : mode == Detect::interpolated && w0 * v[0]->disc + w1 * v[1]->disc + w2 * v[2]->disc > threshold_;
    discarded += discard ? 1 : 0;
    // A discarded fragment still takes part in the depth test: the rubber sheet it belongs to
    // spans a region the source eye does not see, and warped surfaces behind it there come from
    // elsewhere in the source image (seen past an occluder that is missing from it).
    const auto q = static_cast<float>(l0 * v[0]->q + l1 * v[1]->q + l2 * v[2]->q);
    if (!(q > t_.q[o])) return;
    t_.q[o] = q;
    if (discard) {
      t_.state[o] = static_cast<uint8_t>(WarpPixel::discarded);
      return;
    }
    t_.src[o] = vec2(static_cast<float>(w0 * v[0]->sx + w1 * v[1]->sx + w2 * v[2]->sx),
                     static_cast<float>(w0 * v[0]->sy + w1 * v[1]->sy + w2 * v[2]->sy));
    t_.state[o] = static_cast<uint8_t>(WarpPixel::covered);
  }

  WarpTarget t_;
  bool detect_;
  DiscardRule rule_;
  double threshold_;
  bool affine_;
};

/// The warped vertices of one row of cells: lattice rows y0..y1, every column, computed for the
/// points the cells' triangles use.
class CellRowVertices {
 public:
  CellRowVertices(const WarpGrid& g, const Reprojector& reproject, int cy)
      : g_(g), reproject_(reproject), y0_(g.y0(cy)), rows_(std::max(g.y1(cy) - g.y0(cy) + 1, 1)),
        v_(static_cast<size_t>(rows_) * (g.width + 2)) {}

  /// Computes the vertices cell (cx) uses: its whole block when it is subdivided or thin,
  /// otherwise its corners, its centre and every point of its edges (the fine ones need them all).
  /// Called for the cells of the row in order cx = 0, 1, ...: a cell's first column is the last
  /// column of the cell before, which computed all of it either way.
  void prepare(int cx, int cy) {
    const int x0 = g_.x0(cx), x1 = g_.x1(cx), y1 = g_.y1(cy);
    const int first = cx > 0 ? x0 + 1 : x0;
    if (g_.subdivided[g_.cell(cx, cy)] || x1 - x0 < 2 || y1 - y0_ < 2) {
      for (int j = y0_; j <= y1; ++j)
        for (int i = first; i <= x1; ++i) set(i, j);
      return;
    }
    for (int i = first; i <= x1; ++i) {
      set(i, y0_);
      set(i, y1);
    }
    for (int j = y0_ + 1; j < y1; ++j) {
      if (cx == 0) set(x0, j);
      set(x1, j);
    }
    set((x0 + x1) / 2, (y0_ + y1) / 2);
  }

  [[nodiscard]] const GridVertex& at(int i, int j) const { return v_[index(i, j)]; }

 private:
  [[nodiscard]] size_t index(int i, int j) const {
    return static_cast<size_t>(j - y0_) * static_cast<size_t>(g_.width + 2) + static_cast<size_t>(i + 1);
  }
  void set(int i, int j) { v_[index(i, j)] = reproject_.vertex(i, j); }

  const WarpGrid& g_;
  const Reprojector& reproject_;
  int y0_;
  int rows_;
  std::vector<GridVertex> v_;
};

/// Marks the occluding-edge band of the target's rows: a covered pixel whose right-hand
/// neighbour is covered by a surface nearer by more than `step` pixels of disparity. The nearer
/// surface's silhouette lies somewhere between its last source pixel centre and the one before,
/// so its warped image may reach up to a pixel further left than its first warped vertex: the
/// pixel there shows either surface and is left for the hole filler. With `discarded_too` (the
/// interpolated rule, which discards fragments of the surfaces beside a gap as well, their
/// silhouettes among them) a discarded neighbour that near counts too (its depth is stored).
void mark_occluding_edges(const WarpTarget& t, double disparity_per_inverse_depth, double step, bool discarded_too) {
  const auto nearer_side = [&](uint8_t state) {
    return state == static_cast<uint8_t>(WarpPixel::covered) ||
           (discarded_too && state == static_cast<uint8_t>(WarpPixel::discarded));
  };
  for (int y = t.y0; y < t.y1; ++y) {
    const size_t row = t.at(0, y);
    for (int x = 0; x + 1 < t.width; ++x) {
      const size_t o = row + x;
      if (t.state[o] != static_cast<uint8_t>(WarpPixel::covered) || !nearer_side(t.state[o + 1])) continue;
      if (disparity_per_inverse_depth * (static_cast<double>(t.q[o + 1]) - t.q[o]) > step)
        t.state[o] = static_cast<uint8_t>(WarpPixel::occluding_edge);
    }
  }
}

/// Writes the target's rows of the target eye from the warp buffers and counts their pixels.
void resolve_rows(const WarpTarget& t, const Image& source, Image& target, WarpStats& stats) {
  const int sw = source.width(), sh = source.height();
  const EyeReader from(source);
  EyeWriter out(target);
  for (int y = t.y0; y < t.y1; ++y)
    for (int x = 0; x < t.width; ++x) {
      const size_t b = t.at(x, y);
      const size_t o = static_cast<size_t>(y) * static_cast<size_t>(t.width) + static_cast<size_t>(x);
      if (t.state[b] != static_cast<uint8_t>(WarpPixel::covered)) {
        const auto state = static_cast<WarpPixel>(t.state[b]);
        (state == WarpPixel::discarded        ? stats.pixels_discarded
         : state == WarpPixel::occluding_edge ? stats.pixels_occluding_edge
                                              : stats.pixels_uncovered)++;
        out.hole(o);
        continue;
      }
      ++stats.pixels_covered;
      // Bilinear lookup: texel centres sit at integer + 0.5, so a source position on a pixel
      // centre reads that pixel alone.
      const vec2 s = t.src[b];
      const float u = s.x - 0.5f, v = s.y - 0.5f;
      const float fu = std::floor(u), fv = std::floor(v);
      const float ax = u - fu, ay = v - fv;
      const auto at = [&](int i, int j) {
        return from.rgb(static_cast<size_t>(std::clamp(j, 0, sh - 1)) * sw + static_cast<size_t>(std::clamp(i, 0, sw - 1)));
      };
      const int i0 = static_cast<int>(fu), j0 = static_cast<int>(fv);
      const auto row_lerp = [&](int j) { return at(i0, j) + ax * (at(i0 + 1, j) - at(i0, j)); };
      // On a row of source pixel centres (every position a horizontal rig gives native cells) the
      // lower row has weight 0: the lookup is the upper row's, without reading the lower one.
      const vec3 top = row_lerp(j0);
      const vec3 rgb = ay == 0.0f ? top : top + ay * (row_lerp(j0 + 1) - top);
      // The other AOVs come from the source pixel the position falls in.
      const size_t n = static_cast<size_t>(std::clamp(static_cast<int>(std::floor(s.y)), 0, sh - 1)) * sw +
                       static_cast<size_t>(std::clamp(static_cast<int>(std::floor(s.x)), 0, sw - 1));
      const float depth = t.q[b] > 0.0f ? 1.0f / t.q[b] : std::numeric_limits<float>::infinity();
      out.copy(o, rgb, from.normal(n), from.albedo(n), depth, from.prim(n), Source::reprojected);
    }
}

/// Largest vertical displacement (px) the reprojection gives the source image's corners over all
/// depths from the near plane to infinity. A stereo rig with a horizontal baseline gives 0.
double vertical_displacement_bound(const Reprojector& reproject, const EyeCamera& from) {
  double bound = 0.0;
  for (const int i : {0, from.width - 1})
    for (const int j : {0, from.height - 1})
      for (const double inv_z : {0.0, 1.0 / from.znear}) {
        const std::optional<dvec2> p = reproject.position(i, j, inv_z);
        bound = p ? std::max(bound, std::abs(p->y - reproject.lattice_y(j))) : std::numeric_limits<double>::infinity();
      }
  return bound;
}

}  // namespace

double binocular_parallax(double interaxial, double depth) {
  if (!std::isfinite(depth)) return 0.0;
  return 2.0 * std::atan(interaxial / (2.0 * depth));
}

double parallax_difference_arcmin(double interaxial, double zmin, double zmax) {
  return std::abs(binocular_parallax(interaxial, zmin) - binocular_parallax(interaxial, zmax)) * kArcminPerRadian;
}

uint64_t WarpGrid::flagged_count() const {
  return static_cast<uint64_t>(std::count(flagged.begin(), flagged.end(), uint8_t{1}));
}

uint64_t WarpGrid::opening_count() const {
  return static_cast<uint64_t>(std::count(opening.begin(), opening.end(), uint8_t{1}));
}

uint64_t WarpGrid::subdivided_count() const {
  return static_cast<uint64_t>(std::count(subdivided.begin(), subdivided.end(), uint8_t{1}));
}

WarpGrid build_warp_grid(std::span<const float> depth, int width, int height, const GridSettings& settings,
                         const Executor& executor) {
  const double threshold_arcmin = settings.threshold_arcmin, interaxial = settings.interaxial;
  if (!(threshold_arcmin > 0.0) || !std::isfinite(threshold_arcmin))
    throw InputError(fmt::format("grid warp: parallax threshold {} arcmin must be positive and finite", threshold_arcmin));
  if (width < 1 || height < 1 || depth.size() != static_cast<size_t>(width) * static_cast<size_t>(height))
    throw InputError(fmt::format("grid warp: a depth plane of {} values does not fit a {}x{} image", depth.size(), width, height));
  WarpGrid g;
  g.width = width;
  g.height = height;
  g.cells_x = (width + kGridCell - 1) / kGridCell;
  g.cells_y = (height + kGridCell - 1) / kGridCell;
  g.threshold_arcmin = threshold_arcmin;
  const size_t cells = static_cast<size_t>(g.cells_x) * g.cells_y;
  g.zmin.assign(cells, std::numeric_limits<float>::infinity());
  g.zmax.assign(cells, 0.0f);
  g.parallax_arcmin.assign(cells, 0.0f);
  g.flagged.assign(cells, 0);
  g.opening.assign(cells, 0);
  g.subdivided.assign(cells, 0);
  g.inverse_depth.resize(depth.size());
  g.excess.resize(depth.size());
  // The excess opening, in units of f e, above which a cell opens a gap (none when not asked).
  const double opening_limit = settings.opening_px > 0.0 ? settings.opening_px / (settings.focal_px * interaxial)
                                                         : std::numeric_limits<double>::infinity();
  // Per pixel row: its gaps, then per cell column the depth range over the cell's lattice span
  // (columns 16 cx .. 16 cx + 16, clipped) and whether a gap in its own columns opens.
  const size_t row_cells = static_cast<size_t>(height) * g.cells_x;
  std::vector<float> row_lo(row_cells), row_hi(row_cells);
  std::vector<uint8_t> row_open(row_cells);
  executor.for_range(static_cast<size_t>(height), 8, [&](size_t begin, size_t end) {
    for (size_t j = begin; j < end; ++j) {
      gap_row(depth, width, static_cast<int>(j), g.inverse_depth.data(), g.excess.data());
      const float* z = depth.data() + j * width;
      const float* excess = g.excess.data() + j * width;
      for (int cx = 0; cx < g.cells_x; ++cx) {
        float lo = std::numeric_limits<float>::infinity(), hi = 0.0f;
        for (int x = std::max(g.x0(cx), 0); x <= std::min(g.x1(cx), width - 1); ++x) {
          lo = std::min(lo, z[x]);
          hi = std::max(hi, z[x]);
        }
        bool open = false;
        if (std::isfinite(opening_limit))
          for (int x = std::max(g.x0(cx), 0); x < std::min(g.x1(cx), width - 1); ++x) open |= excess[x] > opening_limit;
        const size_t k = j * g.cells_x + static_cast<size_t>(cx);
        row_lo[k] = lo;
        row_hi[k] = hi;
        row_open[k] = open ? 1 : 0;
      }
    }
  });
  executor.for_each(static_cast<size_t>(g.cells_y), [&](size_t row) {
    const int cy = static_cast<int>(row);
    for (int cx = 0; cx < g.cells_x; ++cx) {
      float lo = std::numeric_limits<float>::infinity(), hi = 0.0f;
      const size_t c = g.cell(cx, cy);
      for (int y = std::max(g.y0(cy), 0); y <= std::min(g.y1(cy), height - 1); ++y) {
        const size_t k = static_cast<size_t>(y) * g.cells_x + static_cast<size_t>(cx);
        lo = std::min(lo, row_lo[k]);
        hi = std::max(hi, row_hi[k]);
        g.opening[c] |= row_open[k];
      }
      g.zmin[c] = lo;
      g.zmax[c] = hi;
      g.parallax_arcmin[c] = static_cast<float>(parallax_difference_arcmin(interaxial, lo, hi));
      g.flagged[c] = g.parallax_arcmin[c] > threshold_arcmin ? 1 : 0;
    }
  });
  // The paper's T-junction rule: a flagged cell's 4-neighbours are subdivided too.
  for (int cy = 0; cy < g.cells_y; ++cy)
    for (int cx = 0; cx < g.cells_x; ++cx) {
      const bool s = g.flagged[g.cell(cx, cy)] || g.opening[g.cell(cx, cy)] || (cx > 0 && g.flagged[g.cell(cx - 1, cy)]) ||
                     (cx + 1 < g.cells_x && g.flagged[g.cell(cx + 1, cy)]) || (cy > 0 && g.flagged[g.cell(cx, cy - 1)]) ||
                     (cy + 1 < g.cells_y && g.flagged[g.cell(cx, cy + 1)]);
      g.subdivided[g.cell(cx, cy)] = s ? 1 : 0;
    }
  return g;
}

std::vector<uint8_t> grid_warp(const WarpGrid& grid, const Image& source, const EyeCamera& from, const EyeCamera& to,
                               double interaxial, const WarpOptions& options, const Executor& executor, Image& target,
                               WarpStats& stats) {
  if (source.width() != grid.width || source.height() != grid.height || target.width() != to.width ||
      target.height() != to.height || from.width != grid.width || from.height != grid.height)
    throw InputError(fmt::format("grid warp: image sizes disagree (grid {}x{}, source {}x{}, target {}x{})", grid.width,
                                 grid.height, source.width(), source.height(), target.width(), target.height()));
  if (options.detect_disocclusions && (!(options.discontinuity_px > 0.0) || !std::isfinite(options.discontinuity_px)))
    throw InputError(fmt::format("grid warp: discontinuity threshold {} px must be positive and finite",
                                 options.discontinuity_px));
  const Reprojector reproject(grid, from, to, interaxial);
  const size_t w = static_cast<size_t>(to.width);
  std::vector<uint8_t> state(w * static_cast<size_t>(to.height), static_cast<uint8_t>(WarpPixel::uncovered));
  // Per cell row: its grid triangles' counts, and the pixel counts of the target rows it resolves.
  std::vector<WarpStats> row_stats(static_cast<size_t>(grid.cells_y));
  const auto warp_row = [&](int cy, const WarpTarget& buffers) {
    CellRowVertices vertices(grid, reproject, cy);
    GridRasterizer raster(buffers, options, reproject.uniform_w());
    for (int cx = 0; cx < grid.cells_x; ++cx) {
      vertices.prepare(cx, cy);
      // A coarse cell is flat in parallax by construction: nothing in it is discarded.
      const bool detect = grid.subdivided[grid.cell(cx, cy)] != 0;
      if (native_cell(grid, cx, cy)) {
        for (int j = grid.y0(cy); j < grid.y1(cy); ++j)
          for (int i = grid.x0(cx); i < grid.x1(cx); ++i) {
            const GridVertex &a = vertices.at(i, j), &b = vertices.at(i + 1, j);
            if (raster.top_edge_span(a, b, detect)) continue;
            const GridVertex &c = vertices.at(i + 1, j + 1), &d = vertices.at(i, j + 1);
            raster.draw(a, b, c, detect);
            raster.draw(a, c, d, detect);
          }
        continue;
      }
      cell_triangles(grid, cx, cy, [&](int i0, int j0, int i1, int j1, int i2, int j2) {
        raster.draw(vertices.at(i0, j0), vertices.at(i1, j1), vertices.at(i2, j2), detect);
      });
    }
    WarpStats& counts = row_stats[static_cast<size_t>(cy)];
    counts.triangles = raster.triangles;
    counts.triangles_culled = raster.culled;
    counts.fragments = raster.fragments;
    counts.fragments_discarded = raster.discarded;
  };
  // Marks the occluding edges of finished target rows and writes them into the target eye.
  const auto resolve = [&](const WarpTarget& rows, WarpStats& counts) {
    if (options.detect_disocclusions && options.occluding_edge_px > 0.0)
      mark_occluding_edges(rows, from.f_px * interaxial, options.occluding_edge_px,
                           options.rule == DiscardRule::interpolated);
    resolve_rows(rows, source, target, counts);
  };
  // The target rows [16 cy, 16 cy + 16) of cell row cy, clipped to the image.
  const auto own_rows = [&](int cy) {
    return std::pair(cy * kGridCell, std::min(cy * kGridCell + kGridCell, to.height));
  };

  const double vertical = vertical_displacement_bound(reproject, from);
  // Where the reprojection moves no vertex off its source row (within half a fixed-point step, so
  // every vertex snaps back onto it; any rig with a horizontal baseline), cell row cy draws only
  // into its own rows: its lattice rows' pixel centres, each row on the top edges that the fill
  // rule includes. Each cell row is then warped and resolved in one task, in buffers of its own
  // rows that stay in cache, instead of a warp over the whole image and a second pass reading the
  // whole-image buffers back. Which fragment wins a pixel does not change, nor does the image.
  if (options.resolve_per_cell_row && vertical < 0.5 / static_cast<double>(kSubOne) && to.height == grid.height) {
    executor.for_each(static_cast<size_t>(grid.cells_y), [&](size_t k) {
      const int cy = static_cast<int>(k);
      const auto [y0, y1] = own_rows(cy);
      const size_t n = static_cast<size_t>(y1 - y0) * w;
      std::vector<float> q(n, -1.0f);
      std::vector<vec2> src(n);
      const WarpTarget buffers{to.width, y0, y1, q.data(), src.data(), state.data() + static_cast<size_t>(y0) * w};
      warp_row(cy, buffers);
      resolve(buffers, row_stats[k]);
    });
  } else {
    std::vector<float> q(state.size(), -1.0f);
    std::vector<vec2> src(state.size());
    const WarpTarget whole{to.width, 0, to.height, q.data(), src.data(), state.data()};
    // A cell row of lattice rows [16 cy, 16 cy + 16] writes target rows within 7 px of those when
    // the reprojection moves nothing further vertically, so rows of one parity never share a pixel
    // and run in parallel: even rows first, then odd ones — the same order on any thread count.
    const bool banded = vertical < 7.0;
    for (int parity = 0; parity < 2; ++parity) {
      const size_t count = static_cast<size_t>(grid.cells_y - parity + 1) / 2;
      if (banded) {
        executor.for_each(count, [&](size_t k) { warp_row(static_cast<int>(2 * k) + parity, whole); });
      } else {
        for (size_t k = 0; k < count; ++k) warp_row(static_cast<int>(2 * k) + parity, whole);
      }
    }
    // Resolved in bands of 16 rows; a band's pixel counts go with the cell row of the same index.
    const int bands = (to.height + kGridCell - 1) / kGridCell;
    if (static_cast<size_t>(bands) > row_stats.size()) row_stats.resize(static_cast<size_t>(bands));
    executor.for_each(static_cast<size_t>(bands), [&](size_t b) {
      const auto [y0, y1] = own_rows(static_cast<int>(b));
      resolve(whole.rows(y0, y1), row_stats[b]);
    });
  }

  stats = WarpStats{};
  for (const WarpStats& s : row_stats) {
    stats.triangles += s.triangles;
    stats.triangles_culled += s.triangles_culled;
    stats.fragments += s.fragments;
    stats.fragments_discarded += s.fragments_discarded;
    stats.pixels_covered += s.pixels_covered;
    stats.pixels_discarded += s.pixels_discarded;
    stats.pixels_occluding_edge += s.pixels_occluding_edge;
    stats.pixels_uncovered += s.pixels_uncovered;
  }
  return state;
}

Image grid_overlay(const WarpGrid& grid, const Image& source) {
  Image out(source.width(), source.height());
  Plane& rgb = out.add_plane(planes::rgb);
  const float* src = source.data_f32(planes::rgb);
  float* dst = rgb.data_f32();
  const int w = grid.width, h = grid.height;
  for (size_t i = 0; i < source.pixel_count() * 3; ++i) dst[i] = 0.35f * src[i];
  const auto tint = [&](int x, int y, const vec3& c, float a) {
    float* p = dst + 3 * (static_cast<size_t>(y) * w + x);
    for (int k = 0; k < 3; ++k) p[k] = (1.0f - a) * p[k] + a * c[k];
  };
  const vec3 red(1.0f, 0.05f, 0.02f), orange(1.0f, 0.45f, 0.0f), line(0.9f, 0.9f, 0.9f);
  for (int cy = 0; cy < grid.cells_y; ++cy)
    for (int cx = 0; cx < grid.cells_x; ++cx) {
      const size_t c = grid.cell(cx, cy);
      if (!grid.subdivided[c]) continue;
      const vec3 colour = grid.flagged[c] ? red : orange;
      for (int y = cy * kGridCell; y < std::min((cy + 1) * kGridCell, h); ++y)
        for (int x = cx * kGridCell; x < std::min((cx + 1) * kGridCell, w); ++x) tint(x, y, colour, 0.45f);
    }
  // Triangle edges of the coarse cells, drawn between the pixel centres they join.
  const auto segment = [&](int i0, int j0, int i1, int j1) {
    const int n = std::max(std::abs(i1 - i0), std::abs(j1 - j0));
    for (int s = 0; s <= n; ++s) {
      const int x = n == 0 ? i0 : static_cast<int>(std::lround(i0 + double(i1 - i0) * s / n));
      const int y = n == 0 ? j0 : static_cast<int>(std::lround(j0 + double(j1 - j0) * s / n));
      if (x >= 0 && y >= 0 && x < w && y < h) tint(x, y, line, 0.8f);
    }
  };
  for (int cy = 0; cy < grid.cells_y; ++cy)
    for (int cx = 0; cx < grid.cells_x; ++cx) {
      if (grid.subdivided[grid.cell(cx, cy)]) continue;
      cell_triangles(grid, cx, cy, [&](int i0, int j0, int i1, int j1, int i2, int j2) {
        segment(i0, j0, i1, j1);
        segment(i1, j1, i2, j2);
        segment(i2, j2, i0, j0);
      });
    }
  return out;
}

}  // namespace sb
