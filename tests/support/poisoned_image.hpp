// Planes made with PlaneInit::unset poisoned with a NaN that no stage writes (poison_unset_planes),
// to check that a stage or pipeline writing into such an image sets every sample of every plane.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <string>

#include "renderer/image.hpp"

namespace sb::test {

/// Turns poison_unset_planes on for its lifetime.
class PoisonUnsetPlanes {
 public:
  PoisonUnsetPlanes() { poison_unset_planes(true); }
  ~PoisonUnsetPlanes() { poison_unset_planes(false); }
  PoisonUnsetPlanes(const PoisonUnsetPlanes&) = delete;
  PoisonUnsetPlanes& operator=(const PoisonUnsetPlanes&) = delete;
};

/// The samples of `plane` that still hold the poison.
inline size_t sentinel_count(const Plane& plane) {
  size_t n = 0;
  if (plane.type() == PlaneType::u32) {
    for (const uint32_t v : plane.u32()) n += v == kUnsetPoison ? 1 : 0;
  } else {
    for (const float v : plane.f32()) n += std::bit_cast<uint32_t>(v) == kUnsetPoison ? 1 : 0;
  }
  return n;
}

/// The samples of `image` that still hold the poison, per plane ("" when none).
inline std::string unwritten(const Image& image) {
  std::string out;
  for (const Plane& plane : image.planes())
    if (const size_t n = sentinel_count(plane); n > 0) out += std::string(plane.name()) + ": " + std::to_string(n) + " ";
  return out;
}

}  // namespace sb::test
