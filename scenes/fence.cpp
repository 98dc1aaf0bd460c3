// `fence`: a chain-link fence in front of a yard — the fence a cut-out (glTF alphaMode MASK: a
// diamond-mesh texture whose holes are transparent), behind it crates on a tiled floor and a
// brick wall, lit by a low sun and a lamp. Through every hole the two eyes see different surfaces
// a few centimetres apart, and the wires' shadows pattern the floor: the many small disocclusions
// of foliage and fences that a reprojected right eye has to find and fill.
#include <algorithm>
#include <cmath>
#include <string>

#include "scenes/procedural.hpp"
#include "scenes/scene_generator.hpp"
#include "scenes/textures.hpp"

namespace sb::scenes {

namespace {

/// One diamond of the fence: wires along both diagonals of the tile, `wire` thick (a fraction of
/// the tile's side), opaque galvanised grey; everything else has alpha 0.
TextureImage chain_link_texture(int size, float wire) {
  TextureImage image(size, size);
  const float half = 0.5f * wire * std::sqrt(2.0f);  // half the thickness, measured along u - v
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const float u = (static_cast<float>(x) + 0.5f) / static_cast<float>(size);
      const float v = (static_cast<float>(y) + 0.5f) / static_cast<float>(size);
      // Distance, in u - v and u + v, to the nearest diagonal of this tile or its neighbours.
      const float a = std::fabs(u - v), b = std::fabs(u + v - 1.0f);
      const bool on_wire = std::min(a, 1.0f - a) < half || b < half;
      image.set(x, y, vec3(0.5f + 0.08f * std::sin(6.2831853f * (u + 2.0f * v))));
      image.rgba[(static_cast<size_t>(y) * static_cast<size_t>(size) + static_cast<size_t>(x)) * 4 + 3] =
          on_wire ? 255 : 0;
    }
  return image;
}

void build(const GeneratorContext& ctx, GltfBuilder& b) {
  const float diamond = static_cast<float>(ctx.param("mesh_cm")) / 100.0f;
  const float wire = static_cast<float>(ctx.param("wire"));
  // The textures take 32-bit seeds: one drawn from the whole 64-bit seed (a cast kept its low half,
  // so seeds 2 and 2 + 2^32 gave one scene).
  Rng rng(ctx.seed, 51);
  const auto seed = static_cast<uint32_t>(rng.next());
  const float half_pi = 0.5f * static_cast<float>(kPi);

  const int tiles = b.add_material(
      "floor", vec3(1.0f),
      add_texture(b, "floor_tiles", floor_tiles_texture(256, seed, vec3(0.42f, 0.4f, 0.37f), vec3(0.3f, 0.3f, 0.32f))));
  const int bricks = b.add_material(
      "wall", vec3(1.0f),
      add_texture(b, "bricks", stone_bricks_texture(256, seed + 1, vec3(0.55f, 0.3f, 0.22f), vec3(0.7f, 0.68f, 0.62f))));
  const int crate = b.add_material(
      "crate", vec3(1.0f), add_texture(b, "planks", wood_texture(256, seed + 2, vec3(0.62f, 0.48f, 0.3f), vec3(0.35f, 0.24f, 0.14f), 4)));
  const int post = b.add_material("post", vec3(0.35f, 0.36f, 0.38f));
  const int mesh = b.add_material("chain_link", vec3(1.0f), add_texture(b, "chain_link", chain_link_texture(64, wire)));
  b.set_alpha_mask(mesh);

  // Floor from 1 m behind the camera to the wall at z = -9 m; the wall 4 m high.
  b.add_node("floor", b.add_mesh("floor", transformed(make_plane({16.0f, 10.0f}, {8, 5}, 0.5f), translation({0, 0, -4})), tiles));
  const MeshData wall = transformed(make_plane({16.0f, 4.0f}, {8, 2}, 0.5f), translation({0, 2.0f, -9}) * rotation_x(half_pi));
  b.add_node("wall", b.add_mesh("wall", wall, bricks));
  // Crates between the fence and the wall, at several depths.
  const vec3 crates[][2] = {{{-2.4f, 0.0f, -4.6f}, {-1.4f, 1.0f, -3.6f}},
                            {{-0.6f, 0.0f, -6.2f}, {0.6f, 1.2f, -5.0f}},
                            {{1.3f, 0.0f, -4.2f}, {2.1f, 0.8f, -3.4f}},
                            {{1.5f, 0.8f, -4.1f}, {2.0f, 1.3f, -3.6f}}};
  for (size_t i = 0; i < 4; ++i)
    b.add_node("crate" + std::to_string(i), b.add_mesh("crate" + std::to_string(i), make_box(crates[i][0], crates[i][1], 1.0f), crate));

  // The fence at z = -2.5 m: 7 m wide, 2.2 m high, one diamond per texture tile, and posts every 2 m.
  const MeshData fence = transformed(make_plane({7.0f, 2.2f}, {1, 1}, 1.0f / diamond),
                                     translation({0, 1.1f, -2.5f}) * rotation_x(half_pi));
  b.add_node("fence", b.add_mesh("fence", fence, mesh));
  for (int k = -1; k <= 1; ++k) {
    const MeshData p = transformed(make_cylinder(0.03f, 2.3f, 12), translation({2.0f * static_cast<float>(k), 0.0f, -2.45f}));
    b.add_node("post" + std::to_string(k + 1), b.add_mesh("post" + std::to_string(k + 1), p, post));
  }

  // A low sun from behind the camera's left throws the wires' shadows onto the floor and crates;
  // a lamp behind the fence lights the yard.
  b.add_directional_light("sun", {0.4f, -0.55f, -0.75f}, {1.0f, 0.95f, 0.85f}, 3.0f);
  b.add_point_light("lamp", {1.5f, 3.0f, -5.0f}, vec3(1.0f, 0.9f, 0.75f), 25.0f);
  b.set_background(vec3(0.35f, 0.45f, 0.6f));
  b.set_ambient(0.05);
  set_default_view(b, {.eye = {0.0f, 1.5f, 0.5f}, .target = {0.0f, 1.1f, -2.5f}, .zfar = 100.0});
}

}  // namespace

GeneratorEntry fence_generator() {
  GeneratorInfo info;
  info.name = "fence";
  info.description = "a chain-link fence (a cut-out, glTF alphaMode MASK) before crates and a wall: many small disocclusions";
  info.file_name = "fence.glb";
  // A stress case outside the built-in set that the pipelines' tests and `scenes generate --all`
  // cover: behind a fence almost every pixel is near a disocclusion, so the grid warp's hole mask
  // covers most of the image (docs/architecture.md, "Cut-outs").
  info.builtin = false;
  info.params = {{"mesh_cm", 6.0, 1.0, 50.0, "diagonal spacing of the fence's wires (cm)"},
                 {"wire", 0.12, 0.02, 0.5, "thickness of a wire as a fraction of the spacing"}};
  return {info, build};
}

}  // namespace sb::scenes
