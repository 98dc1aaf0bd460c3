// A small deterministic glTF 2.0 writer for the scene generators: one binary buffer, meshes,
// materials with embedded PNG textures, a node hierarchy, KHR_lights_punctual lights and a
// camera carrying the stereobench rig defaults; written as .glb or as .gltf with embedded data.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/math.hpp"
#include "renderer/rig.hpp"
#include "renderer/scene.hpp"
#include "scenes/primitives.hpp"

namespace sb::scenes {

/// A node's local transform: translation, rotation, scale, or a full matrix (which must be
/// decomposable into TRS, as glTF requires).
struct NodeTransform {
  dvec3 translation{0.0};
  dquat rotation{1.0, 0.0, 0.0, 0.0};  ///< glm order (w, x, y, z); unit length
  dvec3 scale{1.0};
  std::optional<dmat4> matrix;  ///< when set, written instead of TRS

  /// Translation only.
  static NodeTransform at(const dvec3& t) { return NodeTransform{t}; }
  /// Translation, rotation about +Y (radians) and uniform scale.
  static NodeTransform trs(const dvec3& t, double yaw, double uniform_scale = 1.0);
};

/// Index component type of a geometry's indices.
enum class IndexType { automatic, uint16, uint32 };

/// One glTF primitive of a mesh: a geometry drawn with a material.
struct MeshPrimitive {
  int geometry = -1;
  int material = -1;
};

/// Counts of what a builder holds, with meshes counted once per node that instances them (as a
/// loader that flattens the node hierarchy sees them).
struct SceneStats {
  size_t triangles = 0;
  size_t vertices = 0;
  size_t lights = 0;
  size_t point_lights = 0;
  size_t directional_lights = 0;
  size_t nodes = 0;
  size_t meshes = 0;
  size_t materials = 0;
  size_t textures = 0;
};

/// Builds one glTF asset in memory and writes it. Object indices are returned by the add_*
/// functions in the order of the glTF arrays; the output depends only on the calls made (the
/// JSON keys are sorted, numbers are printed in shortest round-trip form), so the same calls
/// give a byte-identical file.
class GltfBuilder {
 public:
  /// `generator` and `seed` go into the scene's extras together with the parameters.
  GltfBuilder(std::string generator, uint64_t seed, std::map<std::string, double> params = {});

  /// A Lambertian material: linear base colour factor, optional base colour texture (-1: none).
  int add_material(const std::string& name, const vec4& base_color, int texture = -1, bool double_sided = true);
  /// Convenience: an opaque colour.
  int add_material(const std::string& name, const vec3& base_color, int texture = -1, bool double_sided = true) {
    return add_material(name, vec4(base_color, 1.0f), texture, double_sided);
  }
  /// Makes a material a cut-out: glTF alphaMode MASK with `cutoff` (the alpha is the base colour
  /// factor's times the texture's).
  void set_alpha_mask(int material, double cutoff = 0.5);
  /// A base colour texture from RGBA8 sRGB pixels (row 0 at the top), embedded as PNG (stored as
  /// RGB when every alpha is 255) and sampled with REPEAT and LINEAR_MIPMAP_LINEAR.
  int add_texture(const std::string& name, int width, int height, std::span<const uint8_t> rgba8);

  /// Stores a geometry's vertex and index data (positions with min/max, unit normals, UVs when
  /// `with_uvs` and present) and returns its handle; meshes can share it.
  int add_geometry(const MeshData& mesh, bool with_uvs = true, IndexType index_type = IndexType::automatic);
  /// A mesh of one or more primitives.
  int add_mesh(const std::string& name, const std::vector<MeshPrimitive>& primitives);
  /// A mesh of one primitive; UVs are written only if the material has a texture.
  int add_mesh(const std::string& name, const MeshData& mesh, int material,
               IndexType index_type = IndexType::automatic);
  /// A node instancing `mesh` (-1: none) under `parent` (-1: a root of the scene).
  int add_node(const std::string& name, int mesh, const NodeTransform& transform = {}, int parent = -1);

  /// A point light of `intensity` W/sr (glTF's candela read radiometrically) at `position`.
  int add_point_light(const std::string& name, const vec3& position, const vec3& color, float intensity,
                      int parent = -1);
  /// A directional light travelling along `direction` with irradiance `intensity` W/m^2.
  int add_directional_light(const std::string& name, const vec3& direction, const vec3& color, float intensity,
                            int parent = -1);

  /// The scene's default camera: a node at the pose with a perspective camera (`yfov` radians,
  /// aspect from the rig size) and `extras.stereobench` {interaxial, convergence, width, height}.
  /// Returns the camera's node.
  int set_camera(const std::string& name, const CameraPose& pose, double yfov, double znear, double zfar,
                 const RigDefaults& rig);
  /// Keys one property of a node in the scene's animation: `property` "translation", "scale"
  /// (3 floats per key) or "rotation" (x, y, z, w per key); `interpolation` "LINEAR", "STEP" or
  /// "CUBICSPLINE" (then in-tangent, value and out-tangent per key). The channel goes into the
  /// glTF animation (clip) named `clip`, created at its first channel. Returns the channel's index
  /// within its clip.
  int add_animation_channel(int node, const std::string& property, std::span<const float> times,
                            std::span<const float> values, const std::string& interpolation = "LINEAR",
                            const std::string& clip = "animation");
  /// Radiance of rays that miss (scene extras).
  void set_background(const vec3& rgb) { background_ = rgb; }
  /// The ambient term of DESIGN §3 (scene extras).
  void set_ambient(double ambient) { ambient_ = ambient; }
  /// Reserve room in the binary buffer for `bytes` more bytes (large generated scenes).
  void reserve_buffer(size_t bytes) { bin_.reserve(bin_.size() + bytes); }

  [[nodiscard]] const SceneStats& stats() const { return stats_; }
  /// Size of the binary buffer so far.
  [[nodiscard]] size_t buffer_bytes() const { return bin_.size(); }

  /// The glTF JSON document (buffers[0] without a uri).
  [[nodiscard]] nlohmann::json document() const;
  /// Writes `.glb` (binary container) or `.gltf` (buffer embedded as a base64 data URI),
  /// atomically; returns the file size. InputError for another extension or a GLB over 4 GiB,
  /// IoError if the file cannot be written.
  size_t write(const std::filesystem::path& path) const;

 private:
  struct Geometry {
    int position = -1, normal = -1, uv = -1, indices = -1;
    size_t vertices = 0, triangles = 0;
  };
  struct MeshCounts {
    size_t vertices = 0, triangles = 0;
  };

  int add_buffer_view(const void* data, size_t bytes, int target);
  int add_accessor(int buffer_view, int component_type, size_t count, const char* type,
                   const nlohmann::json& min = nullptr, const nlohmann::json& max = nullptr);
  int add_light_node(const std::string& name, const nlohmann::json& light, const NodeTransform& transform, int parent);
  void count_instance(int mesh);

  std::string generator_;
  uint64_t seed_ = 0;
  std::map<std::string, double> params_;
  vec3 background_{0.0f};
  double ambient_ = 0.0;

  std::vector<unsigned char> bin_;
  nlohmann::json buffer_views_ = nlohmann::json::array();
  nlohmann::json accessors_ = nlohmann::json::array();
  nlohmann::json materials_ = nlohmann::json::array();
  nlohmann::json textures_ = nlohmann::json::array();
  nlohmann::json images_ = nlohmann::json::array();
  nlohmann::json meshes_ = nlohmann::json::array();
  nlohmann::json nodes_ = nlohmann::json::array();
  nlohmann::json lights_ = nlohmann::json::array();
  nlohmann::json cameras_ = nlohmann::json::array();
  /// The animations in the order of their first channel: name, channels and samplers.
  nlohmann::json animations_ = nlohmann::json::array();
  std::vector<int> roots_;
  std::vector<Geometry> geometries_;
  std::vector<MeshCounts> mesh_counts_;
  std::vector<bool> material_textured_;
  SceneStats stats_;
};

}  // namespace sb::scenes
