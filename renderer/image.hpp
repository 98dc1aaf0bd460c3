// Float image buffers with named AOV planes (radiance, depth, normal, albedo, ids, source tags):
// what every pipeline writes for one eye and what image I/O and the metrics read.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

namespace sb {

/// Sample type of a plane: float32 for radiance and geometry, uint32 for ids and tags.
enum class PlaneType : uint8_t { f32, u32 };

[[nodiscard]] const char* to_string(PlaneType type);

/// Standard plane names (DESIGN §2). Their channel count and type are fixed: add_plane() refuses
/// a standard name with another shape, and image I/O maps them to conventional EXR channel names.
namespace planes {
inline constexpr std::string_view rgb = "rgb";        ///< 3 x f32, linear radiance
inline constexpr std::string_view alpha = "alpha";    ///< 1 x f32, coverage (read from foreign files)
inline constexpr std::string_view depth = "depth";    ///< 1 x f32, linear view-space distance along -Z
inline constexpr std::string_view normal = "normal";  ///< 3 x f32, world-space unit normal
inline constexpr std::string_view albedo = "albedo";  ///< 3 x f32, linear albedo
inline constexpr std::string_view primid = "primid";  ///< 1 x u32, primitive id or kNoPrimitive
inline constexpr std::string_view source = "source";  ///< 1 x u32, a Source tag per pixel
}  // namespace planes

/// Shape of a standard plane.
struct PlaneShape {
  int channels = 0;
  PlaneType type = PlaneType::f32;
};

/// The fixed shape of a standard plane name, or nothing for any other name.
[[nodiscard]] std::optional<PlaneShape> standard_plane_shape(std::string_view name);

/// Largest width or height an Image accepts.
inline constexpr int kMaxImageDimension = 65536;

/// Primitive id of a pixel that sees no surface.
inline constexpr uint32_t kNoPrimitive = 0xFFFFFFFFu;

/// Where a pixel's value came from; stored as its numeric value in the "source" plane.
enum class Source : uint8_t {
  hole,
  rasterized,
  traced,
  reprojected,
  reshaded_traced,
  reshaded_raster,
  inpainted,
};

/// Number of Source values (for histograms indexed by the tag).
inline constexpr std::size_t kSourceCount = 7;

/// The tag's name as used in results and reports ("reshaded_traced", ...).
[[nodiscard]] std::string_view to_string(Source source);
/// Parses a tag name; throws InputError naming the value and listing the valid names.
[[nodiscard]] Source parse_source(std::string_view name);
/// The tag with numeric value `value`, or nothing if it is out of range (e.g. read from a file).
[[nodiscard]] std::optional<Source> source_from_u32(uint32_t value);

/// Whether a new plane's samples are set: to the plane's empty value (0, kNoPrimitive for
/// "primid"), or left unset for a writer that sets every sample before anything reads one (it
/// saves a pass over the memory; an unset sample that is read is undefined).
enum class PlaneInit : uint8_t { filled, unset };

/// The bits of a NaN that no stage writes: with poison_unset_planes(true), planes made with
/// PlaneInit::unset hold it in every sample until they are written.
inline constexpr uint32_t kUnsetPoison = 0x7fc0dead;

/// For tests: while on, planes made with PlaneInit::unset are filled with kUnsetPoison instead of
/// being left unset, so that a sample no stage wrote can be found in the output. Off by default;
/// nothing outside the tests turns it on.
void poison_unset_planes(bool on);

/// Allocator of plane samples: a resize default-initializes new samples, which for float and
/// uint32 leaves them unset, so that PlaneInit::unset costs nothing and `filled` fills once.
template <class T>
struct SampleAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = SampleAllocator<U>;
  };
  SampleAllocator() = default;
  template <class U>
  SampleAllocator(const SampleAllocator<U>& /*other*/) noexcept {}
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

/// One named plane of an image: `channels` interleaved samples per pixel, row-major, row 0 at the
/// top, stored contiguously as float32 or uint32 (only the vector matching the type is used).
class Plane {
 public:
  /// A zero-filled plane (kNoPrimitive-filled for "primid"), or one with unset samples; throws
  /// InputError for a bad shape.
  Plane(std::string name, int channels, PlaneType type, int width, int height, PlaneInit init = PlaneInit::filled);

  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  [[nodiscard]] int channels() const noexcept { return channels_; }
  [[nodiscard]] PlaneType type() const noexcept { return type_; }
  [[nodiscard]] int width() const noexcept { return width_; }
  [[nodiscard]] int height() const noexcept { return height_; }
  [[nodiscard]] std::size_t pixel_count() const noexcept {
    return static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
  }
  /// Number of samples: pixel_count() * channels().
  [[nodiscard]] std::size_t value_count() const noexcept { return pixel_count() * static_cast<std::size_t>(channels_); }

  /// Raw samples; throw InputError if the plane has the other type.
  [[nodiscard]] float* data_f32();
  [[nodiscard]] const float* data_f32() const;
  [[nodiscard]] uint32_t* data_u32();
  [[nodiscard]] const uint32_t* data_u32() const;
  /// The samples as spans (same checks as data_f32 / data_u32).
  [[nodiscard]] std::span<float> f32() { return {data_f32(), value_count()}; }
  [[nodiscard]] std::span<const float> f32() const { return {data_f32(), value_count()}; }
  [[nodiscard]] std::span<uint32_t> u32() { return {data_u32(), value_count()}; }
  [[nodiscard]] std::span<const uint32_t> u32() const { return {data_u32(), value_count()}; }

  /// Index of the first sample of pixel (x, y) in the data arrays. No bounds check.
  [[nodiscard]] std::size_t offset(int x, int y) const noexcept {
    return (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)) *
           static_cast<std::size_t>(channels_);
  }
  /// Sample access without type or bounds checks (for hot loops; the plane's type must match).
  [[nodiscard]] float& at_f32(int x, int y, int c = 0) noexcept {
    return f32_[offset(x, y) + static_cast<std::size_t>(c)];
  }
  [[nodiscard]] float at_f32(int x, int y, int c = 0) const noexcept {
    return f32_[offset(x, y) + static_cast<std::size_t>(c)];
  }
  [[nodiscard]] uint32_t& at_u32(int x, int y, int c = 0) noexcept {
    return u32_[offset(x, y) + static_cast<std::size_t>(c)];
  }
  [[nodiscard]] uint32_t at_u32(int x, int y, int c = 0) const noexcept {
    return u32_[offset(x, y) + static_cast<std::size_t>(c)];
  }

  /// Sets every sample to `value` (the plane's type must match; InputError otherwise).
  void fill(float value);
  void fill(uint32_t value);

  /// Same name, shape and bit-identical samples.
  [[nodiscard]] bool operator==(const Plane& other) const;

 private:
  std::string name_;
  int channels_ = 0;
  PlaneType type_ = PlaneType::f32;
  int width_ = 0;
  int height_ = 0;
  std::vector<float, SampleAllocator<float>> f32_;
  std::vector<uint32_t, SampleAllocator<uint32_t>> u32_;
};

/// One eye's image: a size and an ordered list of planes of that size. Plane lookup by name is a
/// linear search over a handful of planes: look a plane up once, then loop over its samples.
class Image {
 public:
  Image() = default;
  /// An image with no planes; throws InputError unless 0 <= width, height <= kMaxImageDimension.
  Image(int width, int height);

  [[nodiscard]] int width() const noexcept { return width_; }
  [[nodiscard]] int height() const noexcept { return height_; }
  [[nodiscard]] std::size_t pixel_count() const noexcept {
    return static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
  }
  [[nodiscard]] bool empty() const noexcept { return pixel_count() == 0; }

  /// Adds a zero-filled plane (kNoPrimitive for "primid"; unset samples with PlaneInit::unset) and returns it. Throws InputError if the
  /// name is taken, is not a lowercase identifier ([a-z][a-z0-9_]*, at most 64 characters; not
  /// "left" or "right", the EXR eye layers), or is a standard name with another shape. References to planes stay valid when more planes are added (not on removal).
  Plane& add_plane(std::string_view name, int channels, PlaneType type, PlaneInit init = PlaneInit::filled);
  /// Adds a standard plane with its fixed shape; throws InputError for a non-standard name.
  Plane& add_plane(std::string_view standard_name, PlaneInit init = PlaneInit::filled);
  /// Removes a plane if present; returns whether it was.
  bool remove_plane(std::string_view name);

  [[nodiscard]] bool has_plane(std::string_view name) const noexcept;
  /// The named plane; throws InputError naming it and listing the planes present.
  [[nodiscard]] Plane& plane(std::string_view name);
  [[nodiscard]] const Plane& plane(std::string_view name) const;
  /// The named plane or nullptr.
  [[nodiscard]] Plane* find_plane(std::string_view name) noexcept;
  [[nodiscard]] const Plane* find_plane(std::string_view name) const noexcept;
  [[nodiscard]] const std::deque<Plane>& planes() const noexcept { return planes_; }
  /// Plane names in order, comma separated (for messages).
  [[nodiscard]] std::string plane_list() const;

  /// Samples of a named plane (lookup + type check, see Plane).
  [[nodiscard]] float* data_f32(std::string_view name) { return plane(name).data_f32(); }
  [[nodiscard]] const float* data_f32(std::string_view name) const { return plane(name).data_f32(); }
  [[nodiscard]] uint32_t* data_u32(std::string_view name) { return plane(name).data_u32(); }
  [[nodiscard]] const uint32_t* data_u32(std::string_view name) const { return plane(name).data_u32(); }

  /// Linear radiance of pixel (x, y) from the "rgb" plane (InputError if absent; no bounds check).
  [[nodiscard]] std::array<float, 3> rgb_at(int x, int y) const;
  /// Sets the radiance of pixel (x, y) in the "rgb" plane.
  void set_rgb(int x, int y, const std::array<float, 3>& rgb);
  /// Whether (x, y) lies inside the image.
  [[nodiscard]] bool contains(int x, int y) const noexcept { return x >= 0 && y >= 0 && x < width_ && y < height_; }

  /// Same size and the same planes in the same order with bit-identical samples.
  [[nodiscard]] bool operator==(const Image& other) const = default;

 private:
  int width_ = 0;
  int height_ = 0;
  std::deque<Plane> planes_;  ///< a deque, so that adding a plane never moves the others
};

}  // namespace sb
