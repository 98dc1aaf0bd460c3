// `temple`: a peripteral temple on a stepped platform — a peristyle of fluted Ionic columns,
// entablature, pediments and a tiled roof, a cella with an inner colonnade — with statues on
// pedestals and thirteen braziers; it stands in for Sun Temple.
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

// Platform: stylobate top at kFloor; the peristyle's column lines x = +-kColX, z in [kColZ1, kColZ0].
constexpr float kFloor = 1.2f;
constexpr float kColX = 7.5f, kColZ0 = 2.5f, kColZ1 = -22.5f;
constexpr float kColumnHeight = 8.5f;
constexpr float kArchitrave = kFloor + kColumnHeight;  // 9.7
constexpr float kFrieze = kArchitrave + 0.9f, kCornice = kFrieze + 0.9f, kEave = kCornice + 0.4f;
constexpr float kRidge = 3.0f, kRoofHalf = 8.6f;
// The cella: inner faces at x = +-kCellaX, from its front wall at z = kCellaZ0 to the back kCellaZ1.
constexpr float kCellaX = 3.7f, kCellaWall = 0.8f, kCellaZ0 = -2.0f, kCellaZ1 = -18.7f;

/// A statue on its pedestal: a robed figure built from primitives, posed from the seed, with its
/// attribute (spear, shield or offering bowl) as a second part. Local y = 0 is the pedestal foot.
struct Statue {
  MeshData stone;      ///< pedestal and figure
  MeshData attribute;  ///< bronze
};

Statue make_statue(Rng& rng) {
  Statue s;
  MeshData& m = s.stone;
  // Pedestal: plinth, die and cap.
  append_mesh(m, make_box({-0.45f, 0.0f, -0.45f}, {0.45f, 0.2f, 0.45f}, 1.0f));
  append_mesh(m, make_box({-0.35f, 0.2f, -0.35f}, {0.35f, 1.2f, 0.35f}, 1.0f));
  append_mesh(m, make_box({-0.42f, 1.2f, -0.42f}, {0.42f, 1.35f, 0.42f}, 1.0f));
  const float base = 1.35f;
  MeshData fig;
  const float lean = rng.uniformf(-0.06, 0.06);  // contrapposto sway
  // Feet peeking out under the robe.
  for (float side : {-1.0f, 1.0f})
    append_mesh(fig, transformed(make_uv_sphere(0.06f, 16, 8), translation({side * 0.1f, 0.03f, 0.08f}) * scaling({0.9f, 0.5f, 1.8f})));
  // Robe: a flared, fluted skirt from the waist to the hem.
  append_mesh(fig, make_surface(64, 24, true, false, [&](float u, float v) {
    const float phi = 2.0f * kPiF * u;
    const float y = glm::mix(0.08f, 1.02f, v);
    const float r = glm::mix(0.27f, 0.16f, std::pow(v, 0.8f)) * (1.0f + 0.05f * std::cos(18.0f * phi) * (1.0f - v));
    return vec3(r * std::sin(phi) * 1.15f + lean * v, y, r * std::cos(phi));
  }));
  // Torso, elliptical in plan: waist, chest, shoulders, neck.
  MeshData torso = make_lathe({{0.0f, 0.98f}, {0.16f, 0.98f}, {0.17f, 1.15f}, {0.2f, 1.33f}, {0.21f, 1.45f}, {0.15f, 1.52f},
                               {0.065f, 1.56f}, {0.06f, 1.64f}, {0.0f, 1.64f}},
                              40, 50.0f, 1.0f);
  append_mesh(fig, torso, translation({lean, 0.0f, 0.0f}) * scaling({1.35f, 1.0f, 0.85f}));
  // Head with hair.
  const float tilt = rng.uniformf(-0.15, 0.15);
  const vec3 head(lean + 0.02f * tilt, 1.74f, 0.0f);
  append_mesh(fig, make_uv_sphere(0.11f, 32, 16), translation(head) * scaling({0.9f, 1.1f, 1.0f}));
  append_mesh(fig, make_uv_sphere(0.118f, 32, 16), translation(head + vec3(0.0f, 0.03f, -0.025f)) * scaling({0.92f, 1.0f, 1.0f}));
  append_mesh(fig, make_box({-0.015f, -0.02f, 0.0f}, {0.015f, 0.03f, 0.05f}), translation(head + vec3(0.0f, 0.0f, 0.085f)));
  // Arms: one raised holding a staff or spear, the other lowered or holding a bowl/shield.
  const bool right_raised = rng.chance(0.5);
  const int attribute = rng.uniform_int(0, 2);
  for (float side : {-1.0f, 1.0f}) {
    const vec3 shoulder(lean + side * 0.27f, 1.48f, 0.0f);
    const bool raised = (side > 0.0f) == right_raised;
    vec3 elbow, hand;
    if (raised) {
      elbow = shoulder + vec3(side * 0.12f, -0.18f, 0.12f);
      hand = elbow + vec3(side * 0.02f, 0.2f, 0.16f);
    } else {
      elbow = shoulder + vec3(side * 0.06f, -0.28f, rng.uniformf(0.0, 0.08));
      hand = elbow + vec3(side * 0.02f, -0.06f, 0.26f);
    }
    const std::vector<vec3> arm = catmull_rom({shoulder, elbow, hand}, 6);
    std::vector<float> radii;
    for (size_t i = 0; i < arm.size(); ++i) radii.push_back(glm::mix(0.06f, 0.038f, static_cast<float>(i) / static_cast<float>(arm.size() - 1)));
    append_mesh(fig, make_tube(arm, radii, 16, true));
    append_mesh(fig, make_uv_sphere(0.045f, 16, 8), translation(hand));
    append_mesh(fig, make_uv_sphere(0.065f, 16, 8), translation(shoulder));
    CylinderOptions o;
    if (raised && attribute != 2) {
      // Staff or spear, held upright.
      append_mesh(s.attribute, make_cylinder(0.018f, 2.3f, 12, o), translation(hand - vec3(0.0f, 1.2f, 0.0f)));
      if (attribute == 1) append_mesh(s.attribute, make_cone(0.04f, 0.22f, 12), translation(hand + vec3(0.0f, 1.1f, 0.0f)));
    } else if (!raised && attribute == 1) {
      // Round shield resting against the lowered arm.
      const MeshData shield = make_lathe({{0.0f, 0.0f}, {0.33f, 0.0f}, {0.34f, 0.02f}, {0.3f, 0.06f}, {0.0f, 0.09f}}, 48, 35.0f, 1.0f);
      append_mesh(s.attribute, shield, translation(hand + vec3(side * 0.06f, 0.0f, 0.0f)) * rotation_z(side * 0.5f * kPiF));
    } else if (!raised && attribute == 2) {
      // Offering bowl held in front.
      append_mesh(s.attribute, make_lathe({{0.0f, 0.0f}, {0.04f, 0.0f}, {0.1f, 0.05f}, {0.09f, 0.055f}, {0.0f, 0.015f}}, 32, 60.0f, 1.0f),
                  translation(hand + vec3(0.0f, 0.03f, 0.05f)));
    }
  }
  append_mesh(m, fig, translation({0.0f, base, 0.0f}));
  if (!s.attribute.empty()) transform_mesh(s.attribute, translation({0.0f, base, 0.0f}));
  return s;
}

/// A bronze brazier on a tripod: its bowl rim at y = 1.0 (local).
MeshData make_brazier() {
  MeshData m = make_lathe({{0.0f, 0.78f}, {0.08f, 0.78f}, {0.24f, 0.88f}, {0.31f, 1.0f}, {0.28f, 1.0f}, {0.21f, 0.9f}, {0.0f, 0.86f}},
                          40, 45.0f, 1.0f);
  for (int k = 0; k < 3; ++k) {
    const float a = 2.0f * kPiF * static_cast<float>(k) / 3.0f;
    const vec3 d(std::sin(a), 0.0f, std::cos(a));
    const std::vector<vec3> leg = catmull_rom({d * 0.1f + vec3(0, 0.85f, 0), d * 0.22f + vec3(0, 0.45f, 0), d * 0.3f + vec3(0, 0.02f, 0)}, 6);
    append_mesh(m, make_tube(leg, std::vector<float>(leg.size(), 0.018f), 10, true));
  }
  append_mesh(m, make_torus(0.16f, 0.012f, 32, 6), translation({0.0f, 0.35f, 0.0f}));
  return m;
}

/// The triangular gable over a front or back of the temple: a prism of depth `depth` whose front
/// face is at z = 0 and faces +Z.
MeshData make_pediment(float half_width, float height, float depth, float uv_per_meter) {
  MeshData m;
  const vec3 l(-half_width, 0.0f, 0.0f), r(half_width, 0.0f, 0.0f), t(0.0f, height, 0.0f), back(0.0f, 0.0f, -depth);
  for (int face = 0; face < 2; ++face) {
    const vec3 off = face == 0 ? vec3(0.0f) : back;
    const vec3 n = face == 0 ? vec3(0, 0, 1) : vec3(0, 0, -1);
    const uint32_t a = m.add_vertex(l + off, n, box_uv(l + off, n, uv_per_meter));
    const uint32_t b = m.add_vertex(r + off, n, box_uv(r + off, n, uv_per_meter));
    const uint32_t c = m.add_vertex(t + off, n, box_uv(t + off, n, uv_per_meter));
    if (face == 0) m.add_triangle(a, b, c);
    else m.add_triangle(a, c, b);
  }
  const vec3 nl = glm::normalize(vec3(-height, half_width, 0.0f)), nr = glm::normalize(vec3(height, half_width, 0.0f));
  m.add_quad(l, t, t + back, l + back, nl, uv_per_meter);
  m.add_quad(t, r, r + back, t + back, nr, uv_per_meter);
  m.add_quad(l, l + back, r + back, r, {0, -1, 0}, uv_per_meter);
  return m;
}

void build(const GeneratorContext& ctx, GltfBuilder& b) {
  Rng rng(ctx.seed, 41);
  const auto tex_seed = static_cast<uint32_t>(rng.next());

  const int ashlar_tex = add_texture(b, "ashlar", stone_bricks_texture(512, tex_seed, {0.62f, 0.56f, 0.46f}, {0.5f, 0.47f, 0.42f}, 2, 4));
  const int marble_tex = add_texture(b, "marble", stone_texture(256, tex_seed + 1u, {0.72f, 0.68f, 0.6f}, 0.14f));
  const int paving_tex = add_texture(b, "paving", floor_tiles_texture(512, tex_seed + 2u, {0.55f, 0.5f, 0.42f}, {0.48f, 0.43f, 0.36f}, 4));
  const int sand_tex = add_texture(b, "sand", stone_texture(256, tex_seed + 3u, {0.42f, 0.36f, 0.26f}, 0.25f));
  const int ashlar_mat = b.add_material("ashlar", vec3(1.0f), ashlar_tex);
  const int marble_mat = b.add_material("marble", vec3(1.0f), marble_tex);
  const int paving_mat = b.add_material("paving", vec3(1.0f), paving_tex);
  const int sand_mat = b.add_material("ground", vec3(1.0f), sand_tex);
  const int tile_mat = b.add_material("roof_tiles", vec3(0.45f, 0.18f, 0.1f));
  const int bronze_mat = b.add_material("bronze", vec3(0.32f, 0.2f, 0.08f));

  // Ground and the stepped platform (three steps on every side) with a paved top.
  b.add_node("ground", b.add_mesh("ground", transformed(make_plane({160.0f, 160.0f}, {16, 16}, 0.25f), translation({0.0f, 0.0f, -10.0f})),
                                  sand_mat));
  {
    MeshData steps;
    const float x1 = kColX + 1.5f, z0 = kColZ0 + 1.5f, z1 = kColZ1 - 1.5f;
    for (int k = 0; k < 3; ++k) {
      const float grow = 0.5f * static_cast<float>(3 - k);
      const float y0 = 0.4f * static_cast<float>(k), y1 = y0 + 0.4f;
      append_mesh(steps, make_box({-x1 - grow + 0.5f, y0, z1 - grow + 0.5f}, {x1 + grow - 0.5f, y1, z0 + grow - 0.5f}, 0.5f));
    }
    b.add_node("platform", b.add_mesh("platform", steps, ashlar_mat));
    b.add_node("pavement", b.add_mesh("pavement",
                                      transformed(make_plane({2.0f * x1 - 1.0f, z0 - z1 - 1.0f}, {8, 14}, 0.25f),
                                                  translation({0.0f, kFloor + 0.002f, 0.5f * (z0 + z1)})),
                                      paving_mat));
  }

  // Peristyle: 6 x 11 fluted Ionic columns, one mesh instanced by 30 nodes.
  ColumnSpec outer;
  outer.height = kColumnHeight;
  outer.radius = 0.72f;
  outer.segments = 96;
  outer.rings = 16;
  outer.flutes = 24;
  outer.flute_depth = 0.07f;
  outer.capital = CapitalStyle::ionic;
  {
    const int column = b.add_mesh("column_ionic", make_column(outer), marble_mat);
    const int root = b.add_node("peristyle", -1, NodeTransform::at({0.0, kFloor, 0.0}));
    int k = 0;
    for (int j = 0; j <= 10; ++j) {
      const float z = kColZ0 + (kColZ1 - kColZ0) * static_cast<float>(j) / 10.0f;
      for (int i = 0; i < 6; ++i) {
        const float x = -kColX + 2.0f * kColX * static_cast<float>(i) / 5.0f;
        if (j != 0 && j != 10 && i != 0 && i != 5) continue;
        b.add_node(fmt::format("column{:02d}", k++), column, NodeTransform::at({x, 0.0, z}), root);
      }
    }
  }

  // Entablature (architrave, frieze with triglyphs, cornice), ceiling, pediments and roof.
  {
    MeshData ent;
    const float hw = 0.75f;
    for (const auto& [y0, y1, w] : {std::tuple{kArchitrave, kFrieze, hw}, std::tuple{kFrieze, kCornice, hw - 0.1f},
                                    std::tuple{kCornice, kEave, hw + 0.45f}}) {
      append_mesh(ent, make_box({-kColX - w, y0, kColZ0 - w}, {kColX + w, y1, kColZ0 + w}, 0.5f));
      append_mesh(ent, make_box({-kColX - w, y0, kColZ1 - w}, {kColX + w, y1, kColZ1 + w}, 0.5f));
      append_mesh(ent, make_box({kColX - w, y0, kColZ1 + w}, {kColX + w, y1, kColZ0 - w}, 0.5f));
      append_mesh(ent, make_box({-kColX - w, y0, kColZ1 + w}, {-kColX + w, y1, kColZ0 - w}, 0.5f));
    }
    // Triglyphs on the outer faces of the frieze, every half intercolumniation.
    const float out = hw - 0.1f;
    for (int i = 0; i <= 10; ++i) {
      const float x = -kColX + 1.5f * static_cast<float>(i);
      append_mesh(ent, make_box({x - 0.25f, kFrieze, kColZ0 + out}, {x + 0.25f, kCornice, kColZ0 + out + 0.06f}, 1.0f));
      append_mesh(ent, make_box({x - 0.25f, kFrieze, kColZ1 - out - 0.06f}, {x + 0.25f, kCornice, kColZ1 - out}, 1.0f));
    }
    for (int i = 0; i <= 20; ++i) {
      const float z = kColZ0 - 1.25f * static_cast<float>(i);
      append_mesh(ent, make_box({kColX + out, kFrieze, z - 0.25f}, {kColX + out + 0.06f, kCornice, z + 0.25f}, 1.0f));
      append_mesh(ent, make_box({-kColX - out - 0.06f, kFrieze, z - 0.25f}, {-kColX - out, kCornice, z + 0.25f}, 1.0f));
    }
    // Coffered ceiling over the peristyle and the cella.
    append_mesh(ent, make_box({-kColX + hw, kCornice, kColZ1 + hw}, {kColX - hw, kCornice + 0.3f, kColZ0 - hw}, 0.5f));
    for (int i = 0; i < 16; ++i) {
      const float z = kColZ0 - 1.5f * static_cast<float>(i + 1);
      append_mesh(ent, make_box({-kColX + hw, kCornice - 0.35f, z - 0.12f}, {kColX - hw, kCornice, z + 0.12f}, 1.0f));
    }
    // Pediments front and back.
    const float overhang = hw + 0.45f;
    append_mesh(ent, make_pediment(kColX + overhang, kRidge, 0.8f, 0.5f), translation({0.0f, kEave, kColZ0 + overhang}));
    append_mesh(ent, make_pediment(kColX + overhang, kRidge, 0.8f, 0.5f), translation({0.0f, kEave, kColZ1 - overhang}) * rotation_y(kPiF));
    b.add_node("entablature", b.add_mesh("entablature", ent, marble_mat));

    // Roof: two slabs and rows of cover tiles running down the slopes.
    MeshData roof;
    const float slope = std::atan2(kRidge, kRoofHalf);
    const float length = std::sqrt(kRidge * kRidge + kRoofHalf * kRoofHalf) + 0.3f;
    const float zf = kColZ0 + overhang + 0.1f, zb = kColZ1 - overhang - 0.1f;
    for (float side : {-1.0f, 1.0f}) {
      const mat4 place = translation({0.0f, kEave + kRidge, 0.0f}) * rotation_z(side * (0.5f * kPiF + slope));
      // Local +Y runs down the slope from the ridge; +X is the slab's outward normal.
      append_mesh(roof, make_box({0.0f, 0.0f, zb}, {0.25f, length, zf}, 0.5f), place);
      CylinderOptions o;
      o.caps = true;
      for (float z = zb + 0.2f; z < zf - 0.1f; z += 0.45f)
        append_mesh(roof, make_cylinder(0.09f, length, 10, o), place * translation({0.25f, 0.0f, z}));
    }
    roof.uvs.clear();
    b.add_node("roof", b.add_mesh("roof", roof, tile_mat));
  }

  // Cella: side and back walls, the front wall around its doorway with a moulded frame, antae,
  // and an inner Doric colonnade with its architraves.
  {
    MeshData walls;
    const float xo = kCellaX + kCellaWall, top = kCornice;
    append_mesh(walls, make_box({kCellaX, kFloor, kCellaZ1}, {xo, top, -0.5f}, 0.5f));
    append_mesh(walls, make_box({-xo, kFloor, kCellaZ1}, {-kCellaX, top, -0.5f}, 0.5f));
    append_mesh(walls, make_box({-xo, kFloor, kCellaZ1 - kCellaWall}, {xo, top, kCellaZ1}, 0.5f));
    append_mesh(walls, make_box({-kCellaX, kFloor, kCellaZ0 - kCellaWall}, {-1.6f, top, kCellaZ0}, 0.5f));
    append_mesh(walls, make_box({1.6f, kFloor, kCellaZ0 - kCellaWall}, {kCellaX, top, kCellaZ0}, 0.5f));
    append_mesh(walls, make_box({-1.6f, kFloor + 6.0f, kCellaZ0 - kCellaWall}, {1.6f, top, kCellaZ0}, 0.5f));
    b.add_node("cella", b.add_mesh("cella", walls, ashlar_mat));
    MeshData trim;
    append_mesh(trim, make_box({-1.9f, kFloor, kCellaZ0}, {-1.6f, kFloor + 6.3f, kCellaZ0 + 0.12f}, 1.0f));
    append_mesh(trim, make_box({1.6f, kFloor, kCellaZ0}, {1.9f, kFloor + 6.3f, kCellaZ0 + 0.12f}, 1.0f));
    append_mesh(trim, make_box({-1.9f, kFloor + 6.0f, kCellaZ0}, {1.9f, kFloor + 6.45f, kCellaZ0 + 0.18f}, 1.0f));
    for (float side : {-1.0f, 1.0f})
      append_mesh(trim, make_box({side > 0 ? kCellaX - 0.1f : -kCellaX - kCellaWall - 0.1f, kFloor, -0.9f},
                                 {side > 0 ? kCellaX + kCellaWall + 0.1f : -kCellaX + 0.1f, kArchitrave, -0.4f}, 1.0f));
    b.add_node("cella_trim", b.add_mesh("cella_trim", trim, marble_mat));

    ColumnSpec inner;
    inner.height = 7.0f;
    inner.radius = 0.35f;
    inner.segments = 60;
    inner.flutes = 20;
    inner.flute_depth = 0.06f;
    inner.capital = CapitalStyle::doric;
    const int column = b.add_mesh("column_doric", make_column(inner), marble_mat);
    const int root = b.add_node("inner_colonnade", -1, NodeTransform::at({0.0, kFloor, 0.0}));
    int k = 0;
    MeshData beams;
    for (float x : {-2.6f, 2.6f}) {
      for (int j = 0; j < 5; ++j)
        b.add_node(fmt::format("inner_column{:02d}", k++), column, NodeTransform::at({x, 0.0, -5.0 - 3.0 * j}), root);
      append_mesh(beams, make_box({x - 0.4f, kFloor + 7.0f, -17.4f}, {x + 0.4f, kFloor + 7.6f, -4.6f}, 1.0f));
    }
    b.add_node("inner_architraves", b.add_mesh("inner_architraves", beams, marble_mat));
  }

  // Statues: a pair before the steps, a pair in the porch, a pair in the cella and the cult
  // statue at its back, each with its own pose.
  {
    struct Placement {
      vec3 at;
      float yaw, scale;
    };
    const Placement places[7] = {{{-6.0f, 0.0f, 7.0f}, 0.15f, 1.0f},  {{6.0f, 0.0f, 7.0f}, -0.15f, 1.0f},
                                 {{-3.0f, kFloor, 0.0f}, 0.3f, 1.0f},  {{3.0f, kFloor, 0.0f}, -0.3f, 1.0f},
                                 {{-1.6f, kFloor, -15.0f}, 0.4f, 1.0f}, {{1.6f, kFloor, -15.0f}, -0.4f, 1.0f},
                                 {{0.0f, kFloor, -17.4f}, 0.0f, 2.2f}};
    for (int i = 0; i < 7; ++i) {
      Statue s = make_statue(rng);
      std::vector<MeshPrimitive> prims = {{b.add_geometry(s.stone), marble_mat}};
      if (!s.attribute.empty()) {
        s.attribute.uvs.clear();
        prims.push_back({b.add_geometry(s.attribute, false), bronze_mat});
      }
      const int mesh = b.add_mesh(fmt::format("statue{}", i), prims);
      b.add_node(fmt::format("statue{}", i), mesh, NodeTransform::trs(dvec3(places[i].at), places[i].yaw, places[i].scale));
    }
  }

  // Thirteen braziers, each with its fire (a point light) 0.25 m above the bowl.
  {
    const int brazier = b.add_mesh("brazier", make_brazier(), bronze_mat);
    struct Fire {
      vec3 at;
      float intensity;
    };
    std::vector<Fire> fires = {{{-3.0f, 0.0f, 6.5f}, 6.0f}, {{3.0f, 0.0f, 6.5f}, 6.0f}};
    for (float x : {-6.0f, -3.0f, 3.0f, 6.0f}) fires.push_back({{x, kFloor, 1.2f}, 5.0f});
    for (float z : {-5.5f, -9.0f, -12.5f})
      for (float x : {-1.2f, 1.2f}) fires.push_back({{x, kFloor, z}, 4.0f});
    fires.push_back({{0.0f, kFloor, -15.2f}, 5.0f});
    for (size_t i = 0; i < fires.size(); ++i) {
      b.add_node(fmt::format("brazier{:02d}", i), brazier, NodeTransform::at(dvec3(fires[i].at)));
      // 1-2 m to the nearest stone: E = 4-6 / 1.5^2 ~ 2-3 W/m^2, L ~ 0.4 on the marble.
      b.add_point_light(fmt::format("fire{:02d}", i), fires[i].at + vec3(0.0f, 1.25f, 0.0f), {1.0f, 0.62f, 0.3f}, fires[i].intensity);
    }
  }

  // Late sun from the front right: E = 3.5 W/m^2 * cos, long shadows into the porch.
  b.add_directional_light("sun", {-0.45f, -0.5f, -0.75f}, {1.0f, 0.9f, 0.75f}, 3.5f);
  b.set_background(vec3(0.5f, 0.58f, 0.72f));
  b.set_ambient(0.05);
  // Before the steps, looking up at the facade; converged on the front colonnade.
  set_default_view(b, {.eye = {6.5f, 2.0f, 25.0f}, .target = {0.0f, 6.0f, -4.0f}, .convergence = 23.0, .zfar = 1000.0});
}

}  // namespace

GeneratorEntry temple_generator() {
  GeneratorInfo info;
  info.name = "temple";
  info.description = "a temple of fluted columns with statues, steps and a roof, 1 sun + 13 braziers (Sun Temple stand-in)";
  info.file_name = "temple.glb";
  return {info, build};
}

}  // namespace sb::scenes
