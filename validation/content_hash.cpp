// SHA-256 through OpenSSL's EVP interface.
#include "validation/content_hash.hpp"

#include <array>
#include <fstream>
#include <vector>

#include <fmt/format.h>
#include <openssl/evp.h>

#include "renderer/error.hpp"

namespace sb::validation {

namespace {
EVP_MD_CTX* md(void* p) { return static_cast<EVP_MD_CTX*>(p); }
}  // namespace

Sha256::Sha256() : ctx_(EVP_MD_CTX_new()) {
  if (ctx_ == nullptr || EVP_DigestInit_ex(md(ctx_), EVP_sha256(), nullptr) != 1)
    throw std::runtime_error("OpenSSL could not start a SHA-256 digest");
}

Sha256::~Sha256() { EVP_MD_CTX_free(md(ctx_)); }

Sha256& Sha256::add(std::span<const std::byte> bytes) {
  if (!bytes.empty() && EVP_DigestUpdate(md(ctx_), bytes.data(), bytes.size()) != 1)
    throw std::runtime_error("OpenSSL SHA-256 update failed");
  return *this;
}

Sha256& Sha256::add(std::string_view text) {
  // The length first, so that ("ab", "c") and ("a", "bc") differ.
  add_value(static_cast<uint64_t>(text.size()));
  return add(std::as_bytes(std::span<const char>(text.data(), text.size())));
}

std::string Sha256::hex() {
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
  unsigned int n = 0;
  if (EVP_DigestFinal_ex(md(ctx_), digest.data(), &n) != 1) throw std::runtime_error("OpenSSL SHA-256 final failed");
  std::string out;
  out.reserve(2 * n);
  for (unsigned int i = 0; i < n; ++i) out += fmt::format("{:02x}", digest[i]);
  return out;
}

std::string hash_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(fmt::format("cannot read '{}' to hash it; check that it exists and is readable", path.string()));
  Sha256 sha;
  std::vector<char> buffer(1 << 20);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const auto got = static_cast<size_t>(in.gcount());
    sha.add(std::as_bytes(std::span<const char>(buffer.data(), got)));
  }
  if (in.bad()) throw IoError(fmt::format("reading '{}' failed while hashing it", path.string()));
  return sha.hex();
}

std::string hash_scene(const Scene& scene) {
  Sha256 sha;
  sha.add("stereobench-scene-hash 1");
  sha.add_value(static_cast<uint64_t>(scene.meshes.size()));
  for (const Mesh& m : scene.meshes) {
    sha.add_value(m.material);
    sha.add_value(static_cast<uint64_t>(m.positions.size()));
    sha.add_pod(std::span<const vec3>(m.positions));
    sha.add_value(static_cast<uint64_t>(m.normals.size()));
    sha.add_pod(std::span<const vec3>(m.normals));
    sha.add_value(static_cast<uint64_t>(m.uvs.size()));
    sha.add_pod(std::span<const vec2>(m.uvs));
    sha.add_value(static_cast<uint64_t>(m.indices.size()));
    sha.add_pod(std::span<const uint32_t>(m.indices));
  }
  sha.add_value(static_cast<uint64_t>(scene.materials.size()));
  for (const Material& m : scene.materials) {
    sha.add_value(m.base_color);
    sha.add_value(m.base_color_texture);
    sha.add_value(m.texcoord);
    sha.add_value(static_cast<uint8_t>(m.double_sided));
    // Only a cut-out changes what is rendered (BLEND renders as OPAQUE); opaque materials hash as
    // they did before cut-outs existed, so stored references keep their scene hashes.
    if (m.alpha_mode == Material::AlphaMode::mask) {
      sha.add("alpha-mask");
      sha.add_value(m.alpha_cutoff);
    }
    // Likewise a texture transform (the meshes' uvs hold it already; Blender's material reads it).
    if (m.has_uv_transform()) {
      sha.add("uv-transform");
      for (const double v : m.uv_transform) sha.add_value(v);
    }
  }
  sha.add_value(static_cast<uint64_t>(scene.textures.size()));
  for (const Texture& t : scene.textures) {
    sha.add_value(t.width);
    sha.add_value(t.height);
    sha.add_value(static_cast<uint8_t>(t.repeat_s));
    sha.add_value(static_cast<uint8_t>(t.repeat_t));
    sha.add_pod(std::span<const float>(t.rgba));
  }
  sha.add_value(static_cast<uint64_t>(scene.lights.size()));
  for (const Light& l : scene.lights) {
    sha.add_value(static_cast<int>(l.type));
    sha.add_value(l.position);
    sha.add_value(l.direction);
    sha.add_value(l.color);
    sha.add_value(l.intensity);
    sha.add_value(l.range);
    sha.add_value(l.inner_cone);
    sha.add_value(l.outer_cone);
  }
  sha.add_value(scene.background);
  sha.add_value(scene.ambient);
  return sha.hex();
}

std::string hash_image(const Image& image) {
  Sha256 sha;
  sha.add("stereobench-image-hash 1");
  sha.add_value(image.width());
  sha.add_value(image.height());
  for (const Plane& p : image.planes()) {
    sha.add(p.name());
    sha.add_value(p.channels());
    sha.add_value(static_cast<int>(p.type()));
    if (p.type() == PlaneType::f32)
      sha.add_pod(std::span<const float>(p.data_f32(), p.value_count()));
    else
      sha.add_pod(std::span<const uint32_t>(p.data_u32(), p.value_count()));
  }
  return sha.hex();
}

}  // namespace sb::validation
