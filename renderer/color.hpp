// The exact piecewise sRGB transfer functions (IEC 61966-2-1), shared by PNG previews, texture
// decoding and the 8-bit metrics so that every part of the suite encodes colour the same way.
#pragma once

#include <cmath>
#include <cstdint>

namespace sb {

namespace detail {
/// The OETF in double precision, for values >= 0.
[[nodiscard]] inline double encode_srgb(double a) {
  return a <= 0.0031308 ? a * 12.92 : 1.055 * std::pow(a, 1.0 / 2.4) - 0.055;
}
/// The inverse OETF in double precision, for values >= 0.
[[nodiscard]] inline double decode_srgb(double a) {
  return a <= 0.04045 ? a / 12.92 : std::pow((a + 0.055) / 1.055, 2.4);
}
}  // namespace detail

/// sRGB-encoded value in [0, 1] to linear light (inverse OETF). Values outside [0, 1] are
/// extended symmetrically through the piecewise formula; NaN stays NaN.
[[nodiscard]] inline float srgb_to_linear(float encoded) {
  const double v = encoded;
  return static_cast<float>(std::copysign(detail::decode_srgb(std::fabs(v)), v));
}

/// Linear light to sRGB encoding (OETF), same extension as srgb_to_linear.
[[nodiscard]] inline float linear_to_srgb(float linear) {
  const double v = linear;
  return static_cast<float>(std::copysign(detail::encode_srgb(std::fabs(v)), v));
}

/// Linear light to an 8-bit sRGB code: clamp to [0, 1] (NaN counts as 0), encode, round to the
/// nearest code.
[[nodiscard]] inline uint8_t linear_to_srgb8(float linear) {
  const float clamped = linear > 0.0f ? (linear < 1.0f ? linear : 1.0f) : 0.0f;  // NaN -> 0
  return static_cast<uint8_t>(std::lround(detail::encode_srgb(clamped) * 255.0));
}

/// 8-bit sRGB code to linear light.
[[nodiscard]] inline float srgb8_to_linear(uint8_t code) { return srgb_to_linear(static_cast<float>(code) / 255.0f); }

}  // namespace sb
