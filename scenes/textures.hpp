// Procedural, tileable base colour textures for the generated scenes (stone, tiles, cloth, wood,
// checkers), computed in linear colour and stored as RGBA8 sRGB.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "renderer/math.hpp"

namespace sb::scenes {

class GltfBuilder;

/// An RGBA8 sRGB image, row 0 at the top.
struct TextureImage {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgba;

  TextureImage(int w, int h) : width(w), height(h), rgba(static_cast<size_t>(w) * static_cast<size_t>(h) * 4, 255) {}
  /// Stores a linear colour (clamped to [0, 1]) at (x, y), opaque.
  void set(int x, int y, const vec3& linear);
};

/// Running-bond stone bricks with mortar joints, per-brick tone and worn edges.
/// `bricks_x` x `rows` bricks per tile.
[[nodiscard]] TextureImage stone_bricks_texture(int size, uint32_t seed, const vec3& stone, const vec3& mortar,
                                                int bricks_x = 4, int rows = 8);
/// Square floor slabs in two alternating marble tones with grout; `tiles` per side.
[[nodiscard]] TextureImage floor_tiles_texture(int size, uint32_t seed, const vec3& tone_a, const vec3& tone_b,
                                               int tiles = 4);
/// Woven cloth: `style` 0 = stripes with borders, 1 = diamonds, 2 = roundels; the weave shows as
/// a fine cross-hatch.
[[nodiscard]] TextureImage cloth_texture(int size, uint32_t seed, const vec3& ground, const vec3& pattern, int style);
/// Wood planks (rows of boards with staggered ends and grain), or plain grain when planks = 0.
[[nodiscard]] TextureImage wood_texture(int size, uint32_t seed, const vec3& light, const vec3& dark, int planks);
/// Mottled plain stone or plaster.
[[nodiscard]] TextureImage stone_texture(int size, uint32_t seed, const vec3& tone, float variation);
/// A checkerboard of `checks` x `checks` squares.
[[nodiscard]] TextureImage checker_texture(int size, int checks, const vec3& a, const vec3& b);

/// Adds the image to the builder as a texture (see GltfBuilder::add_texture).
int add_texture(GltfBuilder& builder, const std::string& name, const TextureImage& image);

}  // namespace sb::scenes
