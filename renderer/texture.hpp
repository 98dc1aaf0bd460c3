// Base colour textures with box-filtered mip chains, trilinear sampling, and the two level-of-detail
// rules of DESIGN §3: screen-space UV derivatives (raster) and ray cones (ray tracing).
#pragma once

#include <string>
#include <vector>

#include "renderer/math.hpp"
#include "renderer/scene.hpp"

namespace sb {

/// A texture and its mip chain (level 0 = the image, each next level half the size, down to 1x1).
///
/// Level n + 1 has floor(size / 2) texels per axis (at least 1), as in OpenGL. Each texel of a
/// coarser level is the exact box-filter average of its footprint in the finer level: a 2-tap
/// average where the axis has even length, and for an odd length 2k + 1 -> k a 3-tap polyphase box
/// with weights ((k - i), k, (i + 1)) / (2k + 1) for output texel i (Barrett, "Non-Power-of-Two
/// Mipmap Creation", NVIDIA 2003). An axis already 1 texel long is copied. Every level therefore
/// keeps the mean of level 0 exactly (up to float rounding), and the filter is separable.
///
/// Texture coordinates follow glTF and OpenGL: uv (0, 0) is the top-left corner of the image (row
/// 0 is the top row), texel (i, j) of a w x h level has its centre at ((i + 0.5) / w, (j + 0.5) / h).
/// Wrapping is per axis from the Texture: REPEAT (repeat_s / repeat_t) or CLAMP_TO_EDGE.
class MipTexture {
 public:
  /// Builds the chain (level 0 alone without `chain`); throws InputError naming the texture if its
  /// size is not positive or its rgba array does not hold width * height * 4 floats.
  explicit MipTexture(const Texture& texture, bool chain = true);

  [[nodiscard]] int levels() const;
  /// Size of a level; throws InputError for a level outside [0, levels()).
  [[nodiscard]] int width(int level = 0) const;
  [[nodiscard]] int height(int level = 0) const;
  /// Bilinear lookup in one level; uv wraps or clamps as the texture's sampler says. A non-finite
  /// coordinate reads as 0. Throws InputError for a level outside [0, levels()).
  [[nodiscard]] vec4 sample_bilinear(vec2 uv, int level) const;
  /// Trilinear lookup: lod clamped to [0, levels - 1], linear between the two nearest levels
  /// floor(lod) and floor(lod) + 1. A NaN lod (e.g. from a degenerate ray cone) samples level 0.
  [[nodiscard]] vec4 sample_trilinear(vec2 uv, float lod) const;

 private:
  /// One level of the chain: RGBA texels, row-major, row 0 at the top.
  struct Level {
    int width = 0;
    int height = 0;
    std::vector<vec4> texels;
  };

  [[nodiscard]] const Level& level_at(int level) const;  ///< checked access
  [[nodiscard]] vec4 bilinear(const Level& level, vec2 uv) const;

  std::vector<Level> levels_;
  bool repeat_s_ = true;
  bool repeat_t_ = true;
  std::string name_;  ///< for error messages
};

/// Level of detail from UV derivatives (UV units per pixel) for a width x height texture.
/// duv = (du/dx, dv/dx, du/dy, dv/dy), as in GBuffer::duv.
///
/// The footprint of one pixel in texels is the image of the unit pixel under the Jacobian
/// J = [du/dx * w, du/dy * w; dv/dx * h, dv/dy * h]. The OpenGL rule takes rho = the longer of J's
/// two columns (the pixel's x and y axes mapped to texels). This function takes rho = the largest
/// singular value of J, the major axis of the footprint ellipse, and returns log2(rho).
///
/// Why: a ray cone models the same footprint as its cross-section across the ray (a disc of
/// diameter W for a circular cone, lod_from_ray_cone; an ellipse for a primary ray's cone,
/// lod_from_elliptic_cone) projected along the ray onto the surface, which stretches it by
/// 1 / |cos theta| along the surface's tilt direction; its LOD is log2 of the major axis of that
/// footprint in texels. The largest singular value is the same quantity for the rasterizer, so
/// for a plane both rules give the same level at every pixel and tilt (tests/texture/lod_test.cpp).
/// The OpenGL max-axis rule is not invariant under rotating the tilt direction on screen: for a
/// tilt along the screen diagonal it is lower by up to log2(sqrt 2) = 0.5 (0.17 at 40 degrees,
/// 0.34 at 60, 0.48 at 80), so the raster path would drift to the edge of DESIGN §3's +-0.5
/// agreement. The largest singular value lies between the OpenGL value and sqrt(2) times it, so it
/// never selects a sharper (more aliased) level than the OpenGL rule. The geometric mean
/// sqrt|det J| (the cone's isotropic area) and the minor axis disagree with the cone by 1.26 and
/// 2.5 levels at 80 degrees.
///
/// The raw value is returned: -inf for a zero footprint (no UVs), very negative for
/// magnification; sample_trilinear clamps it to [0, levels - 1].
[[nodiscard]] float lod_from_derivatives(const vec4& duv, int width, int height);

/// Ray-cone spread angle per pixel: alpha = atan(2 tan(vfov / 2) / H), the angle one pixel row
/// subtends on the optical axis (the whole cone angle, not the half angle, as in Ray Tracing Gems
/// ch. 20). The pixel on the optical axis has a primary cone of width W = t * alpha at hit distance t
/// (the chapter's small-angle form of 2 t tan(alpha / 2)); pixels off the axis subtend less
/// (lod_from_ray_cone, primary_cone in shading.hpp). Throws InputError unless 0 < vfov < pi and H > 0.
[[nodiscard]] double ray_cone_spread(double vfov, int height);

/// The per-triangle constant of ray-cone LOD: 0.5 log2(texel-space area / world-space area), with
/// t_a = w h |(uv1 - uv0) x (uv2 - uv0)| and p_a = |(p1 - p0) x (p2 - p0)| (the triangle areas
/// doubled; the factors cancel). Returns -inf when the UVs are degenerate (the LOD clamps to 0)
/// and +inf when only the positions are.
[[nodiscard]] float ray_cone_triangle_lod(const vec3& p0, const vec3& p1, const vec3& p2, const vec2& uv0,
                                          const vec2& uv1, const vec2& uv2, int width, int height);

/// Ray-cone LOD (Akenine-Möller et al., Ray Tracing Gems ch. 20): triangle constant + log2(cone width at the
/// hit) - log2(|cos| of the angle between the ray and the surface normal). Wißmann et al.'s eq. 3,
/// which cites the chapter, prints 0.5 log2 for the second term; the triangle constant (their
/// eq. 4) is already half the log of an area ratio, a length scale, and the cone's width is a
/// length, so the chapter's log2 is kept (with 0.5 log2 the level would depend on the world's
/// unit of length).
///
/// Conventions: cone_width is the full width W (not the radius) in world units, abs_cos_theta is
/// |n . d| for unit n and d; both are used as absolute values. The result is raw (+-inf or NaN for
/// degenerate inputs; sample_trilinear clamps it and reads NaN as level 0).
///
/// A circular cone fits the pixel on the optical axis only: there W = t * alpha is the pixel's
/// footprint across the ray, and for an isotropically mapped surface this LOD equals
/// lod_from_derivatives at any distance and tilt. Away from the axis a pixel subtends alpha
/// cos^2(phi) radially and alpha cos(phi) tangentially (phi the ray's angle to the eye's viewing
/// direction, its -Z; an off-axis eye's principal point is not the image centre), and no single
/// width fits both: W = t * alpha picks levels coarser than the rasterizer by up to -2 log2
/// cos(phi) (0.63 levels in the corners of a 40-degree 16:9 frame), W = t * alpha cos^1.5(phi)
/// (the geometric mean of the two axes) is still off by +-0.5 log2(1 / cos(phi)) wherever the
/// surface's tilt runs radially or tangentially on screen: 0.128 levels at the sides of the
/// 480x270 textured-plane frame, 0.16, 0.31 and 0.59 over 40-, 60- and 90-degree 1920x1080
/// frames (tests/texture/lod_test.cpp).
/// Primary rays therefore use lod_from_elliptic_cone.
[[nodiscard]] float lod_from_ray_cone(float triangle_lod, float cone_width, float abs_cos_theta);

/// Ray-cone LOD for a cone of elliptic cross-section: triangle constant + log2 of the major axis
/// of the cone's footprint on the surface.
///
/// axis_a and axis_b are the principal axes of the cone's cross-section at the hit, perpendicular
/// to the unit ray direction `dir`, each as long as the full width of the cone along it (world
/// units); `normal` is the surface's unit normal. The footprint is the cross-section projected
/// along the ray onto the surface's tangent plane, w -> w - (n . w) / (n . d) d; the result is
/// triangle_lod + log2(sigma_max), sigma_max the largest singular value of the 3x2 matrix of the
/// two projected axes (the major axis of the footprint ellipse). For a circular cross-section
/// (|axis_a| = |axis_b| = W) that is W / |n . d|, lod_from_ray_cone exactly.
///
/// With the primary cone of shading.hpp (axes t alpha cos^2(phi) radially and t alpha cos(phi)
/// tangentially, the pixel's exact angular extents) the footprint is the pixel's own footprint on
/// the surface's tangent plane, so on an isotropically mapped plane this LOD equals
/// lod_from_derivatives at every pixel, tilt and field of view (to float rounding:
/// tests/texture/lod_test.cpp). Both rules see the flat triangle (the cone its geometric normal,
/// the rasterizer its planar interpolation), so this holds triangle by triangle on curved meshes
/// too. The triangle constant is area based: where a triangle stretches the texture k times more
/// along one surface axis than the other, the cone's level differs from the rasterizer's major
/// axis by up to 0.5 log2(k), depending on how the footprint lies; the ray tracer therefore maps
/// the footprint through the triangle's texel map instead (the overload below), of which this is
/// the isotropic case. |n . d| is taken as at least 1e-6 (a ray along the surface reads as a very
/// coarse level); otherwise the raw value is returned (-inf for a zero cross-section, NaN for
/// non-finite input).
[[nodiscard]] float lod_from_elliptic_cone(float triangle_lod, const vec3& axis_a, const vec3& axis_b,
                                           const vec3& normal, const vec3& dir);

/// The linear map from a triangle's plane to texel space: a world-space vector w in the plane
/// moves the texture coordinates by (u . w, v . w) texels of a width x height texture. It is the
/// triangle's own (the map its vertices' positions and coordinates define), so it holds anisotropy
/// that the area ratio of ray_cone_triangle_lod averages away.
struct TexelMap {
  dvec3 u{0.0}, v{0.0};
  bool flat = false;  ///< the triangle has no area: no map (the LOD is +inf, the coarsest level)
};
[[nodiscard]] TexelMap triangle_texel_map(const vec3& p0, const vec3& p1, const vec3& p2, const vec2& uv0,
                                          const vec2& uv1, const vec2& uv2, int width, int height);

/// Ray-cone LOD through a triangle's texel map: log2 of the major axis, in texels, of the cone's
/// footprint on the triangle's plane (the cross-section projected along the ray as above, then
/// mapped by `map`). The rasterizer's lod_from_derivatives is log2 of the major axis of the
/// pixel's footprint mapped the same way, so with the primary cone the two agree on any planar
/// mapping, stretched or sheared too (tests/texture/lod_test.cpp); for an isotropic map of scale
/// 2^triangle_lod this is the overload above. +inf for a flat triangle, -inf where the footprint
/// maps to a point.
[[nodiscard]] float lod_from_elliptic_cone(const TexelMap& map, const vec3& axis_a, const vec3& axis_b,
                                           const vec3& normal, const vec3& dir);

}  // namespace sb
