// Crack removal: per row, narrow hole runs filled by linear interpolation between their neighbours.
#include "renderer/stages/crack_fill.hpp"

#include <atomic>
#include <cmath>
#include <limits>
#include <vector>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/stages/eye_image.hpp"

namespace sb {

namespace {

void require_crack_planes(const Image& image, int max_width) {
  if (max_width < 0)
    throw InputError(fmt::format("crack fill: max width {} must be 0 or more pixels", max_width));
  for (std::string_view name :
       {planes::rgb, planes::depth, planes::normal, planes::albedo, planes::primid, planes::source})
    if (!image.has_plane(name))
      throw InputError(fmt::format("crack fill: the image has no '{}' plane (it has {})", name, image.plane_list()));
}

}  // namespace

uint64_t mark_depth_cracks(Image& image, int max_width, double depth_ratio, const Executor& executor) {
  require_crack_planes(image, max_width);
  if (!(depth_ratio >= 1.0 && depth_ratio < 1e6))
    throw InputError(fmt::format("crack fill: depth ratio {} must be 1 or more", depth_ratio));
  const float* depth = image.data_f32(planes::depth);
  const uint32_t* tag = image.data_u32(planes::source);
  EyeWriter out(image);
  const int w = image.width(), h = image.height();
  const auto hole = static_cast<uint32_t>(Source::hole);
  const auto bound = [&](size_t i) { return tag[i] != hole && std::isfinite(depth[i]); };
  std::atomic<uint64_t> marked{0};
  executor.for_range(static_cast<size_t>(h), 4, [&](size_t begin, size_t end) {
    uint64_t n_marked = 0;
    std::vector<size_t> deeper;
    for (size_t y = begin; y < end; ++y) {
      const size_t row = y * static_cast<size_t>(w);
      int a = 1;
      while (a < w) {
        const size_t l = row + a - 1;
        if (!bound(l)) {
          ++a;
          continue;
        }
        // The run [a, b) of pixels that are holes or deeper than L, at most max_width + 1 long.
        const double left_limit = depth[l] * depth_ratio;
        int b = a;
        while (b < w && b - a <= max_width && (tag[row + b] == hole || depth[row + b] > left_limit)) ++b;
        if (b == a || b - a > max_width || b == w || !bound(row + b)) {
          a = std::max(a + 1, b);
          continue;
        }
        const double right_limit = depth[row + b] * depth_ratio;
        deeper.clear();
        bool crack = true;
        for (int k = a; k < b && crack; ++k) {
          if (tag[row + k] == hole) continue;
          crack = depth[row + k] > right_limit;
          deeper.push_back(row + k);
        }
        if (crack && !deeper.empty()) {
          for (const size_t i : deeper) out.hole(i);
          n_marked += deeper.size();
        }
        a = b + 1;
      }
    }
    marked += n_marked;
  });
  return marked;
}

CrackFillStats fill_cracks(Image& image, int max_width, const Executor& executor, CrackMode mode) {
  require_crack_planes(image, max_width);
  float* rgb = image.data_f32(planes::rgb);
  float* depth = image.data_f32(planes::depth);
  float* normal = image.data_f32(planes::normal);
  float* albedo = image.data_f32(planes::albedo);
  uint32_t* prim = image.data_u32(planes::primid);
  uint32_t* tag = image.data_u32(planes::source);
  const int w = image.width(), h = image.height();
  const auto hole = static_cast<uint32_t>(Source::hole);

  std::atomic<uint64_t> hole_pixels{0}, cracks{0}, filled{0}, large{0}, large_pixels{0}, border{0}, border_pixels{0},
      unfilled{0}, unfilled_pixels{0};
  executor.for_range(static_cast<size_t>(h), 4, [&](size_t begin, size_t end) {
    uint64_t n_holes = 0, n_cracks = 0, n_filled = 0, n_large = 0, n_large_px = 0, n_border = 0, n_border_px = 0,
             n_unfilled = 0, n_unfilled_px = 0;
    for (size_t y = begin; y < end; ++y) {
      const size_t row = y * static_cast<size_t>(w);
      int x = 0;
      while (x < w) {
        if (tag[row + x] != hole) {
          ++x;
          continue;
        }
        // A run [a, b) of hole pixels.
        const int a = x;
        while (x < w && tag[row + x] == hole) ++x;
        const int b = x;
        const auto n = static_cast<uint64_t>(b - a);
        n_holes += n;
        if (a == 0 || b == w) {
          ++n_border;
          n_border_px += n;
          continue;
        }
        if (b - a > max_width) {
          ++n_large;
          n_large_px += n;
          continue;
        }
        if (mode == CrackMode::count) {
          ++n_unfilled;
          n_unfilled_px += n;
          continue;
        }
        // Interpolate between L = a - 1 and R = b.
        const size_t l = row + a - 1, r = row + b;
        const size_t far = depth[r] > depth[l] ? r : l;
        const bool finite = std::isfinite(depth[l]) && std::isfinite(depth[r]);
        for (int k = a; k < b; ++k) {
          const size_t i = row + k;
          const float t = static_cast<float>(k - a + 1) / static_cast<float>(b - a + 1);
          for (int c = 0; c < 3; ++c) {
            rgb[3 * i + c] = rgb[3 * l + c] * (1.0f - t) + rgb[3 * r + c] * t;
            normal[3 * i + c] = normal[3 * far + c];
            albedo[3 * i + c] = albedo[3 * far + c];
          }
          depth[i] = finite ? depth[l] * (1.0f - t) + depth[r] * t : std::numeric_limits<float>::infinity();
          prim[i] = prim[far];
          tag[i] = static_cast<uint32_t>(Source::inpainted);
        }
        ++n_cracks;
        n_filled += n;
      }
    }
    hole_pixels += n_holes;
    cracks += n_cracks;
    filled += n_filled;
    large += n_large;
    large_pixels += n_large_px;
    border += n_border;
    border_pixels += n_border_px;
    unfilled += n_unfilled;
    unfilled_pixels += n_unfilled_px;
  });
  CrackFillStats s;
  s.hole_pixels = hole_pixels;
  s.cracks = cracks;
  s.pixels_filled = filled;
  s.large_holes = large;
  s.large_hole_pixels = large_pixels;
  s.border_holes = border;
  s.border_hole_pixels = border_pixels;
  s.cracks_unfilled = unfilled;
  s.crack_pixels_unfilled = unfilled_pixels;
  return s;
}

int max_crack_option(const std::string& pipeline, const PipelineOptions& options) {
  const int n = options.get_int("max_crack");
  if (n < 0 || n > 64) throw InputError(fmt::format("{}: option max_crack={} is out of range 0..64 (pixels)", pipeline, n));
  return n;
}

void add_crack_counters(Counters& counters, const CrackFillStats& stats) {
  counters.set("pixels_filled_crack", stats.pixels_filled);
  counters.set("holes_left", stats.holes_left());
  counters.set("cracks_filled", stats.cracks);
  counters.set("large_holes", stats.large_holes);
  counters.set("large_hole_pixels", stats.large_hole_pixels);
  counters.set("border_holes", stats.border_holes);
  counters.set("border_hole_pixels", stats.border_hole_pixels);
  counters.set("cracks_unfilled", stats.cracks_unfilled);
  counters.set("crack_pixels_unfilled", stats.crack_pixels_unfilled);
}

}  // namespace sb
