// A cut-out test scene (glTF alphaMode MASK): a red square with a checker of holes in front of a
// grey wall, lit so that its shadow falls on the wall; for the renderer's and the ground truths'
// cut-out tests.
#pragma once

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/io/gltf_loader.hpp"
#include "renderer/scene.hpp"
#include "scenes/gltf_builder.hpp"
#include "support/scratch_dir.hpp"

namespace sb::test {

/// What stands in front of the wall.
enum class Front { none, opaque, cutout_texture, cutout_factor };

/// A grey wall 3 m behind a 2 m red square at the origin, both facing a camera at (0, 0, 5), lit
/// by a point light beside the camera so that the square's shadow falls on the wall. The square
/// is `front`: absent, opaque, cut out by a 4x4 checker of alpha 0 and 255 (one period across
/// it), or cut out by its factor alone (base colour alpha `factor_alpha`).
inline Scene cutout_scene(const test::ScratchDir& dir, Front front, float factor_alpha = 1.0f, double cutoff = 0.5) {
  scenes::GltfBuilder b("cutout-test", 1);
  const int grey = b.add_material("wall", vec3(0.6f));
  scenes::MeshData wall;
  wall.add_quad(vec3(-6, -4, -3), vec3(6, -4, -3), vec3(6, 4, -3), vec3(-6, 4, -3), vec3(0, 0, 1));
  b.add_node("wall", b.add_mesh("wall", wall, grey));
  if (front != Front::none) {
    int texture = -1;
    if (front == Front::cutout_texture) {
      std::vector<uint8_t> rgba;
      for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) rgba.insert(rgba.end(), {230, 40, 40, static_cast<uint8_t>((x + y) % 2 ? 0 : 255)});
      texture = b.add_texture("checker", 4, 4, rgba);
    }
    const int red = b.add_material("square", vec4(0.8f, 0.1f, 0.1f, factor_alpha), texture);
    if (front == Front::cutout_texture || front == Front::cutout_factor) b.set_alpha_mask(red, cutoff);
    scenes::MeshData square;
    square.add_quad(vec3(-1, -1, 0), vec3(1, -1, 0), vec3(1, 1, 0), vec3(-1, 1, 0), vec3(0, 0, 1), 0.5f);
    b.add_node("square", b.add_mesh("square", square, red));
  }
  b.add_point_light("lamp", vec3(1.5f, 1.0f, 4.0f), vec3(1.0f), 40.0f);
  RigDefaults rig;
  rig.width = 160;
  rig.height = 120;
  rig.interaxial = 0.2;
  rig.convergence = 5.0;
  b.set_camera("camera", CameraPose::look_at(dvec3(0.0, 0.0, 5.0), dvec3(0.0)), 0.8, 0.05, 0.0, rig);
  const std::string name = "cutout.gltf";
  b.write(dir / name);
  return io::load_gltf(dir / name);
}

/// The file cutout_scene wrote into `dir`.
inline std::filesystem::path cutout_file(const ScratchDir& dir) { return dir / "cutout.gltf"; }

/// The KHR_texture_transform cutout_scene_transformed gives the checker: two periods across and
/// half of one down, turned by 0.4 rad and moved by a fifth of a period, so that a tool reading
/// the coordinates untransformed (or turned the other way) cuts different holes.
constexpr const char* kCheckerTransform = R"({"offset": [0.05, 0.3], "rotation": 0.4, "scale": [2.0, 0.5]})";

/// cutout_scene with the checker cut-out, its texture transformed (kCheckerTransform; the file
/// lists the extension as required), written as cutout-transformed.gltf and loaded.
inline Scene cutout_scene_transformed(const ScratchDir& dir) {
  (void)cutout_scene(dir, Front::cutout_texture);
  nlohmann::json doc = nlohmann::json::parse(read_text(cutout_file(dir)));
  for (nlohmann::json& m : doc["materials"])
    if (m["pbrMetallicRoughness"].contains("baseColorTexture"))
      m["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"] =
          nlohmann::json::parse(kCheckerTransform);
  doc["extensionsUsed"].push_back("KHR_texture_transform");
  doc["extensionsRequired"].push_back("KHR_texture_transform");
  std::ofstream(dir / "cutout-transformed.gltf", std::ios::trunc) << doc.dump();
  return io::load_gltf(dir / "cutout-transformed.gltf");
}

/// The file cutout_scene_transformed wrote into `dir`.
inline std::filesystem::path cutout_transformed_file(const ScratchDir& dir) { return dir / "cutout-transformed.gltf"; }

}  // namespace sb::test
