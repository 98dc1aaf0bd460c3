// `stereobench validate`: records, images and the terminal table for a plain and a reprojecting
// pipeline against the built-in ground truth; bad input and a missing provider tool.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/io/image_io.hpp"
#include "support/run_cli.hpp"
#include "support/scratch_dir.hpp"

namespace sb {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// The common arguments; the truth cache in the scratch folder unless `cache` names another.
std::string base_args(const test::ScratchDir& dir, const std::string& cache = "") {
  return "validate --scene box-wall --resolution 160x90 --threads 2 --scenes-dir '" +
         (fs::path(SB_BINARY_DIR) / "Testing" / "scenes-cache").string() + "' --out '" + (dir / "out").string() +
         "' --cache " + (cache.empty() ? test::quoted(dir / "cache") : cache);
}

/// The work folder of `stem` (scene and provider) in `out`: `work/<stem>_<12 hex digits of the truth
/// key>`; empty unless there is exactly one.
fs::path work_folder(const fs::path& out, const std::string& stem) {
  std::vector<fs::path> found;
  if (fs::is_directory(out / "work"))
    for (const auto& entry : fs::directory_iterator(out / "work")) {
      const std::string name = entry.path().filename().string();
      if (name.size() == stem.size() + 13 && name.rfind(stem + "_", 0) == 0) found.push_back(entry.path());
    }
  return found.size() == 1 ? found.front() : fs::path();
}

TEST(Validate, WritesRecordsImagesAndTable) {
  test::ScratchDir dir;
  const test::CliRun r = test::run_cli(base_args(dir) + " --pipelines plain-rt,repro-rt --pipelines fw-warp");
  ASSERT_EQ(r.code, 0) << r.out;
  for (const char* p : {"plain-rt", "repro-rt", "fw-warp"}) EXPECT_NE(r.out.find(p), std::string::npos) << r.out;
  const fs::path out = dir / "out";
  const json plain = json::parse(test::read_text(out / "box-wall_full_plain-rt.json"));
  EXPECT_EQ(plain["kind"], "stereobench.validation");
  EXPECT_EQ(plain["truth"]["provider"], "full");
  EXPECT_EQ(plain["metrics"]["psnr"], "inf") << "plain-rt's right eye is the built-in ground truth";
  EXPECT_EQ(plain["metrics"]["ssim"], 1.0);
  EXPECT_EQ(plain["regions"]["reprojected"]["pixels"], 0);
  EXPECT_TRUE(plain["regions"]["reprojected"]["psnr"].is_null());

  const json repro = json::parse(test::read_text(out / "box-wall_full_repro-rt.json"));
  EXPECT_GT(repro["regions"]["reprojected"]["pixels"].get<int>(), 10000);  // 14254 of 14400 measured
  EXPECT_GT(repro["holes"]["true_disocclusions"]["pixels"].get<int>(), 0);
  EXPECT_GT(repro["holes"]["not_reprojected"]["recall"].get<double>(), 0.9);  // measured 1.0
  EXPECT_EQ(repro["regions"]["true_disocclusions"]["pixels"], repro["holes"]["true_disocclusions"]["pixels"]);
  EXPECT_GT(repro["total_s"].get<double>(), 0.0);
  EXPECT_FALSE(repro["metrics_version"].get<std::string>().empty());
  for (const auto& [name, path] : repro["images"].items()) EXPECT_TRUE(fs::exists(path.get<std::string>())) << name;
  const json summary = json::parse(test::read_text(out / "box-wall_full_summary.json"));
  EXPECT_EQ(summary["records"].size(), 3u);

  // The hole overlay draws the mask the recall and precision beside it score: found (green) the
  // true positives, missed (red) the rest of the true disocclusions, flagged in vain (blue) the
  // rest of the pixels not reprojected. Tinted pixels have a channel of at least 0.75 (sRGB 225),
  // the others none above 0.3 (sRGB 149).
  for (const char* p : {"plain-rt", "repro-rt", "fw-warp"}) {
    const json record = json::parse(test::read_text(out / (std::string("box-wall_full_") + p + ".json")));
    const json& scored = record["holes"]["not_reprojected"];
    const io::DecodedImage overlay = io::read_image(record["images"]["holes_png"].get<std::string>());
    ASSERT_EQ(overlay.channels, 3) << p;
    size_t found = 0, missed = 0, wasted = 0;
    for (size_t i = 0; i < overlay.values.size(); i += 3) {
      const float red = overlay.values[i], green = overlay.values[i + 1], blue = overlay.values[i + 2];
      if (std::max({red, green, blue}) < 200.0f / 255.0f) continue;
      (red > green && red > blue ? missed : green > blue ? found : wasted) += 1;
    }
    const auto tp = scored["true_positives"].get<size_t>();
    EXPECT_EQ(found, tp) << p;
    EXPECT_EQ(missed, record["holes"]["true_disocclusions"]["pixels"].get<size_t>() - tp) << p;
    EXPECT_EQ(wasted, scored["pixels"].get<size_t>() - tp) << p;
  }
}

TEST(Validate, ExternalTruthIsRenderedOnceThenCached) {
  test::ScratchDir dir;
  const std::string args = base_args(dir) + " --truth povray --pipelines plain-rt,repro-rt";
  const test::CliRun first = test::run_cli(args);
  ASSERT_EQ(first.code, 0) << first.out << "\n(POV-Ray is installed by ci/install-deps.sh povray)";
  EXPECT_EQ(first.out.find("from the cache"), std::string::npos) << first.out;
  const test::CliRun second = test::run_cli(args);
  ASSERT_EQ(second.code, 0) << second.out;
  EXPECT_NE(second.out.find("from the cache"), std::string::npos) << second.out;
  const json record = json::parse(test::read_text(dir / "out" / "box-wall_povray_plain-rt.json"));
  EXPECT_EQ(record["truth"]["provider"], "povray");
  EXPECT_TRUE(record["truth"]["cached"].get<bool>());
  EXPECT_EQ(record["truth"]["cache_key"].get<std::string>().size(), 64u);
  EXPECT_NE(record["truth"]["tool_version"].get<std::string>().find("POV-Ray 3.7"), std::string::npos);
  // Our ray tracer against POV-Ray on an untextured scene: the providers agree (three-way test).
  EXPECT_NE(record["metrics"]["psnr"], "inf");
  EXPECT_GE(record["metrics"]["psnr"].get<double>(), 45.0);

  // Served from the cache into another --out, the record's command renders the truth again in
  // that --out's work folder, made ready there; it named the first run's folder, whose files a
  // later run may replace.
  const fs::path other = dir / "other";
  const test::CliRun third = test::run_cli(
      "validate --scene box-wall --resolution 160x90 --threads 2 --scenes-dir " +
      test::quoted(fs::path(SB_BINARY_DIR) / "Testing" / "scenes-cache") + " --out " + test::quoted(other) +
      " --cache " + test::quoted(dir / "cache") + " --truth povray --pipelines plain-rt");
  ASSERT_EQ(third.code, 0) << third.out;
  EXPECT_NE(third.out.find("from the cache"), std::string::npos) << third.out;
  const json served = json::parse(test::read_text(other / "box-wall_povray_plain-rt.json"));
  const fs::path work = work_folder(other, "box-wall_povray");
  ASSERT_FALSE(work.empty());
  const std::string command = served["truth"]["command"].get<std::string>();
  EXPECT_NE(command.find(work.string()), std::string::npos) << command;
  EXPECT_EQ(command.find((dir / "out").string()), std::string::npos) << command;
  EXPECT_TRUE(fs::is_regular_file(work / "scene.pov"));
  EXPECT_FALSE(fs::exists(work / "right.exr")) << "made ready, not rendered";
  // Run as recorded, it renders the cached image again.
  ASSERT_EQ(test::run_shell(command).code, 0) << command;
  const Image again = io::read_exr(work / "right.exr");
  const Image cached = io::read_exr(other / "box-wall_truth-povray.exr");
  ASSERT_TRUE(again.has_plane(planes::rgb) && cached.has_plane(planes::rgb));
  const auto a = again.plane(planes::rgb).f32(), b = cached.plane(planes::rgb).f32();
  EXPECT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end())) << "the command renders another image";
}

TEST(Validate, EmptyCacheFolderTurnsTheCacheOff) {
  test::ScratchDir dir;
  // Run from the scratch folder: an empty --cache taken as a folder name would cache there.
  const std::string args = "cd " + test::quoted(dir.path()) + " && " + SB_CLI_PATH + " " + base_args(dir, "''") +
                           " --truth povray --pipelines plain-rt";
  for (int run = 0; run < 2; ++run) {
    const test::CliRun r = test::run_shell(args);
    ASSERT_EQ(r.code, 0) << r.out << "\n(POV-Ray is installed by ci/install-deps.sh povray)";
    EXPECT_EQ(r.out.find("from the cache"), std::string::npos) << "run " << run << ":\n" << r.out;
  }
  const json record = json::parse(test::read_text(dir / "out" / "box-wall_povray_plain-rt.json"));
  EXPECT_FALSE(record["truth"]["cached"].get<bool>());
  for (const auto& entry : fs::directory_iterator(dir.path()))
    EXPECT_EQ(entry.path().filename(), "out") << "left behind: " << entry.path();
  // Another scene into the same --out renders in a work folder of its own: the first record's
  // command, which renders its truth again, still finds its own scene there.
  std::string other = args;
  other.replace(other.find("--scene box-wall"), std::string("--scene box-wall").size(), "--scene thin-pole");
  ASSERT_EQ(test::run_shell(other).code, 0);
  const std::string command = record["truth"]["command"].get<std::string>();
  const fs::path work = work_folder(dir / "out", "box-wall_povray");
  ASSERT_FALSE(work.empty());
  EXPECT_NE(command.find(work.string()), std::string::npos) << command;
  EXPECT_FALSE(work_folder(dir / "out", "thin-pole_povray").empty());
}

TEST(Validate, EachRigRendersItsTruthInAWorkFolderOfItsOwn) {
  test::ScratchDir dir;
  const std::string args = base_args(dir) + " --truth povray --no-cache --pipelines plain-rt";
  ASSERT_EQ(test::run_cli(args).code, 0) << "(POV-Ray is installed by ci/install-deps.sh povray)";
  const fs::path out = dir / "out";
  const json record = json::parse(test::read_text(out / "box-wall_povray_plain-rt.json"));
  const std::string command = record["truth"]["command"].get<std::string>();
  const fs::path first = work_folder(out, "box-wall_povray");
  ASSERT_FALSE(first.empty());
  fs::remove(first / "right.exr");

  // Another rig whose truth fails to render (POV-Ray stopped at once) leaves the first run's records,
  // and its work folder, whose command renders the truth those records describe.
  std::string other = args;
  other.replace(other.find("160x90"), 6, "200x100");
  const test::CliRun failed = test::run_shell("STEREOBENCH_TOOL_TIMEOUT=0.001 " + std::string(SB_CLI_PATH) + " " + other);
  ASSERT_EQ(failed.code, 4) << failed.out;
  ASSERT_EQ(test::run_shell(command).code, 0) << command;
  const Image again = io::read_exr(first / "right.exr");
  EXPECT_EQ(again.width(), 160);
  const Image truth = io::read_exr(out / "box-wall_truth-povray.exr");
  ASSERT_TRUE(again.has_plane(planes::rgb) && truth.has_plane(planes::rgb));
  const auto a = again.plane(planes::rgb).f32(), b = truth.plane(planes::rgb).f32();
  EXPECT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end())) << "the command renders another image";

  // Once a run with another rig replaces the records, the first work folder, which no record names
  // any more, is removed; one no earlier record named (another run's, rendering meanwhile) is left.
  const fs::path others = out / "work" / "box-wall_povray_0123456789ab";
  fs::create_directories(others);
  const test::CliRun replaced = test::run_cli(other);
  ASSERT_EQ(replaced.code, 0) << replaced.out;
  EXPECT_FALSE(fs::exists(first));
  EXPECT_TRUE(fs::exists(others));
  fs::remove(others);
  const fs::path second = work_folder(out, "box-wall_povray");
  ASSERT_FALSE(second.empty());
  EXPECT_NE(json::parse(test::read_text(out / "box-wall_povray_plain-rt.json"))["truth"]["command"].get<std::string>().find(
                second.string()),
            std::string::npos);
}

TEST(Validate, PipelineOptionsApplyAndAreChecked) {
  test::ScratchDir dir;
  const test::CliRun worse = test::run_cli(base_args(dir) + " --pipelines repro-rt --option discontinuity_px=1000000");
  ASSERT_EQ(worse.code, 0) << worse.out;
  const json record = json::parse(test::read_text(dir / "out" / "box-wall_full_repro-rt.json"));
  EXPECT_EQ(record["options"]["discontinuity_px"], "1000000");
  // Without disocclusion detection the hole mask misses most true disocclusions.
  EXPECT_LT(record["holes"]["not_reprojected"]["recall"].get<double>(), 0.9);  // measured 0.773 (1.0 with defaults)
  const test::CliRun undeclared = test::run_cli(base_args(dir) + " --pipelines plain-rt --option discontinuity_px=1");
  EXPECT_EQ(undeclared.code, 3) << undeclared.out;
  EXPECT_NE(undeclared.out.find("discontinuity_px"), std::string::npos) << undeclared.out;
}

TEST(Validate, ALeftEyeSynthesizedInPartIsMeasuredAgainstPlainRtsLeftEye) {
  test::ScratchDir dir;
  const test::CliRun r = test::run_cli(base_args(dir) + " --pipelines plain-raster,repro-rt,bidir-warp,bidir-warp-rt");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("left eyes synthesized in part, against plain-rt's left eye:"), std::string::npos) << r.out;
  const fs::path out = dir / "out";
  // Left eyes the pipelines render themselves are not measured.
  for (const char* own : {"plain-raster", "repro-rt"})
    EXPECT_TRUE(json::parse(test::read_text(out / ("box-wall_full_" + std::string(own) + ".json")))["left_eye"].is_null())
        << own;
  // bidir-warp-rt traces its holes: a left eye closer to plain-rt's than bidir-warp's.
  const json traced = json::parse(test::read_text(out / "box-wall_full_bidir-warp-rt.json"))["left_eye"];
  ASSERT_TRUE(traced.is_object()) << traced;
  const json bidir = json::parse(test::read_text(out / "box-wall_full_bidir-warp.json"))["left_eye"];
  ASSERT_TRUE(bidir.is_object()) << bidir;
  EXPECT_LE(traced["metrics"]["mse"].get<double>(), bidir["metrics"]["mse"].get<double>());
  ASSERT_TRUE(bidir.is_object()) << bidir;
  EXPECT_EQ(bidir["reference"], "plain-rt");
  EXPECT_GT(bidir["synthesized_pixels"].get<uint64_t>(), 0u);
  EXPECT_LT(bidir["synthesized_pixels"].get<uint64_t>(), 160u * 90u);
  // The holes bidir-warp-rt traces from the left eye are rendered, not synthesized (they were
  // counted, and the table said "not rendered by the left eye").
  EXPECT_LT(traced["synthesized_pixels"].get<uint64_t>(), bidir["synthesized_pixels"].get<uint64_t>());
  // The same numbers as comparing the two left eyes of the renders' EXRs by hand.
  const std::string common = " --scene box-wall --resolution 160x90 --stereo none --out '" + (dir / "eyes").string() +
                             "' --scenes-dir '" + (fs::path(SB_BINARY_DIR) / "Testing" / "scenes-cache").string() + "'";
  ASSERT_EQ(test::run_cli("render --pipeline bidir-warp" + common).code, 0);
  ASSERT_EQ(test::run_cli("render --pipeline plain-rt" + common).code, 0);
  const test::CliRun c = test::run_cli("compare --eye left " + test::quoted(dir / "eyes" / "box-wall_bidir-warp.exr") +
                                       " " + test::quoted(dir / "eyes" / "box-wall_plain-rt.exr") + " --json " +
                                       test::quoted(dir / "compare.json"));
  ASSERT_LE(c.code, 2) << c.out;
  const json by_hand = json::parse(test::read_text(dir / "compare.json"));
  EXPECT_NEAR(bidir["metrics"]["mse"].get<double>(), by_hand["metrics"]["mse"].get<double>(), 1e-9) << by_hand;
  EXPECT_NEAR(bidir["metrics"]["ssim"].get<double>(), by_hand["metrics"]["ssim"].get<double>(), 1e-9) << by_hand;
  // Its own left eye and that eye's difference image are written beside the right eye's; a
  // pipeline that renders its left eye whole has neither.
  const json images = json::parse(test::read_text(out / "box-wall_full_bidir-warp.json"))["images"];
  EXPECT_EQ(images["left_png"], (out / "box-wall_full_bidir-warp_left.png").string());
  EXPECT_EQ(images["left_diff_png"], (out / "box-wall_full_bidir-warp_left_diff.png").string());
  for (const char* key : {"left_png", "left_diff_png"}) EXPECT_TRUE(fs::exists(images[key].get<std::string>())) << key;
  // The left eye written is the render's own left eye (identical pixels), and its difference map is
  // the left eye's, not the right eye's.
  const auto psnr_of = [&](const std::string& a, const std::string& b, const char* name) {
    const fs::path report = dir / (std::string(name) + ".json");
    const test::CliRun run = test::run_cli("compare " + test::quoted(a) + " " + test::quoted(b) + " --json " + test::quoted(report));
    EXPECT_LE(run.code, 2) << run.out;
    return json::parse(test::read_text(report))["metrics"]["psnr"];
  };
  EXPECT_EQ(psnr_of(images["left_png"], (dir / "eyes" / "box-wall_bidir-warp_left.png").string(), "left"), "inf");
  EXPECT_NE(psnr_of(images["left_diff_png"], images["diff_png"], "diffs"), "inf");
  EXPECT_FALSE(json::parse(test::read_text(out / "box-wall_full_repro-rt.json"))["images"].contains("left_png"));
  EXPECT_FALSE(fs::exists(out / "box-wall_full_repro-rt_left.png"));
}

TEST(Validate, VariantsAreMeasuredBesideTheirPipelineUnderTheirOwnName) {
  test::ScratchDir dir;
  const test::CliRun r =
      test::run_cli(base_args(dir) + " --pipelines bidir-warp,bidir-warp:occlusion=ztest --option max_crack=3");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("\nbidir-warp:occlusion=ztest "), std::string::npos) << r.out;
  const fs::path out = dir / "out";
  const json plain = json::parse(test::read_text(out / "box-wall_full_bidir-warp.json"));
  const json ztest = json::parse(test::read_text(out / "box-wall_full_bidir-warp@occlusion=ztest.json"));
  EXPECT_EQ(plain["pipeline"], "bidir-warp");
  EXPECT_EQ(ztest["pipeline"], "bidir-warp:occlusion=ztest");
  EXPECT_EQ(plain["options"]["occlusion"], "none");
  EXPECT_EQ(ztest["options"]["occlusion"], "ztest") << "the variant's own option";
  EXPECT_EQ(ztest["options"]["max_crack"], "3") << "--option applies to the variant too";
  for (const auto& [name, path] : ztest["images"].items()) EXPECT_TRUE(fs::exists(path.get<std::string>())) << name;
  EXPECT_TRUE(fs::exists(out / "box-wall_full_bidir-warp@occlusion=ztest_right.png"));
  // The z-test keeps hidden surfaces out of the right eye: measured 36.13 dB published, 62.41 dB
  // with the z-test; the two records come from two renders.
  EXPECT_GT(ztest["metrics"]["psnr"].get<double>(), plain["metrics"]["psnr"].get<double>() + 10.0);

  const std::pair<std::string, const char*> bad[] = {
      {"bidir-warp:occlusion=zbuf", "pipeline entry 'bidir-warp:occlusion=zbuf': bidir-warp: option occlusion=zbuf"},
      {"bidir-warp:occlusion", "'occlusion' is not KEY=VALUE"},
      {"bidir-warp:max_crack=2:max_crack=4", "fixes option max_crack twice"},
      {"bidir-warp:occlusions=ztest", "has no option 'occlusions'"},
      {"no-such:tile=8", "unknown pipeline 'no-such'"},
      // A value of 300 zeros and an 8 reads as 8; the name would pass a file name's 255 bytes.
      {"plain-raster:tile=" + std::string(300, '0') + "8", "is 319 characters long; it names files"},
      {"bidir-warp:max_crack=3/1,bidir-warp:max_crack=3#1", "would write files of the same name"},
      {"repro-rt:threshold_arcmin= 1", "'threshold_arcmin= 1' holds a blank; write KEY=VALUE without spaces"},
      // One variant under two spellings would be rendered and measured twice.
      {"bidir-warp:max_crack=2:occlusion=ztest,bidir-warp:occlusion=ztest:max_crack=2",
       "'bidir-warp:max_crack=2:occlusion=ztest' and 'bidir-warp:occlusion=ztest:max_crack=2' name the same variant of "
       "bidir-warp; name it once"},
      // A name given twice, also beside 'all' or as 'all' twice, is refused as bench, path and
      // sweeps refuse it (validate used to run it once).
      {"plain-rt,plain-rt", "--pipelines names 'plain-rt' twice"},
      {"all,plain-rt", "'plain-rt' is one of the pipelines 'all' includes"},
      {"all,all", "--pipelines names 'all' twice"},
  };
  for (const auto& [entry, message] : bad) {
    const test::CliRun e = test::run_cli(base_args(dir) + " --pipelines '" + entry + "'");
    EXPECT_EQ(e.code, 3) << entry << ":\n" << e.out;
    EXPECT_NE(e.out.find(message), std::string::npos) << entry << ":\n" << e.out;
  }
}

TEST(Validate, ARunIntoAnEarlierOnesFolderRemovesTheRecordsItLeavesBehind) {
  // fw-warp's record stayed beside a later run of repro-rt alone at another interaxial, pointing at
  // truth and disocclusion images that now showed the later rig.
  test::ScratchDir dir;
  const fs::path out = dir / "out";
  ASSERT_EQ(test::run_cli(base_args(dir) + " --pipelines repro-rt,fw-warp").code, 0);
  ASSERT_TRUE(fs::exists(out / "box-wall_full_fw-warp.json"));
  ASSERT_TRUE(fs::exists(out / "box-wall_full_fw-warp_right.png"));
  const test::CliRun r = test::run_cli(base_args(dir) + " --interaxial 0.12 --pipelines repro-rt");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("removed the earlier records of fw-warp with their images"), std::string::npos) << r.out;
  std::vector<std::string> left;
  for (const fs::directory_entry& e : fs::directory_iterator(out))
    if (e.path().filename().string().find("fw-warp") != std::string::npos) left.push_back(e.path().filename());
  EXPECT_TRUE(left.empty()) << left.front();
  // The shared images and the run's own record stay, and the summary lists what is there.
  for (const char* kept : {"box-wall_truth-full.png", "box-wall_disocclusions-full.png", "box-wall_full_repro-rt.json"})
    EXPECT_TRUE(fs::exists(out / kept)) << kept;
  const json summary = json::parse(test::read_text(out / "box-wall_full_summary.json"));
  ASSERT_EQ(summary["records"].size(), 1u);
  EXPECT_EQ(summary["records"][0]["rig"]["interaxial_m"], 0.12);

  // A pipeline validated again without the option that asked for an image last time: that image
  // (the grid overlay here; partials alike) stayed beside the new record, showing the old rig.
  ASSERT_EQ(test::run_cli(base_args(dir) + " --pipelines repro-rt --option grid_overlay=true").code, 0);
  ASSERT_TRUE(fs::exists(out / "box-wall_full_repro-rt_grid.png"));
  const test::CliRun again = test::run_cli(base_args(dir) + " --interaxial 0.1 --pipelines repro-rt");
  ASSERT_EQ(again.code, 0) << again.out;
  EXPECT_FALSE(fs::exists(out / "box-wall_full_repro-rt_grid.png"));
  for (const char* kept : {"box-wall_full_repro-rt.json", "box-wall_full_repro-rt_right.png"})
    EXPECT_TRUE(fs::exists(out / kept)) << kept << ": written again, so kept";
}

TEST(Validate, WhatARigForbidsIsRefusedBeforeAnythingRendersAndAStopLeavesNoSummary) {
  test::ScratchDir dir;
  const fs::path out = dir / "out";
  // A convergence of 1 mm gives a max disparity of some 2900 px at 160x90: rt-buffer's default
  // depth 2e exceeds its limit. It is refused before plain-rt, listed first, renders.
  const test::CliRun near = test::run_cli(base_args(dir) + " --convergence 0.001 --pipelines plain-rt,rt-buffer");
  EXPECT_EQ(near.code, 3) << near.out;
  EXPECT_NE(near.out.find("rt-buffer: the default depth t = 2 x max disparity"), std::string::npos) << near.out;
  EXPECT_FALSE(fs::exists(out / "box-wall_full_plain-rt.json")) << "a pipeline rendered before the refusal";
  // Under a variant the message names the entry.
  const test::CliRun variant =
      test::run_cli(base_args(dir) + " --convergence 0.001 --pipelines plain-rt,rt-buffer:margin=0.02");
  EXPECT_EQ(variant.code, 3) << variant.out;
  EXPECT_NE(variant.out.find("pipeline entry 'rt-buffer:margin=0.02': rt-buffer: the default depth"),
            std::string::npos)
      << variant.out;

  // A run that stops on the way (here: the second pipeline's right-eye image path is a folder)
  // leaves an earlier run's summary, records and images as they were and none of its own files:
  // every file is made under a temporary name and all are renamed into place at the end. The
  // earlier summary and records used to be removed first, a good run lost to a failing one.
  ASSERT_EQ(test::run_cli(base_args(dir) + " --pipelines plain-rt,repro-rt").code, 0);
  ASSERT_TRUE(fs::exists(out / "box-wall_full_summary.json"));
  fs::remove(out / "box-wall_full_repro-rt_right.png");
  const auto files_in = [&] {
    std::map<std::string, std::string> files;
    for (const fs::directory_entry& e : fs::directory_iterator(out))
      if (e.is_regular_file()) files[e.path().filename().string()] = test::read_text(e.path());
    return files;
  };
  const std::map<std::string, std::string> before = files_in();
  ASSERT_GE(before.size(), 10u);
  fs::create_directories(out / "box-wall_full_repro-rt_right.png");
  const test::CliRun stopped = test::run_cli(base_args(dir) + " --interaxial 0.3 --pipelines plain-rt,repro-rt");
  EXPECT_EQ(stopped.code, 3) << stopped.out;
  EXPECT_NE(stopped.out.find("box-wall_full_repro-rt_right.png is a folder"), std::string::npos) << stopped.out;
  const std::map<std::string, std::string> after = files_in();
  EXPECT_EQ(after.size(), before.size()) << "files appeared or went (temporaries?)";
  for (const auto& [name, text] : before) {
    ASSERT_TRUE(after.count(name)) << name << " went";
    EXPECT_TRUE(after.at(name) == text) << name << " changed";
  }
  EXPECT_TRUE(fs::is_directory(out / "box-wall_full_repro-rt_right.png")) << "a folder is never removed";
}

TEST(Validate, BadInputAndMissingTools) {
  test::ScratchDir dir;
  const test::CliRun unknown = test::run_cli(base_args(dir) + " --pipelines plain-rt,no-such-pipeline");
  EXPECT_EQ(unknown.code, 3) << unknown.out;
  EXPECT_NE(unknown.out.find("no-such-pipeline"), std::string::npos) << unknown.out;
  const test::CliRun truth = test::run_cli(base_args(dir) + " --truth mitsuba");
  EXPECT_EQ(truth.code, 3) << truth.out;
  EXPECT_NE(truth.out.find("full, blender, povray"), std::string::npos) << truth.out;
  ::setenv("STEREOBENCH_BLENDER", "/nonexistent/blender", 1);
  const test::CliRun missing = test::run_cli(base_args(dir) + " --truth blender --pipelines plain-rt");
  ::unsetenv("STEREOBENCH_BLENDER");
  EXPECT_EQ(missing.code, 4) << missing.out;
  EXPECT_NE(missing.out.find("unavailable"), std::string::npos) << missing.out;
  EXPECT_FALSE(fs::exists(dir / "out" / "box-wall_blender_plain-rt.json")) << "no record for a truth that was not rendered";
}

}  // namespace
}  // namespace sb
