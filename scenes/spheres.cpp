// `spheres`: randomly placed, (nearly) non-intersecting spheres of varied radius and colour
// filling a box in front of the camera, lit by five point lights — Al-Hagri et al.'s
// "Fixed Spheres" scene.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "scenes/procedural.hpp"
#include "scenes/scene_generator.hpp"

namespace sb::scenes {

namespace {

struct Sphere {
  vec3 centre;
  float radius;
};

/// A uniform grid over the volume for the overlap test (a std::vector of cells: deterministic).
class SphereGrid {
 public:
  SphereGrid(const vec3& lo, const vec3& hi, float cell) : lo_(lo), cell_(cell) {
    dims_ = glm::max(glm::ivec3(glm::ceil((hi - lo) / cell)), glm::ivec3(1));
    cells_.resize(static_cast<size_t>(dims_.x) * static_cast<size_t>(dims_.y) * static_cast<size_t>(dims_.z));
  }
  /// Whether `s` keeps `gap` clear of every sphere inserted so far.
  [[nodiscard]] bool free(const Sphere& s, float gap, float max_radius) const {
    const float reach = s.radius + max_radius + gap;
    const glm::ivec3 a = cell_of(s.centre - vec3(reach)), b = cell_of(s.centre + vec3(reach));
    for (int z = a.z; z <= b.z; ++z)
      for (int y = a.y; y <= b.y; ++y)
        for (int x = a.x; x <= b.x; ++x)
          for (const Sphere& o : cells_[index(x, y, z)])
            if (glm::length(o.centre - s.centre) < o.radius + s.radius + gap) return false;
    return true;
  }
  void insert(const Sphere& s) {
    const glm::ivec3 c = cell_of(s.centre);
    cells_[index(c.x, c.y, c.z)].push_back(s);
  }

 private:
  [[nodiscard]] glm::ivec3 cell_of(const vec3& p) const {
    return glm::clamp(glm::ivec3(glm::floor((p - lo_) / cell_)), glm::ivec3(0), dims_ - 1);
  }
  [[nodiscard]] size_t index(int x, int y, int z) const {
    return (static_cast<size_t>(z) * static_cast<size_t>(dims_.y) + static_cast<size_t>(y)) * static_cast<size_t>(dims_.x) +
           static_cast<size_t>(x);
  }
  vec3 lo_;
  float cell_;
  glm::ivec3 dims_;
  std::vector<std::vector<Sphere>> cells_;
};

void build(const GeneratorContext& ctx, GltfBuilder& b) {
  const int count = ctx.int_param("count");
  const int segments = ctx.int_param("segments");
  Rng rng(ctx.seed, 1);

  // The volume: 10 m wide, 6 m high, 3 m to 14 m in front of the camera at the origin; it spans
  // roughly the view frustum at its middle depth, so both near and far spheres are on screen.
  const vec3 lo(-5.0f, -3.0f, -14.0f), hi(5.0f, 3.0f, -3.0f);
  // Radii shrink a little with the count so that the volume fraction stays near 6 %.
  const float scale = std::cbrt(1000.0f / static_cast<float>(count));
  const float r_min = 0.07f * scale, r_max = 0.32f * scale;

  SphereGrid grid(lo, hi, 2.0f * r_max);
  std::vector<Sphere> spheres;
  spheres.reserve(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) {
    // Rejection sampling: try for a clear spot; after 64 misses accept the last candidate
    // ("non-intersecting-ish": only in very dense settings can spheres touch).
    Sphere s{};
    for (int attempt = 0; attempt < 64; ++attempt) {
      // Radii skewed towards small ones, as in a natural size distribution.
      const float u = static_cast<float>(rng.uniform());
      s.radius = r_min + (r_max - r_min) * u * u;
      s.centre = vec3(rng.uniformf(lo.x + s.radius, hi.x - s.radius), rng.uniformf(lo.y + s.radius, hi.y - s.radius),
                      rng.uniformf(lo.z + s.radius, hi.z - s.radius));
      if (grid.free(s, 0.02f * scale, r_max)) break;
    }
    grid.insert(s);
    spheres.push_back(s);
  }

  // One unit sphere, instanced by every node with its own radius (uniform scale) and material.
  MeshData unit = make_uv_sphere(1.0f, segments, std::max(2, segments / 2));
  unit.uvs.clear();
  const int geometry = b.add_geometry(unit, false);
  for (size_t i = 0; i < spheres.size(); ++i) {
    const float hue = static_cast<float>(rng.uniform());
    const float sat = rng.uniformf(0.35, 0.85);
    const float val = rng.uniformf(0.45, 0.9);
    // Double-sided, as exported scenes mostly are: a sphere is closed, and Kim's redirection culls
    // its back faces all the same (culled_meshes), while the ray tracer needs no back-face filter.
    const int material = b.add_material(fmt::format("sphere{:04d}", i), hsv_to_rgb(hue, sat, val));
    const int mesh = b.add_mesh(fmt::format("sphere{:04d}", i), {MeshPrimitive{geometry, material}});
    NodeTransform t;
    t.translation = dvec3(spheres[i].centre);
    t.scale = dvec3(static_cast<double>(spheres[i].radius));
    b.add_node(fmt::format("sphere{:04d}", i), mesh, t);
  }

  // Five point lights around and inside the volume. At the typical 4-6 m to a sphere each gives
  // E = 30/r^2 = 0.8-1.9 W/m^2; two or three together light a 0.7-albedo sphere to L ~ 0.3-0.8.
  const vec3 lights[5] = {{-4.0f, 3.5f, -4.0f}, {4.5f, 3.0f, -6.0f}, {0.0f, -2.5f, -8.5f}, {-3.5f, 0.5f, -13.0f}, {3.5f, -1.0f, -12.0f}};
  const vec3 tints[5] = {{1.0f, 0.95f, 0.85f}, {0.85f, 0.92f, 1.0f}, {1.0f, 1.0f, 1.0f}, {1.0f, 0.9f, 0.9f}, {0.9f, 1.0f, 0.92f}};
  for (int i = 0; i < 5; ++i) b.add_point_light(fmt::format("light{}", i), lights[i], tints[i], 30.0f);

  b.set_background(vec3(0.02f, 0.02f, 0.03f));
  b.set_ambient(0.02);
  // The volume's centre is 8.5 m away: the convergence plane cuts it in the middle.
  set_default_view(b, {.eye = {0, 0, 0}, .target = {0.0f, 0.0f, -8.5f}, .zfar = 200.0});
}

}  // namespace

GeneratorEntry spheres_generator() {
  GeneratorInfo info;
  info.name = "spheres";
  info.description = "1000 randomly placed spheres of varied radius and colour, 5 point lights (Al-Hagri's Fixed Spheres)";
  info.file_name = "spheres.glb";
  info.params = {
      {"count", 1000, 1, 100000, "number of spheres", true},
      {"segments", 24, 4, 256, "tessellation: segments around each sphere (rings = segments/2)", true},
  };
  return {info, build};
}

}  // namespace sb::scenes
