// Loads glTF 2.0 scenes (.gltf with external or embedded buffers, .glb) into sb::Scene.
#pragma once

#include <cstdint>
#include <filesystem>

#include "renderer/scene.hpp"

namespace sb::io {

/// The most triangles a scene may expand to (instancing included); load_gltf refuses more.
inline constexpr uint64_t kMaxSceneTriangles = 1'500'000'000;

struct GltfLoadOptions {
  bool load_textures = true;  ///< decode base colour textures (off: materials keep their factor only)
};

/// Loads a scene. Every fault in the file — malformed JSON, wrong types, references or accessors
/// out of range, missing or truncated buffers — throws InputError naming the file and the JSON
/// pointer of the fault. Features the renderer does not support are reported once each in
/// Scene::warnings, never silently dropped.
[[nodiscard]] Scene load_gltf(const std::filesystem::path& path, const GltfLoadOptions& options = {});

/// Version of the glTF loading library, for provenance records.
[[nodiscard]] const char* gltf_loader_version();

}  // namespace sb::io
