// Mip chain construction, bilinear/trilinear sampling and the raster and ray-cone LOD rules
// declared in texture.hpp.
#include "renderer/texture.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

#include "renderer/error.hpp"

namespace sb {
namespace {

/// The largest eigenvalue of the Gram matrix [e f; f g] (the squared major axis of the ellipse
/// two vectors span), in the form without cancellation.
double major_axis_squared(double e, double g, double f) {
  const double half_diff = 0.5 * (e - g);
  return 0.5 * (e + g) + std::sqrt(half_diff * half_diff + f * f);
}

/// The cone's cross-section axes projected along the ray onto the tangent plane of `normal`:
/// w - (n.w / n.d) d. A ray along the surface reads as |n.d| = 1e-6: a finite, very coarse level
/// instead of inf - inf.
std::pair<dvec3, dvec3> footprint_axes(const vec3& axis_a, const vec3& axis_b, const vec3& normal, const vec3& dir) {
  const dvec3 n(normal), d(dir), a(axis_a), b(axis_b);
  double nd = glm::dot(n, d);
  if (!(std::fabs(nd) >= 1e-6)) nd = nd < 0.0 ? -1e-6 : 1e-6;
  return {a - (glm::dot(n, a) / nd) * d, b - (glm::dot(n, b) / nd) * d};
}

/// The source texels (first, first + 1, ...) and weights that make one output texel along an axis.
struct AxisTaps {
  int first = 0;
  int count = 1;
  double weight[3] = {1.0, 0.0, 0.0};
};

/// Exact box filter of output texel i's footprint when an axis of n texels halves to max(1, n / 2).
AxisTaps axis_taps(int n, int i) {
  if (n == 1) return {0, 1, {1.0, 0.0, 0.0}};
  if (n % 2 == 0) return {2 * i, 2, {0.5, 0.5, 0.0}};
  // Odd n = 2k + 1 -> k texels: output i covers [i (2k + 1) / k, (i + 1) (2k + 1) / k) of the source,
  // which overlaps texel 2i by (k - i) / k, texel 2i + 1 fully and texel 2i + 2 by (i + 1) / k.
  const double k = n / 2;
  const double inv = 1.0 / static_cast<double>(n);
  return {2 * i, 3, {(k - i) * inv, k * inv, (i + 1) * inv}};
}

/// Next level's size along an axis (the OpenGL rule).
int half_size(int n) { return std::max(1, n / 2); }

/// Wraps a texel index into [0, n) for REPEAT; the index is at most one period outside.
int wrap_repeat(int i, int n) { return i < 0 ? i + n : (i >= n ? i - n : i); }
int wrap_clamp(int i, int n) { return std::clamp(i, 0, n - 1); }

}  // namespace

MipTexture::MipTexture(const Texture& texture, bool chain)
    : repeat_s_(texture.repeat_s), repeat_t_(texture.repeat_t), name_(texture.name) {
  if (texture.width <= 0 || texture.height <= 0)
    throw InputError(fmt::format("texture '{}': size {}x{} is not positive; a texture needs at least one texel",
                                 texture.name, texture.width, texture.height));
  const std::size_t texel_count = static_cast<std::size_t>(texture.width) * static_cast<std::size_t>(texture.height);
  if (texture.rgba.size() != texel_count * 4)
    throw InputError(fmt::format("texture '{}': {} floats for {}x{} RGBA texels; expected {}", texture.name,
                                 texture.rgba.size(), texture.width, texture.height, texel_count * 4));

  // Level 0: the image itself.
  Level base;
  base.width = texture.width;
  base.height = texture.height;
  base.texels.resize(texel_count);
  for (std::size_t i = 0; i < texel_count; ++i)
    base.texels[i] =
        vec4(texture.rgba[4 * i], texture.rgba[4 * i + 1], texture.rgba[4 * i + 2], texture.rgba[4 * i + 3]);
  levels_.push_back(std::move(base));

  // Coarser levels: separable box filter, horizontal pass then vertical pass, accumulated in double.
  while (chain && (levels_.back().width > 1 || levels_.back().height > 1)) {
    const Level& src = levels_.back();
    const int sw = src.width, sh = src.height;
    const int dw = half_size(sw), dh = half_size(sh);

    std::vector<dvec4> rows(static_cast<std::size_t>(dw) * static_cast<std::size_t>(sh));
    for (int y = 0; y < sh; ++y)
      for (int x = 0; x < dw; ++x) {
        const AxisTaps taps = axis_taps(sw, x);
        dvec4 sum(0.0);
        for (int t = 0; t < taps.count; ++t)
          sum += taps.weight[t] * dvec4(src.texels[static_cast<std::size_t>(y) * sw + (taps.first + t)]);
        rows[static_cast<std::size_t>(y) * dw + x] = sum;
      }

    Level dst;
    dst.width = dw;
    dst.height = dh;
    dst.texels.resize(static_cast<std::size_t>(dw) * static_cast<std::size_t>(dh));
    for (int y = 0; y < dh; ++y) {
      const AxisTaps taps = axis_taps(sh, y);
      for (int x = 0; x < dw; ++x) {
        dvec4 sum(0.0);
        for (int t = 0; t < taps.count; ++t)
          sum += taps.weight[t] * rows[static_cast<std::size_t>(taps.first + t) * dw + x];
        dst.texels[static_cast<std::size_t>(y) * dw + x] = vec4(sum);
      }
    }
    levels_.push_back(std::move(dst));
  }
}

int MipTexture::levels() const { return static_cast<int>(levels_.size()); }

const MipTexture::Level& MipTexture::level_at(int level) const {
  if (level < 0 || level >= levels())
    throw InputError(
        fmt::format("texture '{}': mip level {} requested; the chain has levels 0..{}", name_, level, levels() - 1));
  return levels_[static_cast<std::size_t>(level)];
}

int MipTexture::width(int level) const { return level_at(level).width; }
int MipTexture::height(int level) const { return level_at(level).height; }

vec4 MipTexture::sample_bilinear(vec2 uv, int level) const { return bilinear(level_at(level), uv); }

vec4 MipTexture::bilinear(const Level& level, vec2 uv) const {
  // Reduce the coordinates first (in double, so that large repeat counts keep their fraction):
  // REPEAT is periodic with period 1, CLAMP_TO_EDGE reads the edge texel beyond [0, 1].
  double u = std::isfinite(uv.x) ? static_cast<double>(uv.x) : 0.0;
  double v = std::isfinite(uv.y) ? static_cast<double>(uv.y) : 0.0;
  u = repeat_s_ ? u - std::floor(u) : std::clamp(u, 0.0, 1.0);
  v = repeat_t_ ? v - std::floor(v) : std::clamp(v, 0.0, 1.0);

  // Texel centres at (i + 0.5) / w: continuous texel coordinate minus one half.
  const double x = u * level.width - 0.5, y = v * level.height - 0.5;
  const double xf = std::floor(x), yf = std::floor(y);
  const float fx = static_cast<float>(x - xf), fy = static_cast<float>(y - yf);
  const int x0 = static_cast<int>(xf), y0 = static_cast<int>(yf);

  const int w = level.width, h = level.height;
  const int xa = repeat_s_ ? wrap_repeat(x0, w) : wrap_clamp(x0, w);
  const int xb = repeat_s_ ? wrap_repeat(x0 + 1, w) : wrap_clamp(x0 + 1, w);
  const int ya = repeat_t_ ? wrap_repeat(y0, h) : wrap_clamp(y0, h);
  const int yb = repeat_t_ ? wrap_repeat(y0 + 1, h) : wrap_clamp(y0 + 1, h);

  const auto texel = [&](int tx, int ty) { return level.texels[static_cast<std::size_t>(ty) * w + tx]; };
  const vec4 top = (1.0f - fx) * texel(xa, ya) + fx * texel(xb, ya);
  const vec4 bottom = (1.0f - fx) * texel(xa, yb) + fx * texel(xb, yb);
  return (1.0f - fy) * top + fy * bottom;
}

vec4 MipTexture::sample_trilinear(vec2 uv, float lod) const {
  if (std::isnan(lod)) lod = 0.0f;
  const int last = levels() - 1;
  lod = std::clamp(lod, 0.0f, static_cast<float>(last));
  const int l0 = static_cast<int>(std::floor(lod));
  const float f = lod - static_cast<float>(l0);
  const vec4 fine = bilinear(levels_[static_cast<std::size_t>(l0)], uv);
  if (l0 >= last || f == 0.0f) return fine;
  const vec4 coarse = bilinear(levels_[static_cast<std::size_t>(l0) + 1], uv);
  return (1.0f - f) * fine + f * coarse;
}

float lod_from_derivatives(const vec4& duv, int width, int height) {
  if (width <= 0 || height <= 0)
    throw InputError(fmt::format("lod_from_derivatives: texture size {}x{} is not positive", width, height));
  // Columns of the texel-space Jacobian: the pixel's x and y axes mapped to texels.
  const double ax = static_cast<double>(duv.x) * width, ay = static_cast<double>(duv.y) * height;
  const double bx = static_cast<double>(duv.z) * width, by = static_cast<double>(duv.w) * height;
  // Largest eigenvalue of J^T J (the squared major axis).
  return static_cast<float>(0.5 * std::log2(major_axis_squared(ax * ax + ay * ay, bx * bx + by * by, ax * bx + ay * by)));
}

double ray_cone_spread(double vfov, int height) {
  if (!(vfov > 0.0 && vfov < kPi))
    throw InputError(fmt::format("ray_cone_spread: vertical field of view {} rad is outside (0, pi)", vfov));
  if (height <= 0) throw InputError(fmt::format("ray_cone_spread: image height {} is not positive", height));
  return std::atan(2.0 * std::tan(0.5 * vfov) / height);
}

float ray_cone_triangle_lod(const vec3& p0, const vec3& p1, const vec3& p2, const vec2& uv0, const vec2& uv1,
                            const vec2& uv2, int width, int height) {
  if (width <= 0 || height <= 0)
    throw InputError(fmt::format("ray_cone_triangle_lod: texture size {}x{} is not positive", width, height));
  const dvec3 e1 = dvec3(p1) - dvec3(p0), e2 = dvec3(p2) - dvec3(p0);
  const double p_a = glm::length(glm::cross(e1, e2));
  const dvec2 t1 = dvec2(uv1) - dvec2(uv0), t2 = dvec2(uv2) - dvec2(uv0);
  const double t_a = static_cast<double>(width) * height * std::fabs(t1.x * t2.y - t1.y * t2.x);
  if (t_a == 0.0) return -std::numeric_limits<float>::infinity();
  if (p_a == 0.0) return std::numeric_limits<float>::infinity();
  return static_cast<float>(0.5 * std::log2(t_a / p_a));
}

float lod_from_ray_cone(float triangle_lod, float cone_width, float abs_cos_theta) {
  return static_cast<float>(static_cast<double>(triangle_lod) + std::log2(std::fabs(static_cast<double>(cone_width))) -
                            std::log2(std::fabs(static_cast<double>(abs_cos_theta))));
}


float lod_from_elliptic_cone(float triangle_lod, const vec3& axis_a, const vec3& axis_b, const vec3& normal,
                             const vec3& dir) {
  const auto [pa, pb] = footprint_axes(axis_a, axis_b, normal, dir);
  const double sigma_max_sq = major_axis_squared(glm::dot(pa, pa), glm::dot(pb, pb), glm::dot(pa, pb));
  return static_cast<float>(static_cast<double>(triangle_lod) + 0.5 * std::log2(sigma_max_sq));
}

TexelMap triangle_texel_map(const vec3& p0, const vec3& p1, const vec3& p2, const vec2& uv0, const vec2& uv1,
                            const vec2& uv2, int width, int height) {
  if (width <= 0 || height <= 0)
    throw InputError(fmt::format("triangle_texel_map: texture size {}x{} is not positive", width, height));
  // w = a e1 + b e2 in the plane has (a, b) = G^-1 (e1 . w, e2 . w), G the edges' Gram matrix, and
  // moves the coordinates by a d1 + b d2 (d1, d2 the edges' coordinate steps in texels).
  const dvec3 e1 = dvec3(p1) - dvec3(p0), e2 = dvec3(p2) - dvec3(p0);
  const double g11 = glm::dot(e1, e1), g12 = glm::dot(e1, e2), g22 = glm::dot(e2, e2);
  const double det = g11 * g22 - g12 * g12;
  TexelMap m;
  if (!(det > 0.0) || !std::isfinite(det)) {
    m.flat = true;
    return m;
  }
  const dvec2 size(width, height);
  const dvec2 d1 = (dvec2(uv1) - dvec2(uv0)) * size, d2 = (dvec2(uv2) - dvec2(uv0)) * size;
  // Row k of the map: (d1_k, d2_k) G^-1 (e1, e2)^T.
  const auto row = [&](double s1, double s2) {
    return ((s1 * g22 - s2 * g12) / det) * e1 + ((s2 * g11 - s1 * g12) / det) * e2;
  };
  m.u = row(d1.x, d2.x);
  m.v = row(d1.y, d2.y);
  return m;
}

float lod_from_elliptic_cone(const TexelMap& map, const vec3& axis_a, const vec3& axis_b, const vec3& normal,
                             const vec3& dir) {
  if (map.flat) return std::numeric_limits<float>::infinity();
  const auto [pa, pb] = footprint_axes(axis_a, axis_b, normal, dir);
  // The footprint's axes in texels: the columns of the 2x2 matrix whose major axis is the level.
  const dvec2 ta(glm::dot(map.u, pa), glm::dot(map.v, pa)), tb(glm::dot(map.u, pb), glm::dot(map.v, pb));
  const double sigma_max_sq = major_axis_squared(glm::dot(ta, ta), glm::dot(tb, tb), glm::dot(ta, tb));
  return static_cast<float>(0.5 * std::log2(sigma_max_sq));
}

}  // namespace sb
