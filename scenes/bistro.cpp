// `bistro`: a dense café interior with high depth complexity — tall windows letting in the sun,
// a bar counter with stools, back shelves full of bottles and glasses, round tables with bentwood
// chairs, potted plants and pendant lamps (13 point lights); it stands in for Bistro Interior.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "scenes/architecture.hpp"
#include "scenes/procedural.hpp"
#include "scenes/scene_generator.hpp"
#include "scenes/textures.hpp"

namespace sb::scenes {

namespace {

constexpr float kPiF = static_cast<float>(kPi);

// The room: x in [kX0, kX1], z in [kZ0, kZ1], floor at 0, ceiling at kHeight; walls kWall thick.
constexpr float kX0 = -6.0f, kX1 = 6.0f, kZ0 = -9.0f, kZ1 = 5.0f, kHeight = 3.4f, kWall = 0.25f;
// Windows in the wall x = kX1.
constexpr int kWindows = 4;
constexpr float kWindowWidth = 1.8f, kSill = 0.8f, kHead = 2.9f;
float window_z(int i) { return -7.0f + 3.3f * static_cast<float>(i); }
// The bar: counter front at z = kBarFront, back shelves against the wall z = kZ0.
constexpr float kBarX0 = -3.5f, kBarX1 = 3.0f, kBarFront = -6.2f, kBarBack = -6.9f, kBarTop = 1.12f;

/// Profiles (radius, y) of turned objects, walked with the outside on the right.
const std::vector<std::vector<vec2>>& bottle_profiles() {
  static const std::vector<std::vector<vec2>> p = {
      // wine
      {{0, 0}, {0.037f, 0}, {0.038f, 0.005f}, {0.038f, 0.2f}, {0.034f, 0.225f}, {0.02f, 0.25f}, {0.014f, 0.27f},
       {0.014f, 0.31f}, {0.016f, 0.315f}, {0.016f, 0.325f}, {0, 0.325f}},
      // squat liquor
      {{0, 0}, {0.045f, 0}, {0.046f, 0.01f}, {0.046f, 0.15f}, {0.04f, 0.17f}, {0.016f, 0.19f}, {0.014f, 0.24f},
       {0.016f, 0.245f}, {0.016f, 0.26f}, {0, 0.26f}},
      // long neck
      {{0, 0}, {0.03f, 0}, {0.031f, 0.005f}, {0.031f, 0.16f}, {0.02f, 0.2f}, {0.012f, 0.24f}, {0.011f, 0.29f},
       {0.013f, 0.3f}, {0, 0.3f}},
      // decanter
      {{0, 0}, {0.05f, 0}, {0.055f, 0.02f}, {0.06f, 0.08f}, {0.05f, 0.14f}, {0.02f, 0.17f}, {0.018f, 0.21f},
       {0.024f, 0.22f}, {0, 0.22f}},
  };
  return p;
}

MeshData make_wine_glass() {
  return make_lathe({{0, 0},          {0.035f, 0},     {0.035f, 0.004f}, {0.006f, 0.012f}, {0.005f, 0.09f},
                     {0.02f, 0.105f}, {0.038f, 0.14f}, {0.036f, 0.19f},  {0.034f, 0.19f},  {0.036f, 0.14f},
                     {0.018f, 0.112f}, {0, 0.106f}},
                    48, 50.0f, 1.0f);
}

MeshData make_tumbler() {
  return make_lathe({{0, 0}, {0.035f, 0}, {0.04f, 0.1f}, {0.037f, 0.1f}, {0.032f, 0.012f}, {0, 0.012f}}, 48, 50.0f, 1.0f);
}

/// A bentwood bistro chair facing +Z: turned seat, four splayed legs with a ring, a bent hoop back.
MeshData make_chair() {
  MeshData m;
  append_mesh(m, make_lathe({{0, 0.43f}, {0.2f, 0.43f}, {0.212f, 0.445f}, {0.212f, 0.465f}, {0.2f, 0.48f}, {0, 0.482f}}, 40, 40.0f, 1.0f));
  append_mesh(m, make_torus(0.19f, 0.016f, 40, 8), translation({0.0f, 0.425f, 0.0f}));
  for (int k = 0; k < 4; ++k) {
    const float a = 0.25f * kPiF + 0.5f * kPiF * static_cast<float>(k);
    const vec3 d(std::sin(a), 0.0f, std::cos(a));
    std::vector<vec3> path;
    for (int i = 0; i <= 8; ++i) {
      const float t = static_cast<float>(i) / 8.0f;
      path.push_back(d * (0.16f + 0.07f * t + 0.02f * std::sin(kPiF * t)) + vec3(0.0f, 0.43f * (1.0f - t), 0.0f));
    }
    append_mesh(m, make_tube(path, std::vector<float>(path.size(), 0.014f), 12, true));
  }
  append_mesh(m, make_torus(0.2f, 0.01f, 40, 6), translation({0.0f, 0.2f, 0.0f}));
  // Back: the outer hoop continues the rear legs; an inner oval loop sits inside it.
  const std::vector<vec3> hoop = catmull_rom({{-0.15f, 0.44f, -0.13f}, {-0.17f, 0.62f, -0.2f}, {-0.16f, 0.82f, -0.23f},
                                              {0.0f, 0.93f, -0.24f}, {0.16f, 0.82f, -0.23f}, {0.17f, 0.62f, -0.2f},
                                              {0.15f, 0.44f, -0.13f}},
                                             12);
  append_mesh(m, make_tube(hoop, std::vector<float>(hoop.size(), 0.015f), 12, true));
  std::vector<vec3> loop;
  for (int i = 0; i <= 40; ++i) {
    const float a = 2.0f * kPiF * static_cast<float>(i) / 40.0f;
    loop.push_back({0.09f * std::sin(a), 0.7f + 0.1f * std::cos(a), -0.215f - 0.01f * std::cos(a)});
  }
  // Capped: the loop's two ends meet only to rounding (and at different tilts), and the chair is
  // then a closed solid, which lets Kim's redirection cull its back faces (culled_meshes).
  append_mesh(m, make_tube(loop, std::vector<float>(loop.size(), 0.009f), 8, true));
  m.uvs.clear();
  return m;
}

/// A pendant lamp: cord from the ceiling and an enamelled shade whose mouth is at y = 0 (local).
MeshData make_lamp_shade() {
  return make_lathe({{0, 0.25f}, {0.045f, 0.24f}, {0.065f, 0.21f}, {0.14f, 0.095f}, {0.21f, 0.0f}, {0.225f, 0.0f},
                     {0.15f, 0.105f}, {0.07f, 0.225f}, {0.05f, 0.26f}, {0, 0.27f}},
                    40, 40.0f, 1.0f);
}

void build(const GeneratorContext& ctx, GltfBuilder& b) {
  Rng rng(ctx.seed, 31);
  const auto tex_seed = static_cast<uint32_t>(rng.next());

  // Textures and materials.
  const int floor_tex = add_texture(b, "floor_tiles", floor_tiles_texture(512, tex_seed, {0.62f, 0.6f, 0.56f}, {0.07f, 0.07f, 0.07f}, 8));
  const int planks_tex = add_texture(b, "wood_planks", wood_texture(512, tex_seed + 1u, {0.36f, 0.2f, 0.09f}, {0.14f, 0.07f, 0.03f}, 6));
  const int grain_tex = add_texture(b, "wood_grain", wood_texture(256, tex_seed + 2u, {0.42f, 0.26f, 0.12f}, {0.2f, 0.1f, 0.04f}, 0));
  const int plaster_tex = add_texture(b, "plaster", stone_texture(256, tex_seed + 3u, {0.62f, 0.52f, 0.38f}, 0.08f));
  const int marble_tex = add_texture(b, "marble", stone_texture(256, tex_seed + 4u, {0.72f, 0.71f, 0.68f}, 0.12f));
  const int floor_mat = b.add_material("floor", vec3(1.0f), floor_tex);
  const int wall_mat = b.add_material("plaster", vec3(1.0f), plaster_tex);
  const int wood_mat = b.add_material("wood_panels", vec3(1.0f), planks_tex);
  const int grain_mat = b.add_material("wood", vec3(1.0f), grain_tex);
  const int marble_mat = b.add_material("marble", vec3(1.0f), marble_tex);
  const int frame_mat = b.add_material("window_frames", vec3(0.62f, 0.62f, 0.58f));
  const int iron_mat = b.add_material("cast_iron", vec3(0.05f, 0.05f, 0.05f));
  const int chrome_mat = b.add_material("chrome", vec3(0.5f, 0.5f, 0.52f));
  const int leather_mat = b.add_material("leather", vec3(0.3f, 0.07f, 0.05f));
  const int bentwood_mat = b.add_material("bentwood", vec3(0.16f, 0.08f, 0.04f));
  const int glass_mat = b.add_material("glass", vec3(0.55f, 0.6f, 0.6f));
  const int mirror_mat = b.add_material("mirror", vec3(0.08f, 0.09f, 0.1f));
  const int shade_mat = b.add_material("enamel", vec3(0.08f, 0.25f, 0.14f));
  const int pot_mat = b.add_material("terracotta", vec3(0.5f, 0.22f, 0.12f));
  const int leaves_mat = b.add_material("leaves", vec3(0.08f, 0.25f, 0.06f));
  const int gilt_mat = b.add_material("gilt", vec3(0.5f, 0.36f, 0.1f));

  // Floor, ceiling with beams, walls (the window wall built around its openings).
  b.add_node("floor", b.add_mesh("floor", transformed(make_plane({kX1 - kX0, kZ1 - kZ0}, {12, 14}, 0.4f),
                                                      translation({0.5f * (kX0 + kX1), 0.0f, 0.5f * (kZ0 + kZ1)})),
                                 floor_mat));
  {
    MeshData walls;
    append_mesh(walls, make_box({kX0 - kWall, kHeight, kZ0 - kWall}, {kX1 + kWall, kHeight + 0.2f, kZ1 + kWall}, 0.5f));
    append_mesh(walls, make_box({kX0 - kWall, 0.0f, kZ0 - kWall}, {kX0, kHeight, kZ1 + kWall}, 0.5f));
    append_mesh(walls, make_box({kX0, 0.0f, kZ0 - kWall}, {kX1, kHeight, kZ0}, 0.5f));
    append_mesh(walls, make_box({kX0, 0.0f, kZ1}, {kX1, kHeight, kZ1 + kWall}, 0.5f));
    append_mesh(walls, make_box({kX1, 0.0f, kZ0 - kWall}, {kX1 + kWall, kSill, kZ1 + kWall}, 0.5f));
    append_mesh(walls, make_box({kX1, kHead, kZ0 - kWall}, {kX1 + kWall, kHeight, kZ1 + kWall}, 0.5f));
    float z = kZ0 - kWall;
    for (int i = 0; i <= kWindows; ++i) {
      const float next = i < kWindows ? window_z(i) - 0.5f * kWindowWidth : kZ1 + kWall;
      append_mesh(walls, make_box({kX1, kSill, z}, {kX1 + kWall, kHead, next}, 0.5f));
      if (i < kWindows) z = window_z(i) + 0.5f * kWindowWidth;
    }
    b.add_node("walls", b.add_mesh("walls", walls, wall_mat));

    MeshData frames;
    for (int i = 0; i < kWindows; ++i) {
      const float zc = window_z(i), hw = 0.5f * kWindowWidth, f = 0.07f, x0 = kX1 - 0.04f, x1 = kX1 + 0.1f;
      append_mesh(frames, make_box({x0, kSill - 0.05f, zc - hw - 0.02f}, {x1 + 0.05f, kSill, zc + hw + 0.02f}));  // sill
      append_mesh(frames, make_box({x0, kSill, zc - hw}, {x1, kHead, zc - hw + f}));
      append_mesh(frames, make_box({x0, kSill, zc + hw - f}, {x1, kHead, zc + hw}));
      append_mesh(frames, make_box({x0, kHead - f, zc - hw + f}, {x1, kHead, zc + hw - f}));
      append_mesh(frames, make_box({x0, kSill, zc - hw + f}, {x1, kSill + f, zc + hw - f}));
      append_mesh(frames, make_box({x0 + 0.03f, kSill + f, zc - 0.025f}, {x1 - 0.03f, kHead - f, zc + 0.025f}));  // mullion
      append_mesh(frames, make_box({x0 + 0.03f, 2.3f, zc - hw + f}, {x1 - 0.03f, 2.35f, zc + hw - f}));     // transom
    }
    frames.uvs.clear();
    b.add_node("window_frames", b.add_mesh("window_frames", frames, frame_mat));

    MeshData beams;
    for (int i = 0; i < 9; ++i) {
      const float zb = kZ0 + 1.0f + 1.6f * static_cast<float>(i);
      append_mesh(beams, make_box({kX0, kHeight - 0.25f, zb - 0.1f}, {kX1, kHeight, zb + 0.1f}, 1.0f));
    }
    b.add_node("ceiling_beams", b.add_mesh("ceiling_beams", beams, grain_mat));
    MeshData wood;
    // Wainscot on the left and back walls, with a chair rail.
    append_mesh(wood, make_box({kX0, 0.0f, kZ0}, {kX0 + 0.03f, 1.0f, kZ1}, 1.0f));
    append_mesh(wood, make_box({kX0, 1.0f, kZ0}, {kX0 + 0.06f, 1.06f, kZ1}, 1.0f));
    append_mesh(wood, make_box({kX0, 0.0f, kZ1 - 0.03f}, {kX1, 1.0f, kZ1}, 1.0f));
    b.add_node("wainscot", b.add_mesh("wainscot", wood, wood_mat));
  }

  // The bar: counter with raised panels, marble top and a brass foot rail; the back bar with a
  // cabinet, a mirror and three shelves.
  {
    MeshData counter;
    append_mesh(counter, make_box({kBarX0, 0.0f, kBarBack}, {kBarX1, kBarTop - 0.06f, kBarFront}, 1.0f));
    const int panels = 10;
    const float pw = (kBarX1 - kBarX0) / panels;
    for (int i = 0; i < panels; ++i) {
      const float x = kBarX0 + pw * static_cast<float>(i);
      append_mesh(counter, make_box({x + 0.08f, 0.18f, kBarFront}, {x + pw - 0.08f, 0.92f, kBarFront + 0.025f}, 1.0f));
    }
    append_mesh(counter, make_box({kBarX0 - 0.05f, 0.0f, kBarFront}, {kBarX1 + 0.05f, 0.12f, kBarFront + 0.04f}, 1.0f));
    // Back bar cabinet and shelves.
    append_mesh(counter, make_box({kBarX0 - 0.1f, 0.0f, kZ0}, {kBarX1 + 0.1f, 0.95f, kZ0 + 0.55f}, 1.0f));
    for (float y : {1.35f, 1.8f, 2.25f})
      append_mesh(counter, make_box({kBarX0, y - 0.03f, kZ0}, {kBarX1, y, kZ0 + 0.28f}, 1.0f));
    for (int i = 0; i < 4; ++i) {
      const float x = kBarX0 + (kBarX1 - kBarX0) * static_cast<float>(i) / 3.0f;
      append_mesh(counter, make_box({x - 0.03f, 0.95f, kZ0}, {x + 0.03f, 2.6f, kZ0 + 0.3f}, 1.0f));
    }
    append_mesh(counter, make_box({kBarX0 - 0.1f, 2.6f, kZ0}, {kBarX1 + 0.1f, 2.7f, kZ0 + 0.34f}, 1.0f));
    b.add_node("bar", b.add_mesh("bar", counter, wood_mat));
    b.add_node("bar_top", b.add_mesh("bar_top", make_box({kBarX0 - 0.1f, kBarTop - 0.06f, kBarBack - 0.05f},
                                                        {kBarX1 + 0.1f, kBarTop, kBarFront + 0.1f}, 1.0f),
                                     marble_mat));
    b.add_node("back_bar_top", b.add_mesh("back_bar_top", make_box({kBarX0 - 0.12f, 0.95f, kZ0}, {kBarX1 + 0.12f, 1.0f, kZ0 + 0.58f}, 1.0f),
                                          marble_mat));
    MeshData mirror = make_box({kBarX0 + 0.05f, 1.0f, kZ0}, {kBarX1 - 0.05f, 2.55f, kZ0 + 0.01f});
    mirror.uvs.clear();
    b.add_node("mirror", b.add_mesh("mirror", mirror, mirror_mat));
    MeshData rail;
    CylinderOptions o;
    append_mesh(rail, make_cylinder(0.025f, kBarX1 - kBarX0, 24, o), translation({kBarX0, 0.22f, kBarFront + 0.2f}) * rotation_z(-0.5f * kPiF));
    for (int i = 0; i <= 6; ++i) {
      const float x = kBarX0 + 0.1f + (kBarX1 - kBarX0 - 0.2f) * static_cast<float>(i) / 6.0f;
      append_mesh(rail, make_cylinder(0.012f, 0.2f, 10, o), translation({x, 0.22f, kBarFront}) * rotation_x(0.5f * kPiF));
    }
    rail.uvs.clear();
    b.add_node("foot_rail", b.add_mesh("foot_rail", rail, chrome_mat));
  }

  // Bottles on the back bar and its shelves: four shapes in six glass colours.
  {
    const vec3 glass_colors[6] = {{0.05f, 0.2f, 0.08f}, {0.25f, 0.12f, 0.04f}, {0.5f, 0.3f, 0.06f},
                                  {0.5f, 0.55f, 0.53f}, {0.06f, 0.1f, 0.3f},   {0.4f, 0.05f, 0.06f}};
    int colour_mats[6];
    for (int c = 0; c < 6; ++c) colour_mats[c] = b.add_material(fmt::format("bottle_glass{}", c), glass_colors[c]);
    int shape_geometry[4];
    for (int s = 0; s < 4; ++s) {
      MeshData bottle = make_lathe(bottle_profiles()[static_cast<size_t>(s)], 36, 40.0f, 1.0f);
      bottle.uvs.clear();
      shape_geometry[s] = b.add_geometry(bottle, false);
    }
    int meshes[4][6];
    for (auto& row : meshes) std::fill(std::begin(row), std::end(row), -1);
    const int root = b.add_node("bottles", -1);
    int k = 0;
    for (float y : {1.0f, 1.35f, 1.8f, 2.25f}) {
      float x = kBarX0 + 0.12f;
      while (x < kBarX1 - 0.12f) {
        const int s = rng.uniform_int(0, 3), c = rng.uniform_int(0, 5);
        if (meshes[s][c] < 0) meshes[s][c] = b.add_mesh(fmt::format("bottle_{}_{}", s, c), {{shape_geometry[s], colour_mats[c]}});
        const float z = kZ0 + (y < 1.1f ? rng.uniformf(0.12, 0.45) : rng.uniformf(0.08, 0.2));
        b.add_node(fmt::format("bottle{:03d}", k++), meshes[s][c], NodeTransform::trs({x, y, z}, rng.uniform(0.0, 6.28)), root);
        x += rng.uniformf(0.1, 0.17);
      }
    }
  }

  // Glasses: rows on the back bar, a few on the counter and on every table.
  const int wine_glass = b.add_mesh("wine_glass", make_wine_glass(), glass_mat);
  const int tumbler = b.add_mesh("tumbler", make_tumbler(), glass_mat);
  {
    const int root = b.add_node("glasses", -1);
    int k = 0;
    for (int i = 0; i < 24; ++i) {
      const float x = kBarX0 + 0.3f + 0.26f * static_cast<float>(i);
      if (x > kBarX1 - 0.2f) break;
      b.add_node(fmt::format("glass{:03d}", k++), i % 3 == 0 ? tumbler : wine_glass, NodeTransform::at({x, 1.0, kZ0 + 0.48}), root);
    }
    for (int i = 0; i < 8; ++i)
      b.add_node(fmt::format("glass{:03d}", k++), rng.chance(0.5) ? tumbler : wine_glass,
                 NodeTransform::at({rng.uniform(kBarX0 + 0.2, kBarX1 - 0.2), kBarTop, rng.uniform(kBarBack + 0.1, kBarFront - 0.1)}), root);
  }

  // Bar stools along the counter.
  {
    MeshData steel;
    CylinderOptions o;
    append_mesh(steel, make_cylinder(0.03f, 0.68f, 20, o), translation({0.0f, 0.04f, 0.0f}));
    append_mesh(steel, make_lathe({{0, 0}, {0.22f, 0}, {0.22f, 0.02f}, {0.05f, 0.05f}, {0, 0.06f}}, 40, 40.0f, 1.0f));
    append_mesh(steel, make_torus(0.17f, 0.012f, 40, 8), translation({0.0f, 0.3f, 0.0f}));
    for (int k = 0; k < 3; ++k)
      append_mesh(steel, make_cylinder(0.008f, 0.17f, 8, o),
                  translation({0.0f, 0.3f, 0.0f}) * rotation_y(2.0f * kPiF * static_cast<float>(k) / 3.0f) * rotation_x(0.5f * kPiF));
    steel.uvs.clear();
    MeshData seat = make_lathe({{0, 0.72f}, {0.19f, 0.72f}, {0.205f, 0.74f}, {0.205f, 0.78f}, {0.18f, 0.805f}, {0, 0.81f}}, 40, 35.0f, 1.0f);
    seat.uvs.clear();
    const int stool = b.add_mesh("bar_stool", {{b.add_geometry(steel, false), chrome_mat}, {b.add_geometry(seat, false), leather_mat}});
    for (int i = 0; i < 7; ++i)
      b.add_node(fmt::format("stool{}", i), stool, NodeTransform::at({kBarX0 + 0.5 + 0.92 * i, 0.0, kBarFront + 0.5}));
  }

  // Tables with chairs and pendant lamps above them; four more lamps over the bar: 13 lights.
  {
    MeshData top = make_lathe({{0, 0.72f}, {0.38f, 0.72f}, {0.39f, 0.73f}, {0.39f, 0.745f}, {0.38f, 0.752f}, {0, 0.752f}}, 64, 35.0f, 1.0f);
    MeshData base = make_lathe({{0, 0}, {0.26f, 0}, {0.26f, 0.02f}, {0.2f, 0.04f}, {0.06f, 0.08f}, {0.035f, 0.12f},
                                {0.03f, 0.66f}, {0.06f, 0.69f}, {0.1f, 0.72f}, {0, 0.72f}},
                               32, 35.0f, 1.0f);
    base.uvs.clear();
    const int table = b.add_mesh("table", {{b.add_geometry(top), marble_mat}, {b.add_geometry(base, false), iron_mat}});
    const int chair = b.add_mesh("chair", make_chair(), bentwood_mat);
    CylinderOptions o;
    MeshData cord = make_cylinder(0.006f, 1.0f, 8, o);
    cord.uvs.clear();
    MeshData shade = make_lamp_shade();
    shade.uvs.clear();
    const int cord_geometry = b.add_geometry(cord, false);
    const int lamp = b.add_mesh("pendant_lamp", {{b.add_geometry(shade, false), shade_mat}});
    const int cord_mesh = b.add_mesh("lamp_cord", {{cord_geometry, iron_mat}});

    // A pendant: shade mouth at `mouth`, its light 3 cm below the mouth.
    int light = 0;
    const auto pendant = [&](const vec3& at, float mouth) {
      const int n = b.add_node(fmt::format("pendant{:02d}", light), lamp, NodeTransform::at({at.x, mouth, at.z}));
      NodeTransform c;
      c.translation = {0.0, 0.27, 0.0};
      c.scale = {1.0, kHeight - mouth - 0.27, 1.0};
      b.add_node(fmt::format("pendant_cord{:02d}", light), cord_mesh, c, n);
      // Over a table: E = 5/1.42^2 = 2.5 W/m^2 on the top (L ~ 0.55 on marble); bar lamps: 4/0.95^2.
      b.add_point_light(fmt::format("pendant{:02d}", light), {at.x, mouth - 0.03f, at.z}, {1.0f, 0.85f, 0.65f},
                        at.z < kBarFront ? 4.0f : 5.0f);
      ++light;
    };
    int t = 0, c = 0;
    for (float z : {-3.2f, -0.6f, 2.0f})
      for (float x : {-3.6f, -1.2f, 1.2f}) {
        const vec3 p(x + rng.uniformf(-0.15, 0.15), 0.0f, z + rng.uniformf(-0.15, 0.15));
        b.add_node(fmt::format("table{}", t), table, NodeTransform::trs(dvec3(p), rng.uniform(0.0, 6.28)));
        const int chairs = rng.uniform_int(3, 4);
        const float start = rng.uniformf(0.0, 6.28);
        for (int i = 0; i < chairs; ++i) {
          const float a = start + 2.0f * kPiF * static_cast<float>(i) / static_cast<float>(chairs) + rng.uniformf(-0.3, 0.3);
          const vec3 at = p + 0.58f * vec3(std::sin(a), 0.0f, std::cos(a));
          // The chair faces +Z locally; turn it towards the table, a little askew.
          b.add_node(fmt::format("chair{:02d}", c++), chair, NodeTransform::trs(dvec3(at), a + kPiF + rng.uniformf(-0.25, 0.25)));
        }
        for (int g = 0; g < 2; ++g) {
          const float a = rng.uniformf(0.0, 6.28), r = rng.uniformf(0.1, 0.28);
          b.add_node(fmt::format("table_glass{}_{}", t, g), g == 0 ? wine_glass : tumbler,
                     NodeTransform::at(dvec3(p + vec3(r * std::sin(a), 0.752f, r * std::cos(a)))));
        }
        pendant(p, 2.2f);
        ++t;
      }
    for (int i = 0; i < 4; ++i) pendant({-2.7f + 1.6f * static_cast<float>(i), 0.0f, -6.55f}, 2.1f);
  }

  // Banquette and pictures along the left wall, potted plants between the windows and by the bar.
  {
    b.add_node("banquette", b.add_mesh("banquette",
                                       [] {
                                         MeshData m = make_box({kX0 + 0.03f, 0.0f, -5.0f}, {kX0 + 0.58f, 0.45f, 3.5f});
                                         append_mesh(m, make_box({kX0 + 0.03f, 0.45f, -5.0f}, {kX0 + 0.2f, 1.0f, 3.5f}));
                                         m.uvs.clear();
                                         return m;
                                       }(),
                                       leather_mat));
    MeshData frames;
    for (int i = 0; i < 5; ++i) {
      const float z = -4.2f + 1.7f * static_cast<float>(i);
      const float w = rng.uniformf(0.5, 0.8), h = rng.uniformf(0.5, 0.75);
      append_mesh(frames, make_box({kX0 + 0.03f, 1.75f - 0.5f * h, z - 0.5f * w}, {kX0 + 0.08f, 1.75f + 0.5f * h, z + 0.5f * w}));
      const int canvas_mat = b.add_material(fmt::format("painting{}", i),
                                            hsv_to_rgb(static_cast<float>(rng.uniform()), rng.uniformf(0.3, 0.7), rng.uniformf(0.25, 0.6)));
      MeshData canvas = make_box({kX0 + 0.08f, 1.75f - 0.5f * h + 0.06f, z - 0.5f * w + 0.06f}, {kX0 + 0.09f, 1.75f + 0.5f * h - 0.06f, z + 0.5f * w - 0.06f});
      canvas.uvs.clear();
      b.add_node(fmt::format("painting{}", i), b.add_mesh(fmt::format("painting{}", i), canvas, canvas_mat));
    }
    frames.uvs.clear();
    b.add_node("picture_frames", b.add_mesh("picture_frames", frames, gilt_mat));

    MeshData pot = make_lathe({{0, 0}, {0.16f, 0}, {0.2f, 0.3f}, {0.22f, 0.33f}, {0.22f, 0.36f}, {0.19f, 0.36f}, {0.18f, 0.32f}, {0, 0.32f}},
                              32, 35.0f, 1.0f);
    pot.uvs.clear();
    const int pot_geometry = b.add_geometry(pot, false);
    const vec3 spots[4] = {{kX1 - 0.45f, 0.0f, -5.35f}, {kX1 - 0.45f, 0.0f, -2.05f}, {kX1 - 0.45f, 0.0f, 1.25f}, {kX0 + 0.5f, 0.0f, -8.4f}};
    for (int i = 0; i < 4; ++i) {
      MeshData leaves = make_leaf_cluster(150, 0.55f, ctx.seed + static_cast<uint64_t>(i) * 977u, 8);
      transform_mesh(leaves, translation({0.0f, 0.3f, 0.0f}));
      const int plant = b.add_mesh(fmt::format("plant{}", i), {{pot_geometry, pot_mat}, {b.add_geometry(leaves, false), leaves_mat}});
      b.add_node(fmt::format("plant{}", i), plant, NodeTransform::at(dvec3(spots[i])));
    }
  }

  // Sun through the windows, from the right and above: E = 4 W/m^2 * cos in the sun patches.
  b.add_directional_light("sun", {-0.72f, -0.55f, -0.3f}, {1.0f, 0.95f, 0.85f}, 4.0f);
  b.set_background(vec3(0.75f, 0.8f, 0.88f));
  b.set_ambient(0.05);
  // From the entrance corner across the tables to the bar; converged on the middle tables.
  set_default_view(b, {.eye = {-4.6f, 1.65f, 4.3f}, .target = {0.3f, 1.0f, -5.0f}, .convergence = 6.0, .zfar = 200.0});
}

}  // namespace

GeneratorEntry bistro_generator() {
  GeneratorInfo info;
  info.name = "bistro";
  info.description = "a dense café interior: bar, stools, bottle shelves, tables and chairs, plants, 1 sun + 13 lamps (Bistro stand-in)";
  info.file_name = "bistro.glb";
  return {info, build};
}

}  // namespace sb::scenes
