// `dragon`: a single high-polygon organic mesh — a serpentine dragon swept along a smooth 3-D
// curve, with head, tapering tail, dorsal spikes, scales, legs, claws, horns and whiskers — on a
// ground plane with one to ten point lights (five by default); it stands in for the Stanford Dragon.
#include <algorithm>
#include <cmath>
#include <functional>

#include <fmt/format.h>

#include "scenes/procedural.hpp"
#include "scenes/scene_generator.hpp"

namespace sb::scenes {

namespace {

constexpr float kTau = static_cast<float>(2.0 * kPi);

/// An arc-length parametrised smooth curve (a densely sampled Catmull-Rom spline).
class Curve {
 public:
  explicit Curve(const std::vector<vec3>& control) : points_(catmull_rom(control, 400)) {
    lengths_.resize(points_.size(), 0.0f);
    for (size_t i = 1; i < points_.size(); ++i) lengths_[i] = lengths_[i - 1] + glm::length(points_[i] - points_[i - 1]);
  }
  [[nodiscard]] float length() const { return lengths_.back(); }
  /// Point at arc length s (clamped).
  [[nodiscard]] vec3 at(float s) const {
    s = std::clamp(s, 0.0f, length());
    const auto it = std::upper_bound(lengths_.begin(), lengths_.end(), s);
    const size_t i = std::clamp<size_t>(static_cast<size_t>(it - lengths_.begin()), 1, points_.size() - 1);
    const float seg = lengths_[i] - lengths_[i - 1];
    const float t = seg > 0.0f ? (s - lengths_[i - 1]) / seg : 0.0f;
    return glm::mix(points_[i - 1], points_[i], t);
  }
  [[nodiscard]] vec3 tangent(float s) const {
    const float h = 0.002f * length();
    return glm::normalize(at(s + h) - at(s - h));
  }

 private:
  std::vector<vec3> points_;
  std::vector<float> lengths_;
};

/// A frame along a curve whose normal follows world up as closely as the tangent allows, so that
/// angle 0 around the tube is always the back (dorsal side) and pi the belly.
struct Frame {
  vec3 t, n, b;
};
Frame up_frame(const vec3& tangent) {
  Frame f;
  f.t = tangent;
  vec3 up = vec3(0, 1, 0) - glm::dot(vec3(0, 1, 0), tangent) * tangent;
  if (glm::length(up) < 1e-3f) up = vec3(1, 0, 0) - glm::dot(vec3(1, 0, 0), tangent) * tangent;
  f.n = glm::normalize(up);
  f.b = glm::cross(f.t, f.n);
  return f;
}

/// How a part is swept: its curve, its radius and surface displacement as functions of the
/// normalised arc length v in [0, 1] and the angle phi around it (0 = up).
struct SweepSpec {
  const Curve* curve = nullptr;
  std::function<float(float v)> radius;
  std::function<float(float v, float phi, const vec3& p)> displacement;  ///< along the radius, meters
  vec2 squash{1.0f, 1.0f};  ///< (sideways, up) scale of the cross-section
  int around = 8;
  int along = 2;
};

/// Triangles a sweep adds: its grid plus two end caps.
size_t sweep_triangles(int around, int along) { return 2u * static_cast<size_t>(around) * static_cast<size_t>(along + 1); }

/// Sweeps a closed cross-section along the curve; normals come from the displaced surface.
void add_sweep(MeshData& out, const SweepSpec& spec) {
  const int nu = spec.around, nv = spec.along;
  const float len = spec.curve->length();
  std::vector<vec3> pos;
  pos.reserve(static_cast<size_t>(nu + 1) * static_cast<size_t>(nv + 1));
  std::vector<Frame> frames(static_cast<size_t>(nv) + 1);
  for (int j = 0; j <= nv; ++j) {
    const float v = static_cast<float>(j) / nv;
    const float s = v * len;
    const vec3 c = spec.curve->at(s);
    const Frame f = up_frame(spec.curve->tangent(s));
    frames[static_cast<size_t>(j)] = f;
    const float r = spec.radius(v);
    for (int i = 0; i <= nu; ++i) {
      const float phi = kTau * static_cast<float>(i % nu) / nu;
      const vec3 dir = std::cos(phi) * f.n * spec.squash.y + std::sin(phi) * f.b * spec.squash.x;
      const vec3 p0 = c + r * dir;
      const float d = spec.displacement ? spec.displacement(v, phi, p0) : 0.0f;
      pos.push_back(c + (r + d) * dir);
    }
  }
  const std::vector<vec3> ends[2] = {
      std::vector<vec3>(pos.begin(), pos.begin() + nu + 1),
      std::vector<vec3>(pos.end() - (nu + 1), pos.end())};
  MeshData m = make_grid_surface(nu, nv, true, false, std::move(pos), vec2(1.0f));
  // Caps: fans over the (tiny) end rings.
  for (int e = 0; e < 2; ++e) {
    const Frame& f = frames[e == 0 ? 0 : static_cast<size_t>(nv)];
    const vec3 n = e == 0 ? -f.t : f.t;
    const std::vector<vec3>& ring = ends[e];
    vec3 centre(0.0f);
    for (int i = 0; i < nu; ++i) centre += ring[static_cast<size_t>(i)];
    centre /= static_cast<float>(nu);
    const uint32_t c = m.add_vertex(centre, n);
    const auto first = static_cast<uint32_t>(m.positions.size());
    for (int i = 0; i < nu; ++i) m.add_vertex(ring[static_cast<size_t>(i)], n);
    for (uint32_t i = 0; i < static_cast<uint32_t>(nu); ++i) {
      const uint32_t a = first + i, b = first + (i + 1) % static_cast<uint32_t>(nu);
      if (e == 1) m.add_triangle(c, a, b);
      else m.add_triangle(c, b, a);
    }
  }
  m.uvs.clear();
  append_mesh(out, m);
}

/// Grid size for a part of `budget` triangles whose length is `aspect` times its circumference.
ivec2 grid_for(size_t budget, float aspect, int min_around) {
  const int around = std::max(min_around, static_cast<int>(std::lround(std::sqrt(static_cast<double>(budget) / (2.0 * aspect)))));
  const int along = std::max(2, static_cast<int>(std::lround(static_cast<double>(budget) / (2.0 * around))) - 1);
  return {around, along};
}

/// Smooth interpolation of (v, value) keys.
float keyed(const std::vector<vec2>& keys, float v) {
  if (v <= keys.front().x) return keys.front().y;
  for (size_t k = 1; k < keys.size(); ++k)
    if (v <= keys[k].x) {
      const float t = (v - keys[k - 1].x) / (keys[k].x - keys[k - 1].x);
      return glm::mix(keys[k - 1].y, keys[k].y, t * t * (3.0f - 2.0f * t));
    }
  return keys.back().y;
}

/// Signed angular distance a - b wrapped to [-pi, pi].
float angle_diff(float a, float b) {
  float d = std::fmod(a - b + static_cast<float>(kPi), kTau);
  if (d < 0.0f) d += kTau;
  return d - static_cast<float>(kPi);
}

/// Overlapping scales in (arc length, angle): a shingle bump per cell, highest at its rear edge.
float scale_relief(float s_len, float phi, float scale_len, int around) {
  const float row = s_len / scale_len;
  const float ri = std::floor(row);
  const float shift = std::fmod(ri, 2.0f) * 0.5f;
  const float col = phi / kTau * static_cast<float>(around) + shift;
  const float fa = row - ri;
  const float fb = col - std::floor(col);
  const float across = 1.0f - (2.0f * fb - 1.0f) * (2.0f * fb - 1.0f);
  return std::pow(fa, 1.5f) * std::sqrt(std::max(0.0f, across));
}

void build(const GeneratorContext& ctx, GltfBuilder& b) {
  const auto target = static_cast<size_t>(ctx.param("triangles"));
  Rng rng(ctx.seed, 7);
  const auto noise_seed = static_cast<uint32_t>(rng.next());
  const auto jitter = [&rng](float a) { return rng.uniformf(-a, a); };

  // The body's spine: tail tip (resting on the ground) to snout tip, arched and winding, the neck
  // raised. Meters; the dragon is about 4.3 m long and 1.6 m high.
  std::vector<vec3> spine = {
      {-2.15f, 0.07f, -0.55f}, {-1.85f, 0.08f, -0.05f}, {-1.4f, 0.18f, 0.32f}, {-0.9f, 0.42f, 0.3f},
      {-0.4f, 0.62f, -0.05f},  {0.1f, 0.58f, -0.42f},   {0.62f, 0.5f, -0.3f},  {0.95f, 0.55f, 0.1f},
      {1.15f, 0.85f, 0.32f},   {1.22f, 1.22f, 0.26f},   {1.38f, 1.5f, 0.08f},  {1.72f, 1.52f, -0.02f},
      {1.98f, 1.43f, -0.06f}};
  for (size_t i = 1; i + 1 < spine.size(); ++i) spine[i] += vec3(jitter(0.04f), jitter(0.03f), jitter(0.04f));
  const Curve body_curve(spine);
  const float body_len = body_curve.length();

  // Body radius along the spine: thin tail, full belly, narrower neck, skull, tapering snout, with
  // rounded tips at both ends.
  const std::vector<vec2> radius_keys = {{0.0f, 0.006f}, {0.01f, 0.025f}, {0.12f, 0.065f}, {0.35f, 0.18f}, {0.52f, 0.25f},
                                         {0.66f, 0.23f}, {0.76f, 0.15f}, {0.83f, 0.135f}, {0.885f, 0.18f}, {0.93f, 0.145f},
                                         {0.985f, 0.08f}, {1.0f, 0.012f}};
  const auto body_radius = [&](float v) { return keyed(radius_keys, v); };
  const float v_head = 0.84f;  // where the head begins

  const auto body_relief = [&](float v, float phi, const vec3& p) {
    const float s_len = v * body_len;
    const float r = body_radius(v);
    float d = 0.0f;
    // Dorsal crest with backward-leaning spikes, fading out at the tail tip and on the snout.
    const float along = std::fmod(s_len / 0.075f, 1.0f);
    const float spike = along * along * (1.0f - along) * 6.75f;
    const float crest_fade = smooth(0.02f, 0.12f, v) * (1.0f - smooth(0.9f, 0.95f, v));
    const float dphi = angle_diff(phi, 0.0f);
    d += r * crest_fade * (0.1f + 0.5f * spike) * std::exp(-(dphi * dphi) / (0.09f * 0.09f));
    // Belly plates (transverse bands) underneath, shingled scales elsewhere.
    const float belly = std::exp(-std::pow(angle_diff(phi, static_cast<float>(kPi)) / 0.7f, 2.0f));
    const float plate = std::fmod(s_len / 0.045f, 1.0f);
    const float scale_amp = 0.035f * r * (1.0f - smooth(v_head, v_head + 0.03f, v));
    d += scale_amp * ((1.0f - belly) * scale_relief(s_len, phi, 0.03f, 40) + belly * std::pow(plate, 2.0f));
    // Irregular organic variation.
    d += 0.06f * r * fbm(p * 9.0f, noise_seed, 3);
    // Head: eye bulges, brow ridges, a mouth groove and nostrils.
    if (v > v_head) {
      for (float side : {1.0f, -1.0f}) {
        const float eye_phi = side * 1.15f;
        const float de = angle_diff(phi, eye_phi), dv = (v - 0.905f) * body_len;
        d += r * 0.28f * std::exp(-(de * de) / 0.05f - (dv * dv) / 0.0012f);
        const float db = angle_diff(phi, side * 0.75f), dvb = (v - 0.895f) * body_len;
        d += r * 0.22f * std::exp(-(db * db) / 0.03f - (dvb * dvb) / 0.004f);
        const float dm = angle_diff(phi, side * 1.95f);
        d -= r * 0.12f * smooth(0.9f, 0.93f, v) * std::exp(-(dm * dm) / 0.004f);
        const float dn = angle_diff(phi, side * 0.6f), dvn = (v - 0.99f) * body_len;
        d -= r * 0.25f * std::exp(-(dn * dn) / 0.02f - (dvn * dvn) / 0.0002f);
      }
    }
    return d;
  };

  // Triangle budgets: the body takes what the other parts leave, so the total lands on target.
  const auto part_budget = [&](double fraction) { return static_cast<size_t>(static_cast<double>(target) * fraction); };
  struct Part {
    std::vector<vec3> control;
    std::vector<vec2> radius;  ///< (v, radius) keys
    double share = 0.0;        ///< fraction of the triangle budget
    ivec2 grid{0};
  };
  std::vector<Part> parts;
  const auto attach = [&](float v, float side, float out, float down) {
    const float s = v * body_len;
    const Frame f = up_frame(body_curve.tangent(s));
    const float r = body_radius(v);
    return body_curve.at(s) + f.b * side * out * r - f.n * down * r;
  };
  // Legs: hip, knee, ankle, foot on the ground, each with four clawed toes.
  for (const auto& [v, fwd] : {std::pair{0.42f, -1.0f}, std::pair{0.7f, 1.0f}})
    for (float side : {1.0f, -1.0f}) {
      const float s = v * body_len;
      const Frame f = up_frame(body_curve.tangent(s));
      const vec3 hip = attach(v, side, 0.5f, 0.3f);
      vec3 lateral = f.b * side;
      lateral.y = 0.0f;
      lateral = glm::normalize(lateral);
      vec3 ahead = f.t;
      ahead.y = 0.0f;
      ahead = glm::normalize(ahead);
      const float hip_h = hip.y;
      const vec3 knee = hip + lateral * 0.22f + ahead * (0.1f * fwd) + vec3(0, 0.05f - 0.3f * hip_h, 0);
      const vec3 ankle = vec3(knee.x, 0.12f, knee.z) + lateral * 0.06f - ahead * 0.05f * fwd;
      const vec3 foot = vec3(ankle.x, 0.055f, ankle.z) + ahead * 0.06f;
      parts.push_back({{hip, knee, ankle, foot}, {{0.0f, 0.11f}, {0.45f, 0.075f}, {0.8f, 0.055f}, {1.0f, 0.06f}}, 0.026});
      for (int toe = 0; toe < 4; ++toe) {
        const float spread = (static_cast<float>(toe) - 1.5f) * 0.42f + jitter(0.08f);
        const vec3 dir = glm::normalize(ahead * std::cos(spread) + lateral * std::sin(spread));
        const vec3 t0 = foot + dir * 0.02f;
        const vec3 t1 = foot + dir * 0.11f + vec3(0, -0.01f, 0);
        const vec3 t2 = foot + dir * 0.18f + vec3(0, -0.035f, 0);
        const vec3 tip = foot + dir * 0.21f + vec3(0, -0.05f, 0);
        parts.push_back({{t0, t1, t2, tip}, {{0.0f, 0.027f}, {0.5f, 0.021f}, {0.8f, 0.012f}, {1.0f, 0.0015f}}, 0.0055});
      }
    }
  // Horns sweeping back from the skull, and long whiskers from the snout.
  for (float side : {1.0f, -1.0f}) {
    const float v = 0.885f;
    const Frame f = up_frame(body_curve.tangent(v * body_len));
    const vec3 base = attach(v, side, 0.45f, -0.75f);
    const vec3 back = -f.t;
    parts.push_back({{base, base + back * 0.12f + f.n * 0.1f + f.b * side * 0.04f,
                      base + back * 0.3f + f.n * 0.14f + f.b * side * 0.08f, base + back * 0.45f + f.n * 0.08f + f.b * side * 0.1f},
                     {{0.0f, 0.035f}, {0.4f, 0.026f}, {0.8f, 0.012f}, {1.0f, 0.002f}},
                     0.012});
    const vec3 w0 = attach(0.975f, side, 0.7f, 0.3f);
    const float wave = jitter(0.05f);
    parts.push_back({{w0, w0 + f.b * side * 0.12f + f.t * 0.05f, w0 + f.b * side * 0.28f - f.n * (0.1f + wave),
                      w0 + f.b * side * 0.38f - f.t * 0.15f - f.n * 0.25f, w0 + f.b * side * 0.42f - f.t * 0.3f - f.n * 0.3f},
                     {{0.0f, 0.009f}, {0.5f, 0.006f}, {1.0f, 0.0015f}},
                     0.006});
  }
  // Budgets: legs 2.6 % each, toes 0.55 % each, horns 1.2 %, whiskers 0.6 %; the body gets the
  // rest, about 77 %.
  std::vector<Curve> part_curves;
  part_curves.reserve(parts.size());
  size_t others = 0;
  for (Part& p : parts) {
    part_curves.emplace_back(p.control);
    const float mean_r = keyed(p.radius, 0.4f);
    const float aspect = part_curves.back().length() / (kTau * mean_r);
    p.grid = grid_for(part_budget(p.share), aspect, 8);
    others += sweep_triangles(p.grid.x, p.grid.y);
  }
  const size_t body_budget = target > others ? target - others : target / 2;
  // The body's rows are rounded to the budget: the whole mesh lands within one row of the target.
  const ivec2 body_grid = grid_for(body_budget, body_len / (kTau * 0.13f), 12);
  const int body_along = body_grid.y;

  MeshData dragon;
  dragon.reserve(static_cast<size_t>(body_grid.x + 1) * static_cast<size_t>(body_along + 1) * 11 / 10, target);
  add_sweep(dragon, {&body_curve, body_radius, body_relief, {1.1f, 0.92f}, body_grid.x, body_along});
  for (size_t i = 0; i < parts.size(); ++i) {
    const Part& p = parts[i];
    const auto radius = [&p](float v) { return keyed(p.radius, v); };
    const auto relief = [&p, noise_seed](float v, float, const vec3& q) {
      return 0.05f * keyed(p.radius, v) * fbm(q * 14.0f, noise_seed + 3u, 3);
    };
    add_sweep(dragon, {&part_curves[i], radius, relief, {1.0f, 1.0f}, p.grid.x, p.grid.y});
  }
  dragon.uvs.clear();

  const int dragon_mat = b.add_material("dragon", vec3(0.62f, 0.48f, 0.2f));
  b.add_node("dragon", b.add_mesh("dragon", dragon, dragon_mat));
  const int ground_mat = b.add_material("ground", vec3(0.45f, 0.45f, 0.44f));
  MeshData ground = make_plane({30.0f, 30.0f}, {16, 16});
  ground.uvs.clear();
  b.add_node("ground", b.add_mesh("ground", ground, ground_mat));

  // Key, fill, rim and two low lights, 2.5-4 m from the dragon: the key gives E = 30/3.2^2 =
  // 2.9 W/m^2 (L = 0.57 on the 0.62 albedo), the others 0.5-1.5 W/m^2 each. Lights 6-10 (for
  // light-count sweeps) fill the widest gaps in azimuth around the dragon, and one hangs overhead;
  // they stand 3.3-3.8 m from its middle and give 0.35-0.95 W/m^2 there, like the fill and low
  // lights. `lights` = N keeps the first N of the list: each N adds one light to the scene of
  // N - 1, and the default five never change.
  struct PointLight {
    const char* name;
    vec3 position;
    vec3 color;
    float intensity;
  };
  static const PointLight kLights[] = {
      {"key", {2.4f, 3.2f, 2.6f}, {1.0f, 0.96f, 0.9f}, 30.0f},
      {"fill", {-2.8f, 2.2f, 2.4f}, {0.85f, 0.9f, 1.0f}, 12.0f},
      {"rim", {0.5f, 3.0f, -3.0f}, {1.0f, 1.0f, 1.0f}, 18.0f},
      {"low_left", {-2.5f, 0.6f, -1.2f}, {1.0f, 0.9f, 0.8f}, 5.0f},
      {"low_right", {2.8f, 0.5f, -0.2f}, {0.9f, 1.0f, 0.9f}, 5.0f},
      {"front", {-0.2f, 1.6f, 3.3f}, {1.0f, 0.95f, 0.9f}, 10.0f},
      {"overhead", {0.2f, 4.2f, 0.0f}, {1.0f, 1.0f, 0.95f}, 11.0f},
      {"back_left", {-1.45f, 2.4f, -2.85f}, {0.85f, 0.9f, 1.0f}, 12.0f},
      {"back_right", {2.4f, 2.0f, -2.15f}, {1.0f, 0.95f, 0.85f}, 10.0f},
      {"side_low", {-3.4f, 0.8f, 0.8f}, {0.95f, 1.0f, 0.95f}, 5.0f},
  };
  const int light_count = ctx.int_param("lights");
  for (int i = 0; i < light_count; ++i) {
    const PointLight& l = kLights[static_cast<size_t>(i)];
    b.add_point_light(l.name, l.position, l.color, l.intensity);
  }

  b.set_background(vec3(0.05f, 0.05f, 0.06f));
  b.set_ambient(0.02);
  set_default_view(b, {.eye = {1.2f, 1.45f, 4.3f}, .target = {0.25f, 0.8f, 0.0f}, .zfar = 200.0});
}

}  // namespace

GeneratorEntry dragon_generator() {
  GeneratorInfo info;
  info.name = "dragon";
  info.description = "a single ~1.1 M-triangle organic mesh (a scaly serpentine dragon) on a ground plane, 5 point lights by default";
  info.file_name = "dragon.glb";
  info.params = {{"triangles", 1100000, 50000, 20000000, "triangles of the dragon mesh (within 1 %)", true},
                 {"lights", 5, 1, 10, "point lights: the first N of key, fill, rim, two low lights, then front, "
                  "overhead, two back lights and a low side light", true}};
  return {info, build};
}

}  // namespace sb::scenes
