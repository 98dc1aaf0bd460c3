// Difference heat maps and SSIM map images on fixed colour scales, written as PNG.
#include "validation/metric_images.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/io/image_io.hpp"

namespace sb::validation {

namespace {

using Rgb8 = std::array<uint8_t, 3>;

/// Heat ramp stops (sRGB codes), equally spaced in t; lightness rises from each stop to the next.
constexpr std::array<Rgb8, 7> kHeatStops{{
    {0, 0, 0},        // black
    {40, 11, 84},     // deep violet
    {120, 28, 109},   // magenta
    {190, 55, 82},    // red
    {237, 105, 37},   // orange
    {251, 180, 26},   // yellow
    {252, 255, 164},  // pale yellow
}};

/// Linear interpolation (in sRGB codes) between equally spaced stops at t in [0, 1].
template <std::size_t N>
Rgb8 ramp(const std::array<Rgb8, N>& stops, double t) {
  if (!(t > 0.0)) return stops.front();  // also NaN
  if (t >= 1.0) return stops.back();
  const double pos = t * static_cast<double>(N - 1);
  const std::size_t i = static_cast<std::size_t>(pos);
  const double f = pos - static_cast<double>(i);
  Rgb8 c{};
  for (std::size_t k = 0; k < 3; ++k)
    c[k] = static_cast<uint8_t>(std::lround(double(stops[i][k]) * (1.0 - f) + double(stops[i + 1][k]) * f));
  return c;
}

/// The SSIM ramp: white, then the heat stops from the lightest to black.
constexpr std::array<Rgb8, 8> ssim_stops() {
  std::array<Rgb8, 8> s{};
  s[0] = {255, 255, 255};
  for (std::size_t i = 0; i < kHeatStops.size(); ++i) s[i + 1] = kHeatStops[kHeatStops.size() - 1 - i];
  return s;
}

void check_region(const RegionMask* region, int width, int height) {
  if (region != nullptr &&
      (region->width != width || region->height != height ||
       region->inside.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height)))
    throw InputError(fmt::format("the region mask is {}x{} but the image is {}x{}; give a mask of the image size",
                                 region->width, region->height, width, height));
}

/// Dims the pixels outside the region to a third and draws its outline.
void mark_region(Srgb8Image& image, const RegionMask* region) {
  if (region == nullptr) return;
  const int w = image.width, h = image.height;
  const auto inside = [&](int x, int y) {
    return region->inside[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)] != 0;
  };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* px =
          &image.rgb[(static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)) * 3];
      if (!inside(x, y)) {
        for (int c = 0; c < 3; ++c) px[c] = static_cast<uint8_t>(px[c] / 3);
        continue;
      }
      const bool edge = (x > 0 && !inside(x - 1, y)) || (x + 1 < w && !inside(x + 1, y)) ||
                        (y > 0 && !inside(x, y - 1)) || (y + 1 < h && !inside(x, y + 1));
      if (edge) std::copy(kOutlineColour.begin(), kOutlineColour.end(), px);
    }
}

}  // namespace

std::array<uint8_t, 3> heat_colour(double t) { return ramp(kHeatStops, t); }

double difference_heat(int difference) {
  const int d = std::clamp(difference, 0, 255);
  return std::log2(1.0 + d) / 8.0;
}

std::array<uint8_t, 3> ssim_colour(double ssim) {
  static constexpr std::array<Rgb8, 8> stops = ssim_stops();
  if (std::isnan(ssim)) return kNoSsimColour;
  return ramp(stops, std::sqrt(std::clamp(1.0 - ssim, 0.0, 1.0)));
}

Srgb8Image difference_image(const Srgb8Image& a, const Srgb8Image& b, const RegionMask* region) {
  // compare_images' checks, on the same terms (sizes, byte counts, mask size).
  (void)mse(a, b, region);
  // One colour per possible difference: the ramp is evaluated 256 times, not per pixel.
  std::array<Rgb8, 256> lut{};
  for (int d = 0; d < 256; ++d) lut[static_cast<std::size_t>(d)] = heat_colour(difference_heat(d));
  Srgb8Image out{a.width, a.height, std::vector<uint8_t>(a.rgb.size())};
  for (std::size_t i = 0; i < a.pixel_count(); ++i) {
    int largest = 0;
    for (std::size_t c = 0; c < 3; ++c)
      largest = std::max(largest, std::abs(int(a.rgb[i * 3 + c]) - int(b.rgb[i * 3 + c])));
    std::copy_n(lut[static_cast<std::size_t>(largest)].begin(), 3,
                out.rgb.begin() + static_cast<std::ptrdiff_t>(i * 3));
  }
  mark_region(out, region);
  return out;
}

Srgb8Image ssim_image(const SsimMap& map, const RegionMask* region) {
  if (map.values.size() != static_cast<std::size_t>(map.width) * static_cast<std::size_t>(map.height))
    throw InputError(fmt::format("an SSIM map of {}x{} holds {} values", map.width, map.height, map.values.size()));
  check_region(region, map.width, map.height);
  Srgb8Image out{map.width, map.height, std::vector<uint8_t>(map.values.size() * 3)};
  for (std::size_t i = 0; i < map.values.size(); ++i) {
    const Rgb8 c = ssim_colour(map.values[i]);
    std::copy_n(c.begin(), 3, out.rgb.begin() + static_cast<std::ptrdiff_t>(i * 3));
  }
  mark_region(out, region);
  return out;
}

void write_png(const std::filesystem::path& path, const Srgb8Image& image) {
  io::write_png_rgb8(path, image.rgb, image.width, image.height);
}

}  // namespace sb::validation
