// Image metrics for tests: SSIM (Wang et al. 2004) on sRGB-encoded 8-bit values, the way
// psnr_srgb8 in render_support.hpp compares images.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <vector>

#include "renderer/color.hpp"
#include "renderer/image.hpp"

namespace sb::test {

/// SSIM's window: 11 x 11 Gaussian weights, sigma 1.5, normalised to sum 1 (separable).
inline constexpr int kSsimRadius = 5;
inline constexpr int kSsimWindow = 2 * kSsimRadius + 1;

/// The normalised 1-D Gaussian of the SSIM window (sigma 1.5, 11 taps).
inline std::array<double, kSsimWindow> ssim_gaussian() {
  std::array<double, kSsimWindow> g{};
  double sum = 0.0;
  for (int i = 0; i < kSsimWindow; ++i) {
    const double x = i - kSsimRadius;
    g[static_cast<size_t>(i)] = std::exp(-x * x / (2.0 * 1.5 * 1.5));
    sum += g[static_cast<size_t>(i)];
  }
  for (double& v : g) v /= sum;
  return g;
}

/// Gaussian-weighted window means of a w x h plane at every pixel whose window lies inside the
/// plane: a (w - 10) x (h - 10) result, horizontal pass then vertical pass.
inline std::vector<double> ssim_window_means(const std::vector<double>& plane, int w, int h) {
  const std::array<double, kSsimWindow> g = ssim_gaussian();
  const int vw = w - 2 * kSsimRadius, vh = h - 2 * kSsimRadius;
  std::vector<double> rows(static_cast<size_t>(vw) * static_cast<size_t>(h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < vw; ++x) {
      double s = 0.0;
      for (int k = 0; k < kSsimWindow; ++k) s += g[static_cast<size_t>(k)] * plane[static_cast<size_t>(y) * w + x + k];
      rows[static_cast<size_t>(y) * vw + x] = s;
    }
  std::vector<double> out(static_cast<size_t>(vw) * static_cast<size_t>(vh));
  for (int y = 0; y < vh; ++y)
    for (int x = 0; x < vw; ++x) {
      double s = 0.0;
      for (int k = 0; k < kSsimWindow; ++k) s += g[static_cast<size_t>(k)] * rows[static_cast<size_t>(y + k) * vw + x];
      out[static_cast<size_t>(y) * vw + x] = s;
    }
  return out;
}

/// The SSIM map of two single-channel w x h planes of 0..255 values over the valid region
/// ((w - 10) x (h - 10), the pixels whose window fits entirely): K1 = 0.01, K2 = 0.03, L = 255,
/// population (co)variances. std::invalid_argument for a plane smaller than the window.
inline std::vector<double> ssim_map(const std::vector<double>& a, const std::vector<double>& b, int w, int h) {
  if (w < kSsimWindow || h < kSsimWindow) throw std::invalid_argument("SSIM needs images of at least 11x11 pixels");
  const size_t n = static_cast<size_t>(w) * static_cast<size_t>(h);
  std::vector<double> aa(n), bb(n), ab(n);
  for (size_t i = 0; i < n; ++i) {
    aa[i] = a[i] * a[i];
    bb[i] = b[i] * b[i];
    ab[i] = a[i] * b[i];
  }
  const std::vector<double> ma = ssim_window_means(a, w, h), mb = ssim_window_means(b, w, h);
  const std::vector<double> maa = ssim_window_means(aa, w, h), mbb = ssim_window_means(bb, w, h);
  const std::vector<double> mab = ssim_window_means(ab, w, h);
  constexpr double c1 = (0.01 * 255.0) * (0.01 * 255.0), c2 = (0.03 * 255.0) * (0.03 * 255.0);
  std::vector<double> s(ma.size());
  for (size_t i = 0; i < s.size(); ++i) {
    const double va = maa[i] - ma[i] * ma[i], vb = mbb[i] - mb[i] * mb[i], cov = mab[i] - ma[i] * mb[i];
    s[i] = ((2.0 * ma[i] * mb[i] + c1) * (2.0 * cov + c2)) / ((ma[i] * ma[i] + mb[i] * mb[i] + c1) * (va + vb + c2));
  }
  return s;
}

/// Channel `c` of an image's "rgb" plane as sRGB-encoded 8-bit codes (linear_to_srgb8), as doubles.
inline std::vector<double> srgb8_channel(const Image& image, int c) {
  const float* rgb = image.data_f32(planes::rgb);
  std::vector<double> out(image.pixel_count());
  for (size_t i = 0; i < out.size(); ++i) out[i] = linear_to_srgb8(rgb[i * 3 + static_cast<size_t>(c)]);
  return out;
}

/// SSIM of the sRGB-encoded 8-bit rgb planes (Wang et al. 2004: 11 x 11 Gaussian window, sigma 1.5,
/// K1 0.01, K2 0.03, L 255, population statistics), per channel, then averaged over R, G, B: the
/// mean over the pixels whose window fits inside the image. With `mask` (one value per pixel,
/// non-zero = counted) the mean runs over the valid pixels the mask selects; NaN when it selects none.
/// std::invalid_argument for different sizes, a wrongly sized mask or an image under 11 x 11.
inline double ssim_srgb8(const Image& a, const Image& b, std::span<const uint8_t> mask = {}) {
  const int w = a.width(), h = a.height();
  if (b.width() != w || b.height() != h) throw std::invalid_argument("SSIM of images of different sizes");
  if (!mask.empty() && mask.size() != a.pixel_count()) throw std::invalid_argument("SSIM mask size differs from the image");
  double sum = 0.0;
  size_t count = 0;
  for (int c = 0; c < 3; ++c) {
    const std::vector<double> s = ssim_map(srgb8_channel(a, c), srgb8_channel(b, c), w, h);
    const int vw = w - 2 * kSsimRadius;
    for (size_t i = 0; i < s.size(); ++i) {
      const size_t x = i % static_cast<size_t>(vw) + kSsimRadius, y = i / static_cast<size_t>(vw) + kSsimRadius;
      if (!mask.empty() && mask[y * static_cast<size_t>(w) + x] == 0) continue;
      sum += s[i];
      ++count;
    }
  }
  return count == 0 ? std::numeric_limits<double>::quiet_NaN() : sum / static_cast<double>(count);
}

}  // namespace sb::test
