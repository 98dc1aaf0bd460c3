// Image files as the metrics see them: any image file read as 8-bit sRGB (EXR and other linear
// files encoded like encode_srgb8, 8-bit files taken as stored), and region masks read from files.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "validation/metrics.hpp"

namespace sb::validation {

/// An image file read for comparison.
struct Srgb8File {
  Srgb8Image image;
  /// Colour channels in the file: 1 (grey, replicated to R, G, B) or 3 (RGB). An alpha channel is
  /// ignored (colours are taken as stored, not composited).
  int colour_channels = 3;
  /// How the file's samples became 8-bit sRGB, e.g. "png, 8-bit sRGB as stored" or
  /// "openexr, linear float encoded to sRGB" (for messages and records).
  std::string encoding;
  /// The eye taken from a stereo EXR ("left" or "right"), empty for a single image.
  std::string eye;
};

/// Reads an image file as 8-bit sRGB.
///  - EXR: read with the suite's channel mapping (its "rgb" plane, i.e. R,G,B) and encoded like
///    encode_srgb8. A stereo EXR needs `eye` ("left" or "right"); without it that is an InputError
///    that says so. `eye` is ignored for a single-image EXR and for other formats.
///  - Files whose samples are sRGB-encoded (8-bit PNG, JPEG, ...): taken as stored; 16-bit samples
///    are rounded to the nearest 8-bit code.
///  - Other linear files (HDR, float TIFF): encoded like encode_srgb8.
/// 1 channel is grey (replicated), 3 is RGB, 4 is RGB plus an ignored alpha; other channel counts
/// are an InputError naming the file. A missing file or one that is not a readable image is an
/// InputError (it is input the user gave); an existing file that cannot be opened for reading
/// (permissions, I/O error) is an IoError. NaN samples are an InputError naming the file.
[[nodiscard]] Srgb8File read_srgb8_file(const std::filesystem::path& path, std::string_view eye = {});

/// Reads a region mask: a pixel is inside when one of its colour channels is non-zero (alpha is
/// not looked at, so an opaque black mask is empty); in an EXR, R, G and B when it has them (a
/// rendered EXR's depth, normals and albedo are not looked at), otherwise every float channel (a
/// Y- or A-only mask). Any image format; a stereo EXR is read through `eye` as for read_srgb8_file. InputError for a
/// missing or unreadable file and for NaN samples.
[[nodiscard]] RegionMask read_region_mask(const std::filesystem::path& path, std::string_view eye = {});

}  // namespace sb::validation
