// The deterministic glTF 2.0 writer used by the scene generators.
#include "scenes/gltf_builder.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/image_io.hpp"
#include "sb_version.hpp"

namespace sb::scenes {

using nlohmann::json;

namespace {

// glTF enumerations.
constexpr int kArrayBuffer = 34962;
constexpr int kElementArrayBuffer = 34963;
constexpr int kUnsignedShort = 5123;
constexpr int kUnsignedInt = 5125;
constexpr int kFloat = 5126;
constexpr int kLinear = 9729;
constexpr int kLinearMipmapLinear = 9987;
constexpr int kRepeat = 10497;

constexpr uint32_t kGlbMagic = 0x46546C67;  // "glTF"
constexpr uint32_t kChunkJson = 0x4E4F534A;  // "JSON"
constexpr uint32_t kChunkBin = 0x004E4942;   // "BIN\0"

json vec_json(const dvec3& v) { return json::array({v.x, v.y, v.z}); }

/// Unit quaternion of an orthonormal basis (columns right, up, back), as glTF's [x, y, z, w].
dquat basis_rotation(const dvec3& right, const dvec3& up, const dvec3& back) {
  return glm::normalize(glm::quat_cast(dmat3(right, up, back)));
}

/// Rotation taking the node's -Z onto `direction` (unit), keeping +Y up where possible.
dquat rotation_towards(const dvec3& direction) {
  const dvec3 back = -glm::normalize(direction);
  dvec3 right = glm::cross(dvec3(0.0, 1.0, 0.0), back);
  if (glm::length(right) < 1e-9) right = glm::cross(dvec3(0.0, 0.0, -1.0), back);
  right = glm::normalize(right);
  return basis_rotation(right, glm::cross(back, right), back);
}

void check_finite(const vec3& v, const char* what, const std::string& name) {
  if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
    throw std::logic_error(fmt::format("glTF builder: non-finite {} in '{}'", what, name));
}

/// Standard base64 of a byte range (with padding), appended to `out`.
void base64_append(std::string& out, const unsigned char* data, size_t size) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  size_t i = 0;
  for (; i + 2 < size; i += 3) {
    const uint32_t v = (uint32_t{data[i]} << 16) | (uint32_t{data[i + 1]} << 8) | data[i + 2];
    out.push_back(kAlphabet[(v >> 18) & 63]);
    out.push_back(kAlphabet[(v >> 12) & 63]);
    out.push_back(kAlphabet[(v >> 6) & 63]);
    out.push_back(kAlphabet[v & 63]);
  }
  if (i < size) {
    uint32_t v = uint32_t{data[i]} << 16;
    if (i + 1 < size) v |= uint32_t{data[i + 1]} << 8;
    out.push_back(kAlphabet[(v >> 18) & 63]);
    out.push_back(kAlphabet[(v >> 12) & 63]);
    out.push_back(i + 1 < size ? kAlphabet[(v >> 6) & 63] : '=');
    out.push_back('=');
  }
}

void put_u32(std::ofstream& out, uint32_t v) {
  const std::array<unsigned char, 4> b = {static_cast<unsigned char>(v), static_cast<unsigned char>(v >> 8),
                                          static_cast<unsigned char>(v >> 16), static_cast<unsigned char>(v >> 24)};
  out.write(reinterpret_cast<const char*>(b.data()), 4);
}

/// A scene file's write that failed (a full disk, a lost folder): names the file, not its
/// temporary, with the cause.
[[noreturn]] void write_failed(const std::filesystem::path& path, size_t bytes) {
  throw IoError(fmt::format("cannot write the scene file {} ({} bytes): {}; check free disk space and the folder's "
                            "permissions",
                            path.string(), bytes, std::strerror(errno)));
}

}  // namespace

NodeTransform NodeTransform::trs(const dvec3& t, double yaw, double uniform_scale) {
  NodeTransform x;
  x.translation = t;
  x.rotation = glm::angleAxis(yaw, dvec3(0.0, 1.0, 0.0));
  x.scale = dvec3(uniform_scale);
  return x;
}

GltfBuilder::GltfBuilder(std::string generator, uint64_t seed, std::map<std::string, double> params)
    : generator_(std::move(generator)), seed_(seed), params_(std::move(params)) {}

// ---------------------------------------------------------------------------------------------
// Buffer, views and accessors

int GltfBuilder::add_buffer_view(const void* data, size_t bytes, int target) {
  const size_t offset = bin_.size();  // always 4-byte aligned: every view is padded below
  const auto* p = static_cast<const unsigned char*>(data);
  bin_.insert(bin_.end(), p, p + bytes);
  bin_.resize((bin_.size() + 3) & ~size_t{3}, 0);
  json view = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}};
  if (target != 0) view["target"] = target;
  buffer_views_.push_back(std::move(view));
  return static_cast<int>(buffer_views_.size()) - 1;
}

int GltfBuilder::add_accessor(int buffer_view, int component_type, size_t count, const char* type, const json& min,
                              const json& max) {
  json a = {{"bufferView", buffer_view}, {"componentType", component_type}, {"count", count}, {"type", type}};
  if (!min.is_null()) a["min"] = min;
  if (!max.is_null()) a["max"] = max;
  accessors_.push_back(std::move(a));
  return static_cast<int>(accessors_.size()) - 1;
}

int GltfBuilder::add_geometry(const MeshData& mesh, bool with_uvs, IndexType index_type) {
  const std::string name = fmt::format("geometry {}", geometries_.size());
  const size_t nv = mesh.positions.size();
  if (nv == 0 || mesh.indices.empty() || mesh.indices.size() % 3 != 0)
    throw std::logic_error(fmt::format("glTF builder: {} has no triangles", name));
  if (mesh.normals.size() != nv)
    throw std::logic_error(fmt::format("glTF builder: {} has {} normals for {} positions", name, mesh.normals.size(), nv));
  if (nv > 0xFFFFFFFEull) throw std::logic_error(fmt::format("glTF builder: {} has too many vertices", name));

  Geometry g;
  g.vertices = nv;
  g.triangles = mesh.indices.size() / 3;

  // POSITION with exact float min/max (the validator compares them with the data).
  vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (const vec3& p : mesh.positions) {
    check_finite(p, "position", name);
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  const int pv = add_buffer_view(mesh.positions.data(), nv * sizeof(vec3), kArrayBuffer);
  g.position = add_accessor(pv, kFloat, nv, "VEC3",
                            json::array({static_cast<double>(lo.x), static_cast<double>(lo.y), static_cast<double>(lo.z)}),
                            json::array({static_cast<double>(hi.x), static_cast<double>(hi.y), static_cast<double>(hi.z)}));

  // NORMAL, renormalised in float so that every one is unit length to float precision.
  std::vector<vec3> normals(mesh.normals);
  for (vec3& n : normals) {
    check_finite(n, "normal", name);
    const float len = glm::length(n);
    if (!(len > 0.0f)) throw std::logic_error(fmt::format("glTF builder: {} has a zero-length normal", name));
    n /= len;
  }
  g.normal = add_accessor(add_buffer_view(normals.data(), nv * sizeof(vec3), kArrayBuffer), kFloat, nv, "VEC3");

  if (with_uvs && mesh.uvs.size() == nv)
    g.uv = add_accessor(add_buffer_view(mesh.uvs.data(), nv * sizeof(vec2), kArrayBuffer), kFloat, nv, "VEC2");

  for (uint32_t i : mesh.indices)
    if (i >= nv) throw std::logic_error(fmt::format("glTF builder: {} has index {} >= {} vertices", name, i, nv));
  // 16-bit indices when every index stays below the primitive-restart value 65535.
  const bool short_ok = nv <= 65535;
  if (index_type == IndexType::uint16 && !short_ok)
    throw std::logic_error(fmt::format("glTF builder: {} has {} vertices, too many for 16-bit indices", name, nv));
  const bool use_short = index_type == IndexType::uint16 || (index_type == IndexType::automatic && short_ok);
  if (use_short) {
    std::vector<uint16_t> idx(mesh.indices.begin(), mesh.indices.end());
    g.indices = add_accessor(add_buffer_view(idx.data(), idx.size() * 2, kElementArrayBuffer), kUnsignedShort,
                             idx.size(), "SCALAR");
  } else {
    g.indices = add_accessor(add_buffer_view(mesh.indices.data(), mesh.indices.size() * 4, kElementArrayBuffer),
                             kUnsignedInt, mesh.indices.size(), "SCALAR");
  }
  geometries_.push_back(g);
  return static_cast<int>(geometries_.size()) - 1;
}

// ---------------------------------------------------------------------------------------------
// Materials and textures

int GltfBuilder::add_material(const std::string& name, const vec4& base_color, int texture, bool double_sided) {
  if (texture >= static_cast<int>(textures_.size()))
    throw std::logic_error(fmt::format("glTF builder: material '{}' names texture {} of {}", name, texture, textures_.size()));
  const auto c = [](float v) { return static_cast<double>(std::clamp(v, 0.0f, 1.0f)); };
  json pbr = {{"baseColorFactor", json::array({c(base_color.x), c(base_color.y), c(base_color.z), c(base_color.w)})},
              {"metallicFactor", 0.0},
              {"roughnessFactor", 1.0}};
  if (texture >= 0) pbr["baseColorTexture"] = {{"index", texture}};
  json m = {{"name", name}, {"pbrMetallicRoughness", std::move(pbr)}};
  if (double_sided) m["doubleSided"] = true;
  materials_.push_back(std::move(m));
  material_textured_.push_back(texture >= 0);
  ++stats_.materials;
  return static_cast<int>(materials_.size()) - 1;
}

void GltfBuilder::set_alpha_mask(int material, double cutoff) {
  if (material < 0 || material >= static_cast<int>(materials_.size()))
    throw std::logic_error(fmt::format("glTF builder: no material {} to make a cut-out", material));
  materials_[static_cast<size_t>(material)]["alphaMode"] = "MASK";
  materials_[static_cast<size_t>(material)]["alphaCutoff"] = cutoff;
}

int GltfBuilder::add_texture(const std::string& name, int width, int height, std::span<const uint8_t> rgba8) {
  if (width <= 0 || height <= 0 ||
      rgba8.size() != static_cast<size_t>(width) * static_cast<size_t>(height) * 4)
    throw std::logic_error(fmt::format("glTF builder: texture '{}' of {}x{} has {} bytes", name, width, height, rgba8.size()));
  bool opaque = true;
  for (size_t i = 3; i < rgba8.size() && opaque; i += 4) opaque = rgba8[i] == 255;
  std::vector<unsigned char> png;
  if (opaque) {
    std::vector<uint8_t> rgb;
    rgb.reserve(rgba8.size() / 4 * 3);
    for (size_t i = 0; i < rgba8.size(); i += 4) rgb.insert(rgb.end(), rgba8.begin() + static_cast<ptrdiff_t>(i),
                                                            rgba8.begin() + static_cast<ptrdiff_t>(i + 3));
    png = io::encode_png(rgb.data(), width, height, 3);
  } else {
    png = io::encode_png(rgba8.data(), width, height, 4);
  }
  const int view = add_buffer_view(png.data(), png.size(), 0);
  images_.push_back({{"name", name}, {"bufferView", view}, {"mimeType", "image/png"}});
  textures_.push_back({{"name", name}, {"sampler", 0}, {"source", static_cast<int>(images_.size()) - 1}});
  ++stats_.textures;
  return static_cast<int>(textures_.size()) - 1;
}

// ---------------------------------------------------------------------------------------------
// Meshes and nodes

int GltfBuilder::add_mesh(const std::string& name, const std::vector<MeshPrimitive>& primitives) {
  if (primitives.empty()) throw std::logic_error(fmt::format("glTF builder: mesh '{}' has no primitives", name));
  json prims = json::array();
  MeshCounts counts;
  for (const MeshPrimitive& p : primitives) {
    if (p.geometry < 0 || p.geometry >= static_cast<int>(geometries_.size()) || p.material < 0 ||
        p.material >= static_cast<int>(materials_.size()))
      throw std::logic_error(fmt::format("glTF builder: mesh '{}' names a missing geometry or material", name));
    const Geometry& g = geometries_[static_cast<size_t>(p.geometry)];
    if (material_textured_[static_cast<size_t>(p.material)] && g.uv < 0)
      throw std::logic_error(fmt::format("glTF builder: mesh '{}' has a textured material but no UVs", name));
    json attributes = {{"POSITION", g.position}, {"NORMAL", g.normal}};
    if (g.uv >= 0) attributes["TEXCOORD_0"] = g.uv;
    prims.push_back({{"attributes", std::move(attributes)}, {"indices", g.indices}, {"material", p.material}, {"mode", 4}});
    counts.vertices += g.vertices;
    counts.triangles += g.triangles;
  }
  meshes_.push_back({{"name", name}, {"primitives", std::move(prims)}});
  mesh_counts_.push_back(counts);
  ++stats_.meshes;
  return static_cast<int>(meshes_.size()) - 1;
}

int GltfBuilder::add_mesh(const std::string& name, const MeshData& mesh, int material, IndexType index_type) {
  if (material < 0 || material >= static_cast<int>(materials_.size()))
    throw std::logic_error(fmt::format("glTF builder: mesh '{}' names missing material {}", name, material));
  const bool textured = material_textured_[static_cast<size_t>(material)];
  const int geometry = add_geometry(mesh, textured, index_type);
  return add_mesh(name, {MeshPrimitive{geometry, material}});
}

void GltfBuilder::count_instance(int mesh) {
  const MeshCounts& c = mesh_counts_[static_cast<size_t>(mesh)];
  stats_.triangles += c.triangles;
  stats_.vertices += c.vertices;
}

int GltfBuilder::add_node(const std::string& name, int mesh, const NodeTransform& t, int parent) {
  if (mesh >= static_cast<int>(meshes_.size()) || parent >= static_cast<int>(nodes_.size()))
    throw std::logic_error(fmt::format("glTF builder: node '{}' names a missing mesh or parent", name));
  json node = {{"name", name}};
  if (mesh >= 0) node["mesh"] = mesh;
  if (t.matrix) {
    json m = json::array();
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m.push_back((*t.matrix)[c][r]);
    node["matrix"] = std::move(m);
  } else {
    if (t.translation != dvec3(0.0)) node["translation"] = vec_json(t.translation);
    const dquat q = glm::normalize(t.rotation);
    if (q != dquat(1.0, 0.0, 0.0, 0.0)) node["rotation"] = json::array({q.x, q.y, q.z, q.w});
    if (t.scale != dvec3(1.0)) node["scale"] = vec_json(t.scale);
  }
  nodes_.push_back(std::move(node));
  const int index = static_cast<int>(nodes_.size()) - 1;
  if (parent >= 0) {
    json& p = nodes_[static_cast<size_t>(parent)];
    if (!p.contains("children")) p["children"] = json::array();
    p["children"].push_back(index);
  } else {
    roots_.push_back(index);
  }
  if (mesh >= 0) count_instance(mesh);
  ++stats_.nodes;
  return index;
}

// ---------------------------------------------------------------------------------------------
// Lights and camera

int GltfBuilder::add_light_node(const std::string& name, const json& light, const NodeTransform& transform, int parent) {
  lights_.push_back(light);
  const int node = add_node(name, -1, transform, parent);
  nodes_[static_cast<size_t>(node)]["extensions"] = {
      {"KHR_lights_punctual", {{"light", static_cast<int>(lights_.size()) - 1}}}};
  ++stats_.lights;
  return node;
}

int GltfBuilder::add_point_light(const std::string& name, const vec3& position, const vec3& color, float intensity,
                                 int parent) {
  check_finite(position, "light position", name);
  const json light = {{"name", name},
                      {"type", "point"},
                      {"color", vec_json(dvec3(color))},
                      {"intensity", static_cast<double>(intensity)}};
  ++stats_.point_lights;
  return add_light_node(name, light, NodeTransform::at(dvec3(position)), parent);
}

int GltfBuilder::add_directional_light(const std::string& name, const vec3& direction, const vec3& color,
                                       float intensity, int parent) {
  if (!(glm::length(direction) > 0.0f)) throw std::logic_error(fmt::format("glTF builder: light '{}' has no direction", name));
  const json light = {{"name", name},
                      {"type", "directional"},
                      {"color", vec_json(dvec3(color))},
                      {"intensity", static_cast<double>(intensity)}};
  NodeTransform t;
  t.rotation = rotation_towards(dvec3(direction));
  ++stats_.directional_lights;
  return add_light_node(name, light, t, parent);
}

int GltfBuilder::add_animation_channel(int node, const std::string& property, std::span<const float> times,
                                       std::span<const float> values, const std::string& interpolation,
                                       const std::string& clip) {
  const size_t width = property == "rotation" ? 4 : 3;
  const size_t per_key = interpolation == "CUBICSPLINE" ? 3 : 1;
  if (node < 0 || static_cast<size_t>(node) >= nodes_.size() || times.empty() ||
      values.size() != times.size() * width * per_key)
    throw std::logic_error(fmt::format("glTF builder: animation of node {} ({}) has {} values for {} keys", node,
                                       property, values.size(), times.size()));
  const auto [lo, hi] = std::minmax_element(times.begin(), times.end());
  const int input = add_accessor(add_buffer_view(times.data(), times.size_bytes(), 0), kFloat, times.size(), "SCALAR",
                                 json::array({static_cast<double>(*lo)}), json::array({static_cast<double>(*hi)}));
  const int output = add_accessor(add_buffer_view(values.data(), values.size_bytes(), 0), kFloat,
                                  values.size() / width, width == 4 ? "VEC4" : "VEC3");
  auto it = std::find_if(animations_.begin(), animations_.end(), [&](const json& a) { return a["name"] == clip; });
  if (it == animations_.end()) {
    animations_.push_back({{"name", clip}, {"channels", json::array()}, {"samplers", json::array()}});
    it = animations_.end() - 1;
  }
  json& samplers = (*it)["samplers"];
  json& channels = (*it)["channels"];
  samplers.push_back({{"input", input}, {"output", output}, {"interpolation", interpolation}});
  channels.push_back({{"sampler", samplers.size() - 1}, {"target", {{"node", node}, {"path", property}}}});
  return static_cast<int>(channels.size()) - 1;
}

int GltfBuilder::set_camera(const std::string& name, const CameraPose& pose, double yfov, double znear, double zfar,
                            const RigDefaults& rig) {
  if (!cameras_.empty()) throw std::logic_error("glTF builder: the scene camera is set twice");
  json perspective = {{"yfov", yfov}, {"znear", znear}};
  if (zfar > znear) perspective["zfar"] = zfar;
  if (rig.width && rig.height) perspective["aspectRatio"] = static_cast<double>(*rig.width) / *rig.height;
  cameras_.push_back({{"name", name}, {"type", "perspective"}, {"perspective", std::move(perspective)}});

  NodeTransform t;
  t.translation = pose.position;
  t.rotation = basis_rotation(pose.right, pose.up, pose.back);
  const int node = add_node(name, -1, t);
  json sbx = json::object();
  if (rig.interaxial) sbx["interaxial"] = *rig.interaxial;
  if (rig.convergence) sbx["convergence"] = *rig.convergence;
  if (rig.width) sbx["width"] = *rig.width;
  if (rig.height) sbx["height"] = *rig.height;
  json& n = nodes_[static_cast<size_t>(node)];
  n["camera"] = 0;
  n["extras"] = {{"stereobench", std::move(sbx)}};
  return node;
}

// ---------------------------------------------------------------------------------------------
// Output

json GltfBuilder::document() const {
  json doc;
  doc["asset"] = {{"version", "2.0"}, {"generator", "stereobench " SB_VERSION_STRING}};
  json scene = {{"name", generator_},
                {"extras",
                 {{"stereobench",
                   {{"generator", generator_},
                    {"seed", seed_},
                    {"params", params_.empty() ? json::object() : json(params_)},
                    {"background", vec_json(dvec3(background_))},
                    {"ambient", ambient_}}}}}};
  if (!roots_.empty()) scene["nodes"] = roots_;
  doc["scene"] = 0;
  doc["scenes"] = json::array({std::move(scene)});
  const auto put = [&doc](const char* key, const json& array) {
    if (!array.empty()) doc[key] = array;
  };
  put("nodes", nodes_);
  put("meshes", meshes_);
  put("materials", materials_);
  put("textures", textures_);
  put("images", images_);
  put("accessors", accessors_);
  put("bufferViews", buffer_views_);
  put("cameras", cameras_);
  put("animations", animations_);
  if (!textures_.empty())
    doc["samplers"] = json::array({{{"magFilter", kLinear}, {"minFilter", kLinearMipmapLinear}, {"wrapS", kRepeat},
                                    {"wrapT", kRepeat}}});
  if (!bin_.empty()) doc["buffers"] = json::array({{{"byteLength", bin_.size()}}});
  if (!lights_.empty()) {
    doc["extensionsUsed"] = json::array({"KHR_lights_punctual"});
    doc["extensions"] = {{"KHR_lights_punctual", {{"lights", lights_}}}};
  }
  return doc;
}

size_t GltfBuilder::write(const std::filesystem::path& path) const {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext != ".glb" && ext != ".gltf")
    throw InputError(fmt::format("cannot write scene '{}': the file name must end in .glb or .gltf", path.string()));

  json doc = document();
  // Both formats are streamed from the one in-memory buffer (no second copy of it, which matters
  // for the 10^8-triangle complexity scenes); write_atomically gives the same all-or-nothing
  // guarantee as write_file_atomically.
  if (ext == ".glb") {
    std::string text = doc.dump();
    text.resize((text.size() + 3) & ~size_t{3}, ' ');
    const uint64_t total = 12 + 8 + text.size() + (bin_.empty() ? 0 : 8 + bin_.size());
    if (total > 0xFFFFFFFFull)
      throw InputError(fmt::format("cannot write scene '{}': {} bytes exceed the 4 GiB limit of GLB", path.string(), total));
    io::write_atomically(path, [&](const std::filesystem::path& tmp) {
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      put_u32(out, kGlbMagic);
      put_u32(out, 2);
      put_u32(out, static_cast<uint32_t>(total));
      put_u32(out, static_cast<uint32_t>(text.size()));
      put_u32(out, kChunkJson);
      out.write(text.data(), static_cast<std::streamsize>(text.size()));
      if (!bin_.empty()) {
        put_u32(out, static_cast<uint32_t>(bin_.size()));
        put_u32(out, kChunkBin);
        out.write(reinterpret_cast<const char*>(bin_.data()), static_cast<std::streamsize>(bin_.size()));
      }
      out.close();
      if (!out) write_failed(path, static_cast<size_t>(total));
    });
    return static_cast<size_t>(total);
  }

  static constexpr const char* kPlaceholder = "@stereobench-buffer@";
  if (!bin_.empty()) doc["buffers"][0]["uri"] = kPlaceholder;
  const std::string text = doc.dump(1);
  const size_t at = bin_.empty() ? std::string::npos : text.find(kPlaceholder);
  size_t total = 0;
  io::write_atomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (at == std::string::npos) {
      out.write(text.data(), static_cast<std::streamsize>(text.size()));
      total = text.size();
    } else {
      static constexpr std::string_view kPrefix = "data:application/octet-stream;base64,";
      out.write(text.data(), static_cast<std::streamsize>(at));
      out.write(kPrefix.data(), static_cast<std::streamsize>(kPrefix.size()));
      total = at + kPrefix.size();
      std::string chunk;
      constexpr size_t kStep = 3 * (size_t{1} << 18);
      for (size_t i = 0; i < bin_.size(); i += kStep) {
        chunk.clear();
        base64_append(chunk, bin_.data() + i, std::min(kStep, bin_.size() - i));
        out.write(chunk.data(), static_cast<std::streamsize>(chunk.size()));
        total += chunk.size();
      }
      const size_t rest = at + std::strlen(kPlaceholder);
      out.write(text.data() + rest, static_cast<std::streamsize>(text.size() - rest));
      total += text.size() - rest;
    }
    out.put('\n');
    ++total;
    out.close();
    if (!out) write_failed(path, total);
  });
  return total;
}

}  // namespace sb::scenes
