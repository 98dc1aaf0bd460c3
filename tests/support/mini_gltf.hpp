// A tiny glTF writer for tests: lets a test lay out accessors byte by byte (any component type,
// stride, sparse, normalisation) and write .gltf (external or embedded buffer) or .glb.
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace sb::test {

class MiniGltf {
 public:
  nlohmann::json doc;
  std::vector<unsigned char> bin;

  MiniGltf() {
    doc["asset"] = {{"version", "2.0"}};
    doc["scene"] = 0;
    doc["scenes"] = nlohmann::json::array({{{"nodes", nlohmann::json::array()}}});
  }

  /// Appends raw bytes (4-byte aligned) as a bufferView; returns its index.
  int add_view(const void* data, size_t bytes, int stride = 0) {
    while (bin.size() % 4) bin.push_back(0);
    const size_t offset = bin.size();
    bin.resize(offset + bytes);
    std::memcpy(bin.data() + offset, data, bytes);
    nlohmann::json v = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}};
    if (stride) v["byteStride"] = stride;
    doc["bufferViews"].push_back(v);
    return static_cast<int>(doc["bufferViews"].size() - 1);
  }

  template <class T>
  int add_view(const std::vector<T>& values, int stride = 0) {
    return add_view(values.data(), values.size() * sizeof(T), stride);
  }

  int add_accessor(int view, int component_type, size_t count, const std::string& type,
                   size_t byte_offset = 0, bool normalized = false) {
    nlohmann::json a = {{"bufferView", view}, {"componentType", component_type}, {"count", count}, {"type", type}};
    if (byte_offset) a["byteOffset"] = byte_offset;
    if (normalized) a["normalized"] = true;
    doc["accessors"].push_back(a);
    return static_cast<int>(doc["accessors"].size() - 1);
  }

  /// FLOAT VEC3 positions with min/max.
  int add_positions(const std::vector<float>& xyz) {
    const int a = add_accessor(add_view(xyz), 5126, xyz.size() / 3, "VEC3");
    std::vector<float> lo(3, 1e30f), hi(3, -1e30f);
    for (size_t i = 0; i < xyz.size(); ++i) {
      lo[i % 3] = std::min(lo[i % 3], xyz[i]);
      hi[i % 3] = std::max(hi[i % 3], xyz[i]);
    }
    doc["accessors"][a]["min"] = lo;
    doc["accessors"][a]["max"] = hi;
    return a;
  }

  int add_mesh(const nlohmann::json& primitives) {
    doc["meshes"].push_back({{"primitives", primitives}});
    return static_cast<int>(doc["meshes"].size() - 1);
  }

  /// Adds a node; root nodes are listed in scene 0.
  int add_node(const nlohmann::json& node, bool root = true) {
    doc["nodes"].push_back(node);
    const int n = static_cast<int>(doc["nodes"].size() - 1);
    if (root) doc["scenes"][0]["nodes"].push_back(n);
    return n;
  }

  /// One triangle in the z = 0 plane (positions only), instanced by a root node.
  void add_triangle() {
    const int p = add_positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
    const int m = add_mesh(nlohmann::json::array({{{"attributes", {{"POSITION", p}}}}}));
    add_node({{"mesh", m}});
  }

  /// Declares the buffer, unless the test already wrote its own "buffers" entry.
  void finish_buffer(const std::string& uri) {
    if (doc.contains("buffers")) return;
    while (bin.size() % 4) bin.push_back(0);
    nlohmann::json b = {{"byteLength", bin.size()}};
    if (!uri.empty()) b["uri"] = uri;
    doc["buffers"] = nlohmann::json::array({b});
  }

  /// .gltf with the buffer in `<stem>.bin` beside it.
  void write_gltf(const std::filesystem::path& path) {
    const std::string bin_name = path.stem().string() + ".bin";
    if (!bin.empty()) {
      finish_buffer(bin_name);
      write_bytes(path.parent_path() / bin_name, bin);
    }
    write_text(path, doc.dump(1));
  }

  /// .gltf with the buffer embedded as a base64 data URI.
  void write_gltf_embedded(const std::filesystem::path& path) {
    if (!bin.empty()) finish_buffer("data:application/octet-stream;base64," + base64(bin));
    write_text(path, doc.dump(1));
  }

  /// Binary .glb container.
  void write_glb(const std::filesystem::path& path) {
    if (!bin.empty()) finish_buffer("");
    std::string json = doc.dump();
    while (json.size() % 4) json.push_back(' ');
    std::vector<unsigned char> out;
    auto u32 = [&](uint32_t v) { for (int i = 0; i < 4; ++i) out.push_back(static_cast<unsigned char>(v >> (8 * i))); };
    const uint32_t total = 12 + 8 + static_cast<uint32_t>(json.size()) + (bin.empty() ? 0 : 8 + static_cast<uint32_t>(bin.size()));
    u32(0x46546C67);
    u32(2);
    u32(total);
    u32(static_cast<uint32_t>(json.size()));
    u32(0x4E4F534A);
    out.insert(out.end(), json.begin(), json.end());
    if (!bin.empty()) {
      u32(static_cast<uint32_t>(bin.size()));
      u32(0x004E4942);
      out.insert(out.end(), bin.begin(), bin.end());
    }
    write_bytes(path, out);
  }

  static std::string base64(const std::vector<unsigned char>& data) {
    static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string s;
    size_t i = 0;
    for (; i + 2 < data.size(); i += 3) {
      const uint32_t v = (data[i] << 16) | (data[i + 1] << 8) | data[i + 2];
      s += {t[v >> 18], t[(v >> 12) & 63], t[(v >> 6) & 63], t[v & 63]};
    }
    if (i + 1 == data.size()) {
      const uint32_t v = data[i] << 16;
      s += {t[v >> 18], t[(v >> 12) & 63], '=', '='};
    } else if (i + 2 == data.size()) {
      const uint32_t v = (data[i] << 16) | (data[i + 1] << 8);
      s += {t[v >> 18], t[(v >> 12) & 63], t[(v >> 6) & 63], '='};
    }
    return s;
  }

  static void write_bytes(const std::filesystem::path& p, const std::vector<unsigned char>& data) {
    std::ofstream f(p, std::ios::binary);
    f.write(reinterpret_cast<const char*>(data.data()), static_cast<std::streamsize>(data.size()));
  }
  static void write_text(const std::filesystem::path& p, const std::string& text) {
    std::ofstream f(p, std::ios::binary);
    f << text;
  }
};

}  // namespace sb::test
