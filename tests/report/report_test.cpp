// `stereobench report`: the report of the smoke sweep (`stereobench sweep run ci/smoke.toml`: two
// cells, every pipeline), checked in headless Chromium by tests/report/check_report.mjs (loads
// offline without errors, tables, drawn charts, every image, every viewer mode, a screenshot), for
// copied and linked images and every paper preset; and malformed results files (exit 3 naming the
// file and line), torn last lines, missing images, the single-run timing fallback and a foreign
// output folder.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/io/file_lock.hpp"
#include "support/file_size_limit.hpp"
#include "support/image_metrics.hpp"
#include "support/report_support.hpp"
#include "support/run_cli.hpp"
#include "support/scratch_dir.hpp"

namespace sb {
namespace {

namespace fs = std::filesystem;
using test::run_shell;
using test::quoted;
using test::embedded_data;
using test::write_text;
using nlohmann::json;

const fs::path kSource = SB_SOURCE_DIR;
constexpr const char* kInstallHint = "install them with `ci/install-deps.sh chromium` (Debian chromium, node, and the "
                                     "npm packages of ci/package.json)";

/// Fails (never skips) when the browser side is missing, naming the install command.
void require_browser_tools() {
  const char* env = std::getenv("STEREOBENCH_CHROMIUM");
  const fs::path chromium = env ? env : "/usr/bin/chromium";
  ASSERT_TRUE(fs::exists(chromium)) << chromium << " is missing; " << kInstallHint;
  ASSERT_EQ(run_shell("command -v node").code, 0) << "node is missing; " << kInstallHint;
  ASSERT_TRUE(fs::exists(kSource / "ci" / "node_modules" / "playwright-core" / "package.json"))
      << "playwright-core is missing from ci/node_modules; " << kInstallHint;
}

/// Runs check_report.mjs on a report; returns its output (the test fails on a non-zero exit).
/// `quick`: without the viewer's interaction (see check_report.mjs), for reports whose viewer is
/// the same as one checked in full.
std::string check_in_browser(const fs::path& index, const fs::path& screenshot, bool quick = false) {
  const test::CliRun r = run_shell("node " + quoted(kSource / "tests" / "report" / "check_report.mjs") + " " +
                                   quoted(index) + " " + quoted(screenshot) + (quick ? " --quick" : ""));
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(fs::exists(screenshot)) << r.out;
  return r.out;
}

/// Runs the sweep `definition` (TOML text) into dir/sweep and writes its report into dir/report.
void report_of_sweep(const test::ScratchDir& dir, const std::string& definition) {
  write_text(dir / "sweep.toml", definition);
  const test::CliRun run = test::run_cli("sweep run " + quoted(dir / "sweep.toml") + " --out " + quoted(dir / "sweep") +
                                         " --threads 2 --scenes-dir " +
                                         quoted(fs::path(SB_BINARY_DIR) / "Testing" / "scenes-cache"));
  ASSERT_EQ(run.code, 0) << run.out;
  const test::CliRun report =
      test::run_cli("report " + quoted(dir / "sweep" / "results.jsonl") + " --out " + quoted(dir / "report"));
  ASSERT_EQ(report.code, 0) << report.out;
}

TEST(Report, SmokeSweepReportsPassTheBrowserCheck) {
  require_browser_tools();
  if (HasFatalFailure()) return;
  test::ScratchDir dir;
  const fs::path sweep = dir / "smoke";
  const test::CliRun run = test::run_cli("sweep run " + quoted(kSource / "ci" / "smoke.toml") + " --out " + quoted(sweep) +
                                         " --threads 2 --scenes-dir " +
                                         quoted(fs::path(SB_BINARY_DIR) / "Testing" / "scenes-cache"));
  ASSERT_EQ(run.code, 0) << run.out;
  std::vector<json> lines;
  {
    std::ifstream in(sweep / "results.jsonl");
    for (std::string line; std::getline(in, line);)
      if (!line.empty()) lines.push_back(json::parse(line));
  }
  ASSERT_EQ(lines.size(), 2u) << "ci/smoke.toml has two cells";
  const size_t pipeline_count = lines[0]["pipelines"].size();

  // The lines in another order (parallel cells finish in any order), then a line a killed writer
  // left half-written; beside results.jsonl, so that the image paths hold.
  const auto results_text = [&lines](const std::string& name) {
    std::string text;
    for (auto it = lines.rbegin(); it != lines.rend(); ++it) {
      json l = *it;
      l["sweep"] = name;
      text += l.dump() + "\n";
    }
    return text + lines[0].dump().substr(0, 300);
  };
  write_text(sweep / "shuffled.jsonl", results_text("smoke"));

  const test::CliRun r = test::run_cli("report " + quoted(sweep / "shuffled.jsonl") + " --out " + quoted(dir / "report"));
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("shuffled.jsonl:3: unterminated last line"), std::string::npos) << r.out;
  // Per cell: left eye, truth, disocclusions, and four images per pipeline; two more (its own left
  // eye and that eye's difference image) per pipeline that synthesizes part of its left eye.
  size_t left_images = 0;
  for (const json& line : lines)
    for (const auto& [name, files] : line["images"]["pipelines"].items()) left_images += files.contains("left_png") ? 2 : 0;
  EXPECT_EQ(left_images, 2 * 2 * 3u) << "bidir-warp, bidir-warp-rt and the z-test variant in both cells";
  const std::string counts = std::to_string(lines.size()) + " cell(s) x " + std::to_string(pipeline_count) +
                             " pipeline(s), " + std::to_string(lines.size() * (3 + 4 * pipeline_count) + left_images) +
                             " image(s) copied";
  EXPECT_NE(r.out.find(counts), std::string::npos) << r.out;
  // The terminal summary's last column: the right eye's share of the left, - where stages serve both eyes.
  EXPECT_NE(r.out.find("right/left %"), std::string::npos) << r.out;
  const auto last_column = [&](const std::string& pipeline) {
    const size_t at = r.out.find("\n" + pipeline + " ");
    const size_t end = r.out.find('\n', at + 1);
    const std::string row = at == std::string::npos ? "" : r.out.substr(at + 1, end - at - 1);
    return row.substr(row.find_last_of(' ') + 1);
  };
  EXPECT_EQ(last_column("bidir-warp"), "-") << r.out;
  // The left eyes synthesized in part, in a table of their own.
  const size_t left_table = r.out.find("(left eyes synthesized in part, against plain-rt's left eye)");
  ASSERT_NE(left_table, std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\nbidir-warp-rt ", left_table), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("\nrepro-rt ", left_table), std::string::npos) << r.out;
  EXPECT_NE(last_column("repro-rt").find_first_of("0123456789"), std::string::npos) << r.out;

  // The embedded data: cells in cell order, infinite PSNR kept as "inf", the sweep's timing, images copied.
  const json data = embedded_data(dir / "report" / "index.html");
  ASSERT_TRUE(data.is_object());
  EXPECT_EQ(data["schema"], "stereobench.report 1");
  EXPECT_EQ(data["pipelines"][0], "plain-rt");
  EXPECT_EQ(data["pipelines"].size(), pipeline_count);
  ASSERT_EQ(data["cells"].size(), 2u);
  for (int i = 0; i < 2; ++i) {
    const json& cell = data["cells"][i];
    EXPECT_EQ(cell["index"], i);
    EXPECT_EQ(cell["id"], lines[i]["cell_id"]);
    EXPECT_EQ(cell["line"], 2 - i) << "line numbers name the shuffled file's lines";
    EXPECT_EQ(cell["pipelines"]["plain-rt"]["psnr"], "inf") << "plain-rt's right eye is the built-in truth";
    EXPECT_EQ(cell["pipelines"]["repro-rt"]["timing_source"], "median");
    EXPECT_EQ(cell["pipelines"]["repro-rt"]["speedup"], lines[i]["pipelines"]["repro-rt"]["timing"]["speedup_median"]);
    const json& measured = lines[i].at("pipelines").at("repro-rt").at("timing").at("right_over_left_median");
    ASSERT_TRUE(measured.is_number());
    EXPECT_EQ(cell.at("pipelines").at("repro-rt").at("right_over_left"), measured);
    EXPECT_TRUE(cell.at("pipelines").at("bidir-warp").at("right_over_left").is_null()) << "bidir-warp's stages serve both eyes";
    EXPECT_EQ(cell["pipelines"]["repro-rt"]["psnr"], lines[i]["pipelines"]["repro-rt"]["validation"]["metrics"]["psnr"]);
    // bidir-warp synthesizes part of its left eye: the report carries its measure; repro-rt
    // renders its left eye whole and carries none.
    const json& left = lines[i].at("pipelines").at("bidir-warp").at("validation").at("left_eye");
    ASSERT_TRUE(left.is_object());
    EXPECT_EQ(cell["pipelines"]["bidir-warp"]["left_psnr"], left["metrics"]["psnr"]);
    EXPECT_EQ(cell["pipelines"]["bidir-warp"]["left_ssim"], left["metrics"]["ssim"]);
    EXPECT_DOUBLE_EQ(cell["pipelines"]["bidir-warp"]["left_synthesized_fraction"].get<double>(),
                     left["synthesized_pixels"].get<double>() / left["metrics"]["pixels"].get<double>());
    EXPECT_TRUE(cell["pipelines"]["repro-rt"]["left_psnr"].is_null());
    EXPECT_TRUE(cell["pipelines"]["bidir-warp"]["images"]["left"].is_string());
    EXPECT_TRUE(cell["pipelines"]["bidir-warp"]["images"]["left_diff"].is_string());
    EXPECT_FALSE(cell["pipelines"]["repro-rt"]["images"].contains("left")) << "repro-rt's left eye is the cell's";
    EXPECT_TRUE(cell["pipelines"]["repro-rt"]["left_synthesized_fraction"].is_null());
    for (const auto& [key, path] : cell["images"].items()) {
      ASSERT_TRUE(path.is_string()) << key;
      EXPECT_TRUE(fs::exists(dir / "report" / path.get<std::string>())) << path;
    }
    for (const auto& [name, p] : cell["pipelines"].items())
      for (const auto& [key, path] : p["images"].items()) {
        ASSERT_TRUE(path.is_string()) << name << " " << key;
        EXPECT_TRUE(fs::exists(dir / "report" / path.get<std::string>())) << path;
      }
  }
  EXPECT_TRUE(data["paper"].is_null());
  std::printf("%s", check_in_browser(dir / "report" / "index.html", dir / "report.png").c_str());

  // Again into the same folder: the earlier report is replaced. Linked images load from the sweep.
  const test::CliRun again = test::run_cli("report " + quoted(sweep / "shuffled.jsonl") + " --out " + quoted(dir / "report") +
                                           " --link-images --title 'Linked <images>'");
  ASSERT_EQ(again.code, 0) << again.out;
  EXPECT_FALSE(fs::exists(dir / "report" / "images")) << "the earlier report's copies are removed";
  const std::string html = test::read_text(dir / "report" / "index.html");
  EXPECT_NE(html.find("<title>Linked &lt;images&gt;</title>"), std::string::npos);
  EXPECT_EQ(embedded_data(dir / "report" / "index.html")["cells"][0]["images"]["left"],
            "../smoke/" + lines[0]["images"]["left_png"].get<std::string>());
  std::printf("%s", check_in_browser(dir / "report" / "index.html", dir / "report-linked.png", true).c_str());
  // Through a linked folder in --out the links are made from the path as given, as the browser
  // resolves them (not from the folder the link points to, three levels deeper).
  fs::create_directories(dir / "deep" / "a" / "b");
  fs::create_directory_symlink(dir / "deep" / "a" / "b", dir / "lnk");
  const test::CliRun linked = test::run_cli("report " + quoted(sweep / "shuffled.jsonl") + " --out " +
                                            quoted(dir / "lnk" / "rep") + " --link-images");
  ASSERT_EQ(linked.code, 0) << linked.out;
  const std::string left = embedded_data(dir / "lnk" / "rep" / "index.html")["cells"][0]["images"]["left"];
  EXPECT_EQ(left, "../../smoke/" + lines[0]["images"]["left_png"].get<std::string>());
  EXPECT_TRUE(fs::exists((dir / "lnk" / "rep" / left).lexically_normal())) << left;

  // Every paper preset: the paper's numbers beside ours.
  for (const char* preset : {"wissmann-table2", "kim-table2", "kim-table3", "al-hagri-interaxial"}) {
    write_text(sweep / (std::string(preset) + ".jsonl"), results_text(preset));
    const fs::path out = dir / (std::string("report-") + preset);
    const test::CliRun p = test::run_cli("report " + quoted(sweep / (std::string(preset) + ".jsonl")) + " --out " + quoted(out));
    ASSERT_EQ(p.code, 0) << p.out;
    const json pd = embedded_data(out / "index.html");
    ASSERT_TRUE(pd["paper"].is_object()) << preset;
    EXPECT_EQ(pd["paper"]["experiment"], std::string(preset).rfind("al-hagri", 0) == 0 ? "al-hagri" : preset);
    std::printf("%s", check_in_browser(out / "index.html", dir / (std::string("report-") + preset + ".png"), true).c_str());
  }
}

TEST(Report, APathSweepsFrameChartCountsWholeFrames) {
  require_browser_tools();
  if (HasFatalFailure()) return;
  test::ScratchDir dir;
  // Four frames of spheres spinning: the frame axis had ticks at 0, 0.5, 1, 1.5, ...
  report_of_sweep(dir,
                  "[sweep]\nname = \"spin\"\nscenes = [\"spheres\"]\npipelines = [\"plain-rt\", \"repro-rt\"]\n"
                  "baseline = \"plain-rt\"\nmax_disparity_px = [4, 8]\nresolutions = [\"64x36\"]\n"
                  "[path]\nframes = 4\nbvh = \"refit\"\n[path.spin]\naxis = [0, 1, 0]\ndegrees_per_frame = 5.0\n"
                  "mesh_prefix = \"sphere\"\n[timing]\nrepetitions = 1\nwarmup = 0\n");
  if (HasFatalFailure()) return;
  const std::string checked = check_in_browser(dir / "report" / "index.html", dir / "report.png", true);
  EXPECT_NE(checked.find("Frame time along the path"), std::string::npos) << checked;
}

TEST(Report, ManyPipelinesKeepEveryLegendEntryAndStyleAndCloseConvergencesStayApart) {
  require_browser_tools();
  if (HasFatalFailure()) return;
  test::ScratchDir dir;
  // Every pipeline and eleven variants (26 lines): Chart.js's legend, capped at half the chart,
  // dropped entries, and lines 8 apart shared marker, dash and a near colour; convergences 0.5 and
  // 0.501 m were labelled alike and merged in the charts.
  report_of_sweep(dir,
             "[sweep]\nname = \"many\"\nscenes = [\"box-wall\"]\n"
             "pipelines = [\"all\", \"bidir-warp:occlusion=ztest\", \"bidir-warp:occlusion=ztest:clipped=both:max_crack=4\", "
             "\"repro-rt:threshold_arcmin=0.5:discontinuity_px=0.1:occluding_edge_px=0\", "
             "\"repro-rt:discard=interpolated:source_frustum=false\", \"repro-reraster:threshold_arcmin=2\", "
             "\"fw-warp:warp=rows:max_crack=1\", \"fw-warp:background=false\", "
             "\"bw-warp:iterations=8:start=far:filter=nearest\", \"rt-atomic:confirm=true\", "
             "\"rt-buffer:depth=8:margin=0.02\", \"bidir-warp-rt:occlusion=ztest:clipped=both\"]\n"
             "interaxial_m = [0.03, 0.064]\nconvergence_m = [0.5, 0.501]\nresolutions = [\"64x36\"]\n"
             "[timing]\nrepetitions = 1\nwarmup = 0\n");
  if (HasFatalFailure()) return;
  (void)check_in_browser(dir / "report" / "index.html", dir / "report.png", true);
}

/// A minimal valid results line (no images: the report shows them as unavailable).
json minimal_line(const std::string& id, int index) {
  const json metrics{{"psnr", 40.5}, {"ssim", 0.99}, {"mse", test::mse_of_psnr(40.5)}, {"error_fraction", 0.01}};
  const json holes{{"hole_fraction", 0.02}};
  return json{{"kind", "stereobench.sweep_cell"},
              {"schema_version", 1},
              {"sweep", "tiny"},
              {"cell_id", id},
              {"cell_index", index},
              {"cell", {{"scene", "box-wall"}, {"resolution", "16x9"}, {"truth", "full"}, {"lights", nullptr}}},
              {"rig", {{"width", 16}, {"height", 9}, {"interaxial_m", 0.064}, {"convergence_m", 2.0}, {"max_disparity_px", 0.5}}},
              {"baseline", "plain-rt"},
              {"pipelines",
               {{"plain-rt",
                 {{"validation",
                   {{"metrics", metrics}, {"holes", {{"hole_fraction", nullptr}}}, {"total_s", 0.01}}}}},
                {"repro-rt",
                 {{"validation",
                   {{"metrics", metrics},
                    {"holes", holes},
                    {"total_s", 0.004},
                    {"timings_s", {{"left_gbuffer", 0.002}, {"hole_fill", 0.001}}},
                    {"stage_eyes", {{"left_gbuffer", "left"}, {"hole_fill", "right"}}}}}}}}}};
}

TEST(Report, MalformedResultsExit3NamingFileAndLine) {
  test::ScratchDir dir;
  const std::string good = minimal_line("a", 0).dump() + "\n";
  struct Case {
    std::string text;
    std::string expected;  ///< part of the message
  };
  json wrong_type = minimal_line("b", 1);
  wrong_type["rig"]["width"] = "16";
  json no_pipelines = minimal_line("b", 1);
  no_pipelines.erase("pipelines");
  json other_kind = minimal_line("b", 1);
  other_kind["kind"] = "stereobench.validation";
  json newer = minimal_line("b", 1);
  newer["schema_version"] = 2;
  json bad_metric = minimal_line("b", 1);
  bad_metric["pipelines"]["plain-rt"]["validation"]["metrics"]["psnr"] = "high";
  json other_sweep = minimal_line("b", 1);
  other_sweep["sweep"] = "other";
  json other_version = minimal_line("b", 1);
  other_version["definition_sha256"] = "0123456789abcdef";
  json ssim_5 = minimal_line("b", 1);
  ssim_5["pipelines"]["repro-rt"]["validation"]["metrics"]["ssim"] = 5;
  json negative_time = minimal_line("b", 1);
  negative_time["pipelines"]["plain-rt"]["validation"]["total_s"] = -0.5;
  json wrapped_version = minimal_line("b", 1);
  wrapped_version["schema_version"] = 4294967297LL;  // 2^32 + 1, which an int reads as 1
  // The metrics per region were copied into the page unchecked.
  json bad_region = minimal_line("b", 1);
  bad_region["pipelines"]["repro-rt"]["validation"]["regions"] = {{"filled", {{"pixels", -3}, {"psnr", "x"}}}};
  json bad_region_psnr = minimal_line("b", 1);
  bad_region_psnr["pipelines"]["repro-rt"]["validation"]["regions"] = {
      {"reprojected", {{"pixels", 10}, {"psnr", "x"}, {"ssim", 0.9}, {"mse", 1.0}}}};
  const std::vector<Case> cases = {
      {good + "{\"kind\": \"stereobench.sweep_cell\", oops}\n" + minimal_line("c", 2).dump() + "\n",
       "results.jsonl:2: not a JSON line"},
      {good + wrong_type.dump() + "\n", "results.jsonl:2: field 'rig.width' is \"16\" but must be an integer"},
      {good + no_pipelines.dump() + "\n", "results.jsonl:2: field 'pipelines' is missing"},
      {good + other_kind.dump() + "\n", "results.jsonl:2: kind is \"stereobench.validation\""},
      {good + newer.dump() + "\n", "results.jsonl:2: schema_version 2 is newer"},
      {good + bad_metric.dump() + "\n", "results.jsonl:2: field 'pipelines.plain-rt.validation.metrics.psnr' is \"high\""},
      {good + "\n" + minimal_line("a", 5).dump() + "\n", "results.jsonl:3: cell_id 'a' appears twice (also on line 1)"},
      {good + other_sweep.dump() + "\n",
       "results.jsonl:2: a cell of sweep 'other' (definition sha256 ?), but line 1 is of sweep 'tiny' (sha256 ?); a "
       "results file holds the cells of one sweep definition"},
      {good + other_version.dump() + "\n", "results.jsonl:2: a cell of sweep 'tiny' (definition sha256 0123456789ab)"},
      {good + minimal_line("b", 0).dump() + "\n", "results.jsonl:2: cell_index '0' appears twice (also on line 1)"},
      {minimal_line("a", -1).dump() + "\n", "results.jsonl:1: cell_index -1 is negative"},
      {good + ssim_5.dump() + "\n",
       "results.jsonl:2: field 'pipelines.repro-rt.validation.metrics.ssim' is 5, outside [-1, 1]"},
      {good + negative_time.dump() + "\n", "results.jsonl:2: field 'pipelines.plain-rt.validation.total_s' is -0.5"},
      {good + wrapped_version.dump() + "\n", "results.jsonl:2: schema_version 4294967297 is newer"},
      {good + bad_region.dump() + "\n",
       "results.jsonl:2: field 'pipelines.repro-rt.validation.regions.filled.pixels' is -3, outside"},
      {good + bad_region_psnr.dump() + "\n",
       "results.jsonl:2: field 'pipelines.repro-rt.validation.regions.reprojected.psnr' is \"x\""},
      {"[1, 2]\n", "results.jsonl:1: a results line must be a JSON object"},
      {"", "holds no finished cell"},
      {"{\"kind\": \"stereobench.sweep_ce", "holds no finished cell"},
  };
  for (const Case& c : cases) {
    write_text(dir / "results.jsonl", c.text);
    const test::CliRun r = test::run_cli("report " + quoted(dir / "results.jsonl") + " --out " + quoted(dir / "out"));
    EXPECT_EQ(r.code, 3) << c.expected << "\n" << r.out;
    EXPECT_NE(r.out.find(c.expected), std::string::npos) << r.out;
    EXPECT_NE(r.out.find((dir / "results.jsonl").string()), std::string::npos) << "the message names the file: " << r.out;
    EXPECT_FALSE(fs::exists(dir / "out" / "index.html")) << "no report from a bad results file";
  }
  const test::CliRun missing = test::run_cli("report " + quoted(dir / "nope.jsonl") + " --out " + quoted(dir / "out"));
  EXPECT_EQ(missing.code, 3) << missing.out;
  EXPECT_NE(missing.out.find("nope.jsonl does not exist"), std::string::npos) << missing.out;
  const test::CliRun usage = test::run_cli("report " + quoted(dir / "results.jsonl"));
  EXPECT_EQ(usage.code, 3) << usage.out;
  EXPECT_NE(usage.out.find("--out"), std::string::npos) << usage.out;
}

TEST(Report, WarnsOnTornTailAndMissingImagesAndGuardsForeignFolders) {
  test::ScratchDir dir;
  json with_images = minimal_line("b", 1);
  with_images["pipelines"]["repro-rt"]["validation"].erase("stage_eyes");  // as written before stages named eyes
  with_images["images"] = {{"left_png", "cells/0001/left.png"}, {"pipelines", {{"plain-rt", {{"right_png", "cells/0001/r.png"}}}}}};
  // Two of the sweep's three cells: it is unfinished.
  json first = minimal_line("a", 0);
  first["cell_count"] = 3;
  with_images["cell_count"] = 3;
  write_text(dir / "results.jsonl", first.dump() + "\n" + with_images.dump() + "\n{\"kind\": \"stereob");
  const test::CliRun r = test::run_cli("report " + quoted(dir / "results.jsonl") + " --out " + quoted(dir / "out"));
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("results.jsonl:3: unterminated last line"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("image cells/0001/left.png is missing"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("2 of the 3 cells of sweep 'tiny' are in the results: the sweep is unfinished"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("2 cell(s) x 2 pipeline(s), 0 image(s)"), std::string::npos) << r.out;
  const json data = embedded_data(dir / "out" / "index.html");
  EXPECT_TRUE(data["cells"][1]["images"]["left"].is_null());
  // Without a "timing" block the time is the validation's single run: 0.01 s / 0.004 s = 2.5.
  const json& repro = data["cells"][0]["pipelines"]["repro-rt"];
  EXPECT_EQ(repro["timing_source"], "single run");
  EXPECT_DOUBLE_EQ(repro["speedup"].get<double>(), 2.5);
  EXPECT_EQ(repro["stages_s"]["hole_fill"], 0.001);
  // Its right eye's share of the left from the stages' eyes: 0.001 s / 0.002 s; none without them.
  EXPECT_DOUBLE_EQ(repro["right_over_left"].get<double>(), 0.5);
  EXPECT_TRUE(data["cells"][1]["pipelines"]["repro-rt"]["right_over_left"].is_null());
  EXPECT_TRUE(data["cells"][0]["pipelines"]["plain-rt"]["hole_fraction"].is_null()) << "null in the line: null, shown as —";
  // The page lists what the terminal said: the torn line, both missing images, the missing cell.
  EXPECT_EQ(data["warnings"].size(), 4u) << data["warnings"].dump();
  for (const char* asset : {"report.js", "report.css", "chart.umd.min.js"})
    EXPECT_TRUE(fs::exists(dir / "out" / "assets" / asset)) << asset;

  // A report stopped before its index (a full disk, a kill) is replaced by the next run, and what
  // its writes left in the folder it was being written into goes.
  fs::remove(dir / "out" / "index.html");
  write_text(dir / "out" / ".stereobench-next" / ".index.html.tmp-123-0", "<html");
  write_text(dir / "out" / ".stereobench-next" / "assets" / "report.js", "// cut");
  write_text(dir / "out" / ".index.html.tmp-123-0", "<html");  // as an earlier version wrote it
  ASSERT_TRUE(fs::exists(dir / "out" / ".stereobench-report"));
  const test::CliRun again = test::run_cli("report " + quoted(dir / "results.jsonl") + " --out " + quoted(dir / "out"));
  EXPECT_EQ(again.code, 0) << again.out;
  EXPECT_TRUE(fs::exists(dir / "out" / "index.html"));
  EXPECT_FALSE(fs::exists(dir / "out" / ".stereobench-next")) << "the killed write's leftovers go";
  EXPECT_FALSE(fs::exists(dir / "out" / ".index.html.tmp-123-0"));

  // A folder that holds something else is not overwritten.
  write_text(dir / "mine" / "notes.txt", "keep");
  const test::CliRun foreign = test::run_cli("report " + quoted(dir / "results.jsonl") + " --out " + quoted(dir / "mine"));
  EXPECT_EQ(foreign.code, 3) << foreign.out;
  EXPECT_NE(foreign.out.find("is not empty and holds no stereobench report"), std::string::npos) << foreign.out;
  EXPECT_EQ(test::read_text(dir / "mine" / "notes.txt"), "keep");

  // An image path naming a file that is not a PNG (here a text file beside the results) is left
  // out with a warning, not copied into the report.
  write_text(dir / "secret.txt", "not an image");
  json stray = minimal_line("a", 0);
  stray["images"] = {{"left_png", "secret.txt"}};
  write_text(dir / "stray.jsonl", stray.dump() + "\n");
  const test::CliRun leak = test::run_cli("report " + quoted(dir / "stray.jsonl") + " --out " + quoted(dir / "leak"));
  EXPECT_EQ(leak.code, 0) << leak.out;
  EXPECT_NE(leak.out.find("image secret.txt (" + (dir / "secret.txt").string() + ") is not a PNG file; left out"),
            std::string::npos)
      << leak.out;
  size_t copied = 0;
  if (fs::exists(dir / "leak" / "images"))
    for (const auto& e : fs::recursive_directory_iterator(dir / "leak" / "images")) copied += e.is_regular_file();
  EXPECT_EQ(copied, 0u) << "nothing copied";
  EXPECT_TRUE(embedded_data(dir / "leak" / "index.html")["cells"][0]["images"]["left"].is_null());

  // Many images missing (a results file copied without its cells/ folder): three named, the rest
  // counted in one line (one warning each used to flood the terminal and the page), and the page
  // names no folder of this machine.
  json many = minimal_line("a", 0);
  many["images"] = {{"left_png", "cells/0000/left.png"}, {"truth_png", "cells/0000/truth.png"}, {"pipelines", json::object()}};
  for (const char* p : {"plain-rt", "repro-rt"})
    many["images"]["pipelines"][p] = {{"right_png", std::string("cells/0000/") + p + "_r.png"},
                                      {"diff_png", std::string("cells/0000/") + p + "_d.png"},
                                      {"ssim_png", std::string("cells/0000/") + p + "_s.png"}};
  write_text(dir / "moved" / "results.jsonl", many.dump() + "\n");
  const test::CliRun moved = test::run_cli("report " + quoted(dir / "moved" / "results.jsonl") + " --out " +
                                           quoted(dir / "moved-report"));
  ASSERT_EQ(moved.code, 0) << moved.out;
  EXPECT_NE(moved.out.find("and 5 more images are missing (8 of the 8 the results name)"), std::string::npos)
      << moved.out;
  const json page = embedded_data(dir / "moved-report" / "index.html");
  EXPECT_EQ(page["warnings"].size(), 4u) << page["warnings"].dump();
  EXPECT_EQ(page["warnings"].dump().find(dir.path().string()), std::string::npos) << page["warnings"].dump();
}

TEST(Report, CellsMeasuredUnderDifferentThreadCountsAreWarnedAbout) {
  // A sweep resumed with another --threads: its cells' times are not comparable, and the
  // overview's machine row shows only the first cell's count.
  test::ScratchDir dir;
  std::string text;
  for (int i = 0; i < 3; ++i) {
    json line = minimal_line(std::string(1, static_cast<char>('a' + i)), i);
    line["threads"] = i == 0 ? 1 : 2;
    line["jobs"] = 1;
    text += line.dump() + "\n";
  }
  write_text(dir / "results.jsonl", text);
  const test::CliRun r = test::run_cli("report " + quoted(dir / "results.jsonl") + " --out " + quoted(dir / "out"));
  ASSERT_EQ(r.code, 0) << r.out;
  const std::string expected =
      "the cells were measured under different threads: 1 (1 cell), 2 (2 cells); their times and speed-ups are not "
      "comparable";
  EXPECT_NE(r.out.find(expected), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("different jobs"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("different versions"), std::string::npos) << "absent in every line alike: " << r.out;
  const json data = embedded_data(dir / "out" / "index.html");
  ASSERT_EQ(data["warnings"].size(), 1u) << data["warnings"].dump();
  EXPECT_NE(data["warnings"][0].get<std::string>().find("results.jsonl: " + expected), std::string::npos);
}

TEST(Report, ImagesOfEveryPipelineKeepTheirOwnFolderAndALinkedResultsFileFindsThem) {
  // Two pipeline names that the image folders once mapped alike ("repro-rt:x=1", "repro-rt_x_1"):
  // each keeps its own right eye. The results file is read through a link in another folder: its
  // images lie beside the file it links to (all were reported missing).
  test::ScratchDir dir;
  const fs::path store = kSource / "reference" / "store";
  fs::create_directories(dir / "run" / "cells" / "0000");
  fs::copy_file(store / "box-wall_full_160x90_e64.0mm_c4.08m" / "right.png", dir / "run" / "cells" / "0000" / "a.png");
  fs::copy_file(store / "box-wall_povray_160x90_e64.0mm_c4.08m" / "right.png", dir / "run" / "cells" / "0000" / "b.png");
  json line = minimal_line("a", 0);
  line["pipelines"]["repro-rt:x=1"] = line["pipelines"]["repro-rt"];
  line["pipelines"]["repro-rt_x_1"] = line["pipelines"]["repro-rt"];
  line["images"] = {{"pipelines",
                     {{"repro-rt:x=1", {{"right_png", "cells/0000/a.png"}}},
                      {"repro-rt_x_1", {{"right_png", "cells/0000/b.png"}}}}}};
  write_text(dir / "run" / "results.jsonl", line.dump() + "\n");
  fs::create_directories(dir / "elsewhere");
  fs::create_symlink(dir / "run" / "results.jsonl", dir / "elsewhere" / "results.jsonl");

  const test::CliRun r =
      test::run_cli("report " + quoted(dir / "elsewhere" / "results.jsonl") + " --out " + quoted(dir / "out"));
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(r.out.find("is missing"), std::string::npos) << r.out;
  const json pipelines = embedded_data(dir / "out" / "index.html")["cells"][0]["pipelines"];
  const std::string a = pipelines["repro-rt:x=1"]["images"]["right"].get<std::string>();
  const std::string b = pipelines["repro-rt_x_1"]["images"]["right"].get<std::string>();
  EXPECT_NE(a, b);
  EXPECT_EQ(test::read_text(dir / "out" / a), test::read_text(dir / "run" / "cells" / "0000" / "a.png")) << a;
  EXPECT_EQ(test::read_text(dir / "out" / b), test::read_text(dir / "run" / "cells" / "0000" / "b.png")) << b;
}

}  // namespace
}  // namespace sb

namespace sb {
namespace {

TEST(Report, ASecondReportIntoAFolderBeingWrittenIsRefused) {
  // Two reports into one folder would remove each other's images and assets and could leave an
  // index.html naming files that are gone: while one writes (its lock on the folder, held here),
  // another is refused, and the folder is left as it was.
  test::ScratchDir dir;
  write_text(dir / "results.jsonl", minimal_line("a", 0).dump() + "\n");
  const std::string args = "report " + quoted(dir / "results.jsonl") + " --out " + quoted(dir / "out");
  const test::CliRun first = test::run_cli(args);
  ASSERT_EQ(first.code, 0) << first.out;
  const std::string index = test::read_text(dir / "out" / "index.html");
  {
    const io::FileLock held = io::FileLock::acquire(dir / "out");
    const test::CliRun second = test::run_cli(args + " --title other");
    EXPECT_EQ(second.code, 3) << second.out;
    EXPECT_NE(second.out.find("--out " + (dir / "out").string() +
                              ": another report is being written there; wait for it to end, or give another folder"),
              std::string::npos)
        << second.out;
    EXPECT_EQ(test::read_text(dir / "out" / "index.html"), index) << "the report being written is left alone";
    EXPECT_TRUE(fs::exists(dir / "out" / "assets" / "report.js"));
  }
  const test::CliRun after = test::run_cli(args + " --title other");
  EXPECT_EQ(after.code, 0) << after.out;
}

/// A results file of one cell, dir/results.jsonl, whose record names one image (a left eye's) that
/// lies beside it: the smallest input a report copies an image for.
void write_one_cell_results(const fs::path& dir) {
  json line = minimal_line("a", 0);
  line["images"] = {{"left_png", "cells/0000/left.png"}};
  write_text(dir / "results.jsonl", line.dump() + "\n");
  fs::create_directories(dir / "cells" / "0000");
  fs::copy_file(kSource / "reference" / "store" / "box-wall_full_160x90_e64.0mm_c4.08m" / "right.png",
                dir / "cells" / "0000" / "left.png");
}

TEST(Report, AReportThatCannotBeWrittenLeavesTheEarlierOneAsItWas) {
  // A full disk while the new report is written: the earlier report in the folder was removed
  // before the new one was written, and lost. It now stays as it was until the new one is whole.
  test::ScratchDir dir;
  write_one_cell_results(dir.path());
  const std::string args = "report " + quoted(dir / "results.jsonl") + " --out " + quoted(dir / "out");
  const test::CliRun first = test::run_cli(args + " --title first");
  ASSERT_EQ(first.code, 0) << first.out;
  const std::string index = test::read_text(dir / "out" / "index.html");
  const std::string chart = test::read_text(dir / "out" / "assets" / "chart.umd.min.js");
  ASSERT_GT(chart.size(), 100000u) << "the limit below must stop the copy of Chart.js";
  {
    const test::FileSizeLimit limit(100000);
    ASSERT_TRUE(limit.ok());
    const test::CliRun full = test::run_cli(args + " --title second");
    EXPECT_EQ(full.code, 4) << full.out;
    EXPECT_NE(full.out.find("chart.umd.min.js"), std::string::npos) << "names the file it could not write: " << full.out;
    EXPECT_NE(full.out.find("the earlier report in " + (dir / "out").string() + " is kept as it was"),
              std::string::npos)
        << full.out;
  }
  EXPECT_EQ(test::read_text(dir / "out" / "index.html"), index);
  EXPECT_EQ(test::read_text(dir / "out" / "assets" / "chart.umd.min.js"), chart);
  EXPECT_TRUE(fs::exists(dir / "out" / "assets" / "report.js"));
  const std::string left = embedded_data(dir / "out" / "index.html")["cells"][0]["images"]["left"].get<std::string>();
  ASSERT_EQ(left.rfind("images/", 0), 0u) << left;
  EXPECT_TRUE(fs::exists(dir / "out" / left)) << "the earlier report's images stay: " << left;
  EXPECT_FALSE(fs::exists(dir / "out" / ".stereobench-next")) << "nothing of the new report is left";

  // With room, the new report takes the earlier one's place.
  const test::CliRun again = test::run_cli(args + " --title second");
  ASSERT_EQ(again.code, 0) << again.out;
  EXPECT_NE(test::read_text(dir / "out" / "index.html").find("<title>second</title>"), std::string::npos);
  EXPECT_TRUE(fs::exists(dir / "out" / left));
  EXPECT_FALSE(fs::exists(dir / "out" / ".stereobench-next"));
}

TEST(Report, AnEarlierPartThatCannotBeRemovedIsSetAsideAndTheNewReportTakesItsPlace) {
  // The earlier report's images folder is not the user's to empty (another owner's, read-only):
  // its index and assets were removed, its images folder emptied in part, and then the removal
  // failed, leaving no report at all. The earlier parts are now set aside by renames (in the
  // folder, which needs no permission on them), the new report takes their place, and a part that
  // cannot be removed stays set aside, with a warning.
  // As root the reports run as nobody (setpriv), from a folder under /tmp that nobody can reach
  // (the build tree may lie under a private home); as another user a read-only folder of their
  // own does the same.
  std::string made = "/tmp/sb-report-aside-XXXXXX";  // not TMPDIR, which nobody may not reach
  ASSERT_NE(::mkdtemp(made.data()), nullptr);
  const fs::path dir = made;
  const fs::perms read_only = fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                              fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec;
  fs::permissions(dir, read_only | fs::perms::owner_write);
  write_one_cell_results(dir);
  fs::copy(fs::path(SB_BINARY_DIR) / "report-assets", dir / "assets", fs::copy_options::recursive);
  fs::copy_file(SB_CLI_PATH, dir / "stereobench");
  std::string as_user;  // setpriv's command line, as root
  const auto report = [&](const std::string& title) {
    return run_shell("STEREOBENCH_REPORT_ASSETS=" + quoted(dir / "assets") + " " + as_user +
                     quoted(dir / "stereobench") + " report " + quoted(dir / "results.jsonl") + " --out " +
                     quoted(dir / "out") + " --title " + title);
  };
  const test::CliRun first = report("first");
  ASSERT_EQ(first.code, 0) << first.out;
  const fs::path images = dir / "out" / "images";
  ASSERT_TRUE(fs::is_directory(images));
  if (::geteuid() == 0) {
    ASSERT_EQ(run_shell("chown -R 65534 " + quoted(dir / "out") + " && chown root " + quoted(images)).code, 0);
    as_user = "setpriv --reuid=65534 --regid=65534 --clear-groups ";
  }
  fs::permissions(images, read_only);
  const test::CliRun second = report("second");
  EXPECT_EQ(second.code, 0) << second.out;
  const fs::path leftover = dir / "out" / ".stereobench-leftover-images-1";
  EXPECT_NE(second.out.find("cannot remove the earlier report's images, left as " + leftover.string()),
            std::string::npos)
      << second.out;
  EXPECT_NE(test::read_text(dir / "out" / "index.html").find("<title>second</title>"), std::string::npos);
  EXPECT_TRUE(fs::exists(dir / "out" / "assets" / "report.js"));
  const std::string left = embedded_data(dir / "out" / "index.html")["cells"][0]["images"]["left"].get<std::string>();
  EXPECT_TRUE(fs::exists(dir / "out" / left)) << "the new report's image: " << left;
  // What of it could be removed is gone (the image, in a folder of the user's); the rest stays.
  EXPECT_TRUE(fs::is_directory(leftover));
  EXPECT_FALSE(fs::exists(dir / "out" / ".stereobench-earlier-images"));
  EXPECT_FALSE(fs::exists(dir / "out" / ".stereobench-next"));

  // The leftover does not stand in the way of the next report, which says again that it is there.
  const test::CliRun third = report("third");
  EXPECT_EQ(third.code, 0) << third.out;
  EXPECT_NE(third.out.find("cannot remove " + leftover.string() + ", an earlier report's part left there"),
            std::string::npos)
      << third.out;
  EXPECT_NE(test::read_text(dir / "out" / "index.html").find("<title>third</title>"), std::string::npos);

  // Once it can be removed, the next report removes it.
  fs::permissions(leftover, fs::perms::owner_write, fs::perm_options::add);
  if (!as_user.empty()) {
    ASSERT_EQ(run_shell("chown 65534 " + quoted(leftover)).code, 0);
  }
  const test::CliRun fourth = report("fourth");
  EXPECT_EQ(fourth.code, 0) << fourth.out;
  EXPECT_EQ(fourth.out.find("cannot remove"), std::string::npos) << fourth.out;
  EXPECT_FALSE(fs::exists(leftover));
  EXPECT_NE(test::read_text(dir / "out" / "index.html").find("<title>fourth</title>"), std::string::npos);
  if (!::testing::Test::HasFailure()) fs::remove_all(dir);
}

TEST(Report, AReportStoppedWhileTakingTheFolderLeavesTheEarlierOneToComeBack) {
  // A report stopped after its images took their place but before its index did: the next report
  // puts back every part of the earlier one (its images over the stopped report's), so that the
  // earlier report is whole again, as a failing next report then says.
  test::ScratchDir dir;
  write_one_cell_results(dir.path());
  const std::string args = "report " + quoted(dir / "results.jsonl") + " --out " + quoted(dir / "out");
  ASSERT_EQ(test::run_cli(args + " --title first").code, 0);
  const fs::path out = dir / "out";
  const std::string index = test::read_text(out / "index.html");
  const std::string left = embedded_data(out / "index.html")["cells"][0]["images"]["left"].get<std::string>();
  const std::string image = test::read_text(out / left);
  // The state a stop between the images' and the index's renames leaves.
  for (const char* part : {"index.html", "assets", "images"})
    fs::rename(out / part, out / (std::string(".stereobench-earlier-") + part));
  fs::create_directories(out / fs::path(left).parent_path());
  write_text(out / left, "the stopped report's image");
  {
    const test::FileSizeLimit limit(100000);  // the next report cannot copy Chart.js
    ASSERT_TRUE(limit.ok());
    const test::CliRun full = test::run_cli(args + " --title second");
    EXPECT_EQ(full.code, 4) << full.out;
    EXPECT_NE(full.out.find("the earlier report in " + out.string() + " is kept as it was"), std::string::npos)
        << full.out;
  }
  EXPECT_EQ(test::read_text(out / "index.html"), index);
  EXPECT_EQ(test::read_text(out / left), image) << "the earlier report's image, not the stopped one's";
  EXPECT_TRUE(fs::exists(out / "assets" / "report.js"));
  for (const char* part : {"index.html", "assets", "images"})
    EXPECT_FALSE(fs::exists(out / (std::string(".stereobench-earlier-") + part))) << part;
  const test::CliRun again = test::run_cli(args + " --title second");
  ASSERT_EQ(again.code, 0) << again.out;
  EXPECT_NE(test::read_text(out / "index.html").find("<title>second</title>"), std::string::npos);

  // A run stopped while it put the earlier parts back puts the index back last: stopped after the
  // images, the folder holds no index, and the next run puts back the assets and the index.
  const std::string second = test::read_text(out / "index.html");
  const std::string report_js = test::read_text(out / "assets" / "report.js");
  for (const char* part : {"index.html", "assets"})
    fs::rename(out / part, out / (std::string(".stereobench-earlier-") + part));
  fs::create_directories(out / "assets");
  write_text(out / "assets" / "report.js", "the stopped report's script");
  {
    const test::FileSizeLimit limit(100000);
    ASSERT_TRUE(limit.ok());
    EXPECT_EQ(test::run_cli(args + " --title third").code, 4);
  }
  EXPECT_EQ(test::read_text(out / "index.html"), second);
  EXPECT_EQ(test::read_text(out / "assets" / "report.js"), report_js);
}

}  // namespace
}  // namespace sb
