// The POV-Ray SDL export without running POV-Ray: the distance that sets a point light's fade,
// the written lights, camera, materials and textures.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "renderer/error.hpp"
#include "renderer/io/image_io.hpp"
#include "support/scratch_dir.hpp"
#include "validation/providers/povray_export.hpp"

namespace sb {
namespace {

using validation::povray::export_scene;
using validation::povray::min_distance_to_scene;

Scene unit_square_scene() {
  Scene s;
  s.name = "square";
  Mesh m;
  m.name = "square";
  m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  m.indices = {0, 1, 2, 0, 2, 3};
  s.meshes.push_back(m);
  return s;
}

TEST(PovrayExport, MinDistanceToScene) {
  const Scene s = unit_square_scene();
  EXPECT_DOUBLE_EQ(min_distance_to_scene(s, {0.5, 0.5, 2.0}), 2.0);          // above the face
  EXPECT_DOUBLE_EQ(min_distance_to_scene(s, {2.0, 0.5, 0.0}), 1.0);          // beside an edge
  EXPECT_NEAR(min_distance_to_scene(s, {-3.0, -4.0, 0.0}), 5.0, 1e-12);      // off a vertex
  EXPECT_NEAR(min_distance_to_scene(s, {0.25, 0.75, -0.5}), 0.5, 1e-12);     // below, inside the diagonal
  EXPECT_TRUE(std::isinf(min_distance_to_scene(Scene{}, {0.0, 0.0, 0.0})));
}

TEST(PovrayExport, WritesCalibratedLightsCameraAndMaterials) {
  const test::ScratchDir dir;
  Scene s = unit_square_scene();
  s.background = vec3(0.1f, 0.2f, 0.3f);
  Light point;
  point.name = "lamp";
  point.position = vec3(0.5f, 0.5f, 2.0f);
  point.intensity = 8.0f;
  Light sun;
  sun.name = "sun";
  sun.type = Light::Type::directional;
  sun.direction = vec3(0.0f, 0.0f, -1.0f);
  sun.intensity = 2.0f;
  s.lights = {point, sun};
  const StereoRig rig(CameraPose::look_at({0.5, 0.5, 3.0}, {0.5, 0.5, 0.0}), RigParams{});
  const EyeCamera eye = rig.eye(Eye::right);
  const auto r = export_scene(s, eye, dir.path());
  const std::string sdl = test::read_text(r.sdl_file);

  ASSERT_EQ(r.lights.size(), 2u);
  // Point light: fd = 1e-4 * 2 m, colour I / (2 pi fd^2).
  EXPECT_DOUBLE_EQ(r.lights[0].min_distance, 2.0);
  EXPECT_DOUBLE_EQ(r.lights[0].fade_distance, 2e-4);
  EXPECT_NEAR(r.lights[0].colour[0], 8.0 / (2.0 * kPi * 4e-8), 1e-6 * r.lights[0].colour[0]);
  EXPECT_NEAR(r.lights[0].max_falloff_error, 1e-8, 1e-20);
  // Directional light: E / pi.
  EXPECT_NEAR(r.lights[1].colour[0], 2.0 / kPi, 1e-15);
  EXPECT_NE(sdl.find("fade_power 2"), std::string::npos);
  EXPECT_NE(sdl.find("parallel point_at"), std::string::npos);
  EXPECT_NE(sdl.find("background { rgb <0.100000001, 0.200000003, 0.300000012> }"), std::string::npos) << sdl;
  EXPECT_NE(sdl.find("assumed_gamma 1.0 ambient_light rgb 0"), std::string::npos);
  EXPECT_NE(sdl.find("diffuse 1 brilliance 1"), std::string::npos);
  EXPECT_NE(sdl.find("mesh2"), std::string::npos);
  EXPECT_NE(sdl.find("face_indices { 2"), std::string::npos);
  EXPECT_EQ(sdl.find("look_at"), std::string::npos);
  EXPECT_EQ(sdl.find("normal_vectors"), std::string::npos);  // the mesh has none
  EXPECT_EQ(r.triangles, 2u);
  EXPECT_TRUE(r.warnings.empty());
}

TEST(PovrayExport, BakesTexturesAndFlipsV) {
  const test::ScratchDir dir;
  Scene s = unit_square_scene();
  s.meshes[0].uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  s.meshes[0].material = 0;
  Texture t;
  t.name = "checker";
  t.width = 2;
  t.height = 2;
  t.rgba = {1, 1, 1, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1, 1};
  t.repeat_s = false;
  s.textures.push_back(t);
  Material m;
  m.base_color = vec4(0.5f, 0.25f, 1.0f, 1.0f);
  m.base_color_texture = 0;
  s.materials.push_back(m);
  s.meshes[0].uvs[1].x = 1.5f;  // read outside a clamped axis: reported
  const StereoRig rig(CameraPose::look_at({0.5, 0.5, 3.0}, {0.5, 0.5, 0.0}), RigParams{});
  const auto r = export_scene(s, rig.eye(Eye::right), dir.path());
  ASSERT_EQ(r.texture_files.size(), 1u);
  // Clamped along s: one replicated texel on each side (4 x 2), mapped back onto [0, 1].
  const Image baked = io::read_exr(r.texture_files[0]);
  ASSERT_EQ(baked.width(), 4);
  ASSERT_EQ(baked.height(), 2);
  for (const int x : {0, 1}) {
    EXPECT_FLOAT_EQ(baked.rgb_at(x, 0)[0], 0.5f) << x;
    EXPECT_FLOAT_EQ(baked.rgb_at(x, 0)[1], 0.25f) << x;
  }
  for (const int x : {2, 3}) EXPECT_FLOAT_EQ(baked.rgb_at(x, 0)[0], 0.0f) << x;
  const std::string sdl = test::read_text(r.sdl_file);
  EXPECT_NE(sdl.find("uv_mapping image_map { exr \"texture_0.exr\" interpolate 2 } scale <2, 1, 1> translate "
                     "<-0.5, 0, 0>"),
            std::string::npos)
      << sdl;
  EXPECT_NE(sdl.find("uv_vectors { 4,\n    <0, 1>"), std::string::npos) << sdl;  // v = 1 - v
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("clamps"), std::string::npos);
}

TEST(PovrayExport, SpotLightIsAnInputErrorAndWritesNothing) {
  const test::ScratchDir dir;
  Scene s = unit_square_scene();
  Light spot;
  spot.name = "spot-1";
  spot.type = Light::Type::spot;
  s.lights.push_back(spot);
  const StereoRig rig(CameraPose::look_at({0.5, 0.5, 3.0}, {0.5, 0.5, 0.0}), RigParams{});
  EXPECT_THROW((void)export_scene(s, rig.eye(Eye::right), dir / "out"), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

}  // namespace
}  // namespace sb
