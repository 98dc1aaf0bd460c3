// True disocclusions by exact visibility tests against the left eye, hole masks from source tags,
// their scores and the overlay image.
#include "renderer/stages/disocclusion.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/stages/primary_rays.hpp"

namespace sb {

VisibleSurfaces trace_visible_surfaces(const RenderScene& scene, const EyeCamera& eye, const Executor& executor) {
  const int w = eye.width, h = eye.height;
  const size_t n = static_cast<size_t>(w) * static_cast<size_t>(h);
  VisibleSurfaces v{w, h, std::vector<float>(n, std::numeric_limits<float>::infinity()),
                    std::vector<uint32_t>(n, kNoPrimitive)};
  const PrimaryRays primary(eye);
  executor.for_tiles(w, h, kTraceTile, [&](const PixelRect& tile) {
    for_pixel_blocks(tile, w, [&](const PixelBlock& block) {
      RayQuery rays[kRayPacket];
      RayHit hits[kRayPacket];
      const int count = block.n;
      const uint32_t* pixels = block.index;
      for (int i = 0; i < count; ++i) rays[i] = primary(block.x[i], block.y[i]);
      scene.rays().intersect(std::span<const RayQuery>(rays, static_cast<size_t>(count)),
                             std::span<RayHit>(hits, static_cast<size_t>(count)));
      for (int i = 0; i < count; ++i) {
        if (hits[i].prim == kNoPrimitiveId) continue;
        v.depth[pixels[i]] = hits[i].t * cos_to_axis(eye, rays[i].dir);
        v.prim[pixels[i]] = hits[i].prim;
      }
    });
  });
  return v;
}

namespace {

/// A pixel's verdict from the geometric tests, or the occlusion ray that decides it.
struct Verdict {
  Disocclusion kind = Disocclusion::visible;
  bool needs_ray = false;  ///< true: hidden if `ray` hits something nearer than `distance - tolerance`
  RayQuery ray;
  double distance = std::numeric_limits<double>::infinity();  ///< from the left eye to the point
  double tolerance = 0.0;
};

/// A surface point and its unit geometric normal, turned towards the eye that sees it.
struct SurfaceHit {
  dvec3 position{0.0};
  dvec3 normal{0.0, 0.0, 1.0};
};

/// The per-pixel tests of true_disocclusions for one rig.
class DisocclusionTester {
 public:
  DisocclusionTester(const RenderScene& scene, const StereoRig& rig)
      : scene_(scene), right_(rig.eye(Eye::right)), left_(rig.eye(Eye::left)), right_rays_(right_),
        eps_(scene.ray_epsilon()) {}

  /// The verdict for right-eye pixel (x, y), which sees `prim` at linear `depth` (or nothing).
  [[nodiscard]] Verdict classify(int x, int y, uint32_t prim, float depth) const {
    const RayQuery ray = right_rays_(x, y);
    return prim == kNoPrimitive ? classify_background(ray) : classify_surface(ray, prim, depth);
  }

 private:
  /// Whether continuous left-eye pixel coordinates lie outside the left image.
  [[nodiscard]] bool outside_image(const dvec3& projected) const {
    return !(projected.x >= 0.0 && projected.x < left_.width && projected.y >= 0.0 && projected.y < left_.height);
  }

  [[nodiscard]] Verdict classify_background(const RayQuery& ray) const {
    Verdict v;
    // A direction seen from the left eye: the projection of a point at infinity.
    if (outside_image(left_.project(left_.origin + dvec3(ray.dir)))) {
      v.kind = Disocclusion::outside_frustum;
      return v;
    }
    v.needs_ray = true;
    v.ray.origin = vec3(left_.origin);
    v.ray.dir = ray.dir;
    return v;
  }

  [[nodiscard]] Verdict classify_surface(const RayQuery& ray, uint32_t prim, float depth) const {
    Verdict v;
    const SurfaceHit hit = reconstruct(ray, prim, depth);
    const dvec3 projected = left_.project(hit.position);
    if (!(projected.z > left_.znear) || outside_image(projected)) {
      v.kind = Disocclusion::outside_frustum;
      return v;
    }
    // The left eye on the other side of the triangle's plane sees its other face (or, single-sided,
    // nothing of it); in the plane it sees the triangle edge-on.
    if (glm::dot(hit.normal, left_.origin - hit.position) <= 0.0) {
      v.kind = Disocclusion::hidden;
      return v;
    }
    // The left eye's own closest hit towards the point: anything nearer than the point (by more
    // than the float resolution of the hit distance) hides it. A hit on a neighbouring triangle
    // at the same distance — the point lies on a shared edge or on coplanar geometry — is the same
    // surface point and does not.
    const dvec3 to_point = hit.position - left_.origin;
    const double distance = glm::length(to_point);
    if (distance <= static_cast<double>(eps_)) return v;  // the point touches the eye: nothing in between
    v.needs_ray = true;
    v.ray.origin = vec3(left_.origin);
    v.ray.dir = vec3(to_point / distance);
    v.distance = distance;
    v.tolerance = std::max(16.0 * static_cast<double>(eps_), 1e-5 * distance);
    return v;
  }

  /// The primary ray's hit on triangle `prim`: the ray intersected with the triangle's plane in
  /// double precision, so that the point lies on that plane up to double rounding (the float hit
  /// distance may put it a few float ulps off the plane, which matters at the scale of the normal
  /// offset). The linear depth gives the point when the ray is parallel to the plane.
  [[nodiscard]] SurfaceHit reconstruct(const RayQuery& ray, uint32_t prim, float depth) const {
    const auto [mesh_index, tri] = scene_.geometry().locate(prim);
    const Mesh& mesh = scene_.scene().meshes[mesh_index];
    const dvec3 v0(mesh.positions[mesh.indices[tri * 3 + 0]]);
    const dvec3 v1(mesh.positions[mesh.indices[tri * 3 + 1]]);
    const dvec3 v2(mesh.positions[mesh.indices[tri * 3 + 2]]);
    const dvec3 origin(ray.origin), dir(ray.dir);
    const dvec3 n = glm::cross(v1 - v0, v2 - v0);
    const double along = glm::dot(n, dir);
    SurfaceHit hit;
    hit.position = along != 0.0 ? origin + (glm::dot(n, v0 - origin) / along) * dir
                                : origin + (static_cast<double>(depth) / static_cast<double>(cos_to_axis(right_, ray.dir))) * dir;
    const double len = glm::length(n);
    hit.normal = len > 0.0 ? n / len : -dir;
    if (glm::dot(hit.normal, right_.origin - hit.position) < 0.0) hit.normal = -hit.normal;
    return hit;
  }

  const RenderScene& scene_;
  EyeCamera right_;
  EyeCamera left_;
  PrimaryRays right_rays_;
  float eps_;
};

/// Collects the visibility rays of one tile and casts them in packets of 16; a ray that hits
/// something nearer than its point marks the pixel hidden.
class VisibilityBatch {
 public:
  VisibilityBatch(const RayScene& rays, std::vector<uint8_t>& mask) : rays_(rays), mask_(mask) {}

  void add(size_t pixel, const Verdict& v) {
    queries_[n_] = v.ray;
    limits_[n_] = v.distance - v.tolerance;
    pixels_[n_] = pixel;
    if (++n_ == kRayPacket) flush();
  }

  void flush() {
    if (n_ == 0) return;
    RayHit hits[kRayPacket];
    rays_.intersect(std::span<const RayQuery>(queries_, static_cast<size_t>(n_)),
                    std::span<RayHit>(hits, static_cast<size_t>(n_)));
    for (int i = 0; i < n_; ++i) {
      const bool blocked = hits[i].prim != kNoPrimitiveId && static_cast<double>(hits[i].t) < limits_[i];
      mask_[pixels_[i]] = static_cast<uint8_t>(blocked ? Disocclusion::hidden : Disocclusion::visible);
    }
    n_ = 0;
  }

 private:
  const RayScene& rays_;
  std::vector<uint8_t>& mask_;
  RayQuery queries_[kRayPacket];
  double limits_[kRayPacket] = {};
  size_t pixels_[kRayPacket] = {};
  int n_ = 0;
};

}  // namespace

TrueDisocclusions true_disocclusions(const RenderScene& scene, const StereoRig& rig, const VisibleSurfaces& right,
                                     const Executor& executor) {
  const int w = rig.params().width, h = rig.params().height;
  const size_t n = static_cast<size_t>(w) * static_cast<size_t>(h);
  if (right.width != w || right.height != h || right.depth.size() != n || right.prim.size() != n)
    throw InputError(fmt::format("true_disocclusions: the visible surfaces are {}x{} ({} depths, {} ids) but the rig "
                                 "renders {}x{}; trace them with the rig's right eye",
                                 right.width, right.height, right.depth.size(), right.prim.size(), w, h));
  TrueDisocclusions truth;
  truth.mask.assign(n, static_cast<uint8_t>(Disocclusion::visible));
  const DisocclusionTester tester(scene, rig);
  executor.for_tiles(w, h, kTraceTile, [&](const PixelRect& tile) {
    VisibilityBatch batch(scene.rays(), truth.mask);
    for (int y = tile.y0; y < tile.y1; ++y)
      for (int x = tile.x0; x < tile.x1; ++x) {
        const size_t i = static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x);
        const Verdict v = tester.classify(x, y, right.prim[i], right.depth[i]);
        if (v.needs_ray)
          batch.add(i, v);
        else
          truth.mask[i] = static_cast<uint8_t>(v.kind);
      }
    batch.flush();
  });
  for (uint8_t m : truth.mask) {
    truth.outside_frustum += m == static_cast<uint8_t>(Disocclusion::outside_frustum) ? 1 : 0;
    truth.hidden += m == static_cast<uint8_t>(Disocclusion::hidden) ? 1 : 0;
  }
  return truth;
}

namespace {

/// Whether a source tag marks a pixel the pipeline had to fill instead of reprojecting it (an
/// unknown tag does not).
bool is_hole_source(uint32_t tag) {
  const std::optional<Source> s = source_from_u32(tag);
  return s && (*s == Source::hole || *s == Source::reshaded_traced || *s == Source::reshaded_raster ||
               *s == Source::inpainted);
}

/// InputError unless `mask` has one value per pixel of `image`.
void require_per_pixel(const Image& image, std::span<const uint8_t> mask, const char* what) {
  if (mask.size() != image.pixel_count())
    throw InputError(fmt::format("hole_overlay: the {} mask has {} values but the image is {}x{} ({} pixels)", what,
                                 mask.size(), image.width(), image.height(), image.pixel_count()));
}

/// A linear radiance value clamped to [0, 1] (NaN reads as 0).
float clamp01(float v) { return v > 0.0f ? std::min(v, 1.0f) : 0.0f; }

}  // namespace

std::vector<uint8_t> hole_mask_from_sources(const Image& right) {
  const std::span<const uint32_t> source = right.plane(planes::source).u32();
  std::vector<uint8_t> mask(source.size());
  std::transform(source.begin(), source.end(), mask.begin(), [](uint32_t tag) { return is_hole_source(tag) ? 1 : 0; });
  return mask;
}

std::vector<uint8_t> not_reprojected_mask(const Image& eye) {
  const std::span<const uint32_t> source = eye.plane(planes::source).u32();
  std::vector<uint8_t> mask(source.size());
  std::transform(source.begin(), source.end(), mask.begin(),
                 [](uint32_t tag) { return tag != static_cast<uint32_t>(Source::reprojected) ? 1 : 0; });
  return mask;
}

bool has_reprojected_pixels(const Image& image) {
  const std::span<const uint32_t> source = image.plane(planes::source).u32();
  return std::find(source.begin(), source.end(), static_cast<uint32_t>(Source::reprojected)) != source.end();
}

HoleScores score_holes(std::span<const uint8_t> holes, std::span<const uint8_t> truth) {
  if (holes.size() != truth.size())
    throw InputError(fmt::format("score_holes: the hole mask has {} pixels but the true disocclusion mask has {}; "
                                 "both must come from the same right eye",
                                 holes.size(), truth.size()));
  HoleScores s;
  for (size_t i = 0; i < holes.size(); ++i) {
    const bool flagged = holes[i] != 0, disoccluded = truth[i] != 0;
    s.hole_pixels += flagged ? 1 : 0;
    s.true_pixels += disoccluded ? 1 : 0;
    s.true_positives += flagged && disoccluded ? 1 : 0;
  }
  if (s.true_pixels > 0) s.recall = static_cast<double>(s.true_positives) / static_cast<double>(s.true_pixels);
  if (s.hole_pixels > 0) s.precision = static_cast<double>(s.true_positives) / static_cast<double>(s.hole_pixels);
  return s;
}

Image hole_overlay(const Image& right, std::span<const uint8_t> holes, std::span<const uint8_t> truth) {
  require_per_pixel(right, holes, "hole");
  require_per_pixel(right, truth, "true disocclusion");
  constexpr float kDim = 0.3f, kTintedDim = 0.25f, kTint = 0.75f;
  const vec3 found(0.0f, 1.0f, 0.0f), missed(1.0f, 0.0f, 0.0f), wasted(0.0f, 0.35f, 1.0f);
  const float* radiance = right.data_f32(planes::rgb);
  Image out(right.width(), right.height());
  float* rgb = out.add_plane(planes::rgb).data_f32();
  for (size_t i = 0; i < right.pixel_count(); ++i) {
    const vec3 base(clamp01(radiance[i * 3]), clamp01(radiance[i * 3 + 1]), clamp01(radiance[i * 3 + 2]));
    const bool flagged = holes[i] != 0, disoccluded = truth[i] != 0;
    vec3 c = kDim * base;
    if (flagged || disoccluded) {
      const vec3& tint = flagged ? (disoccluded ? found : wasted) : missed;
      c = kTintedDim * base + kTint * tint;
    }
    rgb[i * 3 + 0] = c.x;
    rgb[i * 3 + 1] = c.y;
    rgb[i * 3 + 2] = c.z;
  }
  return out;
}

std::optional<HoleAnalysis> analyze_holes(const RenderScene& scene, const StereoRig& rig, const Image& right,
                                          const Executor& executor) {
  if (!has_reprojected_pixels(right)) return std::nullopt;
  const auto start = std::chrono::steady_clock::now();
  HoleAnalysis a;
  a.truth = true_disocclusions(scene, rig, trace_visible_surfaces(scene, rig.eye(Eye::right), executor), executor);
  const std::vector<uint8_t> holes = not_reprojected_mask(right);
  a.scores = score_holes(holes, a.truth.mask);
  a.overlay = hole_overlay(right, holes, a.truth.mask);
  a.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return a;
}

}  // namespace sb
