// Restricted rays for the target pixels whose visible surface the source eye's frustum does not
// contain: the ray parameter interval inside the source frustum per pixel, the scene's triangles
// clipped to the part of the target frustum outside it, and rays only where those can be hit.
#include "renderer/stages/source_frustum.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/stages/primary_rays.hpp"

namespace sb {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

/// The half-space n·p + d >= 0 in world coordinates, n of unit length: at() is a signed distance.
struct HalfSpace {
  dvec3 n{0.0, 0.0, 1.0};
  double d = 0.0;

  [[nodiscard]] double at(const dvec3& p) const { return glm::dot(n, p) + d; }
  [[nodiscard]] HalfSpace outside() const { return {-n, -d}; }
};

/// The half-space (q·n + offset >= 0 with q = p − origin), normalised.
HalfSpace half_space(const dvec3& n, double offset, const dvec3& origin) {
  const double len = glm::length(n);
  return {n / len, (offset - glm::dot(n, origin)) / len};
}

/// The five half-spaces whose intersection is an eye's frustum: pixel coordinates 0 <= x <= W and
/// 0 <= y <= H, and depth at or beyond the near plane. With q = p − origin, lateral = q·right,
/// vertical = q·up, depth = −q·back, x = cx + f·lateral/depth and y = cy − f·vertical/depth.
std::array<HalfSpace, 5> frustum_half_spaces(const EyeCamera& c) {
  return {half_space(c.f_px * c.right - c.cx * c.back, 0.0, c.origin),
          half_space(-c.f_px * c.right - (c.width - c.cx) * c.back, 0.0, c.origin),
          half_space(-c.f_px * c.up - c.cy * c.back, 0.0, c.origin),
          half_space(c.f_px * c.up - (c.height - c.cy) * c.back, 0.0, c.origin),
          half_space(-c.back, -c.znear, c.origin)};
}

/// The part [in, out] of a ray inside the source frustum, in units of its pixel's direction
/// vector D (see PixelRays): depth along the target's axis equals the parameter.
struct RaySpan {
  double in = 0.0;
  double out = kInfinity;
  bool empty = false;
};

/// A convex polygon of at most 16 vertices (a triangle clipped by at most 13 half-spaces).
struct Polygon {
  std::array<dvec3, 16> v{};
  int n = 0;
};

/// Sutherland–Hodgman: the part of `p` inside `h`.
Polygon clip(const Polygon& p, const HalfSpace& h) {
  Polygon out;
  for (int i = 0; i < p.n; ++i) {
    const dvec3& a = p.v[static_cast<size_t>(i)];
    const dvec3& b = p.v[static_cast<size_t>((i + 1) % p.n)];
    const double da = h.at(a), db = h.at(b);
    if (da >= 0.0) out.v[static_cast<size_t>(out.n++)] = a;
    if ((da >= 0.0) != (db >= 0.0) && out.n < 16) out.v[static_cast<size_t>(out.n++)] = a + (da / (da - db)) * (b - a);
  }
  return out;
}

/// Distance (m) by which a point must lie outside a source half-space to count: the two eyes'
/// top, bottom and near planes coincide for a rig with a horizontal baseline, and a triangle
/// clipped to one and then to the outside of the other leaves only rounding noise.
constexpr double kOutsideTolerance = 1e-9;

/// Bits of a vertex outcode: outside target half-space k (k < 6, the last one the depth cap) or
/// outside source half-space k (bit 6 + k).
constexpr uint16_t kTargetBits = 0x3F;
constexpr uint16_t kSourceBits = 0x7C0;

/// Per target row, where the parts of triangles outside the source frustum may be seen: the
/// nearest depth, and the columns (a conservative box) their projections may cover.
struct RowReach {
  double zmin = kInfinity;
  int x0 = std::numeric_limits<int>::max();
  int x1 = std::numeric_limits<int>::min();

  void add(const RowReach& o) {
    zmin = std::min(zmin, o.zmin);
    x0 = std::min(x0, o.x0);
    x1 = std::max(x1, o.x1);
  }
};

/// The clipping geometry: the target frustum capped at a depth, and the source frustum.
struct Regions {
  std::array<HalfSpace, 6> target;  ///< target frustum from depth 0 (not its near plane) to the cap
  std::array<HalfSpace, 5> source;
  EyeCamera to;

  /// Outcode of a vertex. Beyond the depth cap only that bit is worked out and the vertex counts
  /// as outside every source half-space: a triangle wholly beyond the cap is dropped all the same,
  /// and one reaching in front of it is clipped.
  [[nodiscard]] uint16_t outcode(const dvec3& p) const {
    if (target[5].at(p) < 0.0) return static_cast<uint16_t>((1u << 5) | kSourceBits);
    uint16_t code = 0;
    for (size_t k = 0; k + 1 < target.size(); ++k)
      if (target[k].at(p) < 0.0) code |= static_cast<uint16_t>(1u << k);
    for (size_t k = 0; k < source.size(); ++k)
      if (source[k].at(p) < -kOutsideTolerance) code |= static_cast<uint16_t>(1u << (6 + k));
    return code;
  }

  /// Widens reach[row] for every target row the parts of triangle (a, b, c) outside the source
  /// frustum may cover, by the nearest depth and the columns of those parts. Returns whether there
  /// was such a part.
  bool lower_rows(const dvec3& a, const dvec3& b, const dvec3& c, std::vector<RowReach>& reach) const {
    Polygon p;
    p.v[0] = a;
    p.v[1] = b;
    p.v[2] = c;
    p.n = 3;
    for (const HalfSpace& h : target) {
      p = clip(p, h);
      if (p.n == 0) return false;
    }
    bool any = false;
    for (const HalfSpace& h : source) {
      bool outside = false;
      for (int i = 0; i < p.n && !outside; ++i) outside = h.at(p.v[static_cast<size_t>(i)]) < -kOutsideTolerance;
      if (!outside) continue;
      const Polygon q = clip(p, h.outside());
      if (q.n == 0) continue;
      double depth = kInfinity, x_lo = kInfinity, x_hi = -kInfinity, y_lo = kInfinity, y_hi = -kInfinity;
      for (int i = 0; i < q.n; ++i) {
        const dvec3 projected = to.project(q.v[static_cast<size_t>(i)]);
        if (!(projected.z > 0.0) || !std::isfinite(projected.x) || !std::isfinite(projected.y)) {
          // A part reaching the eye's plane projects without bound: every row and column.
          depth = 0.0;
          x_lo = y_lo = -kInfinity;
          x_hi = y_hi = kInfinity;
          break;
        }
        depth = std::min(depth, projected.z);
        x_lo = std::min(x_lo, projected.x);
        x_hi = std::max(x_hi, projected.x);
        y_lo = std::min(y_lo, projected.y);
        y_hi = std::max(y_hi, projected.y);
      }
      // Rows and columns whose pixel centres (j + 0.5, i + 0.5) may lie in [y_lo, y_hi] and
      // [x_lo, x_hi], with one to spare each side, clamped to the image (the part lies inside the
      // target frustum's side planes, so its projection lies in the image up to rounding).
      const auto index = [](double v, int n) { return static_cast<int>(std::clamp(v, 0.0, static_cast<double>(n - 1))); };
      const auto first = [&](double lo, int n) { return index(std::floor(lo - 0.5) - 1.0, n); };
      const auto last = [&](double hi, int n) { return index(std::floor(hi - 0.5) + 1.0, n); };
      const RowReach part{depth, first(x_lo, to.width), last(x_hi, to.width)};
      for (int j = first(y_lo, to.height); j <= last(y_hi, to.height); ++j) reach[static_cast<size_t>(j)].add(part);
      any = true;
    }
    return any;
  }
};

/// What a candidate pixel needs.
enum class Check : uint8_t {
  none,       ///< its ray can only see what the source frustum holds
  outside,    ///< its ray never enters the source frustum
  through,    ///< its ray leaves the source frustum again: trace [0, out]
  near_part,  ///< trace [0, in] if geometry reaches the pixel's row nearer than depth `in`
};

/// The target pixels' rays against the source frustum. The ray of pixel (x, y) runs from the
/// target eye along D = ((x + 0.5 − cx)/f)·right + ((cy − y − 0.5)/f)·up − back, whose depth
/// component is 1, so that a ray parameter in units of D is the target depth. Each source
/// half-space is a + t·b >= 0 along it, with a fixed per image and b affine in the pixel centre.
class PixelRays {
 public:
  PixelRays(const EyeCamera& to, const std::array<HalfSpace, 5>& source) : to_(to) {
    const dvec3 origin(vec3(to.origin));  // as primary_ray rounds it
    for (size_t k = 0; k < source.size(); ++k) {
      const HalfSpace& h = source[k];
      a_[k] = h.at(origin);
      bx_[k] = glm::dot(h.n, to.right) / to.f_px;
      by_[k] = -glm::dot(h.n, to.up) / to.f_px;
      b0_[k] = -bx_[k] * to.cx - by_[k] * to.cy - glm::dot(h.n, to.back);
    }
  }

  /// The check pixel (x, y) needs and its span.
  [[nodiscard]] Check check(int x, int y, RaySpan& s) const {
    s = RaySpan{};
    const double px = x + 0.5, py = y + 0.5;
    for (size_t k = 0; k < a_.size(); ++k) {
      const double b = b0_[k] + bx_[k] * px + by_[k] * py;
      if (b > 0.0) {
        if (a_[k] < 0.0) s.in = std::max(s.in, -a_[k] / b);  // otherwise inside from t = 0 on
      } else if (b < 0.0) {
        s.out = std::min(s.out, -a_[k] / b);
      } else if (a_[k] < 0.0) {
        s.empty = true;
      }
    }
    if (s.empty || s.in > s.out) return Check::outside;
    if (std::isfinite(s.out)) return Check::through;
    return s.in > 0.0 ? Check::near_part : Check::none;
  }

  /// The pixels of row y whose rays may leave the source frustum or miss it (some half-space with
  /// b <= 0): columns [0, left] and [right, W − 1] (left < 0 or right >= W when empty). b is
  /// affine in the column, so each half-space contributes a half-line of columns.
  void exits(int y, int& left, int& right) const {
    left = -1;
    right = to_.width;
    const double py = y + 0.5;
    for (size_t k = 0; k < a_.size(); ++k) {
      const double c = b0_[k] + by_[k] * py;  // b = c + bx·(x + 0.5)
      if (bx_[k] == 0.0) {
        if (c <= 0.0) left = to_.width - 1;
        continue;
      }
      const double x_zero = -c / bx_[k] - 0.5;  // column where b = 0
      if (bx_[k] > 0.0) {
        left = std::max(left, static_cast<int>(std::clamp(std::floor(x_zero), -1.0, static_cast<double>(to_.width - 1))));
      } else {
        right = std::min(right, static_cast<int>(std::clamp(std::ceil(x_zero), 0.0, static_cast<double>(to_.width))));
      }
    }
  }

  /// Embree's ray parameter (along the unit direction) of parameter t along D.
  [[nodiscard]] double unit_parameter(int x, int y, double t) const {
    const double u = (x + 0.5 - to_.cx) / to_.f_px, v = (to_.cy - y - 0.5) / to_.f_px;
    return t * std::sqrt(u * u + v * v + 1.0);
  }

 private:
  EyeCamera to_;
  std::array<double, 5> a_{}, b0_{}, bx_{}, by_{};
};

}  // namespace

SourceFrustumStats mark_outside_source_frustum(const RenderScene& scene, const EyeCamera& from, const EyeCamera& to,
                                               const Executor& executor, std::vector<uint8_t>& states, uint8_t candidate,
                                               uint8_t mark) {
  const int w = to.width, h = to.height;
  if (states.size() != static_cast<size_t>(w) * static_cast<size_t>(h))
    throw InputError(fmt::format("source frustum: {} pixel states for a {}x{} target eye", states.size(), w, h));
  const std::array<HalfSpace, 5> source = frustum_half_spaces(from);
  const PixelRays pixel_rays(to, source);

  // Per row: the deepest point at which a candidate pixel's ray enters the source frustum for good
  // (nothing deeper can hide in front of it), and the pixels whose rays never enter it or leave it
  // again.
  struct Special {
    int x;
    Check check;
    RaySpan span;
  };
  std::vector<double> row_cap(static_cast<size_t>(h), 0.0);
  std::vector<std::vector<Special>> specials(static_cast<size_t>(h));
  executor.for_range(static_cast<size_t>(h), 8, [&](size_t begin, size_t end) {
    for (size_t j = begin; j < end; ++j) {
      const int y = static_cast<int>(j);
      int left = 0, right = 0;
      pixel_rays.exits(y, left, right);
      const auto visit = [&](int x) {
        if (states[j * static_cast<size_t>(w) + static_cast<size_t>(x)] != candidate) return;
        RaySpan span;
        const Check check = pixel_rays.check(x, y, span);
        if (check == Check::outside || check == Check::through) specials[j].push_back({x, check, span});
        if (check == Check::near_part) row_cap[j] = std::max(row_cap[j], span.in);
      };
      for (int x = 0; x <= std::min(left, w - 1); ++x) visit(x);
      for (int x = std::max(right, left + 1); x < w; ++x) visit(x);
      // Between them every b is positive and the entry parameter max_k(−a_k / b_k) of the
      // half-spaces the ray enters is convex in the column: its largest value is at an end.
      for (const int x : {left + 1, right - 1}) {
        if (x < 0 || x >= w || left + 1 > right - 1) continue;
        RaySpan span;
        if (pixel_rays.check(x, y, span) == Check::near_part) row_cap[j] = std::max(row_cap[j], span.in);
      }
    }
  });
  const double cap = *std::max_element(row_cap.begin(), row_cap.end());

  // Per target row, the nearest depth at which a triangle outside the source frustum (and inside
  // the target frustum, not deeper than the cap) may be seen, and the columns where.
  SourceFrustumStats stats;
  std::vector<RowReach> reach(static_cast<size_t>(h));
  if (cap > 0.0) {
    Regions regions;
    const std::array<HalfSpace, 5> target = frustum_half_spaces(to);
    std::copy(target.begin(), target.end(), regions.target.begin());
    // Rays start at the eye, not at its near plane: the target side keeps every depth from 0 on,
    // so that surfaces in front of the near plane, outside the source frustum, are clipped too.
    regions.target[4] = half_space(-to.back, 0.0, to.origin);  // depth >= 0
    regions.target[5] = half_space(to.back, cap, to.origin);    // depth = −q·back <= cap
    regions.source = source;
    // Projected from the float-rounded origin the rays start at (see primary_ray).
    regions.to = to;
    regions.to.origin = dvec3(vec3(to.origin));
    const Scene& s = scene.scene();
    const SceneGeometry& geometry = scene.geometry();
    // Outcodes of every vertex, meshes one after another.
    std::vector<size_t> first_vertex(s.meshes.size() + 1, 0);
    for (size_t m = 0; m < s.meshes.size(); ++m) first_vertex[m + 1] = first_vertex[m] + s.meshes[m].positions.size();
    std::vector<uint16_t> codes(first_vertex.back());
    constexpr size_t kGrain = 16384;
    executor.for_range(codes.size(), kGrain, [&](size_t begin, size_t end) {
      size_t m = static_cast<size_t>(std::upper_bound(first_vertex.begin(), first_vertex.end(), begin) - first_vertex.begin()) - 1;
      for (size_t v = begin; v < end; ++v) {
        while (v >= first_vertex[m + 1]) ++m;
        codes[v] = regions.outcode(dvec3(s.meshes[m].positions[v - first_vertex[m]]));
      }
    });
    // Triangles in fixed chunks, each widening its own copy of the rows' reach (merged below: the
    // minima and maxima do not depend on the order).
    const size_t triangles = geometry.triangle_count();
    const size_t chunks = (triangles + kGrain - 1) / kGrain;
    std::vector<std::vector<RowReach>> chunk_reach(chunks);
    std::vector<uint64_t> chunk_near(chunks, 0);
    executor.for_each(chunks, [&](size_t k) {
      const size_t begin = k * kGrain, end = std::min(begin + kGrain, triangles);
      size_t m = geometry.locate(static_cast<uint32_t>(begin)).first;
      for (size_t t = begin; t < end; ++t) {
        while (t >= geometry.first_triangle[m + 1]) ++m;
        const Mesh& mesh = s.meshes[m];
        const size_t local = t - geometry.first_triangle[m];
        const uint32_t i0 = mesh.indices[local * 3], i1 = mesh.indices[local * 3 + 1], i2 = mesh.indices[local * 3 + 2];
        const uint16_t c0 = codes[first_vertex[m] + i0], c1 = codes[first_vertex[m] + i1], c2 = codes[first_vertex[m] + i2];
        // Wholly outside one target half-space, or wholly inside the (convex) source frustum.
        if ((c0 & c1 & c2 & kTargetBits) != 0 || ((c0 | c1 | c2) & kSourceBits) == 0) continue;
        if (chunk_reach[k].empty()) chunk_reach[k].resize(static_cast<size_t>(h));
        if (regions.lower_rows(dvec3(mesh.positions[i0]), dvec3(mesh.positions[i1]), dvec3(mesh.positions[i2]),
                               chunk_reach[k]))
          ++chunk_near[k];
      }
    });
    for (size_t k = 0; k < chunks; ++k) {
      stats.triangles_near += chunk_near[k];
      if (chunk_reach[k].empty()) continue;
      for (size_t j = 0; j < reach.size(); ++j) reach[j].add(chunk_reach[k][j]);
    }
  }

  // The rays, row by row in packets of up to 16 (the same packets on any thread count).
  std::vector<uint64_t> row_rays(static_cast<size_t>(h), 0), row_marked(static_cast<size_t>(h), 0);
  executor.for_range(static_cast<size_t>(h), 4, [&](size_t begin, size_t end) {
    RayQuery rays[kRayPacket];
    RayHit hits[kRayPacket];
    double enter[kRayPacket];
    size_t pixel[kRayPacket];
    bool through[kRayPacket];
    for (size_t j = begin; j < end; ++j) {
      int n = 0;
      const auto flush = [&] {
        if (n == 0) return;
        scene.rays().intersect(std::span<const RayQuery>(rays, static_cast<size_t>(n)),
                               std::span<RayHit>(hits, static_cast<size_t>(n)));
        for (int i = 0; i < n; ++i) {
          const bool hit = hits[i].prim != kNoPrimitiveId;
          // Through: outside when nothing is hit before the ray leaves the source frustum, or the
          // hit lies before it enters. Near part: outside when anything is hit before it enters.
          const bool outside = through[i] ? (!hit || static_cast<double>(hits[i].t) < enter[i]) : hit;
          if (outside) {
            states[pixel[i]] = mark;
            ++row_marked[j];
          }
        }
        row_rays[j] += static_cast<uint64_t>(n);
        n = 0;
      };
      const auto add = [&](int x, const RaySpan& span, bool trace_through) {
        rays[n] = primary_ray(to, x, static_cast<int>(j));
        rays[n].tfar =
            static_cast<float>(pixel_rays.unit_parameter(x, static_cast<int>(j), trace_through ? span.out : span.in));
        enter[n] = pixel_rays.unit_parameter(x, static_cast<int>(j), span.in);
        through[n] = trace_through;
        pixel[n] = j * static_cast<size_t>(w) + static_cast<size_t>(x);
        if (++n == kRayPacket) flush();
      };
      for (const Special& sp : specials[j]) {
        if (sp.check == Check::outside) {
          states[j * static_cast<size_t>(w) + static_cast<size_t>(sp.x)] = mark;
          ++row_marked[j];
        } else {
          add(sp.x, sp.span, true);
        }
      }
      flush();
      // Rays that may meet a clipped triangle before entering the source frustum: whatever a ray
      // hits before it enters lies outside the source frustum, so on a clipped part, which
      // projects onto the pixel's centre; only the row's columns of those parts are looked at.
      const RowReach& row = reach[j];
      if (!(row.zmin < row_cap[j])) continue;
      for (int x = row.x0; x <= row.x1; ++x) {
        if (states[j * static_cast<size_t>(w) + static_cast<size_t>(x)] != candidate) continue;
        RaySpan span;
        if (pixel_rays.check(x, static_cast<int>(j), span) == Check::near_part && span.in > row.zmin) add(x, span, false);
      }
      flush();
    }
  });
  for (size_t j = 0; j < row_rays.size(); ++j) {
    stats.rays += row_rays[j];
    stats.pixels += row_marked[j];
  }
  return stats;
}

}  // namespace sb
