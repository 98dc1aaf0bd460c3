// The test SSIM of support/image_metrics.hpp: exact on identical and flat images, lowered by
// noise, symmetric, equal to a direct 11x11 window sum, and restricted by a mask.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "renderer/color.hpp"
#include "support/image_metrics.hpp"

namespace sb {
namespace {

/// An image whose pixels carry 8-bit sRGB codes from `code(x, y, channel)`.
template <class F>
Image image_of_codes(int w, int h, F&& code) {
  Image image(w, h);
  image.add_plane(planes::rgb);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      image.set_rgb(x, y, {srgb8_to_linear(code(x, y, 0)), srgb8_to_linear(code(x, y, 1)), srgb8_to_linear(code(x, y, 2))});
  return image;
}

/// A deterministic pseudo-random code in 0..255 per (x, y, c, seed).
uint8_t hashed_code(int x, int y, int c, uint32_t seed) {
  uint32_t h = static_cast<uint32_t>(x) * 73856093u ^ static_cast<uint32_t>(y) * 19349663u ^
               static_cast<uint32_t>(c) * 83492791u ^ seed * 2654435761u;
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  h ^= h >> 15;
  return static_cast<uint8_t>(h & 0xFFu);
}

/// A smooth test pattern with some structure in every channel.
uint8_t pattern(int x, int y, int c) {
  return static_cast<uint8_t>(std::lround(127.5 + 100.0 * std::sin(0.21 * x + 0.7 * c) * std::cos(0.13 * y)));
}

TEST(Ssim, IdenticalImagesGiveOne) {
  const Image a = image_of_codes(64, 48, pattern);
  EXPECT_DOUBLE_EQ(test::ssim_srgb8(a, a), 1.0);
}

TEST(Ssim, FlatImagesGiveTheLuminanceTerm) {
  // Flat images have no variance: SSIM = (2 m1 m2 + C1) / (m1^2 + m2^2 + C1).
  const Image a = image_of_codes(32, 32, [](int, int, int) { return uint8_t{100}; });
  const Image b = image_of_codes(32, 32, [](int, int, int) { return uint8_t{110}; });
  const double c1 = (0.01 * 255) * (0.01 * 255);
  EXPECT_NEAR(test::ssim_srgb8(a, b), (2.0 * 100 * 110 + c1) / (100.0 * 100 + 110.0 * 110 + c1), 1e-12);
}

TEST(Ssim, NoiseLowersItAndItIsSymmetric) {
  const Image a = image_of_codes(96, 64, pattern);
  const Image b = image_of_codes(96, 64, [](int x, int y, int c) {
    return static_cast<uint8_t>(std::clamp(int(pattern(x, y, c)) + int(hashed_code(x, y, c, 7) % 17) - 8, 0, 255));
  });
  const double s = test::ssim_srgb8(a, b);
  EXPECT_LT(s, 0.99);
  EXPECT_GT(s, 0.5);
  EXPECT_EQ(s, test::ssim_srgb8(b, a));
}

TEST(Ssim, SeparableFilterEqualsADirectWindowSum) {
  const int w = 23, h = 19;
  std::vector<double> a(size_t(w) * h), b(a.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      a[size_t(y) * w + x] = hashed_code(x, y, 0, 1);
      b[size_t(y) * w + x] = hashed_code(x, y, 0, 2) / 4 + a[size_t(y) * w + x] / 2;
    }
  const std::vector<double> map = test::ssim_map(a, b, w, h);
  const auto g = test::ssim_gaussian();
  const double c1 = (0.01 * 255) * (0.01 * 255), c2 = (0.03 * 255) * (0.03 * 255);
  ASSERT_EQ(map.size(), size_t(w - 10) * (h - 10));
  for (int y = 5; y < h - 5; ++y)
    for (int x = 5; x < w - 5; ++x) {
      double ma = 0, mb = 0, maa = 0, mbb = 0, mab = 0;
      for (int dy = -5; dy <= 5; ++dy)
        for (int dx = -5; dx <= 5; ++dx) {
          const double wt = g[size_t(dx + 5)] * g[size_t(dy + 5)];
          const double va = a[size_t(y + dy) * w + x + dx], vb = b[size_t(y + dy) * w + x + dx];
          ma += wt * va, mb += wt * vb, maa += wt * va * va, mbb += wt * vb * vb, mab += wt * va * vb;
        }
      const double expected = ((2 * ma * mb + c1) * (2 * (mab - ma * mb) + c2)) /
                              ((ma * ma + mb * mb + c1) * (maa - ma * ma + mbb - mb * mb + c2));
      EXPECT_NEAR(map[size_t(y - 5) * (w - 10) + (x - 5)], expected, 1e-9) << x << ", " << y;
    }
}

TEST(Ssim, MaskSelectsTheRegion) {
  // Perturb columns < 10 only; windows centred at x >= 15 never reach them.
  const Image a = image_of_codes(64, 32, pattern);
  const Image b = image_of_codes(64, 32, [](int x, int y, int c) {
    return x < 10 ? static_cast<uint8_t>(255 - pattern(x, y, c)) : pattern(x, y, c);
  });
  std::vector<uint8_t> right_part(a.pixel_count(), 0), left_part(a.pixel_count(), 0);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) (x >= 15 ? right_part : left_part)[size_t(y) * 64 + x] = 1;
  EXPECT_DOUBLE_EQ(test::ssim_srgb8(a, b, right_part), 1.0);
  EXPECT_LT(test::ssim_srgb8(a, b, left_part), 0.9);
  EXPECT_TRUE(std::isnan(test::ssim_srgb8(a, b, std::vector<uint8_t>(a.pixel_count(), 0))));
  EXPECT_THROW((void)test::ssim_srgb8(a, b, std::vector<uint8_t>(3, 1)), std::invalid_argument);
}

}  // namespace
}  // namespace sb
