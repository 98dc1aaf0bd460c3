// `stereobench bench --preset` and `--lights`: each preset runs its first rows and prints a table per
// series, the JSON holds every row, and bad presets or light counts exit with code 3 and say why.
// Timings are never asserted, only that they were measured. Kim's presets add image quality
// against the reference and the memory check, crossover and stage grouping of the complexity table.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "apps/bench_presets.hpp"

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
  EXPECT_EQ(j.at("kind"), "stereobench.bench_preset");
  EXPECT_EQ(j.at("schema_version"), 1);
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
                           "al-hagri-lights", "Table 5", "kim-focal", "kim-complexity", "Table 2", "Table 3",
                           "--resolution replaces the image size"})
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
      {"bench --preset kim-focal --convergence 2 -n 1 -w 0" + sd, {"--preset kim-focal", "drop --convergence"}},
      {"bench --preset kim-focal --scene atrium -n 1 -w 0" + sd, {"drop --scene"}},
      {"bench --preset kim-complexity --interaxial 0.1 -n 1 -w 0" + sd, {"drop --interaxial"}},
      {"bench --preset kim-focal --pipelines bidir-warp --baseline bidir-warp -n 1 -w 0" + sd,
       {"kim-focal compares every right eye with plain-raster's", "add plain-raster to --pipelines"}},
      {"bench --preset kim-complexity --pipelines plain-raster -n 1 -w 0" + sd, {"add bidir-warp to --pipelines"}},
      {"bench --preset-rows 1 --scene box-wall" + quick, {"--preset-rows needs --preset"}},
      // The JSON rewritten after every row would replace a scene file a row reads, or its stamp.
      {"bench --preset kim-focal --preset-rows 1 -n 1 -w 0 --json '" + (dir / "scenes" / "atrium.glb").string() + "'" + sd,
       {"--json " + (dir / "scenes" / "atrium.glb").string() + " names the same file as a scene file of the preset"}},
      {"bench --preset al-hagri-lights --preset-rows 1" + quick + " --json '" +
           (dir / "scenes" / "dragon_lights-10.glb.stamp").string() + "'",
       {"names the same file as a scene file's stamp"}},
      {"bench --scene box-wall --resolution 32x18 --json '" + (dir / "scenes" / "box-wall.gltf.stamp").string() + "'" +
           quick,
       {"names the same file as the scene file's stamp"}},
      {"bench --preset al-hagri-lights --pipelines plain-rt,warp-drive" + sd,
       {"--pipelines: unknown pipeline 'warp-drive'"}},
      {"bench --scene box-wall --resolution 32x18 --pipelines 'plain-rt, ideal-copy' -n 1 -w 0" + sd,
       {"--pipelines: pipeline entry ' ideal-copy' has blanks around it"}},
      {"bench --scene box-wall --resolution 32x18 --lights 0" + quick, {"--lights 0", "'box-wall'", "has 1 light", "1..1"}},
      {"bench --scene box-wall --resolution 32x18 --lights 99" + quick, {"--lights 99", "'box-wall'", "has 1 light"}},
      {"render --scene box-wall --resolution 32x18 --lights 99 --out '" + dir.path().string() + "'" + sd,
       {"--lights 99", "'box-wall'", "has 1 light"}},
      // Numbers in another base than ten would run silently with another value (0x10 is 16).
      {"bench --scene box-wall --resolution 32x18 --vfov 0x10" + quick, {"--vfov: '0x10' is not a decimal number"}},
      {"bench --scene box-wall --resolution 32x18 --pipelines plain-rt -n 0x2 -w 0" + sd,
       {"--repetitions: '0x2' is not a decimal integer"}},
      // The option at fault is named, also for the baseline and an option without a name.
      {"bench --scene box-wall --resolution 32x18 --baseline nope" + quick, {"--baseline: unknown pipeline 'nope'"}},
      {"bench --scene box-wall --resolution 32x18 --option plain-rt.=4" + quick,
       {"--option plain-rt.=4: name it PIPELINE.OPTION=VALUE"}},
      {"bench --preset al-hagri-lights --json -" + quick, {"--json - with --preset"}},
      {"bench --preset al-hagri-lights --json /dev/null" + quick,
       {"--json /dev/null with --preset", "a device or pipe cannot be"}},
  };
  for (const Case& c : cases) {
    const CliRun r = test::run_cli(c.args);
    EXPECT_EQ(r.code, 3) << c.args << "\n" << r.out;
    for (const std::string& e : c.expect)
      EXPECT_NE(r.out.find(e), std::string::npos) << c.args << "\nexpected: " << e << "\ngot: " << r.out;
  }
  // A run refused before its timing starts keeps an earlier --json (it was removed first): a
  // preset's pipelines, a rig a pipeline refuses.
  const std::string keep = (dir / "keep.json").string();
  for (const std::string& args :
       {"bench --preset kim-complexity --pipelines bw-warp -n 1 -w 0" + sd,
        "bench --scene box-wall --resolution 64x36 --pipelines rt-buffer --baseline rt-buffer --max-disparity 3000 -n 1 "
        "-w 0" + sd}) {
    { std::ofstream(keep) << "{\"earlier\": true}\n"; }
    const CliRun r = test::run_cli(args + " --json '" + keep + "'");
    EXPECT_EQ(r.code, 3) << args << "\n" << r.out;
    EXPECT_EQ(test::read_text(keep), "{\"earlier\": true}\n") << args;
  }
  // A refused run leaves no folder it would have written its --json into.
  const CliRun nosuch = test::run_cli("bench --scene nosuch" + quick + " --json '" + (dir / "made" / "here" / "x.json").string() + "'");
  EXPECT_EQ(nosuch.code, 3) << nosuch.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "made"));
  // Nothing of a preset is generated on bad input (box-wall is, by the --lights cases).
  EXPECT_FALSE(std::filesystem::exists(dir / "scenes" / "dragon_lights-10.glb"));
  if (std::filesystem::exists(dir / "scenes"))
    for (const auto& f : std::filesystem::directory_iterator(dir / "scenes")) {
      const std::string name = f.path().filename().string();
      EXPECT_TRUE(name.rfind("atrium", 0) != 0 && name.rfind("complexity", 0) != 0) << name;
    }
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

TEST(BenchOptions, GivenOptionsArePrintedAndRecorded) {
  test::ScratchDir dir("benchoptions");
  const CliRun b = test::run_cli(
      "bench --pipelines plain-raster,bidir-warp -n 1 -w 0 -o bidir-warp.occlusion=ztest "
      "--scene box-wall --resolution 32x18 --scenes-dir '" +
      (dir / "scenes").string() + "' --json '" + (dir / "bench.json").string() + "'");
  ASSERT_EQ(b.code, 0) << b.out;
  EXPECT_NE(b.out.find("options: bidir-warp.occlusion=ztest\n"), std::string::npos) << b.out;
  const json j = json::parse(test::read_text(dir / "bench.json"));
  const json& pipelines = j.at("pipelines");
  ASSERT_EQ(pipelines.size(), 2u);
  // Every option's value, defaults included.
  EXPECT_EQ(pipelines[0].at("options").at("tile"), "64");
  EXPECT_EQ(pipelines[1].at("options").at("occlusion"), "ztest");
  EXPECT_EQ(pipelines[1].at("options").at("max_crack"), "2");

  const CliRun preset = test::run_cli(
      "bench --preset kim-focal --preset-rows 1 --resolution 32x18 -n 1 -w 0 "
      "--pipelines plain-raster,bidir-warp -o bidir-warp.occlusion=ztest "
      "--scenes-dir '" +
      (dir / "scenes").string() + "' --json '" + (dir / "focal.json").string() + "'");
  ASSERT_EQ(preset.code, 0) << preset.out;
  EXPECT_NE(preset.out.find("options: bidir-warp.occlusion=ztest\n"), std::string::npos) << preset.out;
  EXPECT_EQ(json::parse(test::read_text(dir / "focal.json")).at("options").at("bidir-warp").at("occlusion"), "ztest");
}

TEST(BenchEyes, EachPipelinesTimeSplitsIntoItsEyesAndWhatTheyShare) {
  test::ScratchDir dir("bencheyes");
  const CliRun b = test::run_cli("bench --pipelines plain-raster,repro-rt,bidir-warp -n 2 -w 0 --scene box-wall "
                                 "--resolution 64x36 --scenes-dir '" +
                                 (dir / "scenes").string() + "' --json '" + (dir / "bench.json").string() + "'");
  ASSERT_EQ(b.code, 0) << b.out;
  EXPECT_NE(b.out.find("per-eye medians"), std::string::npos) << b.out;
  EXPECT_NE(b.out.find("; both: redirect, left_gbuffer"), std::string::npos) << b.out;
  const json pipelines = json::parse(test::read_text(dir / "bench.json")).at("pipelines");
  ASSERT_EQ(pipelines.size(), 3u);
  for (const json& p : pipelines) {
    SCOPED_TRACE(p.at("name").get<std::string>());
    const json& eyes = p.at("eyes_s");
    // Each repetition's shares add up to its total; with two repetitions the medians are means.
    const double sum = eyes.at("left").at("median").get<double>() + eyes.at("right").at("median").get<double>() +
                       eyes.at("both").at("median").get<double>();
    EXPECT_NEAR(sum, p.at("total_s").at("median").get<double>(), 1e-9);
  }
  // Rendered left eyes: the right eye's share is measured; repro-rt's right eye is its grid and holes.
  for (int i : {0, 1}) {
    const json& p = pipelines[static_cast<size_t>(i)];
    EXPECT_TRUE(p.at("eyes_s").at("shared_stages").empty());
    EXPECT_EQ(p.at("eyes_s").at("both").at("median").get<double>(), 0.0);
    EXPECT_GT(p.at("right_over_left").at("median").get<double>(), 0.0);
  }
  const json& repro = pipelines[1];
  const json& st = repro.at("stages_s");
  const auto right_eye = [&](size_t rep) {
    double sum = 0.0;
    for (const char* s : {"grid_metric", "grid_warp", "source_frustum", "hole_fill"})
      sum += st.at(s).at("samples")[rep].get<double>();
    return sum;
  };
  EXPECT_NEAR(repro.at("eyes_s").at("right").at("min").get<double>(), std::min(right_eye(0), right_eye(1)), 1e-12);
  // Bidirectional warping shares every stage between the eyes: no split.
  const json& bidir = pipelines[2];
  EXPECT_TRUE(bidir.at("right_over_left").is_null());
  EXPECT_EQ(bidir.at("eyes_s").at("left").at("median").get<double>(), 0.0);
  EXPECT_EQ(bidir.at("eyes_s").at("shared_stages").size(), bidir.at("stages_s").size());
}

TEST(BenchOptions, VariantsRunBesideTheirPipelineWithTheirOwnOptions) {
  test::ScratchDir dir("benchvariants");
  const std::string scene =
      " --scene box-wall --resolution 32x18 -n 1 --scenes-dir '" + (dir / "scenes").string() + "'";
  const std::string common = scene + " -w 0";
  const CliRun b = test::run_cli(
      "bench --pipelines plain-raster,bidir-warp,bidir-warp:occlusion=ztest:max_crack=4 "
      "-o bidir-warp.max_crack=3 -o bidir-warp.segment=16 --json '" +
      (dir / "bench.json").string() + "' -w 1" + scene);
  ASSERT_EQ(b.code, 0) << b.out;
  EXPECT_NE(b.out.find("\nbidir-warp:occlusion=ztest:max_crack=4 "), std::string::npos) << b.out;
  // Every progress line names the variant, the warm-up's too.
  EXPECT_NE(b.out.find("warm-up 1/1 bidir-warp:occlusion=ztest:max_crack=4\n"), std::string::npos) << b.out;
  const json pipelines = json::parse(test::read_text(dir / "bench.json")).at("pipelines");
  ASSERT_EQ(pipelines.size(), 3u);
  EXPECT_EQ(pipelines[1].at("name"), "bidir-warp");
  EXPECT_EQ(pipelines[1].at("options").at("occlusion"), "none");
  EXPECT_EQ(pipelines[1].at("options").at("max_crack"), "3");
  EXPECT_EQ(pipelines[2].at("name"), "bidir-warp:occlusion=ztest:max_crack=4");
  EXPECT_EQ(pipelines[2].at("options").at("occlusion"), "ztest");
  EXPECT_EQ(pipelines[2].at("options").at("max_crack"), "4");  // the variant's own value wins
  EXPECT_EQ(pipelines[2].at("options").at("segment"), "16");   // the pipeline's given options apply too
  EXPECT_TRUE(pipelines[2].at("stages_s").contains("ztest"));
  EXPECT_FALSE(pipelines[1].at("stages_s").contains("ztest"));

  // Bad entries, and given options (checked with the entries that use them, and needing one).
  const std::string variant = "--pipelines plain-raster,bidir-warp:max_crack=4 -o ";
  for (const auto& [args, says] : std::vector<std::pair<std::string, std::string>>{
           {"--pipelines plain-raster,bidir-warp:occlusion",
            "pipeline entry 'bidir-warp:occlusion': 'occlusion' is not KEY=VALUE"},
           {"--pipelines plain-raster,bidir-warp:occlusions=ztest",
            "pipeline entry 'bidir-warp:occlusions=ztest': pipeline 'bidir-warp' has no option 'occlusions'"},
           {"--pipelines plain-raster,bidir-warp:occlusion=zbuf", "option occlusion=zbuf is not one of none, ztest"},
           {"--pipelines plain-raster,bidir-warp:=ztest", "'=ztest' is not KEY=VALUE"},
           {"--pipelines plain-raster,bidirr:occlusion=ztest", "unknown pipeline 'bidirr'"},
           {"--pipelines plain-raster,bidir-warp:occlusion=ztest,bidir-warp:occlusion=ztest",
            "names 'bidir-warp:occlusion=ztest' twice"},
           {variant + "bidir-warp.occlusions=ztest", "has no option 'occlusions'"},
           {variant + "bidir-warp.occlusion=zbuf", "option occlusion=zbuf is not one of none, ztest"},
           {variant + "fw-warp.max_crack=3", "options given for pipeline 'fw-warp', which is not benchmarked"}}) {
    const CliRun bad = test::run_cli("bench " + args + common);
    EXPECT_EQ(bad.code, 3) << args << "\n" << bad.out;
    EXPECT_NE(bad.out.find(says), std::string::npos) << args << "\n" << bad.out;
  }
}

// ---- Kim's presets ----

TEST(BenchPresetKim, AnSsimBelowItsWindowIsPrintedAsUndefined) {
  // 8x8 is below SSIM's 11x11 window: the table says so, as compare does (it printed "nan").
  test::ScratchDir dir("kimsmall");
  const CliRun r = test::run_cli("bench --preset kim-focal --preset-rows 1 --resolution 8x8 --pipelines "
                                 "plain-raster,bidir-warp -n 1 -w 0 --scenes-dir '" + (dir / "scenes").string() + "'");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("undefined/"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("nan"), std::string::npos) << r.out;
}

TEST(BenchPreset, ARigARowRefusesIsNamedBeforeTheSeriesTable) {
  test::ScratchDir dir("refusedrig");
  // rt-buffer's buffer depth beyond its bound at 600x600: refused before the series' table header
  // (an empty header was printed above the error).
  const CliRun r = test::run_cli("bench --preset al-hagri-lights --preset-rows 1 -n 1 -w 0 -p rt-buffer -o "
                                 "rt-buffer.depth=4096 --scenes-dir '" + (dir / "scenes").string() + "'");
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find("(no row of the series has run)"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("rt-buffer ms"), std::string::npos) << "a table header before the refusal:\n" << r.out;
}

TEST(BenchPresetKim, FramesThatCannotFitAreRefusedBeforeAnyRowRendersOrTheEarlierJsonGoes) {
  test::ScratchDir dir("kimframes");
  // Under an 8 GB address-space limit a 8192x8192 row (about 20 GiB of frames) cannot fit. The
  // complexity preset's row estimate comes from the triangle count alone, and the focal preset
  // rendered its quality images before any check: both ran into the allocation.
  for (const char* preset : {"kim-complexity", "kim-focal"}) {
    SCOPED_TRACE(preset);
    const std::filesystem::path earlier = dir / (std::string(preset) + ".json");
    std::ofstream(earlier) << "an earlier run's\n";
    const CliRun r = test::run_shell("ulimit -v 8000000; " + std::string(SB_CLI_PATH) + " bench --preset " + preset +
                                     " -r 8192x8192 --preset-rows 1 -n 1 -w 0 --scenes-dir '" +
                                     (dir / "scenes").string() + "' --json '" + earlier.string() + "'");
    EXPECT_EQ(r.code, 4) << r.out;
    EXPECT_NE(r.out.find("benchmark at 8192x8192 needs about 20.00 GiB of memory"), std::string::npos) << r.out;
    EXPECT_EQ(test::read_text(earlier), "an earlier run's\n") << "a refused run keeps the earlier file";
  }
}

TEST(BenchPresetKim, ARowARigRefusesStopsTheSeriesBeforeItsFirstRow) {
  test::ScratchDir dir("kimdeep");
  // A later row's rig that a pipeline refuses (at this field of view the second distance needs a
  // buffer deeper than rt-buffer's bound) stops the series before its first row runs: it stopped
  // after the first, whose table was never printed.
  const CliRun deep = test::run_cli("bench --preset kim-focal --preset-rows 2 --resolution 8x8 --vfov 0.00458 "
                                    "--pipelines plain-raster,rt-buffer -n 1 -w 0 --scenes-dir '" +
                                    (dir / "scenes").string() + "' --json '" + (dir / "deep.json").string() + "'");
  EXPECT_EQ(deep.code, 3) << deep.out;
  EXPECT_NE(deep.out.find("atrium by focal distance, row DF mm = 2000: rt-buffer: the default depth"),
            std::string::npos)
      << deep.out;
  EXPECT_NE(deep.out.find("(no row of the series has run)"), std::string::npos) << deep.out;
  EXPECT_EQ(deep.out.find("DF mm = 6000:"), std::string::npos) << "the first row ran: " << deep.out;
}

TEST(BenchPresetKim, FocalComparesEveryMethodWithPlainRasterAtThreeDistances) {
  test::ScratchDir dir("kimfocal");
  const CliRun r = test::run_cli("bench --preset kim-focal --resolution 160x90 --repetitions 1 --warmup 0 --scenes-dir '" +
                                 (dir / "scenes").string() + "' --json '" + (dir / "focal.json").string() + "'");
  ASSERT_EQ(r.code, 0) << r.out;
  for (const char* part :
       {"atrium by focal distance", "Kim, Table 2", "DF mm", "6000", "2000", "300", "bidir-warp",
        "bidir-warp:occlusion=ztest", "bw-warp", "fw-warp", "bidir-warp-rt", "plain-raster ms", "speed-up", "160x90"})
    EXPECT_NE(r.out.find(part), std::string::npos) << part << "\n" << r.out;

  // The summary speaks of Kim's 960x540; the run says what it replaced.
  EXPECT_NE(r.out.find("as run, replacing the preset's: image size 160x90\n"), std::string::npos) << r.out;

  const json j = json::parse(test::read_text(dir / "focal.json"));
  EXPECT_TRUE(j.at("complete").get<bool>());
  EXPECT_EQ(j.at("overrides"), "image size 160x90");
  EXPECT_EQ(j.at("reference"), "plain-raster");
  EXPECT_EQ(j.at("baseline"), "plain-raster");
  const json& rows = j.at("rows");
  ASSERT_EQ(rows.size(), 3u);
  const double distances[] = {6.0, 2.0, 0.3};
  for (size_t i = 0; i < 3; ++i) {
    const json& row = rows[i];
    SCOPED_TRACE(row.at("value").get<std::string>());
    EXPECT_EQ(row.at("scene").at("name"), "atrium");
    EXPECT_NEAR(row.at("rig").at("convergence_m").get<double>(), distances[i], 1e-12);
    EXPECT_NEAR(row.at("rig").at("interaxial_m").get<double>(), 0.064, 1e-12);
    EXPECT_EQ(row.at("rig").at("width").get<int>(), 160);
    EXPECT_EQ(row.at("rig").at("height").get<int>(), 90);
    for (const char* p : {"bidir-warp", "bidir-warp:occlusion=ztest", "bw-warp", "fw-warp", "bidir-warp-rt"}) {
      const json& q = row.at("quality").at(p);
      const double ssim = q.at("ssim").get<double>();
      EXPECT_GT(ssim, 0.0) << p;
      EXPECT_LE(ssim, 1.0) << p;
      // Every method reprojects some pixels wrongly at 160x90: PSNR is finite (a number, not "inf").
      EXPECT_GT(q.at("psnr").get<double>(), 0.0) << p;
      EXPECT_GT(row.at("median_total_ms").at(p).get<double>(), 0.0) << p;
      EXPECT_GT(row.at("speedup_median").at(p).get<double>(), 0.0) << p;
    }
    EXPECT_FALSE(row.at("quality").contains("plain-raster"));  // the reference itself is not a method
    EXPECT_GT(row.at("median_total_ms").at("plain-raster").get<double>(), 0.0);
    EXPECT_EQ(row.at("speedup_median").at("plain-raster").get<double>(), 1.0);
  }
  // Kim's finding at the nearest focal distance (300 mm): bidirectional warping keeps the quality
  // that single-view backward and forward warping lose. Measured at 160x90: SSIM 0.908 against
  // 0.769 (bw-warp) and 0.778 (fw-warp); Kim reports 0.995 against 0.779 and 0.781.
  const json& near = rows[2].at("quality");
  EXPECT_GT(near.at("bidir-warp").at("ssim").get<double>(), near.at("bw-warp").at("ssim").get<double>());
  EXPECT_GT(near.at("bidir-warp").at("ssim").get<double>(), near.at("fw-warp").at("ssim").get<double>());
  // With the z-test (measured at 160x90: 0.9888, 0.9888, 0.9878) it is ahead at every distance.
  for (const json& row : rows) {
    const json& q = row.at("quality");
    const double ztest = q.at("bidir-warp:occlusion=ztest").at("ssim").get<double>();
    for (const char* p : {"bidir-warp", "bw-warp", "fw-warp"}) EXPECT_GT(ztest, q.at(p).at("ssim").get<double>()) << p;
  }
}

TEST(BenchPresetKim, ComplexityFirstRowSplitsRenderingAndWarping) {
  test::ScratchDir dir("kimcomplexity");
  const CliRun r = test::run_cli("bench --preset kim-complexity --preset-rows 1 --resolution 160x90 --repetitions 1 "
                                 "--warmup 0 --scenes-dir '" + (dir / "scenes").string() + "' --json '" +
                                 (dir / "complexity.json").string() + "'");
  ASSERT_EQ(r.code, 0) << r.out;
  for (const char* part : {"complexity by triangle count", "rendering ms", "warping ms", "peak MiB", "1e5 (",
                           "plain-raster", "bidir-warp", "crossover:", "of the memory left"})
    EXPECT_NE(r.out.find(part), std::string::npos) << part << "\n" << r.out;
  EXPECT_EQ(r.out.find("\n1e6 ("), std::string::npos) << r.out;  // --preset-rows 1: the 1e5 row only

  const json j = json::parse(test::read_text(dir / "complexity.json"));
  EXPECT_TRUE(j.at("complete").get<bool>());
  ASSERT_EQ(j.at("rows").size(), 1u);
  const json& row = j.at("rows")[0];
  EXPECT_FALSE(row.at("skipped").get<bool>());
  // The generator meets N within 1 % (scenes/complexity.cpp).
  EXPECT_NEAR(row.at("scene").at("triangles").get<double>(), 1e5, 1e3);
  EXPECT_EQ(row.at("rig").at("width").get<int>(), 160);
  EXPECT_NEAR(row.at("rig").at("interaxial_m").get<double>(), 0.064, 1e-12);
  EXPECT_GT(row.at("memory").at("peak_bytes").get<double>(), 0.0);
  const json& groups = row.at("stage_groups");
  // Table 3's four methods by default: 2-Pass, Ours, BW and FW.
  for (const char* p : {"plain-raster", "bidir-warp", "bw-warp", "fw-warp"}) {
    SCOPED_TRACE(p);
    const json& g = groups.at(p);
    EXPECT_GT(g.at("rendering_ms").get<double>(), 0.0);
    EXPECT_EQ(g.at("other_ms").get<double>(), 0.0);
    EXPECT_TRUE(g.at("other_stages").empty());
    // One repetition: the medians are that repetition's sums, which add up to its total.
    EXPECT_NEAR(g.at("rendering_ms").get<double>() + g.at("warping_ms").get<double>(), g.at("total_ms").get<double>(),
                1e-9 * g.at("total_ms").get<double>());
  }
  EXPECT_EQ(groups.at("plain-raster").at("warping_ms").get<double>(), 0.0);  // 2-pass: no warp stage
  for (const char* p : {"bidir-warp", "bw-warp", "fw-warp"}) EXPECT_GT(groups.at(p).at("warping_ms").get<double>(), 0.0) << p;
  // The crossover follows the row's speed-up, as printed.
  const bool faster = cli::speedup_above_one(j.at("rows").at(0).at("speedup_median").at("bidir-warp").get<double>());
  const json& cross = j.at("crossover");
  if (faster) {
    EXPECT_EQ(cross.at("value"), "1e5");
    EXPECT_NE(r.out.find("from 1e5 triangles on"), std::string::npos) << r.out;
  } else {
    EXPECT_TRUE(cross.at("value").is_null());
    EXPECT_NE(r.out.find("none in the measured range (1e5)"), std::string::npos) << r.out;
  }
}

TEST(BenchPresetKim, TheCrossoverIsOverPlainRasterWhateverTheBaseline) {
  // End to end under another --baseline: the crossover agrees with plain-raster's and bidir-warp's
  // own samples, and the line says the table's column is over that baseline. Whether bidir-warp is
  // faster here depends on the machine, so the computation itself is pinned by
  // SpeedupBetweenTwoPipelinesIgnoresTheRowsBaseline below.
  test::ScratchDir dir("kimcross");
  const CliRun r = test::run_cli("bench --preset kim-complexity --preset-rows 1 --resolution 64x36 --repetitions 3 "
                                 "--warmup 0 --pipelines plain-raster,bidir-warp --baseline bidir-warp --scenes-dir '" +
                                 (dir / "scenes").string() + "' --json '" + (dir / "c.json").string() + "'");
  ASSERT_EQ(r.code, 0) << r.out;
  const json j = json::parse(test::read_text(dir / "c.json"));
  std::map<std::string, std::vector<double>> samples;
  for (const json& p : j.at("rows")[0].at("bench").at("pipelines"))
    samples[p.at("name").get<std::string>()] = p.at("total_samples_s").get<std::vector<double>>();
  std::vector<double> ratios;
  for (size_t k = 0; k < 3; ++k) ratios.push_back(samples.at("plain-raster")[k] / samples.at("bidir-warp")[k]);
  std::sort(ratios.begin(), ratios.end());
  const bool faster = cli::speedup_above_one(ratios[1]);
  EXPECT_EQ(j.at("crossover").at("value").is_null(), !faster) << j.at("crossover").dump();
  EXPECT_NE(r.out.find("the table's speed-ups are over --baseline bidir-warp"), std::string::npos) << r.out;
}

TEST(BenchPresetKim, SpeedupBetweenTwoPipelinesIgnoresTheRowsBaseline) {
  // A row timed against rt-adelson: bidir-warp's speed-up over plain-raster comes from their own
  // samples, paired per repetition (the crossover took the row's speed-up over the baseline).
  BenchResult row;
  row.baseline = "rt-adelson";
  const auto add = [&](const char* name, std::vector<double> totals, double speedup) {
    PipelineBench b;
    b.name = name;
    b.total_seconds = std::move(totals);
    b.speedup.median = speedup;
    row.pipelines.push_back(b);
  };
  add("rt-adelson", {0.9, 1.0, 1.1}, 1.0);
  add("plain-raster", {0.2, 0.3, 0.2}, 4.0);
  add("bidir-warp", {0.25, 0.2, 0.4}, 3.0);
  // Ratios 0.8, 1.5, 0.5: median 0.8, below 1, although the row's figure for bidir-warp is 3.
  EXPECT_DOUBLE_EQ(cli::speedup_between(row, "plain-raster", "bidir-warp"), 0.8);
  EXPECT_DOUBLE_EQ(cli::speedup_between(row, "bidir-warp", "plain-raster"), 1.25);
}

TEST(BenchPresetKim, PeakEstimateExtrapolatesFromTheLargestMeasuredRows) {
  const uint64_t base = 100;
  // No row measured: the prior.
  EXPECT_EQ(cli::estimate_peak_bytes({}, base, 1e5, 1000.0, 2.0), 100u + 1000u + 200000u);
  // One row: proportional to its share above the base (here 10 bytes per triangle).
  EXPECT_EQ(cli::estimate_peak_bytes({{1e3, 10100}}, base, 1e4, 1000.0, 2.0), 100u + 100000u);
  // Two or more rows (any order): the line through the two largest, 5 bytes per triangle from 1e4.
  EXPECT_EQ(cli::estimate_peak_bytes({{1e4, 60100}, {1e2, 5000}, {1e3, 15100}}, base, 1e5, 0.0, 0.0),
            60100u + 5u * 90000u);
  // A flat or falling line is held at a tenth of the proportional rate (noise must not make a
  // larger row look free): (60100 - 100) / 1e4 / 10 = 0.6 bytes per triangle.
  EXPECT_EQ(cli::estimate_peak_bytes({{1e3, 70000}, {1e4, 60100}}, base, 1e5, 0.0, 0.0), 60100u + 54000u);
  // Never below the base.
  EXPECT_EQ(cli::estimate_peak_bytes({{1e3, 50}}, base, 1e4, 0.0, 0.0), base);
}

TEST(BenchPresetKim, CrossoverIsWhereTheMethodStaysFaster) {
  // By the paired speed-up the table prints (the median totals could say otherwise).
  EXPECT_EQ(cli::crossover_row({0.8, 1.05, 1.2}), std::optional<size_t>(1));
  EXPECT_EQ(cli::crossover_row({1.1, 1.05, 1.2}), std::optional<size_t>(0));
  EXPECT_EQ(cli::crossover_row({1.1, 0.95, 1.2}), std::optional<size_t>(2));  // must stay faster
  EXPECT_EQ(cli::crossover_row({1.1, 1.05, 1.0}), std::nullopt);  // equal is not faster
  EXPECT_EQ(cli::crossover_row({1.1, 1.004}), std::nullopt);  // nor is what the table prints as 1.00x
  EXPECT_EQ(cli::crossover_row({}), std::nullopt);
}

TEST(BenchPresetKim, StagesGroupAsRenderingOrWarping) {
  using cli::StageGroup;
  // The stages plain-raster, bidir-warp, bidir-warp-rt, fw-warp and bw-warp report.
  for (const char* s :
       {"redirect", "ztest", "left_gbuffer", "left_shading", "right_gbuffer", "right_shading", "left_trace"})
    EXPECT_EQ(cli::stage_group(s), StageGroup::rendering) << s;
  for (const char* s : {"motion", "warp", "crack_fill", "background", "hole_fill", "warp_depth", "warp_color",
                        "backward_warp"})
    EXPECT_EQ(cli::stage_group(s), StageGroup::warping) << s;
  for (const char* s : {"allocate", "scanlines", "shading"}) EXPECT_EQ(cli::stage_group(s), StageGroup::other) << s;
}

}  // namespace
}  // namespace sb
