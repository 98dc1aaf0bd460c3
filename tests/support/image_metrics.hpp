// PSNR and SSIM for tests: the suite's own metrics (validation/metrics.hpp) on the sRGB-encoded
// 8-bit rgb planes. They need the validation layer, which the library rooms (tests/CMakeLists.txt:
// SB_LIBRARY_ROOMS) do not link.
#pragma once

#include <cmath>

#include "renderer/image.hpp"
#include "validation/metrics.hpp"

namespace sb::test {

/// PSNR of the sRGB-encoded 8-bit rgb planes (validation::encode_srgb8, mse and psnr_from_mse):
/// infinity for identical images.
inline double psnr_srgb8(const Image& a, const Image& b) {
  return validation::psnr_from_mse(
      validation::mse(validation::encode_srgb8(a, "image A"), validation::encode_srgb8(b, "image B")));
}

/// SSIM (DESIGN §6.2: Wang et al. 2004, as validation::ssim_map) of the rgb planes encoded with
/// validation::encode_srgb8: the mean over the pixels at least 5 pixels from the border; NaN for
/// images under 11 x 11. InputError for different sizes or NaN samples.
inline double ssim_srgb8(const Image& a, const Image& b) {
  return validation::ssim_map(validation::encode_srgb8(a, "image A"), validation::encode_srgb8(b, "image B")).mean;
}

/// The MSE (8-bit codes) that validation::psnr_from_mse turns into `psnr` (0 for an infinite one):
/// for records whose PSNR and MSE must agree, as a measured one's do.
inline double mse_of_psnr(double psnr) { return std::isinf(psnr) ? 0.0 : 255.0 * 255.0 / std::pow(10.0, psnr / 10.0); }

}  // namespace sb::test
