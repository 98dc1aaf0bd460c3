// Side-by-side timing (validation/benchmark.hpp): the order pipelines run in within repetitions.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "renderer/parallel.hpp"
#include "renderer/render_scene.hpp"
#include "support/render_support.hpp"
#include "validation/benchmark.hpp"

namespace sb {
namespace {

/// The pipeline a progress line ("repetition 2/3 plain-rt 1.2 ms") names, or "" for a warm-up.
std::string timed_pipeline(const std::string& line) {
  if (line.rfind("repetition ", 0) != 0) return "";
  const size_t name = line.find(' ', std::string("repetition ").size()) + 1;
  return line.substr(name, line.find(' ', name) - name);
}

TEST(Benchmark, EachRepetitionStartsOnePipelineFurtherAlong) {
  // The pipeline run first in a repetition was measured up to 10 % slower in its first stage:
  // a fixed order favoured every pipeline after the baseline. Rotated, each takes every place.
  const Scene scene = test::load_builtin("box-wall");
  const RenderScene prepared(scene);
  const StereoRig rig = test::rig_at(scene, 32, 18);
  BenchConfig config;
  config.pipelines = {"plain-rt", "plain-raster", "ideal-copy"};
  config.baseline = "plain-rt";
  config.warmup = 0;
  config.repetitions = 4;
  std::vector<std::string> order;
  const BenchResult r =
      run_bench(prepared, rig, config, Executor(1), [&](const std::string& line) {
        if (const std::string p = timed_pipeline(line); !p.empty()) order.push_back(p);
      });
  const std::vector<std::string> expected = {"plain-rt",   "plain-raster", "ideal-copy", "plain-raster",
                                             "ideal-copy", "plain-rt",     "ideal-copy", "plain-rt",
                                             "plain-raster", "plain-rt",   "plain-raster", "ideal-copy"};
  EXPECT_EQ(order, expected);
  // Results stay filed under their pipelines, one sample per repetition each.
  ASSERT_EQ(r.pipelines.size(), 3u);
  for (const PipelineBench& p : r.pipelines) EXPECT_EQ(p.total_seconds.size(), 4u) << p.name;
  EXPECT_EQ(r.pipelines[0].name, "plain-rt");
  EXPECT_DOUBLE_EQ(r.pipelines[0].speedup.median, 1.0);
}

}  // namespace
}  // namespace sb
