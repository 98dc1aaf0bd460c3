// `stereobench nightly`: two runs of a tiny sweep give two run folders with results, gate files and
// a report, two history lines with the per-pipeline medians and gate counts, and a report whose
// Trends section has a point per run (embedded data and Chromium); a malformed history is bad input.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <functional>
#include <optional>
#include <fstream>
#include <regex>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "renderer/error.hpp"
#include "renderer/io/file_lock.hpp"
#include "support/lock_wait.hpp"
#include "support/report_support.hpp"
#include "support/run_cli.hpp"
#include "support/scratch_dir.hpp"
#include "validation/history.hpp"

namespace sb {
namespace {

namespace fs = std::filesystem;
using test::run_shell;
using test::quoted;
using test::embedded_data;
using test::write_text;
using nlohmann::json;

const fs::path kSource = SB_SOURCE_DIR;

std::vector<json> json_lines(const fs::path& file) {
  std::vector<json> out;
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) out.push_back(json::parse(line));
  return out;
}

/// box-wall at 64x36: the baseline and two reprojection pipelines, one repetition.
constexpr const char* kDefinition = R"([sweep]
name = "nightly-tiny"
scenes = ["box-wall"]
pipelines = ["plain-rt", "repro-rt", "repro-warp"]
baseline = "plain-rt"
resolutions = ["64x36"]
truths = ["full"]

[timing]
repetitions = 1
warmup = 0

[output]
images = true
exr = false
)";

/// A gate both runs pass with a wide margin: the limits are a third below what the tiny sweep
/// measures (deterministic images; timing is not gated here), so the test checks the pass path of
/// nightly, not the pipelines' quality (tests/gate does that).
constexpr const char* kGateConfig = R"([defaults]
min_psnr = 20           # measured: repro-rt 39.88 dB, repro-warp 32.67 dB, plain-rt inf
min_ssim = 0.6          # measured: repro-rt 0.9932, repro-warp 0.9892, plain-rt 1
max_hole_fraction = 0.1 # measured: repro-rt 0.0104, repro-warp 0.0017, plain-rt 0
)";

/// The definition, the gate config and an empty baseline (every time_regression check is then a
/// skip: no entry for the cell) that nightly_args names.
void write_inputs(const test::ScratchDir& dir, const std::string& gate_config = kGateConfig) {
  write_text(dir / "tiny.toml", kDefinition);
  write_text(dir / "gate.toml", gate_config);
  write_text(dir / "empty-baseline.json", "{}\n");
}

/// The nightly command line of the tiny sweep; without `gate_flag` the gate config is the
/// definition's [gate] config (or ci/gate.toml).
std::string nightly_args(const test::ScratchDir& dir, bool gate_flag = true) {
  return "nightly " + quoted(dir / "tiny.toml") + " --out " + quoted(dir / "runs") +
         (gate_flag ? " --gate-config " + quoted(dir / "gate.toml") : std::string()) + " --baseline " +
         quoted(dir / "empty-baseline.json") + " --scenes-dir " + quoted(dir / "scenes") + " --cache '' --threads 1";
}

TEST(NightlyTest, TwoRunsGiveHistoryGateFilesAndTrends) {
  test::ScratchDir dir;
  write_inputs(dir);

  const test::CliRun first = test::run_cli(nightly_args(dir));
  ASSERT_EQ(first.code, 0) << first.out;
  const test::CliRun second = test::run_cli(nightly_args(dir));
  ASSERT_EQ(second.code, 0) << second.out;
  EXPECT_NE(second.out.find("gate verdict: pass (exit 0)"), std::string::npos) << second.out;

  // Two complete run folders named by their UTC start.
  std::vector<fs::path> runs;
  for (const fs::directory_entry& e : fs::directory_iterator(dir / "runs"))
    if (e.is_directory()) runs.push_back(e.path());
  std::sort(runs.begin(), runs.end());
  ASSERT_EQ(runs.size(), 2u);
  const std::regex run_id(R"(\d{8}T\d{6}Z(-\d+)?)");
  for (const fs::path& r : runs) {
    EXPECT_TRUE(std::regex_match(r.filename().string(), run_id)) << r;
    for (const char* f : {"results.jsonl", "gate-junit.xml", "gate.json", "nightly.json", "report/index.html"})
      EXPECT_TRUE(fs::is_regular_file(r / f)) << r / f;
    EXPECT_EQ(json_lines(r / "results.jsonl").size(), 1u) << r;
    const json gate = json::parse(test::read_text(r / "gate.json"));
    EXPECT_EQ(gate["verdict"], "pass") << gate.dump(2);
    EXPECT_NE(test::read_text(r / "gate-junit.xml").find("<testsuites"), std::string::npos);
    // Paths a CI step started elsewhere can open.
    const json done = json::parse(test::read_text(r / "nightly.json"));
    EXPECT_TRUE(fs::path(done["history"].get<std::string>()).is_absolute()) << done.dump();
    EXPECT_TRUE(fs::is_regular_file(done["report"].get<std::string>())) << done.dump();
  }

  // Two history lines, one per run, in run order, with every field.
  const std::vector<json> history = json_lines(dir / "runs" / "history.jsonl");
  ASSERT_EQ(history.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    const json& h = history[i];
    EXPECT_NO_THROW(validation::check_history_line(h, "line"));
    EXPECT_EQ(h["run_id"], runs[i].filename().string());
    EXPECT_TRUE(std::regex_match(h["date"].get<std::string>(), std::regex(R"(\d{4}-\d{2}-\d{2}T\d{2}:\d{2}:\d{2}Z)")));
    EXPECT_FALSE(h["host"].get<std::string>().empty());
    // The revision of the work tree holding the definition, as git itself reports it ("unknown"
    // where the build tree lies outside any git work tree).
    const test::CliRun git = run_shell("git -C " + quoted(dir.path()) + " rev-parse --short HEAD 2>/dev/null");
    std::string expected = git.code == 0 ? git.out : "unknown";
    while (!expected.empty() && expected.back() == '\n') expected.pop_back();
    EXPECT_EQ(h["git_revision"], expected);
    if (git.code == 0) {
      EXPECT_TRUE(std::regex_match(expected, std::regex("[0-9a-f]{4,40}"))) << expected;
    }
    EXPECT_EQ(h["sweep"], "nightly-tiny");
    EXPECT_EQ(h["definition_sha256"].get<std::string>().size(), 64u);
    EXPECT_EQ(h["results"], runs[i].filename().string() + "/results.jsonl");
    EXPECT_EQ(h["cells"], 1);
    ASSERT_EQ(h["pipelines"].size(), 3u) << h.dump(2);
    for (const char* p : {"plain-rt", "repro-rt", "repro-warp"}) {
      const json& s = h["pipelines"][p];
      EXPECT_EQ(s["cells"], 1) << p;
      EXPECT_TRUE(s["median_s"].is_number() && s["median_s"].get<double>() > 0.0) << p << s.dump();
      EXPECT_TRUE(s["ssim"].is_number()) << p << s.dump();
      EXPECT_TRUE(s["hole_fraction"].is_number()) << p << s.dump();
      EXPECT_TRUE(s["speedup"].is_number()) << p << s.dump();
    }
    // The baseline renders the truth itself: PSNR infinite; the reprojections are finite.
    EXPECT_EQ(h["pipelines"]["plain-rt"]["psnr"], "inf");
    EXPECT_TRUE(h["pipelines"]["repro-rt"]["psnr"].is_number());
    EXPECT_EQ(h["gate"]["verdict"], "pass");
    EXPECT_EQ(h["gate"]["exit_code"], 0);
    EXPECT_GT(h["gate"]["counts"]["pass"].get<int>(), 0);
    EXPECT_EQ(h["gate"]["counts"]["fail"], 0);
    EXPECT_EQ(h["gate"]["counts"]["warn"], 0);
  }
  EXPECT_LT(history[0]["run_id"].get<std::string>(), history[1]["run_id"].get<std::string>());

  // The second run's report embeds both runs.
  const fs::path index = runs[1] / "report" / "index.html";
  const json data = embedded_data(index);
  ASSERT_TRUE(data.is_object());
  ASSERT_TRUE(data["history"].is_array());
  ASSERT_EQ(data["history"].size(), 2u);
  for (const json& h : data["history"]) EXPECT_TRUE(h["pipelines"]["repro-rt"]["psnr"].is_number());

  // The page in Chromium: the Trends section with one table row and one point per run in each
  // chart, every chart drawn (check_report.mjs, without the viewer's interaction).
  const test::CliRun browser = run_shell("node " + quoted(kSource / "tests" / "report" / "check_report.mjs") + " " +
                                         quoted(index) + " " + quoted(dir / "report.png") + " --quick");
  EXPECT_EQ(browser.code, 0) << browser.out;
  EXPECT_NE(browser.out.find("PSNR per run: 2 datasets of 2 points"), std::string::npos) << browser.out;
  EXPECT_NE(browser.out.find("Median time per run: 3 datasets of 2 points"), std::string::npos) << browser.out;
  EXPECT_NE(browser.out.find("Gate verdict per run: 4 datasets of 2 points"), std::string::npos) << browser.out;

  // `stereobench report --history` gives the same section from the history file.
  const test::CliRun report = test::run_cli("report " + quoted(runs[0] / "results.jsonl") + " --out " +
                                            quoted(dir / "report-again") + " --history " +
                                            quoted(dir / "runs" / "history.jsonl"));
  ASSERT_EQ(report.code, 0) << report.out;
  EXPECT_EQ(embedded_data(dir / "report-again" / "index.html")["history"].size(), 2u);

  // A history of 60 nightly runs keeps the trend charts legible (check_report.mjs: the plot at
  // least 45 % of a chart's height, the run labels unrotated); rotated date-times left a strip.
  std::string long_history;
  for (int day = 0; day < 60; ++day) {
    json h = history[static_cast<size_t>(day % 2)];
    const std::string date = fmt::format("2025-{:02}-{:02}", 1 + day / 28, 1 + day % 28);
    h["date"] = date + "T02:00:00Z";
    h["run_id"] = fmt::format("2025{:02}{:02}T020000Z", 1 + day / 28, 1 + day % 28);
    long_history += h.dump() + "\n";
  }
  std::ofstream(dir / "long.jsonl") << long_history;
  const test::CliRun long_report = test::run_cli("report " + quoted(runs[0] / "results.jsonl") + " --out " +
                                                 quoted(dir / "report-long") + " --history " + quoted(dir / "long.jsonl"));
  ASSERT_EQ(long_report.code, 0) << long_report.out;
  const test::CliRun long_browser = run_shell("node " + quoted(kSource / "tests" / "report" / "check_report.mjs") + " " +
                                              quoted(dir / "report-long" / "index.html") + " " +
                                              quoted(dir / "report-long.png") + " --quick");
  EXPECT_EQ(long_browser.code, 0) << long_browser.out;
  EXPECT_NE(long_browser.out.find("Median time per run: 3 datasets of 60 points"), std::string::npos) << long_browser.out;
}

TEST(NightlyTest, ResumesAnUnfinishedRunAndRecordsItOnce) {
  test::ScratchDir dir;
  write_inputs(dir);
  const test::CliRun first = test::run_cli(nightly_args(dir));
  ASSERT_EQ(first.code, 0) << first.out;
  std::vector<fs::path> runs;
  for (const fs::directory_entry& e : fs::directory_iterator(dir / "runs"))
    if (e.is_directory()) runs.push_back(e.path());
  ASSERT_EQ(runs.size(), 1u);
  // As if killed after appending its history line, while writing the report: the run has no
  // nightly.json, and its report folder holds assets but no index.html.
  fs::remove(runs[0] / "nightly.json");
  fs::remove(runs[0] / "report" / "index.html");
  ASSERT_TRUE(fs::is_directory(runs[0] / "report" / "assets"));
  const test::CliRun again = test::run_cli(nightly_args(dir));
  ASSERT_EQ(again.code, 0) << again.out;
  EXPECT_NE(again.out.find("run " + runs[0].filename().string() + " (resumed): 1 cells × 3 pipelines, 1 finished already, 0 to run"),
            std::string::npos)
      << again.out;
  EXPECT_NE(again.out.find("not appended again"), std::string::npos) << again.out;
  EXPECT_TRUE(fs::is_regular_file(runs[0] / "nightly.json"));
  EXPECT_TRUE(fs::is_regular_file(runs[0] / "report" / "index.html")) << "the half-written report was replaced";
  EXPECT_EQ(json_lines(dir / "runs" / "history.jsonl").size(), 1u);
  size_t folders = 0;
  for (const fs::directory_entry& e : fs::directory_iterator(dir / "runs")) folders += e.is_directory() ? 1 : 0;
  EXPECT_EQ(folders, 1u);
}

TEST(NightlyTest, ARunStoppedBeforeItsFirstCellDoesNotHoldBackAnEditedDefinition) {
  // A nightly stopped before its first cell was recorded leaves a run folder whose sweep marker
  // names the definition but no results line. With the definition edited, the next nightly took
  // that folder for its own (no line to tell otherwise) and the sweep then refused it, on every
  // run until the folder was removed by hand.
  test::ScratchDir dir;
  write_inputs(dir);
  const test::CliRun first = test::run_cli(nightly_args(dir));
  ASSERT_EQ(first.code, 0) << first.out;
  fs::path run;
  for (const fs::directory_entry& e : fs::directory_iterator(dir / "runs"))
    if (e.is_directory()) run = e.path();
  ASSERT_FALSE(run.empty());
  fs::remove(run / "nightly.json");
  fs::remove(run / "results.jsonl");
  ASSERT_TRUE(fs::exists(run / ".stereobench-sweep.json"));
  std::string edited = kDefinition;
  edited.replace(edited.find("repetitions = 1"), 15, "repetitions = 2");
  write_text(dir / "tiny.toml", edited);
  const test::CliRun again = test::run_cli(nightly_args(dir));
  ASSERT_EQ(again.code, 0) << again.out;
  EXPECT_NE(again.out.find("note: the unfinished run " + run.string() + " is not a run of "),
            std::string::npos)
      << again.out;
  size_t folders = 0;
  for (const fs::directory_entry& e : fs::directory_iterator(dir / "runs")) folders += e.is_directory() ? 1 : 0;
  EXPECT_EQ(folders, 2u) << "a new run, the stopped one left as it was";
  EXPECT_FALSE(fs::exists(run / "results.jsonl"));
  // Unedited, such a run is resumed.
  const fs::path resumed_run = [&] {
    fs::path newest;
    for (const fs::directory_entry& e : fs::directory_iterator(dir / "runs"))
      if (e.is_directory() && e.path().filename() > newest.filename()) newest = e.path();
    return newest;
  }();
  fs::remove(resumed_run / "nightly.json");
  fs::remove(resumed_run / "results.jsonl");
  const test::CliRun third = test::run_cli(nightly_args(dir));
  ASSERT_EQ(third.code, 0) << third.out;
  EXPECT_NE(third.out.find("run " + resumed_run.filename().string() + " (resumed)"), std::string::npos) << third.out;
}

TEST(NightlyTest, AnUnfinishedRunOfAnotherPipelineSetIsLeftForANewRun) {
  // An unfinished run whose cells a build with other pipelines recorded (a definition listing
  // "all" follows the build): resumed, it took this build's cells beside them, the results file
  // then held two pipeline sets, and every later nightly chose that run again and stopped on it.
  test::ScratchDir dir;
  write_inputs(dir);
  ASSERT_EQ(test::run_cli(nightly_args(dir)).code, 0);
  fs::path run;
  for (const fs::directory_entry& e : fs::directory_iterator(dir / "runs"))
    if (e.is_directory()) run = e.path();
  ASSERT_FALSE(run.empty());
  fs::remove(run / "nightly.json");  // unfinished
  std::vector<json> cells = json_lines(run / "results.jsonl");
  ASSERT_EQ(cells.size(), 1u);
  cells[0]["pipelines"].erase("repro-warp");
  write_text(run / "results.jsonl", cells[0].dump() + "\n");
  const test::CliRun again = test::run_cli(nightly_args(dir));
  ASSERT_EQ(again.code, 0) << again.out;
  EXPECT_NE(again.out.find("note: the unfinished run " + run.string() + " is not a run of "), std::string::npos)
      << again.out;
  EXPECT_EQ(json_lines(run / "results.jsonl").size(), 1u) << "the older run left as it was";
  size_t folders = 0;
  for (const fs::directory_entry& e : fs::directory_iterator(dir / "runs")) folders += e.is_directory() ? 1 : 0;
  EXPECT_EQ(folders, 2u);
}

TEST(NightlyTest, FailingGateExitsTwoAndIsRecorded) {
  test::ScratchDir dir;
  // 45 dB is above both reprojections' PSNR (39.88 and 32.67 dB measured); plain-rt is inf.
  write_inputs(dir, "[defaults]\nmin_psnr = 45\n");
  const test::CliRun r = test::run_cli(nightly_args(dir));
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("gate verdict: fail (exit 2)"), std::string::npos) << r.out;
  const std::vector<json> history = json_lines(dir / "runs" / "history.jsonl");
  ASSERT_EQ(history.size(), 1u);
  EXPECT_EQ(history[0]["gate"]["verdict"], "fail");
  EXPECT_EQ(history[0]["gate"]["exit_code"], 2);
  EXPECT_EQ(history[0]["gate"]["counts"]["fail"], 2);  // the PSNR of repro-rt and repro-warp
  EXPECT_EQ(history[0]["gate"]["counts"]["pass"], 2);  // plain-rt's infinite PSNR; the sweep is complete
}

TEST(NightlyTest, DefinitionNamesItsGateConfigAndTheFlagOverridesIt) {
  test::ScratchDir dir;
  write_inputs(dir);  // gate.toml passes
  // The definition's own gate config (relative to the definition) fails: 45 dB is above both
  // reprojections' PSNR (39.88 and 32.67 dB measured).
  write_text(dir / "tiny.toml", std::string(kDefinition) + "\n[gate]\nconfig = \"strict-gate.toml\"\n");
  write_text(dir / "strict-gate.toml", "[defaults]\nmin_psnr = 45\n");
  const test::CliRun r = test::run_cli(nightly_args(dir, false));
  EXPECT_EQ(r.code, 2) << r.out;
  const std::vector<json> history = json_lines(dir / "runs" / "history.jsonl");
  ASSERT_EQ(history.size(), 1u);
  EXPECT_EQ(history[0]["gate"]["counts"]["fail"], 2);
  const fs::path run = dir / "runs" / history[0]["run_id"].get<std::string>();
  const json gate = json::parse(test::read_text(run / "gate.json"));
  EXPECT_EQ(fs::path(gate["config"].get<std::string>()), dir / "strict-gate.toml") << gate["config"];

  // --gate-config wins over the definition's: the next run (same sweep, cells already measured in a
  // new run folder) passes.
  const test::CliRun r2 = test::run_cli(nightly_args(dir, true));
  EXPECT_EQ(r2.code, 0) << r2.out;

  // A [gate] config that does not exist is bad input naming the definition and the path.
  write_text(dir / "tiny.toml", std::string(kDefinition) + "\n[gate]\nconfig = \"missing.toml\"\n");
  const test::CliRun r3 = test::run_cli(nightly_args(dir, false));
  EXPECT_EQ(r3.code, 3) << r3.out;
  EXPECT_NE(r3.out.find("missing.toml"), std::string::npos) << r3.out;
  EXPECT_NE(r3.out.find("[gate] config"), std::string::npos) << r3.out;
}

TEST(NightlyTest, MalformedHistoryIsBadInputNamingFileAndLine) {
  test::ScratchDir dir;
  write_inputs(dir);
  const fs::path history = dir / "runs" / "history.jsonl";
  write_text(history, "\n{\"kind\": \"stereobench.nightly_run\", \"schema_version\": 1}\n");
  const test::CliRun r = test::run_cli(nightly_args(dir) + " --history " + quoted(history));
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find(history.string() + ":2:"), std::string::npos) << r.out;
  // Read before the sweep: nothing ran.
  size_t run_folders = 0;
  for (const fs::directory_entry& e : fs::directory_iterator(dir / "runs")) run_folders += e.is_directory() ? 1 : 0;
  EXPECT_EQ(run_folders, 0u);

  // A folder given as the history is bad input, also found before the sweep.
  const test::CliRun folder = test::run_cli(nightly_args(dir) + " --history " + quoted(dir / "runs"));
  EXPECT_EQ(folder.code, 3) << folder.out;
  EXPECT_NE(folder.out.find("--history " + (dir / "runs").string() + " is a folder; give the JSON Lines file"),
            std::string::npos)
      << "names the option: " << folder.out;
  run_folders = 0;
  for (const fs::directory_entry& e : fs::directory_iterator(dir / "runs")) run_folders += e.is_directory() ? 1 : 0;
  EXPECT_EQ(run_folders, 0u);

  // A usage error makes no folder.
  const test::CliRun bad_threads = test::run_cli("nightly " + quoted(dir / "tiny.toml") + " --out " +
                                                 quoted(dir / "never") + " --threads -3");
  EXPECT_EQ(bad_threads.code, 3) << bad_threads.out;
  EXPECT_FALSE(fs::exists(dir / "never")) << bad_threads.out;

  // A history that cannot be appended to (its folder is a file) is found before the sweep too,
  // named by the flag: it used to fail after the sweep, leaving a passing gate-junit.xml behind.
  write_text(dir / "afile", "x\n");
  const test::CliRun blocked = test::run_cli(nightly_args(dir) + " --history " + quoted(dir / "afile" / "h.jsonl"));
  EXPECT_EQ(blocked.code, 4) << blocked.out;
  EXPECT_NE(blocked.out.find("--history " + (dir / "afile" / "h.jsonl").string() + ": cannot make its folder"),
            std::string::npos)
      << blocked.out;
  run_folders = 0;
  for (const fs::directory_entry& e : fs::directory_iterator(dir / "runs")) run_folders += e.is_directory() ? 1 : 0;
  EXPECT_EQ(run_folders, 0u);

  // A gate config of [regression] alone with no baseline file would check nothing: refused before
  // the sweep, not after it.
  write_text(dir / "reg-only.toml", "[regression]\ntolerance = 0.1\n");
  // Run from the scratch folder, where the default baseline (ci/baseline.json) does not exist.
  const test::CliRun reg_only =
      run_shell("cd " + quoted(dir.path()) + " && " + SB_CLI_PATH + " nightly " + quoted(dir / "tiny.toml") + " --out " +
                quoted(dir / "runs") + " --history " + quoted(dir / "fresh.jsonl") + " --gate-config " +
                quoted(dir / "reg-only.toml") + " --scenes-dir " +
                quoted(dir / "scenes") + " --cache '' --threads 1");
  EXPECT_EQ(reg_only.code, 3) << reg_only.out;
  EXPECT_NE(reg_only.out.find("sets no threshold, only [regression], and there is no baseline file ci/baseline.json"),
            std::string::npos)
      << reg_only.out;
  // ... and so would one with a baseline of another sweep's cells (found only after every cell ran).
  write_text(dir / "other-baseline.json",
             R"({"spheres|e=default|c=default|64x36|lights=all|full": {"plain-rt": {"samples_s": [0.1], )"
             R"("median_s": 0.1, "recorded": "2026-01-01T00:00:00Z", "host": "h"}}})");
  const test::CliRun foreign =
      test::run_cli("nightly " + quoted(dir / "tiny.toml") + " --out " + quoted(dir / "runs") + " --history " +
                    quoted(dir / "fresh.jsonl") + " --gate-config " + quoted(dir / "reg-only.toml") + " --baseline " +
                    quoted(dir / "other-baseline.json") + " --scenes-dir " + quoted(dir / "scenes") +
                    " --cache '' --threads 1");
  EXPECT_EQ(foreign.code, 3) << foreign.out;
  EXPECT_NE(foreign.out.find("holds no (cell, pipeline) of sweep"), std::string::npos) << foreign.out;
  run_folders = 0;
  for (const fs::directory_entry& e : fs::directory_iterator(dir / "runs")) run_folders += e.is_directory() ? 1 : 0;
  EXPECT_EQ(run_folders, 0u);

  // `report --history` reads the history before the results: the message names the history's line.
  write_text(history, "not json\n");
  const test::CliRun r2 = test::run_cli("report " + quoted(dir / "none.jsonl") + " --out " + quoted(dir / "rep") +
                                        " --history " + quoted(history));
  EXPECT_EQ(r2.code, 3) << r2.out;
  EXPECT_NE(r2.out.find(history.string() + ":1:"), std::string::npos) << r2.out;

  // A bad option is refused before a run folder is made (an empty one would be resumed next time).
  fs::remove(history);
  const test::CliRun threads = test::run_cli(nightly_args(dir) + " --threads -1");
  EXPECT_EQ(threads.code, 3) << threads.out;
  run_folders = 0;
  for (const fs::directory_entry& e : fs::directory_iterator(dir / "runs")) run_folders += e.is_directory() ? 1 : 0;
  EXPECT_EQ(run_folders, 0u);

  // The report comes last, but its missing page assets are a missing tool found before the sweep.
  fs::create_directories(dir / "no-assets");
  const test::CliRun assets =
      run_shell("STEREOBENCH_REPORT_ASSETS=" + quoted(dir / "no-assets") + " " + SB_CLI_PATH + " " + nightly_args(dir));
  EXPECT_EQ(assets.code, 4) << assets.out;
  EXPECT_NE(assets.out.find("report asset " + (dir / "no-assets").string()), std::string::npos) << assets.out;
  run_folders = 0;
  for (const fs::directory_entry& e : fs::directory_iterator(dir / "runs")) run_folders += e.is_directory() ? 1 : 0;
  EXPECT_EQ(run_folders, 0u);
}

TEST(NightlyTest, HistoryLinesWithImpossibleValuesAreRefused) {
  const validation::NightlyRun run{"20261121T200000Z",
                                   "2026-11-21T20:00:00Z",
                                   "host",
                                   "abc1234",
                                   "smoke",
                                   "ci/smoke.toml",
                                   "0123",
                                   "20261121T200000Z/results.jsonl"};
  const json cell = {
      {"pipelines",
       {{"repro-rt",
         {{"validation", {{"metrics", {{"psnr", 41.0}, {"ssim", 0.99}}}, {"holes", {{"hole_fraction", 0.02}}}}},
          {"timing", {{"median_s", 0.5}, {"speedup_median", 1.7}}}}}}}};
  const json good = validation::history_entry(run, {cell}, validation::GateReport{});
  EXPECT_NO_THROW(validation::check_history_line(good, "h:1"));
  // Each of these used to be accepted and drawn in the trend charts.
  const std::pair<std::function<void(json&)>, std::string> cases[] = {
      {[](json& h) { h["cells"] = "1"; }, "\"cells\" must be a count >= 0"},
      {[](json& h) { h["gate"]["exit_code"] = "0"; }, "gate.exit_code \"0\" does not go with verdict \"pass\""},
      {[](json& h) { h["gate"]["exit_code"] = 77; }, "gate.exit_code 77 does not go with verdict"},
      {[](json& h) { h["gate"]["verdict"] = "great"; }, "gate.verdict \"great\" is not"},
      {[](json& h) { h["date"] = "not a date"; }, "\"date\" \"not a date\" is not a UTC time"},
      {[](json& h) { h["pipelines"]["repro-rt"]["ssim"] = 9.96; }, "pipelines.repro-rt.ssim is 9.96, outside [-1, 1]"},
      {[](json& h) { h["pipelines"]["repro-rt"]["median_s"] = -0.5; }, "pipelines.repro-rt.median_s is -0.5"},
      {[](json& h) { h["pipelines"]["repro-rt"]["cells"] = -1; }, "pipelines.repro-rt.cells must be a count"},
      {[](json& h) { h["date"] = "2026-02-30T23:00:00Z"; }, "\"date\" \"2026-02-30T23:00:00Z\" is not a UTC time"},
      {[](json& h) { h["pipelines"]["repro-rt"]["median_s"] = "inf"; }, "pipelines.repro-rt.median_s is \"inf\""},
      {[](json& h) { h["pipelines"]["repro-rt"]["speedup"] = "inf"; }, "pipelines.repro-rt.speedup is \"inf\""},
  };
  for (const auto& [edit, expect] : cases) {
    json h = good;
    edit(h);
    try {
      validation::check_history_line(h, "h:1");
      ADD_FAILURE() << "accepted: " << h.dump();
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("h:1: " + expect), std::string::npos) << e.what();
    }
  }
}

TEST(NightlyTest, RunFoldersWithLongSuffixesOrderWithoutOverflow) {
  // Folders of earlier runs, finished, one with a suffix beyond any int: the new run orders after
  // them (it said "internal error: stoi", exit 4).
  test::ScratchDir dir;
  write_inputs(dir);
  for (const char* id : {"20200101T000000Z", "20200101T000000Z-99999999999", "20200101T000000Z-7"}) {
    fs::create_directories(dir / "runs" / id);
    write_text(dir / "runs" / id / "nightly.json", "{}\n");  // the file a finished run leaves
  }
  const test::CliRun r = test::run_cli(nightly_args(dir));
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find(" (new): "), std::string::npos) << "a new run, none resumed: " << r.out;
}

TEST(NightlyTest, AReportFolderThatCannotTakeTheReportIsRefusedBeforeTheSweep) {
  // An unfinished run whose report path is a file: found before any cell runs, named as the run's
  // report folder (it was found after the sweep and history line, and called nightly's --out).
  test::ScratchDir dir;
  write_inputs(dir);
  const fs::path run = dir / "runs" / "20200101T000000Z";
  fs::create_directories(run);
  write_text(run / "report", "not a folder\n");
  const test::CliRun r = test::run_cli(nightly_args(dir));
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find("the run's report folder " + (run / "report").string() + " is a file"), std::string::npos)
      << r.out;
  EXPECT_FALSE(fs::exists(run / "results.jsonl")) << "no cell ran";
  EXPECT_FALSE(fs::exists(dir / "runs" / "history.jsonl")) << "no run was recorded";
}

TEST(NightlyTest, AHistoryThatCannotBeWrittenLeavesNoRunFolder) {
  // A --history whose folder cannot be made (a file is in the way) is refused before --out is
  // made: it left an empty --out behind.
  test::ScratchDir dir;
  write_inputs(dir);
  write_text(dir / "a-file", "x\n");
  const test::CliRun r = test::run_cli(nightly_args(dir) + " --history " + quoted(dir / "a-file" / "history.jsonl"));
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("cannot make its folder"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "runs")) << r.out;
}

TEST(NightlyTest, SweepsSharingAHistoryKeepTheirRunsApart) {
  // Two sweeps, one history: a new run takes an id no line of the history has (it used to take the
  // other sweep's id of the same second and was silently not recorded), its trends show its own
  // sweep's runs only, and a resumed run whose id another sweep's line took is refused.
  test::ScratchDir dir;
  write_inputs(dir);
  const std::string history = quoted(dir / "shared.jsonl");
  const test::CliRun a = test::run_cli(nightly_args(dir) + " --history " + history);
  ASSERT_EQ(a.code, 0) << a.out;
  const std::vector<json> lines = json_lines(dir / "shared.jsonl");
  ASSERT_EQ(lines.size(), 1u);
  // Lines of another sweep for every second of the next two minutes.
  std::string others;
  size_t other_runs = 0;
  const std::time_t now = std::time(nullptr);
  for (std::time_t t = now; t < now + 120; ++t) {
    std::tm utc{};
    gmtime_r(&t, &utc);
    std::array<char, 32> id{}, date{};
    std::strftime(id.data(), id.size(), "%Y%m%dT%H%M%SZ", &utc);
    std::strftime(date.data(), date.size(), "%Y-%m-%dT%H:%M:%SZ", &utc);
    if (lines[0]["run_id"] == id.data()) continue;
    json other = lines[0];
    other["run_id"] = id.data();
    other["date"] = date.data();
    other["sweep"] = "other-sweep";
    other["results"] = std::string("elsewhere/") + id.data() + "/results.jsonl";
    others += other.dump() + "\n";
    ++other_runs;
  }
  std::ofstream(dir / "shared.jsonl", std::ios::app) << others;

  std::string b_args = nightly_args(dir) + " --history " + history;
  b_args.replace(b_args.find(" --out " + quoted(dir / "runs")), (" --out " + quoted(dir / "runs")).size(),
                 " --out " + quoted(dir / "runs-b"));
  const test::CliRun b = test::run_cli(b_args);
  ASSERT_EQ(b.code, 0) << b.out;
  const std::vector<json> after = json_lines(dir / "shared.jsonl");
  ASSERT_EQ(after.size(), other_runs + 2) << "the run was recorded";
  const std::string b_id = after.back()["run_id"].get<std::string>();
  EXPECT_TRUE(std::regex_match(b_id, std::regex(R"(\d{8}T\d{6}Z-2)"))) << b_id;
  EXPECT_TRUE(fs::is_directory(dir / "runs-b" / b_id));
  EXPECT_EQ(after.back()["results"], "runs-b/" + b_id + "/results.jsonl");
  EXPECT_NE(b.out.find(fmt::format("note: the trends leave out {} runs of other sweeps", other_runs)), std::string::npos)
      << b.out;
  const json page = embedded_data(dir / "runs-b" / b_id / "report" / "index.html");
  EXPECT_NE(page["history_note"].get<std::string>().find(fmt::format("leave out {} runs of other sweeps", other_runs)),
            std::string::npos)
      << "the page says it too";
  // By the history file's name alone: the page names no folder of this machine.
  EXPECT_EQ(page["history_note"].get<std::string>().find(dir.path().string()), std::string::npos) << page["history_note"];
  const json trends = page["history"];
  ASSERT_EQ(trends.size(), 2u) << trends.dump();
  for (const json& r : trends) EXPECT_EQ(r["sweep"], "nightly-tiny");
  // `report --history` draws the same trends (it drew every sweep's runs, without a word).
  const test::CliRun rep = test::run_cli("report " + quoted(dir / "runs-b" / b_id / "results.jsonl") + " --out " +
                                         quoted(dir / "rep-b") + " --history " + history);
  ASSERT_EQ(rep.code, 0) << rep.out;
  EXPECT_NE(rep.out.find(fmt::format("note: the trends leave out {} runs of other sweeps", other_runs)),
            std::string::npos)
      << rep.out;
  const json again = embedded_data(dir / "rep-b" / "index.html");
  EXPECT_EQ(again["history"], trends);

  // An unfinished run folder named as another sweep's recorded run: resuming it is refused before
  // any cell runs.
  const std::string taken = after[1]["run_id"].get<std::string>();
  fs::create_directories(dir / "runs-c" / taken);
  std::string c_args = b_args;
  c_args.replace(c_args.find(quoted(dir / "runs-b")), quoted(dir / "runs-b").size(), quoted(dir / "runs-c"));
  const test::CliRun c = test::run_cli(c_args);
  EXPECT_EQ(c.code, 3) << c.out;
  EXPECT_NE(c.out.find("already holds a run " + taken + " of another results file"), std::string::npos) << c.out;
  EXPECT_FALSE(fs::exists(dir / "runs-c" / taken / "results.jsonl")) << "no cell ran";
  EXPECT_EQ(json_lines(dir / "shared.jsonl").size(), other_runs + 2);
}


/// The nightly command line of the tiny sweep with `out` and `history` in place of the defaults.
std::string nightly_args_into(const test::ScratchDir& dir, const std::string& out, const fs::path& history) {
  std::string args = nightly_args(dir) + " --history " + quoted(history);
  const std::string runs = " --out " + quoted(dir / "runs");
  args.replace(args.find(runs), runs.size(), " --out " + quoted(dir / out));
  return args;
}

TEST(NightlyTest, ConcurrentRunsSharingAHistoryTakeDifferentIds) {
  // Two runs into their own --out, one history, started together: each takes its own id (both
  // used to take the id of their second and append it twice, after which every nightly on that
  // history was refused), both are recorded, and the history stays readable for the next run.
  test::ScratchDir dir;
  write_inputs(dir);
  const fs::path history = dir / "shared.jsonl";
  test::start_cli_in_background(nightly_args_into(dir, "a", history), dir / "a.log");
  test::start_cli_in_background(nightly_args_into(dir, "b", history), dir / "b.log");
  const test::CliRun a = test::wait_for_background(dir / "a.log");
  const test::CliRun b = test::wait_for_background(dir / "b.log");
  ASSERT_EQ(a.code, 0) << a.out;
  ASSERT_EQ(b.code, 0) << b.out;
  const std::vector<json> lines = json_lines(history);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_NE(lines[0]["run_id"], lines[1]["run_id"]);
  for (const json& line : lines) {
    EXPECT_FALSE(fs::exists(validation::run_claim_path(history, line["run_id"].get<std::string>())))
        << "a finished run drops its claim";
  }
  const test::CliRun next = test::run_cli(nightly_args_into(dir, "a", history));
  EXPECT_EQ(next.code, 0) << next.out;
  EXPECT_EQ(json_lines(history).size(), 3u);
}

TEST(NightlyTest, AnIdClaimedByARunningNightlyIsNotTaken) {
  // Runs of another --out sharing the history hold claims on the ids of every second of the next
  // two minutes (as running nightlies do, before their history lines exist): a new run takes the
  // next free id of its second.
  test::ScratchDir dir;
  write_inputs(dir);
  const fs::path history = dir / "shared.jsonl";
  std::vector<io::FileLock> claims;
  {
    const io::FileLock lock = validation::lock_history(history);
    const std::time_t now = std::time(nullptr);
    for (std::time_t t = now; t < now + 120; ++t) {
      std::tm utc{};
      gmtime_r(&t, &utc);
      std::array<char, 32> id{};
      std::strftime(id.data(), id.size(), "%Y%m%dT%H%M%SZ", &utc);
      std::optional<io::FileLock> claim = validation::claim_run_id(history, id.data());
      ASSERT_TRUE(claim.has_value()) << id.data();
      claims.push_back(std::move(*claim));
    }
  }
  const test::CliRun r = test::run_cli(nightly_args_into(dir, "runs-b", history));
  ASSERT_EQ(r.code, 0) << r.out;
  const std::vector<json> lines = json_lines(history);
  ASSERT_EQ(lines.size(), 1u);
  const std::string id = lines[0]["run_id"].get<std::string>();
  EXPECT_TRUE(std::regex_match(id, std::regex(R"(\d{8}T\d{6}Z-2)"))) << id;
  EXPECT_TRUE(fs::is_directory(dir / "runs-b" / id));
}

TEST(NightlyTest, ResumingARunThatAnotherNightlyIsRunningIsRefused) {
  // An unfinished run folder whose id another live nightly holds (the claim, held here): the
  // resume is refused before any cell runs; once that run has gone (its claim free), it resumes.
  test::ScratchDir dir;
  write_inputs(dir);
  const std::string id = "20260101T000000Z";
  fs::create_directories(dir / "runs" / id);
  const fs::path history = dir / "runs" / "history.jsonl";
  {
    std::optional<io::FileLock> claim = validation::claim_run_id(history, id);
    ASSERT_TRUE(claim.has_value());
    const test::CliRun r = test::run_cli(nightly_args(dir));
    EXPECT_EQ(r.code, 3) << r.out;
    EXPECT_NE(r.out.find("the unfinished run " + (dir / "runs" / id).string() +
                         " is being run by another nightly (it holds the claim " +
                         validation::run_claim_path(history, id).string() + " on id " + id + " in " +
                         history.string() + "); wait for that run to end, or give another --out"),
              std::string::npos)
        << r.out;
    EXPECT_FALSE(fs::exists(dir / "runs" / id / "results.jsonl")) << "no cell ran";
  }
  // The claim of a run that was killed stays behind, free: the run resumes under its id.
  ASSERT_TRUE(fs::exists(validation::run_claim_path(history, id)));
  const test::CliRun again = test::run_cli(nightly_args(dir));
  ASSERT_EQ(again.code, 0) << again.out;
  EXPECT_NE(again.out.find("run " + id + " (resumed)"), std::string::npos) << again.out;
  EXPECT_FALSE(fs::exists(validation::run_claim_path(history, id))) << "the finished run dropped its claim";
}

TEST(NightlyTest, AFinalWriteThatFailsLeavesNoVerdict) {
  // gate-junit.xml, gate.json and nightly.json are written one after the other: when one fails (a
  // full disk; here gate.json is a link to /dev/full, which a run leaves in place), the ones
  // already written go, so that the stopped run (exit 4) leaves no verdict behind.
  test::ScratchDir dir;
  write_inputs(dir);
  const fs::path run = dir / "runs" / "20260101T000000Z";
  fs::create_directories(run);
  fs::create_symlink("/dev/full", run / "gate.json");
  const test::CliRun r = test::run_cli(nightly_args(dir));
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("gate.json"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(run / "gate-junit.xml")) << "the JUnit file written before was removed";
  EXPECT_FALSE(fs::exists(run / "nightly.json"));
  EXPECT_TRUE(fs::exists(run / "results.jsonl")) << "the run was resumed and ran its cells";
}

}  // namespace
}  // namespace sb
