// `slanted-plane`: a finely tessellated plane slanted in depth, so that forward reprojection
// stretches it and opens cracks between reprojected samples.
#include "scenes/scene_generator.hpp"

namespace sb::scenes {

namespace {

void build(const GeneratorContext& ctx, GltfBuilder& b) {
  const float angle = static_cast<float>(degrees_to_radians(ctx.param("angle")));
  const int material = b.add_material("plane", vec3(0.6f));
  // 8 m x 5 m, 48 x 30 quads, turned about +Y so that its right edge recedes.
  const MeshData plane = transformed(make_plane({8.0f, 5.0f}, {48, 30}),
                                     translation({0.0f, 1.2f, -5.0f}) * rotation_y(angle) *
                                         rotation_x(0.5f * static_cast<float>(kPi)));
  b.add_node("plane", b.add_mesh("plane", plane, material));

  // From behind the camera's right, slightly from above: at the default angle cos = 0.9, so
  // E = 1.8 W/m^2 and L = 0.6/pi * 1.8 = 0.34.
  b.add_directional_light("sun", {-0.6f, -0.3f, -0.75f}, vec3(1.0f), 2.0f);
  b.set_background(vec3(0.0f));
  b.set_ambient(0.0);
  set_default_view(b, {.eye = {0.0f, 1.2f, 0.0f}, .target = {0.0f, 1.2f, -5.0f}, .zfar = 100.0});
}

}  // namespace

GeneratorEntry slanted_plane_generator() {
  GeneratorInfo info;
  info.name = "slanted-plane";
  info.description = "analytic: a tessellated plane slanted in depth (reprojection cracks)";
  info.file_name = "slanted-plane.gltf";
  info.analytic = true;
  info.params = {{"angle", 60.0, 0.0, 85.0, "turn of the plane about +Y (degrees; 0 faces the camera)"}};
  return {info, build};
}

}  // namespace sb::scenes
