// Per-triangle visibility comparison between the two eyes.
#include "renderer/stages/redirection.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "renderer/scene.hpp"

namespace sb {

namespace {

/// x_ndc of a world point in an eye; nothing (NaN) when it lies at or behind the eye's plane.
double x_ndc(const EyeCamera& eye, const dvec3& p) {
  const dvec3 s = eye.project(p);
  if (!(s.z > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return 2.0 * s.x / eye.width - 1.0;
}

/// Eq. (1) from the x_ndc of the three vertices (NaN: at or behind the eye's plane).
double frustum_from_ndc(double x0, double x1, double x2) {
  double largest = 0.0;
  for (const double x : {x0, x1, x2}) {
    if (std::isnan(x)) return 0.0;
    largest = std::max(largest, std::abs(x));
  }
  return largest <= 1.0 ? 1.0 : 1.0 / largest;
}

/// A triangle's (unnormalized) normal, its length and its centroid: what eq. (3) needs of it.
struct TriangleFacing {
  dvec3 n;
  double area2;
  dvec3 centroid;
  TriangleFacing(const dvec3& v0, const dvec3& v1, const dvec3& v2)
      : n(glm::cross(v1 - v0, v2 - v0)), area2(glm::length(n)), centroid((v0 + v1 + v2) / 3.0) {}

  /// Eq. (3) (eq. (4) when single-sided) for an eye at `origin`.
  [[nodiscard]] double visibility(const dvec3& origin, bool single_sided) const {
    const dvec3 to_eye = origin - centroid;
    const double distance = glm::length(to_eye);
    if (area2 == 0.0 || distance == 0.0) return 0.0;
    const double cosine = glm::dot(n, to_eye) / (area2 * distance);
    return single_sided ? cosine : std::abs(cosine);
  }
};

/// Whether some of the three x_ndc are NaN (at or behind the eye's plane) and some are not.
bool crosses_eye_plane(const double (&x)[3]) {
  const int behind = int(std::isnan(x[0])) + int(std::isnan(x[1])) + int(std::isnan(x[2]));
  return behind > 0 && behind < 3;
}

/// Whether a triangle's horizontal extent (its vertices' x_ndc, all in front of the eye) overlaps
/// the image's, [-1, 1].
bool reaches_image(const double (&x)[3]) {
  if (std::isnan(x[0]) || std::isnan(x[1]) || std::isnan(x[2])) return false;
  return std::min({x[0], x[1], x[2]}) <= 1.0 && std::max({x[0], x[1], x[2]}) >= -1.0;
}

/// The redirection from the vertices' x_ndc in each eye ({x0, x1, x2}) and their positions.
uint8_t redirect_from(const EyeCamera& left, const EyeCamera& right, const double (&xl)[3], const double (&xr)[3],
                      const dvec3& v0, const dvec3& v1, const dvec3& v2, bool single_sided, ClippedRule clipped) {
  // A triangle reaching behind an eye (a floor or wall passing beside and behind the viewer) has
  // no outermost x_ndc: its projection is unbounded, and it reaches the image borders of both eyes,
  // where each sees a part the other does not. Eq. (1) cannot rank it; both eyes rasterize it.
  if (crosses_eye_plane(xl) || crosses_eye_plane(xr)) return kRedirectBoth;
  const double fl = frustum_from_ndc(xl[0], xl[1], xl[2]), fr = frustum_from_ndc(xr[0], xr[1], xr[2]);
  if (clipped == ClippedRule::both && fl < 1.0 && fr < 1.0) {
    const auto to = static_cast<uint8_t>((reaches_image(xl) ? kRedirectLeft : 0) | (reaches_image(xr) ? kRedirectRight : 0));
    if (to != 0) return to;
  }
  if (fl != fr) return fl > fr ? kRedirectLeft : kRedirectRight;
  const TriangleFacing facing(v0, v1, v2);
  const double bl = facing.visibility(left.origin, single_sided), br = facing.visibility(right.origin, single_sided);
  if (bl != br) return bl > br ? kRedirectLeft : kRedirectRight;
  return kRedirectBoth;
}

}  // namespace

double frustum_visibility(const EyeCamera& eye, const dvec3& v0, const dvec3& v1, const dvec3& v2) {
  return frustum_from_ndc(x_ndc(eye, v0), x_ndc(eye, v1), x_ndc(eye, v2));
}

double facing_visibility(const EyeCamera& eye, const dvec3& v0, const dvec3& v1, const dvec3& v2, bool single_sided) {
  return TriangleFacing(v0, v1, v2).visibility(eye.origin, single_sided);
}

uint8_t redirect(const EyeCamera& left, const EyeCamera& right, const dvec3& v0, const dvec3& v1, const dvec3& v2,
                 bool single_sided, ClippedRule clipped) {
  const double xl[3] = {x_ndc(left, v0), x_ndc(left, v1), x_ndc(left, v2)};
  const double xr[3] = {x_ndc(right, v0), x_ndc(right, v1), x_ndc(right, v2)};
  return redirect_from(left, right, xl, xr, v0, v1, v2, single_sided, clipped);
}

uint8_t facing_share(uint8_t to, const dvec3& v0, const dvec3& v1, const dvec3& v2, const EyeCamera& left,
                     const EyeCamera& right) {
  const auto facing = static_cast<uint8_t>((front_facing(v0, v1, v2, left.origin) ? kRedirectLeft : 0) |
                                           (front_facing(v0, v1, v2, right.origin) ? kRedirectRight : 0));
  // Eq. (1) ranks by the frustum before facing: it can pick the eye a triangle turns its back to
  // (a sliver near a border, clipped less there); the eye it faces then takes it.
  return (to & facing) != 0 ? static_cast<uint8_t>(to & facing) : facing;
}

std::vector<uint8_t> culled_meshes(const SceneGeometry& geometry, const StereoRig& rig, const Executor& executor,
                                   bool closed_too, uint64_t& closed_culled) {
  const Scene& scene = *geometry.scene;
  const EyeCamera eyes[2] = {rig.eye(Eye::left), rig.eye(Eye::right)};
  std::vector<uint8_t> culled(geometry.single_sided);
  std::atomic<uint64_t> n{0};
  if (!closed_too) {
    closed_culled = 0;
    return culled;
  }
  const std::vector<uint8_t>& closed = geometry.closed(executor);
  executor.for_each(scene.meshes.size(), [&](size_t m) {
    if (closed[m] == 0) return;
    // The positions and indices are wound as the file says under any transform (the loader and a
    // path's frames reverse the triangles of a mirrored node), so the mesh stays closed and
    // outward as loaded.
    const Mesh& mesh = scene.meshes[m];
    std::atomic<bool> near{false};
    executor.for_range(mesh.positions.size(), 16384, [&](size_t begin, size_t end) {
      for (size_t v = begin; v < end && !near.load(std::memory_order_relaxed); ++v) {
        const dvec3 p(mesh.positions[v]);
        // Not clearly beyond the near plane (NaN too): the plane may cut the mesh open, or the eye
        // lie in it. The margin covers the rasterizer's own rounding of the depth (the eyes are
        // parallel, so both give a point the same depth but for that rounding).
        for (const EyeCamera& eye : eyes)
          if (!(-glm::dot(p - eye.origin, eye.back) > eye.znear * (1.0 + 1e-6)))
            near.store(true, std::memory_order_relaxed);
      }
    });
    if (near.load()) return;
    culled[m] = 1;
    ++n;
  });
  closed_culled = n;
  return culled;
}

std::vector<uint8_t> redirect_triangles(const SceneGeometry& geometry, const StereoRig& rig,
                                        const std::vector<uint8_t>& culled, const Executor& executor,
                                        RedirectionCounts& counts, ClippedRule clipped) {
  const Scene& scene = *geometry.scene;
  if (culled.size() != scene.meshes.size())
    throw std::logic_error("redirect_triangles: one culling flag per mesh expected");
  const EyeCamera left = rig.eye(Eye::left), right = rig.eye(Eye::right);
  std::vector<uint8_t> bits(geometry.triangle_count(), 0);
  std::atomic<uint64_t> n_left{0}, n_right{0}, n_both{0}, n_none{0};
  // Meshes in parallel, and a large mesh's vertices and triangles in parallel within it: every
  // vertex projected into both eyes once (a vertex is shared by about six triangles), then every
  // triangle compared from its vertices' projections. The decisions are those of redirect().
  executor.for_each(scene.meshes.size(), [&](size_t m) {
    const Mesh& mesh = scene.meshes[m];
    const bool cull = culled[m] != 0;
    const size_t vertices = mesh.positions.size();
    std::vector<double> ndc(2 * vertices);
    executor.for_range(vertices, 4096, [&](size_t begin, size_t end) {
      for (size_t v = begin; v < end; ++v) {
        const dvec3 p(mesh.positions[v]);
        ndc[2 * v] = x_ndc(left, p);
        ndc[2 * v + 1] = x_ndc(right, p);
      }
    });
    executor.for_range(mesh.triangle_count(), 4096, [&](size_t begin, size_t end) {
      uint64_t l = 0, r = 0, b = 0, none = 0;
      for (size_t t = begin; t < end; ++t) {
        const uint32_t i0 = mesh.indices[3 * t], i1 = mesh.indices[3 * t + 1], i2 = mesh.indices[3 * t + 2];
        const double xl[3] = {ndc[2 * i0], ndc[2 * i1], ndc[2 * i2]};
        const double xr[3] = {ndc[2 * i0 + 1], ndc[2 * i1 + 1], ndc[2 * i2 + 1]};
        const dvec3 v0(mesh.positions[i0]), v1(mesh.positions[i1]), v2(mesh.positions[i2]);
        uint8_t to = redirect_from(left, right, xl, xr, v0, v1, v2, cull, clipped);
        if (cull) to = facing_share(to, v0, v1, v2, left, right);
        bits[geometry.first_triangle[m] + t] = to;
        (to == kRedirectBoth ? b : to == kRedirectLeft ? l : to == kRedirectRight ? r : none)++;
      }
      n_left += l;
      n_right += r;
      n_both += b;
      n_none += none;
    });
  });
  counts = {n_left, n_right, n_both, n_none};
  return bits;
}

}  // namespace sb
