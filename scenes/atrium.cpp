// `atrium`: a two-storey colonnaded courtyard — arcades of round arches on columns on both
// levels, an upper gallery with a balustrade, hanging cloths, planted vases and a fountain —
// with procedural stone, tile and cloth textures; it stands in for Crytek Sponza.
#include <algorithm>
#include <cmath>
#include <tuple>

#include <fmt/format.h>

#include "scenes/architecture.hpp"
#include "scenes/procedural.hpp"
#include "scenes/scene_generator.hpp"
#include "scenes/textures.hpp"

namespace sb::scenes {

namespace {

constexpr float kPiF = static_cast<float>(kPi);

// Plan (meters): the open court is bounded by the column lines x = +-kCourtX, z = +-kCourtZ;
// aisles run between them and the walls at x = +-kWallX, z = +-kWallZ.
constexpr float kCourtX = 4.5f, kCourtZ = 13.5f;
constexpr float kWallX = 7.5f, kWallZ = 16.5f, kWallThickness = 0.5f;
constexpr int kLongBays = 8, kShortBays = 3;
// Elevation.
constexpr float kStylobate = 0.15f;                  // aisle floor
constexpr float kGroundColumn = 4.0f;                // column height on the ground floor
constexpr float kSpring1 = kStylobate + kGroundColumn;  // springing of the ground arches
constexpr float kSlabBottom = 6.4f, kGallery = 6.7f;    // gallery slab
constexpr float kUpperColumn = 3.0f;
constexpr float kSpring2 = kGallery + kUpperColumn;
constexpr float kRoofBottom = 11.2f, kRoofTop = 11.5f, kWallTop = 12.1f;

/// One bay of an arcade: the span between two neighbouring columns, placed in the world by a
/// yaw that turns the bay's local +Z towards the court.
struct Bay {
  vec3 centre;  ///< on the column line, at y = 0
  float span;
  float yaw;
  bool long_side;
  int index;  ///< along its side
};

std::vector<vec2> column_positions() {
  std::vector<vec2> p;
  for (int i = 0; i <= kLongBays; ++i) {
    const float z = -kCourtZ + 2.0f * kCourtZ * static_cast<float>(i) / kLongBays;
    p.push_back({-kCourtX, z});
    p.push_back({kCourtX, z});
  }
  for (int j = 1; j < kShortBays; ++j) {
    const float x = -kCourtX + 2.0f * kCourtX * static_cast<float>(j) / kShortBays;
    p.push_back({x, -kCourtZ});
    p.push_back({x, kCourtZ});
  }
  return p;
}

std::vector<Bay> bays() {
  std::vector<Bay> out;
  const float long_span = 2.0f * kCourtZ / kLongBays, short_span = 2.0f * kCourtX / kShortBays;
  for (int i = 0; i < kLongBays; ++i) {
    const float z = -kCourtZ + (static_cast<float>(i) + 0.5f) * long_span;
    out.push_back({{kCourtX, 0.0f, z}, long_span, -0.5f * kPiF, true, i});
    out.push_back({{-kCourtX, 0.0f, z}, long_span, 0.5f * kPiF, true, i});
  }
  for (int j = 0; j < kShortBays; ++j) {
    const float x = -kCourtX + (static_cast<float>(j) + 0.5f) * short_span;
    out.push_back({{x, 0.0f, -kCourtZ}, short_span, 0.0f, false, j});
    out.push_back({{x, 0.0f, kCourtZ}, short_span, kPiF, false, j});
  }
  return out;
}

/// A cloth hung from a rod between two upper columns, falling over the balustrade and the gallery
/// edge with soft vertical folds; local coordinates of a bay (x along it, +z towards the court).
MeshData make_cloth(float width, float top, float bottom, float bulge, int folds, float phase, const vec2& repeats) {
  const int nu = 40, nv = 72;
  return make_surface(
      nu, nv, false, false,
      [&](float u, float v) {
        const float x = (0.5f - u) * width;  // right to left, so the front faces the court
        const float hem = bottom + 0.25f * (2.0f * u - 1.0f) * (2.0f * u - 1.0f);
        const float y = glm::mix(top, hem, v);
        // Gathered on the rod at the top, pushed out by the balustrade below it, folds deepening
        // downwards.
        const float gather = 0.035f * std::fabs(std::sin(kPiF * u * static_cast<float>(folds) * 2.0f)) * (1.0f - v);
        const float out = 0.35f + bulge * smooth(top, top - 1.6f, y);
        const float fold = (0.02f + 0.06f * v) * std::sin(2.0f * kPiF * u * static_cast<float>(folds) + phase + 1.5f * v);
        return vec3(x, y, out + gather + fold);
      },
      repeats);
}

/// A hanging lantern: chain from `ceiling` down to a conical cap, four bars and a ring, its light
/// hanging in the open frame at `light_y`.
MeshData make_lantern(float ceiling, float light_y) {
  MeshData m;
  CylinderOptions thin;
  thin.caps = true;
  const float cap = light_y + 0.2f;
  append_mesh(m, make_cylinder(0.012f, ceiling - cap, 8, thin), translation({0.0f, cap, 0.0f}));
  append_mesh(m, make_cone(0.2f, 0.16f, 24), translation({0.0f, cap - 0.02f, 0.0f}));
  append_mesh(m, make_torus(0.16f, 0.015f, 32, 8), translation({0.0f, light_y - 0.2f, 0.0f}));
  for (int k = 0; k < 4; ++k) {
    const float a = 0.25f * kPiF + 0.5f * kPiF * static_cast<float>(k);
    append_mesh(m, make_cylinder(0.008f, 0.42f, 6, thin), translation({0.16f * std::sin(a), light_y - 0.2f, 0.16f * std::cos(a)}));
  }
  return m;
}

void build(const GeneratorContext& ctx, GltfBuilder& b) {
  Rng rng(ctx.seed, 21);
  const auto tex_seed = static_cast<uint32_t>(rng.next());

  // Textures and materials.
  const int bricks = add_texture(b, "stone_bricks", stone_bricks_texture(512, tex_seed, {0.5f, 0.4f, 0.29f}, {0.55f, 0.52f, 0.47f}));
  const int dressed = add_texture(b, "dressed_stone", stone_texture(256, tex_seed + 1u, {0.56f, 0.5f, 0.4f}, 0.22f));
  const int court_tiles = add_texture(b, "court_tiles", floor_tiles_texture(512, tex_seed + 2u, {0.5f, 0.46f, 0.4f}, {0.3f, 0.27f, 0.24f}, 4));
  const int aisle_tiles = add_texture(b, "aisle_tiles", floor_tiles_texture(512, tex_seed + 3u, {0.45f, 0.38f, 0.3f}, {0.52f, 0.47f, 0.4f}, 8));
  const vec3 cloth_colors[3][2] = {{{0.45f, 0.05f, 0.04f}, {0.62f, 0.45f, 0.1f}},
                                   {{0.05f, 0.09f, 0.32f}, {0.6f, 0.58f, 0.5f}},
                                   {{0.06f, 0.22f, 0.07f}, {0.55f, 0.42f, 0.12f}}};
  int cloth_mats[3];
  for (int c = 0; c < 3; ++c) {
    const int t = add_texture(b, fmt::format("cloth{}", c), cloth_texture(256, tex_seed + 10u + static_cast<uint32_t>(c), cloth_colors[c][0], cloth_colors[c][1], c));
    cloth_mats[c] = b.add_material(fmt::format("cloth{}", c), vec3(1.0f), t);
  }
  const int wall_mat = b.add_material("walls", vec3(1.0f), bricks);
  const int stone_mat = b.add_material("stone", vec3(1.0f), dressed);
  const int court_mat = b.add_material("court_floor", vec3(1.0f), court_tiles);
  const int aisle_mat = b.add_material("aisle_floor", vec3(1.0f), aisle_tiles);
  const int terracotta_mat = b.add_material("terracotta", vec3(1.0f, 0.62f, 0.45f), dressed);
  const int leaves_mat = b.add_material("leaves", vec3(0.1f, 0.28f, 0.07f));
  const int bronze_mat = b.add_material("bronze", vec3(0.3f, 0.2f, 0.09f));
  const int water_mat = b.add_material("water", vec3(0.08f, 0.16f, 0.18f));

  const std::vector<Bay> all_bays = bays();

  // Floors: the sunken court, the stylobate under the aisles, the gallery slab and the roof.
  {
    MeshData court = make_plane({2.0f * (kCourtX - 0.5f), 2.0f * (kCourtZ - 0.5f)}, {8, 26}, 0.25f);
    b.add_node("court_floor", b.add_mesh("court_floor", court, court_mat));
    MeshData slabs;
    for (const auto& [y0, y1, inset] : {std::tuple{0.0f, kStylobate, 0.5f}, std::tuple{kSlabBottom, kGallery, 0.4f},
                                        std::tuple{kRoofBottom, kRoofTop, 0.35f}}) {
      const float ix = kCourtX - inset, iz = kCourtZ - inset;
      append_mesh(slabs, make_box({ix, y0, -kWallZ}, {kWallX, y1, kWallZ}, 0.5f));
      append_mesh(slabs, make_box({-kWallX, y0, -kWallZ}, {-ix, y1, kWallZ}, 0.5f));
      append_mesh(slabs, make_box({-ix, y0, iz}, {ix, y1, kWallZ}, 0.5f));
      append_mesh(slabs, make_box({-ix, y0, -kWallZ}, {ix, y1, -iz}, 0.5f));
    }
    b.add_node("floors", b.add_mesh("floors", slabs, aisle_mat));
  }

  // Outer walls with pilasters facing each column and blind arches in each bay.
  {
    MeshData walls;
    const float t = kWallThickness;
    append_mesh(walls, make_box({kWallX, 0.0f, -kWallZ - t}, {kWallX + t, kWallTop, kWallZ + t}, 0.5f));
    append_mesh(walls, make_box({-kWallX - t, 0.0f, -kWallZ - t}, {-kWallX, kWallTop, kWallZ + t}, 0.5f));
    append_mesh(walls, make_box({-kWallX, 0.0f, kWallZ}, {kWallX, kWallTop, kWallZ + t}, 0.5f));
    append_mesh(walls, make_box({-kWallX, 0.0f, -kWallZ - t}, {kWallX, kWallTop, -kWallZ}, 0.5f));
    MeshData trim;
    for (const vec2& c : column_positions()) {
      for (const auto& [y0, y1] : {std::pair{kStylobate, kSlabBottom}, std::pair{kGallery, kRoofBottom}}) {
        if (std::fabs(std::fabs(c.x) - kCourtX) < 1e-3f && std::fabs(std::fabs(c.y) - kCourtZ) > 1e-3f) {
          const float x = c.x > 0.0f ? kWallX : -kWallX, d = c.x > 0.0f ? -0.12f : 0.12f;
          append_mesh(trim, make_box({std::min(x, x + d), y0, c.y - 0.3f}, {std::max(x, x + d), y1, c.y + 0.3f}, 1.0f));
        } else if (std::fabs(std::fabs(c.y) - kCourtZ) < 1e-3f && std::fabs(std::fabs(c.x) - kCourtX) > 1e-3f) {
          const float z = c.y > 0.0f ? kWallZ : -kWallZ, d = c.y > 0.0f ? -0.12f : 0.12f;
          append_mesh(trim, make_box({c.x - 0.3f, y0, std::min(z, z + d)}, {c.x + 0.3f, y1, std::max(z, z + d)}, 1.0f));
        }
      }
    }
    for (const Bay& bay : all_bays) {
      // The wall facing the bay, one aisle further out.
      const vec3 out = vec3(-std::sin(bay.yaw), 0.0f, -std::cos(bay.yaw));
      const float aisle = bay.long_side ? kWallX - kCourtX : kWallZ - kCourtZ;
      const vec3 on_wall = bay.centre + out * (aisle - 0.03f);
      for (const auto& [spring, radius] : {std::pair{kSpring1 - 0.6f, 0.5f * bay.span - 0.55f}, std::pair{kSpring2 - 0.2f, 0.5f * bay.span - 0.5f}})
        append_mesh(trim, make_arch_ring(radius, radius + 0.12f, 0.1f, 24, 0.0f, kPiF, 1.0f),
                    translation(on_wall + vec3(0.0f, spring, 0.0f)) * rotation_y(bay.yaw));
    }
    b.add_node("walls", b.add_mesh("walls", walls, wall_mat));
    b.add_node("wall_trim", b.add_mesh("wall_trim", trim, stone_mat));
  }

  // Arcades: arch panels and archivolts on both levels, cornices and the roof parapet.
  ColumnSpec ground_spec;
  ground_spec.height = kGroundColumn;
  ground_spec.radius = 0.3f;
  ground_spec.segments = 48;
  ground_spec.capital = CapitalStyle::bell;
  ColumnSpec upper_spec = ground_spec;
  upper_spec.height = kUpperColumn;
  upper_spec.radius = 0.22f;
  upper_spec.segments = 40;
  upper_spec.capital = CapitalStyle::doric;
  {
    MeshData panels, mouldings;
    for (const Bay& bay : all_bays) {
      const mat4 place = translation(bay.centre) * rotation_y(bay.yaw);
      const float r1 = 0.5f * bay.span - capital_half_width(ground_spec);
      append_mesh(panels, make_arch_panel(bay.span, kSlabBottom - kSpring1, r1, 0.6f, 32, 0.5f), place * translation({0.0f, kSpring1, 0.0f}));
      // The archivolt projects 4 cm below the panel's soffit, so that no two faces coincide.
      append_mesh(mouldings, make_arch_ring(r1 - 0.04f, r1 + 0.14f, 0.68f, 32, 0.0f, kPiF, 1.0f), place * translation({0.0f, kSpring1, 0.0f}));
      const float r2 = 0.5f * bay.span - capital_half_width(upper_spec);
      append_mesh(panels, make_arch_panel(bay.span, kRoofBottom - kSpring2, r2, 0.45f, 32, 0.5f), place * translation({0.0f, kSpring2, 0.0f}));
      append_mesh(mouldings, make_arch_ring(r2 - 0.03f, r2 + 0.1f, 0.52f, 32, 0.0f, kPiF, 1.0f), place * translation({0.0f, kSpring2, 0.0f}));
      // Cornice lip under the gallery floor and the parapet on the roof edge.
      append_mesh(mouldings, make_box({-0.5f * bay.span, kSlabBottom + 0.12f, 0.2f}, {0.5f * bay.span, kGallery + 0.05f, 0.55f}, 1.0f), place);
      append_mesh(mouldings, make_box({-0.5f * bay.span, kRoofTop, -0.15f}, {0.5f * bay.span, kWallTop - 0.1f, 0.15f}, 1.0f), place);
      append_mesh(mouldings, make_box({-0.5f * bay.span, kWallTop - 0.1f, -0.22f}, {0.5f * bay.span, kWallTop, 0.22f}, 1.0f), place);
    }
    b.add_node("arcade_walls", b.add_mesh("arcade_walls", panels, wall_mat));
    b.add_node("mouldings", b.add_mesh("mouldings", mouldings, stone_mat));
  }

  // Columns: one mesh per storey, instanced by a node per column under a parent per storey.
  {
    const int ground_col = b.add_mesh("column_ground", make_column(ground_spec), stone_mat);
    const int upper_col = b.add_mesh("column_upper", make_column(upper_spec), stone_mat);
    const int ground_root = b.add_node("colonnade_ground", -1, NodeTransform::at({0.0, kStylobate, 0.0}));
    const int upper_root = b.add_node("colonnade_upper", -1, NodeTransform::at({0.0, kGallery, 0.0}));
    int k = 0;
    for (const vec2& c : column_positions()) {
      b.add_node(fmt::format("column_ground{:02d}", k), ground_col, NodeTransform::at({c.x, 0.0, c.y}), ground_root);
      b.add_node(fmt::format("column_upper{:02d}", k), upper_col, NodeTransform::at({c.x, 0.0, c.y}), upper_root);
      ++k;
    }
  }

  // Balustrade: one mesh per bay length, instanced per upper bay.
  {
    int mesh_for[2] = {-1, -1};
    for (int kind = 0; kind < 2; ++kind) {
      const float span = kind == 0 ? 2.0f * kCourtZ / kLongBays : 2.0f * kCourtX / kShortBays;
      const float clear = span - 0.66f;
      MeshData rail;
      append_mesh(rail, make_box({-0.5f * clear, 0.0f, -0.15f}, {0.5f * clear, 0.12f, 0.15f}, 1.0f));
      append_mesh(rail, make_box({-0.5f * clear, 0.9f, -0.16f}, {0.5f * clear, 1.0f, 0.16f}, 1.0f));
      const int count = static_cast<int>(clear / 0.24f);
      const MeshData baluster = make_baluster(0.78f, 0.065f, 16);
      for (int i = 0; i < count; ++i)
        append_mesh(rail, baluster, translation({-0.5f * clear + (static_cast<float>(i) + 0.5f) * clear / static_cast<float>(count), 0.12f, 0.0f}));
      mesh_for[kind] = b.add_mesh(kind == 0 ? "balustrade_long" : "balustrade_short", rail, stone_mat);
    }
    const int root = b.add_node("balustrade", -1, NodeTransform::at({0.0, kGallery, 0.0}));
    int k = 0;
    for (const Bay& bay : all_bays)
      b.add_node(fmt::format("balustrade{:02d}", k++), mesh_for[bay.long_side ? 0 : 1],
                 NodeTransform::trs(dvec3(bay.centre), bay.yaw), root);
  }

  // Cloths in alternate upper bays of the long sides and a long banner in the middle of the far
  // side; colours, folds and phases from the seed.
  {
    int k = 0;
    for (const Bay& bay : all_bays) {
      const bool far_banner = !bay.long_side && bay.centre.z < 0.0f && bay.index == 1;
      if (!(bay.long_side && bay.index % 2 == 1) && !far_banner) continue;
      const int style = rng.uniform_int(0, 2);
      const float width = far_banner ? 1.3f : bay.span - 0.8f;
      const float bottom = far_banner ? 2.6f : rng.uniformf(4.7, 5.2);
      const MeshData cloth = make_cloth(width, kSpring2 - 0.25f, bottom, far_banner ? 0.25f : 0.42f,
                                        far_banner ? 2 : rng.uniform_int(5, 7), rng.uniformf(0.0, 6.28),
                                        far_banner ? vec2(1.0f, 4.0f) : vec2(2.0f, 3.0f));
      const int mesh = b.add_mesh(fmt::format("cloth{:02d}", k), transformed(cloth, translation(bay.centre) * rotation_y(bay.yaw)),
                                  cloth_mats[style]);
      b.add_node(fmt::format("cloth{:02d}", k), mesh);
      ++k;
    }
  }

  // Planted vases along the court and a fountain in its middle.
  {
    std::vector<vec2> vase = {{0.0f, 0.0f}, {0.22f, 0.0f}, {0.24f, 0.06f}, {0.2f, 0.1f}, {0.32f, 0.3f}, {0.42f, 0.55f},
                              {0.4f, 0.75f}, {0.3f, 0.88f}, {0.34f, 0.95f}, {0.36f, 1.0f}, {0.3f, 1.0f}, {0.28f, 0.95f},
                              {0.0f, 0.95f}};
    const int pot_geometry = b.add_geometry(make_lathe(vase, 40, 35.0f, 1.0f));
    MeshData leaves = make_leaf_cluster(70, 0.75f, ctx.seed, 6);
    transform_mesh(leaves, translation({0.0f, 0.92f, 0.0f}));
    const int leaf_geometry = b.add_geometry(leaves, false);
    const int planter = b.add_mesh("planter", {{pot_geometry, terracotta_mat}, {leaf_geometry, leaves_mat}});
    int k = 0;
    for (float x : {-3.3f, 3.3f})
      for (float z : {-11.0f, -5.5f, 5.5f, 11.0f})
        b.add_node(fmt::format("planter{}", k++), planter, NodeTransform::trs({x, 0.0, z}, rng.uniform(0.0, 6.28)));

    std::vector<vec2> basin = {{0.0f, 0.0f}, {1.7f, 0.0f}, {1.75f, 0.08f}, {1.7f, 0.5f}, {1.78f, 0.55f}, {1.78f, 0.62f},
                               {1.55f, 0.62f}, {1.55f, 0.4f}, {0.0f, 0.4f}};
    std::vector<vec2> upper = {{0.0f, 0.0f}, {0.18f, 0.0f}, {0.16f, 0.15f}, {0.12f, 0.9f}, {0.2f, 1.05f}, {0.55f, 1.2f},
                               {0.62f, 1.3f}, {0.5f, 1.3f}, {0.2f, 1.22f}, {0.1f, 1.3f}, {0.08f, 1.55f}, {0.0f, 1.62f}};
    MeshData stone = make_lathe(basin, 64, 35.0f, 1.0f);
    append_mesh(stone, make_lathe(upper, 40, 35.0f, 1.0f), translation({0.0f, 0.4f, 0.0f}));
    const MeshData water = make_lathe({{1.56f, 0.55f}, {0.0f, 0.55f}}, 64, 40.0f, 1.0f);  // facing up
    const int fountain = b.add_mesh("fountain", {{b.add_geometry(stone), stone_mat}, {b.add_geometry(water, false), water_mat}});
    b.add_node("fountain", fountain);
  }

  // Lanterns: six in the ground-floor aisles, two in the upper gallery.
  {
    const int lantern_low = b.add_mesh("lantern_ground", make_lantern(kSlabBottom, 3.3f), bronze_mat);
    const int lantern_high = b.add_mesh("lantern_upper", make_lantern(kRoofBottom, 9.3f), bronze_mat);
    const float aisle_x = 0.5f * (kCourtX + kWallX);
    int k = 0;
    for (float x : {-aisle_x, aisle_x}) {
      for (float z : {-9.0f, 0.0f, 9.0f}) {
        // E on the aisle floor 3.15 m below: 6/3.15^2 = 0.6 W/m^2; on the wall 1.5 m away ~2.
        b.add_node(fmt::format("lantern{}", k), lantern_low, NodeTransform::at({x, 0.0, z}));
        b.add_point_light(fmt::format("lantern{}", k), {x, 3.3f, z}, {1.0f, 0.8f, 0.55f}, 6.0f);
        ++k;
      }
      b.add_node(fmt::format("lantern{}", k), lantern_high, NodeTransform::at({x, 0.0, 0.0}));
      b.add_point_light(fmt::format("lantern{}", k), {x, 9.3f, 0.0f}, {1.0f, 0.8f, 0.55f}, 5.0f);
      ++k;
    }
  }

  // High sun from the near-left: E = 3.2 * 0.92 W/m^2 on the court floor (L = 0.4 on the 0.45
  // albedo tiles); one arcade lies in shadow, the other in sun.
  b.add_directional_light("sun", {0.35f, -1.0f, -0.3f}, {1.0f, 0.96f, 0.88f}, 3.2f);
  b.set_background(vec3(0.45f, 0.6f, 0.85f));
  b.set_ambient(0.04);
  // From the near end of the court down its length; the fountain is the main subject.
  set_default_view(b, {.eye = {0.0f, 1.7f, 11.8f}, .target = {0.0f, 3.2f, -6.0f}, .convergence = 11.8, .zfar = 500.0});
}

}  // namespace

GeneratorEntry atrium_generator() {
  GeneratorInfo info;
  info.name = "atrium";
  info.description = "a textured two-storey colonnaded courtyard with arches, balustrades and hanging cloths (Sponza stand-in)";
  info.file_name = "atrium.glb";
  return {info, build};
}

}  // namespace sb::scenes
