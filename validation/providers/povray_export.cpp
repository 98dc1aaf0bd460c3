// POV-Ray SDL export of a scene and one eye (see povray_export.hpp and docs/truth_povray.md).
#include "validation/providers/povray_export.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <limits>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/image.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/image_io.hpp"
#include "renderer/text.hpp"

namespace sb::validation::povray {

namespace {

constexpr double kPiD = 3.14159265358979323846;

/// Squared distance from p to triangle (a, b, c): the closest point by Voronoi regions of the
/// vertices, edges and face.
double distance2_to_triangle(const dvec3& p, const dvec3& a, const dvec3& b, const dvec3& c) {
  const dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  const auto dist2 = [&](const dvec3& q) { return glm::dot(p - q, p - q); };
  if (d1 <= 0.0 && d2 <= 0.0) return dist2(a);
  const dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return dist2(b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return dist2(a + (d1 / (d1 - d3)) * ab);
  const dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return dist2(c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return dist2(a + (d2 / (d2 - d6)) * ac);
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
    return dist2(b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b));
  const double denom = va + vb + vc;
  if (denom <= 0.0) {
    // Degenerate triangle: the nearest of its edges.
    const auto seg = [&](const dvec3& s, const dvec3& e) {
      const dvec3 d = e - s;
      const double len2 = glm::dot(d, d);
      const double t = len2 > 0.0 ? std::clamp(glm::dot(p - s, d) / len2, 0.0, 1.0) : 0.0;
      return dist2(s + t * d);
    };
    return std::min({seg(a, b), seg(b, c), seg(c, a)});
  }
  const double v = vb / denom, w = vc / denom;
  return dist2(a + v * ab + w * ac);
}

/// Squared distance from p to an axis-aligned box.
double distance2_to_box(const dvec3& p, const dvec3& lo, const dvec3& hi) {
  const dvec3 d = glm::max(glm::max(lo - p, p - hi), dvec3(0.0));
  return glm::dot(d, d);
}

/// A buffered writer of one text file through stdio, flushed in large blocks.
class SdlStream {
 public:
  explicit SdlStream(const std::filesystem::path& path) : path_(path), file_(std::fopen(path.c_str(), "wb")) {
    if (!file_)
      throw IoError(fmt::format("cannot create the POV-Ray scene file '{}': {}", path.string(), std::strerror(errno)));
  }
  SdlStream(const SdlStream&) = delete;
  SdlStream& operator=(const SdlStream&) = delete;
  ~SdlStream() {
    if (file_) std::fclose(file_);
  }

  template <typename... Args>
  void print(fmt::format_string<Args...> format, Args&&... args) {
    fmt::format_to(std::back_inserter(buffer_), format, std::forward<Args>(args)...);
    if (buffer_.size() >= kFlushBytes) flush();
  }

  /// Flushes and closes the file; IoError on any write failure.
  std::size_t close() {
    flush();
    const int rc = std::fclose(file_);
    file_ = nullptr;
    if (rc != 0)
      throw IoError(fmt::format("cannot write the POV-Ray scene file '{}': {}", path_.string(), std::strerror(errno)));
    return written_;
  }

 private:
  static constexpr std::size_t kFlushBytes = 1u << 20;

  void flush() {
    if (buffer_.size() == 0) return;
    if (std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size())
      throw IoError(fmt::format("cannot write the POV-Ray scene file '{}': {}", path_.string(), std::strerror(errno)));
    written_ += buffer_.size();
    buffer_.clear();
  }

  std::filesystem::path path_;
  std::FILE* file_;
  fmt::memory_buffer buffer_;
  std::size_t written_ = 0;
};

/// A vector with 17 significant digits (doubles round-trip exactly).
std::string vec_d(const dvec3& v) { return fmt::format("<{:.17g}, {:.17g}, {:.17g}>", v.x, v.y, v.z); }

nlohmann::json json_vec(const dvec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); }

/// Texels added on each side of an axis that clamps to its edge: POV-Ray's bilinear lookup blends
/// the image's first and last texels across its edge (it repeats the image), where clamping
/// holds the edge texel; one replicated texel around the image gives the lookup the clamped
/// neighbour within half a texel of the edge. A repeating axis gets none.
struct Padding {
  int s = 0, t = 0;
  explicit Padding(const Texture& texture) : s(texture.repeat_s ? 0 : 1), t(texture.repeat_t ? 0 : 1) {}
  [[nodiscard]] bool any() const { return s != 0 || t != 0; }
};

/// An image of `texture`'s size plus its padding, each texel `value(source texel index)`, the
/// padding replicating the edge texels.
template <class Value>
Image padded_image(const Texture& texture, Value value) {
  const Padding pad(texture);
  const int w = texture.width + 2 * pad.s, h = texture.height + 2 * pad.t;
  Image image(w, h);
  float* rgb = image.add_plane(planes::rgb).data_f32();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int sx = std::clamp(x - pad.s, 0, texture.width - 1), sy = std::clamp(y - pad.t, 0, texture.height - 1);
      const std::array<float, 3> v =
          value(static_cast<std::size_t>(sy) * static_cast<std::size_t>(texture.width) + static_cast<std::size_t>(sx));
      float* out = rgb + (static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)) * 3;
      out[0] = v[0], out[1] = v[1], out[2] = v[2];
    }
  return image;
}

/// The pigment transform that maps texture coordinates onto the padded image: u' = (u W + p) / (W
/// + 2p) along each padded axis (POV-Ray evaluates the pattern at the inverse transform); empty
/// without padding.
std::string padding_transform(const Texture& texture) {
  const Padding pad(texture);
  if (!pad.any()) return "";
  const double w = texture.width, h = texture.height;
  return fmt::format(" scale <{:.17g}, {:.17g}, 1> translate <{:.17g}, {:.17g}, 0>", (w + 2.0 * pad.s) / w,
                     (h + 2.0 * pad.t) / h, 0.0 - pad.s / w, 0.0 - pad.t / h);  // 0 - 0 is +0, not -0
}

/// A cut-out's coverage map as a grey EXR: alpha x factor alpha - cutoff + 0.5 per texel, so that
/// the surface exists where the bilinear lookup is at least 0.5 (the lookup is linear, so the shift
/// commutes with it). POV-Ray reads image maps in half precision; centred on 0.5, a texel exactly
/// at the cutoff stays exactly 0.5, where the alpha itself (e.g. 128/255) would be rounded.
void write_coverage_texture(const Texture& texture, const Material& material, const std::filesystem::path& path) {
  const float* rgba = texture.rgba.data();
  const Image image = padded_image(texture, [&](std::size_t i) {
    const float c = rgba[i * 4 + 3] * material.base_color.w - material.alpha_cutoff + 0.5f;
    return std::array<float, 3>{c, c, c};
  });
  io::write_exr(path, image);
}

/// The base colour texture of `material`, baked with its base colour factor, as a 3-channel
/// half-float EXR (POV-Ray 3.7 reads EXR image maps through OpenEXR's half RGBA interface; the
/// file has no alpha channel: a cut-out's coverage is a map of its own, write_coverage_texture).
void write_baked_texture(const Texture& texture, const vec4& factor, const std::filesystem::path& path) {
  const float* rgba = texture.rgba.data();
  const Image image = padded_image(texture, [&](std::size_t i) {
    return std::array<float, 3>{rgba[i * 4] * factor[0], rgba[i * 4 + 1] * factor[1], rgba[i * 4 + 2] * factor[2]};
  });
  io::ExrWriteOptions options;
  options.float_format = io::ExrFloatFormat::f16;
  io::write_exr(path, image, {}, options);
}

/// Whether any texture coordinate of `mesh` leaves [0, 1] along a clamped axis by more than half
/// a texel, beyond which the padded image (Padding) no longer holds the edge texel.
bool reads_outside_clamp(const Mesh& mesh, const Texture& texture) {
  const float margin_s = 0.5f / static_cast<float>(texture.width), margin_t = 0.5f / static_cast<float>(texture.height);
  for (const vec2& uv : mesh.uvs) {
    if (!texture.repeat_s && (uv.x < -margin_s || uv.x > 1.0f + margin_s)) return true;
    if (!texture.repeat_t && (uv.y < -margin_t || uv.y > 1.0f + margin_t)) return true;
  }
  return false;
}

}  // namespace

double min_distance_to_scene(const Scene& scene, const dvec3& p) {
  double best2 = std::numeric_limits<double>::infinity();
  for (const Mesh& mesh : scene.meshes) {
    if (mesh.triangle_count() == 0) continue;
    dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    for (const vec3& v : mesh.positions) {
      lo = glm::min(lo, dvec3(v));
      hi = glm::max(hi, dvec3(v));
    }
    if (distance2_to_box(p, lo, hi) >= best2) continue;
    const std::size_t n = mesh.triangle_count();
    for (std::size_t t = 0; t < n; ++t) {
      const dvec3 a(mesh.positions[mesh.indices[3 * t]]);
      const dvec3 b(mesh.positions[mesh.indices[3 * t + 1]]);
      const dvec3 c(mesh.positions[mesh.indices[3 * t + 2]]);
      // Cheap rejection by the triangle's bounding box before the exact distance.
      if (distance2_to_box(p, glm::min(glm::min(a, b), c), glm::max(glm::max(a, b), c)) >= best2) continue;
      best2 = std::min(best2, distance2_to_triangle(p, a, b, c));
    }
  }
  return std::sqrt(best2);
}

void check_exportable(const Scene& scene) {
  for (std::size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& light = scene.lights[i];
    if (light.type == Light::Type::spot)
      throw InputError(fmt::format(
          "scene '{}': light {} ('{}') is a spot light, which the povray provider cannot render exactly: "
          "POV-Ray 3.7 fades a spotlight between its cones with a cubic smoothstep in cos(angle), the shading "
          "of DESIGN §3 with KHR_lights_punctual's quadratic ramp; use the `full` or `blender` provider for this "
          "scene, or {}",
          scene.name, i, light.name,
          i == 0 ? "remove the light from the scene, or move it after the lights you keep (--lights keeps the first N)"
                 : fmt::format("keep only the lights before it with --lights {} (in a sweep, lights = [{}])", i, i)));
  }
}

ExportResult export_scene(const Scene& scene, const EyeCamera& eye, const std::filesystem::path& dir) {
  check_exportable(scene);
  ExportResult out;

  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw IoError(fmt::format("cannot create the POV-Ray work folder '{}': {}", dir.string(), ec.message()));

  // Textured materials: one baked EXR each, for the materials some mesh with UVs uses.
  std::vector<std::string> texture_name(scene.materials.size());
  std::vector<std::string> texture_transform(scene.materials.size());  // padding_transform per material
  for (const Mesh& mesh : scene.meshes) {
    if (mesh.material < 0 || mesh.uvs.empty() || mesh.triangle_count() == 0) continue;
    const auto m = static_cast<std::size_t>(mesh.material);
    const Material& material = scene.materials[m];
    if (material.base_color_texture < 0) continue;
    const Texture& texture = scene.textures[static_cast<std::size_t>(material.base_color_texture)];
    if (reads_outside_clamp(mesh, texture))
      out.warnings.push_back(fmt::format(
          "mesh '{}': texture '{}' clamps to its edge but is read more than half a texel outside [0, 1]; "
          "POV-Ray repeats it there",
          mesh.name, texture.name));
    if (!texture_name[m].empty()) continue;
    texture_name[m] = fmt::format("texture_{}.exr", m);
    texture_transform[m] = padding_transform(texture);
    const std::filesystem::path file = dir / texture_name[m];
    write_baked_texture(texture, material.base_color, file);
    out.texture_files.push_back(file);
    if (material.alpha_mode == Material::AlphaMode::mask) {
      const std::filesystem::path coverage = dir / fmt::format("coverage_{}.exr", m);
      write_coverage_texture(texture, material, coverage);
      out.texture_files.push_back(coverage);
    }
  }

  out.sdl_file = dir / "scene.pov";
  const Bounds3 bounds = scene.bounds();
  const dvec3 centre = bounds.empty() ? dvec3(0.0) : dvec3(bounds.center());
  const double radius = bounds.empty() ? 1.0 : 0.5 * glm::length(dvec3(bounds.extent()));
  // POV-Ray's tolerances are absolute (a shadow ray ignores hits nearer than 1e-3, an intersection
  // nearer than 1e-4, and rays end at 1e7 units), which lost the shadows of a scene a millimetre
  // wide and the whole of one ten thousand kilometres wide. Positions are written scaled by the
  // power of two that brings the largest coordinate of the scene and the camera to 512..2048
  // units: exact on float coordinates, and the same image, as the shading depends on ratios of
  // lengths only (a point light's falloff on d / fade_distance, both scaled).
  double largest = std::max({std::abs(eye.origin.x), std::abs(eye.origin.y), std::abs(eye.origin.z)});
  if (!bounds.empty())
    for (const vec3& corner : {bounds.lo, bounds.hi})
      largest = std::max({largest, std::abs(double(corner.x)), std::abs(double(corner.y)), std::abs(double(corner.z))});
  const int scale_exponent = largest > 0.0 && std::isfinite(largest)
                                 ? std::clamp(10 - static_cast<int>(std::lround(std::log2(largest))), -100, 100)
                                 : 0;
  const double scale = std::ldexp(1.0, scale_exponent);
  const auto placed = [scale](const dvec3& p) { return scale * p; };

  // Camera: POV-Ray's perspective ray for pixel (i, j) of a W x H image is
  //   direction + ((i + 0.5) / W - 0.5) right + (0.5 - (j + 0.5) / H) up
  // (no normalisation, no handedness), so with right = (W / f) r, up = (H / f) u and direction
  // = -back + ((W/2 - cx) / f) r + ((cy - H/2) / f) u it is EyeCamera::ray_direction at the pixel
  // centre, unnormalised. Positions are written times `scale`, directions unchanged.
  const double w = eye.width, h = eye.height, f = eye.f_px;
  const dvec3 cam_right = (w / f) * eye.right;
  const dvec3 cam_up = (h / f) * eye.up;
  const dvec3 cam_direction = -eye.back + ((0.5 * w - eye.cx) / f) * eye.right + ((eye.cy - 0.5 * h) / f) * eye.up;

  io::write_atomically(out.sdl_file, [&](const std::filesystem::path& tmp) {
    SdlStream sdl(tmp);
    // Names go into comments with their control characters escaped: a line break in a name would
    // end the comment and run the rest as SDL.
    sdl.print("// stereobench {}: scene '{}' ({}), right eye {}x{}\n", kExportRevision, printable(scene.name),
              printable(scene.path), eye.width, eye.height);
    sdl.print("#version 3.7;\n");
    const bool ambient = scene.ambient != 0.0f;
    // A cut-out's holes pass camera and shadow rays (pigment rgbt 1), each pass one trace level.
    const bool cutouts = scene.has_cutouts();
    sdl.print("global_settings {{ assumed_gamma 1.0 ambient_light rgb {} max_trace_level {} }}\n", ambient ? 1 : 0,
              cutouts ? kCutoutTraceLevel : 5);
    for (std::size_t m = 0; m < scene.materials.size(); ++m)
      if (scene.materials[m].alpha_mode == Material::AlphaMode::mask && !texture_name[m].empty())
        sdl.print("#declare SB_Coverage_{} = function {{ pigment {{ image_map {{ exr \"coverage_{}.exr\" interpolate 2 }}{} }} "
                  "}}\n",
                  m, m, texture_transform[m]);
    sdl.print("background {{ rgb <{:.9g}, {:.9g}, {:.9g}> }}\n", scene.background.x, scene.background.y,
              scene.background.z);
    sdl.print("camera {{\n  perspective\n  location {}\n  right {}\n  up {}\n  direction {}\n}}\n",
              vec_d(placed(eye.origin)), vec_d(cam_right), vec_d(cam_up), vec_d(cam_direction));
    sdl.print("#declare SB_Finish = finish {{ ambient {:.9g} emission 0 diffuse 1 brilliance 1 crand 0 "
              "specular 0 phong 0 reflection 0 }}\n",
              static_cast<double>(scene.ambient));

    // Lights: diffuse 1 has no 1/pi, so every colour carries it.
    for (const Light& light : scene.lights) {
      const dvec3 c = dvec3(light.color) * static_cast<double>(light.intensity);
      if (c.x <= 0.0 && c.y <= 0.0 && c.z <= 0.0) continue;
      ExportedLight el;
      el.name = light.name;
      if (light.type == Light::Type::directional) {
        // A parallel light shadows only between its location and the surface: place it outside
        // the scene's bounding sphere, upstream of the light's direction.
        const dvec3 dirn = glm::normalize(dvec3(light.direction));
        const dvec3 location = centre - (2.0 * radius + 1.0) * dirn;
        el.type = "directional";
        const dvec3 col = c / kPiD;
        el.colour[0] = col.x, el.colour[1] = col.y, el.colour[2] = col.z;
        sdl.print("light_source {{ {} rgb {} parallel point_at {} }}  // '{}'\n", vec_d(placed(location)),
                  vec_d(col), vec_d(placed(location) + dirn), printable(light.name));
      } else {
        const dvec3 position(light.position);
        el.type = "point";
        el.min_distance = min_distance_to_scene(scene, position);
        el.fade_distance = std::isfinite(el.min_distance) ? std::max(kFadeFraction * el.min_distance, kMinFadeDistance)
                                                          : 1.0;
        el.max_falloff_error = std::isfinite(el.min_distance) && el.min_distance > 0.0
                                   ? (el.fade_distance / el.min_distance) * (el.fade_distance / el.min_distance)
                                   : std::numeric_limits<double>::infinity();
        // 2 / (1 + (d/fd)^2) = (2 fd^2 / d^2) / (1 + fd^2 / d^2): colour I / (2 pi fd^2).
        const dvec3 col = c / (2.0 * kPiD * el.fade_distance * el.fade_distance);
        el.colour[0] = col.x, el.colour[1] = col.y, el.colour[2] = col.z;
        sdl.print("light_source {{ {} rgb {} fade_distance {:.17g} fade_power 2 }}  // '{}'\n",
                  vec_d(placed(position)), vec_d(col), scale * el.fade_distance, printable(light.name));
      }
      out.lights.push_back(el);
    }

    // Meshes: one mesh2 each, in world space.
    for (const Mesh& mesh : scene.meshes) {
      const std::size_t tris = mesh.triangle_count();
      if (tris == 0) continue;
      const Material* material = mesh.material >= 0 ? &scene.materials[static_cast<std::size_t>(mesh.material)] : nullptr;
      const std::string* tex = mesh.material >= 0 ? &texture_name[static_cast<std::size_t>(mesh.material)] : nullptr;
      const bool textured = tex && !tex->empty() && !mesh.uvs.empty();
      const bool cutout = material && material->alpha_mode == Material::AlphaMode::mask;
      // A cut-out without a texture to read is the factor's alpha everywhere: absent below the
      // cutoff (SceneGeometry::opaque_at), opaque otherwise.
      if (cutout && !textured && material->base_color.w < material->alpha_cutoff) continue;
      sdl.print("mesh2 {{  // '{}'\n  vertex_vectors {{ {}", printable(mesh.name), mesh.positions.size());
      for (const vec3& p : mesh.positions) {
        const dvec3 q = placed(dvec3(p));  // a float times a power of two: 9 digits still round-trip
        sdl.print(",\n    <{:.9g}, {:.9g}, {:.9g}>", q.x, q.y, q.z);
      }
      sdl.print("\n  }}\n");
      if (!mesh.normals.empty()) {
        sdl.print("  normal_vectors {{ {}", mesh.normals.size());
        for (const vec3& n : mesh.normals) sdl.print(",\n    <{:.9g}, {:.9g}, {:.9g}>", n.x, n.y, n.z);
        sdl.print("\n  }}\n");
      }
      if (textured) {
        // glTF's v runs down the image, POV-Ray's image_map v up.
        sdl.print("  uv_vectors {{ {}", mesh.uvs.size());
        for (const vec2& uv : mesh.uvs) sdl.print(",\n    <{:.9g}, {:.9g}>", uv.x, 1.0 - static_cast<double>(uv.y));
        sdl.print("\n  }}\n");
      }
      sdl.print("  face_indices {{ {}", tris);
      for (std::size_t t = 0; t < tris; ++t)
        sdl.print(",\n    <{}, {}, {}>", mesh.indices[3 * t], mesh.indices[3 * t + 1], mesh.indices[3 * t + 2]);
      sdl.print("\n  }}\n");
      if (textured && cutout) {
        // Coverage as SceneGeometry::opaque_at decides it: the bilinear coverage map (alpha x
        // factor alpha - cutoff + 0.5) against 0.5, giving 0 (the hole: fully transmitting) or 1
        // (the material).
        sdl.print("  texture {{ uv_mapping function {{ select(SB_Coverage_{}(x, y, z).red - 0.5, 0, 1) }}\n"
                  "    texture_map {{\n      [0 pigment {{ rgbt 1 }}]\n"
                  "      [1 pigment {{ uv_mapping image_map {{ exr \"{}\" interpolate 2 }}{} }} finish {{ SB_Finish }}]\n"
                  "    }}\n  }}\n",
                  mesh.material, *tex, texture_transform[static_cast<std::size_t>(mesh.material)]);
      } else if (textured) {
        sdl.print("  texture {{ pigment {{ uv_mapping image_map {{ exr \"{}\" interpolate 2 }}{} }} "
                  "finish {{ SB_Finish }} }}\n",
                  *tex, texture_transform[static_cast<std::size_t>(mesh.material)]);
      } else {
        const vec4 c = material ? material->base_color : vec4(1.0f);
        sdl.print("  texture {{ pigment {{ rgb <{:.9g}, {:.9g}, {:.9g}> }} finish {{ SB_Finish }} }}\n", c.x, c.y, c.z);
      }
      sdl.print("}}\n");
      ++out.meshes;
      out.triangles += tris;
    }
    out.sdl_bytes = sdl.close();
  });

  nlohmann::json lights = nlohmann::json::array();
  for (const ExportedLight& l : out.lights) {
    nlohmann::json j = {{"name", l.name}, {"type", l.type}, {"colour", {l.colour[0], l.colour[1], l.colour[2]}}};
    if (l.type == "point") {
      j["fade_distance"] = l.fade_distance;
      j["fade_power"] = 2;
      j["min_distance"] = l.min_distance;
      j["max_falloff_error"] = l.max_falloff_error;
    }
    lights.push_back(j);
  }
  out.settings = {
      {"export_revision", kExportRevision},
      {"coordinates", "world coordinates times scale (a power of two); camera given by explicit right/up/direction, "
                      "no look_at"},
      {"scale", scale},
      {"camera",
       {{"location", json_vec(eye.origin)},
        {"right", json_vec(cam_right)},
        {"up", json_vec(cam_up)},
        {"direction", json_vec(cam_direction)}}},
      {"finish", {{"ambient", scene.ambient}, {"diffuse", 1}, {"brilliance", 1}, {"specular", 0}, {"phong", 0}}},
      {"ambient_light", scene.ambient != 0.0f ? 1 : 0},
      {"assumed_gamma", 1.0},
      {"calibration",
       {{"point_light_colour", "I * colour / (2 pi fd^2), fade_power 2, fd = max(1e-4 * d_min, 1e-8 m)"},
        {"directional_light_colour", "E * colour / pi, parallel"},
        {"fade_fraction", kFadeFraction}}},
      {"lights", lights},
      {"textures", {{"format", "EXR half RGB, base colour factor baked in; a cut-out's coverage map grey, alpha x "
                               "factor alpha - cutoff + 0.5, opaque at >= 0.5"},
                    {"interpolate", 2},
                    {"count", out.texture_files.size()}}},
      {"max_trace_level", scene.has_cutouts() ? kCutoutTraceLevel : 5},
      {"meshes", out.meshes},
      {"triangles", out.triangles},
      {"sdl_bytes", out.sdl_bytes},
  };
  return out;
}

}  // namespace sb::validation::povray
