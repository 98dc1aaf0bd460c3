// The rasterizer's geometry stages: vertex projection, culling, homogeneous clipping against the
// near plane and the guard band, and fixed-point setup of the triangles the tiles draw.
#include "renderer/raster/raster_setup.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/scene.hpp"

namespace sb::raster {

VertexTransform::VertexTransform(const EyeCamera& eye)
    : width_(eye.width),
      height_(eye.height),
      znear_(eye.znear),
      guard_right_(eye.width + kGuardBandPx),
      guard_bottom_(eye.height + kGuardBandPx) {
  // Fold the viewport into the view-projection: hx = (x_c + w_c) W/2, hy = (w_c - y_c) H/2, w = w_c.
  // Only these three rows are needed; the linear depth w replaces z_c (no far clipping).
  const dmat4 pv = eye.projection_matrix() * eye.view_matrix();
  const auto row = [&pv](int r) { return dvec4(pv[0][r], pv[1][r], pv[2][r], pv[3][r]); };
  row_x_ = (row(0) + row(3)) * (0.5 * eye.width);
  row_y_ = (row(3) - row(1)) * (0.5 * eye.height);
  row_w_ = row(3);
}

double VertexTransform::clip_distance(int plane, double hx, double hy, double w) const {
  switch (plane) {
    case 0: return w - znear_;  // z_c >= -w_c, i.e. view depth >= znear
    case 1: return hx + kGuardBandPx * w;
    case 2: return guard_right_ * w - hx;
    case 3: return hy + kGuardBandPx * w;
    default: return guard_bottom_ * w - hy;
  }
}

uint32_t VertexTransform::outcode(double hx, double hy, double w) const {
  uint32_t code = 0;
  if (hx < 0.0) code |= kOutLeft;
  if (hx > width_ * w) code |= kOutRight;
  if (hy < 0.0) code |= kOutTop;
  if (hy > height_ * w) code |= kOutBottom;
  for (int p = 0; p < kClipPlaneCount; ++p)
    if (clip_distance(p, hx, hy, w) < 0.0) code |= kOutNear << p;
  return code;
}

ProjectedVertex VertexTransform::project(const vec3& position) const {
  const dvec4 p(dvec3(position), 1.0);
  ProjectedVertex v{};
  v.hx = glm::dot(row_x_, p);
  v.hy = glm::dot(row_y_, p);
  v.w = glm::dot(row_w_, p);
  if (!std::isfinite(v.hx) || !std::isfinite(v.hy) || !std::isfinite(v.w)) {
    v.outcode = kCullBits;
    return v;
  }
  v.outcode = outcode(v.hx, v.hy, v.w);
  if ((v.outcode & kClipBits) == 0) {
    v.fx = snap(v.hx, v.w);
    v.fy = snap(v.hy, v.w);
  }
  return v;
}

int32_t snap(double h, double w) {
  // floor(x * 2^13 + 0.5) without a libm call; |x| < 2^16 here, so the int64 conversion is exact.
  const double s = h / w * static_cast<double>(kSubpixelOne) + 0.5;
  const auto i = static_cast<int64_t>(s);
  return static_cast<int32_t>(i - (static_cast<double>(i) > s ? 1 : 0));
}

bool triangle_planes(const ProjectedVertex& a, const ProjectedVertex& b, const ProjectedVertex& c,
                     TrianglePlanes& planes) {
  const dvec3 p0(a.hx, a.hy, a.w), p1(b.hx, b.hy, b.w), p2(c.hx, c.hy, c.w);
  const dvec3 c0 = glm::cross(p1, p2), c1 = glm::cross(p2, p0), c2 = glm::cross(p0, p1);
  const double det = glm::dot(p0, c0);
  if (!(std::abs(det) > 0.0) || !std::isfinite(det)) return false;
  const double inv_det = 1.0 / det;
  planes.inv_w = (c0 + c1 + c2) * inv_det;
  planes.b1_w = c1 * inv_det;
  planes.b2_w = c2 * inv_det;
  return true;
}

namespace {

/// A snapped vertex entering setup.
struct SnappedVertex {
  int32_t fx, fy;
};

/// A polygon vertex during clipping, in homogeneous pixel coordinates.
struct ClipVertex {
  double hx, hy, w;
  uint32_t outcode;
};

/// A convex polygon clipped by five planes has at most 3 + 5 vertices.
constexpr int kMaxClipVertices = 8;

int64_t min3(int64_t a, int64_t b, int64_t c) { return std::min(a, std::min(b, c)); }
int64_t max3(int64_t a, int64_t b, int64_t c) { return std::max(a, std::max(b, c)); }

/// Turns (possibly clipped) triangles into RasterTriangle records.
class Setup {
 public:
  Setup(const SetupInputs& in, std::vector<RasterTriangle>& out, SetupCounts& counts)
      : transform_(*in.transform), out_(out), counts_(counts) {}

  /// Starts a scene triangle. Its planes are computed when its first piece reaches the tiles, so
  /// that triangles covering no pixel centre cost no more than their bounding box.
  void begin(const ProjectedVertex& a, const ProjectedVertex& b, const ProjectedVertex& c, uint32_t prim,
             uint32_t mesh) {
    vertices_[0] = &a, vertices_[1] = &b, vertices_[2] = &c;
    prim_ = prim;
    mesh_ = mesh;
    planes_ = PlaneState::unknown;
  }

  /// Emits the current triangle unclipped.
  void emit_unclipped() {
    const ProjectedVertex &a = *vertices_[0], &b = *vertices_[1], &c = *vertices_[2];
    emit({a.fx, a.fy}, {b.fx, b.fy}, {c.fx, c.fy});
  }

  /// Positive orientation and pixel range; drops zero-area pieces, those whose bounding box holds
  /// no pixel centre, and triangles seen exactly edge-on.
  void emit(SnappedVertex v0, SnappedVertex v1, SnappedVertex v2) {
    // Orientation: edge functions must be >= 0 inside (y down, so this is clockwise on screen).
    const int64_t area = (int64_t{v1.fx} - v0.fx) * (int64_t{v2.fy} - v0.fy) -
                         (int64_t{v1.fy} - v0.fy) * (int64_t{v2.fx} - v0.fx);
    if (area == 0) return;
    if (area < 0) std::swap(v1, v2);

    // Pixel range: pixel i has its centre at (i + 1/2) in fixed point; ceil and floor by arithmetic shifts.
    const int64_t min_x = min3(v0.fx, v1.fx, v2.fx), max_x = max3(v0.fx, v1.fx, v2.fx);
    const int64_t min_y = min3(v0.fy, v1.fy, v2.fy), max_y = max3(v0.fy, v1.fy, v2.fy);
    const int64_t px0 = std::max<int64_t>(0, (min_x - kSubpixelHalf + kSubpixelOne - 1) >> kSubpixelBits);
    const int64_t px1 = std::min<int64_t>(transform_.width() - 1, (max_x - kSubpixelHalf) >> kSubpixelBits);
    const int64_t py0 = std::max<int64_t>(0, (min_y - kSubpixelHalf + kSubpixelOne - 1) >> kSubpixelBits);
    const int64_t py1 = std::min<int64_t>(transform_.height() - 1, (max_y - kSubpixelHalf) >> kSubpixelBits);
    if (px0 > px1 || py0 > py1) return;
    if (planes_ == PlaneState::unknown)
      planes_ = triangle_planes(*vertices_[0], *vertices_[1], *vertices_[2], planes_value_) ? PlaneState::valid
                                                                                              : PlaneState::invalid;
    if (planes_ == PlaneState::invalid) return;

    RasterTriangle& t = out_.emplace_back();
    t.x[0] = v0.fx, t.x[1] = v1.fx, t.x[2] = v2.fx;
    t.y[0] = v0.fy, t.y[1] = v1.fy, t.y[2] = v2.fy;
    t.px0 = static_cast<uint16_t>(px0), t.px1 = static_cast<uint16_t>(px1);
    t.py0 = static_cast<uint16_t>(py0), t.py1 = static_cast<uint16_t>(py1);
    t.prim = prim_;
    t.mesh = mesh_;
    t.inv_w = planes_value_.inv_w;
    ++counts_.emitted;
  }

  /// Sutherland–Hodgman against the near plane and the guard band in homogeneous pixel space, then
  /// a fan. An intersection is always computed from the inside end of the edge, so two triangles
  /// sharing a clipped edge produce the same vertex and stay watertight. The pieces keep the
  /// original triangle's planes, so their barycentrics refer to its vertices.
  void clip_and_emit() {
    const ProjectedVertex &a = *vertices_[0], &b = *vertices_[1], &c = *vertices_[2];
    ClipVertex buffers[2][kMaxClipVertices];
    ClipVertex* src = buffers[0];
    ClipVertex* dst = buffers[1];
    src[0] = {a.hx, a.hy, a.w, a.outcode};
    src[1] = {b.hx, b.hy, b.w, b.outcode};
    src[2] = {c.hx, c.hy, c.w, c.outcode};
    int n = 3;
    for (int plane = 0; plane < kClipPlaneCount; ++plane) {
      const uint32_t bit = kOutNear << plane;
      uint32_t any = 0;
      for (int i = 0; i < n; ++i) any |= src[i].outcode;
      if ((any & bit) == 0) continue;  // the polygon lies inside: unchanged
      int m = 0;
      for (int i = 0; i < n; ++i) {
        const ClipVertex& cur = src[i];
        const ClipVertex& next = src[(i + 1) % n];
        const bool cur_in = (cur.outcode & bit) == 0, next_in = (next.outcode & bit) == 0;
        if (cur_in) dst[m++] = cur;
        if (cur_in != next_in) dst[m++] = cur_in ? intersect(plane, cur, next) : intersect(plane, next, cur);
      }
      n = m;
      if (n < 3) return;
      std::swap(src, dst);
    }
    const SnappedVertex first = to_snapped(src[0]);
    for (int k = 1; k + 1 < n; ++k) emit(first, to_snapped(src[k]), to_snapped(src[k + 1]));
  }

 private:
  [[nodiscard]] ClipVertex intersect(int plane, const ClipVertex& in, const ClipVertex& out) const {
    const double d_in = transform_.clip_distance(plane, in.hx, in.hy, in.w);
    const double d_out = transform_.clip_distance(plane, out.hx, out.hy, out.w);
    const double t = std::clamp(d_in / (d_in - d_out), 0.0, 1.0);
    ClipVertex v;
    v.hx = in.hx + t * (out.hx - in.hx);
    v.hy = in.hy + t * (out.hy - in.hy);
    v.w = in.w + t * (out.w - in.w);
    v.outcode = transform_.outcode(v.hx, v.hy, v.w);
    return v;
  }

  [[nodiscard]] static SnappedVertex to_snapped(const ClipVertex& v) { return {snap(v.hx, v.w), snap(v.hy, v.w)}; }

  enum class PlaneState { unknown, valid, invalid };

  const VertexTransform& transform_;
  std::vector<RasterTriangle>& out_;
  SetupCounts& counts_;
  const ProjectedVertex* vertices_[3] = {nullptr, nullptr, nullptr};
  uint32_t prim_ = 0;
  uint32_t mesh_ = 0;
  PlaneState planes_ = PlaneState::unknown;
  TrianglePlanes planes_value_;
};

}  // namespace

void project_vertices(const SetupInputs& in, size_t begin, size_t end, ProjectedVertex* out) {
  if (begin >= end) return;
  const Scene& scene = *in.geometry->scene;
  const size_t mesh_count = scene.meshes.size();
  // The mesh holding vertex `begin`: the last one whose base is <= begin.
  size_t mesh = static_cast<size_t>(std::upper_bound(in.vertex_base, in.vertex_base + mesh_count + 1, begin) -
                                    in.vertex_base) - 1;
  for (size_t v = begin; v < end;) {
    while (v >= in.vertex_base[mesh + 1]) ++mesh;
    const std::vector<vec3>& positions = scene.meshes[mesh].positions;
    const size_t stop = std::min(end, in.vertex_base[mesh + 1]);
    for (; v < stop; ++v) out[v] = in.transform->project(positions[v - in.vertex_base[mesh]]);
  }
}

void setup_triangles(const SetupInputs& in, uint32_t begin, uint32_t end, std::vector<RasterTriangle>& out,
                     SetupCounts& counts) {
  if (begin >= end) return;
  const SceneGeometry& geometry = *in.geometry;
  const Scene& scene = *geometry.scene;
  Setup setup(in, out, counts);
  uint32_t mesh = geometry.locate(begin).first;
  for (uint32_t id = begin; id < end; ++id) {
    while (id >= geometry.first_triangle[mesh + 1]) ++mesh;
    const Mesh& m = scene.meshes[mesh];
    const uint32_t local = id - geometry.first_triangle[mesh];
    const uint32_t i0 = m.indices[3 * size_t{local}], i1 = m.indices[3 * size_t{local} + 1],
                   i2 = m.indices[3 * size_t{local} + 2];
    ++counts.submitted;
    if (in.triangle_mask != nullptr && (in.triangle_mask[id] & in.triangle_bit) == 0) {
      ++counts.skipped;
      continue;
    }

    // Invalid indices are the loader's to reject, but they must never read out of bounds here.
    const size_t vertex_count = m.positions.size();
    if (i0 >= vertex_count || i1 >= vertex_count || i2 >= vertex_count)
      throw InputError(fmt::format("{}: mesh {} ('{}') triangle {} indexes vertex {} of {}; fix the index buffer",
                                   scene.path, mesh, m.name, local, std::max(i0, std::max(i1, i2)),
                                   vertex_count));
    const ProjectedVertex* base = in.vertices + in.vertex_base[mesh];
    const ProjectedVertex &a = base[i0], &b = base[i1], &c = base[i2];

    // Frustum culling: all three vertices outside one image border or behind the near plane (or
    // any of them not a finite position).
    if (((a.outcode & b.outcode & c.outcode & kCullBits) | ((a.outcode | b.outcode | c.outcode) & kOutInvalid)) != 0) {
      ++counts.culled_frustum;
      continue;
    }
    // Back faces of single-sided meshes, by the ray tracer's world-space rule.
    if (geometry.single_sided[mesh] != 0 &&
        !front_facing(dvec3(m.positions[i0]), dvec3(m.positions[i1]), dvec3(m.positions[i2]), in.eye_origin)) {
      ++counts.culled_backface;
      continue;
    }
    setup.begin(a, b, c, id, mesh);
    const uint32_t any = a.outcode | b.outcode | c.outcode;
    if ((any & kClipBits) == 0) {
      setup.emit_unclipped();
    } else {
      if ((any & kOutNear) != 0) ++counts.clipped_near;
      setup.clip_and_emit();
    }
  }
}

}  // namespace sb::raster
