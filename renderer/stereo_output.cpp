// Anaglyph, side-by-side and over/under composition of an eye pair (stereo_output.hpp). The
// loops are a few float operations per pixel, cheaper than spreading them over threads.
#include "renderer/stereo_output.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstddef>
#include <string>
#include <string_view>

#include "renderer/error.hpp"

namespace sb {
namespace {

/// The eyes' radiance planes, after checking that both exist and have the same size.
struct EyePair {
  const Plane& left;
  const Plane& right;
};

/// The named eye's "rgb" plane, or an InputError naming the eye and the planes it has.
const Plane& eye_rgb(std::string_view what, std::string_view eye, const Image& image) {
  const Plane* plane = image.find_plane(planes::rgb);
  if (plane == nullptr)
    throw InputError(
        fmt::format("{}: the {} eye image has no \"rgb\" plane (planes: {}); pass images with linear radiance", what,
                    eye, image.planes().empty() ? std::string("none") : image.plane_list()));
  return *plane;
}

EyePair check_pair(std::string_view what, const Image& left, const Image& right) {
  const Plane& l = eye_rgb(what, "left", left);
  const Plane& r = eye_rgb(what, "right", right);
  if (left.width() != right.width() || left.height() != right.height())
    throw InputError(fmt::format(
        "{}: the left eye image is {}x{} but the right eye image is {}x{}; both eyes must have the same size", what,
        left.width(), left.height(), right.width(), right.height()));
  return {l, r};
}

/// Linear value clamped to [0, 1], NaN to 0.
float clamp_unit(double v) { return v > 0.0 ? (v < 1.0 ? static_cast<float>(v) : 1.0f) : 0.0f; }

/// Copies a whole eye's "rgb" plane into `dst` with its top-left corner at (x0, y0).
void blit(const Plane& src, Plane& dst, int x0, int y0) {
  const std::size_t row_values = static_cast<std::size_t>(src.width()) * 3;
  for (int y = 0; y < src.height(); ++y)
    std::copy_n(src.data_f32() + src.offset(0, y), row_values, dst.data_f32() + dst.offset(x0, y0 + y));
}

/// Checks a doubled side against the largest image the suite accepts.
void check_combined(std::string_view what, std::string_view axis, int doubled) {
  if (doubled > kMaxImageDimension)
    throw InputError(fmt::format("{}: the combined {} {} exceeds the largest image side {}; render smaller eyes", what,
                                 axis, doubled, kMaxImageDimension));
}

}  // namespace

Image anaglyph_dubois(const Image& left, const Image& right) {
  const EyePair eyes = check_pair("anaglyph_dubois", left, right);
  Image out(left.width(), left.height());
  Plane& rgb = out.add_plane(planes::rgb);

  const float* l = eyes.left.data_f32();
  const float* r = eyes.right.data_f32();
  float* o = rgb.data_f32();
  for (std::size_t p = 0; p < out.pixel_count(); ++p, l += 3, r += 3, o += 3)
    for (int row = 0; row < 3; ++row) {
      // Accumulate the six products in double so that a white pair reaches the row sum exactly.
      double sum = 0.0;
      for (int c = 0; c < 3; ++c)
        sum += static_cast<double>(kDuboisRedCyanLeft[row][c]) * l[c] +
               static_cast<double>(kDuboisRedCyanRight[row][c]) * r[c];
      o[row] = clamp_unit(sum);
    }
  return out;
}

Image side_by_side(const Image& left, const Image& right) {
  const EyePair eyes = check_pair("side_by_side", left, right);
  check_combined("side_by_side", "width", 2 * left.width());
  Image out(2 * left.width(), left.height());
  Plane& rgb = out.add_plane(planes::rgb);
  blit(eyes.left, rgb, 0, 0);
  blit(eyes.right, rgb, left.width(), 0);
  return out;
}

Image over_under(const Image& left, const Image& right) {
  const EyePair eyes = check_pair("over_under", left, right);
  check_combined("over_under", "height", 2 * left.height());
  Image out(left.width(), 2 * left.height());
  Plane& rgb = out.add_plane(planes::rgb);
  blit(eyes.left, rgb, 0, 0);
  blit(eyes.right, rgb, 0, left.height());
  return out;
}

}  // namespace sb
