// Target-eye pixels whose visible surface lies outside the source eye's frustum: the part of a
// reprojection's disocclusions that no depth discontinuity in the source image betrays. With the
// stereo rig's parallel eyes these are surfaces nearer than the convergence distance entering the
// right eye at its right edge (the left eye's frustum ends before them), and, at the right eye's
// left edge, surfaces beyond the left image's left edge where a warp stretches the border pixels
// over them.
#pragma once

#include <cstdint>
#include <vector>

#include "renderer/parallel.hpp"
#include "renderer/render_scene.hpp"
#include "renderer/rig.hpp"

namespace sb {

/// Counters of one search.
struct SourceFrustumStats {
  uint64_t triangles_near = 0;  ///< triangles reaching the part of the target frustum the source eye cannot see
  uint64_t rays = 0;            ///< restricted rays cast
  uint64_t pixels = 0;          ///< pixels marked
};

/// Marks with `mark` every target pixel i with states[i] == `candidate` whose primary ray (from
/// `to` through the pixel centre, as trace_eye casts it) first hits a surface outside `from`'s
/// frustum — a point that projects outside [0, W] x [0, H] of the source image or to its near
/// plane or behind it — or hits nothing after leaving that frustum for good. Exact up to the float
/// resolution of the hit distance, and cheap: per pixel ray, the source frustum is an interval
/// [t_in, t_out] of the ray parameter (five half-spaces along a line), and
/// - a ray that never enters the source frustum is outside whatever it hits;
/// - a ray that leaves it again (t_out finite) is traced over [0, t_out]: outside when it hits
///   nothing there or hits before t_in;
/// - otherwise it can only see an outside surface before t_in. The scene's triangles are clipped
///   to the part of the target frustum outside the source frustum and nearer than the deepest
///   t_in (from depth 0 on, not from the near plane: the rays start at the eye); a pixel is traced
///   over [0, t_in] only when a clipped triangle's projection reaches its row and column, nearer
///   than the pixel's t_in depth. With parallel eyes that region is the thin wedge between the two
///   frusta's side planes in front of the convergence plane (and anything in front of the near
///   plane), so few pixels are traced.
/// `from` and `to` must have the size of the states (one per target pixel, row-major). The result
/// does not depend on the executor's thread count.
SourceFrustumStats mark_outside_source_frustum(const RenderScene& scene, const EyeCamera& from, const EyeCamera& to,
                                               const Executor& executor, std::vector<uint8_t>& states, uint8_t candidate,
                                               uint8_t mark);

}  // namespace sb
