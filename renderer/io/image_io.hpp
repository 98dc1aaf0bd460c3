// Image file I/O through OpenImageIO: stereo EXR with named AOV layers, sRGB PNG previews, and
// in-memory PNG encoding and image decoding for glTF textures. No OpenImageIO type appears here.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "renderer/color.hpp"
#include "renderer/image.hpp"

namespace sb::io {

/// String attributes stored in an EXR header, e.g. {"stereobench/rig", "<json>"}.
using ImageMetadata = std::map<std::string, std::string>;

/// Sample format of the float planes in a written EXR. uint32 planes are always UINT.
enum class ExrFloatFormat : uint8_t {
  f32,  ///< FLOAT: bit-exact round trip (the default)
  f16,  ///< HALF: half the size, about 3 significant digits
};

/// EXR writing options.
struct ExrWriteOptions {
  ExrFloatFormat float_format = ExrFloatFormat::f32;
  std::string compression = "zip";  ///< any OpenEXR compression name: none, zip, zips, piz, ...
};

/// Writes both eyes into ONE EXR file as layers "left." and "right." with OpenEXR channel names:
/// rgb -> R,G,B; alpha -> A; depth -> Z; normal -> N.X,N.Y,N.Z; albedo -> albedo.R,.G,.B;
/// primid and source -> UINT channels "primid", "source"; any other plane p -> "p" (1 channel)
/// or "p.R", "p.G", ... (2-4 channels) or "p.0", "p.1", ... The eyes must have the same size.
/// `metadata` becomes string attributes (non-empty values; keys that OpenEXR or OpenImageIO
/// interpret, such as "compression" or "oiio:*", are refused). Written atomically: InputError for
/// an unwritable image (empty, no planes, sizes differ) or bad metadata, IoError if the file
/// cannot be written.
void write_exr_stereo(const std::filesystem::path& path, const Image& left, const Image& right,
                      const ImageMetadata& metadata = {}, const ExrWriteOptions& options = {});

/// Writes one image into an EXR file with the channel names of write_exr_stereo, without a layer
/// prefix (R, G, B, Z, N.X, ...).
void write_exr(const std::filesystem::path& path, const Image& image, const ImageMetadata& metadata = {},
               const ExrWriteOptions& options = {});

/// Reads a stereo EXR. Eyes are found as (in this order of preference) channel layers "left." and
/// "right." (this suite), OpenEXR multi-view names ("<layer>.left.R"; unprefixed channels belong
/// to the view that has no channels of its own), or parts named "left"/"right". Channel names map
/// back to planes as in write_exr_stereo; Blender pass names (Combined, Depth, Normal, DiffCol)
/// map to rgb, depth, normal, albedo; other layers become planes with sanitised lowercase names.
/// HALF and FLOAT channels become float planes (exactly), UINT channels uint32 planes. Planes come
/// in a canonical order: the standard ones (rgb, alpha, depth, normal, albedo, primid, source),
/// then the others sorted by name. Pixels outside a file's data window stay at the plane default.
/// InputError if the file is missing, unreadable, not an image or has no stereo pair.
[[nodiscard]] std::pair<Image, Image> read_exr_stereo(const std::filesystem::path& path);

/// True when the file's header tags any channel with an eye (a 'left.'/'right.' layer or a part
/// named left/right): read_exr_stereo is the reader for it. Reads the header only.
[[nodiscard]] bool exr_holds_stereo_pair(const std::filesystem::path& path);

/// One eye of an EXR whose channels are tagged with eyes (exr_holds_stereo_pair): its own channels,
/// or, where it has none and the other eye has some, the unnamed ones (OpenEXR multi-view's default
/// view). A file holding that eye alone reads as well as a pair. InputError naming the channels
/// when the file has no channel of that eye.
[[nodiscard]] Image read_exr_eye(const std::filesystem::path& path, bool right);

/// Reads a single-image EXR (or any file OpenImageIO reads as float) with the channel mapping of
/// read_exr_stereo: a plain R,G,B(,A) file gives "rgb" (and "alpha"), "Z" gives "depth".
/// InputError if the file is missing, unreadable, or holds a stereo pair (use read_exr_stereo): any
/// channel tagged with an eye, also beside unnamed ones (OpenEXR multi-view's default view).
[[nodiscard]] Image read_exr(const std::filesystem::path& path);

/// The string attributes of an image file's header (first part), except OpenImageIO's internal
/// "oiio:" ones. Includes standard string attributes such as "compression".
[[nodiscard]] ImageMetadata read_exr_metadata(const std::filesystem::path& path);

/// One channel of an image file as stored: its name and sample format ("half", "float", "uint").
struct ChannelInfo {
  std::string name;
  std::string format;
  bool operator==(const ChannelInfo&) const = default;
};

/// The channels of an image file's first part, in file order.
[[nodiscard]] std::vector<ChannelInfo> read_channel_info(const std::filesystem::path& path);

/// Writes a 1- or 3-channel float plane as an 8-bit PNG: each value clamped to [0, 1], encoded
/// with the exact sRGB OETF and rounded to the nearest code (linear_to_srgb8), tagged sRGB.
/// Written atomically; InputError for a missing, uint32 or wrongly shaped plane, IoError on write failure.
void write_png_preview(const std::filesystem::path& path, const Image& image, std::string_view plane = planes::rgb);

/// Writes already-encoded 8-bit sRGB pixels (row-major, row 0 at the top, w*h*3 bytes) as a PNG
/// tagged sRGB, atomically.
void write_png_rgb8(const std::filesystem::path& path, const std::vector<uint8_t>& rgb, int width, int height);

/// Whether a PNG says what its codes mean: `srgb` writes the sRGB chunk (with its gAMA and cHRM
/// fallbacks), for images meant to be looked at (previews, difference and mask pictures);
/// `untagged` writes none (the textures of generated scenes, whose bytes the scenes' hashes cover).
enum class PngColour { untagged, srgb };

/// Encodes 8-bit pixels (row-major, interleaved, 1-4 channels; with 2 or 4 channels the last is
/// straight, unpremultiplied alpha, stored as given) as PNG bytes in memory. The same
/// pixels always give the same bytes (no time stamps or software tags). InputError for a bad
/// shape, IoError if encoding fails.
[[nodiscard]] std::vector<unsigned char> encode_png(const uint8_t* pixels, int width, int height, int channels,
                                                    PngColour colour = PngColour::untagged);

/// A decoded image: interleaved samples as float, row 0 at the top.
struct DecodedImage {
  int width = 0;
  int height = 0;
  int channels = 0;
  /// width * height * channels; integer formats scaled to [0, 1]; alpha as stored (straight in
  /// PNG, never premultiplied here)
  std::vector<float> values;
  /// Whether the samples are sRGB-encoded (8-bit PNG and JPEG: yes; EXR, HDR: no). Values are
  /// never linearised here: the caller decides (glTF base colour is sRGB, other maps are not).
  bool srgb = false;
  bool integer = false;  ///< stored as integer samples (8- or 16-bit), not floating point
  std::string format;    ///< the reader that decoded it, e.g. "png", "jpeg", "openexr"
};

/// Decodes an image file held in memory (PNG, JPEG, EXR, TIFF, BMP, HDR, ... whatever
/// OpenImageIO reads; the format is found from the bytes). `name_for_errors` names the image in
/// messages (e.g. "scene.glb image 3"). InputError if the bytes are not a readable image.
/// ResourceError, before the pixels are decoded, when the decoded values and `then_per_pixel`
/// bytes per pixel more (what the caller makes of them: a texture and its mip chain) would not
/// fit in the memory left: each stage checked alone fits where the whole does not.
[[nodiscard]] DecodedImage decode_image(std::span<const unsigned char> bytes, const std::string& name_for_errors,
                                        uint64_t then_per_pixel = 0);

/// Reads an image file as decode_image does. InputError if missing or unreadable.
[[nodiscard]] DecodedImage read_image(const std::filesystem::path& path);

/// The format of an image file from its first bytes, as decode_image recognises it ("png",
/// "jpeg", "openexr", ...), or "" when the file is unreadable or holds no known signature.
[[nodiscard]] std::string image_file_format(const std::filesystem::path& path);

/// The OpenImageIO library version, e.g. "2.4.7", for provenance records.
[[nodiscard]] std::string oiio_version();

}  // namespace sb::io
