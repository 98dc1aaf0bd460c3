// Stereo outputs: the Dubois red-cyan anaglyph in linear light (white, black, one lit channel,
// clamping), side-by-side and over/under pixel placement, and the errors for unusable eye pairs.
#include "renderer/stereo_output.hpp"

#include <gtest/gtest.h>

#include <array>
#include <limits>
#include <string>

#include "renderer/error.hpp"
#include "renderer/image.hpp"
#include "support/input_error.hpp"

namespace sb {
namespace {

/// An eye image with an "rgb" plane where every pixel is `rgb`.
Image uniform_eye(int w, int h, const std::array<float, 3>& rgb) {
  Image image(w, h);
  image.add_plane(planes::rgb);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) image.set_rgb(x, y, rgb);
  return image;
}

/// An eye image whose pixel (x, y) encodes its position and the eye: (eye, x, y).
Image coded_eye(int w, int h, float eye) {
  Image image(w, h);
  image.add_plane(planes::rgb);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) image.set_rgb(x, y, {eye, static_cast<float>(x), static_cast<float>(y)});
  return image;
}

float clamp01(double v) { return v < 0.0 ? 0.0f : (v > 1.0 ? 1.0f : static_cast<float>(v)); }


TEST(Anaglyph, WhitePairGivesTheClampedRowSums) {
  const Image out = anaglyph_dubois(uniform_eye(3, 2, {1.0f, 1.0f, 1.0f}), uniform_eye(3, 2, {1.0f, 1.0f, 1.0f}));
  ASSERT_EQ(out.width(), 3);
  ASSERT_EQ(out.height(), 2);
  ASSERT_TRUE(out.has_plane(planes::rgb));
  EXPECT_EQ(out.planes().size(), 1u);
  for (int row = 0; row < 3; ++row) {
    double sum = 0.0;
    for (int c = 0; c < 3; ++c) sum += double{kDuboisRedCyanLeft[row][c]} + double{kDuboisRedCyanRight[row][c]};
    EXPECT_NEAR(sum, 1.0, 1e-5) << "row " << row << " of [left | right] should sum to 1";
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 3; ++x) EXPECT_FLOAT_EQ(out.rgb_at(x, y)[row], clamp01(sum)) << "channel " << row;
  }
}

TEST(Anaglyph, BlackPairGivesBlack) {
  const Image out = anaglyph_dubois(uniform_eye(4, 4, {0.0f, 0.0f, 0.0f}), uniform_eye(4, 4, {0.0f, 0.0f, 0.0f}));
  for (const float v : out.plane(planes::rgb).f32()) EXPECT_EQ(v, 0.0f);
}

TEST(Anaglyph, AppliesTheMatricesInLinearLightAndClamps) {
  // A left eye with only red and a right eye with only blue (half intensity): the output is the
  // first column of L plus half the third column of R, each channel clamped to [0, 1].
  const Image out = anaglyph_dubois(uniform_eye(2, 1, {1.0f, 0.0f, 0.0f}), uniform_eye(2, 1, {0.0f, 0.0f, 0.5f}));
  for (int row = 0; row < 3; ++row) {
    const double expected = double{kDuboisRedCyanLeft[row][0]} + 0.5 * double{kDuboisRedCyanRight[row][2]};
    EXPECT_FLOAT_EQ(out.rgb_at(1, 0)[row], clamp01(expected)) << "channel " << row;
  }
  // Left red reaches output red through L[0][0]; right blue takes away a little of it through R[0][2].
  EXPECT_NEAR(out.rgb_at(0, 0)[0], 0.4561 - 0.5 * 0.00155529, 1e-6);
  // Bright input is clamped to 1, NaN reads as 0.
  const Image bright = anaglyph_dubois(uniform_eye(1, 1, {5.0f, 5.0f, 5.0f}), uniform_eye(1, 1, {5.0f, 5.0f, 5.0f}));
  for (const float v : bright.plane(planes::rgb).f32()) EXPECT_EQ(v, 1.0f);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const Image broken = anaglyph_dubois(uniform_eye(1, 1, {nan, 0.0f, 0.0f}), uniform_eye(1, 1, {0.0f, 0.0f, 0.0f}));
  for (const float v : broken.plane(planes::rgb).f32()) EXPECT_EQ(v, 0.0f);
}

TEST(StereoLayout, SideBySidePutsTheLeftEyeOnTheLeft) {
  const int w = 5, h = 3;
  const Image out = side_by_side(coded_eye(w, h, 0.0f), coded_eye(w, h, 1.0f));
  ASSERT_EQ(out.width(), 2 * w);
  ASSERT_EQ(out.height(), h);
  EXPECT_EQ(out.planes().size(), 1u);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < 2 * w; ++x) {
      const std::array<float, 3> px = out.rgb_at(x, y);
      const bool right = x >= w;
      EXPECT_EQ(px[0], right ? 1.0f : 0.0f) << x << "," << y;
      EXPECT_EQ(px[1], static_cast<float>(right ? x - w : x)) << x << "," << y;
      EXPECT_EQ(px[2], static_cast<float>(y)) << x << "," << y;
    }
}

TEST(StereoLayout, OverUnderPutsTheLeftEyeOnTop) {
  const int w = 4, h = 3;
  const Image out = over_under(coded_eye(w, h, 0.0f), coded_eye(w, h, 1.0f));
  ASSERT_EQ(out.width(), w);
  ASSERT_EQ(out.height(), 2 * h);
  for (int y = 0; y < 2 * h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::array<float, 3> px = out.rgb_at(x, y);
      const bool right = y >= h;
      EXPECT_EQ(px[0], right ? 1.0f : 0.0f) << x << "," << y;
      EXPECT_EQ(px[1], static_cast<float>(x)) << x << "," << y;
      EXPECT_EQ(px[2], static_cast<float>(right ? y - h : y)) << x << "," << y;
    }
}

TEST(StereoLayout, EmptyEyesGiveAnEmptyImage) {
  const Image out = side_by_side(uniform_eye(0, 0, {0.0f, 0.0f, 0.0f}), uniform_eye(0, 0, {0.0f, 0.0f, 0.0f}));
  EXPECT_TRUE(out.empty());
  EXPECT_TRUE(out.has_plane(planes::rgb));
}

TEST(StereoOutputErrors, SizeMismatchNamesBothSizes) {
  const Image left = uniform_eye(4, 3, {0.5f, 0.5f, 0.5f}), right = uniform_eye(4, 2, {0.5f, 0.5f, 0.5f});
  for (const auto& [name, fn] :
       {std::pair<std::string, Image (*)(const Image&, const Image&)>{"anaglyph_dubois", &anaglyph_dubois},
        {"side_by_side", &side_by_side},
        {"over_under", &over_under}}) {
    const std::string message = test::input_error([&, f = fn] { (void)f(left, right); });
    EXPECT_NE(message.find(name), std::string::npos) << message;
    EXPECT_NE(message.find("4x3"), std::string::npos) << message;
    EXPECT_NE(message.find("4x2"), std::string::npos) << message;
  }
}

TEST(StereoOutputErrors, MissingRgbPlaneNamesTheEyeAndItsPlanes) {
  Image depth_only(4, 3);
  depth_only.add_plane(planes::depth);
  const Image good = uniform_eye(4, 3, {0.5f, 0.5f, 0.5f});
  const std::string right_missing = test::input_error([&] { (void)anaglyph_dubois(good, depth_only); });
  EXPECT_NE(right_missing.find("right eye"), std::string::npos) << right_missing;
  EXPECT_NE(right_missing.find("\"rgb\""), std::string::npos) << right_missing;
  EXPECT_NE(right_missing.find("depth"), std::string::npos) << right_missing;
  const std::string left_missing = test::input_error([&] { (void)over_under(Image(4, 3), good); });
  EXPECT_NE(left_missing.find("left eye"), std::string::npos) << left_missing;
  EXPECT_NE(left_missing.find("none"), std::string::npos) << left_missing;
}

TEST(StereoOutputErrors, CombinedSizeAboveTheLimitIsRejected) {
  const int wide = kMaxImageDimension / 2 + 1;
  const std::string message = test::input_error([&] {
    (void)side_by_side(uniform_eye(wide, 1, {0, 0, 0}), uniform_eye(wide, 1, {0, 0, 0}));
  });
  EXPECT_NE(message.find("width"), std::string::npos) << message;
}

}  // namespace
}  // namespace sb
