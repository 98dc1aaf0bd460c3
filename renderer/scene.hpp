// The in-memory scene every pipeline renders: world-space triangle meshes, materials, textures,
// punctual lights and cameras, as loaded from glTF (renderer/io/gltf_loader.hpp).
#pragma once

#include <array>
#include <cstdint>
#include <cmath>
#include <optional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "renderer/math.hpp"

namespace sb {

/// A base colour texture: linear RGBA float, row 0 at the top of the image.
struct Texture {
  std::string name;
  int width = 0;
  int height = 0;
  std::vector<float> rgba;  ///< width * height * 4, linear (sRGB decoded)
  bool repeat_s = true;     ///< glTF wrapS REPEAT (else CLAMP_TO_EDGE; MIRRORED_REPEAT is reported)
  bool repeat_t = true;
};

/// Lambertian material (DESIGN §3): albedo = base colour factor x base colour texture.
struct Material {
  /// glTF alphaMode. `mask` cuts the surface out where its alpha (base colour factor alpha x base
  /// colour texture alpha) is below alpha_cutoff: rays and the rasterizer pass through there, shadow
  /// rays too (SceneGeometry::opaque_at). `blend` is rendered as opaque (reported by the loader).
  enum class AlphaMode { opaque, mask, blend };
  std::string name;
  vec4 base_color{1.0f};
  int base_color_texture = -1;  ///< index into Scene::textures, or -1
  int texcoord = 0;             ///< which TEXCOORD_n set the texture reads
  /// The base colour texture's KHR_texture_transform in glTF texture space: a texture coordinate
  /// (u, v) reads (t[0] u + t[1] v + t[2], t[3] u + t[4] v + t[5]). The loader has applied it to
  /// the meshes' uvs already; it is kept for a tool that reads the file's own coordinates (Blender).
  std::array<double, 6> uv_transform{1.0, 0.0, 0.0, 0.0, 1.0, 0.0};
  [[nodiscard]] bool has_uv_transform() const {
    return uv_transform != std::array<double, 6>{1.0, 0.0, 0.0, 0.0, 1.0, 0.0};
  }
  bool double_sided = false;    ///< glTF doubleSided
  AlphaMode alpha_mode = AlphaMode::opaque;
  float alpha_cutoff = 0.5f;    ///< glTF alphaCutoff (mask only): opaque where alpha >= alpha_cutoff
};

/// A triangle mesh in world space (one glTF primitive instanced by one node).
struct Mesh {
  std::string name;
  int node = -1;       ///< glTF node index that instanced it
  /// Which of its node's EXT_mesh_gpu_instancing instances it is; -1 where the node has none.
  int instance = -1;
  /// Posed by a glTF skin (its vertices placed by its joints, not by its node).
  bool skinned = false;
  int material = -1;   ///< index into Scene::materials; -1 = default white material
  std::vector<vec3> positions;
  std::vector<vec3> normals;  ///< empty, or one per position (shading normals, world space)
  /// The file gives vertex normals that were dropped (some have length zero): the mesh is shaded
  /// with its geometric normals, where a tool importing the file itself would use them.
  bool file_normals_dropped = false;
  std::vector<vec2> uvs;      ///< empty, or one per position (the material's TEXCOORD set)
  std::vector<uint32_t> indices;  ///< three per triangle
  /// For a mesh on an animated node (Scene::animation moves its node): its vertices and normals in
  /// the node's own space, where the animation's world transform of each frame places them; empty
  /// otherwise.
  std::vector<vec3> local_positions, local_normals;
  /// Whether its triangles are in reversed order, for a world transform that mirrors (negative
  /// determinant), so that they keep facing the way the file says.
  bool mirrored = false;
  /// The affine world-space transform that takes it from where the scene file places it to where
  /// it is now: the identity as loaded; a path's frame (renderer/animation.hpp) sets it with the
  /// positions. A ground truth that imports the scene file itself (Blender) places the node with it.
  /// Not finite where no transform does (a node scaled to nothing in the file).
  dmat4 moved{1.0};

  [[nodiscard]] size_t triangle_count() const { return indices.size() / 3; }
  /// Whether triangle t has zero area (its vertices coincide or lie on one line): it covers no
  /// pixel and no ray hits it.
  [[nodiscard]] bool zero_area(size_t t) const;
  /// Whether the mesh is closed and wound outwards: every edge of a triangle with three distinct
  /// corners (by position, so that vertices repeated along a seam count as one) is met as often in
  /// one direction as in the other (once each, or more where closed parts share an edge), and each
  /// part (triangles joined across the edges met once each way) encloses a positive volume
  /// (triangles counter-clockwise seen from outside). An eye outside such a mesh never sees a back
  /// face of it, unless its surface intersects itself (not checked).
  [[nodiscard]] bool is_closed() const;
};

/// A punctual light (KHR_lights_punctual). Intensity is used as radiometric: a point light of
/// intensity I emits I W/sr (glTF's candela read as W/sr), a directional light of intensity E
/// gives irradiance E W/m^2 on a surface facing it.
struct Light {
  enum class Type { point, directional, spot };
  std::string name;
  Type type = Type::point;
  vec3 position{0.0f};
  vec3 direction{0.0f, 0.0f, -1.0f};  ///< direction the light travels (world space, unit)
  vec3 color{1.0f};
  float intensity = 1.0f;
  float range = 0.0f;  ///< 0 = infinite
  float inner_cone = 0.0f;
  float outer_cone = 0.78539816f;
  int node = -1;  ///< the glTF node that places it (-1: none); an animation along a path moves it

  /// Places the light by its node's world transform, as KHR_lights_punctual does: at the node's
  /// origin, shining down its -Z (scale does not matter; scaled to nothing, down world -Z).
  void place(const dmat4& world);
};

/// Largest coordinate magnitude, in metres, a scene may use: vertices, cameras and lights. Embree
/// rejects ray origins beyond about 1.8e18; this leaves room for the scale-aware shadow-ray offset
/// and is far beyond any real scene (the Earth lies 1.5e11 m from the Sun).
inline constexpr double kMaxSceneCoordinate = 1e15;

/// Whether every component of p is finite and within ±kMaxSceneCoordinate.
template <class Vec>
[[nodiscard]] bool within_scene_range(const Vec& p) {
  for (int k = 0; k < 3; ++k)
    if (!(std::abs(static_cast<double>(p[k])) <= kMaxSceneCoordinate)) return false;
  return true;
}

/// A perspective camera placed in the scene.
struct SceneCamera {
  std::string name;
  int node = -1;
  dmat4 world_from_camera{1.0};  ///< camera looks down its -Z, +Y up
  double yfov = 0.8;             ///< radians
  double aspect = 0.0;           ///< 0 = not given
  double znear = 0.01;
  double zfar = 0.0;             ///< 0 = infinite
};

/// Stereo-rig defaults stored by a scene in its camera node's `extras.stereobench`.
struct RigDefaults {
  std::optional<double> interaxial;   ///< m
  std::optional<double> convergence;  ///< m
  std::optional<int> width;
  std::optional<int> height;
  std::string where;  ///< JSON path of the extras they came from ("/nodes/4/extras/stereobench"), or empty
};

/// The glTF node animations of a scene (translation, rotation and scale channels) with the node
/// hierarchy they move: a node's world transform at any time, for camera paths and rigid node
/// animation (renderer/animation.hpp). Meshes and cameras are stored at rest (the nodes' own TRS).
struct NodeAnimation {
  /// A node's local transform at rest: TRS, or a matrix (glTF forbids animating a node with one).
  struct Local {
    dvec3 translation{0.0};
    dquat rotation{1.0, 0.0, 0.0, 0.0};  ///< glm order (w, x, y, z), unit length
    dvec3 scale{1.0};
    std::optional<dmat4> matrix;

    /// The matrix, or T * R * S.
    [[nodiscard]] dmat4 transform() const;
  };
  enum class Property { translation, rotation, scale };
  enum class Interpolation { linear, step, cubic_spline };
  /// One channel: a property of a node keyed over time.
  struct Channel {
    int clip = 0;  ///< the glTF animation it belongs to (index into clips)
    int node = -1;
    Property property = Property::translation;
    Interpolation interpolation = Interpolation::linear;
    std::vector<double> times;   ///< strictly increasing, seconds
    /// Per key: the value (3 numbers, 4 for a rotation x, y, z, w); for a cubic spline the in-tangent,
    /// the value and the out-tangent, in that order.
    std::vector<double> values;
  };

  std::vector<int> parent;    ///< per glTF node: its parent in the loaded scene, -1 for a root or a node outside it
  std::vector<Local> local;   ///< per glTF node: its rest transform
  std::vector<std::string> clips;  ///< per glTF animation: its name ("" when it has none)
  /// The node of every light the loaded scene places, before any are dropped (keep_first_lights):
  /// what an animation moves, and so its time range, does not depend on how many lights are kept.
  std::vector<int> light_nodes;
  std::vector<Channel> channels;

  [[nodiscard]] bool empty() const { return channels.empty(); }
  /// A clip as messages name it: 'name', or #index where it has none.
  [[nodiscard]] std::string clip_label(size_t clip) const;
  /// Every clip's label, comma-separated.
  [[nodiscard]] std::string clip_list() const;
  /// The first and the last key time over the channels that move one of `nodes` (a channel on the
  /// node itself or on an ancestor); (0, 0) when none does.
  [[nodiscard]] std::pair<double, double> time_range(const std::vector<int>& nodes) const;
  /// Whether `node` or one of its ancestors is animated.
  [[nodiscard]] bool moves(int node) const;
  /// The node's world transform at `time` (before the first key: the first; after the last: the
  /// last, as glTF clamps).
  [[nodiscard]] dmat4 world(int node, double time) const;
  /// The node's world transform at rest (every node at its own transform, as the file places it).
  [[nodiscard]] dmat4 rest_world(int node) const;

 private:
  [[nodiscard]] dmat4 local_at(int node, double time) const;
  /// Whether `ancestor` is `node` or one of its ancestors in the loaded hierarchy.
  [[nodiscard]] bool above(int ancestor, int node) const;
};

/// A loaded scene.
struct Scene {
  std::string path;  ///< file it came from
  /// The external files its buffers and images were read from (beside `path`): an output of a
  /// run must not take the place of one.
  std::vector<std::string> files_read;
  std::string name;
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  std::vector<Texture> textures;
  std::vector<Light> lights;
  std::vector<SceneCamera> cameras;
  RigDefaults rig;            ///< from the first camera that carries stereobench extras
  vec3 background{0.0f};      ///< radiance of rays that miss (scene extras)
  float ambient = 0.0f;       ///< ambient term of DESIGN §3 (scene extras)
  std::vector<std::string> warnings;  ///< unsupported features, each named once
  NodeAnimation animation;            ///< glTF node animations, played along a path only
  /// Nodes of the file with a mesh or light that the loaded glTF scene does not reach (those of
  /// another scene, or of none): not part of this scene.
  size_t nodes_not_loaded = 0;
  /// Per node drawn by EXT_mesh_gpu_instancing: each instance's transform in the node's space
  /// (Mesh::instance indexes it). A ground truth that imports the file (Blender, whose importer
  /// does not read the extension) places the copies with it.
  std::map<int, std::vector<dmat4>> instances;

  [[nodiscard]] size_t triangle_count() const;
  /// Triangles of zero area (Mesh::zero_area); one pass over every triangle.
  [[nodiscard]] size_t zero_area_triangle_count() const;
  /// Whether some triangle has a non-zero area; stops at the first one found.
  [[nodiscard]] bool has_triangle_with_area() const;
  /// Whether some material is a cut-out (glTF alphaMode MASK).
  [[nodiscard]] bool has_cutouts() const;
  [[nodiscard]] size_t vertex_count() const;
  [[nodiscard]] Bounds3 bounds() const;
  /// The start of output file names and reference ids: the stem of the file the scene was loaded
  /// from (`path`; `name` for a scene made in memory). Exporters give every scene one name (Blender's
  /// "Scene"), so two files' outputs in one folder would replace each other under `name`. Characters
  /// other than ASCII letters, digits and ._-+ become '_', a leading '.' too, at most 64 bytes,
  /// "scene" when nothing is left: outputs stay in the folder they are written to.
  [[nodiscard]] std::string file_stem() const;
};

/// Keeps the scene's first `count` lights in file order and drops the rest; call it after loading
/// and before building the RenderScene. InputError naming the scene, the count and the scene's
/// number of lights when `count` < 1 or more than the scene has.
void keep_first_lights(Scene& scene, int count);

/// True when nothing lights the scene: no light with a non-zero intensity and colour, and no
/// ambient term. Every surface of such a scene renders black.
[[nodiscard]] bool is_unlit(const Scene& scene);

}  // namespace sb
