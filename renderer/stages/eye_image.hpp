// An eye's output image with the standard AOV planes, a reader that looks its planes up once, and
// a writer that fills one pixel of all of them at once.
#pragma once

#include <limits>

#include "renderer/image.hpp"
#include "renderer/shading.hpp"

namespace sb {

/// A width x height image with planes rgb, depth, normal, albedo, primid and source: empty
/// (radiance 0, kNoPrimitive, tag hole), or with unset samples for a stage that writes every pixel.
[[nodiscard]] Image make_eye_image(int width, int height, PlaneInit init = PlaneInit::filled);

/// Cached plane pointers of an eye image (made by make_eye_image) for per-pixel reads in hot loops.
class EyeReader {
 public:
  explicit EyeReader(const Image& image);

  [[nodiscard]] vec3 rgb(size_t i) const { return load3(rgb_, i); }
  [[nodiscard]] vec3 normal(size_t i) const { return load3(normal_, i); }
  [[nodiscard]] vec3 albedo(size_t i) const { return load3(albedo_, i); }
  [[nodiscard]] float depth(size_t i) const { return depth_[i]; }
  [[nodiscard]] uint32_t prim(size_t i) const { return prim_[i]; }
  [[nodiscard]] uint32_t source(size_t i) const { return source_[i]; }

 private:
  static vec3 load3(const float* plane, size_t i) { return {plane[3 * i], plane[3 * i + 1], plane[3 * i + 2]}; }
  const float* rgb_;
  const float* normal_;
  const float* albedo_;
  const float* depth_;
  const uint32_t* prim_;
  const uint32_t* source_;
};

/// Cached plane pointers of an eye image for per-pixel writes from parallel loops (each pixel is
/// written by one task only).
class EyeWriter {
 public:
  explicit EyeWriter(Image& image);

  /// A visible surface.
  void surface(size_t index, const SurfacePoint& p, const vec3& radiance, const vec3& albedo, float depth,
               Source source) {
    set3(rgb_, index, radiance);
    set3(normal_, index, p.shading_normal);
    set3(albedo_, index, albedo);
    depth_[index] = depth;
    prim_[index] = p.prim;
    source_[index] = static_cast<uint32_t>(source);
  }
  /// A pixel whose values come from elsewhere (a reprojected one).
  void copy(size_t index, const vec3& radiance, const vec3& normal, const vec3& albedo, float depth, uint32_t prim,
            Source source) {
    set3(rgb_, index, radiance);
    set3(normal_, index, normal);
    set3(albedo_, index, albedo);
    depth_[index] = depth;
    prim_[index] = prim;
    source_[index] = static_cast<uint32_t>(source);
  }
  /// Pixel `index` takes every value of pixel `from_index` of `from` (another eye image), with tag
  /// `source`: a reprojected or warped pixel.
  void copy(size_t index, const EyeReader& from, size_t from_index, Source source) {
    copy(index, from.rgb(from_index), from.normal(from_index), from.albedo(from_index), from.depth(from_index),
         from.prim(from_index), source);
  }
  /// A pixel no stage has a value for yet: radiance 0, depth +inf, tag `hole`.
  void hole(size_t index) {
    set3(rgb_, index, vec3(0.0f));
    set3(normal_, index, vec3(0.0f));
    set3(albedo_, index, vec3(0.0f));
    depth_[index] = std::numeric_limits<float>::infinity();
    prim_[index] = kNoPrimitive;
    source_[index] = static_cast<uint32_t>(Source::hole);
  }
  /// A ray or pixel that sees no geometry: the background.
  void background(size_t index, const vec3& background, Source source) {
    set3(rgb_, index, background);
    set3(normal_, index, vec3(0.0f));
    set3(albedo_, index, vec3(0.0f));
    depth_[index] = std::numeric_limits<float>::infinity();
    prim_[index] = kNoPrimitive;
    source_[index] = static_cast<uint32_t>(source);
  }

 private:
  static void set3(float* plane, size_t index, const vec3& v) {
    plane[index * 3 + 0] = v.x;
    plane[index * 3 + 1] = v.y;
    plane[index * 3 + 2] = v.z;
  }
  float* rgb_;
  float* normal_;
  float* albedo_;
  float* depth_;
  uint32_t* prim_;
  uint32_t* source_;
};

}  // namespace sb
