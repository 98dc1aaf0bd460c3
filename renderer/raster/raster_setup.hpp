// Internal to the rasterizer: the vertex stage (projection to homogeneous pixel coordinates),
// frustum and back-face culling, near-plane and guard-band clipping, and the fixed-point triangle
// setup whose records the tiles rasterize.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "renderer/math.hpp"
#include "renderer/rig.hpp"
#include "renderer/scene_geometry.hpp"

namespace sb::raster {

/// Snapped vertex positions carry 13 sub-pixel bits (1/8192 px) and pixel centres are integers.
/// Snapping moves a vertex by at most 1/16384 px per axis, which keeps long axis-aligned edges that pass
/// within a hair of a pixel-centre column on the same side as an exact ray test.
constexpr int kSubpixelBits = 13;
constexpr int64_t kSubpixelOne = int64_t{1} << kSubpixelBits;
constexpr int64_t kSubpixelHalf = kSubpixelOne / 2;

/// Clipped triangles keep inside [-G, W + G] x [-G, H + G] pixels. With images of at most 2^14 px
/// a snapped coordinate stays below (2^14 + 2^15) 2^13 < 2^28.6 in magnitude (int32), a difference
/// of two below 2^29.6, and an edge function (a sum of two products of such differences) below
/// 2^60.2: int64 never overflows.
constexpr double kGuardBandPx = 32768.0;  // 2^15

/// Outcode bits: the four image borders (culling only), the near plane (culling and clipping),
/// the four guard-band planes (clipping only) and invalid positions.
enum Outcode : uint32_t {
  kOutLeft = 1u << 0,
  kOutRight = 1u << 1,
  kOutTop = 1u << 2,
  kOutBottom = 1u << 3,
  kOutNear = 1u << 4,
  kOutGuardLeft = 1u << 5,
  kOutGuardRight = 1u << 6,
  kOutGuardTop = 1u << 7,
  kOutGuardBottom = 1u << 8,
  kOutInvalid = 1u << 9,  ///< a non-finite position: its triangles are dropped as culled
};
constexpr uint32_t kCullBits = kOutLeft | kOutRight | kOutTop | kOutBottom | kOutNear | kOutInvalid;
constexpr uint32_t kClipBits = kOutNear | kOutGuardLeft | kOutGuardRight | kOutGuardTop | kOutGuardBottom;
constexpr int kClipPlaneCount = 5;  ///< near, then the guard band's left, right, top, bottom

/// A vertex after the vertex stage. (hx, hy, w) are homogeneous pixel coordinates — the clip-space
/// position after the viewport transform, before the division: x_px = hx / w, y_px = hy / w, and
/// w is the linear view depth. fx, fy are the snapped pixel position, valid when no clip bit is set.
/// Trivial on purpose: the vertex stage writes every element, so the array is not zero-filled first.
struct ProjectedVertex {
  double hx;
  double hy;
  double w;
  int32_t fx;
  int32_t fy;
  uint32_t outcode;
};

/// The eye's view-projection-viewport transform and its culling and clipping planes.
class VertexTransform {
 public:
  explicit VertexTransform(const EyeCamera& eye);

  /// World position -> homogeneous pixel coordinates, outcode and (when unclipped) snapped position.
  [[nodiscard]] ProjectedVertex project(const vec3& position) const;
  /// Outcode of a homogeneous pixel position; clip bits are set exactly where clip_distance() < 0.
  [[nodiscard]] uint32_t outcode(double hx, double hy, double w) const;
  /// Signed distance (scaled) to clip plane `plane` (0 = near, 1..4 = guard band); >= 0 is inside.
  [[nodiscard]] double clip_distance(int plane, double hx, double hy, double w) const;

  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int height() const { return height_; }

 private:
  dvec4 row_x_{0.0}, row_y_{0.0}, row_w_{0.0};  // rows of viewport * projection * view
  int width_ = 1;
  int height_ = 1;
  double znear_ = 0.05;
  double guard_right_ = 0.0;   // W + G
  double guard_bottom_ = 0.0;  // H + G
};

/// Snaps a homogeneous pixel coordinate to the sub-pixel grid (round half up). Every snapped
/// vertex goes through this one function, so a vertex shared by triangles snaps identically.
[[nodiscard]] int32_t snap(double h, double w);

/// Perspective-correct interpolation planes of one scene triangle over continuous pixel
/// coordinates: plane p evaluates as p.x * x + p.y * y + p.z. With M = [V0 V1 V2] (columns
/// (hx, hy, w)), row i of M^-1 dotted with (x, y, 1) is b_i / w, so the planes of 1/w, b1/w and b2/w
/// follow from the ORIGINAL vertices; every clipped piece of the triangle shares them.
struct TrianglePlanes {
  dvec3 inv_w{0.0};
  dvec3 b1_w{0.0};
  dvec3 b2_w{0.0};
};

/// The planes of triangle (a, b, c); false when it is seen edge-on (singular M).
[[nodiscard]] bool triangle_planes(const ProjectedVertex& a, const ProjectedVertex& b, const ProjectedVertex& c,
                                   TrianglePlanes& planes);

/// A triangle (or a clipped piece of one) ready for the tiles, one cache line: snapped vertices
/// in positive orientation (edge functions >= 0 inside), its inclusive pixel range, the ids, and
/// the plane of 1/w for the depth test. The barycentric planes are recomputed for winners only.
struct alignas(64) RasterTriangle {
  int32_t x[3];
  int32_t y[3];
  uint16_t px0, py0, px1, py1;  ///< pixels [px0, px1] x [py0, py1] hold candidate pixel centres
  uint32_t prim;                ///< global triangle id
  uint32_t mesh;
  dvec3 inv_w;  ///< plane of 1/w
};

/// Counters of one chunk of triangles.
struct SetupCounts {
  uint64_t submitted = 0;
  uint64_t culled_backface = 0;
  uint64_t culled_frustum = 0;
  uint64_t clipped_near = 0;
  uint64_t emitted = 0;
  uint64_t skipped = 0;  ///< left out by the triangle mask
};

/// The inputs every chunk of the setup stage shares.
struct SetupInputs {
  const SceneGeometry* geometry = nullptr;
  const VertexTransform* transform = nullptr;
  const ProjectedVertex* vertices = nullptr;  ///< all meshes' vertices, mesh m from vertex_base[m]
  const size_t* vertex_base = nullptr;        ///< per mesh, prefix sums of the vertex counts
  dvec3 eye_origin{0.0};
  const uint8_t* triangle_mask = nullptr;  ///< per global triangle id; see RasterOptions
  uint8_t triangle_bit = 0;
};

/// Projects the vertices [begin, end) of the global vertex numbering (mesh m's vertex k is
/// vertex_base[m] + k).
void project_vertices(const SetupInputs& in, size_t begin, size_t end, ProjectedVertex* out);

/// Culls, clips and sets up the global triangles [begin, end) in id order, appending the records
/// of those that can cover a pixel centre to `out`. Throws InputError on an out-of-range index.
void setup_triangles(const SetupInputs& in, uint32_t begin, uint32_t end, std::vector<RasterTriangle>& out,
                     SetupCounts& counts);

}  // namespace sb::raster
