// `complexity`: a field of noise-displaced tori and torus-knot tubes receding in depth whose
// total triangle count follows the parameter N (10^5 to 10^8) to within 1 %, for Kim's
// scene-complexity sweep.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "scenes/procedural.hpp"
#include "scenes/scene_generator.hpp"

namespace sb::scenes {

namespace {

constexpr float kTau = static_cast<float>(2.0 * kPi);

/// One object of the field: where it stands, what shape, how finely tessellated.
struct FieldObject {
  vec3 position;
  float size = 1.0f;  ///< overall radius, meters
  float yaw = 0.0f;
  float tilt = 0.0f;
  int shape = 0;      ///< 0 torus, 1..3 torus knots (2,3), (2,5), (3,4)
  int around = 3;     ///< segments around the tube
  int along = 3;      ///< segments along the ring or knot
  vec3 color{0.5f};
  uint32_t noise_seed = 0;
};

/// The object's surface: a tube of radius `tube` around a closed curve, displaced by noise.
MeshData make_field_object(const FieldObject& o) {
  static constexpr int knots[4][2] = {{1, 0}, {2, 3}, {2, 5}, {3, 4}};
  const int p = knots[o.shape][0], q = knots[o.shape][1];
  const float ring = o.shape == 0 ? 0.7f : 0.62f, spread = 0.28f;
  const float tube = o.shape == 0 ? 0.3f : 0.13f;
  const float amp = 0.35f * tube;
  // Centre line and a periodic frame; for knots the torus-surface normal keeps the frame closed.
  auto centre = [&](float t) {
    if (o.shape == 0) return vec3(ring * std::sin(t), 0.0f, ring * std::cos(t));
    const float r = ring + spread * std::cos(static_cast<float>(q) * t);
    return vec3(r * std::sin(static_cast<float>(p) * t), spread * std::sin(static_cast<float>(q) * t),
                r * std::cos(static_cast<float>(p) * t));
  };
  auto frame_normal = [&](float t) {
    if (o.shape == 0) return vec3(std::sin(t), 0.0f, std::cos(t));
    const float a = static_cast<float>(q) * t, b = static_cast<float>(p) * t;
    return vec3(std::cos(a) * std::sin(b), std::sin(a), std::cos(a) * std::cos(b));
  };
  std::vector<vec3> pos;
  pos.reserve(static_cast<size_t>(o.around + 1) * static_cast<size_t>(o.along + 1));
  for (int j = 0; j <= o.along; ++j) {
    const float t = kTau * static_cast<float>(j % o.along) / static_cast<float>(o.along);
    const float h = 1e-3f;
    const vec3 c = centre(t);
    const vec3 tangent = glm::normalize(centre(t + h) - centre(t - h));
    vec3 n = frame_normal(t);
    n = glm::normalize(n - glm::dot(n, tangent) * tangent);
    const vec3 bn = glm::cross(tangent, n);
    for (int i = 0; i <= o.around; ++i) {
      const float phi = kTau * static_cast<float>(i % o.around) / static_cast<float>(o.around);
      const vec3 dir = std::cos(phi) * n + std::sin(phi) * bn;
      const vec3 surface = c + tube * dir;
      const float d = amp * fbm(surface * 3.0f, o.noise_seed, 4);
      pos.push_back(o.size * (c + (tube + d) * dir));
    }
  }
  // u around the tube, v along the curve: dP/du x dP/dv points outwards.
  MeshData m = make_grid_surface(o.around, o.along, true, true, std::move(pos));
  m.uvs.clear();
  return m;
}

void build(const GeneratorContext& ctx, GltfBuilder& b) {
  const auto target = static_cast<size_t>(std::llround(ctx.param("triangles")));
  Rng rng(ctx.seed, 11);
  const size_t ground_triangles = 800;  // a 20 x 20 grid

  // Object count grows with N so that no object exceeds ~150 k triangles.
  const int count = std::clamp(static_cast<int>(target / 150000), 24, 1000);
  // Rows recede geometrically from 3 m; each row holds objects across the view at its depth,
  // sized so that every object covers a similar part of the screen.
  const int rows = std::max(3, static_cast<int>(std::lround(std::sqrt(static_cast<double>(count) / 3.0))));
  const int per_row = (count + rows - 1) / rows;
  const float half_w = std::tan(0.5f * static_cast<float>(degrees_to_radians(40.0))) * 16.0f / 9.0f;

  std::vector<FieldObject> objects;
  objects.reserve(static_cast<size_t>(count));
  size_t remaining = target - ground_triangles;
  for (int k = 0; k < count; ++k) {
    const int row = k / per_row, col = k % per_row;
    const int in_row = std::min(per_row, count - row * per_row);
    const float depth = 3.0f * std::pow(1.3f, static_cast<float>(row));
    const float span = 2.0f * 0.95f * (depth + 1.0f) * half_w;  // the camera stands at z = 1
    const float cell = span / static_cast<float>(in_row);
    FieldObject o;
    o.size = std::min(0.45f * cell, 0.2f * depth);
    o.position = vec3(-0.5f * span + (static_cast<float>(col) + 0.5f) * cell + rng.uniformf(-0.1, 0.1) * cell,
                      o.size * 1.15f, -depth + rng.uniformf(-0.1, 0.1) * depth);
    o.yaw = rng.uniformf(0.0, kTau);
    o.tilt = rng.uniformf(0.3, 1.3);
    o.shape = rng.uniform_int(0, 3);
    o.color = hsv_to_rgb(static_cast<float>(rng.uniform()), rng.uniformf(0.3, 0.7), rng.uniformf(0.5, 0.85));
    o.noise_seed = static_cast<uint32_t>(rng.next());
    // Tessellation: an even share of what is left, with the tube 1:4 (torus) or 1:12 (knots).
    const size_t share = remaining / static_cast<size_t>(count - k);
    const double aspect = o.shape == 0 ? 4.0 : 12.0;
    o.around = std::max(3, static_cast<int>(std::lround(std::sqrt(static_cast<double>(share) / (2.0 * aspect)))));
    o.along = std::max(3, static_cast<int>(std::lround(static_cast<double>(share) / (2.0 * o.around))));
    remaining -= std::min(remaining, static_cast<size_t>(2) * static_cast<size_t>(o.around) * static_cast<size_t>(o.along));
    objects.push_back(o);
  }

  // The ground reaches from just behind the camera to beyond the last row.
  const float far = std::max(80.0f, 3.0f * std::pow(1.3f, static_cast<float>(rows - 1)) * 1.2f + 5.0f);
  const float half = far * half_w + 5.0f;
  const int ground_mat = b.add_material("ground", vec3(0.4f));
  MeshData ground = transformed(make_plane({2.0f * half, far + 3.0f}, {20, 20}), translation({0.0f, 0.0f, 0.5f * (3.0f - far)}));
  ground.uvs.clear();
  b.add_node("ground", b.add_mesh("ground", ground, ground_mat));
  // Reserve the whole binary buffer up front: for N = 10^8 it is about 2.4 GB, and growing it by
  // doubling would briefly need three times that.
  const bool wide = target >= 1000000;
  size_t bytes = 0;
  for (const FieldObject& o : objects) {
    const size_t v = static_cast<size_t>(o.around + 1) * static_cast<size_t>(o.along + 1);
    const size_t idx = static_cast<size_t>(6) * static_cast<size_t>(o.around) * static_cast<size_t>(o.along);
    bytes += 24 * v + ((wide || v > 65535 ? 4 : 2) * idx + 3) / 4 * 4;
  }
  b.reserve_buffer(bytes + 1024);

  for (size_t k = 0; k < objects.size(); ++k) {
    const FieldObject& o = objects[k];
    const MeshData mesh = make_field_object(o);
    const int material = b.add_material(fmt::format("object{:04d}", k), o.color);
    const int geometry = b.add_geometry(mesh, false, wide ? IndexType::uint32 : IndexType::automatic);
    const int m = b.add_mesh(fmt::format("object{:04d}", k), {MeshPrimitive{geometry, material}});
    NodeTransform t;
    t.translation = dvec3(o.position);
    t.rotation = glm::angleAxis(static_cast<double>(o.yaw), dvec3(0, 1, 0)) * glm::angleAxis(static_cast<double>(o.tilt), dvec3(1, 0, 0));
    b.add_node(fmt::format("object{:04d}", k), m, t);
  }

  // A sun from behind the camera's left and two point lights near the front rows: the sun gives
  // E = 2.5 * cos W/m^2 (L up to 0.6 on the 0.75-albedo objects).
  b.add_directional_light("sun", {0.4f, -0.8f, -0.45f}, {1.0f, 0.97f, 0.92f}, 2.5f);
  b.add_point_light("front_left", {-3.0f, 3.0f, -2.0f}, vec3(1.0f), 8.0f);
  b.add_point_light("front_right", {3.0f, 2.5f, -5.0f}, vec3(1.0f), 8.0f);
  b.set_background(vec3(0.35f, 0.45f, 0.6f));
  b.set_ambient(0.03);
  set_default_view(b, {.eye = {0.0f, 1.6f, 1.0f}, .target = {0.0f, 0.4f, -5.5f}, .zfar = 2000.0});
}

}  // namespace

GeneratorEntry complexity_generator() {
  GeneratorInfo info;
  info.name = "complexity";
  info.description = "N triangles (1e5 to 1e8, within 1 %) of displaced tori and knots spread in depth (Kim's complexity sweep)";
  info.file_name = "complexity.glb";
  info.params = {{"triangles", 100000, 100000, 100000000, "total triangle count N", true}};
  return {info, build};
}

}  // namespace sb::scenes
