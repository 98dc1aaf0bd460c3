// SSIM for tests: the suite's own metric (validation/metrics.hpp) on the sRGB-encoded 8-bit rgb
// planes, the way psnr_srgb8 in render_support.hpp compares images.
#pragma once

#include <cmath>

#include "renderer/image.hpp"
#include "validation/metrics.hpp"

namespace sb::test {

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
