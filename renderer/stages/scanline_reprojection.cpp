// Algorithm 1 of Al-Hagri's thesis (after Adelson and Hodges) for one band of scan-lines.
#include "renderer/stages/scanline_reprojection.hpp"

#include <algorithm>
#include <chrono>
#include <vector>

namespace sb {

namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

/// Algorithm 1 for row y: the winning source column per right pixel (kNoSource: NoHit).
void reproject_row(const PixelReprojector& reprojector, const float* left_depth, int width, int y,
                   std::vector<int32_t>& source, ScanlineCounts& counts) {
  source.assign(static_cast<size_t>(width), kNoSource);
  std::vector<uint8_t> bad(static_cast<size_t>(width), 0);
  int32_t old_r = -1;
  bool landed = false;  // whether a reprojection came before in this row
  // Whether a background pixel came since the last reprojection.
  bool background_between = false;
  for (int x = 0; x < width; ++x) {
    const float depth = left_depth[static_cast<size_t>(y) * width + x];
    const int32_t r = reprojector.column(x, y, depth);
    background_between |= is_miss(depth);
    if (r == kMissColumn) continue;
    if (r >= width) {
      // Algorithm 1's else branch: a hit beyond the right edge sets oldR to w − 1, so that a
      // farther surface landing inside again opens no gap over pixels already hit.
      old_r = width - 1;
      landed = true;
      continue;
    }
    // A jump of more than one pixel after an earlier reprojection leaves a gap: its pixels are NoHit,
    // whatever reached them before. The thesis calls the gap bad when the two reprojections come
    // from horizontally adjacent pixels; across a background pixel (not reprojected here) they do
    // not, and the gap's pixels count as missed. A hit left of the image is a reprojection too
    // (rep < w in Algorithm 1): it moves oldR, and the gap up to the next landing inside starts at
    // column 0. Passing over it left a farther surface reprojected earlier where a nearer one,
    // landing left of the image, opens a gap (spheres at 100 px of disparity: 287 such pixels).
    if (landed && r - old_r > 1)
      for (int32_t k = std::max(old_r + 1, 0); k < r; ++k) {
        source[static_cast<size_t>(k)] = kNoSource;
        if (!background_between) bad[static_cast<size_t>(k)] = 1;
      }
    background_between = false;
    old_r = r;
    landed = true;
    if (r < 0) continue;
    // Later pixels (larger source x) overwrite: the nearer surface for a right eye to the right.
    if (source[static_cast<size_t>(r)] != kNoSource) ++counts.overlapped;
    source[static_cast<size_t>(r)] = x;
    bad[static_cast<size_t>(r)] = 0;
  }
  for (int x = 0; x < width; ++x) {
    if (source[static_cast<size_t>(x)] != kNoSource) continue;
    (bad[static_cast<size_t>(x)] ? counts.bad : counts.missed)++;
  }
}

}  // namespace

void ScanlineCounts::add(const ScanlineCounts& o) {
  for (auto [mine, theirs] : {std::pair{&left, &o.left}, std::pair{&right, &o.right}}) {
    mine->primary_rays += theirs->primary_rays;
    mine->shadow_rays += theirs->shadow_rays;
    mine->pixels_shaded += theirs->pixels_shaded;
    mine->pixels_traced += theirs->pixels_traced;
  }
  overlapped += o.overlapped;
  bad += o.bad;
  missed += o.missed;
  left_seconds += o.left_seconds;
  reproject_seconds += o.reproject_seconds;
  right_seconds += o.right_seconds;
}

void add_scanline_counters(StereoResult& r, const ScanlineCounts& counts, const StereoRig& rig) {
  add_counts(r.counters, counts.left, "left", true);
  add_counts(r.counters, counts.right, "right", true);
  r.counters.set("overlapped", counts.overlapped);
  r.counters.set("bad", counts.bad);
  r.counters.set("missed", counts.missed);
  r.counters.set("hole_pixels", counts.bad + counts.missed);
  r.counters.set("pixels_reprojected_right", static_cast<uint64_t>(r.right.pixel_count()) - counts.bad - counts.missed);
  // The write histogram is counted apart, on one thread, outside every timed stage.
  add_write_counters(r.counters, reprojection_writes(PixelReprojector(rig), r.left, Executor(1)), rig, r.left);
}

void scanline_band(const RenderScene& scene, const PixelReprojector& reprojector, int y0, int y1, Image& left,
                   Image& right, ScanlineCounts& counts) {
  const int w = left.width();
  auto start = Clock::now();
  trace_rect(scene, reprojector.left(), reprojector.left_rays(), PixelRect{0, y0, w, y1}, left, counts.left);
  counts.left_seconds += since(start);

  start = Clock::now();
  const float* depth = left.data_f32(planes::depth);
  std::vector<int32_t> source;
  std::vector<uint32_t> no_hit;
  const EyeReader from(left);
  EyeWriter out(right);
  for (int y = y0; y < y1; ++y) {
    reproject_row(reprojector, depth, w, y, source, counts);
    for (int x = 0; x < w; ++x) {
      const size_t p = static_cast<size_t>(y) * w + x;
      // Algorithm 1 computes a Hit pixel's colour again for the right camera; with diffuse
      // materials (the thesis's, and ours) that is the left pixel's, so it is copied.
      if (source[static_cast<size_t>(x)] == kNoSource)
        no_hit.push_back(static_cast<uint32_t>(p));
      else
        out.copy(p, from, p - x + static_cast<size_t>(source[static_cast<size_t>(x)]), Source::reprojected);
    }
  }
  counts.reproject_seconds += since(start);

  start = Clock::now();
  trace_pixels_here(scene, reprojector.right(), reprojector.right_rays(), no_hit, right, counts.right,
                    Source::reshaded_traced);
  counts.right_seconds += since(start);
}

}  // namespace sb
