// Hole statistics of a synthesized right eye (DESIGN §6.3): how much of the image the pipeline
// could not take from the left eye, how it filled it, how the holes are shaped (connected
// regions), the pipeline's own taxonomy and grid counters, and how well its hole mask matches the
// true disocclusions.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/image.hpp"
#include "renderer/stages/disocclusion.hpp"
#include "renderer/stats.hpp"

namespace sb::validation {

/// Connected regions of a mask (8-connectivity).
struct RegionStats {
  uint64_t count = 0;
  uint64_t largest = 0;  ///< pixels of the largest region, 0 without regions
  /// Regions by size: bin k counts regions of [2^k, 2^(k+1)) pixels (1, 2-3, 4-7, ...), with the
  /// last bin open-ended. Always kRegionBins entries.
  std::vector<uint64_t> histogram;
};
inline constexpr int kRegionBins = 16;

/// Connected regions of the non-zero pixels of a width x height mask (OpenCV connected
/// components). InputError if the mask is not width x height.
[[nodiscard]] RegionStats connected_regions(std::span<const uint8_t> mask, int width, int height);

/// Everything §6.3 reports for one right eye.
struct HoleStatistics {
  uint64_t pixels = 0;
  /// The pixels the pipeline did not take from a source image (hole_mask_from_sources): holes it
  /// found and filled, or left.
  uint64_t hole_pixels = 0;
  double hole_fraction = 0.0;
  /// Pixels per source tag ("reprojected", "reshaded_traced", "hole", ...), every tag listed.
  std::map<std::string, uint64_t> pixels_by_source;
  RegionStats hole_regions;
  /// The pipeline's own counters that §6.3 names, when it reports them: hole pixels before filling,
  /// the Al-Hagri taxonomy (missed, overlapped, bad) and grid statistics (cells subdivided,
  /// triangles).
  std::map<std::string, uint64_t> pipeline_counters;
  /// Against the true disocclusions: their count, kinds and connected regions, and how the pixels
  /// the pipeline did NOT reproject from the left eye (rendered for the right eye, filled, or left
  /// as holes) cover them: recall is the share of true disocclusions that were not shown by
  /// reprojection (a reprojected pixel there shows the wrong surface), precision the share of
  /// those pixels that needed it (the rest is work a perfect hole mask would have saved). For a
  /// reprojecting pipeline that renders nothing natively for the right eye this is its hole mask.
  uint64_t true_disocclusions = 0;
  /// The masks counted and scored, one value per pixel: the hole mask (hole_mask_from_sources) and
  /// the pixels not reprojected (not_reprojected_mask), for the region metrics and the overlay.
  std::vector<uint8_t> hole_mask, not_reprojected;
  uint64_t outside_frustum = 0;
  uint64_t hidden = 0;
  RegionStats disocclusion_regions;
  HoleScores scores;
};

/// Counters copied into HoleStatistics::pipeline_counters when a pipeline sets them.
[[nodiscard]] std::span<const char* const> hole_counter_names();

/// The statistics of a right eye with a "source" plane (InputError without one) against the true
/// disocclusions of the same rig (InputError if their size differs).
[[nodiscard]] HoleStatistics hole_statistics(const Image& right, const Counters& counters,
                                             const TrueDisocclusions& truth);

[[nodiscard]] nlohmann::json to_json(const RegionStats& regions);
[[nodiscard]] nlohmann::json to_json(const HoleStatistics& stats);

}  // namespace sb::validation
