// `thin-pole`: a thin vertical pole in front of a wall — the few-pixel-wide occluder whose
// reprojection leaves the bad pixels of Al-Hagri et al., Fig. 14.
#include "scenes/scene_generator.hpp"

namespace sb::scenes {

namespace {

void build(const GeneratorContext& ctx, GltfBuilder& b) {
  const float radius = static_cast<float>(ctx.param("radius"));
  const int floor_mat = b.add_material("floor", vec3(0.45f));
  const int wall_mat = b.add_material("wall", vec3(0.65f, 0.63f, 0.6f));
  const int pole_mat = b.add_material("pole", vec3(0.2f, 0.35f, 0.7f));

  // Floor from 1 m behind the camera to the wall at z = -4 m, which is 3 m high.
  b.add_node("floor", b.add_mesh("floor", transformed(make_plane({10.0f, 5.0f}, {4, 2}), translation({0, 0, -1.5f})), floor_mat));
  const MeshData wall =
      transformed(make_plane({10.0f, 3.0f}, {4, 2}), translation({0, 1.5f, -4}) * rotation_x(0.5f * static_cast<float>(kPi)));
  b.add_node("wall", b.add_mesh("wall", wall, wall_mat));
  // A 2.5 m pole at 2 m: with the default radius it is about 6 px wide at 1080 lines, while the
  // wall 2 m behind it shifts by about 24 px between the eyes.
  b.add_node("pole", b.add_mesh("pole", transformed(make_cylinder(radius, 2.5f, 16), translation({0, 0, -2})), pole_mat));

  b.add_point_light("lamp", {1.0f, 2.5f, -0.5f}, vec3(1.0f), 20.0f);
  b.set_background(vec3(0.0f));
  b.set_ambient(0.0);
  set_default_view(b, {.eye = {0.0f, 1.2f, 0.0f}, .target = {0.0f, 1.2f, -2.0f}, .zfar = 100.0});
}

}  // namespace

GeneratorEntry thin_pole_generator() {
  GeneratorInfo info;
  info.name = "thin-pole";
  info.description = "analytic: a thin vertical pole in front of a wall (the bad-pixel case of Al-Hagri Fig. 14)";
  info.file_name = "thin-pole.gltf";
  info.analytic = true;
  info.params = {{"radius", 0.004, 0.0005, 0.1, "radius of the pole (m)"}};
  return {info, build};
}

}  // namespace sb::scenes
