// Reading image files for the metrics: format detection, stereo EXR eye selection, 8-bit sRGB
// conversion and region masks.
#include "validation/image_files.hpp"

#include <array>
#include <cmath>
#include <fstream>
#include <optional>
#include <utility>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/io/image_io.hpp"

namespace sb::validation {

namespace {

namespace fs = std::filesystem;

/// Checks that `path` names a readable file; returns whether it is an OpenEXR file (by its magic
/// number). Missing: InputError; present but unreadable: IoError.
bool open_and_sniff_exr(const fs::path& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) throw InputError(fmt::format("{}: no such file; check the path", path.string()));
  if (fs::is_directory(status)) throw InputError(fmt::format("{} is a folder, not an image file", path.string()));
  // An image reader on a device never ends (/dev/zero) or blocks (a terminal).
  if (!fs::is_regular_file(status))
    throw InputError(fmt::format("{} is a device, pipe or socket, not an image file; give the path of an image file",
                                 path.string()));
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw IoError(fmt::format("{} exists but cannot be opened for reading; check its permissions", path.string()));
  std::array<char, 4> magic{};
  in.read(magic.data(), magic.size());
  return in.gcount() == 4 && magic == std::array<char, 4>{'\x76', '\x2f', '\x31', '\x01'};
}

void check_eye(std::string_view eye) {
  if (!eye.empty() && eye != "left" && eye != "right")
    throw InputError(fmt::format("eye '{}' is unknown; give left or right", eye));
}

/// A single image from an EXR file: the file itself when it holds one image, the chosen eye when
/// it holds a stereo pair (InputError without a choice).
Image read_exr_image(const fs::path& path, std::string_view eye, std::string& taken_eye) {
  check_eye(eye);
  try {
    return io::read_exr(path);
  } catch (const InputError&) {
    // Either a file of eyes or an unreadable file. One of eyes that cannot be read reports its own
    // fault (a truncated file, say), not that it holds eyes.
    bool stereo = false;
    try {
      stereo = io::exr_holds_stereo_pair(path);
    } catch (const Error&) {
    }
    if (!stereo) throw;
  }
  if (eye.empty())
    throw InputError(fmt::format("{} is a stereo EXR (its channels are tagged with eyes: left./right. layers, "
                                 "views or parts); choose one with --eye left|right",
                                 path.string()));
  taken_eye = std::string(eye);
  return io::read_exr_eye(path, eye == "right");
}

/// The planes of an image read from a file other than its alpha: what carries colour or grey.
std::vector<const Plane*> colour_planes(const Image& image) {
  std::vector<const Plane*> out;
  for (const Plane& p : image.planes())
    if (p.name() != planes::alpha) out.push_back(&p);
  return out;
}

/// 8-bit codes of an sRGB-encoded sample scaled to [0, 1] (8-bit exactly, 16-bit rounded).
uint8_t code_of(float encoded) {
  const float c = encoded > 0.0f ? (encoded < 1.0f ? encoded : 1.0f) : 0.0f;
  return static_cast<uint8_t>(std::lround(c * 255.0f));
}

}  // namespace

Srgb8File read_srgb8_file(const fs::path& path, std::string_view eye) {
  Srgb8File file;
  if (open_and_sniff_exr(path)) {
    const Image image = read_exr_image(path, eye, file.eye);
    if (image.has_plane(planes::rgb)) {
      file.image = encode_srgb8(image, path.string());
      file.encoding = "openexr, linear float encoded to sRGB";
      return file;
    }
    // A grey EXR: its one channel (Y, or any single name) counts as R = G = B; an alpha channel
    // beside it is not read.
    const std::vector<const Plane*> colour = colour_planes(image);
    if (colour.size() != 1 || colour.front()->channels() != 1 || colour.front()->type() != PlaneType::f32)
      throw InputError(fmt::format("{} has neither R, G, B channels nor a single grey channel (planes: {}); the "
                                   "metrics compare colour or grey images",
                                   path.string(), image.plane_list()));
    const std::span<const float> grey = colour.front()->f32();
    Image linear(image.width(), image.height());
    float* rgb = linear.add_plane(planes::rgb).data_f32();
    for (std::size_t i = 0; i < grey.size(); ++i) rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = grey[i];
    file.image = encode_srgb8(linear, path.string());
    file.colour_channels = 1;
    file.encoding = "openexr, linear float grey encoded to sRGB";
    return file;
  }

  const io::DecodedImage d = io::read_image(path);
  if (d.channels < 1 || d.channels > 4)
    throw InputError(
        fmt::format("{} has {} channels; compare reads grey (1), grey + alpha (2), RGB (3) or RGBA (4) "
                    "images",
                    path.string(), d.channels));
  const bool grey = d.channels <= 2;
  file.colour_channels = grey ? 1 : 3;
  const std::size_t n = static_cast<std::size_t>(d.width) * static_cast<std::size_t>(d.height);
  const std::size_t stride = static_cast<std::size_t>(d.channels);
  // The colour of pixel i, channel c (grey replicated; alpha not read).
  const auto sample = [&](std::size_t i, std::size_t c) { return d.values[i * stride + (grey ? 0 : c)]; };
  if (d.srgb) {
    file.image = {d.width, d.height, std::vector<uint8_t>(n * 3)};
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t c = 0; c < 3; ++c) {
        // A float file tagged sRGB may hold NaN, which has no code (it was taken as 0, black).
        if (std::isnan(sample(i, c)))
          throw InputError(fmt::format("{} has a NaN sample at pixel ({}, {}); the metrics need finite values",
                                       path.string(), i % static_cast<std::size_t>(d.width),
                                       i / static_cast<std::size_t>(d.width)));
        file.image.rgb[i * 3 + c] = code_of(sample(i, c));
      }
    file.encoding = fmt::format("{}, sRGB as stored", d.format);
  } else {
    Image linear(d.width, d.height);
    float* rgb = linear.add_plane(planes::rgb).data_f32();
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t c = 0; c < 3; ++c) rgb[i * 3 + c] = sample(i, c);
    file.image = encode_srgb8(linear, path.string());
    // An integer file read as linear says so itself (a PNG's gAMA of 1.0, a TIFF tagged linear).
    file.encoding = fmt::format("{}, {} encoded to sRGB", d.format,
                                d.integer ? "linear as the file says (its colour space tag)" : "linear float");
  }
  return file;
}

RegionMask read_region_mask(const fs::path& path, std::string_view eye) {
  RegionMask mask;
  // Marks pixel i inside when one of its first `used` samples (of `channels`) is non-zero; NaN is
  // refused with its place.
  const auto mark = [&](std::span<const float> values, int channels, int used) {
    for (std::size_t k = 0; k < values.size(); ++k) {
      if (static_cast<int>(k % static_cast<std::size_t>(channels)) >= used) continue;
      const std::size_t i = k / static_cast<std::size_t>(channels);
      if (std::isnan(values[k]))
        throw InputError(fmt::format("mask {} has a NaN sample at pixel ({}, {}); a mask needs finite values",
                                     path.string(), i % static_cast<std::size_t>(mask.width),
                                     i / static_cast<std::size_t>(mask.width)));
      if (values[k] != 0.0f) mask.inside[i] = 1;
    }
  };
  if (open_and_sniff_exr(path)) {
    std::string taken;
    const Image image = read_exr_image(path, eye, taken);
    mask = RegionMask::filled(image.width(), image.height(), false);
    if (const Plane* rgb = image.find_plane(planes::rgb)) {
      mark(rgb->f32(), rgb->channels(), rgb->channels());
      return mask;
    }
    // Without R, G, B: every other channel but alpha, float or integer (an id mask); an image of
    // an alpha channel alone is that channel.
    std::vector<const Plane*> channels = colour_planes(image);
    if (channels.empty())
      for (const Plane& p : image.planes()) channels.push_back(&p);
    for (const Plane* p : channels) {
      if (p->type() == PlaneType::f32) {
        mark(p->f32(), p->channels(), p->channels());
      } else {
        const std::span<const uint32_t> ids = p->u32();
        std::vector<float> values(ids.begin(), ids.end());
        mark(values, p->channels(), p->channels());
      }
    }
    return mask;
  }
  const io::DecodedImage d = io::read_image(path);
  mask = RegionMask::filled(d.width, d.height, false);
  // Grey, grey + alpha, RGB, RGBA: the colour channels.
  mark(d.values, d.channels, d.channels == 2 ? 1 : std::min(d.channels, 3));
  return mask;
}

}  // namespace sb::validation
