// SSIM for tests: the suite's own metric (validation/metrics.hpp) on the sRGB-encoded 8-bit rgb
// planes, the way psnr_srgb8 in render_support.hpp compares images.
#pragma once

#include "renderer/image.hpp"
#include "validation/metrics.hpp"

namespace sb::test {

/// SSIM (DESIGN §6.2: Wang et al. 2004, as validation::ssim_map) of the rgb planes encoded with
/// validation::encode_srgb8: the mean over the pixels at least 5 pixels from the border; NaN for
/// images under 11 x 11. InputError for different sizes or NaN samples.
inline double ssim_srgb8(const Image& a, const Image& b) {
  return validation::ssim_map(validation::encode_srgb8(a, "image A"), validation::encode_srgb8(b, "image B")).mean;
}

}  // namespace sb::test
