// `stereobench bench --preset` and `--lights`: each preset runs its first rows and prints a table per
// series, the JSON holds every row, and bad presets or light counts exit with code 3 and say why.
// Timings are never asserted, only that they were measured.
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "support/run_cli.hpp"
#include "support/scratch_dir.hpp"

namespace sb {
namespace {

using nlohmann::json;
using test::CliRun;

/// The quick form of a preset: two pipelines, one repetition, no warm-up, the first rows only.
CliRun run_preset(const std::string& preset, int rows, const test::ScratchDir& dir, const std::string& json_file) {
  return test::run_cli("bench --preset " + preset + " --preset-rows " + std::to_string(rows) +
                       " --pipelines plain-rt,ideal-copy --repetitions 1 --warmup 0 --scenes-dir '" +
                       (dir / "scenes").string() + "' --json '" + (dir / json_file).string() + "'");
}

/// Checks what every preset row records: both pipelines timed, speed-ups against plain-rt.
void expect_timed_row(const json& row) {
  SCOPED_TRACE(row.at("series").get<std::string>() + " " + row.at("value").get<std::string>());
  for (const char* p : {"plain-rt", "ideal-copy"}) {
    EXPECT_GT(row.at("median_total_ms").at(p).get<double>(), 0.0) << p;
    EXPECT_GT(row.at("speedup_median").at(p).get<double>(), 0.0) << p;
  }
  EXPECT_EQ(row.at("speedup_median").at("plain-rt").get<double>(), 1.0);
  EXPECT_EQ(row.at("bench").at("baseline"), "plain-rt");
  EXPECT_EQ(row.at("bench").at("repetitions").get<int>(), 1);
}

TEST(BenchPreset, DimensionsRunsTheFirstSizeOfEveryScene) {
  test::ScratchDir dir("dimensions");
  const CliRun r = run_preset("al-hagri-dimensions", 1, dir, "dimensions.json");
  ASSERT_EQ(r.code, 0) << r.out;
  for (const char* part : {"plain-rt ms", "ideal-copy ms", "speed-up", "200x200", "spheres by image size",
                           "dragon by image size", "complexity by image size", "note: complexity has only 3 lights"})
    EXPECT_NE(r.out.find(part), std::string::npos) << part << "\n" << r.out;
  EXPECT_EQ(r.out.find("250x250"), std::string::npos) << r.out;  // one row per series

  const json j = json::parse(test::read_text(dir / "dimensions.json"));
  EXPECT_TRUE(j.at("complete").get<bool>());
  EXPECT_EQ(j.at("preset"), "al-hagri-dimensions");
  const json& rows = j.at("rows");
  ASSERT_EQ(rows.size(), 6u);  // spheres, atrium, bistro, temple, dragon, complexity
  for (const json& row : rows) {
    expect_timed_row(row);
    EXPECT_EQ(row.at("value"), "200x200");
    EXPECT_EQ(row.at("rig").at("width").get<int>(), 200);
    EXPECT_EQ(row.at("rig").at("height").get<int>(), 200);
    EXPECT_NEAR(row.at("rig").at("max_disparity_px").get<double>(), 15.0, 1e-9);
    const json& scene = row.at("scene");
    EXPECT_EQ(scene.at("lights_requested").get<int>(), 5);
    const size_t expected_lights = scene.at("name") == "complexity" ? 3u : 5u;
    EXPECT_EQ(scene.at("lights").get<size_t>(), expected_lights) << scene.at("name");
  }
}

TEST(BenchPreset, InteraxialRunsItsFirstDisparity) {
  test::ScratchDir dir("interaxial");
  const CliRun r = run_preset("al-hagri-interaxial", 1, dir, "interaxial.json");
  ASSERT_EQ(r.code, 0) << r.out;
  for (const char* part : {"dragon by interaxial distance", "600x600, 5 lights", "e px", "plain-rt ms", "ideal-copy ms"})
    EXPECT_NE(r.out.find(part), std::string::npos) << part << "\n" << r.out;
  const json j = json::parse(test::read_text(dir / "interaxial.json"));
  ASSERT_EQ(j.at("rows").size(), 1u);
  const json& row = j.at("rows")[0];
  expect_timed_row(row);
  EXPECT_EQ(row.at("value"), "10");
  EXPECT_NEAR(row.at("rig").at("max_disparity_px").get<double>(), 10.0, 1e-9);
  EXPECT_EQ(row.at("rig").at("width").get<int>(), 600);
  EXPECT_EQ(row.at("scene").at("lights").get<int>(), 5);
}

TEST(BenchPreset, LightsKeepsTheFirstNOfTheTenLightDragon) {
  test::ScratchDir dir("lights");
  const CliRun r = run_preset("al-hagri-lights", 2, dir, "lights.json");
  ASSERT_EQ(r.code, 0) << r.out;
  for (const char* part : {"dragon by number of lights", "lights", "plain-rt ms", "ideal-copy ms"})
    EXPECT_NE(r.out.find(part), std::string::npos) << part << "\n" << r.out;
  EXPECT_TRUE(std::filesystem::exists(dir / "scenes" / "dragon_lights-10.glb"));
  const json j = json::parse(test::read_text(dir / "lights.json"));
  const json& rows = j.at("rows");
  ASSERT_EQ(rows.size(), 2u);
  for (int n = 1; n <= 2; ++n) {
    const json& row = rows[static_cast<size_t>(n - 1)];
    expect_timed_row(row);
    EXPECT_EQ(row.at("value"), std::to_string(n));
    EXPECT_EQ(row.at("scene").at("lights").get<int>(), n);
    EXPECT_EQ(row.at("scene").at("lights_in_file").get<int>(), 10);
    EXPECT_EQ(row.at("scene").at("params").at("lights").get<double>(), 10.0);
    EXPECT_NEAR(row.at("rig").at("max_disparity_px").get<double>(), 15.0, 1e-9);
  }
}

TEST(BenchPreset, HelpExplainsThePresets) {
  const CliRun h = test::run_cli("bench --help");
  EXPECT_EQ(h.code, 0);
  for (const char* part : {"--preset", "--preset-rows", "--lights", "al-hagri-dimensions", "al-hagri-interaxial",
                           "al-hagri-lights", "Table 5"})
    EXPECT_NE(h.out.find(part), std::string::npos) << part << "\n" << h.out;
}

TEST(BenchPreset, BadPresetsAndLightCountsExitWith3AndSayWhy) {
  test::ScratchDir dir("bad");
  const std::string sd = " --scenes-dir '" + (dir / "scenes").string() + "'";
  const std::string quick = " --pipelines plain-rt,ideal-copy -n 1 -w 0" + sd;
  struct Case { std::string args; std::vector<std::string> expect; };
  const Case cases[] = {
      {"bench --preset al-hagri-sponza" + quick,
       {"unknown preset 'al-hagri-sponza'", "al-hagri-dimensions", "al-hagri-interaxial", "al-hagri-lights"}},
      {"bench --preset al-hagri-lights --scene dragon" + quick, {"--preset al-hagri-lights", "drop --scene"}},
      {"bench --preset al-hagri-lights --resolution 64x64" + quick, {"drop --resolution"}},
      {"bench --preset al-hagri-interaxial --interaxial 0.1" + quick, {"drop --interaxial"}},
      {"bench --preset al-hagri-dimensions --max-disparity 20" + quick, {"drop --max-disparity"}},
      {"bench --preset al-hagri-lights --lights 3" + quick, {"drop --lights"}},
      {"bench --preset-rows 1 --scene box-wall" + quick, {"--preset-rows needs --preset"}},
      {"bench --preset al-hagri-lights --pipelines plain-rt,warp-drive" + sd, {"unknown pipeline 'warp-drive'"}},
      {"bench --scene box-wall --resolution 32x18 --lights 0" + quick, {"--lights 0", "'box-wall'", "has 1 light", "1..1"}},
      {"bench --scene box-wall --resolution 32x18 --lights 99" + quick, {"--lights 99", "'box-wall'", "has 1 light"}},
      {"render --scene box-wall --resolution 32x18 --lights 99 --out '" + dir.path().string() + "'" + sd,
       {"--lights 99", "'box-wall'", "has 1 light"}},
  };
  for (const Case& c : cases) {
    const CliRun r = test::run_cli(c.args);
    EXPECT_EQ(r.code, 3) << c.args << "\n" << r.out;
    for (const std::string& e : c.expect)
      EXPECT_NE(r.out.find(e), std::string::npos) << c.args << "\nexpected: " << e << "\ngot: " << r.out;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "scenes" / "dragon_lights-10.glb"));  // nothing generated on bad input
}

TEST(BenchLights, TheLightCountUsedIsPrintedAndRecorded) {
  test::ScratchDir dir("benchlights");
  const std::string common = " --scene complexity --resolution 32x18 --scenes-dir '" + (dir / "scenes").string() + "'";
  const CliRun b = test::run_cli("bench --pipelines plain-rt --baseline plain-rt -n 1 -w 0 --lights 2 --json '" +
                                 (dir / "bench.json").string() + "'" + common);
  ASSERT_EQ(b.code, 0) << b.out;
  EXPECT_NE(b.out.find("first 2 of 3 lights"), std::string::npos) << b.out;
  const json j = json::parse(test::read_text(dir / "bench.json"));
  EXPECT_EQ(j.at("scene").at("lights").get<int>(), 2);
  EXPECT_EQ(j.at("scene").at("lights_in_file").get<int>(), 3);

  const CliRun all = test::run_cli("bench --pipelines plain-rt --baseline plain-rt -n 1 -w 0" + common);
  ASSERT_EQ(all.code, 0) << all.out;
  EXPECT_NE(all.out.find("triangles, 3 lights)"), std::string::npos) << all.out;

  const CliRun r = test::run_cli("render --pipeline plain-rt --lights 1 --out '" + dir.path().string() + "'" + common);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("first 1 of 3 lights"), std::string::npos) << r.out;
  const json s = json::parse(test::read_text(dir / "complexity_plain-rt_stats.json"));
  EXPECT_EQ(s.at("scene").at("lights").get<int>(), 1);
  EXPECT_GT(s.at("counters").at("shadow_rays").get<uint64_t>(), 0u);
}

}  // namespace
}  // namespace sb
