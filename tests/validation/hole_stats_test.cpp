// Hole statistics: connected regions, counts per source tag, and scores against the truth.
#include <gtest/gtest.h>

#include <algorithm>

#include "renderer/error.hpp"
#include "renderer/stages/eye_image.hpp"
#include "validation/hole_stats.hpp"

namespace sb::validation {
namespace {

TEST(ConnectedRegions, CountsEightConnectedRegionsAndBinsTheirSizes) {
  // 8 x 5:  a single pixel, an L of 5 pixels, and two diagonal pixels that touch (one region).
  const std::vector<uint8_t> mask = {
      1, 0, 0, 0, 0, 0, 0, 0,  //
      0, 0, 1, 0, 0, 0, 1, 0,  //
      0, 0, 1, 0, 0, 0, 0, 1,  //
      0, 0, 1, 1, 1, 0, 0, 0,  //
      0, 0, 0, 0, 0, 0, 0, 0};
  const RegionStats r = connected_regions(mask, 8, 5);
  EXPECT_EQ(r.count, 3u);
  EXPECT_EQ(r.largest, 5u);
  ASSERT_EQ(r.histogram.size(), static_cast<size_t>(kRegionBins));
  EXPECT_EQ(r.histogram[0], 1u);  // 1 pixel
  EXPECT_EQ(r.histogram[1], 1u);  // 2-3 pixels
  EXPECT_EQ(r.histogram[2], 1u);  // 4-7 pixels
}

TEST(ConnectedRegions, EmptyAndMisshapenMasks) {
  const RegionStats none = connected_regions(std::vector<uint8_t>(12, 0), 4, 3);
  EXPECT_EQ(none.count, 0u);
  EXPECT_EQ(none.largest, 0u);
  EXPECT_THROW((void)connected_regions(std::vector<uint8_t>(11, 0), 4, 3), InputError);
}

TEST(HoleStatistics, CountsTagsRegionsAndScores) {
  Image right = make_eye_image(4, 2);
  uint32_t* src = right.data_u32(planes::source);
  const Source tags[8] = {Source::reprojected, Source::reshaded_traced, Source::reshaded_traced, Source::reprojected,
                          Source::rasterized,  Source::reprojected,    Source::hole,            Source::reprojected};
  for (int i = 0; i < 8; ++i) src[i] = static_cast<uint32_t>(tags[i]);
  TrueDisocclusions truth;
  truth.mask = {0, 2, 0, 0, 1, 1, 0, 0};
  truth.hidden = 2;
  truth.outside_frustum = 1;
  Counters counters;
  counters.set("hole_pixels", 3);
  counters.set("grid_triangles", 40);
  counters.set("primary_rays", 99);
  const HoleStatistics s = hole_statistics(right, counters, truth);
  EXPECT_EQ(s.pixels, 8u);
  EXPECT_EQ(s.hole_pixels, 3u);
  EXPECT_DOUBLE_EQ(s.hole_fraction, 3.0 / 8.0);
  EXPECT_EQ(s.pixels_by_source.at("reprojected"), 4u);
  EXPECT_EQ(s.pixels_by_source.at("rasterized"), 1u);
  EXPECT_EQ(s.pixels_by_source.at("reshaded_traced"), 2u);
  EXPECT_EQ(s.pixels_by_source.at("hole"), 1u);
  EXPECT_EQ(s.pixels_by_source.at("inpainted"), 0u);
  EXPECT_EQ(s.hole_regions.count, 1u);  // (1,0), (2,0) and (2,1) are one region
  EXPECT_EQ(s.hole_regions.largest, 3u);
  EXPECT_EQ(s.disocclusion_regions.count, 1u);  // (1,0), (0,1) and (1,1) touch
  EXPECT_EQ(s.pipeline_counters.at("hole_pixels"), 3u);
  EXPECT_EQ(s.pipeline_counters.at("grid_triangles"), 40u);
  EXPECT_EQ(s.pipeline_counters.count("primary_rays"), 0u);
  // Not reprojected: (1,0), (2,0), (0,1) rasterized, (2,1); truly disoccluded: (1,0), (0,1), (1,1).
  EXPECT_EQ(s.true_disocclusions, 3u);
  EXPECT_EQ(s.scores.hole_pixels, 4u);
  EXPECT_EQ(std::count(s.not_reprojected.begin(), s.not_reprojected.end(), uint8_t{1}), 4);  // the mask scored
  EXPECT_EQ(std::count(s.hole_mask.begin(), s.hole_mask.end(), uint8_t{1}), 3);
  EXPECT_EQ(s.scores.true_positives, 2u);
  EXPECT_DOUBLE_EQ(s.scores.recall, 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(s.scores.precision, 0.5);
  const auto j = to_json(s);
  EXPECT_EQ(j["not_reprojected"]["recall"], 2.0 / 3.0);
  EXPECT_EQ(j["true_disocclusions"]["hidden"], 2);

  TrueDisocclusions wrong;
  wrong.mask.assign(7, 0);
  EXPECT_THROW((void)hole_statistics(right, counters, wrong), InputError);
}

}  // namespace
}  // namespace sb::validation
