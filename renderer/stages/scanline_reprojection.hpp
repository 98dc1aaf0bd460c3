// Adelson and Hodges' scan-line reprojection (Al-Hagri, Algorithm 1), shared by rt-adelson (one
// thread) and rt-es-isler (scan-lines in parallel): each left scan-line is traced and its hits are
// reprojected left to right in order, so that a later (larger source x) pixel overwrites an
// earlier one; a jump of more than one pixel between consecutive reprojections marks the pixels
// in between NoHit ("bad"), and every NoHit pixel of the right scan-line is traced.
#pragma once

#include <cstdint>

#include "renderer/image.hpp"
#include "renderer/pipeline.hpp"
#include "renderer/render_scene.hpp"
#include "renderer/stages/pixel_reprojection.hpp"
#include "renderer/stages/trace.hpp"

namespace sb {

/// Side of the bands of scan-lines the pipelines process as one unit: the height of the 4x4 ray
/// packets, so that the left eye is traced in plain-rt's packets and matches it bit for bit.
inline constexpr int kScanlineBand = 4;

/// What one band did.
struct ScanlineCounts {
  TraceCounts left;
  TraceCounts right;
  uint64_t overlapped = 0;  ///< writes onto a right pixel already hit
  uint64_t bad = 0;         ///< pixels in gaps of more than one pixel between consecutive reprojections
  uint64_t missed = 0;      ///< NoHit pixels no gap accounts for
  double left_seconds = 0.0;
  double reproject_seconds = 0.0;
  double right_seconds = 0.0;

  void add(const ScanlineCounts& o);
};

/// Processes scan-lines [y0, y1) (a band of kScanlineBand rows, or the image's last rows) in the
/// calling thread: traces them in the left eye, reprojects each row in order into `right` (tag
/// `reprojected`) and traces the right pixels left NoHit (tag `reshaded_traced`).
void scanline_band(const RenderScene& scene, const PixelReprojector& reprojector, int y0, int y1, Image& left,
                   Image& right, ScanlineCounts& counts);

/// Adds a run's counts to its result: rays and pixels per eye, overlapped, bad, missed,
/// hole_pixels (bad + missed) and the Lemma 1 write histogram of the left eye.
void add_scanline_counters(StereoResult& result, const ScanlineCounts& counts, const StereoRig& rig);

}  // namespace sb
