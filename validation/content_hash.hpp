// Content hashes (SHA-256, hex) of files, scenes and images: the keys of the truth cache and the
// image hashes of reference provenance.
#pragma once

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include "renderer/image.hpp"
#include "renderer/scene.hpp"

namespace sb::validation {

/// Incremental SHA-256.
class Sha256 {
 public:
  Sha256();
  ~Sha256();
  Sha256(const Sha256&) = delete;
  Sha256& operator=(const Sha256&) = delete;

  Sha256& add(std::span<const std::byte> bytes);
  Sha256& add(std::string_view text);
  /// Adds a value's object representation (for trivially copyable numbers and arrays of them).
  template <class T>
  Sha256& add_pod(std::span<const T> values) {
    return add(std::as_bytes(values));
  }
  template <class T>
  Sha256& add_value(const T& value) {
    return add(std::as_bytes(std::span<const T, 1>(&value, 1)));
  }
  /// The digest as 64 lowercase hex digits; the object cannot be used afterwards.
  [[nodiscard]] std::string hex();

 private:
  void* ctx_;
};

/// SHA-256 of a file's bytes; IoError naming the file if it cannot be read.
[[nodiscard]] std::string hash_file(const std::filesystem::path& path);

/// SHA-256 of everything in a loaded scene that shading and visibility depend on: geometry,
/// normals, UVs, materials, texture texels, lights, background and ambient (not names or paths).
/// Two scenes with the same hash render the same images.
[[nodiscard]] std::string hash_scene(const Scene& scene);

/// SHA-256 of an image's size and planes (names, shapes and samples, bit for bit).
[[nodiscard]] std::string hash_image(const Image& image);

}  // namespace sb::validation
