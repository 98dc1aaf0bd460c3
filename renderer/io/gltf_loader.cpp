// glTF 2.0 loading: container and JSON checks, tinygltf for buffers and images, conversion to
// world-space meshes with every accessor layout the format allows.
#include "renderer/io/gltf_loader.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <set>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_INCLUDE_STB_IMAGE
#define TINYGLTF_NO_INCLUDE_STB_IMAGE_WRITE
#include <tiny_gltf.h>

#include "renderer/color.hpp"
#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/gltf_check.hpp"
#include "renderer/io/image_io.hpp"
#include "renderer/io/json_text.hpp"
#include "renderer/memory.hpp"
#include "renderer/rig.hpp"
#include "renderer/text.hpp"

namespace sb::io {

namespace fs = std::filesystem;
using nlohmann::json;

const char* gltf_loader_version() { return "tinygltf 2.7.0"; }

namespace {

struct GlbParts {
  std::string json_text;
  bool is_glb = false;
  bool has_bin = false;  ///< a .glb with a BIN chunk
  uint64_t bin_length = 0;  ///< its length in bytes
  uint64_t json_end = 0;    ///< where the JSON chunk ends in the file (a .glb)
};

uint32_t read_u32(const std::string& bytes, size_t offset) {
  uint32_t v;
  std::memcpy(&v, bytes.data() + offset, 4);
  return v;
}

/// Splits a .glb container into its JSON chunk, checking every length against the file.
GlbParts split_container(const std::string& bytes, const std::string& file, bool glb_name) {
  GlbParts parts;
  const bool magic = bytes.size() >= 4 && bytes.compare(0, 4, "glTF") == 0;
  if (glb_name && !magic) {
    std::string head;
    for (size_t i = 0; i < std::min<size_t>(4, bytes.size()); ++i) {
      const unsigned char c = static_cast<unsigned char>(bytes[i]);
      head += std::isprint(c) ? std::string(1, static_cast<char>(c)) : fmt::format("\\x{:02x}", c);
    }
    throw InputError(fmt::format("{}: not a binary glTF file: it starts with '{}', not the magic 'glTF'; the file is "
                                 "damaged or not a .glb (a JSON glTF file is named .gltf)",
                                 file, head));
  }
  if (!magic) {
    parts.json_text = bytes;
    return parts;
  }
  parts.is_glb = true;
  if (bytes.size() < 20)
    throw InputError(fmt::format("{}: truncated .glb: {} bytes, shorter than the 20-byte header; "
                                 "the file is damaged, regenerate or re-export it", file, bytes.size()));
  const uint32_t version = read_u32(bytes, 4);
  const uint32_t length = read_u32(bytes, 8);
  if (version != 2)
    throw InputError(fmt::format("{}: .glb container version {} is not supported (only 2)", file, version));
  if (length != bytes.size())
    throw InputError(fmt::format("{}: truncated or padded .glb: header says {} bytes, file has {}; "
                                 "the file is damaged, regenerate or re-export it", file, length, bytes.size()));
  const uint32_t json_len = read_u32(bytes, 12);
  const uint32_t json_type = read_u32(bytes, 16);
  if (json_type != 0x4E4F534A)
    throw InputError(fmt::format("{}: .glb first chunk is not JSON (type 0x{:08x})", file, json_type));
  if (uint64_t{20} + json_len > bytes.size())
    throw InputError(fmt::format("{}: truncated .glb: JSON chunk of {} bytes runs past the end of the "
                                 "{}-byte file", file, json_len, bytes.size()));
  const uint64_t bin_at = uint64_t{20} + json_len;
  if (bin_at < bytes.size()) {
    if (bin_at + 8 > bytes.size())
      throw InputError(fmt::format("{}: truncated .glb: BIN chunk header cut off at byte {}", file, bin_at));
    const uint32_t bin_len = read_u32(bytes, bin_at);
    const uint32_t bin_type = read_u32(bytes, bin_at + 4);
    if (bin_type != 0x004E4942)
      throw InputError(fmt::format("{}: .glb second chunk is not BIN (type 0x{:08x})", file, bin_type));
    if (bin_at + 8 + bin_len > bytes.size())
      throw InputError(fmt::format("{}: truncated .glb: BIN chunk of {} bytes runs past the end of the "
                                   "{}-byte file", file, bin_len, bytes.size()));
    if (bin_len == 0)
      throw InputError(fmt::format("{}: the .glb's BIN chunk (at byte {}) is empty: the file is damaged or was "
                                   "written without its binary data; export the scene again",
                                   file, bin_at));
    parts.has_bin = true;
    parts.bin_length = bin_len;
  }
  parts.json_end = bin_at;
  parts.json_text = bytes.substr(20, json_len);
  return parts;
}

/// The file as tinygltf is to read it. tinygltf 2.7 refuses some valid files: a skin without
/// inverseBindMatrices (optional in glTF 2.0), an animation channel without a target node, and an
/// index accessor that has no bufferView (every index from sparse substitution). The converter
/// reads skins from the JSON, so a file with skins is handed over without them. The other two are
/// refused here, naming the JSON path.
std::string tinygltf_input(const json& doc, const std::string& bytes, const GlbParts& parts, const std::string& file) {
  if (auto anims = doc.find("animations"); anims != doc.end())
    for (size_t a = 0; a < anims->size(); ++a)
      if (auto chs = (*anims)[a].find("channels"); chs != (*anims)[a].end())
        for (size_t c = 0; c < chs->size(); ++c)
          if (!(*chs)[c].at("target").contains("node"))
            throw InputError(fmt::format("{}: /animations/{}/channels/{}/target: a channel without a node (one an "
                                         "extension targets) cannot be read here; remove the channel",
                                         file, a, c));
  if (auto meshes = doc.find("meshes"); meshes != doc.end())
    for (size_t m = 0; m < meshes->size(); ++m)
      for (size_t p = 0; p < (*meshes)[m].at("primitives").size(); ++p) {
        const json& prim = (*meshes)[m]["primitives"][p];
        if (auto i = prim.find("indices"); i != prim.end() && !doc["accessors"][i->get<size_t>()].contains("bufferView"))
          throw InputError(fmt::format("{}: /meshes/{}/primitives/{}/indices: accessor {} has no bufferView (its "
                                       "indices all come from sparse substitution), which cannot be read here; "
                                       "export the indices densely",
                                       file, m, p, i->get<size_t>()));
      }
  if (!doc.contains("skins")) return bytes;
  json reduced = doc;
  reduced.erase("skins");
  for (json& node : reduced["nodes"]) node.erase("skin");
  std::string text = reduced.dump();
  if (!parts.is_glb) return text;
  // A .glb: the new JSON chunk (padded with spaces to 4 bytes) before the file's own BIN chunk.
  while (text.size() % 4 != 0) text.push_back(' ');
  const std::string rest = bytes.substr(parts.json_end);
  const auto u32 = [](uint64_t v) {
    std::string out(4, '\0');
    for (int i = 0; i < 4; ++i) out[static_cast<size_t>(i)] = static_cast<char>((v >> (8 * i)) & 0xFF);
    return out;
  };
  return bytes.substr(0, 8) + u32(20 + text.size() + rest.size()) + u32(text.size()) + bytes.substr(16, 4) + text +
         rest;
}

/// A JSON parser message with the token it last read cut to 40 characters: a syntax error inside
/// a data URI would otherwise quote kilobytes of base64.
std::string short_parse_error(const std::string& what) {
  const std::string key = "last read: '";
  const size_t at = what.find(key);
  if (at == std::string::npos) return what;
  const size_t start = at + key.size();
  // The token ends at the quote before "; expected ..." when the parser adds that, else at the last quote.
  const size_t expected = what.find("'; expected ", start);
  const size_t end = expected != std::string::npos ? expected : what.rfind('\'');
  if (end == std::string::npos || end <= start || end - start <= 40) return what;
  return what.substr(0, start + 40) + "...' (" + std::to_string(end - start) + " characters)" + what.substr(end + 1);
}

bool is_data_uri(const std::string& uri) { return uri.rfind("data:", 0) == 0; }

std::string percent_decode(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(static_cast<unsigned char>(s[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(s[i + 2]))) {
      out.push_back(static_cast<char>(std::stoi(s.substr(i + 1, 2), nullptr, 16)));
      i += 2;
    } else {
      out.push_back(s[i]);
    }
  }
  return out;
}

/// A base64 data URI buffer must decode to exactly its declared byteLength (as the loader demands).
/// A base64 data URI of one of the media types glTF names for `top` ("buffers" or "images"), its
/// payload of base64 characters only.
void check_data_uri(const std::string& uri, const std::string& top, const std::string& where, const std::string& file) {
  const size_t comma = uri.find(',');
  if (comma == std::string::npos || uri.rfind(";base64", comma) == std::string::npos)
    throw InputError(fmt::format("{}: {}/uri: data URI is not base64-encoded; only base64 data URIs are "
                                 "supported", file, where));
  const std::string type = uri.substr(5, uri.rfind(";base64", comma) - 5);
  // Images: PNG and JPEG in glTF 2.0, other image types through extensions (EXT_texture_webp,
  // KHR_texture_basisu), which a texture may name beside a PNG fallback.
  const bool known = top == "buffers" ? type == "application/octet-stream" || type == "application/gltf-buffer"
                                      : type.rfind("image/", 0) == 0 && type.size() > 6;
  if (!known)
    throw InputError(fmt::format("{}: {}/uri: data URI of media type '{}'; {} take {}", file, where, type, top,
                                 top == "buffers" ? "'data:application/octet-stream;base64,...'"
                                                  : "an image type, e.g. 'data:image/png;base64,...'"));
  size_t end = uri.size();
  for (size_t pad = 0; end > comma + 1 && pad < 2 && uri[end - 1] == '='; ++pad) --end;
  for (size_t i = comma + 1; i < end; ++i) {
    const auto c = static_cast<unsigned char>(uri[i]);
    if (!std::isalnum(c) && c != '+' && c != '/')
      throw InputError(fmt::format("{}: {}/uri: the data URI's base64 payload has the character '{}' at position "
                                   "{}; the data is damaged, export the scene again",
                                   file, where, std::isprint(c) ? std::string(1, static_cast<char>(c))
                                                                : fmt::format("\\x{:02x}", c),
                                   i - comma - 1));
  }
}

void check_data_uri_length(const json& buffer, const std::string& where, const std::string& file) {
  const std::string& uri = buffer.at("uri").get_ref<const std::string&>();
  check_data_uri(uri, "buffers", where, file);
  const size_t comma = uri.find(',');
  size_t chars = uri.size() - comma - 1;
  size_t pad = 0;
  while (chars > 0 && pad < 2 && uri[comma + chars] == '=') { --chars; ++pad; }
  const uint64_t have = (chars * 3) / 4;
  const uint64_t need = buffer.at("byteLength").get<uint64_t>();
  if (have < need)
    throw InputError(fmt::format("{}: {}: the data URI holds {} bytes but byteLength says {}; the buffer is "
                                 "truncated", file, where, have, need));
  if (have > need)
    throw InputError(fmt::format("{}: {}: the data URI holds {} bytes but byteLength says {}; the buffer's data "
                                 "and its length disagree: set {}/byteLength to {}, or export the scene again",
                                 file, where, have, need, where, have));
}

/// A URI with a scheme other than data: ("file:", "https:"); one letter before the colon is a
/// Windows drive, not a scheme.
bool has_scheme(const std::string& uri) {
  const size_t colon = uri.find(':');
  if (colon == std::string::npos || colon < 2 || !std::isalpha(static_cast<unsigned char>(uri[0]))) return false;
  return std::all_of(uri.begin(), uri.begin() + static_cast<std::ptrdiff_t>(colon), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '+' || c == '-' || c == '.';
  });
}

/// A path with a root ("/x", "\\server\x") or a Windows drive ("C:\x", "C:x"), after percent-decoding.
bool is_absolute_path(const std::string& path) {
  if (!path.empty() && (path[0] == '/' || path[0] == '\\')) return true;
  return path.size() >= 2 && std::isalpha(static_cast<unsigned char>(path[0])) && path[1] == ':';
}

/// The one rule for external buffers and images, quoted by every message that enforces it.
constexpr const char* kUriRule =
    "buffers and images are read from paths relative to the scene file's folder (subfolders and '..' "
    "are allowed) or from base64 data: URIs";

/// The file an external URI names, resolved against the scene's folder. URIs with a scheme and
/// absolute paths are refused here, before any file is looked at.
fs::path resolve_uri(const std::string& uri, const fs::path& dir, const std::string& file, const std::string& where) {
  if (has_scheme(uri))
    throw InputError(fmt::format("{}: {}: '{}' is a {} URI; {} — copy the file next to the scene (or into a "
                                 "folder below or beside it) and make the URI relative to the scene file",
                                 file, where, uri, uri.substr(0, uri.find(':') + 1), kUriRule));
  const std::string path = percent_decode(uri);
  if (path.find('\0') != std::string::npos)
    throw InputError(fmt::format("{}: {}: '{}' decodes to a path with a NUL byte (%00), which no file name holds; fix "
                                 "the uri",
                                 file, where, uri));
  if (is_absolute_path(path))
    throw InputError(fmt::format("{}: {}: '{}' is an absolute path; {} — make the URI relative to the scene "
                                 "file's folder '{}'",
                                 file, where, uri, kUriRule, dir.string()));
  return dir / path;
}

/// The files an external URI check let through, by the path tinygltf asks for: it decodes a URI
/// in its own way ('+' as a blank, as in a query string), so "a+b.bin" reaches it as "a b.bin";
/// it reads the file checked, and nothing else.
using AllowedFiles = std::map<std::string, fs::path>;

std::string file_key(const fs::path& p) { return p.lexically_normal().string(); }

/// External buffers and images must name files by the rule of kUriRule that exist, and buffers
/// must hold their declared byteLength. A buffer without a uri is a .glb's BIN chunk, which the
/// file must have. Returns the files the scene may read.
AllowedFiles check_external_files(const json& doc, const fs::path& dir, const std::string& file,
                                  const GlbParts& parts) {
  AllowedFiles allowed;
  for (const char* top : {"buffers", "images"}) {
    auto it = doc.find(top);
    if (it == doc.end()) continue;
    for (size_t i = 0; i < it->size(); ++i) {
      const json& e = (*it)[i];
      auto u = e.find("uri");
      if (u == e.end()) {
        if (std::string(top) == "buffers" && !(parts.is_glb && i == 0 && parts.has_bin))
          throw InputError(fmt::format(
              "{}: /buffers/{}: has no uri, {}; give it the uri of its .bin file or a data URI", file, i,
              parts.is_glb && i == 0 ? "so it is the .glb's BIN chunk, but the file has none (damaged or truncated)"
                                     : "which only the first buffer of a .glb may omit (it is the BIN chunk)"));
        // The BIN chunk may be padded to 4 bytes past the buffer, never shorter.
        if (std::string(top) == "buffers" && e.at("byteLength").get<uint64_t>() > parts.bin_length)
          throw InputError(fmt::format("{}: /buffers/0/byteLength: {} bytes, but the .glb's BIN chunk holds {}; the "
                                       "file is damaged or truncated, export the scene again",
                                       file, e.at("byteLength").get<uint64_t>(), parts.bin_length));
        continue;
      }
      if (is_data_uri(u->get<std::string>())) {
        if (std::string(top) == "buffers") check_data_uri_length(e, fmt::format("/buffers/{}", i), file);
        else check_data_uri(u->get<std::string>(), top, fmt::format("/images/{}", i), file);
        continue;
      }
      const std::string where = fmt::format("/{}/{}/uri", top, i);
      const fs::path p = resolve_uri(u->get<std::string>(), dir, file, where);
      std::error_code ec;
      if (!fs::exists(p, ec))
        throw InputError(fmt::format("{}: {}: referenced file '{}' does not exist; URIs are relative to the "
                                     "scene file's folder: put the file there or fix the uri", file, where,
                                     p.string()));
      if (!fs::is_regular_file(p, ec))
        throw InputError(fmt::format("{}: {}: '{}' is {}, not a regular file; fix the uri", file, where, p.string(),
                                     fs::is_directory(p, ec) ? "a folder" : "a device, pipe or socket"));
      // One that cannot be opened (permissions) is named here, with the reason, not by the
      // loader's own words later ("File read error", or an image without data).
      if (std::FILE* f = std::fopen(p.c_str(), "rb")) {
        std::fclose(f);
      } else {
        const int err = errno;
        throw IoError(fmt::format("{}: {}: cannot read '{}': {}; make it readable for this user", file, where,
                                  p.string(), std::strerror(err)));
      }
      if (std::string(top) == "buffers") {
        const uint64_t need = e.at("byteLength").get<uint64_t>();
        const uint64_t have = fs::file_size(p, ec);
        if (have != need)
          throw InputError(fmt::format("{}: {}: '{}' has {} bytes but byteLength says {}; the buffer is "
                                       "{} or the file is inconsistent", file, where, p.string(), have, need,
                                       have < need ? "truncated" : "of another size"));
      }
      allowed.emplace(file_key(dir / tinygltf::dlib::urldecode(u->get<std::string>())), p);
    }
  }
  return allowed;
}

/// tinygltf's file access limited to the files check_external_files let through. On its own it
/// also looks in the working folder for a file missing from the scene's folder, and its decoding
/// of a URI differs from RFC 3986's, so it could ask for another file than the one checked.
bool allowed_file_exists(const std::string& path, void* allowed) {
  return static_cast<const AllowedFiles*>(allowed)->count(file_key(path)) > 0;
}

bool read_allowed_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* allowed) {
  const AllowedFiles& files = *static_cast<const AllowedFiles*>(allowed);
  const auto it = files.find(file_key(path));
  if (it == files.end()) {
    if (err) *err += fmt::format("'{}' is not a file the scene's URIs name", path);
    return false;
  }
  return tinygltf::ReadWholeFile(out, err, it->second.string(), nullptr);
}

/// Keeps the encoded bytes of an image; decoding happens in the converter through image_io.
bool keep_image_bytes(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                      const unsigned char* bytes, int size, void*) {
  image->image.assign(bytes, bytes + size);
  image->width = -1;  // marks "encoded, not decoded"
  image->height = -1;
  return true;
}

/// A checked view of one accessor's elements.
struct AccessorView {
  const unsigned char* base = nullptr;  ///< nullptr: no bufferView, elements are zero
  size_t count = 0;
  int components = 0;
  int component_type = 0;
  size_t component_size = 0;
  size_t stride = 0;
  bool normalized = false;
};

int component_count(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
  }
}

size_t component_size(int ct) {
  switch (ct) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
  }
}

const char* type_name(int components) {
  switch (components) {
    case 1: return "SCALAR";
    case 2: return "VEC2";
    case 3: return "VEC3";
    case 4: return "VEC4";
    case 9: return "MAT3";
    case 16: return "MAT4";
    default: return "MAT";
  }
}

/// Reads one component as float, applying glTF's normalisation rules.
float read_component(const unsigned char* p, int ct, bool normalized) {
  switch (ct) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: { float f; std::memcpy(&f, p, 4); return f; }
    case TINYGLTF_COMPONENT_TYPE_BYTE: { int8_t v; std::memcpy(&v, p, 1); return normalized ? std::max(v / 127.0f, -1.0f) : float(v); }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: { uint8_t v = *p; return normalized ? v / 255.0f : float(v); }
    case TINYGLTF_COMPONENT_TYPE_SHORT: { int16_t v; std::memcpy(&v, p, 2); return normalized ? std::max(v / 32767.0f, -1.0f) : float(v); }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t v; std::memcpy(&v, p, 2); return normalized ? v / 65535.0f : float(v); }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { uint32_t v; std::memcpy(&v, p, 4); return normalized ? float(v / 4294967295.0) : float(v); }
    default: return 0.0f;
  }
}

uint32_t read_index(const unsigned char* p, int ct) {
  switch (ct) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return *p;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t v; std::memcpy(&v, p, 2); return v; }
    default: { uint32_t v; std::memcpy(&v, p, 4); return v; }
  }
}

/// Converts a tinygltf model into a Scene, checking every byte range it reads.
class Converter {
 public:
  Converter(const tinygltf::Model& model, const json& doc, std::string file, const GltfLoadOptions& options)
      : m_(model), doc_(doc), file_(std::move(file)), options_(options) {}

  Scene run() {
    Scene scene;
    scene.path = file_;
    check_extensions();
    convert_materials(scene);
    traverse(scene);
    read_scene_extras(scene);
    if (scene.meshes.empty()) {
      // What was skipped on the way explains an empty scene better than the rule alone.
      std::string skipped;
      for (const auto& [key, text] : warning_text_) skipped += "; " + text;
      throw InputError(fmt::format("{}: the scene has no triangles to render (no mesh with TRIANGLES, "
                                   "TRIANGLE_STRIP or TRIANGLE_FAN primitives is reachable from the scene's "
                                   "nodes){}; add geometry or pick another scene", file_, skipped));
    }
    // Triangles of zero area render as background alone, which any comparison passes.
    if (!scene.has_triangle_with_area())
      throw InputError(fmt::format("{}: the scene has no triangles to render: every one of its {} triangles has zero "
                                   "area (its vertices coincide or lie on one line), so nothing can be seen; check "
                                   "the primitives' indices and POSITION accessors, or pick another scene",
                                   file_, scene.triangle_count()));
    for (const auto& [key, count] : warning_counts_)
      scene.warnings.push_back(count > 1 ? fmt::format("{} ({} occurrences)", warning_text_[key], count)
                                         : warning_text_[key]);
    if (is_unlit(scene))
      scene.warnings.push_back(fmt::format(
          "{}: the scene is unlit ({}, ambient 0): every surface renders black, so a comparison sees at most "
          "silhouettes against the background and cannot tell pipelines apart; add a KHR_lights_punctual light or set "
          "the scene's extras.stereobench.ambient",
          file_, scene.lights.empty() ? "no lights" : "every light has zero intensity or colour"));
    return scene;
  }

 private:
  [[noreturn]] void fail(const std::string& path, const std::string& what) const {
    throw InputError(fmt::format("{}: {}: {}", file_, path, what));
  }

  /// Records an unsupported feature once, counting repeats.
  void warn(const std::string& key, const std::string& text) { note(key, "unsupported: " + text); }

  /// A warning said once per key, with its count.
  void note(const std::string& key, const std::string& text) {
    if (warning_counts_[key]++ == 0) warning_text_[key] = text;
  }

  /// Required extensions were checked with the JSON (check_gltf_json); the unsupported ones the
  /// file only uses are ignored, and said so.
  void check_extensions() {
    const std::vector<std::string>& supported = supported_gltf_extensions();
    for (const std::string& e : m_.extensionsUsed)
      if (std::find(supported.begin(), supported.end(), e) == supported.end())
        warn("ext:" + e, fmt::format("extension '{}' is ignored", e));
    // glTF requires every extension an object uses to be listed in extensionsUsed; one that is
    // not would otherwise be dropped without a word.
    std::set<std::string> unlisted;
    collect_unlisted_extensions(doc_, unlisted);
    for (const std::string& e : unlisted)
      if (std::find(supported.begin(), supported.end(), e) == supported.end())
        warn("ext:" + e, fmt::format("extension '{}' is ignored (the file uses it without listing it in "
                                     "extensionsUsed, which glTF requires)",
                                     e));
  }

  void collect_unlisted_extensions(const json& v, std::set<std::string>& out) const {
    if (v.is_object()) {
      for (const auto& [key, value] : v.items()) {
        if (key == "extensions" && value.is_object()) {
          for (const auto& [name, ext] : value.items())
            if (std::find(m_.extensionsUsed.begin(), m_.extensionsUsed.end(), name) == m_.extensionsUsed.end())
              out.insert(name);
        }
        if (key != "extras") collect_unlisted_extensions(value, out);
      }
    } else if (v.is_array()) {
      for (const json& e : v) collect_unlisted_extensions(e, out);
    }
  }

  AccessorView view_of(int index, const std::string& path) const {
    const tinygltf::Accessor& a = m_.accessors[static_cast<size_t>(index)];
    const std::string apath = fmt::format("/accessors/{}", index);
    AccessorView v;
    v.count = a.count;
    v.components = component_count(a.type);
    v.component_type = a.componentType;
    v.component_size = component_size(a.componentType);
    v.normalized = a.normalized;
    const size_t elem = v.component_size * static_cast<size_t>(v.components);
    if (a.bufferView < 0) {
      v.stride = elem;
      return v;
    }
    const tinygltf::BufferView& bv = m_.bufferViews[static_cast<size_t>(a.bufferView)];
    const tinygltf::Buffer& buf = m_.buffers[static_cast<size_t>(bv.buffer)];
    const std::string bvpath = fmt::format("/bufferViews/{}", a.bufferView);
    if (bv.byteOffset > buf.data.size() || bv.byteLength > buf.data.size() - bv.byteOffset)
      fail(bvpath, fmt::format("bytes [{}, {}) lie outside buffer {} of {} bytes (used by {})", bv.byteOffset,
                               bv.byteOffset + bv.byteLength, bv.buffer, buf.data.size(), path));
    v.stride = bv.byteStride ? bv.byteStride : elem;
    if (v.stride < elem)
      fail(bvpath + "/byteStride", fmt::format("stride {} is smaller than one {} element of {} bytes (accessor {})",
                                               v.stride, type_name(v.components), elem, index));
    // Last byte read. The JSON check bounds count and offsets by 2^53 and strides by 252, so
    // this sum cannot overflow 64 bits.
    const uint64_t end = uint64_t{a.byteOffset} + uint64_t{v.stride} * (a.count - 1) + elem;
    if (end > bv.byteLength)
      fail(apath, fmt::format("{} elements of {} bytes (stride {}) from offset {} need {} bytes, but "
                              "bufferView {} has {}; the count is wrong or the buffer is truncated (used by {})",
                              a.count, elem, v.stride, a.byteOffset, end,
                              a.bufferView, bv.byteLength, path));
    v.base = buf.data.data() + bv.byteOffset + a.byteOffset;
    return v;
  }

  /// Reads an accessor as floats (count x components), applying sparse substitution.
  std::vector<float> read_floats(int index, int want_components, const std::string& path) {
    const AccessorView v = view_of(index, path);
    if (v.components != want_components)
      fail(path, fmt::format("accessor {} has type {}, but {} is needed here", index, type_name(v.components),
                             type_name(want_components)));
    std::vector<float> out(v.count * static_cast<size_t>(v.components), 0.0f);
    if (v.base)
      for (size_t i = 0; i < v.count; ++i)
        for (int c = 0; c < v.components; ++c)
          out[i * v.components + c] =
              read_component(v.base + i * v.stride + c * v.component_size, v.component_type, v.normalized);
    for_each_sparse(index, v, [&](uint32_t target, const unsigned char* value) {
      for (int c = 0; c < v.components; ++c)
        out[target * v.components + c] = read_component(value + c * v.component_size, v.component_type, v.normalized);
    });
    for (float f : out)
      if (!std::isfinite(f)) fail(fmt::format("/accessors/{}", index), fmt::format("contains a non-finite value (used by {})", path));
    return out;
  }

  /// Calls set(element, value bytes) for every sparse substitution of accessor `index`, in order.
  template <class Set>
  void for_each_sparse(int index, const AccessorView& v, Set&& set) {
    const tinygltf::Accessor& a = m_.accessors[static_cast<size_t>(index)];
    if (!a.sparse.isSparse) return;
    const std::string sp = fmt::format("/accessors/{}/sparse", index);
    const size_t n = static_cast<size_t>(a.sparse.count);
    auto span_of = [&](int view, size_t offset, size_t bytes, const std::string& where) -> const unsigned char* {
      const tinygltf::BufferView& bv = m_.bufferViews[static_cast<size_t>(view)];
      const tinygltf::Buffer& buf = m_.buffers[static_cast<size_t>(bv.buffer)];
      if (bv.byteOffset > buf.data.size() || bv.byteLength > buf.data.size() - bv.byteOffset ||
          offset > bv.byteLength || bytes > bv.byteLength - offset)
        fail(where, fmt::format("{} bytes at offset {} lie outside bufferView {}", bytes, offset, view));
      return buf.data.data() + bv.byteOffset + offset;
    };
    const size_t isize = component_size(a.sparse.indices.componentType);
    const unsigned char* idx = span_of(a.sparse.indices.bufferView, a.sparse.indices.byteOffset, n * isize, sp + "/indices");
    const size_t elem = v.component_size * static_cast<size_t>(v.components);
    const unsigned char* val = span_of(a.sparse.values.bufferView, a.sparse.values.byteOffset, n * elem, sp + "/values");
    std::optional<uint32_t> previous;
    for (size_t i = 0; i < n; ++i) {
      const uint32_t target = read_index(idx + i * isize, a.sparse.indices.componentType);
      if (target >= v.count)
        fail(sp + "/indices", fmt::format("sparse index {} at element {} is out of range for {} elements", target, i, v.count));
      // glTF requires strictly increasing indices: with one given twice, which value wins is
      // the reader's choice, and another tool's may differ.
      if (previous && target <= *previous)
        fail(sp + "/indices", fmt::format("sparse index {} at element {} follows {}; the indices must increase "
                                          "strictly (glTF 2.0, accessor.sparse.indices)",
                                          target, i, *previous));
      previous = target;
      set(target, val + i * elem);
    }
  }

  std::vector<uint32_t> read_indices(int index, size_t vertex_count, const std::string& path) {
    const AccessorView v = view_of(index, path);
    if (v.components != 1)
      fail(path, fmt::format("index accessor {} has type {}, indices must be SCALAR", index, type_name(v.components)));
    if (v.component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        v.component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        v.component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
      fail(path, fmt::format("index accessor {} has component type {}; indices must be UNSIGNED_BYTE, "
                             "UNSIGNED_SHORT or UNSIGNED_INT", index, v.component_type));
    std::vector<uint32_t> out(v.count, 0);
    if (v.base)
      for (size_t i = 0; i < v.count; ++i) out[i] = read_index(v.base + i * v.stride, v.component_type);
    for_each_sparse(index, v, [&](uint32_t target, const unsigned char* value) {
      out[target] = read_index(value, v.component_type);
    });
    for (size_t i = 0; i < out.size(); ++i)
      if (out[i] >= vertex_count)
        fail(fmt::format("/accessors/{}", index),
             fmt::format("index value {} at element {} is out of range: the primitive has {} vertices (used by {})",
                         out[i], i, vertex_count, path));
    return out;
  }

  /// KHR_texture_transform of a textureInfo (checked by check_gltf_json): the affine map of the
  /// extension's GLSL, translation x rotation x scale, with the rotation as its example reads it
  /// (rotation pi/2, scale 0.5, offset (0, 1) maps the unit square onto the lower left quadrant:
  /// u' = cos r su u + sin r sv v + ou, v' = -sin r su u + cos r sv v + ov); its texCoord
  /// overrides the textureInfo's.
  static void read_texture_transform(Material& mat, const json& texture_info) {
    const auto ext = texture_info.find("extensions");
    if (ext == texture_info.end() || !ext->is_object()) return;
    const auto tt = ext->find("KHR_texture_transform");
    if (tt == ext->end()) return;
    const auto pair = [&](const char* key, double fallback) {
      const auto v = tt->find(key);
      return v == tt->end() ? std::array<double, 2>{fallback, fallback}
                            : std::array<double, 2>{(*v)[0].get<double>(), (*v)[1].get<double>()};
    };
    const std::array<double, 2> offset = pair("offset", 0.0), scale = pair("scale", 1.0);
    const double rotation = tt->value("rotation", 0.0);
    const double c = std::cos(rotation), s = std::sin(rotation);
    mat.uv_transform = {c * scale[0], s * scale[1], offset[0], -s * scale[0], c * scale[1], offset[1]};
    if (const auto tc = tt->find("texCoord"); tc != tt->end()) mat.texcoord = tc->get<int>();
  }

  void convert_materials(Scene& scene) {
    std::map<int, int> texture_of_gltf;  // glTF texture index -> Scene::textures index
    for (size_t i = 0; i < m_.materials.size(); ++i) {
      const tinygltf::Material& gm = m_.materials[i];
      const std::string path = fmt::format("/materials/{}", i);
      Material mat;
      mat.name = gm.name.empty() ? fmt::format("material{}", i) : gm.name;
      const auto& f = gm.pbrMetallicRoughness.baseColorFactor;
      mat.base_color = vec4(float(f[0]), float(f[1]), float(f[2]), float(f[3]));
      mat.double_sided = gm.doubleSided;
      if (gm.normalTexture.index >= 0) warn("normalTexture", "normal textures are ignored (geometric or vertex normals are used)");
      if (gm.emissiveTexture.index >= 0 || gm.emissiveFactor[0] > 0 || gm.emissiveFactor[1] > 0 || gm.emissiveFactor[2] > 0)
        warn("emissive", "emission is ignored (direct light from punctual lights only)");
      if (gm.occlusionTexture.index >= 0)
        warn("occlusionTexture", "occlusion textures are ignored (direct light only; the ambient term is not occluded)");
      if (gm.pbrMetallicRoughness.metallicRoughnessTexture.index >= 0)
        warn("metallicRoughnessTexture", "metallic-roughness textures are ignored (surfaces are Lambertian)");
      if (gm.alphaMode == "MASK") {
        mat.alpha_mode = Material::AlphaMode::mask;
        mat.alpha_cutoff = static_cast<float>(gm.alphaCutoff);
      } else if (gm.alphaMode == "BLEND") {
        mat.alpha_mode = Material::AlphaMode::blend;
        warn("alpha:BLEND", "alphaMode BLEND (rendered as OPAQUE: surfaces are not blended)");
      }
      const int t = gm.pbrMetallicRoughness.baseColorTexture.index;
      if (t >= 0 && options_.load_textures) {
        mat.texcoord = gm.pbrMetallicRoughness.baseColorTexture.texCoord;
        read_texture_transform(mat, doc_.at("materials").at(i).at("pbrMetallicRoughness").at("baseColorTexture"));
        auto it = texture_of_gltf.find(t);
        if (it == texture_of_gltf.end()) {
          const int converted = convert_texture(scene, t, path + "/pbrMetallicRoughness/baseColorTexture");
          it = texture_of_gltf.emplace(t, converted).first;
        }
        mat.base_color_texture = it->second;
      }
      scene.materials.push_back(std::move(mat));
    }
  }

  /// What a texture takes per texel beyond its decoded values (4 B per channel), at the peak,
  /// which comes when the scene is prepared: its RGBA floats (16 B), beside them the mip chain's
  /// level 0 (16 B), the first level's row pass in double (16 B) and the coarser levels (5.3 B),
  /// 53.3 B with the decoder's and the process's own memory on top. Calibrated on the measured
  /// peak of an 8192x8192 RGB PNG, 60.6 B per texel (4.07 GB, `scenes info`): 50 B more than the
  /// decoded values' 12 B gives 62 B.
  static constexpr uint64_t kTextureBytesPerTexel = 50;

  int convert_texture(Scene& scene, int t, const std::string& path) {
    const tinygltf::Texture& gt = m_.textures[static_cast<size_t>(t)];
    if (gt.source < 0) {
      warn("texture-no-source", "textures without an image source (the factor alone is used)");
      return -1;
    }
    const tinygltf::Image& gi = m_.images[static_cast<size_t>(gt.source)];
    const std::string ipath = fmt::format("/images/{}", gt.source);
    if (gi.width != -1 || gi.image.empty())
      fail(ipath, fmt::format("image has no data (used by {})", path));
    DecodedImage img;
    try {
      // Checked once for the whole, before decoding: each stage checked alone against what was
      // left fitted, and together a 20000x20000 PNG of 1.2 MB took the whole machine.
      img = decode_image(gi.image, fmt::format("{} {}", file_, ipath), kTextureBytesPerTexel);
    } catch (const ResourceError&) {
      throw;  // too large for this machine, not malformed
    } catch (const Error& e) {
      fail(ipath, fmt::format("cannot decode the image: {}", e.what()));
    }
    Texture tex;
    tex.name = gi.name.empty() ? (gi.uri.empty() || is_data_uri(gi.uri) ? fmt::format("image{}", gt.source) : gi.uri) : gi.name;
    tex.width = img.width;
    tex.height = img.height;
    const int ch = img.channels;
    // PNG and JPEG decode to [0, 1]; another format OpenImageIO reads (a float TIFF or EXR, a
    // Radiance file) may hold anything, and a NaN or negative colour would reach the images.
    for (size_t i = 0; i < img.values.size(); ++i)
      if (!(img.values[i] >= 0.0f && img.values[i] <= 1.0f)) {
        const size_t texel = i / static_cast<size_t>(ch);
        fail(ipath, fmt::format("texel ({}, {}) channel {} is {}; a base colour texture holds values in [0, 1] (glTF "
                                "images are PNG or JPEG)",
                                texel % static_cast<size_t>(img.width), texel / static_cast<size_t>(img.width),
                                i % static_cast<size_t>(ch), img.values[i]));
      }
    // An RGBA image becomes the texture in place; another is copied out, and its values freed.
    if (ch == 4) tex.rgba = std::move(img.values);
    else tex.rgba.resize(static_cast<size_t>(img.width) * img.height * 4);
    for (size_t p = 0; p < static_cast<size_t>(img.width) * img.height; ++p) {
      const float* s = (ch == 4 ? tex.rgba.data() : img.values.data()) + p * ch;
      const float r = s[0], g = ch >= 3 ? s[1] : s[0], b = ch >= 3 ? s[2] : s[0];
      const float a = ch == 4 ? s[3] : ch == 2 ? s[1] : 1.0f;
      // glTF base colour textures are sRGB-encoded.
      tex.rgba[p * 4 + 0] = srgb_to_linear(r);
      tex.rgba[p * 4 + 1] = srgb_to_linear(g);
      tex.rgba[p * 4 + 2] = srgb_to_linear(b);
      tex.rgba[p * 4 + 3] = a;
    }
    img.values = {};
    if (gt.sampler >= 0) {
      const tinygltf::Sampler& s = m_.samplers[static_cast<size_t>(gt.sampler)];
      tex.repeat_s = s.wrapS != TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
      tex.repeat_t = s.wrapT != TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
      if (s.wrapS == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT || s.wrapT == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT)
        warn("mirrored", "MIRRORED_REPEAT wrapping (treated as REPEAT)");
      // Textures are filtered trilinearly (DESIGN §3): a sampler asking for nearest texels (pixel art)
      // comes out smoothed.
      if (s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST || s.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST ||
          s.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST ||
          s.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_LINEAR)
        warn("nearest", "NEAREST texture filtering (textures are filtered trilinearly)");
    }
    scene.textures.push_back(std::move(tex));
    return static_cast<int>(scene.textures.size() - 1);
  }

  /// A node's own transform as glTF gives it: its matrix, or translation, rotation (normalized)
  /// and scale.
  static NodeAnimation::Local local_of(const tinygltf::Node& n) {
    NodeAnimation::Local l;
    if (n.matrix.size() == 16) {
      dmat4 m;
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r) m[c][r] = n.matrix[static_cast<size_t>(c * 4 + r)];
      l.matrix = m;
      return l;
    }
    if (n.translation.size() == 3) l.translation = dvec3(n.translation[0], n.translation[1], n.translation[2]);
    if (n.rotation.size() == 4) {
      // glm: (w, x, y, z). Normalized after scaling by the largest component, so that components
      // whose squares overflow (1e200) or underflow turn the node as their direction says.
      dquat q(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]);
      const double largest = std::max({std::abs(q.w), std::abs(q.x), std::abs(q.y), std::abs(q.z)});
      if (largest > 0.0) {
        q = q / largest;
        l.rotation = q / glm::length(q);
      }
    }
    if (n.scale.size() == 3) l.scale = dvec3(n.scale[0], n.scale[1], n.scale[2]);
    return l;
  }

  /// EXT_mesh_gpu_instancing: the node's instances, each its translation, rotation and scale
  /// (T * R * S, in the node's space: the node's world transform times it places the instance).
  /// nullopt where the node has no instancing (its mesh is drawn once); an empty list draws nothing.
  std::optional<std::vector<dmat4>> instances_of(int ni) {
    const json* found = instancing_attributes(ni);
    if (!found) return std::nullopt;
    const json& attributes = *found;
    const std::string ip = fmt::format("/nodes/{}/extensions/EXT_mesh_gpu_instancing/attributes", ni);
    std::optional<size_t> count;
    const auto read = [&](const char* name, int components) -> std::vector<float> {
      if (!attributes.contains(name)) return {};
      const std::string where = ip + "/" + name;
      std::vector<float> values = read_floats(attributes[name].get<int>(), components, where);
      const size_t n = values.size() / static_cast<size_t>(components);
      if (count && *count != n)
        fail(where, fmt::format("has {} instances where the node's other instancing attributes have {}; give every "
                                "attribute one element per instance",
                                n, *count));
      count = n;
      return values;
    };
    const std::vector<float> t = read("TRANSLATION", 3), r = read("ROTATION", 4), sc = read("SCALE", 3);
    if (!count) {
      note("instancing-no-attributes", fmt::format("{}: no TRANSLATION, ROTATION or SCALE; the mesh is drawn once, "
                                                   "where the node places it",
                                                   ip));
      return std::nullopt;
    }
    std::vector<dmat4> out(*count);
    for (size_t k = 0; k < *count; ++k) {
      NodeAnimation::Local l;
      if (!t.empty()) l.translation = dvec3(t[k * 3], t[k * 3 + 1], t[k * 3 + 2]);
      if (!r.empty()) {
        const dquat q(r[k * 4 + 3], r[k * 4], r[k * 4 + 1], r[k * 4 + 2]);  // glm: (w, x, y, z)
        const double len = glm::length(q);
        if (!(len > 0.0))
          fail(ip + "/ROTATION", fmt::format("instance {}'s quaternion has length zero; a rotation is a unit "
                                             "quaternion [x, y, z, w], e.g. [0, 0, 0, 1] for none",
                                             k));
        l.rotation = q / len;
      }
      if (!sc.empty()) l.scale = dvec3(sc[k * 3], sc[k * 3 + 1], sc[k * 3 + 2]);
      out[k] = l.transform();
    }
    return out;
  }


  /// The file's node animations (translation, rotation, scale channels of the loaded scene's
  /// nodes) and the node hierarchy they move, for paths (renderer/animation.hpp); a still render
  /// shows the nodes at rest. Morph-target weights are reported as unsupported.
  void convert_animations(Scene& scene) {
    if (m_.animations.empty()) return;
    NodeAnimation& a = scene.animation;
    // The hierarchy as the loaded scene has it (the traversal checked it for cycles): a node
    // outside it, and what it parents there, does not move anything shown.
    a.parent = parent_;
    a.local.clear();
    for (const tinygltf::Node& n : m_.nodes) a.local.push_back(local_of(n));
    size_t weights = 0, outside = 0;
    for (size_t ai = 0; ai < m_.animations.size(); ++ai) {
      const tinygltf::Animation& anim = m_.animations[ai];
      a.clips.push_back(anim.name);
      // glTF 2.0 §3.11: within one animation, a node's property is keyed by one channel at most.
      std::map<std::pair<int, int>, std::string> keyed;  // (node, property) -> the channel keying it
      for (size_t ci = 0; ci < anim.channels.size(); ++ci) {
        const tinygltf::AnimationChannel& gc = anim.channels[ci];
        const std::string cpath = fmt::format("/animations/{}/channels/{}", ai, ci);
        if (gc.target_path == "weights") {
          ++weights;
          continue;
        }
        if (gc.target_node < 0) continue;  // glTF allows a channel without a node: it animates nothing
        if (static_cast<size_t>(gc.target_node) >= m_.nodes.size())
          fail(cpath + "/target/node", fmt::format("node {} does not exist (the file has {} nodes)", gc.target_node,
                                                   m_.nodes.size()));
        NodeAnimation::Channel ch;
        ch.clip = static_cast<int>(ai);
        ch.node = gc.target_node;
        int width = 3;
        if (gc.target_path == "translation") ch.property = NodeAnimation::Property::translation;
        else if (gc.target_path == "scale") ch.property = NodeAnimation::Property::scale;
        else if (gc.target_path == "rotation") ch.property = NodeAnimation::Property::rotation, width = 4;
        else fail(cpath + "/target/path", fmt::format("'{}' is not translation, rotation, scale or weights", gc.target_path));
        if (!visited_[static_cast<size_t>(ch.node)]) {  // a node outside the loaded scene moves nothing shown
          ++outside;
          continue;
        }
        if (a.local[static_cast<size_t>(ch.node)].matrix)
          fail(cpath + "/target/node", fmt::format("node {} has a matrix, and glTF allows animating only a node "
                                                   "given by translation, rotation and scale", ch.node));
        if (gc.sampler < 0 || static_cast<size_t>(gc.sampler) >= anim.samplers.size())
          fail(cpath + "/sampler", fmt::format("sampler {} does not exist (animation {} has {})", gc.sampler, ai,
                                               anim.samplers.size()));
        const tinygltf::AnimationSampler& gs = anim.samplers[static_cast<size_t>(gc.sampler)];
        const std::string spath = fmt::format("/animations/{}/samplers/{}", ai, gc.sampler);
        if (gs.interpolation == "STEP") ch.interpolation = NodeAnimation::Interpolation::step;
        else if (gs.interpolation == "CUBICSPLINE") ch.interpolation = NodeAnimation::Interpolation::cubic_spline;
        else if (gs.interpolation.empty() || gs.interpolation == "LINEAR") ch.interpolation = NodeAnimation::Interpolation::linear;
        else fail(spath + "/interpolation", fmt::format("'{}' is not LINEAR, STEP or CUBICSPLINE", gs.interpolation));
        // glTF 2.0 §3.11: key times are floats; translation and scale floats; rotations floats or
        // normalized integers.
        const tinygltf::Accessor& in = m_.accessors[static_cast<size_t>(gs.input)];
        const tinygltf::Accessor& out = m_.accessors[static_cast<size_t>(gs.output)];
        if (in.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
          fail(spath + "/input", fmt::format("accessor {} holds component type {}; key times must be floats (5126)",
                                             gs.input, in.componentType));
        const bool float_out = out.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT;
        const bool normalized_out = out.normalized && out.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
        if (!float_out && !(ch.property == NodeAnimation::Property::rotation && normalized_out))
          fail(spath + "/output",
               fmt::format("accessor {} holds component type {}{}; a {} must be floats (5126){}", gs.output,
                           out.componentType, out.normalized ? " (normalized)" : "", gc.target_path,
                           ch.property == NodeAnimation::Property::rotation ? " or normalized 8- or 16-bit integers" : ""));
        // Both are kept as doubles while the file is loaded. The accessors' ranges first: a count
        // beyond its buffer view is a malformed file, not a memory limit.
        (void)view_of(gs.input, spath + "/input");
        (void)view_of(gs.output, spath + "/output");
        require_memory(16 * (uint64_t{in.count} + uint64_t{out.count} * static_cast<uint64_t>(width)),
                       fmt::format("loading {}: {} ({} keys)", file_, spath, in.count),
                       "check the sampler's accessor counts, or use a smaller animation");
        const std::vector<float> times = read_floats(gs.input, 1, spath + "/input");
        const std::vector<float> values = read_floats(gs.output, width, spath + "/output");
        if (times.empty()) fail(spath + "/input", "the sampler has no keyframe");
        for (size_t k = 0; k < times.size(); ++k) {
          if (times[k] < 0.0f) fail(spath + "/input", fmt::format("key time {} is negative", times[k]));
          if (k > 0 && !(times[k] > times[k - 1]))
            fail(spath + "/input", fmt::format("key times must increase: {} follows {}", times[k], times[k - 1]));
        }
        const size_t per_key = ch.interpolation == NodeAnimation::Interpolation::cubic_spline ? 3 : 1;
        if (values.size() != times.size() * per_key * static_cast<size_t>(width))
          fail(spath + "/output", fmt::format("{} values for {} key times ({} per key expected)", values.size() / width,
                                              times.size(), per_key));
        // A key rotation is a quaternion with a direction, as a node's rotation is (a spline's
        // tangents may be zero; its value may not).
        if (ch.property == NodeAnimation::Property::rotation)
          for (size_t k = 0; k < times.size(); ++k) {
            const float* q = values.data() + (k * per_key + (per_key == 3 ? 1 : 0)) * 4;
            if (!(std::max({std::abs(q[0]), std::abs(q[1]), std::abs(q[2]), std::abs(q[3])}) > 0.0f))
              fail(spath + "/output", fmt::format("the rotation of key {} (at {} s) is a quaternion of length zero; a "
                                                  "rotation is a unit quaternion [x, y, z, w], e.g. [0, 0, 0, 1] for "
                                                  "none",
                                                  k, times[k]));
          }
        ch.times.assign(times.begin(), times.end());
        ch.values.assign(values.begin(), values.end());
        const auto [it, first] = keyed.emplace(std::pair(ch.node, static_cast<int>(ch.property)), cpath);
        if (!first)
          fail(cpath + "/target", fmt::format("keys node {}'s {} as {} does; within one animation a node's property may "
                                              "be keyed by one channel only",
                                              ch.node, gc.target_path, it->second));
        a.channels.push_back(std::move(ch));
      }
    }
    if (weights > 0) warn("animation-weights", fmt::format("{} morph-target weight channel(s) ignored", weights));
    if (outside > 0)
      warn("animation-outside", fmt::format("{} animation channel(s) key nodes outside the loaded scene and are not "
                                            "played", outside));
    if (!a.channels.empty())
      scene.warnings.push_back(fmt::format("{} animation(s) ({}) with {} node channel(s): a still image shows the nodes "
                                           "at rest; a path plays them (`stereobench path --gltf-animation`, or "
                                           "`--gltf-clip NAME` for one; a sweep's [path] gltf_animation = true, or "
                                           "gltf_clip = \"NAME\")",
                                           m_.animations.size(), a.clip_list(), a.channels.size()));
  }

  /// Walks the scene's node forest iteratively (deep or cyclic hierarchies cannot overflow the stack).
  void traverse(Scene& scene) {
    std::vector<int> roots;
    if (!m_.scenes.empty()) {
      const size_t si = m_.defaultScene >= 0 ? static_cast<size_t>(m_.defaultScene) : 0;
      for (int n : m_.scenes[si].nodes) roots.push_back(n);
      if (m_.scenes.size() > 1) warn("scenes", fmt::format("{} scenes in the file; only scene {} is loaded", m_.scenes.size(), si));
    } else {
      std::vector<bool> has_parent(m_.nodes.size(), false);
      for (const auto& n : m_.nodes)
        for (int c : n.children) has_parent[static_cast<size_t>(c)] = true;
      for (size_t i = 0; i < m_.nodes.size(); ++i)
        if (!has_parent[i]) roots.push_back(static_cast<int>(i));
    }
    // Count the triangles the traversal would produce before allocating them.
    parent_.assign(m_.nodes.size(), -1);
    std::vector<bool>& visited = visited_;
    visited.assign(m_.nodes.size(), false);
    struct Item { int node; dmat4 world; };
    std::vector<Item> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back({*it, dmat4(1.0)});
    std::vector<Item> order;
    uint64_t triangles = 0, vertices = 0;
    while (!stack.empty()) {
      Item item = stack.back();
      stack.pop_back();
      const size_t ni = static_cast<size_t>(item.node);
      if (visited[ni])
        fail(fmt::format("/nodes/{}", ni), "node is reached twice: the node hierarchy has a cycle or a node "
                                           "with two parents, which glTF forbids");
      visited[ni] = true;
      const tinygltf::Node& n = m_.nodes[ni];
      item.world = item.world * local_of(n).transform();
      order.push_back(item);
      if (n.mesh >= 0) {
        const uint64_t copies = instance_count(static_cast<int>(ni));
        const auto& prims = m_.meshes[static_cast<size_t>(n.mesh)].primitives;
        for (size_t pi = 0; pi < prims.size(); ++pi) {
          const std::string ppath = fmt::format("/meshes/{}/primitives/{}", n.mesh, pi);
          if (all_at_origin(prims[pi])) continue;
          const uint64_t each = estimated_triangles(prims[pi], ppath);
          // Against the limit before multiplying: a count of 2^53 copies would wrap around.
          if (each > 0 && copies > kMaxSceneTriangles / each) {
            triangles = kMaxSceneTriangles + 1;
            break;
          }
          triangles += copies * each;
          if (auto it = prims[pi].attributes.find("POSITION"); it != prims[pi].attributes.end())
            if (const uint64_t count = view_of(it->second, ppath).count; count > 0)
              vertices = copies > ((uint64_t{1} << 62) - vertices) / count ? uint64_t{1} << 62
                                                                            : vertices + copies * count;
          if (triangles > kMaxSceneTriangles) break;
        }
      }
      if (triangles > kMaxSceneTriangles)
        fail(fmt::format("/nodes/{}", ni), fmt::format("the scene expands to more than {} triangles; this is "
                                                        "beyond what the renderer holds in memory", kMaxSceneTriangles));
      for (auto c = n.children.rbegin(); c != n.children.rend(); ++c) {
        parent_[static_cast<size_t>(*c)] = item.node;
        stack.push_back({*c, item.world});
      }
    }
    // Before any mesh is read: an accessor's count alone (without a bufferView its elements are
    // zeros) can ask for more than the machine holds, which under overcommit ends in the OOM killer.
    require_memory(loaded_mesh_bytes(triangles, vertices),
                   fmt::format("loading {}: {} triangles, {} vertices", file_, triangles, vertices),
                   "use a smaller scene, check the accessors' counts, or run on a machine with more memory");
    // The animations first: a mesh on an animated node keeps its node-local vertices.
    convert_animations(scene);
    for (const Item& item : order) visit(scene, item.node, item.world);
    // Nodes with meshes or lights that the loaded scene does not reach: in another glTF scene, or
    // in none. They are not rendered here; a tool that imports the file whole would show them.
    for (size_t i = 0; i < m_.nodes.size(); ++i)
      if (!visited[i] && (m_.nodes[i].mesh >= 0 || m_.nodes[i].extensions.count("KHR_lights_punctual") > 0))
        ++scene.nodes_not_loaded;
    if (scene.nodes_not_loaded > 0 && m_.scenes.size() <= 1)
      warn("orphan-nodes", fmt::format("{} node(s) with a mesh or light are in no scene and are not loaded",
                                       scene.nodes_not_loaded));
    // A camera the loaded scene does not reach is not the rig's pose: without another, the rig
    // frames the scene from +Z instead, which a render alone would not tell.
    if (scene.cameras.empty())
      for (size_t i = 0; i < m_.nodes.size(); ++i)
        if (!visited[i] && m_.nodes[i].camera >= 0) {
          note("orphan-camera", fmt::format("the camera of node {} is in no loaded scene and is not used: the rig "
                                            "frames the scene from +Z instead; add the node to the scene",
                                            i));
          break;
        }
  }

  /// A skinned node's joint matrices (glTF 2.0 §3.7.3): joint i's world transform, as the file
  /// places its node, times its inverse bind matrix (identity where the skin gives none). The skinned
  /// node's own transform is not used, as glTF says.
  struct Skinning {
    int skin = -1;
    std::vector<dmat4> joints;
  };

  /// The skinning of node `ni`, or nullopt where it has no skin. Skeletal animation is not played:
  /// a skinned mesh keeps the pose of its joints at rest, which a path whose animation moves them
  /// is told.
  std::optional<Skinning> skinning_of(Scene& scene, int ni) {
    const json& node = doc_.at("nodes").at(static_cast<size_t>(ni));
    if (!node.contains("skin")) return std::nullopt;
    Skinning s;
    s.skin = node["skin"].get<int>();
    const std::string sp = fmt::format("/skins/{}", s.skin);
    const json& skin = doc_.at("skins").at(static_cast<size_t>(s.skin));
    const json& joints = skin.at("joints");
    std::vector<float> inverse_bind;
    if (skin.contains("inverseBindMatrices")) {
      const int a = skin["inverseBindMatrices"].get<int>();
      inverse_bind = read_floats(a, 16, sp + "/inverseBindMatrices");
      if (inverse_bind.size() / 16 < joints.size())
        fail(sp + "/inverseBindMatrices", fmt::format("accessor {} has {} matrices for {} joints; give one per joint",
                                                      a, inverse_bind.size() / 16, joints.size()));
    }
    bool moved = scene.animation.moves(ni);
    for (size_t j = 0; j < joints.size(); ++j) {
      const int joint = joints[j].get<int>();
      dmat4 ibm(1.0);
      if (!inverse_bind.empty())
        for (int c = 0; c < 4; ++c)
          for (int r = 0; r < 4; ++r) ibm[c][r] = inverse_bind[j * 16 + static_cast<size_t>(c * 4 + r)];
      s.joints.push_back(rest_world_of(joint) * ibm);
      moved = moved || scene.animation.moves(joint);
    }
    if (moved)
      note("skin-animation", "skeletal animation is not played: skinned meshes keep the pose of their joints at rest "
                             "in every frame of a path");
    return s;
  }

  /// Node `ni`'s world transform as the file places it, whether or not the loaded scene reaches it
  /// (a skin's joints may lie outside it).
  dmat4 rest_world_of(int ni) {
    if (all_parents_.empty()) {
      all_parents_.assign(m_.nodes.size(), -1);
      for (size_t p = 0; p < m_.nodes.size(); ++p)
        for (int c : m_.nodes[p].children) all_parents_[static_cast<size_t>(c)] = static_cast<int>(p);
    }
    dmat4 world(1.0);
    size_t steps = 0;
    for (int n = ni; n >= 0; n = all_parents_[static_cast<size_t>(n)]) {
      if (++steps > m_.nodes.size())
        fail(fmt::format("/nodes/{}", ni), "the node's ancestors form a cycle, which glTF forbids (a node that is its "
                                           "own ancestor); it is a skin's joint, so its place is needed");
      world = local_of(m_.nodes[static_cast<size_t>(n)]).transform() * world;
    }
    return world;
  }

  /// A skinned primitive's JOINTS_n / WEIGHTS_n sets, read once; at(v) is vertex v's transform:
  /// the sum of weight times joint matrix over its sets, the weights normalized to sum 1 (as
  /// Blender's armature modifier does). A vertex with no weight keeps the skin's bind space.
  struct SkinBlend {
    const Skinning* skin = nullptr;
    std::vector<std::vector<float>> joints, weights;  ///< per set, 4 per vertex

    [[nodiscard]] dmat4 at(size_t v) const {
      dmat4 sum(0.0);
      double total = 0.0;
      for (size_t set = 0; set < joints.size(); ++set)
        for (size_t c = 0; c < 4; ++c) {
          const double weight = weights[set][v * 4 + c];
          if (weight == 0.0) continue;
          sum += weight * skin->joints[static_cast<size_t>(joints[set][v * 4 + c])];
          total += weight;
        }
      return total > 0.0 ? sum / total : dmat4(1.0);
    }
  };

  /// Reads and checks the skin attributes of a primitive with nv vertices (joints in range,
  /// weights not negative).
  SkinBlend skin_blend(const Skinning& skin, const tinygltf::Primitive& prim, size_t nv, const std::string& ppath) {
    SkinBlend b;
    b.skin = &skin;
    for (int set = 0;; ++set) {
      const auto j = prim.attributes.find(fmt::format("JOINTS_{}", set));
      const auto w = prim.attributes.find(fmt::format("WEIGHTS_{}", set));
      if (j == prim.attributes.end() || w == prim.attributes.end()) break;
      const std::string jp = fmt::format("{}/attributes/JOINTS_{}", ppath, set);
      const std::string wp = fmt::format("{}/attributes/WEIGHTS_{}", ppath, set);
      std::vector<float> joints = read_floats(j->second, 4, jp);
      std::vector<float> weights = read_floats(w->second, 4, wp);
      if (joints.size() != nv * 4) fail(jp, fmt::format("has {} elements but POSITION has {}", joints.size() / 4, nv));
      if (weights.size() != nv * 4) fail(wp, fmt::format("has {} elements but POSITION has {}", weights.size() / 4, nv));
      for (size_t v = 0; v < nv; ++v)
        for (size_t c = 0; c < 4; ++c) {
          const float weight = weights[v * 4 + c], joint = joints[v * 4 + c];
          if (weight < 0.0f) fail(wp, fmt::format("vertex {} has a negative weight {:g}", v, weight));
          if (weight > 0.0f && !(joint < static_cast<float>(skin.joints.size())))
            fail(jp, fmt::format("vertex {} names joint {:g} of skin {}, which has {} joints", v, joint, skin.skin,
                                 skin.joints.size()));
        }
      b.joints.push_back(std::move(joints));
      b.weights.push_back(std::move(weights));
    }
    if (b.joints.empty())
      note("skin-without-weights", fmt::format("{}: a skinned primitive without JOINTS_0 and WEIGHTS_0 is placed in "
                                               "its skin's bind space, as the file's vertices are",
                                               ppath));
    return b;
  }

  /// How many times a node's mesh is drawn: the element count of its first EXT_mesh_gpu_instancing
  /// attribute (instances_of checks that the others agree as it reads them), else once.
  uint64_t instance_count(int ni) const {
    const json* attributes = instancing_attributes(ni);
    if (!attributes || doc_.at("nodes").at(static_cast<size_t>(ni)).contains("skin")) return 1;
    for (const char* name : {"TRANSLATION", "ROTATION", "SCALE"})
      if (attributes->contains(name))
        return view_of((*attributes)[name].get<int>(), fmt::format("/nodes/{}/extensions/EXT_mesh_gpu_instancing", ni))
            .count;
    return 1;
  }

  /// The attributes of node `ni`'s EXT_mesh_gpu_instancing (checked by check_gltf_json), or
  /// nullptr where it has none.
  const json* instancing_attributes(int ni) const {
    const json& node = doc_.at("nodes").at(static_cast<size_t>(ni));
    const auto ext = node.find("extensions");
    if (ext == node.end() || !ext->contains("EXT_mesh_gpu_instancing")) return nullptr;
    return &(*ext)["EXT_mesh_gpu_instancing"]["attributes"];
  }

  /// Whether a primitive's POSITION accessor has neither a bufferView nor sparse values: glTF
  /// makes every such vertex (0, 0, 0), so every triangle is degenerate and nothing of it can be seen.
  bool all_at_origin(const tinygltf::Primitive& prim) const {
    const auto it = prim.attributes.find("POSITION");
    if (it == prim.attributes.end()) return false;
    const tinygltf::Accessor& a = m_.accessors[static_cast<size_t>(it->second)];
    return a.bufferView < 0 && !a.sparse.isSparse;
  }

  /// Triangles a primitive will produce; checks the byte range of the accessor it counts by.
  uint64_t estimated_triangles(const tinygltf::Primitive& prim, const std::string& path) const {
    int counted = prim.indices;
    if (counted < 0)
      if (auto it = prim.attributes.find("POSITION"); it != prim.attributes.end()) counted = it->second;
    if (counted < 0) return 0;
    const uint64_t n = view_of(counted, path).count;
    return prim.mode == TINYGLTF_MODE_TRIANGLES ? n / 3 : n;
  }

  /// What the meshes of a scene take while they are read, at most: per vertex its position,
  /// normal and texture coordinate (32 B) and the decoded accessors of one attribute at a time
  /// (24 B); per triangle its indices, read and kept (24 B).
  static uint64_t loaded_mesh_bytes(uint64_t triangles, uint64_t vertices) { return 56 * vertices + 24 * triangles; }

  void visit(Scene& scene, int ni, const dmat4& world) {
    const tinygltf::Node& n = m_.nodes[static_cast<size_t>(ni)];
    const std::string npath = fmt::format("/nodes/{}", ni);
    if (n.mesh >= 0) {
      if (const std::optional<Skinning> skin = skinning_of(scene, ni)) {
        if (instancing_attributes(ni))
          note(fmt::format("skin-instances-{}", ni),
               fmt::format("/nodes/{}: a skinned node's EXT_mesh_gpu_instancing is ignored (its mesh is drawn once, "
                           "posed by its skin)",
                           ni));
        convert_mesh(scene, ni, n.mesh, world, dmat4(1.0), -1, &*skin);
      } else if (const std::optional<std::vector<dmat4>> instances = instances_of(ni)) {
        for (size_t k = 0; k < instances->size(); ++k)
          convert_mesh(scene, ni, n.mesh, world, (*instances)[k], static_cast<int>(k));
        scene.instances[ni] = *instances;
      } else {
        convert_mesh(scene, ni, n.mesh, world, dmat4(1.0), -1);
      }
    }
    if (n.camera >= 0) {
      convert_camera(scene, ni, world);
    } else if (const json& node_json = doc_.at("nodes").at(static_cast<size_t>(ni));
               node_json.contains("extras") && node_json["extras"].is_object() &&
               node_json["extras"].contains("stereobench")) {
      note("stray-rig-extras", fmt::format("/nodes/{}/extras/stereobench is on a node without a camera and is "
                                           "ignored: the rig's defaults are read from the first camera's node",
                                           ni));
    }
    auto ext = n.extensions.find("KHR_lights_punctual");
    if (ext != n.extensions.end()) {
      const int li = ext->second.Get("light").GetNumberAsInt();
      convert_light(scene, li, world);
      scene.lights.back().node = ni;
      scene.animation.light_nodes.push_back(ni);
    }
  }

  /// Adds the primitives of mesh `mi` on node `ni` at `node_world * instance` (instance `k` of
  /// the node's EXT_mesh_gpu_instancing, or -1 with the identity where it has none).
  /// With `skin`, each vertex is placed by its joints instead (skinning_of), and `node_world` and
  /// `instance` are not used.
  void convert_mesh(Scene& scene, int ni, int mi, const dmat4& node_world, const dmat4& instance, int k,
                    const Skinning* skin = nullptr) {
    const tinygltf::Mesh& gm = m_.meshes[static_cast<size_t>(mi)];
    const dmat4 world = node_world * instance;
    const dmat3 normal_matrix = glm::transpose(glm::inverse(dmat3(world)));
    const dmat3 instance_normals = glm::transpose(glm::inverse(dmat3(instance)));
    const bool flip = glm::determinant(dmat3(world)) < 0.0;
    for (size_t pi = 0; pi < gm.primitives.size(); ++pi) {
      const tinygltf::Primitive& prim = gm.primitives[pi];
      const std::string ppath = fmt::format("/meshes/{}/primitives/{}", mi, pi);
      if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
          prim.mode != TINYGLTF_MODE_TRIANGLE_FAN) {
        static const char* names[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP"};
        warn(fmt::format("mode{}", prim.mode), fmt::format("primitives of mode {} are skipped (only triangles render)",
                                                         prim.mode >= 0 && prim.mode < 4 ? names[prim.mode] : "?"));
        continue;
      }
      if (!prim.targets.empty()) warn("morph", "morph targets are ignored (base shape used)");
      auto pos_it = prim.attributes.find("POSITION");
      if (pos_it == prim.attributes.end()) fail(ppath + "/attributes", "primitive has no POSITION attribute");
      if (all_at_origin(prim)) {
        warn("positions-at-origin",
             fmt::format("{}/attributes/POSITION: accessor {} has no bufferView and no sparse values, so every vertex "
                         "is at the origin and no triangle can be seen; the primitive is skipped",
                         ppath, pos_it->second));
        continue;
      }
      Mesh mesh;
      mesh.name = gm.name.empty() ? fmt::format("mesh{}", mi) : gm.name;
      if (gm.primitives.size() > 1) mesh.name += fmt::format(".{}", pi);
      if (k >= 0) mesh.name += fmt::format("#{}", k);
      mesh.node = ni;
      mesh.instance = k;
      mesh.skinned = skin != nullptr;
      mesh.material = prim.material;
      const std::vector<float> pos = read_floats(pos_it->second, 3, ppath + "/attributes/POSITION");
      const size_t nv = pos.size() / 3;
      // A mesh that an animation moves keeps its node-local geometry for the frames of a path. A
      // skinned one stays in the pose of its joints at rest (skinning_of says so where they move).
      const bool animated = !skin && scene.animation.moves(ni);
      // Per vertex, the transform of its joints blended by its weights.
      const SkinBlend blend = skin ? skin_blend(*skin, prim, nv, ppath) : SkinBlend();
      // Per vertex of a skinned primitive, whether its blend mirrors (its triangles are reversed).
      std::vector<bool> mirrors(skin ? nv : 0);
      if (animated) {
        mesh.local_positions.resize(nv);
        for (size_t v = 0; v < nv; ++v)
          mesh.local_positions[v] = vec3(dvec3(instance * dvec4(pos[v * 3], pos[v * 3 + 1], pos[v * 3 + 2], 1.0)));
      }
      // A skinned mesh's triangles are reversed one by one below, where their joints mirror.
      mesh.mirrored = !skin && flip;
      mesh.positions.resize(nv);
      for (size_t v = 0; v < nv; ++v) {
        const dmat4 to_world = skin ? blend.at(v) : world;
        if (skin) mirrors[v] = glm::determinant(dmat3(to_world)) < 0.0;
        const dvec3 p = dvec3(to_world * dvec4(pos[v * 3], pos[v * 3 + 1], pos[v * 3 + 2], 1.0));
        if (!within_scene_range(p))
          fail(fmt::format("/nodes/{}", ni),
               fmt::format("places vertex {} of mesh '{}' at ({:g}, {:g}, {:g}) m, beyond the ±{:g} m a scene may "
                           "span; check the node's scale and the file's units",
                           v, mesh.name, p.x, p.y, p.z, kMaxSceneCoordinate));
        mesh.positions[v] = vec3(p);
      }
      // Every other attribute has POSITION's count: checked before it is read, so that a small
      // file cannot make the loader allocate for a count it does not have.
      const auto same_count = [&](int accessor, const std::string& where) {
        const size_t n = view_of(accessor, where).count;
        if (n != nv) fail(where, fmt::format("accessor {} has {} elements but POSITION has {}", accessor, n, nv));
      };
      for (const auto& [name, accessor] : prim.attributes)
        if (name.rfind("COLOR_", 0) == 0)
          warn("vertex-colors", "vertex colours (COLOR_n) are ignored: the base colour is the material's factor and "
                                "texture");
      std::vector<float> nrm;
      if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
        same_count(it->second, ppath + "/attributes/NORMAL");
        nrm = read_floats(it->second, 3, ppath + "/attributes/NORMAL");
        // glTF normals are unit length; a zero one has no direction to interpolate.
        size_t zero = 0;
        for (size_t v = 0; v < nv; ++v) zero += nrm[v * 3] == 0.0f && nrm[v * 3 + 1] == 0.0f && nrm[v * 3 + 2] == 0.0f;
        if (zero > 0) {
          scene.warnings.push_back(
              fmt::format("{}/attributes/NORMAL: {} of the {} vertex normals have length zero (accessor {}); the "
                          "primitive is shaded with its geometric normals",
                          ppath, zero, nv, it->second));
          nrm.clear();
          mesh.file_normals_dropped = true;
        }
      }
      if (!nrm.empty()) {
        mesh.normals.resize(nv);
        if (animated) {
          mesh.local_normals.resize(nv);
          for (size_t v = 0; v < nv; ++v)
            mesh.local_normals[v] = vec3(instance_normals * dvec3(nrm[v * 3], nrm[v * 3 + 1], nrm[v * 3 + 2]));
        }
        for (size_t v = 0; v < nv; ++v) {
          // A skinned vertex's blend again (cheaper than holding a matrix per vertex).
          const dmat3 to_world = skin ? glm::transpose(glm::inverse(dmat3(blend.at(v)))) : normal_matrix;
          dvec3 nn = to_world * dvec3(nrm[v * 3], nrm[v * 3 + 1], nrm[v * 3 + 2]);
          const double len = glm::length(nn);
          mesh.normals[v] = len > 0.0 ? vec3(nn / len) : vec3(0.0f, 1.0f, 0.0f);
        }
      }
      const int tc = prim.material >= 0 ? scene.materials[static_cast<size_t>(prim.material)].texcoord : 0;
      const std::string uv_name = fmt::format("TEXCOORD_{}", tc);
      if (auto it = prim.attributes.find(uv_name); it != prim.attributes.end()) {
        same_count(it->second, ppath + "/attributes/" + uv_name);
        const std::vector<float> uv = read_floats(it->second, 2, ppath + "/attributes/" + uv_name);
        mesh.uvs.resize(nv);
        for (size_t v = 0; v < nv; ++v) mesh.uvs[v] = vec2(uv[v * 2], uv[v * 2 + 1]);
        // The texture's KHR_texture_transform, applied once here: every renderer, the texture LOD
        // and the POV-Ray export read transformed coordinates.
        if (prim.material >= 0 && scene.materials[static_cast<size_t>(prim.material)].has_uv_transform()) {
          const std::array<double, 6>& t = scene.materials[static_cast<size_t>(prim.material)].uv_transform;
          for (vec2& c : mesh.uvs) {
            const double u = c.x, w = c.y;
            c = vec2(static_cast<float>(t[0] * u + t[1] * w + t[2]), static_cast<float>(t[3] * u + t[4] * w + t[5]));
            if (!std::isfinite(c.x) || !std::isfinite(c.y))
              fail(fmt::format("/materials/{}/pbrMetallicRoughness/baseColorTexture/extensions/KHR_texture_transform",
                               prim.material),
                   fmt::format("takes the texture coordinates of {} beyond the range of a float ({} at ({}, {})); "
                               "give a smaller scale or offset",
                               ppath, c.x, u, w));
          }
        }
      } else if (prim.material >= 0 && scene.materials[static_cast<size_t>(prim.material)].base_color_texture >= 0) {
        warn("missing-uv:" + uv_name,
             fmt::format("textured materials on primitives without the texture coordinates they read, {} (texture "
                         "ignored there)",
                         uv_name));
      }
      std::vector<uint32_t> idx;
      if (prim.indices >= 0) {
        idx = read_indices(prim.indices, nv, ppath + "/indices");
      } else {
        idx.resize(nv);
        for (size_t v = 0; v < nv; ++v) idx[v] = static_cast<uint32_t>(v);
      }
      mesh.indices = triangulate(idx, prim.mode, ppath);
      if (mesh.indices.empty() && prim.mode != TINYGLTF_MODE_TRIANGLES)
        // Said (and listed by an otherwise empty scene's error), not dropped in silence.
        note("short-" + ppath, fmt::format("{}: a {} of {} {} has no triangle; it is skipped", ppath,
                                           prim.mode == TINYGLTF_MODE_TRIANGLE_STRIP ? "TRIANGLE_STRIP" : "TRIANGLE_FAN",
                                           idx.size(), idx.size() == 1 ? "vertex" : "vertices"));
      if (skin) {
        // Each triangle keeps facing the way the file says under the blend at its first corner.
        for (size_t t = 0; t < mesh.indices.size(); t += 3)
          if (mirrors[mesh.indices[t]])
            std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);
      } else if (flip) {
        for (size_t t = 0; t < mesh.indices.size(); t += 3) std::swap(mesh.indices[t + 1], mesh.indices[t + 2]);
      }
      if (!mesh.indices.empty()) scene.meshes.push_back(std::move(mesh));
    }
  }

  std::vector<uint32_t> triangulate(const std::vector<uint32_t>& idx, int mode, const std::string& path) {
    std::vector<uint32_t> out;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      if (idx.size() % 3 != 0)
        fail(path, fmt::format("TRIANGLES primitive has {} indices, not a multiple of 3", idx.size()));
      return idx;
    }
    if (idx.size() < 3) return out;
    out.reserve((idx.size() - 2) * 3);
    for (size_t i = 0; i + 2 < idx.size(); ++i) {
      if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        // Every other triangle of a strip is wound the other way round.
        if (i % 2 == 0) out.insert(out.end(), {idx[i], idx[i + 1], idx[i + 2]});
        else out.insert(out.end(), {idx[i + 1], idx[i], idx[i + 2]});
      } else {
        out.insert(out.end(), {idx[0], idx[i + 1], idx[i + 2]});
      }
    }
    return out;
  }

  void convert_camera(Scene& scene, int ni, const dmat4& world) {
    const tinygltf::Node& n = m_.nodes[static_cast<size_t>(ni)];
    const tinygltf::Camera& gc = m_.cameras[static_cast<size_t>(n.camera)];
    if (gc.type != "perspective") {
      warn("ortho", "orthographic cameras are ignored, with their pose: without a perspective camera the rig frames "
                    "the scene's bounds from +Z (give a perspective camera to keep the view)");
      return;
    }
    if (!within_scene_range(dvec3(world[3])))
      fail(fmt::format("/nodes/{}", ni),
           fmt::format("places the camera at ({:g}, {:g}, {:g}) m, beyond the ±{:g} m a scene may span; check the "
                       "node's translation and the file's units",
                       world[3].x, world[3].y, world[3].z, kMaxSceneCoordinate));
    // The first camera is the rig's: its pose needs a viewing direction and an up axis that are not
    // parallel, checked here so that the message names the node. Other cameras are not used (an
    // exporter may hide one with a zero scale).
    if (scene.cameras.empty()) {
      try {
        (void)CameraPose::from_matrix(world);
      } catch (const InputError& e) {
        fail(fmt::format("/nodes/{}", ni),
             fmt::format("the camera's transform (this node's with its parents') cannot place the rig: {} (or "
                         "its parents')",
                         e.what()));
      }
    }
    SceneCamera cam;
    cam.name = n.name.empty() ? (gc.name.empty() ? fmt::format("camera{}", n.camera) : gc.name) : n.name;
    cam.node = ni;
    cam.world_from_camera = world;
    cam.yfov = gc.perspective.yfov;
    cam.aspect = gc.perspective.aspectRatio;
    cam.znear = gc.perspective.znear;
    cam.zfar = gc.perspective.zfar;
    if (scene.cameras.empty()) {
      const json& node_json = doc_.at("nodes").at(static_cast<size_t>(ni));
      if (auto e = node_json.find("extras"); e != node_json.end() && e->is_object())
        if (auto sbx = e->find("stereobench"); sbx != e->end()) {
          if (sbx->contains("interaxial")) scene.rig.interaxial = sbx->at("interaxial").get<double>();
          if (sbx->contains("convergence")) scene.rig.convergence = sbx->at("convergence").get<double>();
          if (sbx->contains("width")) scene.rig.width = sbx->at("width").get<int>();
          if (sbx->contains("height")) scene.rig.height = sbx->at("height").get<int>();
          scene.rig.where = fmt::format("/nodes/{}/extras/stereobench", ni);
        }
    } else {
      warn("cameras", "more than one camera: the first in node order is the default rig's pose");
    }
    scene.cameras.push_back(cam);
  }

  void convert_light(Scene& scene, int li, const dmat4& world) {
    const json& lj = doc_.at("extensions").at("KHR_lights_punctual").at("lights").at(static_cast<size_t>(li));
    Light l;
    l.name = lj.value("name", fmt::format("light{}", li));
    const std::string type = lj.at("type").get<std::string>();
    l.type = type == "directional" ? Light::Type::directional : type == "spot" ? Light::Type::spot : Light::Type::point;
    if (auto c = lj.find("color"); c != lj.end()) l.color = vec3((*c)[0].get<float>(), (*c)[1].get<float>(), (*c)[2].get<float>());
    l.intensity = lj.value("intensity", 1.0f);
    l.range = lj.value("range", 0.0f);
    if (l.range > 0.0f) warn("range", "light 'range' (lights have no cutoff; inverse-square falloff is exact)");
    if (l.type == Light::Type::spot) {
      const json& s = lj.at("spot");
      l.inner_cone = s.value("innerConeAngle", 0.0f);
      l.outer_cone = s.value("outerConeAngle", 0.78539816f);
    }
    if (l.type != Light::Type::directional && !within_scene_range(dvec3(world[3])))
      fail(fmt::format("/extensions/KHR_lights_punctual/lights/{}", li),
           fmt::format("light '{}' is placed at ({:g}, {:g}, {:g}) m, beyond the ±{:g} m a scene may span; check "
                       "its node's translation and the file's units",
                       l.name, world[3].x, world[3].y, world[3].z, kMaxSceneCoordinate));
    l.place(world);
    scene.lights.push_back(l);
  }

  void read_scene_extras(Scene& scene) {
    auto scenes = doc_.find("scenes");
    if (scenes == doc_.end() || scenes->empty()) return;
    const size_t si = m_.defaultScene >= 0 ? static_cast<size_t>(m_.defaultScene) : 0;
    const json& s = (*scenes)[si];
    if (auto n = s.find("name"); n != s.end() && n->is_string()) scene.name = n->get<std::string>();
    auto e = s.find("extras");
    if (e == s.end() || !e->is_object()) return;
    auto sbx = e->find("stereobench");
    if (sbx == e->end()) return;
    if (auto b = sbx->find("background"); b != sbx->end())
      scene.background = vec3((*b)[0].get<float>(), (*b)[1].get<float>(), (*b)[2].get<float>());
    if (auto a = sbx->find("ambient"); a != sbx->end()) scene.ambient = a->get<float>();
  }

  const tinygltf::Model& m_;
  const json& doc_;
  std::string file_;
  GltfLoadOptions options_;
  std::vector<int> parent_;    ///< per node: its parent as the traversal reached it, -1 for a root or unreached
  std::vector<int> all_parents_;  ///< per node: its parent in the file, -1 for a root (rest_world_of)
  std::vector<bool> visited_;  ///< per node: whether the loaded scene reaches it
  std::map<std::string, int> warning_counts_;
  std::map<std::string, std::string> warning_text_;
};

}  // namespace

Scene load_gltf(const fs::path& path, const GltfLoadOptions& options) {
  const std::string file = path.string();
  std::error_code ec;
  if (!fs::exists(path, ec))
    throw InputError(fmt::format("{}: scene file does not exist; check the path, or run "
                                 "`stereobench scenes list` for the built-in scenes", file));
  if (!fs::is_regular_file(path, ec))
    throw InputError(fmt::format("{}: not a regular file; give a .gltf or .glb file", file));
  // The reader takes at most 4 GiB (a .glb's own length field has 32 bits), and loading holds the
  // file about three times over (its bytes, the reader's copy, the buffers it decodes) before the
  // meshes are converted: refused before the first byte is read, naming the file.
  if (const uintmax_t size = fs::file_size(path, ec); !ec) {
    if (size > std::numeric_limits<uint32_t>::max())
      throw InputError(fmt::format("{}: {} bytes; a glTF file is at most 4 GiB (a .glb's length field has 32 bits): "
                                   "split the scene, or keep its buffers in external .bin files",
                                   file, size));
    require_memory(3 * uint64_t{size}, fmt::format("loading {} ({:.1f} MiB, held about three times while it is read)",
                                                   file, double(size) / (1024.0 * 1024.0)),
                   "use a smaller scene, or run on a machine with more memory");
  }
  // A file that cannot be read (permissions, a failing disk, too little memory) is an I/O failure.
  const std::string bytes = read_file(path);
  if (bytes.empty()) throw InputError(fmt::format("{}: the file is empty; give a .gltf or .glb file", file));
  const GlbParts parts = split_container(bytes, file, lowercase(path.extension().string()) == ".glb");
  json doc;
  try {
    doc = parse_json(parts.json_text);
  } catch (const JsonTextError& e) {
    // A syntax error has a byte; nesting and number range are limits of the reader on valid JSON.
    if (e.byte() == 0)
      throw InputError(fmt::format("{}: its JSON exceeds what the reader accepts: {}", file, e.what()));
    // Not JSON from its first byte, under another name than .gltf: some other kind of file (an
    // image or a mesh given as the scene).
    if (e.byte() == 1 && lowercase(path.extension().string()) != ".gltf")
      throw InputError(fmt::format("{}: not a glTF scene (neither glTF JSON nor binary .glb); give a .gltf or .glb "
                                   "file, or a built-in scene name (stereobench scenes list)",
                                   file));
    throw InputError(fmt::format("{}: not valid JSON at byte {}: {}; the file is cut short or damaged there: export it "
                                 "again, or mend the JSON",
                                 file, e.byte(), short_parse_error(e.what())));
  }
  check_gltf_json(doc, file);
  const fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  AllowedFiles allowed = check_external_files(doc, dir, file, parts);

  const std::string input = tinygltf_input(doc, bytes, parts, file);

  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(keep_image_bytes, nullptr);
  loader.SetFsCallbacks({allowed_file_exists, tinygltf::ExpandFilePath, read_allowed_file, tinygltf::WriteWholeFile,
                         &allowed});
  tinygltf::Model model;
  std::string err, warn;
  const bool ok = parts.is_glb
      ? loader.LoadBinaryFromMemory(&model, &err, &warn, reinterpret_cast<const unsigned char*>(input.data()),
                                    static_cast<unsigned int>(input.size()), dir.string())
      : loader.LoadASCIIFromString(&model, &err, &warn, input.data(), static_cast<unsigned int>(input.size()),
                                   dir.string());
  if (!ok || !err.empty()) {
    while (!err.empty() && (err.back() == '\n' || err.back() == '\r')) err.pop_back();
    throw InputError(fmt::format("{}: cannot load: {}", file, err.empty() ? "unknown error" : err));
  }
  for (size_t i = 0; i < model.buffers.size(); ++i)
    if (model.buffers[i].data.size() < static_cast<size_t>(doc["buffers"][i]["byteLength"].get<uint64_t>()))
      throw InputError(fmt::format("{}: /buffers/{}: holds {} bytes but byteLength says {}; the buffer is truncated",
                                   file, i, model.buffers[i].data.size(), doc["buffers"][i]["byteLength"].get<uint64_t>()));
  Scene scene = Converter(model, doc, file, options).run();
  if (scene.name.empty()) scene.name = path.stem().string();
  for (const auto& [key, read] : allowed) scene.files_read.push_back(read.string());
  return scene;
}

}  // namespace sb::io
