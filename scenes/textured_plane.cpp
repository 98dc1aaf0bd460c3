// `textured-plane`: a large ground plane with a high-frequency checker seen at grazing angles, so
// that every mip level is in view (texture level-of-detail tests).
#include "scenes/scene_generator.hpp"
#include "scenes/textures.hpp"

namespace sb::scenes {

namespace {

void build(const GeneratorContext& ctx, GltfBuilder& b) {
  const float repeats_per_meter = static_cast<float>(ctx.param("frequency"));
  // 256 x 256 texels, 32 x 32 checks of 8 texels: the mip chain averages to a known grey.
  const int texture = add_texture(b, "checker", checker_texture(256, 32, vec3(0.8f), vec3(0.05f)));
  const int material = b.add_material("checker", vec3(1.0f), texture);
  // 200 m x 200 m, 20 x 20 quads so that no triangle spans the whole depth range.
  const MeshData ground = transformed(make_plane({200.0f, 200.0f}, {20, 20}, repeats_per_meter), translation({0, 0, -95}));
  b.add_node("ground", b.add_mesh("ground", ground, material));

  // E = 2.5 * 0.86 W/m^2: white checks L = 0.8/pi * 2.15 = 0.55.
  b.add_directional_light("sun", {0.3f, -1.0f, -0.5f}, vec3(1.0f), 2.5f);
  b.set_background(vec3(0.3f, 0.4f, 0.6f));
  b.set_ambient(0.0);
  set_default_view(b, {.eye = {0.0f, 1.0f, 0.0f}, .target = {0.0f, 0.0f, -12.0f}, .zfar = 1000.0});
}

}  // namespace

GeneratorEntry textured_plane_generator() {
  GeneratorInfo info;
  info.name = "textured-plane";
  info.description = "analytic: a large ground plane with a high-frequency checker at grazing angles (mip levels)";
  info.file_name = "textured-plane.gltf";
  info.analytic = true;
  info.params = {{"frequency", 0.5, 0.01, 10.0, "texture repeats per meter (each repeat has 32 x 32 checks)"}};
  return {info, build};
}

}  // namespace sb::scenes
