// Object-space triangle-mesh primitives for the scene generators (boxes, spheres, fluted columns,
// lathes, tubes, arches, ...) and the helpers that transform and merge them.
//
// Conventions: meters, +Y up. Every primitive has unit vertex normals that agree with its
// counter-clockwise winding (the front side faces where the normal points), no triangle repeats
// a vertex, and UVs are in texture repeats (most primitives map one meter to `uv_per_meter`
// repeats so that textures keep their scale across parts).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "renderer/math.hpp"

namespace sb::scenes {

/// An indexed triangle mesh in object space: one glTF primitive.
struct MeshData {
  std::vector<vec3> positions;
  std::vector<vec3> normals;  ///< unit, one per position
  std::vector<vec2> uvs;      ///< one per position, or empty
  std::vector<uint32_t> indices;  ///< three per triangle, counter-clockwise seen from the front

  [[nodiscard]] size_t vertex_count() const { return positions.size(); }
  [[nodiscard]] size_t triangle_count() const { return indices.size() / 3; }
  [[nodiscard]] bool empty() const { return indices.empty(); }
  [[nodiscard]] Bounds3 bounds() const;

  void reserve(size_t vertices, size_t triangles);
  /// Adds a vertex and returns its index.
  uint32_t add_vertex(const vec3& position, const vec3& normal, const vec2& uv = vec2(0.0f));
  void add_triangle(uint32_t a, uint32_t b, uint32_t c);
  /// Adds a planar quad p0..p3 (given in either circular order) facing `normal`, with
  /// world-aligned box-mapped UVs (see box_uv).
  void add_quad(const vec3& p0, const vec3& p1, const vec3& p2, const vec3& p3, const vec3& normal,
                float uv_per_meter = 1.0f);
};

/// Box-mapped UV of a point on a surface with the given normal: the two world axes most
/// perpendicular to the normal, times `uv_per_meter`.
[[nodiscard]] vec2 box_uv(const vec3& position, const vec3& normal, float uv_per_meter);

/// Transforms positions by `m`, normals by its inverse transpose (renormalised); a mirroring
/// transform also reverses the winding so that fronts stay fronts.
void transform_mesh(MeshData& mesh, const mat4& m);
/// A transformed copy.
[[nodiscard]] MeshData transformed(MeshData mesh, const mat4& m);
/// Appends `src` to `dst` (UVs are kept only if both have them, or `dst` is empty).
void append_mesh(MeshData& dst, const MeshData& src);
/// Appends `src` transformed by `m`.
void append_mesh(MeshData& dst, const MeshData& src, const mat4& m);
/// Area-weighted vertex normals from the triangles (vertices without area get +Y).
void compute_vertex_normals(MeshData& mesh);

/// Affine helpers: translation, rotation about +Y (radians) and scale.
[[nodiscard]] mat4 translation(const vec3& t);
[[nodiscard]] mat4 rotation_y(float radians);
[[nodiscard]] mat4 rotation_x(float radians);
[[nodiscard]] mat4 rotation_z(float radians);
[[nodiscard]] mat4 scaling(const vec3& s);
/// translation(t) * rotation_y(yaw) * scaling(s).
[[nodiscard]] mat4 placement(const vec3& t, float yaw = 0.0f, const vec3& s = vec3(1.0f));
/// A rotation taking +Y to `direction` (unit), for aligning primitives built along +Y.
[[nodiscard]] mat4 align_y_to(const vec3& direction);

/// Axis-aligned box between `lo` and `hi`, 24 vertices, box-mapped UVs in world scale.
[[nodiscard]] MeshData make_box(const vec3& lo, const vec3& hi, float uv_per_meter = 1.0f);
/// Axis-aligned box of `size` centred at the origin.
[[nodiscard]] MeshData make_box_centered(const vec3& size, float uv_per_meter = 1.0f);

/// Plane in XZ facing +Y, centred at the origin, `divisions` quads per axis.
[[nodiscard]] MeshData make_plane(const vec2& size, const ivec2& divisions, float uv_per_meter = 1.0f);

/// UV sphere centred at the origin: `segments` around Y, `rings` latitude bands (>= 2);
/// 2 * segments * (rings - 1) triangles, exact radial normals.
[[nodiscard]] MeshData make_uv_sphere(float radius, int segments, int rings);

/// Options of make_cylinder.
struct CylinderOptions {
  float radius_top = -1.0f;  ///< < 0: same as the bottom radius
  int rings = 1;             ///< subdivisions along the height
  bool caps = true;          ///< close both ends with discs
  int flutes = 0;            ///< concave vertical grooves (Doric/Ionic fluting), 0 = plain
  float flute_depth = 0.05f; ///< groove depth as a fraction of the radius
  float uv_per_meter = 1.0f;
};

/// Cylinder (or truncated cone) standing on the XZ plane from y = 0 to y = height.
/// Side: 2 * segments * rings triangles; caps add 2 * segments.
[[nodiscard]] MeshData make_cylinder(float radius, float height, int segments, const CylinderOptions& options = {});

/// Cone standing on y = 0 with its apex at y = height.
[[nodiscard]] MeshData make_cone(float radius, float height, int segments, bool cap = true);

/// Torus around +Y: ring radius `major`, tube radius `minor`; 2 * major_segments * minor_segments
/// triangles.
[[nodiscard]] MeshData make_torus(float major, float minor, int major_segments, int minor_segments);

/// Surface of revolution about +Y of a profile of (radius, y) points. Walk the profile so that the
/// outside lies on the right-hand side in the (r, y) plane (for a closed solid: from the bottom
/// centre outwards, up the side, back to the top centre). Profile corners sharper than
/// `crease_degrees` get split normals; points with radius 0 become fans.
[[nodiscard]] MeshData make_lathe(const std::vector<vec2>& profile, int segments, float crease_degrees = 40.0f,
                                  float uv_per_meter = 1.0f);

/// A band of an annulus in the XY plane (an archivolt or voussoir ring) between `start` and `end`
/// angles (radians, 0 = +X, pi/2 = +Y), extruded over z in [-depth/2, depth/2], closed.
[[nodiscard]] MeshData make_arch_ring(float inner_radius, float outer_radius, float depth, int segments,
                                      float start = 0.0f, float end = static_cast<float>(kPi),
                                      float uv_per_meter = 1.0f);

/// The wall block above a round arch: a box x in [-width/2, width/2], y in [0, height],
/// z in [-depth/2, depth/2] with a semicircular opening of `radius` centred at the origin (the
/// springing line is y = 0). Needs radius < width/2 and radius < height.
[[nodiscard]] MeshData make_arch_panel(float width, float height, float radius, float depth, int segments,
                                       float uv_per_meter = 1.0f);

/// A tube swept along a polyline with rotation-minimising frames; one radius per path point.
[[nodiscard]] MeshData make_tube(const std::vector<vec3>& path, const std::vector<float>& radii, int segments,
                                 bool caps = true);

/// A grid surface from (nu + 1) x (nv + 1) positions (row-major, u fastest). Normals come from the
/// neighbouring positions (so displaced surfaces get displaced normals) and face along
/// dP/du x dP/dv. With wrap_u (wrap_v) the last column (row) must repeat the first and is welded
/// for the normals. Triangles that would repeat a position are left out. UV = (u, v) * uv_scale.
[[nodiscard]] MeshData make_grid_surface(int nu, int nv, bool wrap_u, bool wrap_v, std::vector<vec3> positions,
                                         const vec2& uv_scale = vec2(1.0f));

/// make_grid_surface of a function of (u, v) in [0, 1]^2.
[[nodiscard]] MeshData make_surface(int nu, int nv, bool wrap_u, bool wrap_v,
                                    const std::function<vec3(float u, float v)>& position,
                                    const vec2& uv_scale = vec2(1.0f));

/// Catmull-Rom spline through `points` (centripetal would be overkill here: uniform), sampled
/// with `samples_per_span` samples per span; includes both end points.
[[nodiscard]] std::vector<vec3> catmull_rom(const std::vector<vec3>& points, int samples_per_span);

}  // namespace sb::scenes
