// Image file I/O through OpenImageIO (one of the few files that may see its types): stereo EXR
// with named AOV layers, sRGB PNG previews, in-memory PNG encoding and image decoding.
#include "renderer/io/image_io.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>
#include <set>

#include <Imath/half.h>
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/memory.hpp"
#include "renderer/text.hpp"

namespace sb::io {

namespace fs = std::filesystem;
using OIIO::TypeDesc;

namespace {

// ---- Errors ---------------------------------------------------------------------------------

/// The pending error of an ImageOutput/ImageInput (or else OIIO's global one), never empty.
/// Reading it also clears it, so OIIO does not print it again when the object is destroyed.
template <typename T>
std::string oiio_error(const T* object) {
  std::string message = object ? object->geterror() : std::string();
  const std::string global = OIIO::geterror();
  if (message.empty()) message = global;
  if (message.empty()) message = "no details reported by OpenImageIO";
  // OIIO messages may span lines, one per report of the same fault (a codec's message, then
  // OIIO's with it quoted): ours is one line of the reports not contained in another one.
  std::vector<std::string> lines;
  for (size_t start = 0; start <= message.size();) {
    const size_t end = std::min(message.find('\n', start), message.size());
    std::string line = message.substr(start, end - start);
    while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
    if (!line.empty()) lines.push_back(std::move(line));
    start = end + 1;
  }
  std::vector<std::string> kept;
  for (size_t i = 0; i < lines.size(); ++i) {
    bool repeated = false;
    for (size_t k = 0; k < lines.size() && !repeated; ++k)
      repeated = k != i && lines[k].find(lines[i]) != std::string::npos && (lines[k] != lines[i] || k < i);
    if (!repeated) kept.push_back(lines[i]);
  }
  return kept.empty() ? message : fmt::format("{}", fmt::join(kept, "; "));
}

std::string oiio_global_error() { return oiio_error<OIIO::ImageInput>(nullptr); }

constexpr const char* kCorruptHint = "the file is damaged, truncated or not an image; regenerate or replace it";

// ---- Channel naming -------------------------------------------------------------------------

constexpr std::array<const char*, 4> kColourSuffixes = {"R", "G", "B", "A"};

/// EXR channel names of a plane, without the eye layer prefix (see write_exr_stereo).
std::vector<std::string> exr_channel_names(const Plane& plane) {
  const std::string& name = plane.name();
  if (name == planes::rgb) return {"R", "G", "B"};
  if (name == planes::alpha) return {"A"};
  if (name == planes::depth) return {"Z"};
  if (name == planes::normal) return {"N.X", "N.Y", "N.Z"};
  if (name == planes::albedo) return {"albedo.R", "albedo.G", "albedo.B"};
  if (plane.channels() == 1) return {name};  // primid, source and single-channel planes
  std::vector<std::string> names;
  for (int c = 0; c < plane.channels(); ++c)
    names.push_back(plane.channels() <= 4 ? fmt::format("{}.{}", name, kColourSuffixes[static_cast<std::size_t>(c)])
                                          : fmt::format("{}.{}", name, c));
  return names;
}

// ---- EXR writing ----------------------------------------------------------------------------

/// One channel of the file being written and where its samples come from.
struct OutChannel {
  std::string name;
  TypeDesc format;
  const Plane* plane = nullptr;
  int component = 0;
  std::size_t offset = 0;  ///< byte offset inside a native pixel
};

/// Channels of the file being written, in order, with the native pixel size.
struct ExrLayout {
  std::vector<OutChannel> channels;
  std::size_t pixel_bytes = 0;
};

void add_eye_channels(ExrLayout& layout, const Image& image, const std::string& prefix, ExrFloatFormat float_format) {
  for (const Plane& plane : image.planes()) {
    const std::vector<std::string> names = exr_channel_names(plane);
    const TypeDesc format = plane.type() == PlaneType::u32        ? TypeDesc(TypeDesc::UINT)
                            : float_format == ExrFloatFormat::f16 ? TypeDesc(TypeDesc::HALF)
                                                                  : TypeDesc(TypeDesc::FLOAT);
    for (int c = 0; c < plane.channels(); ++c) {
      layout.channels.push_back({prefix + names[static_cast<std::size_t>(c)], format, &plane, c, layout.pixel_bytes});
      layout.pixel_bytes += format.size();
    }
  }
}

/// Interleaves the planes into one native-format buffer (per-channel sample types).
std::vector<unsigned char> interleave(const ExrLayout& layout, std::size_t pixel_count) {
  std::vector<unsigned char> buffer(layout.pixel_bytes * pixel_count);
  const std::size_t stride = layout.pixel_bytes;
  for (const OutChannel& ch : layout.channels) {
    const auto in_stride = static_cast<std::size_t>(ch.plane->channels());
    const auto component = static_cast<std::size_t>(ch.component);
    unsigned char* dst = buffer.data() + ch.offset;
    // Blocks of pixels are independent: convert them in parallel.
    const auto for_pixels = [&](const auto& convert) {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pixel_count, 4096),
                        [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t i = range.begin(); i < range.end(); ++i) convert(i);
                        });
    };
    if (ch.plane->type() == PlaneType::u32) {
      const uint32_t* src = ch.plane->data_u32() + component;
      for_pixels([&](std::size_t i) { std::memcpy(dst + i * stride, src + i * in_stride, 4); });
    } else if (ch.format == TypeDesc::HALF) {
      const float* src = ch.plane->data_f32() + component;
      for_pixels([&](std::size_t i) {
        const Imath::half h(src[i * in_stride]);
        std::memcpy(dst + i * stride, &h, sizeof(h));
      });
    } else {
      const float* src = ch.plane->data_f32() + component;
      for_pixels([&](std::size_t i) { std::memcpy(dst + i * stride, src + i * in_stride, 4); });
    }
  }
  return buffer;
}

void check_metadata(const ImageMetadata& metadata, const fs::path& path) {
  // Header attributes that OpenEXR or OpenImageIO interpret themselves.
  static const std::set<std::string, std::less<>> reserved = {"channels",
                                                              "compression",
                                                              "dataWindow",
                                                              "displayWindow",
                                                              "lineOrder",
                                                              "pixelAspectRatio",
                                                              "screenWindowCenter",
                                                              "screenWindowWidth",
                                                              "tiles",
                                                              "type",
                                                              "name",
                                                              "version",
                                                              "chunkCount",
                                                              "view",
                                                              "multiView",
                                                              "maxSamplesPerPixel",
                                                              "PixelAspectRatio",
                                                              "ImageDescription",
                                                              "Copyright",
                                                              "DateTime"};
  for (const auto& [key, value] : metadata) {
    if (key.empty() || key.size() > 255 || key.find('\0') != std::string::npos)
      throw InputError(fmt::format("metadata for {}: key '{}' is invalid; keys are 1 to 255 characters without NUL",
                                   path.string(), key));
    if (reserved.count(key) || key.starts_with("oiio:") || key.starts_with("openexr:"))
      throw InputError(
          fmt::format("metadata key '{}' for {} is reserved by OpenEXR/OpenImageIO; use a namespaced key "
                      "such as 'stereobench/{}'",
                      key, path.string(), key));
    if (value.empty())
      throw InputError(
          fmt::format("metadata value of '{}' for {} is empty, and OpenEXR headers drop empty strings; "
                      "leave the key out or store a placeholder",
                      key, path.string()));
    if (value.find('\0') != std::string::npos)
      throw InputError(fmt::format("metadata value of '{}' for {} contains a NUL character; encode it (e.g. as JSON)",
                                   key, path.string()));
  }
}

void check_compression(const std::string& compression, const fs::path& path) {
  static const std::set<std::string, std::less<>> known = {"none",  "rle", "zips", "zip",  "piz",
                                                           "pxr24", "b44", "b44a", "dwaa", "dwab"};
  if (!known.count(compression))
    throw InputError(
        fmt::format("EXR compression '{}' for {} is unknown; use one of none, rle, zips, zip, piz, "
                    "pxr24, b44, b44a, dwaa, dwab",
                    compression, path.string()));
}

/// Reads back the first and the last scan line of a just-written EXR. The OpenEXR writer's final
/// flush can fail (a full disk) without close() reporting it, which leaves a short file; reading
/// the last chunk through the offset table finds that before the file takes its final name.
void verify_exr_ends(const fs::path& tmp, const fs::path& path) {
  auto in = OIIO::ImageInput::open(tmp.string());
  const auto incomplete = [&](const std::string& why) {
    return IoError(fmt::format("cannot finish {}: the written file is incomplete ({}); check free disk space",
                               path.string(), why));
  };
  if (!in) throw incomplete(oiio_global_error());
  const OIIO::ImageSpec& spec = in->spec();
  std::vector<unsigned char> line(spec.scanline_bytes(true));
  for (const int y : {spec.y, spec.y + spec.height - 1})
    if (!in->read_scanlines(0, 0, y, y + 1, 0, 0, spec.nchannels, TypeDesc::UNKNOWN, line.data()))
      throw incomplete(oiio_error(in.get()));
}

/// Writes the eyes (prefix, image) as one single-part EXR, atomically.
void write_exr_layers(const fs::path& path, const std::vector<std::pair<std::string, const Image*>>& eyes,
                      const ImageMetadata& metadata, const ExrWriteOptions& options) {
  const Image& first = *eyes.front().second;
  for (const auto& [prefix, image] : eyes) {
    const std::string what =
        prefix.empty() ? std::string("the image") : fmt::format("the {} eye", prefix.substr(0, prefix.size() - 1));
    if (image->empty())
      throw InputError(
          fmt::format("cannot write {}: {} is empty ({}x{})", path.string(), what, image->width(), image->height()));
    if (image->planes().empty())
      throw InputError(fmt::format("cannot write {}: {} has no planes", path.string(), what));
    if (image->width() != first.width() || image->height() != first.height())
      throw InputError(fmt::format("cannot write {}: the eyes differ in size ({}x{} and {}x{})", path.string(),
                                   first.width(), first.height(), image->width(), image->height()));
  }
  check_metadata(metadata, path);
  check_compression(options.compression, path);

  ExrLayout layout;
  for (const auto& [prefix, image] : eyes) add_eye_channels(layout, *image, prefix, options.float_format);

  OIIO::ImageSpec spec(first.width(), first.height(), static_cast<int>(layout.channels.size()),
                       options.float_format == ExrFloatFormat::f16 ? TypeDesc::HALF : TypeDesc::FLOAT);
  spec.channelnames.clear();
  spec.channelformats.clear();
  for (const OutChannel& ch : layout.channels) {
    spec.channelnames.push_back(ch.name);
    spec.channelformats.push_back(ch.format);
  }
  // Channel roles are carried by the names; OIIO must not reinterpret any channel as alpha or depth.
  spec.alpha_channel = -1;
  spec.z_channel = -1;
  spec.attribute("compression", options.compression);
  // Without this OpenImageIO stamps the current time (capDate), and identical images would give
  // different files. An empty value suppresses the stamp.
  spec.attribute("DateTime", "");
  for (const auto& [key, value] : metadata) spec.attribute(key, value);

  const std::vector<unsigned char> pixels = interleave(layout, first.pixel_count());
  write_atomically(path, [&](const fs::path& tmp) {
    auto out = OIIO::ImageOutput::create("openexr");
    if (!out)
      throw IoError(
          fmt::format("cannot write {}: OpenImageIO could not create its EXR writer ({}); its OpenEXR plugin is "
                      "missing, or memory ran out",
                      path.string(), oiio_global_error()));
    if (!out->open(tmp.string(), spec))
      throw IoError(
          fmt::format("cannot write {}: {}; check that the folder is writable", path.string(), oiio_error(out.get())));
    if (!out->write_image(TypeDesc::UNKNOWN, pixels.data())) {
      const std::string message = oiio_error(out.get());
      out->close();
      throw IoError(fmt::format("cannot write {}: {}; check free disk space", path.string(), message));
    }
    if (!out->close())
      throw IoError(fmt::format("cannot finish {}: {}; check free disk space", path.string(), oiio_error(out.get())));
    verify_exr_ends(tmp, path);
  });
}

// ---- EXR reading: channel classification ----------------------------------------------------

enum class EyeTag : uint8_t { none, left, right };

EyeTag eye_tag(std::string_view token) {
  const std::string t = lowercase(token);
  if (t == "left") return EyeTag::left;
  if (t == "right") return EyeTag::right;
  return EyeTag::none;
}

std::vector<std::string> split_name(const std::string& name) {
  std::vector<std::string> tokens;
  std::size_t start = 0;
  for (;;) {
    const std::size_t dot = name.find('.', start);
    tokens.push_back(name.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  return tokens;
}

/// One channel of the input file, its eye and its name with the eye token removed.
struct InChannel {
  int part = 0;
  int index = 0;  ///< channel index inside its part
  TypeDesc format;
  std::string name;  ///< full name as stored
  EyeTag eye = EyeTag::none;
  std::string layer;   ///< name without the eye token and the last component, "" for "R"
  std::string suffix;  ///< last component: "R", "Z", "X", "primid", ...
};

/// A plane to build and, per component, the channel that fills it.
struct PlanePlan {
  std::string name;
  PlaneType type = PlaneType::f32;
  std::vector<const InChannel*> sources;
};

/// An opened input file with its parts.
struct InputFile {
  fs::path path;
  std::unique_ptr<OIIO::ImageInput> input;
  std::vector<OIIO::ImageSpec> parts;
  std::vector<InChannel> channels;
  int width = 0;
  int height = 0;
};

/// Reader configuration: present colour and alpha as stored. PNG (and glTF) alpha is straight;
/// without this OpenImageIO would premultiply colour by alpha on reading.
const OIIO::ImageSpec& straight_alpha_config() {
  static const OIIO::ImageSpec config = [] {
    OIIO::ImageSpec spec;
    spec.attribute("oiio:UnassociatedAlpha", 1);
    return spec;
  }();
  return config;
}

std::unique_ptr<OIIO::ImageInput> open_input(const fs::path& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status))
    throw InputError(
        fmt::format("{} does not exist; check the path (and that the step that writes it ran)", path.string()));
  if (fs::is_directory(status)) throw InputError(fmt::format("{} is a folder, not an image file", path.string()));
  auto input = OIIO::ImageInput::open(path.string(), &straight_alpha_config());
  if (!input)
    throw InputError(fmt::format("cannot read image {}: {}; {}", path.string(), oiio_global_error(), kCorruptHint));
  return input;
}

EyeTag part_eye(const OIIO::ImageSpec& spec) {
  for (const char* attribute : {"view", "oiio:subimagename", "name"}) {
    const EyeTag eye = eye_tag(spec.get_string_attribute(attribute));
    if (eye != EyeTag::none) return eye;
  }
  return EyeTag::none;
}

InputFile open_file(const fs::path& path) {
  InputFile file;
  file.path = path;
  file.input = open_input(path);
  OIIO::ImageInput& in = *file.input;
  for (int s = 0; in.seek_subimage(s, 0); ++s) file.parts.push_back(in.spec());
  (void)in.geterror();  // seeking past the last part is expected to fail
  if (file.parts.empty())
    throw InputError(fmt::format("cannot read image {}: no readable part; {}", path.string(), kCorruptHint));

  const OIIO::ImageSpec& first = file.parts.front();
  file.width = first.full_width > 0 ? first.full_width : first.width;
  file.height = first.full_height > 0 ? first.full_height : first.height;
  if (file.width <= 0 || file.height <= 0 || file.width > kMaxImageDimension || file.height > kMaxImageDimension)
    throw InputError(fmt::format("image {} has an unsupported size {}x{}; each side must be in 1..{}", path.string(),
                                 file.width, file.height, kMaxImageDimension));

  for (std::size_t p = 0; p < file.parts.size(); ++p) {
    const OIIO::ImageSpec& spec = file.parts[p];
    if (spec.deep)
      throw InputError(
          fmt::format("image {} holds deep data, which is not supported; write flat images", path.string()));
    if (spec.depth > 1)
      throw InputError(fmt::format("image {} is a volume ({} slices), not a flat image", path.string(), spec.depth));
    const int pw = spec.full_width > 0 ? spec.full_width : spec.width;
    const int ph = spec.full_height > 0 ? spec.full_height : spec.height;
    // The data window is read whole (an EXR's may reach beyond the display window).
    if (spec.width > kMaxImageDimension || spec.height > kMaxImageDimension)
      throw InputError(fmt::format("image {}: part {} has a data window of {}x{}; each side must be in 1..{}",
                                   path.string(), p, spec.width, spec.height, kMaxImageDimension));
    if (pw != file.width || ph != file.height)
      throw InputError(fmt::format("image {}: part {} is {}x{} but part 0 is {}x{}; all parts must have the same size",
                                   path.string(), p, pw, ph, file.width, file.height));
    const EyeTag eye_of_part = part_eye(spec);
    for (int c = 0; c < spec.nchannels; ++c) {
      InChannel ch;
      ch.part = static_cast<int>(p);
      ch.index = c;
      ch.format = spec.channelformat(c);
      ch.name = spec.channel_name(c);
      std::vector<std::string> tokens = split_name(ch.name);
      // Eye: a leading layer "left."/"right." (this suite), an OpenEXR multi-view token before the
      // last component ("layer.left.R"), or the part's view/name.
      if (tokens.size() >= 2 && eye_tag(tokens.front()) != EyeTag::none) {
        ch.eye = eye_tag(tokens.front());
        tokens.erase(tokens.begin());
      } else if (tokens.size() >= 3 && eye_tag(tokens[tokens.size() - 2]) != EyeTag::none) {
        ch.eye = eye_tag(tokens[tokens.size() - 2]);
        tokens.erase(tokens.end() - 2);
      } else {
        ch.eye = eye_of_part;
      }
      ch.suffix = tokens.back();
      tokens.pop_back();
      for (const std::string& t : tokens) ch.layer += (ch.layer.empty() ? "" : ".") + t;
      file.channels.push_back(std::move(ch));
    }
  }
  return file;
}

std::string channel_list(const InputFile& file) {
  std::string list;
  for (const InChannel& ch : file.channels) list += (list.empty() ? "" : ", ") + ch.name;
  return list.empty() ? std::string("none") : list;
}

bool is_integer_32(TypeDesc t) { return t.basetype == TypeDesc::UINT || t.basetype == TypeDesc::INT; }

/// A lowercase plane identifier from a foreign layer name ("ViewLayer.Emit" -> "viewlayer_emit").
std::string sanitise_plane_name(std::string_view raw) {
  std::string name;
  for (const char c : raw) {
    const auto u = static_cast<unsigned char>(c);
    name += std::isalnum(u) ? static_cast<char>(std::tolower(u)) : '_';
  }
  if (name.empty() || name[0] < 'a' || name[0] > 'z') name = "p_" + name;
  if (name.size() > 60) name.resize(60);
  return name;
}

/// Rank of a component suffix when ordering the channels of a generic layer.
std::pair<int, std::string> component_rank(const std::string& suffix) {
  static constexpr std::string_view colour = "RGBA";
  static constexpr std::string_view vector = "XYZW";
  if (suffix.size() == 1) {
    if (const auto i = colour.find(suffix[0]); i != std::string_view::npos) return {static_cast<int>(i), ""};
    if (const auto i = vector.find(suffix[0]); i != std::string_view::npos) return {static_cast<int>(i), ""};
  }
  if (!suffix.empty() && std::all_of(suffix.begin(), suffix.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return {suffix.size() < 6 ? std::stoi(suffix) : 99999, ""};
  return {100000, suffix};
}

/// Maps the channels of one eye (or of a mono image) to planes.
class PlanePlanner {
 public:
  void add_layer(const std::string& layer, const std::vector<const InChannel*>& channels) {
    if (layer.empty()) {
      add_unlayered(channels);
      return;
    }
    const std::string last = layer.substr(layer.rfind('.') == std::string::npos ? 0 : layer.rfind('.') + 1);
    if ((layer == "N" || last == "Normal") && try_standard(planes::normal, channels, {"X", "Y", "Z"})) return;
    if ((layer == "albedo" || last == "DiffCol") && try_standard(planes::albedo, channels, {"R", "G", "B"})) return;
    if (last == "Depth" && try_standard(planes::depth, channels, {"Z"})) return;
    if (last == "Combined") {
      std::vector<const InChannel*> colour, rest;
      for (const InChannel* ch : channels) (ch->suffix == "A" ? rest : colour).push_back(ch);
      if (try_standard(planes::rgb, colour, {"R", "G", "B"})) {
        if (!rest.empty() && !try_standard(planes::alpha, rest, {"A"})) add_generic(layer + ".A", rest);
        return;
      }
    }
    add_generic(layer, channels);
  }

  /// Plans in canonical order: standard planes first, then the others by name.
  std::vector<PlanePlan> take() {
    static constexpr std::array<std::string_view, 7> order = {
        planes::rgb, planes::alpha, planes::depth, planes::normal, planes::albedo, planes::primid, planes::source};
    std::vector<PlanePlan> sorted;
    std::vector<bool> used(plans_.size(), false);
    for (const std::string_view name : order)
      for (std::size_t i = 0; i < plans_.size(); ++i)
        if (!used[i] && plans_[i].name == name) {
          sorted.push_back(std::move(plans_[i]));
          used[i] = true;
        }
    // OpenEXR stores channels sorted by name, so the writer's plane order is lost anyway: sort the
    // other planes by name too, so that the order never depends on the file's channel order.
    const std::size_t first_other = sorted.size();
    for (std::size_t i = 0; i < plans_.size(); ++i)
      if (!used[i]) sorted.push_back(std::move(plans_[i]));
    std::sort(sorted.begin() + static_cast<std::ptrdiff_t>(first_other), sorted.end(),
              [](const PlanePlan& a, const PlanePlan& b) { return a.name < b.name; });
    plans_.clear();
    return sorted;
  }

 private:
  bool taken(std::string_view name) const {
    return std::any_of(plans_.begin(), plans_.end(), [&](const PlanePlan& p) { return p.name == name; });
  }

  /// Claims standard plane `name` if `channels` hold exactly the suffixes `order`.
  bool try_standard(std::string_view name, const std::vector<const InChannel*>& channels,
                    std::initializer_list<const char*> order) {
    if (taken(name) || channels.size() != order.size()) return false;
    PlanePlan plan{std::string(name), standard_plane_shape(name)->type, {}};
    for (const char* suffix : order) {
      const auto it =
          std::find_if(channels.begin(), channels.end(), [&](const InChannel* ch) { return ch->suffix == suffix; });
      if (it == channels.end()) return false;
      plan.sources.push_back(*it);
    }
    plans_.push_back(std::move(plan));
    return true;
  }

  /// Unlayered channels: R,G,B -> rgb, A -> alpha, Z -> depth, anything else its own plane.
  void add_unlayered(const std::vector<const InChannel*>& channels) {
    std::vector<const InChannel*> colour;
    for (const InChannel* ch : channels)
      if (ch->suffix == "R" || ch->suffix == "G" || ch->suffix == "B") colour.push_back(ch);
    const bool have_rgb = try_standard(planes::rgb, colour, {"R", "G", "B"});
    for (const InChannel* ch : channels) {
      if (have_rgb && (ch->suffix == "R" || ch->suffix == "G" || ch->suffix == "B")) continue;
      if (ch->suffix == "A" && try_standard(planes::alpha, {ch}, {"A"})) continue;
      if (ch->suffix == "Z" && try_standard(planes::depth, {ch}, {"Z"})) continue;
      if (ch->suffix == planes::primid && try_standard(planes::primid, {ch}, {"primid"})) continue;
      if (ch->suffix == planes::source && try_standard(planes::source, {ch}, {"source"})) continue;
      add_generic(ch->suffix, {ch});
    }
  }

  /// Any other layer: a plane named after it, components in R,G,B,A / X,Y,Z,W / numeric order.
  void add_generic(const std::string& layer, std::vector<const InChannel*> channels) {
    std::stable_sort(channels.begin(), channels.end(), [](const InChannel* a, const InChannel* b) {
      return component_rank(a->suffix) < component_rank(b->suffix);
    });
    const bool all_ids =
        std::all_of(channels.begin(), channels.end(), [](const InChannel* ch) { return is_integer_32(ch->format); });
    const PlaneType type = all_ids ? PlaneType::u32 : PlaneType::f32;
    std::string name = sanitise_plane_name(layer);
    const auto fits = [&](const std::string& candidate) {
      const auto shape = standard_plane_shape(candidate);
      return !taken(candidate) &&
             (!shape || (shape->channels == static_cast<int>(channels.size()) && shape->type == type));
    };
    if (!fits(name)) {
      int n = 2;
      while (!fits(fmt::format("{}_{}", name, n))) ++n;
      name = fmt::format("{}_{}", name, n);
    }
    plans_.push_back({name, type, std::move(channels)});
  }

  std::vector<PlanePlan> plans_;
};

std::vector<PlanePlan> plan_planes(const std::vector<const InChannel*>& channels) {
  // Group by layer in order of first appearance.
  std::vector<std::pair<std::string, std::vector<const InChannel*>>> layers;
  for (const InChannel* ch : channels) {
    auto it = std::find_if(layers.begin(), layers.end(), [&](const auto& l) { return l.first == ch->layer; });
    if (it == layers.end()) {
      layers.push_back({ch->layer, {}});
      it = layers.end() - 1;
    }
    it->second.push_back(ch);
  }
  PlanePlanner planner;
  for (const auto& [layer, members] : layers) planner.add_layer(layer, members);
  return planner.take();
}

// ---- EXR reading: pixels --------------------------------------------------------------------

/// Reads sample `p` of native type `t` as a double; 8- and 16-bit integers are normalised to
/// [0, 1] the way OpenImageIO presents them, 32-bit integers are kept as ids.
double read_sample(const unsigned char* p, TypeDesc t) {
  switch (t.basetype) {
    case TypeDesc::HALF: {
      Imath::half h;
      std::memcpy(&h, p, sizeof(h));
      return static_cast<float>(h);
    }
    case TypeDesc::FLOAT: {
      float f;
      std::memcpy(&f, p, sizeof(f));
      return f;
    }
    case TypeDesc::DOUBLE: {
      double d;
      std::memcpy(&d, p, sizeof(d));
      return d;
    }
    case TypeDesc::UINT8:
      return *p / 255.0;
    case TypeDesc::UINT16: {
      uint16_t v;
      std::memcpy(&v, p, sizeof(v));
      return v / 65535.0;
    }
    case TypeDesc::UINT: {
      uint32_t v;
      std::memcpy(&v, p, sizeof(v));
      return v;
    }
    case TypeDesc::INT: {
      int32_t v;
      std::memcpy(&v, p, sizeof(v));
      return v;
    }
    default:
      return 0.0;
  }
}

bool is_supported_sample_type(TypeDesc t) {
  switch (t.basetype) {
    case TypeDesc::HALF:
    case TypeDesc::FLOAT:
    case TypeDesc::DOUBLE:
    case TypeDesc::UINT8:
    case TypeDesc::UINT16:
    case TypeDesc::UINT:
    case TypeDesc::INT:
      return true;
    default:
      return false;
  }
}

/// Reads one part's pixels in their native per-channel formats.
std::vector<unsigned char> read_part(InputFile& file, int part) {
  const OIIO::ImageSpec& spec = file.parts[static_cast<std::size_t>(part)];
  for (int c = 0; c < spec.nchannels; ++c)
    if (!is_supported_sample_type(spec.channelformat(c)))
      throw InputError(
          fmt::format("image {}: channel '{}' has sample type '{}', which is not supported (use half, "
                      "float, uint or 8/16-bit)",
                      file.path.string(), spec.channel_name(c), spec.channelformat(c).c_str()));
  std::vector<unsigned char> buffer(spec.image_bytes(true));
  if (!file.input->read_image(part, 0, 0, spec.nchannels, TypeDesc::UNKNOWN, buffer.data()))
    throw InputError(fmt::format("cannot read the pixels of {}: {}; {}", file.path.string(),
                                 oiio_error(file.input.get()), kCorruptHint));
  return buffer;
}

/// Byte offsets of each channel inside a native pixel of a part.
std::vector<std::size_t> channel_offsets(const OIIO::ImageSpec& spec) {
  std::vector<std::size_t> offsets;
  std::size_t offset = 0;
  for (int c = 0; c < spec.nchannels; ++c) {
    offsets.push_back(offset);
    offset += spec.channelformat(c).size();
  }
  return offsets;
}

/// Copies channel `ch` of a part's native pixels into component `component` of `plane`, placing
/// the part's data window inside the image's display window (clipped).
void copy_channel(const InputFile& file, const OIIO::ImageSpec& spec, const std::vector<unsigned char>& pixels,
                  std::size_t offset, const InChannel& ch, Plane& plane, int component) {
  const std::size_t pixel_bytes = spec.pixel_bytes(true);
  const int x0 = spec.x - spec.full_x;
  const int y0 = spec.y - spec.full_y;
  const int sx_begin = std::max(0, -x0);
  const int sx_end = std::min(spec.width, plane.width() - x0);
  const int sy_begin = std::max(0, -y0);
  const int sy_end = std::min(spec.height, plane.height() - y0);
  if (sx_begin >= sx_end || sy_begin >= sy_end) return;

  const auto row = [&](int sy, const auto& convert) {
    const unsigned char* src =
        pixels.data() +
        (static_cast<std::size_t>(sy) * static_cast<std::size_t>(spec.width) + static_cast<std::size_t>(sx_begin)) *
            pixel_bytes +
        offset;
    for (int sx = sx_begin; sx < sx_end; ++sx, src += pixel_bytes) convert(sx + x0, sy + y0, src);
  };
  // Rows are independent: convert them in parallel (each thread writes its own rows).
  const auto all_rows = [&](const auto& convert) {
    tbb::parallel_for(tbb::blocked_range<int>(sy_begin, sy_end), [&](const tbb::blocked_range<int>& rows) {
      for (int sy = rows.begin(); sy < rows.end(); ++sy) row(sy, convert);
    });
  };
  const int c = component;
  if (plane.type() == PlaneType::f32) {
    if (ch.format.basetype == TypeDesc::FLOAT)
      all_rows([&](int x, int y, const unsigned char* src) { std::memcpy(&plane.at_f32(x, y, c), src, 4); });
    else if (ch.format.basetype == TypeDesc::HALF)
      all_rows([&](int x, int y, const unsigned char* src) {
        Imath::half h;
        std::memcpy(&h, src, sizeof(h));
        plane.at_f32(x, y, c) = static_cast<float>(h);
      });
    else
      all_rows([&](int x, int y, const unsigned char* src) {
        plane.at_f32(x, y, c) = static_cast<float>(read_sample(src, ch.format));
      });
  } else if (ch.format.basetype == TypeDesc::UINT) {
    all_rows([&](int x, int y, const unsigned char* src) { std::memcpy(&plane.at_u32(x, y, c), src, 4); });
  } else {
    // Ids stored in another type (e.g. float by another tool): whole numbers only. Serial, so
    // that the error names the first offending pixel.
    for (int sy = sy_begin; sy < sy_end; ++sy)
      row(sy, [&](int x, int y, const unsigned char* src) {
        const double v = read_sample(src, ch.format);
        if (!(v >= 0.0 && v <= 4294967295.0 && v == std::floor(v)))
          throw InputError(
              fmt::format("image {}: channel '{}' holds {} at pixel ({}, {}), which is not a valid value "
                          "for plane '{}' (a whole number in 0..4294967295)",
                          file.path.string(), ch.name, v, x, y, plane.name()));
        plane.at_u32(x, y, c) = static_cast<uint32_t>(v);
      });
  }
}

/// Builds one image per plan list (one per eye), reading each needed part of the file once.
std::vector<Image> build_images(InputFile& file, const std::vector<std::vector<PlanePlan>>& images_plans) {
  // The planes (4 B per channel and pixel) and the largest part read whole beside them.
  uint64_t channels = 0, largest_part = 0;
  const OIIO::ImageSpec* largest = nullptr;
  for (const auto& plans : images_plans)
    for (const PlanePlan& plan : plans) channels += plan.sources.size();
  for (const OIIO::ImageSpec& spec : file.parts)
    if (spec.image_bytes() >= largest_part) {
      largest_part = spec.image_bytes();
      largest = &spec;
    }
  const std::string window = largest != nullptr && (largest->width != file.width || largest->height != file.height)
                                 ? fmt::format(", data window {}x{}", largest->width, largest->height)
                                 : "";
  require_memory(uint64_t{4} * channels * static_cast<uint64_t>(file.width) * static_cast<uint64_t>(file.height) +
                     largest_part,
                 fmt::format("reading image {} ({}x{}{})", file.path.string(), file.width, file.height, window),
                 "use a smaller image, or run on a machine with more memory");
  std::vector<Image> images;
  for (const auto& plans : images_plans) {
    images.emplace_back(file.width, file.height);
    for (const PlanePlan& plan : plans)
      images.back().add_plane(plan.name, static_cast<int>(plan.sources.size()), plan.type);
  }
  for (int part = 0; part < static_cast<int>(file.parts.size()); ++part) {
    const bool needed = std::any_of(images_plans.begin(), images_plans.end(), [&](const auto& plans) {
      return std::any_of(plans.begin(), plans.end(), [&](const PlanePlan& plan) {
        return std::any_of(plan.sources.begin(), plan.sources.end(),
                           [&](const InChannel* ch) { return ch->part == part; });
      });
    });
    if (!needed) continue;
    const OIIO::ImageSpec& spec = file.parts[static_cast<std::size_t>(part)];
    const std::vector<unsigned char> pixels = read_part(file, part);
    const std::vector<std::size_t> offsets = channel_offsets(spec);
    for (std::size_t i = 0; i < images.size(); ++i) {
      for (const PlanePlan& plan : images_plans[i]) {
        Plane& plane = images[i].plane(plan.name);
        for (std::size_t c = 0; c < plan.sources.size(); ++c) {
          const InChannel& ch = *plan.sources[c];
          if (ch.part == part)
            copy_channel(file, spec, pixels, offsets[static_cast<std::size_t>(ch.index)], ch, plane,
                         static_cast<int>(c));
        }
      }
    }
  }
  return images;
}

/// Runs a read step, turning exceptions from inside OpenImageIO/OpenEXR into InputError (running
/// out of memory into ResourceError).
template <typename F>
auto guarded_read(const fs::path& path, F&& read) -> decltype(read()) {
  try {
    return read();
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    // The size an image declares is checked against the memory left before it is decoded
    // (decode_from): running out later is this machine's shortage (exit 4), though a damaged file
    // whose decoder asks for more than the image needs looks the same.
    throw ResourceError(fmt::format("cannot read image {}: out of memory; free memory or run on a machine with more "
                                    "(a damaged file can ask for more too: if it is truncated or not an image, "
                                    "regenerate or replace it)",
                                    path.string()));
  } catch (const std::exception& e) {
    throw InputError(fmt::format("cannot read image {}: {}; {}", path.string(), e.what(), kCorruptHint));
  }
}

// ---- Decoding from memory -------------------------------------------------------------------

/// OpenImageIO format name from the first bytes of a file, or "" if not recognised.
std::string sniff_format(std::span<const unsigned char> b) {
  const auto starts = [&](std::string_view magic) {
    return b.size() >= magic.size() && std::memcmp(b.data(), magic.data(), magic.size()) == 0;
  };
  if (starts("\x89PNG\r\n\x1a\n")) return "png";
  if (starts("\xff\xd8\xff")) return "jpeg";
  if (starts("\x76\x2f\x31\x01")) return "openexr";
  if (starts(std::string_view("II*\0", 4)) || starts(std::string_view("MM\0*", 4))) return "tiff";
  if (starts("#?RADIANCE") || starts("#?RGBE")) return "hdr";
  if (starts("GIF87a") || starts("GIF89a")) return "gif";
  if (b.size() >= 12 && starts("RIFF") && std::memcmp(b.data() + 8, "WEBP", 4) == 0) return "webp";
  if (starts("DDS ")) return "dds";
  if (starts("8BPS")) return "psd";
  if (starts("BM")) return "bmp";
  return "";
}

/// What bytes without an image signature look like. The bytes themselves are not quoted: a scene
/// may name any readable file as its image, and its error message must not show that file's
/// contents. Text or not already tells the usual mistakes apart: a Git LFS pointer or a saved web
/// page in the image's place.
std::string describe_unrecognised(std::span<const unsigned char> b) {
  constexpr std::string_view lfs = "version https://git-lfs";
  if (b.size() >= lfs.size() && std::memcmp(b.data(), lfs.data(), lfs.size()) == 0)
    return "it is a Git LFS pointer file, not the image; fetch the LFS objects (git lfs pull)";
  const std::size_t n = std::min<std::size_t>(b.size(), 64);
  const bool text = std::all_of(b.begin(), b.begin() + static_cast<std::ptrdiff_t>(n), [](unsigned char c) {
    return (c >= 0x20 && c < 0x7f) || c == '\n' || c == '\r' || c == '\t';
  });
  return text ? "it holds text, not image data" : "binary data without a known image signature";
}

/// Whether 8/16-bit samples of this spec are sRGB-encoded (unless the file says linear).
bool is_srgb(const OIIO::ImageSpec& spec) {
  const std::string colour_space = lowercase(spec.get_string_attribute("oiio:ColorSpace"));
  if (spec.format.is_floating_point()) return colour_space == "srgb";
  return colour_space.empty() || colour_space.find("linear") == std::string::npos;
}

DecodedImage decode_from(OIIO::ImageInput& in, const std::string& name, uint64_t then_per_pixel = 0) {
  const OIIO::ImageSpec spec = in.spec();
  if (spec.deep || spec.depth > 1)
    throw InputError(fmt::format("image {} is a deep or volume image; textures must be flat 2D images", name));
  if (spec.width <= 0 || spec.height <= 0 || spec.width > kMaxImageDimension || spec.height > kMaxImageDimension ||
      spec.nchannels <= 0 || spec.nchannels > 64)
    throw InputError(fmt::format("image {} has an unsupported shape {}x{} with {} channels; {}", name, spec.width,
                                 spec.height, spec.nchannels, kCorruptHint));
  // Decoded whole, every channel as float: a file of a few kilobytes can declare gigabytes.
  require_memory((uint64_t{4} * static_cast<uint64_t>(spec.nchannels) + then_per_pixel) *
                     static_cast<uint64_t>(spec.width) * static_cast<uint64_t>(spec.height),
                 fmt::format("decoding image {} ({}x{}, {} channels){}", name, spec.width, spec.height, spec.nchannels,
                             then_per_pixel > 0 ? " and what is made of it" : ""),
                 "use a smaller image, or run on a machine with more memory");
  DecodedImage image;
  image.width = spec.width;
  image.height = spec.height;
  image.channels = spec.nchannels;
  image.srgb = is_srgb(spec);
  image.integer = !spec.format.is_floating_point();
  image.format = in.format_name();
  // Decoded a band of rows at a time, the buffer grown with each band: where the reader decodes
  // row by row (scan-line files other than interlaced PNG), a file that declares more rows than it
  // holds fails at its first missing band, before the memory for the rest is touched. A band is
  // about 64 MiB of floats rounded down to whole multiples of 256 rows (at least 256), so that the
  // 16-, 32- and 256-row chunks of compressed EXR files are never split between two bands. A tiled
  // file is read whole.
  const std::size_t row_values = static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.nchannels);
  image.values.reserve(row_values * static_cast<std::size_t>(spec.height));
  const bool tiled = spec.tile_width != 0;
  const int band =
      tiled ? spec.height
            : static_cast<int>(std::clamp<std::size_t>(((std::size_t{1} << 24) / row_values) / 256, 1, 256) * 256);
  for (int y0 = 0; y0 < spec.height; y0 += band) {
    const int y1 = std::min(spec.height, y0 + band);
    const std::size_t done = image.values.size();
    image.values.resize(done + row_values * static_cast<std::size_t>(y1 - y0));
    float* rows = image.values.data() + done;
    const bool ok = tiled ? in.read_image(0, 0, 0, spec.nchannels, TypeDesc::FLOAT, rows)
                          : in.read_scanlines(0, 0, spec.y + y0, spec.y + y1, 0, 0, spec.nchannels, TypeDesc::FLOAT, rows);
    if (!ok) throw InputError(fmt::format("cannot decode image {}: {}; {}", name, oiio_error(&in), kCorruptHint));
  }
  return image;
}

/// A temporary file that removes itself.
class TempFile {
 public:
  TempFile(std::span<const unsigned char> bytes, const std::string& extension) {
    static std::atomic<unsigned> counter{0};
    path_ = fs::temp_directory_path() / fmt::format("sb-decode-{}-{}.{}", ::getpid(), counter++, extension);
    std::ofstream out(path_, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    if (!out.flush()) throw IoError(fmt::format("cannot write temporary file {} to decode an image", path_.string()));
  }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  ~TempFile() {
    std::error_code ec;
    fs::remove(path_, ec);
  }
  [[nodiscard]] const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

}  // namespace

// ---- Public API -----------------------------------------------------------------------------

void write_exr_stereo(const fs::path& path, const Image& left, const Image& right, const ImageMetadata& metadata,
                      const ExrWriteOptions& options) {
  write_exr_layers(path, {{"left.", &left}, {"right.", &right}}, metadata, options);
}

void write_exr(const fs::path& path, const Image& image, const ImageMetadata& metadata,
               const ExrWriteOptions& options) {
  write_exr_layers(path, {{"", &image}}, metadata, options);
}

std::pair<Image, Image> read_exr_stereo(const fs::path& path) {
  return guarded_read(path, [&] {
    InputFile file = open_file(path);
    std::vector<const InChannel*> left, right, unassigned;
    for (const InChannel& ch : file.channels)
      (ch.eye == EyeTag::left ? left : ch.eye == EyeTag::right ? right : unassigned).push_back(&ch);
    if (left.empty() && right.empty())
      throw InputError(
          fmt::format("{} holds no stereo pair: no 'left.'/'right.' channel layers or parts named left/right "
                      "(channels: {}); read it with read_exr or write it with write_exr_stereo",
                      path.string(), channel_list(file)));
    // OpenEXR multi-view: the default view's channels carry no view name.
    if (left.empty()) left = unassigned;
    if (right.empty()) right = unassigned;
    if (left.empty() || right.empty())
      throw InputError(fmt::format("{} holds only the {} eye (channels: {}); a stereo EXR needs both", path.string(),
                                   left.empty() ? "right" : "left", channel_list(file)));
    std::vector<Image> eyes = build_images(file, {plan_planes(left), plan_planes(right)});
    return std::pair<Image, Image>(std::move(eyes[0]), std::move(eyes[1]));
  });
}

Image read_exr_eye(const fs::path& path, bool right) {
  return guarded_read(path, [&] {
    InputFile file = open_file(path);
    const EyeTag wanted = right ? EyeTag::right : EyeTag::left;
    std::vector<const InChannel*> mine, unassigned;
    bool other = false;
    for (const InChannel& ch : file.channels) {
      if (ch.eye == wanted)
        mine.push_back(&ch);
      else if (ch.eye == EyeTag::none)
        unassigned.push_back(&ch);
      else
        other = true;
    }
    if (mine.empty() && other) mine = unassigned;  // multi-view: the default view is this eye
    if (mine.empty())
      throw InputError(fmt::format("{} holds no {} eye (channels: {}){}", path.string(), right ? "right" : "left",
                                   channel_list(file), other ? fmt::format("; it holds the {} eye", right ? "left" : "right") : ""));
    return std::move(build_images(file, {plan_planes(mine)}).front());
  });
}

bool exr_holds_stereo_pair(const fs::path& path) {
  return guarded_read(path, [&] {
    const InputFile file = open_file(path);
    return std::any_of(file.channels.begin(), file.channels.end(),
                       [](const InChannel& ch) { return ch.eye != EyeTag::none; });
  });
}

Image read_exr(const fs::path& path) {
  return guarded_read(path, [&] {
    InputFile file = open_file(path);
    std::vector<const InChannel*> unassigned;
    for (const InChannel& ch : file.channels)
      if (ch.eye == EyeTag::none) unassigned.push_back(&ch);
    // Channels of an eye beside unnamed ones are OpenEXR multi-view (the default view unnamed):
    // a pair too, whose unnamed channels are one eye, not the whole image.
    if (unassigned.size() < file.channels.size())
      throw InputError(fmt::format("{} holds a stereo pair (channels: {}); read it with read_exr_stereo", path.string(),
                                   channel_list(file)));
    if (unassigned.empty()) throw InputError(fmt::format("{} has no channels; {}", path.string(), kCorruptHint));
    return std::move(build_images(file, {plan_planes(unassigned)}).front());
  });
}

ImageMetadata read_exr_metadata(const fs::path& path) {
  return guarded_read(path, [&] {
    const auto input = open_input(path);
    ImageMetadata metadata;
    for (const OIIO::ParamValue& p : input->spec().extra_attribs) {
      const std::string name = p.name().string();
      if (p.type() == OIIO::TypeString && !name.starts_with("oiio:")) metadata[name] = p.get<OIIO::ustring>().string();
    }
    return metadata;
  });
}

std::vector<ChannelInfo> read_channel_info(const fs::path& path) {
  return guarded_read(path, [&] {
    const auto input = open_input(path);
    const OIIO::ImageSpec& spec = input->spec();
    std::vector<ChannelInfo> channels;
    for (int c = 0; c < spec.nchannels; ++c) channels.push_back({spec.channel_name(c), spec.channelformat(c).c_str()});
    return channels;
  });
}

void write_png_preview(const fs::path& path, const Image& image, std::string_view plane_name) {
  const Plane* plane = image.find_plane(plane_name);
  if (!plane)
    throw InputError(fmt::format("cannot write preview {}: the image has no plane '{}' (planes present: {})",
                                 path.string(), plane_name,
                                 image.planes().empty() ? std::string("none") : image.plane_list()));
  if (plane->type() != PlaneType::f32 || (plane->channels() != 1 && plane->channels() != 3))
    throw InputError(
        fmt::format("cannot write preview {}: plane '{}' has {} {} channel(s); a preview needs 1 or 3 float "
                    "channels",
                    path.string(), plane_name, plane->channels(), to_string(plane->type())));
  if (image.empty()) throw InputError(fmt::format("cannot write preview {}: the image is empty", path.string()));
  const int channels = plane->channels();
  const float* src = plane->data_f32();
  std::vector<uint8_t> codes(plane->value_count());
  const std::size_t row_values = static_cast<std::size_t>(image.width()) * static_cast<std::size_t>(channels);
  tbb::parallel_for(tbb::blocked_range<int>(0, image.height()), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) {
      const std::size_t begin = static_cast<std::size_t>(y) * row_values;
      for (std::size_t i = begin; i < begin + row_values; ++i) codes[i] = linear_to_srgb8(src[i]);
    }
  });
  const std::vector<unsigned char> png =
      encode_png(codes.data(), image.width(), image.height(), channels, PngColour::srgb);
  write_file_atomically(path, png);
}

void write_png_rgb8(const fs::path& path, const std::vector<uint8_t>& rgb, int width, int height) {
  if (width <= 0 || height <= 0 || rgb.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3)
    throw InputError(fmt::format("cannot write {}: {} bytes given for a {}x{} RGB image (needs width*height*3 = {})",
                                 path.string(), rgb.size(), width, height,
                                 static_cast<long long>(width) * static_cast<long long>(height) * 3));
  const std::vector<unsigned char> png = encode_png(rgb.data(), width, height, 3, PngColour::srgb);
  write_file_atomically(path, png);
}

std::vector<unsigned char> encode_png(const uint8_t* pixels, int width, int height, int channels, PngColour colour) {
  if (width <= 0 || height <= 0 || width > kMaxImageDimension || height > kMaxImageDimension)
    throw InputError(fmt::format("encode_png: image size {}x{} is invalid; both sides must be in 1..{}", width, height,
                                 kMaxImageDimension));
  if (channels < 1 || channels > 4)
    throw InputError(fmt::format("encode_png: {} channels requested; PNG holds 1 to 4 channels", channels));
  if (pixels == nullptr) throw InputError("encode_png: no pixel data given (null pointer)");
  std::vector<unsigned char> bytes;
  OIIO::Filesystem::IOVecOutput proxy(bytes);
  auto out = OIIO::ImageOutput::create("png");
  if (!out) throw IoError(fmt::format("encode_png: OpenImageIO has no PNG writer: {}", oiio_global_error()));
  OIIO::ImageSpec spec(width, height, channels, TypeDesc::UINT8);
  // A fixed compression level keeps the bytes independent of OpenImageIO's default.
  spec.attribute("png:compressionLevel", 6);
  // The pixels carry straight (unpremultiplied) alpha, as glTF expects: store them unchanged.
  spec.attribute("oiio:UnassociatedAlpha", 1);
  if (colour == PngColour::srgb) spec.attribute("oiio:ColorSpace", "sRGB");
  if (!out->set_ioproxy(&proxy) || !out->open("memory.png", spec))
    throw IoError(fmt::format("encode_png: cannot start PNG encoding of a {}x{}x{} image: {}", width, height, channels,
                              oiio_error(out.get())));
  if (!out->write_image(TypeDesc::UINT8, pixels)) {
    const std::string message = oiio_error(out.get());
    out->close();
    throw IoError(
        fmt::format("encode_png: PNG encoding of a {}x{}x{} image failed: {}", width, height, channels, message));
  }
  if (!out->close())
    throw IoError(fmt::format("encode_png: finishing the PNG stream failed: {}", oiio_error(out.get())));
  return bytes;
}

std::string image_file_format(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char head[16] = {};
  in.read(reinterpret_cast<char*>(head), sizeof head);
  return sniff_format(std::span<const unsigned char>(head, static_cast<size_t>(in.gcount())));
}

DecodedImage decode_image(std::span<const unsigned char> bytes, const std::string& name_for_errors,
                          uint64_t then_per_pixel) {
  const std::string& name = name_for_errors;
  if (bytes.empty()) throw InputError(fmt::format("image {} is empty (0 bytes); {}", name, kCorruptHint));
  std::string format = sniff_format(bytes);
  if (format.empty()) {
    // Formats without a signature (e.g. Targa) are recognised by the name's extension.
    const std::string extension = lowercase(fs::path(name).extension().string());
    if (extension.size() > 1 && OIIO::is_imageio_format_name(extension.substr(1))) format = extension.substr(1);
  }
  if (format.empty())
    throw InputError(fmt::format("image {} is in a format OpenImageIO does not recognise ({}); use PNG or JPEG",
                                 name, describe_unrecognised(bytes)));
  return guarded_read(fs::path(name), [&] {
    OIIO::Filesystem::IOMemReader proxy(bytes.data(), bytes.size());
    auto in = OIIO::ImageInput::create(OIIO::string_view(format), false, nullptr, nullptr, OIIO::string_view());
    if (!in)
      throw InputError(
          fmt::format("image {}: OpenImageIO cannot read {} images: {}", name, format, oiio_global_error()));
    if (in->supports("ioproxy")) {
      OIIO::ImageSpec spec;
      if (!in->set_ioproxy(&proxy) || !in->open(name, spec, straight_alpha_config()))
        throw InputError(
            fmt::format("cannot decode image {} as {}: {}; {}", name, format, oiio_error(in.get()), kCorruptHint));
      DecodedImage image = decode_from(*in, name, then_per_pixel);
      in->close();
      return image;
    }
    // This reader only reads files: decode through a temporary file.
    const TempFile tmp(bytes, format);
    OIIO::ImageSpec spec;
    if (!in->open(tmp.path().string(), spec, straight_alpha_config()))
      throw InputError(
          fmt::format("cannot decode image {} as {}: {}; {}", name, format, oiio_error(in.get()), kCorruptHint));
    DecodedImage image = decode_from(*in, name, then_per_pixel);
    in->close();
    return image;
  });
}

DecodedImage read_image(const fs::path& path) {
  return guarded_read(path, [&] {
    auto in = open_input(path);
    DecodedImage image = decode_from(*in, path.string());
    in->close();
    return image;
  });
}

std::string oiio_version() {
  const int v = OIIO::openimageio_version();
  return fmt::format("{}.{}.{}", v / 10000, (v / 100) % 100, v % 100);
}

}  // namespace sb::io
