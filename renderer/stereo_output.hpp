// Viewable stereo outputs made from a rendered eye pair: the Dubois red-cyan anaglyph and the
// side-by-side and over/under layouts (DESIGN §4.2), all in linear light.
#pragma once

#include <array>

#include "renderer/image.hpp"

namespace sb {

/// A 3x3 colour matrix, row-major: out[r] = sum_c m[r][c] * in[c].
using ColorMatrix = std::array<std::array<float, 3>, 3>;

/// Dubois's least-squares red-cyan projection for the left eye (E. Dubois, "A projection method
/// to generate anaglyph stereo images", ICASSP 2001), in the normalised form for CRT primaries
/// and red-cyan filters published on his anaglyph page and reproduced from the spectra by Sanders
/// and McAllister ("Producing anaglyphs from synthetic images", SPIE 5006, 2003). Each row of
/// [left | right] sums to 1, so a white pair maps to white.
inline constexpr ColorMatrix kDuboisRedCyanLeft = {{
    {0.4561f, 0.500484f, 0.176381f},
    {-0.0400822f, -0.0378246f, -0.0157589f},
    {-0.0152161f, -0.0205971f, -0.00546856f},
}};

/// The right-eye half of the Dubois red-cyan projection (see kDuboisRedCyanLeft).
inline constexpr ColorMatrix kDuboisRedCyanRight = {{
    {-0.0434706f, -0.0879388f, -0.00155529f},
    {0.378476f, 0.73364f, -0.0184503f},
    {-0.0721527f, -0.112961f, 1.2264f},
}};

/// Red-cyan anaglyph: out = clamp(L * left.rgb + R * right.rgb, 0, 1) per pixel in linear light,
/// with the Dubois matrices above (NaN reads as 0). Returns an image of the eyes' size with one
/// "rgb" plane. Throws InputError if either eye lacks an "rgb" plane or the sizes differ.
[[nodiscard]] Image anaglyph_dubois(const Image& left, const Image& right);

/// Side-by-side layout: the left eye in columns [0, W), the right eye in [W, 2W); one "rgb" plane,
/// values copied unchanged. Throws InputError for a missing "rgb" plane, different sizes, or a
/// combined width above kMaxImageDimension.
[[nodiscard]] Image side_by_side(const Image& left, const Image& right);

/// Over/under layout: the left eye in rows [0, H) (on top), the right eye in rows [H, 2H); one
/// "rgb" plane, values copied unchanged. Same errors as side_by_side, for the combined height.
[[nodiscard]] Image over_under(const Image& left, const Image& right);

}  // namespace sb
