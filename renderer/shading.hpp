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

/// Texture level of detail by ray cones for a primary ray along unit `dir` whose cone is
/// `cone_width` wide where it hits `p` (0 when the material has no texture).
[[nodiscard]] float ray_cone_lod(const RenderScene& scene, const SurfacePoint& p, float cone_width, const vec3& dir);

/// Width of a primary ray's cone at distance t: t * tan(alpha) * cos^1.5(phi), alpha the spread per
/// pixel (ray_cone_spread) and phi the ray's angle to the optical axis. A pixel off the axis
/// subtends alpha cos^2(phi) radially and alpha cos(phi) tangentially; the cone of the same solid
/// angle (alpha^2 cos^3(phi)) has width alpha cos^1.5(phi). With it the ray-cone level stays within
/// 0.31 of the derivative level over the whole frame up to a 60 degree vertical field of view
/// (tests/texture/lod_test.cpp), where a constant width is off by up to 1.25 levels in the corners.
[[nodiscard]] float primary_cone_width(float t, float tan_spread, float cos_off_axis);

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
