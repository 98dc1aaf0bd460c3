// Kim's visibility redirection (§3.1-3.2): every triangle goes to the eye that sees it best, so
// that each eye rasterizes and shades only its share and the two partial images, warped into each
// other, sample every surface from the side that sees more of it.
#pragma once

#include <cstdint>
#include <vector>

#include "renderer/math.hpp"
#include "renderer/parallel.hpp"
#include "renderer/rig.hpp"
#include "renderer/scene_geometry.hpp"

namespace sb {

/// Bits of a triangle's redirection: which eyes rasterize it.
enum RedirectBits : uint8_t {
  kRedirectLeft = 1,
  kRedirectRight = 2,
  kRedirectBoth = kRedirectLeft | kRedirectRight,
};

/// Where a triangle that both eyes' frusta clip goes. Each eye may then see a part of it the other
/// does not (a wall wider than both images: the left eye sees more of its left end, the right eye
/// more of its right end); a part outside the rasterizing eye's frustum reaches the other eye by no
/// warp, so that eye shows what lies behind it there.
enum class ClippedRule : uint8_t {
  one,   ///< Kim's eq. (1) as published: the eye that clips it less (the larger frustum visibility)
  /// each eye whose image it reaches horizontally rasterizes it (eq. (1) when it reaches neither):
  /// both where each may see a part of it, and the eye that sees it where eq. (1) would pick the
  /// other, which does not (a triangle just past one border of one image that reaches far past the
  /// same border of the other)
  both,
};

/// Kim's eq. (1): 1 while the triangle lies within the eye's frustum horizontally
/// (|x_ndc| <= 1 for the vertex with the largest |x_ndc|), decreasing as 1 / |x_ndc| beyond; 0 when
/// a vertex lies at or behind the eye's plane.
[[nodiscard]] double frustum_visibility(const EyeCamera& eye, const dvec3& v0, const dvec3& v1, const dvec3& v2);

/// Kim's eq. (3): |n · (c − p)| / |c − p| for the unit normal n, the eye's position c and the
/// triangle's centroid p — the cosine that scales its projected area. For a single-sided triangle
/// the signed form (eq. 4), so that a back face loses to a front face.
[[nodiscard]] double facing_visibility(const EyeCamera& eye, const dvec3& v0, const dvec3& v1, const dvec3& v2,
                                       bool single_sided);

/// The eye(s) a triangle goes to: the larger frustum visibility wins; on a tie, the larger facing
/// visibility; on an exact tie, both. A triangle with vertices on both sides of an eye's plane
/// (reaching behind the viewer) goes to both: eq. (1) is not defined for it. Under ClippedRule::both
/// a triangle both frusta clip (frustum visibility below 1 in each eye) goes to each eye whose
/// image it reaches.
[[nodiscard]] uint8_t redirect(const EyeCamera& left, const EyeCamera& right, const dvec3& v0, const dvec3& v1,
                               const dvec3& v2, bool single_sided, ClippedRule clipped = ClippedRule::one);

/// Triangles sent to each eye, and those sent to neither (of a culled mesh, facing neither eye).
struct RedirectionCounts {
  uint64_t left = 0;
  uint64_t right = 0;
  uint64_t both = 0;
  uint64_t culled = 0;
};

/// Per mesh, whether its back faces are culled (1) in the redirection: a mesh of a single-sided
/// material; with `closed_too`, also a double-sided one that SceneGeometry::closed() marks and
/// whose every vertex lies beyond the near plane of both eyes. An eye inside a closed mesh has
/// some of it behind itself, so both eyes are then outside it, and no near plane cuts it open: its
/// front faces hide all its back faces in either eye, and culling them changes no full render.
/// Kim's method assumes culling (§2.2, eq. (4)): an eye that rasterizes a closed mesh's back
/// triangles while their front ones go to the other eye shows the mesh's inside. Counts the meshes
/// so culled that were double-sided in `closed_culled`.
[[nodiscard]] std::vector<uint8_t> culled_meshes(const SceneGeometry& geometry, const StereoRig& rig,
                                                 const Executor& executor, bool closed_too, uint64_t& closed_culled);

/// The share of a triangle of a culled mesh, from redirect()'s decision `to`: the eyes of `to` it
/// faces (front_facing, the rasterizer's culling rule); if it faces none of them, every eye it
/// faces; none when it faces neither eye.
[[nodiscard]] uint8_t facing_share(uint8_t to, const dvec3& v0, const dvec3& v1, const dvec3& v2,
                                   const EyeCamera& left, const EyeCamera& right);

/// The RedirectBits of every triangle of the scene, by global triangle id: redirect()'s decisions,
/// with the meshes `culled` marks (one entry per mesh) taken as single-sided and their triangles'
/// shares by facing_share.
[[nodiscard]] std::vector<uint8_t> redirect_triangles(const SceneGeometry& geometry, const StereoRig& rig,
                                                      const std::vector<uint8_t>& culled, const Executor& executor,
                                                      RedirectionCounts& counts,
                                                      ClippedRule clipped = ClippedRule::one);

}  // namespace sb
