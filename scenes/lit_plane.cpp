// `lit-plane`: one large Lambertian plane facing the camera, lit by one point light (or one
// directional light), for analytic radiance checks of the shading core.
#include "scenes/scene_generator.hpp"

namespace sb::scenes {

namespace {

void build(const GeneratorContext& ctx, GltfBuilder& b) {
  const float albedo = static_cast<float>(ctx.param("albedo"));
  // A 20 m x 20 m plane at z = -4 m, facing +Z (towards the camera at the origin).
  const int material = b.add_material("plane", vec3(albedo));
  const MeshData plane = transformed(make_plane({20.0f, 20.0f}, {8, 8}), translation({0, 0, -4}) * rotation_x(0.5f * static_cast<float>(kPi)));
  b.add_node("plane", b.add_mesh("plane", plane, material));

  if (ctx.int_param("directional") != 0) {
    // E = 2 W/m^2 * cos(theta) with cos(theta) = 1/sqrt(1.25): L = albedo/pi * 1.79.
    b.add_directional_light("sun", {0.3f, -0.4f, -1.0f}, vec3(1.0f), 2.0f);
  } else {
    // 2 m in front of the plane: E = 8/2^2 = 2 W/m^2 at the foot point, L = albedo/pi * 2.
    b.add_point_light("lamp", {0.6f, 0.8f, -2.0f}, vec3(1.0f), 8.0f);
  }
  b.set_background(vec3(0.0f));
  b.set_ambient(0.0);
  set_default_view(b, {.eye = {0, 0, 0}, .target = {0, 0, -4}, .zfar = 100.0});
}

}  // namespace

GeneratorEntry lit_plane_generator() {
  GeneratorInfo info;
  info.name = "lit-plane";
  info.description = "analytic: one large plane facing the camera, constant albedo, one point (or directional) light";
  info.file_name = "lit-plane.gltf";
  info.analytic = true;
  info.params = {
      {"directional", 0, 0, 1, "1: light the plane with one directional light instead of a point light", true},
      {"albedo", 0.5, 0.01, 1.0, "grey albedo of the plane"},
  };
  return {info, build};
}

}  // namespace sb::scenes
