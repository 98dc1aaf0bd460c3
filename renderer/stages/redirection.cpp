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

}  // namespace

double frustum_visibility(const EyeCamera& eye, const dvec3& v0, const dvec3& v1, const dvec3& v2) {
  double largest = 0.0;
  for (const dvec3* v : {&v0, &v1, &v2}) {
    const double x = x_ndc(eye, *v);
    if (std::isnan(x)) return 0.0;
    largest = std::max(largest, std::abs(x));
  }
  return largest <= 1.0 ? 1.0 : 1.0 / largest;
}

double facing_visibility(const EyeCamera& eye, const dvec3& v0, const dvec3& v1, const dvec3& v2, bool single_sided) {
  const dvec3 n = glm::cross(v1 - v0, v2 - v0);
  const double area2 = glm::length(n);
  const dvec3 to_eye = eye.origin - (v0 + v1 + v2) / 3.0;
  const double distance = glm::length(to_eye);
  if (area2 == 0.0 || distance == 0.0) return 0.0;
  const double cosine = glm::dot(n, to_eye) / (area2 * distance);
  return single_sided ? cosine : std::abs(cosine);
}

uint8_t redirect(const EyeCamera& left, const EyeCamera& right, const dvec3& v0, const dvec3& v1, const dvec3& v2,
                 bool single_sided) {
  const double fl = frustum_visibility(left, v0, v1, v2), fr = frustum_visibility(right, v0, v1, v2);
  if (fl != fr) return fl > fr ? kRedirectLeft : kRedirectRight;
  const double bl = facing_visibility(left, v0, v1, v2, single_sided);
  const double br = facing_visibility(right, v0, v1, v2, single_sided);
  if (bl != br) return bl > br ? kRedirectLeft : kRedirectRight;
  return kRedirectBoth;
}

std::vector<uint8_t> redirect_triangles(const SceneGeometry& geometry, const StereoRig& rig, const Executor& executor,
                                        RedirectionCounts& counts) {
  const Scene& scene = *geometry.scene;
  const EyeCamera left = rig.eye(Eye::left), right = rig.eye(Eye::right);
  std::vector<uint8_t> bits(geometry.triangle_count(), 0);
  std::atomic<uint64_t> n_left{0}, n_right{0}, n_both{0};
  executor.for_each(scene.meshes.size(), [&](size_t m) {
    const Mesh& mesh = scene.meshes[m];
    const bool single_sided = geometry.single_sided[m] != 0;
    uint64_t l = 0, r = 0, b = 0;
    for (size_t t = 0; t < mesh.triangle_count(); ++t) {
      const dvec3 v0(mesh.positions[mesh.indices[3 * t]]), v1(mesh.positions[mesh.indices[3 * t + 1]]),
          v2(mesh.positions[mesh.indices[3 * t + 2]]);
      const uint8_t to = redirect(left, right, v0, v1, v2, single_sided);
      bits[geometry.first_triangle[m] + t] = to;
      (to == kRedirectBoth ? b : to == kRedirectLeft ? l : r)++;
    }
    n_left += l;
    n_right += r;
    n_both += b;
  });
  counts = {n_left, n_right, n_both};
  return bits;
}

}  // namespace sb
