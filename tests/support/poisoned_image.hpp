// Images poisoned with a sentinel NaN that no stage writes, to check that a stage writing into an
// image made with PlaneInit::unset sets every sample of every plane.
#pragma once

#include <bit>
#include <cstdint>
#include <cstddef>

#include "renderer/image.hpp"

namespace sb::test {

/// The sentinel's bits: a NaN no stage writes (the poison of poison_unset_planes).
inline constexpr uint32_t kSentinel = kUnsetPoison;

/// Fills every sample of every plane of `image` with the sentinel's bits.
inline void poison(Image& image) {
  for (const Plane& plane : image.planes()) {
    Plane& p = image.plane(plane.name());
    if (p.type() == PlaneType::u32) {
      p.fill(kSentinel);
    } else {
      p.fill(std::bit_cast<float>(kSentinel));
    }
  }
}

/// The samples of `plane` that still hold the sentinel.
inline size_t sentinel_count(const Plane& plane) {
  size_t n = 0;
  if (plane.type() == PlaneType::u32) {
    for (const uint32_t v : plane.u32()) n += v == kSentinel ? 1 : 0;
  } else {
    for (const float v : plane.f32()) n += std::bit_cast<uint32_t>(v) == kSentinel ? 1 : 0;
  }
  return n;
}

}  // namespace sb::test
