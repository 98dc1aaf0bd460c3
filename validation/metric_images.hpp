// Pictures of the metrics (DESIGN §6.2): a difference heat map and an SSIM map, as 8-bit sRGB
// images on fixed scales (the same colour means the same error in every picture), and PNG output.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>

#include "validation/metrics.hpp"

namespace sb::validation {

/// The colour of a heat value t in [0, 1] (clamped; NaN gives 0) on the heat ramp: black, deep
/// violet, magenta, red, orange, yellow, pale yellow. Perceptually ordered: the lightness rises
/// monotonically with t, so the ramp reads correctly in grey too.
[[nodiscard]] std::array<uint8_t, 3> heat_colour(double t);

/// The fixed scale of the difference heat map: t = log2(1 + d) / 8 for a largest channel
/// difference of d codes, so 0 is black, 1 code 0.125, 2 codes 0.198, 15 codes 0.5 and 255 codes
/// 1. A logarithmic scale shows one-code rounding differences and whole wrong pixels in one
/// picture.
[[nodiscard]] double difference_heat(int difference);

/// Colour of pixels on the region's outline in both pictures (cyan: not on either ramp).
inline constexpr std::array<uint8_t, 3> kOutlineColour{0, 255, 255};

/// Difference heat map: each pixel's largest channel difference |a - b| (8-bit codes) through
/// difference_heat and heat_colour. With a region, pixels outside it are dimmed to a third and
/// the region's outline (inside pixels with a 4-neighbour outside) is drawn in kOutlineColour.
/// InputError as for compare_images.
[[nodiscard]] Srgb8Image difference_image(const Srgb8Image& a, const Srgb8Image& b, const RegionMask* region = nullptr);

/// The fixed scale of the SSIM map image: t = sqrt(clamp(1 - s, 0, 1)), so SSIM 1 is white,
/// 0.99 gives 0.1, 0.9 gives 0.32, 0.75 gives 0.5 and 0 or below gives 1 (black); the ramp runs
/// from white through the heat ramp's colours backwards (pale yellow, yellow, orange, red, magenta,
/// violet) to black, so that light means good and dark means bad.
[[nodiscard]] std::array<uint8_t, 3> ssim_colour(double ssim);

/// Colour of pixels without an SSIM value (the 5-pixel border, tiny images): mid grey.
inline constexpr std::array<uint8_t, 3> kNoSsimColour{128, 128, 128};

/// SSIM map image: ssim_colour per pixel, kNoSsimColour where the map is NaN; with a region,
/// pixels outside it dimmed to a third and its outline drawn as in difference_image. InputError
/// for a region of another size.
[[nodiscard]] Srgb8Image ssim_image(const SsimMap& map, const RegionMask* region = nullptr);

/// Writes an 8-bit sRGB image as a PNG, atomically (io::write_png_rgb8). IoError if it cannot be
/// written, InputError for an empty or misshapen image.
void write_png(const std::filesystem::path& path, const Srgb8Image& image);

}  // namespace sb::validation
