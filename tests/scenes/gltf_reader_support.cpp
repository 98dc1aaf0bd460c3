// The scene tests' own glTF reader (see gltf_reader_support.hpp).
#include "gltf_reader_support.hpp"

#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include <glm/gtc/matrix_transform.hpp>

namespace sb::test {

using nlohmann::json;

namespace {

std::vector<unsigned char> read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open " + path.string());
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

uint32_t u32(const unsigned char* p) {
  return uint32_t{p[0]} | (uint32_t{p[1]} << 8) | (uint32_t{p[2]} << 16) | (uint32_t{p[3]} << 24);
}

std::vector<unsigned char> base64_decode(const std::string& text) {
  std::vector<unsigned char> out;
  out.reserve(text.size() / 4 * 3);
  uint32_t acc = 0;
  int bits = 0;
  for (char c : text) {
    int v;
    if (c >= 'A' && c <= 'Z') v = c - 'A';
    else if (c >= 'a' && c <= 'z') v = c - 'a' + 26;
    else if (c >= '0' && c <= '9') v = c - '0' + 52;
    else if (c == '+') v = 62;
    else if (c == '/') v = 63;
    else if (c == '=') break;
    else throw std::runtime_error("bad base64");
    acc = (acc << 6) | static_cast<uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<unsigned char>((acc >> bits) & 0xFF));
    }
  }
  return out;
}

/// Parses the file into its JSON and buffer 0.
void parse(const std::filesystem::path& path, json& doc, std::vector<unsigned char>& bin) {
  const std::vector<unsigned char> bytes = read_bytes(path);
  if (bytes.size() >= 20 && u32(bytes.data()) == 0x46546C67) {
    if (u32(bytes.data() + 8) != bytes.size()) throw std::runtime_error("GLB length mismatch");
    const uint32_t json_len = u32(bytes.data() + 12);
    if (u32(bytes.data() + 16) != 0x4E4F534A) throw std::runtime_error("GLB without JSON chunk");
    doc = json::parse(bytes.begin() + 20, bytes.begin() + 20 + json_len);
    const size_t bin_at = 20 + json_len;
    if (bin_at + 8 <= bytes.size()) {
      const uint32_t bin_len = u32(bytes.data() + bin_at);
      if (u32(bytes.data() + bin_at + 4) != 0x004E4942) throw std::runtime_error("GLB without BIN chunk");
      bin.assign(bytes.begin() + static_cast<std::ptrdiff_t>(bin_at + 8),
                 bytes.begin() + static_cast<std::ptrdiff_t>(bin_at + 8 + bin_len));
    }
  } else {
    doc = json::parse(bytes.begin(), bytes.end());
    if (doc.contains("buffers")) {
      const std::string uri = doc["buffers"][0].at("uri").get<std::string>();
      const std::string prefix = "data:application/octet-stream;base64,";
      if (uri.rfind(prefix, 0) != 0) throw std::runtime_error("buffer is not an embedded data URI");
      bin = base64_decode(uri.substr(prefix.size()));
    }
  }
}

/// Raw bytes and element count of an accessor (tightly packed views only, as the builder writes).
const unsigned char* accessor_data(const json& doc, const std::vector<unsigned char>& bin, int index, size_t elem_size,
                                   size_t& count) {
  const json& a = doc.at("accessors").at(static_cast<size_t>(index));
  const json& v = doc.at("bufferViews").at(a.at("bufferView").get<size_t>());
  count = a.at("count").get<size_t>();
  const size_t offset = v.value("byteOffset", size_t{0}) + a.value("byteOffset", size_t{0});
  if (offset + count * elem_size > bin.size()) throw std::runtime_error("accessor past the end of the buffer");
  return bin.data() + offset;
}

std::vector<vec3> read_vec3(const json& doc, const std::vector<unsigned char>& bin, int index) {
  size_t count = 0;
  const unsigned char* p = accessor_data(doc, bin, index, 12, count);
  std::vector<vec3> out(count);
  std::memcpy(out.data(), p, count * 12);
  return out;
}

std::vector<vec2> read_vec2(const json& doc, const std::vector<unsigned char>& bin, int index) {
  size_t count = 0;
  const unsigned char* p = accessor_data(doc, bin, index, 8, count);
  std::vector<vec2> out(count);
  std::memcpy(out.data(), p, count * 8);
  return out;
}

std::vector<uint32_t> read_indices(const json& doc, const std::vector<unsigned char>& bin, int index) {
  const int type = doc.at("accessors").at(static_cast<size_t>(index)).at("componentType").get<int>();
  size_t count = 0;
  std::vector<uint32_t> out;
  if (type == 5123) {
    const unsigned char* p = accessor_data(doc, bin, index, 2, count);
    out.resize(count);
    for (size_t i = 0; i < count; ++i) out[i] = uint32_t{p[2 * i]} | (uint32_t{p[2 * i + 1]} << 8);
  } else if (type == 5125) {
    const unsigned char* p = accessor_data(doc, bin, index, 4, count);
    out.resize(count);
    std::memcpy(out.data(), p, count * 4);
  } else {
    throw std::runtime_error("unexpected index component type");
  }
  return out;
}

dmat4 local_matrix(const json& node) {
  if (node.contains("matrix")) {
    dmat4 m(1.0);
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m[c][r] = node["matrix"][static_cast<size_t>(c * 4 + r)].get<double>();
    return m;
  }
  dmat4 t(1.0), r(1.0), s(1.0);
  if (node.contains("translation"))
    t[3] = dvec4(node["translation"][0].get<double>(), node["translation"][1].get<double>(),
                 node["translation"][2].get<double>(), 1.0);
  if (node.contains("rotation")) {
    const json& q = node["rotation"];
    r = glm::mat4_cast(dquat(q[3].get<double>(), q[0].get<double>(), q[1].get<double>(), q[2].get<double>()));
  }
  if (node.contains("scale"))
    s = glm::scale(dmat4(1.0), dvec3(node["scale"][0].get<double>(), node["scale"][1].get<double>(), node["scale"][2].get<double>()));
  return t * r * s;
}

}  // namespace

size_t ReadGltf::triangle_count() const {
  size_t n = 0;
  for (const ReadPrimitive& p : primitives) n += p.indices.size() / 3;
  return n;
}

size_t ReadGltf::vertex_count() const {
  size_t n = 0;
  for (const ReadPrimitive& p : primitives) n += p.positions.size();
  return n;
}

Bounds3 ReadGltf::bounds() const {
  Bounds3 b;
  for (const ReadPrimitive& p : primitives)
    for (const vec3& v : p.positions) b.extend(v);
  return b;
}

size_t ReadGltf::light_count(const std::string& type) const {
  size_t n = 0;
  if (!doc.contains("nodes")) return 0;
  for (const json& node : doc["nodes"]) {
    if (!node.contains("extensions") || !node["extensions"].contains("KHR_lights_punctual")) continue;
    const size_t li = node["extensions"]["KHR_lights_punctual"]["light"].get<size_t>();
    if (doc["extensions"]["KHR_lights_punctual"]["lights"].at(li).at("type") == type) ++n;
  }
  return n;
}

std::vector<vec3> ReadGltf::point_light_positions() const {
  std::vector<vec3> out;
  for (size_t i = 0; i < doc["nodes"].size(); ++i) {
    const json& node = doc["nodes"][i];
    if (!node.contains("extensions") || !node["extensions"].contains("KHR_lights_punctual")) continue;
    const size_t li = node["extensions"]["KHR_lights_punctual"]["light"].get<size_t>();
    if (doc["extensions"]["KHR_lights_punctual"]["lights"].at(li).at("type") == "point")
      out.emplace_back(vec3(node_world[i][3]));
  }
  return out;
}

int ReadGltf::camera_node() const {
  for (size_t i = 0; i < doc["nodes"].size(); ++i)
    if (doc["nodes"][i].contains("camera")) return static_cast<int>(i);
  return -1;
}

ReadGltf read_gltf(const std::filesystem::path& path) {
  ReadGltf out;
  parse(path, out.doc, out.bin);
  const json& doc = out.doc;
  const size_t node_count = doc.contains("nodes") ? doc["nodes"].size() : 0;
  out.node_world.assign(node_count, dmat4(1.0));
  // Walk the default scene's hierarchy from its roots.
  std::vector<std::pair<size_t, dmat4>> stack;
  for (const json& root : doc.at("scenes").at(doc.value("scene", 0)).value("nodes", json::array()))
    stack.emplace_back(root.get<size_t>(), dmat4(1.0));
  while (!stack.empty()) {
    auto [index, parent] = stack.back();
    stack.pop_back();
    const json& node = doc["nodes"].at(index);
    const dmat4 world = parent * local_matrix(node);
    out.node_world[index] = world;
    for (const json& child : node.value("children", json::array())) stack.emplace_back(child.get<size_t>(), world);
    if (!node.contains("mesh")) continue;
    const int mesh = node["mesh"].get<int>();
    for (const json& prim : doc["meshes"].at(static_cast<size_t>(mesh)).at("primitives")) {
      ReadPrimitive p;
      p.node = static_cast<int>(index);
      p.mesh = mesh;
      p.material = prim.value("material", -1);
      p.positions = read_vec3(doc, out.bin, prim["attributes"]["POSITION"].get<int>());
      for (vec3& v : p.positions) v = vec3(world * dvec4(dvec3(v), 1.0));
      if (prim["attributes"].contains("NORMAL")) p.normals = read_vec3(doc, out.bin, prim["attributes"]["NORMAL"].get<int>());
      if (prim["attributes"].contains("TEXCOORD_0")) p.uvs = read_vec2(doc, out.bin, prim["attributes"]["TEXCOORD_0"].get<int>());
      p.indices = read_indices(doc, out.bin, prim.at("indices").get<int>());
      out.primitives.push_back(std::move(p));
    }
  }
  return out;
}

std::vector<unsigned char> read_binary_payload(const std::filesystem::path& path) {
  json doc;
  std::vector<unsigned char> bin;
  parse(path, doc, bin);
  return bin;
}

}  // namespace sb::test
