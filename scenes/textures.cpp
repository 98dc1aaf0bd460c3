// Procedural tileable textures for the generated scenes.
#include "scenes/textures.hpp"

#include <algorithm>
#include <cmath>

#include "scenes/gltf_builder.hpp"
#include "scenes/procedural.hpp"

namespace sb::scenes {

namespace {

/// Tileable fbm at texel (x, y) of a size-`size` texture with `cells` noise cells per tile.
float tile_fbm(int x, int y, int size, int cells, uint32_t seed, int octaves, float z = 0.0f) {
  const float s = static_cast<float>(cells) / static_cast<float>(size);
  return fbm(vec3((static_cast<float>(x) + 0.5f) * s, (static_cast<float>(y) + 0.5f) * s, z), seed, octaves, cells);
}

/// Random value in [0, 1) for an integer cell.
float cell_random(int a, int b, uint32_t seed) { return static_cast<float>(hash3(a, b, 7, seed)) * 0x1.0p-32f; }

}  // namespace

void TextureImage::set(int x, int y, const vec3& linear) {
  const size_t i = (static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)) * 4;
  rgba[i + 0] = linear_to_srgb8(linear.x);
  rgba[i + 1] = linear_to_srgb8(linear.y);
  rgba[i + 2] = linear_to_srgb8(linear.z);
  rgba[i + 3] = 255;
}

TextureImage stone_bricks_texture(int size, uint32_t seed, const vec3& stone, const vec3& mortar, int bricks_x,
                                  int rows) {
  TextureImage img(size, size);
  const float bw = static_cast<float>(size) / static_cast<float>(bricks_x);
  const float bh = static_cast<float>(size) / static_cast<float>(rows);
  const float joint = std::max(1.5f, 0.06f * bh);
  for (int y = 0; y < size; ++y) {
    const float fy = static_cast<float>(y) + 0.5f;
    const int row = static_cast<int>(fy / bh);
    const float ly = fy - static_cast<float>(row) * bh;
    const float shift = (row % 2) * 0.5f * bw;
    for (int x = 0; x < size; ++x) {
      float fx = static_cast<float>(x) + 0.5f + shift;
      if (fx >= static_cast<float>(size)) fx -= static_cast<float>(size);
      const int col = static_cast<int>(fx / bw);
      const float lx = fx - static_cast<float>(col) * bw;
      // Distance to the nearest joint, roughened so that edges look worn.
      const float rough = 0.8f * joint * tile_fbm(x, y, size, 32, seed + 11u, 3);
      const float d = std::min(std::min(lx, bw - lx), std::min(ly, bh - ly)) + rough;
      const float grain = tile_fbm(x, y, size, 16, seed, 5);
      const float tone = 0.82f + 0.36f * cell_random(col % bricks_x, row, seed);
      const vec3 hue_shift(1.0f + 0.08f * (cell_random(row, col % bricks_x, seed + 3u) - 0.5f), 1.0f,
                           1.0f - 0.08f * (cell_random(row, col % bricks_x, seed + 5u) - 0.5f));
      vec3 c = stone * tone * hue_shift * (1.0f + 0.22f * grain);
      c *= 1.0f - 0.25f * (1.0f - smooth(0.0f, 2.5f * joint, d));  // darker, worn rims
      const vec3 m = mortar * (1.0f + 0.15f * tile_fbm(x, y, size, 64, seed + 9u, 2));
      img.set(x, y, glm::mix(m, c, smooth(0.5f * joint, joint, d)));
    }
  }
  return img;
}

TextureImage floor_tiles_texture(int size, uint32_t seed, const vec3& tone_a, const vec3& tone_b, int tiles) {
  TextureImage img(size, size);
  const float ts = static_cast<float>(size) / static_cast<float>(tiles);
  const float grout = std::max(1.0f, 0.025f * ts);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const float fx = static_cast<float>(x) + 0.5f, fy = static_cast<float>(y) + 0.5f;
      const int tx = static_cast<int>(fx / ts), ty = static_cast<int>(fy / ts);
      const float lx = fx - static_cast<float>(tx) * ts, ly = fy - static_cast<float>(ty) * ts;
      const float d = std::min(std::min(lx, ts - lx), std::min(ly, ts - ly));
      const vec3 base = (tx + ty) % 2 == 0 ? tone_a : tone_b;
      // Marble veins: a sine of a turbulent coordinate.
      const float turb = tile_fbm(x, y, size, 8, seed + static_cast<uint32_t>(tx * 7 + ty * 13), 5);
      const float vein = std::pow(std::fabs(std::sin((fx + fy) / ts * 3.0f + 6.0f * turb)), 0.25f);
      const float tone = 0.9f + 0.2f * cell_random(tx, ty, seed);
      vec3 c = base * tone * (0.78f + 0.22f * vein);
      c *= 1.0f + 0.08f * tile_fbm(x, y, size, 32, seed + 1u, 3);
      img.set(x, y, glm::mix(vec3(0.12f, 0.11f, 0.10f), c, smooth(0.4f * grout, grout, d)));
    }
  return img;
}

TextureImage cloth_texture(int size, uint32_t seed, const vec3& ground, const vec3& pattern, int style) {
  TextureImage img(size, size);
  const float s = static_cast<float>(size);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const float u = (static_cast<float>(x) + 0.5f) / s, v = (static_cast<float>(y) + 0.5f) / s;
      float w = 0.0f;  // pattern weight
      if (style == 0) {
        // Broad stripes with thin pin stripes either side.
        const float band = std::fabs(std::fmod(u * 4.0f, 1.0f) - 0.5f);
        w = std::max(smooth(0.16f, 0.13f, band), smooth(0.03f, 0.0f, std::fabs(band - 0.24f)));
      } else if (style == 1) {
        // Diamonds (a rotated checker) with an outline.
        const float a = std::fabs(std::fmod(u * 4.0f, 1.0f) - 0.5f) + std::fabs(std::fmod(v * 4.0f, 1.0f) - 0.5f);
        w = std::max(smooth(0.36f, 0.33f, a), smooth(0.04f, 0.0f, std::fabs(a - 0.45f)));
      } else {
        // Roundels on a lattice, alternating rings and discs.
        const float cu = std::fmod(u * 3.0f, 1.0f) - 0.5f, cv = std::fmod(v * 3.0f, 1.0f) - 0.5f;
        const float r = std::sqrt(cu * cu + cv * cv);
        w = std::max(smooth(0.2f, 0.17f, r), smooth(0.04f, 0.0f, std::fabs(r - 0.32f)));
      }
      // Weave: alternating warp and weft threads.
      const float warp = 0.5f + 0.5f * std::sin(static_cast<float>(kPi) * static_cast<float>(x));
      const float weft = 0.5f + 0.5f * std::sin(static_cast<float>(kPi) * static_cast<float>(y));
      const float weave = 0.9f + 0.1f * ((x / 2 + y / 2) % 2 == 0 ? warp : weft);
      const float dirt = 1.0f + 0.1f * tile_fbm(x, y, size, 8, seed, 4);
      img.set(x, y, glm::mix(ground, pattern, w) * weave * dirt);
    }
  return img;
}

TextureImage wood_texture(int size, uint32_t seed, const vec3& light, const vec3& dark, int planks) {
  TextureImage img(size, size);
  const int rows = std::max(1, planks);
  const float ph = static_cast<float>(size) / static_cast<float>(rows);
  for (int y = 0; y < size; ++y) {
    const float fy = static_cast<float>(y) + 0.5f;
    const int row = static_cast<int>(fy / ph);
    const float ly = fy - static_cast<float>(row) * ph;
    // Board ends: each row is cut at one staggered place per tile.
    const float cut = cell_random(row, 0, seed) * static_cast<float>(size);
    for (int x = 0; x < size; ++x) {
      const float fx = static_cast<float>(x) + 0.5f;
      const int board = planks > 0 && fx >= cut ? 1 : 0;
      const float turb = tile_fbm(x, y, size, 4, seed + static_cast<uint32_t>(row * 31 + board), 4);
      // Grain: stretched rings along x.
      const float rings = std::sin((ly / ph * 6.0f + 2.5f * turb + cell_random(row, board, seed + 2u) * 10.0f) *
                                   static_cast<float>(kPi));
      const float fine = tile_fbm(x, y * 8, size, 16, seed + 5u, 2);
      const float t = std::clamp(0.5f + 0.35f * rings + 0.15f * fine, 0.0f, 1.0f);
      vec3 c = glm::mix(dark, light, t) * (0.88f + 0.24f * cell_random(row, board, seed + 1u));
      if (planks > 0) {
        const float edge = std::min(ly, ph - ly);
        // Joints at the cut and at the tile edge (two boards per row keep the tile seamless).
        const float end = std::min(std::fabs(fx - cut), std::min(fx, static_cast<float>(size) - fx));
        c *= 0.35f + 0.65f * smooth(0.0f, 1.5f, std::min(edge, end));
      }
      img.set(x, y, c);
    }
  }
  return img;
}

TextureImage stone_texture(int size, uint32_t seed, const vec3& tone, float variation) {
  TextureImage img(size, size);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const float n = tile_fbm(x, y, size, 8, seed, 6);
      const float spots = tile_fbm(x, y, size, 32, seed + 3u, 2);
      img.set(x, y, tone * (1.0f + variation * n) * (1.0f - 0.3f * variation * smooth(0.3f, 0.6f, spots)));
    }
  return img;
}

TextureImage checker_texture(int size, int checks, const vec3& a, const vec3& b) {
  TextureImage img(size, size);
  const int cell = std::max(1, size / checks);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) img.set(x, y, ((x / cell) + (y / cell)) % 2 == 0 ? a : b);
  return img;
}

int add_texture(GltfBuilder& builder, const std::string& name, const TextureImage& image) {
  return builder.add_texture(name, image.width, image.height, image.rgba);
}

}  // namespace sb::scenes
