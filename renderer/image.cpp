// Float image buffers with named AOV planes: shape checks, plane lookup and Source tag names.
#include "renderer/image.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstring>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "renderer/error.hpp"

namespace sb {

namespace {

constexpr std::array<std::string_view, kSourceCount> kSourceNames = {
    "hole", "rasterized", "traced", "reprojected", "reshaded_traced", "reshaded_raster", "inpainted",
};

bool is_plane_identifier(std::string_view name) {
  if (name.empty() || name.size() > 64 || name[0] < 'a' || name[0] > 'z') return false;
  // EXR files name their eye layers so; a plane of that name would read back as an eye.
  if (name == "left" || name == "right") return false;
  return std::all_of(name.begin(), name.end(),
                     [](char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_'; });
}

}  // namespace

const char* to_string(PlaneType type) { return type == PlaneType::f32 ? "f32" : "u32"; }

std::optional<PlaneShape> standard_plane_shape(std::string_view name) {
  if (name == planes::rgb || name == planes::normal || name == planes::albedo) return PlaneShape{3, PlaneType::f32};
  if (name == planes::alpha || name == planes::depth) return PlaneShape{1, PlaneType::f32};
  if (name == planes::primid || name == planes::source) return PlaneShape{1, PlaneType::u32};
  return std::nullopt;
}

std::string_view to_string(Source source) {
  const auto index = static_cast<std::size_t>(source);
  return index < kSourceNames.size() ? kSourceNames[index] : std::string_view("invalid");
}

Source parse_source(std::string_view name) {
  for (std::size_t i = 0; i < kSourceNames.size(); ++i)
    if (kSourceNames[i] == name) return static_cast<Source>(i);
  throw InputError(
      fmt::format("unknown pixel source tag '{}'; valid tags are: {}", name, fmt::join(kSourceNames, ", ")));
}

std::optional<Source> source_from_u32(uint32_t value) {
  if (value >= kSourceCount) return std::nullopt;
  return static_cast<Source>(value);
}

// ---- Plane ----------------------------------------------------------------------------------

namespace {
std::atomic<bool> g_poison_unset{false};
}  // namespace

void poison_unset_planes(bool on) { g_poison_unset.store(on); }

Plane::Plane(std::string name, int channels, PlaneType type, int width, int height, PlaneInit init)
    : name_(std::move(name)), channels_(channels), type_(type), width_(width), height_(height) {
  if (channels < 1 || channels > 64)
    throw InputError(fmt::format("plane '{}': {} channels requested; a plane has 1 to 64 channels", name_, channels));
  if (width < 0 || height < 0 || width > kMaxImageDimension || height > kMaxImageDimension)
    throw InputError(
        fmt::format("plane '{}': size {}x{} is out of range 0..{}", name_, width, height, kMaxImageDimension));
  const bool poison = init == PlaneInit::unset && g_poison_unset.load(std::memory_order_relaxed);
  if (type == PlaneType::f32) {
    f32_.resize(value_count());
    if (init == PlaneInit::filled) fill(0.0f);
    if (poison) fill(std::bit_cast<float>(kUnsetPoison));
  } else {
    u32_.resize(value_count());
    if (init == PlaneInit::filled) fill(name_ == planes::primid ? kNoPrimitive : 0u);
    if (poison) fill(kUnsetPoison);
  }
}

float* Plane::data_f32() {
  if (type_ != PlaneType::f32) throw InputError(fmt::format("plane '{}' holds uint32 samples, not float32", name_));
  return f32_.data();
}

const float* Plane::data_f32() const { return const_cast<Plane*>(this)->data_f32(); }

uint32_t* Plane::data_u32() {
  if (type_ != PlaneType::u32) throw InputError(fmt::format("plane '{}' holds float32 samples, not uint32", name_));
  return u32_.data();
}

const uint32_t* Plane::data_u32() const { return const_cast<Plane*>(this)->data_u32(); }

void Plane::fill(float value) { std::fill_n(data_f32(), value_count(), value); }

void Plane::fill(uint32_t value) { std::fill_n(data_u32(), value_count(), value); }

bool Plane::operator==(const Plane& other) const {
  if (name_ != other.name_ || channels_ != other.channels_ || type_ != other.type_ || width_ != other.width_ ||
      height_ != other.height_)
    return false;
  // Bitwise, so that NaN payloads and signed zeros count as they are stored.
  if (type_ == PlaneType::f32)
    return f32_.size() == other.f32_.size() &&
           (f32_.empty() || std::memcmp(f32_.data(), other.f32_.data(), f32_.size() * sizeof(float)) == 0);
  return u32_ == other.u32_;
}

// ---- Image ----------------------------------------------------------------------------------

Image::Image(int width, int height) : width_(width), height_(height) {
  if (width < 0 || height < 0 || width > kMaxImageDimension || height > kMaxImageDimension)
    throw InputError(
        fmt::format("image size {}x{} is out of range; each side must be in 0..{}", width, height, kMaxImageDimension));
}

Plane& Image::add_plane(std::string_view name, int channels, PlaneType type, PlaneInit init) {
  if (!is_plane_identifier(name))
    throw InputError(
        fmt::format("plane name '{}' is invalid; use a lowercase identifier such as 'motion_x' "
                    "([a-z][a-z0-9_]*, at most 64 characters, not 'left' or 'right')",
                    name));
  if (has_plane(name))
    throw InputError(fmt::format("plane '{}' already exists in this image (planes: {})", name, plane_list()));
  if (const auto shape = standard_plane_shape(name); shape && (shape->channels != channels || shape->type != type))
    throw InputError(fmt::format("standard plane '{}' must have {} {} channel(s), not {} {}", name, shape->channels,
                                 to_string(shape->type), channels, to_string(type)));
  planes_.emplace_back(std::string(name), channels, type, width_, height_, init);
  return planes_.back();
}

Plane& Image::add_plane(std::string_view standard_name, PlaneInit init) {
  const auto shape = standard_plane_shape(standard_name);
  if (!shape)
    throw InputError(
        fmt::format("'{}' is not a standard plane name (rgb, alpha, depth, normal, albedo, primid, "
                    "source); give its channel count and type",
                    standard_name));
  return add_plane(standard_name, shape->channels, shape->type, init);
}

bool Image::remove_plane(std::string_view name) {
  const auto it = std::find_if(planes_.begin(), planes_.end(), [&](const Plane& p) { return p.name() == name; });
  if (it == planes_.end()) return false;
  planes_.erase(it);
  return true;
}

bool Image::has_plane(std::string_view name) const noexcept { return find_plane(name) != nullptr; }

Plane* Image::find_plane(std::string_view name) noexcept {
  for (Plane& p : planes_)
    if (p.name() == name) return &p;
  return nullptr;
}

const Plane* Image::find_plane(std::string_view name) const noexcept {
  return const_cast<Image*>(this)->find_plane(name);
}

Plane& Image::plane(std::string_view name) {
  if (Plane* p = find_plane(name)) return *p;
  throw InputError(fmt::format("image has no plane '{}' (planes present: {})", name,
                               planes_.empty() ? std::string("none") : plane_list()));
}

const Plane& Image::plane(std::string_view name) const { return const_cast<Image*>(this)->plane(name); }

std::string Image::plane_list() const {
  std::string list;
  for (const Plane& p : planes_) {
    if (!list.empty()) list += ", ";
    list += p.name();
  }
  return list;
}

std::array<float, 3> Image::rgb_at(int x, int y) const {
  const float* px = plane(planes::rgb).data_f32() +
                    (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)) * 3;
  return {px[0], px[1], px[2]};
}

void Image::set_rgb(int x, int y, const std::array<float, 3>& rgb) {
  float* px = plane(planes::rgb).data_f32() +
              (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)) * 3;
  px[0] = rgb[0];
  px[1] = rgb[1];
  px[2] = rgb[2];
}

}  // namespace sb
