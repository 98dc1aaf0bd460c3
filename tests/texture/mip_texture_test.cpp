// MipTexture: box-filtered chains (even and odd sizes), texel-centre conventions, REPEAT and
// CLAMP_TO_EDGE wrapping, bilinear and trilinear lookups, and rejection of malformed textures.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>

#include "renderer/error.hpp"
#include "renderer/texture.hpp"

namespace sb {
namespace {

/// A texture whose texel (x, y) is f(x, y).
template <class F>
Texture make_texture(int w, int h, F&& f, bool repeat_s = true, bool repeat_t = true) {
  Texture t;
  t.name = "test";
  t.width = w;
  t.height = h;
  t.repeat_s = repeat_s;
  t.repeat_t = repeat_t;
  t.rgba.resize(static_cast<size_t>(w) * h * 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const vec4 c = f(x, y);
      for (int k = 0; k < 4; ++k) t.rgba[(static_cast<size_t>(y) * w + x) * 4 + k] = c[k];
    }
  return t;
}

Texture random_texture(int w, int h, uint32_t seed, bool repeat_s = true, bool repeat_t = true) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> dist(0.0f, 1.0f);
  return make_texture(
      w, h, [&](int, int) { return vec4(dist(rng), dist(rng), dist(rng), dist(rng)); }, repeat_s, repeat_t);
}

vec4 texel(const Texture& t, int x, int y) {
  const size_t i = (static_cast<size_t>(y) * t.width + x) * 4;
  return {t.rgba[i], t.rgba[i + 1], t.rgba[i + 2], t.rgba[i + 3]};
}

/// uv of the centre of texel (x, y) in a w x h level.
vec2 centre(int x, int y, int w, int h) {
  return {(static_cast<float>(x) + 0.5f) / static_cast<float>(w),
          (static_cast<float>(y) + 0.5f) / static_cast<float>(h)};
}

void expect_vec4_near(const vec4& a, const vec4& b, float tol, const char* what) {
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(a[k], b[k], tol) << what << " channel " << k;
}

/// Mean of a level, read through texel-centre lookups.
dvec4 level_mean(const MipTexture& m, int level) {
  dvec4 sum(0.0);
  const int w = m.width(level), h = m.height(level);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) sum += dvec4(m.sample_bilinear(centre(x, y, w, h), level));
  return sum / static_cast<double>(w * h);
}

TEST(MipTexture, ChainHalvesEachAxisDownToOneByOne) {
  struct Case {
    int w, h, levels, last_but_one_w, last_but_one_h;
  };
  for (const Case& c :
       {Case{8, 8, 4, 2, 2}, Case{5, 3, 3, 2, 1}, Case{7, 1, 3, 3, 1}, Case{1, 6, 3, 1, 3}, Case{640, 360, 10, 2, 1}}) {
    const MipTexture m(random_texture(c.w, c.h, 1));
    ASSERT_EQ(m.levels(), c.levels) << c.w << "x" << c.h;
    EXPECT_EQ(m.width(0), c.w);
    EXPECT_EQ(m.height(0), c.h);
    for (int l = 1; l < m.levels(); ++l) {
      EXPECT_EQ(m.width(l), std::max(1, m.width(l - 1) / 2));
      EXPECT_EQ(m.height(l), std::max(1, m.height(l - 1) / 2));
    }
    EXPECT_EQ(m.width(m.levels() - 2), c.last_but_one_w);
    EXPECT_EQ(m.height(m.levels() - 2), c.last_but_one_h);
    EXPECT_EQ(m.width(m.levels() - 1), 1);
    EXPECT_EQ(m.height(m.levels() - 1), 1);
  }
  const MipTexture single(random_texture(1, 1, 2));
  EXPECT_EQ(single.levels(), 1);
}

TEST(MipTexture, ConstantTextureIsConstantOnEveryLevel) {
  const vec4 c(0.2f, 0.45f, 0.7f, 0.9f);
  for (const ivec2 size : {ivec2(8, 8), ivec2(5, 3), ivec2(7, 9), ivec2(6, 5), ivec2(13, 1), ivec2(33, 17)}) {
    const MipTexture m(make_texture(size.x, size.y, [&](int, int) { return c; }));
    for (int l = 0; l < m.levels(); ++l)
      for (int y = 0; y < m.height(l); ++y)
        for (int x = 0; x < m.width(l); ++x)
          expect_vec4_near(m.sample_bilinear(centre(x, y, m.width(l), m.height(l)), l), c, 1e-6f, "constant");
  }
}

TEST(MipTexture, CheckerboardLevelsAverage) {
  const vec4 black(0.0f, 0.0f, 0.0f, 1.0f), white(1.0f);
  const vec4 grey(0.5f, 0.5f, 0.5f, 1.0f);
  // 2x2 checker: level 1 is the mean.
  const MipTexture two(make_texture(2, 2, [&](int x, int y) { return (x + y) % 2 ? white : black; }));
  ASSERT_EQ(two.levels(), 2);
  expect_vec4_near(two.sample_bilinear({0.5f, 0.5f}, 1), grey, 0.0f, "2x2 checker level 1");

  // 8x8 checker of 2x2-texel squares: level 1 is a one-texel checker, level 2 and 3 are grey.
  const MipTexture blocks(make_texture(8, 8, [&](int x, int y) { return (x / 2 + y / 2) % 2 ? white : black; }));
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x)
      expect_vec4_near(blocks.sample_bilinear(centre(x, y, 4, 4), 1), (x + y) % 2 ? white : black, 0.0f, "level 1");
  for (int l = 2; l < blocks.levels(); ++l)
    for (int y = 0; y < blocks.height(l); ++y)
      for (int x = 0; x < blocks.width(l); ++x)
        expect_vec4_near(blocks.sample_bilinear(centre(x, y, blocks.width(l), blocks.height(l)), l), grey, 0.0f,
                         "coarse level");
}

TEST(MipTexture, OddSizesUseTheExactFootprintBox) {
  // 3 -> 1: all three texels with weight 1/3.
  const float row3[3] = {0.0f, 0.3f, 0.9f};
  const MipTexture three(make_texture(3, 1, [&](int x, int) { return vec4(row3[x]); }));
  ASSERT_EQ(three.levels(), 2);
  EXPECT_NEAR(three.sample_bilinear({0.5f, 0.5f}, 1).x, (0.0f + 0.3f + 0.9f) / 3.0f, 1e-7f);

  // 5 -> 2: output 0 covers texels [0, 2.5), output 1 covers [2.5, 5): weights (2, 2, 1) / 5 and (1, 2, 2) / 5.
  const float row5[5] = {1.0f, 2.0f, 4.0f, 8.0f, 16.0f};
  const MipTexture five(make_texture(5, 1, [&](int x, int) { return vec4(row5[x]); }));
  ASSERT_EQ(five.width(1), 2);
  EXPECT_NEAR(five.sample_bilinear(centre(0, 0, 2, 1), 1).x, (2 * 1.0f + 2 * 2.0f + 4.0f) / 5.0f, 1e-6f);
  EXPECT_NEAR(five.sample_bilinear(centre(1, 0, 2, 1), 1).x, (4.0f + 2 * 8.0f + 2 * 16.0f) / 5.0f, 1e-6f);

  // The same weights along the vertical axis (5 rows, 1 column).
  const MipTexture five_v(make_texture(1, 5, [&](int, int y) { return vec4(row5[y]); }));
  EXPECT_NEAR(five_v.sample_bilinear(centre(0, 1, 1, 2), 1).x, (4.0f + 2 * 8.0f + 2 * 16.0f) / 5.0f, 1e-6f);

  // Every level of a random odd-sized texture keeps the mean of level 0.
  for (const ivec2 size : {ivec2(7, 5), ivec2(9, 3), ivec2(31, 17), ivec2(6, 11)}) {
    const MipTexture m(random_texture(size.x, size.y, 7));
    const dvec4 mean0 = level_mean(m, 0);
    for (int l = 1; l < m.levels(); ++l) {
      const dvec4 mean = level_mean(m, l);
      for (int k = 0; k < 4; ++k) EXPECT_NEAR(mean[k], mean0[k], 1e-6) << size.x << "x" << size.y << " level " << l;
    }
  }
}

TEST(MipTexture, BilinearAtTexelCentresReturnsTheTexel) {
  for (const ivec2 size : {ivec2(4, 3), ivec2(5, 7), ivec2(16, 16)}) {
    const Texture t = random_texture(size.x, size.y, 11);
    const MipTexture m(t);
    for (int y = 0; y < t.height; ++y)
      for (int x = 0; x < t.width; ++x)
        expect_vec4_near(m.sample_bilinear(centre(x, y, t.width, t.height), 0), texel(t, x, y), 1e-6f, "centre");
  }
}

TEST(MipTexture, UvOriginIsTheTopLeftCorner) {
  // Row 0 is the top of the image: small v reads row 0, v near 1 reads the last row.
  const MipTexture m(make_texture(
      2, 4, [](int x, int y) { return vec4(static_cast<float>(x), static_cast<float>(y), 0.0f, 1.0f); }, false, false));
  const vec4 top_left = m.sample_bilinear({0.01f, 0.01f}, 0);
  EXPECT_EQ(top_left.x, 0.0f);
  EXPECT_EQ(top_left.y, 0.0f);
  const vec4 bottom_right = m.sample_bilinear({0.99f, 0.99f}, 0);
  EXPECT_EQ(bottom_right.x, 1.0f);
  EXPECT_EQ(bottom_right.y, 3.0f);
}

TEST(MipTexture, BilinearInterpolatesBetweenCentres) {
  const Texture t = random_texture(4, 4, 3);
  const MipTexture m(t);
  // Halfway between the centres of (1, 2) and (2, 2), and the middle of a 2x2 block of centres.
  expect_vec4_near(m.sample_bilinear({0.5f, 2.5f / 4.0f}, 0), 0.5f * (texel(t, 1, 2) + texel(t, 2, 2)), 1e-6f,
                   "horizontal midpoint");
  expect_vec4_near(m.sample_bilinear({0.5f, 0.5f}, 0),
                   0.25f * (texel(t, 1, 1) + texel(t, 2, 1) + texel(t, 1, 2) + texel(t, 2, 2)), 1e-6f, "2x2 midpoint");
  // A quarter of the way: weights 3/4 and 1/4.
  expect_vec4_near(m.sample_bilinear({(1.5f + 0.25f) / 4.0f, 1.5f / 4.0f}, 0),
                   0.75f * texel(t, 1, 1) + 0.25f * texel(t, 2, 1), 1e-6f, "quarter");
}

TEST(MipTexture, RepeatWrapsAroundTheEdges) {
  const Texture t = random_texture(4, 3, 5, true, true);
  const MipTexture m(t);
  // u = 0 lies between the centres of the last and the first column.
  expect_vec4_near(m.sample_bilinear({0.0f, 0.5f / 3.0f}, 0), 0.5f * (texel(t, 3, 0) + texel(t, 0, 0)), 1e-6f, "u = 0");
  // v = 1 lies between the last and the first row.
  expect_vec4_near(m.sample_bilinear({0.5f / 4.0f, 1.0f}, 0), 0.5f * (texel(t, 0, 2) + texel(t, 0, 0)), 1e-6f, "v = 1");
  // Whole periods (positive, negative, large) do not change the result.
  for (const vec2 shift : {vec2(1.0f, 0.0f), vec2(-3.0f, 2.0f), vec2(1000.0f, -1000.0f)}) {
    const vec2 uv(0.375f, 0.625f);  // exactly representable, also after the shifts
    expect_vec4_near(m.sample_bilinear(uv + shift, 0), m.sample_bilinear(uv, 0), 1e-6f, "period");
  }
}

TEST(MipTexture, ClampToEdgeReadsTheEdgeTexel) {
  const Texture t = random_texture(4, 3, 9, false, false);
  const MipTexture m(t);
  expect_vec4_near(m.sample_bilinear({0.0f, 0.0f}, 0), texel(t, 0, 0), 1e-6f, "corner (0, 0)");
  expect_vec4_near(m.sample_bilinear({1.0f, 1.0f}, 0), texel(t, 3, 2), 1e-6f, "corner (1, 1)");
  expect_vec4_near(m.sample_bilinear({-5.0f, 0.5f / 3.0f}, 0), texel(t, 0, 0), 1e-6f, "far left");
  expect_vec4_near(m.sample_bilinear({7.0f, 2.5f / 3.0f}, 0), texel(t, 3, 2), 1e-6f, "far right");

  // Mixed: REPEAT along s, CLAMP_TO_EDGE along t.
  const Texture mixed_t = random_texture(4, 3, 9, true, false);
  const MipTexture mixed(mixed_t);
  expect_vec4_near(mixed.sample_bilinear({0.0f, -2.0f}, 0), 0.5f * (texel(mixed_t, 3, 0) + texel(mixed_t, 0, 0)), 1e-6f,
                   "repeat s, clamp t");
}

TEST(MipTexture, NonFiniteCoordinatesReadAsZero) {
  const MipTexture m(random_texture(4, 4, 13));
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  expect_vec4_near(m.sample_bilinear({nan, inf}, 0), m.sample_bilinear({0.0f, 0.0f}, 0), 0.0f, "nan/inf");
}

TEST(MipTexture, TrilinearBlendsNeighbouringLevels) {
  const MipTexture m(random_texture(16, 8, 17));
  const vec2 uv(0.37f, 0.61f);
  for (int l = 0; l + 1 < m.levels(); ++l) {
    const vec4 a = m.sample_bilinear(uv, l), b = m.sample_bilinear(uv, l + 1);
    expect_vec4_near(m.sample_trilinear(uv, static_cast<float>(l)), a, 0.0f, "integer lod");
    expect_vec4_near(m.sample_trilinear(uv, static_cast<float>(l) + 0.5f), 0.5f * (a + b), 1e-6f, "halfway");
    expect_vec4_near(m.sample_trilinear(uv, static_cast<float>(l) + 0.25f), 0.75f * a + 0.25f * b, 1e-6f, "quarter");
  }
  // Clamping to [0, levels - 1]; -inf (zero footprint) and NaN read level 0.
  const int last = m.levels() - 1;
  expect_vec4_near(m.sample_trilinear(uv, -3.0f), m.sample_bilinear(uv, 0), 0.0f, "below 0");
  expect_vec4_near(m.sample_trilinear(uv, -std::numeric_limits<float>::infinity()), m.sample_bilinear(uv, 0), 0.0f,
                   "-inf");
  expect_vec4_near(m.sample_trilinear(uv, std::numeric_limits<float>::quiet_NaN()), m.sample_bilinear(uv, 0), 0.0f,
                   "NaN");
  expect_vec4_near(m.sample_trilinear(uv, 100.0f), m.sample_bilinear(uv, last), 0.0f, "above last");
  expect_vec4_near(m.sample_trilinear(uv, std::numeric_limits<float>::infinity()), m.sample_bilinear(uv, last), 0.0f,
                   "+inf");
}

TEST(MipTexture, RejectsMalformedTexturesAndLevels) {
  Texture empty;
  empty.name = "empty";
  EXPECT_THROW({ const MipTexture m(empty); }, InputError);

  Texture short_data = random_texture(4, 4, 1);
  short_data.name = "short";
  short_data.rgba.pop_back();
  try {
    const MipTexture m(short_data);
    ADD_FAILURE() << "no error for a truncated rgba array";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("short"), std::string::npos) << e.what();
  }

  const MipTexture m(random_texture(4, 4, 1));
  EXPECT_THROW((void)m.width(m.levels()), InputError);
  EXPECT_THROW((void)m.height(-1), InputError);
  EXPECT_THROW((void)m.sample_bilinear({0.5f, 0.5f}, 3), InputError);
}

}  // namespace
}  // namespace sb
