// Stage timings: which eye each stage serves, and what the eyes' shares add up to.
#include <gtest/gtest.h>

#include <stdexcept>

#include "renderer/stats.hpp"

namespace sb {
namespace {

TEST(Timings, SplitsTheTimeByTheEyeEachStageServes) {
  Timings t;
  t.add("left_gbuffer", 0.25, StageEye::left);
  t.add("grid_warp", 0.125, StageEye::right);
  t.add("hole_fill", 0.5, StageEye::right);
  t.add("left_gbuffer", 0.25, StageEye::left);  // a repeated stage accumulates
  EXPECT_EQ(t.stages().size(), 3u);
  EXPECT_EQ(t.eye_total(StageEye::left), 0.5);
  EXPECT_EQ(t.eye_total(StageEye::right), 0.625);
  EXPECT_EQ(t.eye_total(StageEye::both), 0.0);
  EXPECT_TRUE(t.shared_stages().empty());
  t.add("redirect", 1.0, StageEye::both);
  EXPECT_EQ(t.shared_stages(), std::vector<std::string>{"redirect"});
  EXPECT_EQ(t.total(), 2.125);
}

TEST(Timings, AStageServesOneEyeThroughout) {
  Timings t;
  t.add("warp", 0.5, StageEye::right);
  EXPECT_THROW(t.add("warp", 0.5, StageEye::both), std::logic_error);
  // A scoped stage claims its eye when it starts, so the mistake throws there, not in a destructor.
  EXPECT_THROW(ScopedStage(t, "warp", StageEye::left), std::logic_error);
  EXPECT_EQ(t.get("warp"), 0.5);
  {
    ScopedStage s(t, "crack_fill", StageEye::right);
    ASSERT_EQ(t.stages().size(), 2u);
    EXPECT_EQ(t.stages()[1].name, "crack_fill");
  }
  EXPECT_EQ(t.stages()[1].eye, StageEye::right);
}

}  // namespace
}  // namespace sb
