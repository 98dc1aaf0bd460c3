// The one shading function of DESIGN §3 and the surface reconstruction it starts from. The raster
// lighting pass, every ray-traced path and every hole filler call these, so that pipeline
// differences come from visibility and reprojection alone.
#pragma once

#include <cstdint>
#include <span>

#include "renderer/math.hpp"
#include "renderer/render_scene.hpp"

namespace sb {

/// A visible surface point, reconstructed from a primitive id and barycentrics.
struct SurfacePoint {
  uint32_t prim = kNoPrimitiveId;
  uint32_t mesh = 0;
  vec3 position{0.0f};
  vec3 geometric_normal{0.0f, 0.0f, 1.0f};  ///< unit, turned towards the viewer
  vec3 shading_normal{0.0f, 0.0f, 1.0f};    ///< unit, in the viewer's hemisphere of the geometric normal
  vec2 uv{0.0f};
  bool has_uv = false;
  int material = -1;
};

/// The surface at barycentrics (b1, b2) of global triangle `prim`, normals turned towards `eye`.
[[nodiscard]] SurfacePoint surface_at(const RenderScene& scene, uint32_t prim, vec2 bary, const vec3& eye);

/// Albedo = base colour factor x base colour texture (trilinear at `lod`), linear RGB.
[[nodiscard]] vec3 albedo_at(const RenderScene& scene, const SurfacePoint& p, float lod);

/// A ray cone's cross-section where it hits a surface: two perpendicular axes across the ray, each
/// as long as the cone's full width along it (world units).
struct ConeSection {
  vec3 axis_a{0.0f};
  vec3 axis_b{0.0f};
};

/// The cone of the primary ray along unit `dir` at hit distance t, for an eye whose unit viewing
/// direction (its -Z) is `view_dir`, with tan_spread = tan(ray_cone_spread(vfov, H)) = 1 / f_px.
///
/// A pixel at angle phi from the viewing direction subtends alpha cos^2(phi) along the radial
/// direction (in the plane of the ray and the viewing direction) and alpha cos(phi) across it,
/// alpha the spread on the axis: the image plane is 1 / cos(phi) farther away along the ray and
/// seen at angle phi radially. The cone takes these two spreads, so its section at t is an ellipse
/// with axes t tan_spread cos^2(phi) (radial) and t tan_spread cos(phi) (tangential), the pixel's
/// own angular footprint; on the axis it is the circle of width t tan_spread of Ray Tracing Gems
/// ch. 20. No circular cone fits both extents: the best single width, t tan_spread cos^1.5(phi),
/// is still up to 0.5 log2(1 / cos(phi)) levels off the rasterizer (texture.hpp, lod_from_ray_cone).
[[nodiscard]] ConeSection primary_cone(float t, float tan_spread, const vec3& dir, const vec3& view_dir);

/// Texture level of detail by ray cones (lod_from_elliptic_cone through the hit triangle's texel
/// map) for a ray along unit `dir` whose cone has section `cone` where it hits `p` (0 when the
/// material has no texture).
[[nodiscard]] float ray_cone_lod(const RenderScene& scene, const SurfacePoint& p, const ConeSection& cone,
                                 const vec3& dir);

/// Texture level of detail from screen-space UV derivatives (0 when the material has no texture).
[[nodiscard]] float derivative_lod(const RenderScene& scene, const SurfacePoint& p, const vec4& duv);

/// Rays cast while shading, for the pipeline counters.
struct ShadeCounts {
  uint64_t shadow_rays = 0;
  uint64_t pixels_shaded = 0;
};

/// Outgoing radiance towards the viewer of up to 16 surface points with their albedos:
/// L = ambient * albedo + sum over lights of (albedo / pi) * E_i * V_i, with V_i an exact shadow ray.
void shade(const RenderScene& scene, std::span<const SurfacePoint> points, std::span<const vec3> albedo,
           std::span<vec3> radiance, ShadeCounts& counts);

}  // namespace sb
