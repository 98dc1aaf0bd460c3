// A minimal, independent glTF reader for the scene tests: parses what the generators write (.glb
// and .gltf with a base64 buffer), flattens the node hierarchy and reads positions and indices,
// so that the tests check the files themselves rather than the generator's own bookkeeping.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/math.hpp"

namespace sb::test {

/// One mesh primitive placed in the world by a node.
struct ReadPrimitive {
  int node = -1;
  int mesh = -1;
  int material = -1;
  std::vector<vec3> positions;  ///< world space
  std::vector<vec3> normals;    ///< object space, as stored
  std::vector<vec2> uvs;        ///< TEXCOORD_0, or empty
  std::vector<uint32_t> indices;
};

/// A parsed glTF file.
struct ReadGltf {
  nlohmann::json doc;
  std::vector<unsigned char> bin;  ///< buffer 0
  std::vector<ReadPrimitive> primitives;
  std::vector<dmat4> node_world;  ///< world_from_node per node

  [[nodiscard]] size_t triangle_count() const;
  [[nodiscard]] size_t vertex_count() const;
  [[nodiscard]] Bounds3 bounds() const;
  /// Lights of a KHR_lights_punctual type ("point", "directional") placed by nodes.
  [[nodiscard]] size_t light_count(const std::string& type) const;
  /// World positions of the point lights.
  [[nodiscard]] std::vector<vec3> point_light_positions() const;
  /// Index of the node carrying the camera, or -1.
  [[nodiscard]] int camera_node() const;
};

/// Reads a .glb or .gltf written by the generators; throws std::runtime_error on anything
/// unexpected.
[[nodiscard]] ReadGltf read_gltf(const std::filesystem::path& path);

/// The bytes of a GLB's BIN chunk, or of a .gltf's decoded buffer (for "did the geometry change").
[[nodiscard]] std::vector<unsigned char> read_binary_payload(const std::filesystem::path& path);

}  // namespace sb::test
