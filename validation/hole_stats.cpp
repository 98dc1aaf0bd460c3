// Hole statistics; OpenCV labels the connected regions.
#include "validation/hole_stats.hpp"

#include <algorithm>
#include <array>
#include <bit>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "renderer/error.hpp"

namespace sb::validation {

using nlohmann::json;

RegionStats connected_regions(std::span<const uint8_t> mask, int width, int height) {
  if (width < 0 || height < 0 || mask.size() != static_cast<size_t>(width) * static_cast<size_t>(height))
    throw InputError(fmt::format("a mask of {} values cannot be a {}x{} image", mask.size(), width, height));
  RegionStats out;
  out.histogram.assign(kRegionBins, 0);
  if (mask.empty()) return out;
  cv::Mat binary(height, width, CV_8U);
  for (int y = 0; y < height; ++y) {
    uint8_t* row = binary.ptr<uint8_t>(y);
    for (int x = 0; x < width; ++x) row[x] = mask[static_cast<size_t>(y) * width + x] != 0 ? 255 : 0;
  }
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(binary, labels, stats, centroids, 8, CV_32S);
  for (int label = 1; label < n; ++label) {  // label 0 is the background
    const auto area = static_cast<uint64_t>(stats.at<int>(label, cv::CC_STAT_AREA));
    ++out.count;
    out.largest = std::max(out.largest, area);
    const int bin = std::min(kRegionBins - 1, static_cast<int>(std::bit_width(area)) - 1);
    ++out.histogram[static_cast<size_t>(bin)];
  }
  return out;
}

std::span<const char* const> hole_counter_names() {
  static constexpr std::array<const char*, 11> names = {
      "hole_pixels",    "missed",         "overlapped",  "bad",
      "grid_cells",     "grid_cells_subdivided", "grid_triangles", "large_holes",
      "large_hole_pixels", "cracks_unfilled", "crack_pixels_unfilled"};
  return names;
}

HoleStatistics hole_statistics(const Image& right, const Counters& counters, const TrueDisocclusions& truth) {
  HoleStatistics s;
  s.pixels = right.pixel_count();
  if (truth.mask.size() != s.pixels)
    throw InputError(fmt::format("the true disocclusion mask has {} pixels but the right eye {}x{} has {}",
                                 truth.mask.size(), right.width(), right.height(), s.pixels));
  s.hole_mask = hole_mask_from_sources(right);
  s.hole_pixels = static_cast<uint64_t>(std::count(s.hole_mask.begin(), s.hole_mask.end(), uint8_t{1}));
  s.hole_fraction = s.pixels == 0 ? 0.0 : static_cast<double>(s.hole_pixels) / static_cast<double>(s.pixels);

  std::array<uint64_t, kSourceCount> by_tag{};
  const uint32_t* source = right.data_u32(planes::source);
  for (size_t i = 0; i < s.pixels; ++i)
    if (source[i] < kSourceCount) ++by_tag[source[i]];
  for (size_t t = 0; t < kSourceCount; ++t)
    s.pixels_by_source[std::string(to_string(static_cast<Source>(t)))] = by_tag[t];

  s.hole_regions = connected_regions(s.hole_mask, right.width(), right.height());
  const auto snapshot = counters.snapshot();
  for (const char* name : hole_counter_names())
    if (auto it = snapshot.find(name); it != snapshot.end()) s.pipeline_counters[name] = it->second;

  s.true_disocclusions = truth.count();
  s.outside_frustum = truth.outside_frustum;
  s.hidden = truth.hidden;
  s.disocclusion_regions = connected_regions(truth.mask, right.width(), right.height());
  s.not_reprojected = not_reprojected_mask(right);
  s.scores = score_holes(s.not_reprojected, truth.mask);
  return s;
}

json to_json(const RegionStats& r) {
  return {{"count", r.count}, {"largest", r.largest}, {"size_histogram_log2", r.histogram}};
}

json to_json(const HoleStatistics& s) {
  return {{"pixels", s.pixels},
          {"hole_pixels", s.hole_pixels},
          {"hole_fraction", s.hole_fraction},
          {"pixels_by_source", s.pixels_by_source},
          {"hole_regions", to_json(s.hole_regions)},
          {"pipeline_counters", s.pipeline_counters},
          {"true_disocclusions",
           {{"pixels", s.true_disocclusions},
            {"fraction", s.pixels == 0 ? 0.0 : static_cast<double>(s.true_disocclusions) / static_cast<double>(s.pixels)},
            {"outside_frustum", s.outside_frustum},
            {"hidden", s.hidden},
            {"regions", to_json(s.disocclusion_regions)}}},
          {"not_reprojected", {{"pixels", s.scores.hole_pixels}, {"true_positives", s.scores.true_positives}, {"recall", s.scores.recall}, {"precision", s.scores.precision}}}};
}

}  // namespace sb::validation
