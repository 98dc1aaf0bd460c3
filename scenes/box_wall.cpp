// `box-wall`: a box standing on a floor in front of a wall, one point light: hard shadows and the
// disocclusions a stereo reprojection has to fill.
#include "scenes/scene_generator.hpp"

namespace sb::scenes {

namespace {

void build(const GeneratorContext& ctx, GltfBuilder& b) {
  const float size = static_cast<float>(ctx.param("size"));
  const int floor_mat = b.add_material("floor", vec3(0.5f));
  const int wall_mat = b.add_material("wall", vec3(0.6f, 0.58f, 0.55f));
  const int box_mat = b.add_material("box", vec3(0.7f, 0.25f, 0.2f));

  // Floor 12 m wide, from 1 m behind the camera to the wall at z = -5 m, which is 3 m high.
  b.add_node("floor", b.add_mesh("floor", transformed(make_plane({12.0f, 8.0f}, {6, 4}), translation({0, 0, -1})), floor_mat));
  const MeshData wall =
      transformed(make_plane({12.0f, 3.0f}, {6, 2}), translation({0, 1.5f, -5}) * rotation_x(0.5f * static_cast<float>(kPi)));
  b.add_node("wall", b.add_mesh("wall", wall, wall_mat));
  b.add_node("box", b.add_mesh("box", make_box({-0.5f * size, 0.0f, -2.5f - 0.5f * size}, {0.5f * size, size, -2.5f + 0.5f * size}),
                               box_mat));

  // Up and to the left: the box shadows the floor and the wall to its right. E on the floor below
  // the light: 30 / 2.5^2 = 4.8 W/m^2 (L = 0.76); on the wall about 1.2 W/m^2.
  b.add_point_light("lamp", {-1.5f, 2.5f, 0.5f}, vec3(1.0f), 30.0f);
  b.set_background(vec3(0.0f));
  b.set_ambient(0.0);
  set_default_view(b, {.eye = {0.0f, 1.2f, 1.5f}, .target = {0.0f, 0.5f * size, -2.5f}, .zfar = 100.0});
}

}  // namespace

GeneratorEntry box_wall_generator() {
  GeneratorInfo info;
  info.name = "box-wall";
  info.description = "analytic: a box on a floor in front of a wall, one point light (shadows, disocclusions)";
  info.file_name = "box-wall.gltf";
  info.analytic = true;
  info.params = {{"size", 0.8, 0.1, 2.0, "edge length of the box (m)"}};
  return {info, build};
}

}  // namespace sb::scenes
