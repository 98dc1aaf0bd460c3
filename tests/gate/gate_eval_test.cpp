// The gate on hand-written results lines: verdicts and exit codes (pass 0, warn 1, fail 2, bad
// input 3), the time regression against a baseline, baseline updates that touch only what is
// named, and JUnit XML that validates against ci/junit.xsd.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "gate/gate_fixture.hpp"
#include "renderer/error.hpp"
#include "renderer/io/file_lock.hpp"
#include "support/lock_wait.hpp"
#include "support/run_cli.hpp"
#include "support/scratch_dir.hpp"
#include "validation/gate.hpp"
#include "validation/junit.hpp"

namespace sb::test {
namespace {

using nlohmann::json;
using validation::Verdict;

const std::string kConfig =
    "[defaults]\n"
    "min_psnr = 30\nwarn_psnr = 35\n"
    "min_ssim = 0.99\n"
    "max_hole_fraction = 0.05\n"
    "[regression]\ntolerance = 0.10\nalpha = 0.05\nmin_repetitions = 3\n"
    "[[rule]]\npipeline = \"repro-rt\"\nmin_psnr = 40\nmin_recall = 0.99\nmin_speedup = 1.2\n";

/// Two cells of two pipelines that pass kConfig: PSNR 45 and 44 dB against limits 40 and 30.
std::vector<json> passing_cells() {
  return {fake_cell(0, 0.064, {{"plain-rt", 90, 1.0, 0, 0, 1, 1.0}, {"repro-rt", 45}}),
          fake_cell(1, 0.12, {{"plain-rt", 90, 1.0, 0, 0, 1, 1.0}, {"repro-rt", 44}})};
}

validation::GateReport evaluate(const std::vector<json>& cells, const validation::Baseline& baseline = {},
                                const std::string& config = kConfig) {
  return validation::evaluate_gate(validation::parse_gate_config(config, "test.toml"),
                                   validation::gate_results(cells, {}, "results.jsonl"), baseline);
}

const validation::GateCheck* find_check(const validation::GateReport& r, const std::string& pipeline,
                                        const std::string& check, int cell = 0) {
  int seen = -1;
  std::string last_cell;
  for (const validation::GateCheck& c : r.checks) {
    if (c.cell_id != last_cell) {
      last_cell = c.cell_id;
      ++seen;
    }
    if (seen == cell && c.pipeline == pipeline && c.check == check) return &c;
  }
  return nullptr;
}

TEST(GateEval, TimeRegressionsOnlyWhereTheConfigAsks) {
  validation::Baseline baseline;
  const std::vector<json> cells = passing_cells();
  for (const char* p : {"plain-rt", "repro-rt"}) baseline.cells[cells[0]["cell_id"].get<std::string>()][p].samples_s = {0.01, 0.01, 0.01};
  // No [regression] table and no rule's regression_tolerance: no time regression check at all.
  const std::string thresholds_only = "[defaults]\nmin_psnr = 30\n";
  validation::GateReport r = evaluate(cells, baseline, thresholds_only);
  EXPECT_EQ(find_check(r, "repro-rt", "time_regression"), nullptr);
  // A rule's tolerance turns it on for its cells alone, also as the config's only check (that
  // config was refused as one that "would pass anything").
  for (const std::string& before : {thresholds_only, std::string()}) {
    r = evaluate(cells, baseline, before + "[[rule]]\npipeline = \"repro-rt\"\nregression_tolerance = 0.2\n");
    EXPECT_NE(find_check(r, "repro-rt", "time_regression"), nullptr);
    EXPECT_EQ(find_check(r, "plain-rt", "time_regression"), nullptr);
  }
}

TEST(GateEval, PassingCellsPass) {
  const validation::GateReport r = evaluate(passing_cells());
  EXPECT_EQ(r.worst, Verdict::skip);  // only the time regression is skipped (no baseline)
  EXPECT_EQ(validation::exit_code(r.worst), 0);
  const validation::GateCheck* psnr = find_check(r, "repro-rt", "psnr");
  ASSERT_NE(psnr, nullptr);
  EXPECT_EQ(psnr->verdict, Verdict::pass);
  EXPECT_EQ(psnr->fail_limit, 40.0);  // the rule overrides the default 30
  const validation::GateCheck* reg = find_check(r, "repro-rt", "time_regression");
  ASSERT_NE(reg, nullptr);
  EXPECT_EQ(reg->verdict, Verdict::skip);
  EXPECT_EQ(reg->message, "no baseline");
  // plain-rt has no recall or speed-up threshold: no such check.
  EXPECT_EQ(find_check(r, "plain-rt", "speedup"), nullptr);
}

TEST(GateEval, AValueJustBeyondItsLimitIsShownApartFromIt) {
  // Both used to be rounded alike: "PSNR 40.00 dB is below the minimum 40.00 dB".
  std::vector<json> cells = passing_cells();
  test::set_psnr(cells[0]["pipelines"]["repro-rt"]["validation"]["metrics"], 39.999999);
  const validation::GateReport near = evaluate(cells);
  const validation::GateCheck* psnr = find_check(near, "repro-rt", "psnr", 0);
  ASSERT_NE(psnr, nullptr);
  EXPECT_EQ(psnr->verdict, Verdict::fail);
  EXPECT_NE(psnr->message.find("39.999999 dB is below the minimum 40 dB"), std::string::npos) << psnr->message;
  test::set_psnr(cells[0]["pipelines"]["repro-rt"]["validation"]["metrics"], 39.5);
  const validation::GateReport beyond = evaluate(cells);
  const validation::GateCheck* far = find_check(beyond, "repro-rt", "psnr", 0);
  ASSERT_NE(far, nullptr);
  EXPECT_NE(far->message.find("39.50 dB is below the minimum 40.00 dB"), std::string::npos) << far->message;
}

TEST(GateEval, AQualityMetricTheRecordLacksFailsAndAnUndefinedRecallIsSkipped) {
  // A null PSNR (a damaged record) used to be skipped, so the gate passed with no PSNR read.
  std::vector<json> cells = passing_cells();
  test::set_psnr(cells[0]["pipelines"]["repro-rt"]["validation"]["metrics"], nullptr);
  cells[1]["pipelines"]["repro-rt"]["validation"]["metrics"]["ssim"] = nullptr;
  cells[0]["pipelines"]["repro-rt"]["validation"]["holes"]["not_reprojected"]["recall"] = nullptr;
  const validation::GateReport r = evaluate(cells);
  const validation::GateCheck* psnr = find_check(r, "repro-rt", "psnr", 0);
  ASSERT_NE(psnr, nullptr);
  EXPECT_EQ(psnr->verdict, Verdict::fail);
  EXPECT_NE(psnr->message.find("no PSNR in the record (/validation/metrics/psnr is null); the record is damaged"),
            std::string::npos)
      << psnr->message;
  const validation::GateCheck* ssim = find_check(r, "repro-rt", "ssim", 1);
  ASSERT_NE(ssim, nullptr);
  EXPECT_EQ(ssim->verdict, Verdict::fail);
  EXPECT_NE(ssim->message.find("no SSIM in the record (/validation/metrics/ssim is null)"), std::string::npos)
      << ssim->message;
  const validation::GateCheck* recall = find_check(r, "repro-rt", "disocclusion_recall", 0);
  ASSERT_NE(recall, nullptr);
  EXPECT_EQ(recall->verdict, Verdict::skip);
  EXPECT_EQ(r.worst, Verdict::fail);
  // An SSIM undefined for the image itself (narrower than its 11x11 window: no pixel measured)
  // is skipped, not blamed on the record.
  cells[1]["pipelines"]["repro-rt"]["validation"]["metrics"]["ssim_pixels"] = 0;
  const validation::GateReport undefined = evaluate(cells);
  const validation::GateCheck* small = find_check(undefined, "repro-rt", "ssim", 1);
  ASSERT_NE(small, nullptr);
  EXPECT_EQ(small->verdict, Verdict::skip);
  EXPECT_NE(small->message.find("undefined for this image (/validation/metrics/ssim_pixels is 0)"), std::string::npos)
      << small->message;
}

TEST(GateEval, ThresholdAboveTheMeasuredValueFails) {
  // repro-rt measured 45 dB; a minimum of 45.5 dB must fail.
  const std::string config = kConfig + "[[rule]]\npipeline = \"repro-rt\"\nscene = \"box-wall\"\nmin_psnr = 45.5\n";
  const validation::GateReport r = evaluate(passing_cells(), {}, config);
  EXPECT_EQ(r.worst, Verdict::fail);
  const validation::GateCheck* psnr = find_check(r, "repro-rt", "psnr");
  ASSERT_NE(psnr, nullptr);
  EXPECT_EQ(psnr->verdict, Verdict::fail);
  EXPECT_DOUBLE_EQ(psnr->measured, 45.0);
  EXPECT_EQ(psnr->fail_limit, 45.5);
  EXPECT_NE(psnr->message.find("45.00 dB"), std::string::npos) << psnr->message;
  EXPECT_NE(psnr->message.find("45.50 dB"), std::string::npos) << psnr->message;
  EXPECT_EQ(psnr->reproduce,
            "stereobench validate --scene box-wall --pipelines repro-rt --truth full --resolution 320x180 "
            "--interaxial 0.064 --convergence 2");
}

TEST(GateEval, AHugeLimitIsShownInExponentFormNotAsThreeHundredDigits) {
  const std::string config = kConfig + "[[rule]]\npipeline = \"repro-rt\"\nmin_speedup = 1e308\n";
  const validation::GateReport r = evaluate(passing_cells(), {}, config);
  const validation::GateCheck* speedup = find_check(r, "repro-rt", "speedup");
  ASSERT_NE(speedup, nullptr);
  EXPECT_EQ(speedup->verdict, Verdict::fail);
  EXPECT_NE(speedup->message.find("is below the minimum 1e+308x"), std::string::npos) << speedup->message;
}

TEST(GateEval, RightEyeShareOfTheLeft) {
  const std::string config = kConfig + "max_right_share = 0.2\nwarn_right_share = 0.18\n";
  std::vector<json> cells = passing_cells();
  auto& first = cells[0]["pipelines"]["repro-rt"]["timing"];
  auto& second = cells[1]["pipelines"]["repro-rt"]["timing"];
  for (const auto& [share, verdict] : std::vector<std::pair<double, Verdict>>{
           {0.15, Verdict::pass}, {0.18, Verdict::pass}, {0.19, Verdict::warn}, {0.2, Verdict::warn}, {0.21, Verdict::fail}}) {
    first["right_over_left_median"] = share;
    const validation::GateReport r = evaluate(cells, {}, config);
    const validation::GateCheck* c = find_check(r, "repro-rt", "right_share");
    ASSERT_NE(c, nullptr);
    EXPECT_EQ(c->verdict, verdict) << share << ": " << c->message;
    EXPECT_DOUBLE_EQ(c->measured, share);
    EXPECT_EQ(find_check(r, "plain-rt", "right_share"), nullptr) << "no level set for plain-rt";
  }
  // A failure says what was measured against which level and reproduces with bench.
  first["right_over_left_median"] = 0.25;
  validation::GateReport r = evaluate(cells, {}, config);
  const validation::GateCheck* c = find_check(r, "repro-rt", "right_share");
  EXPECT_NE(c->message.find("right eye's time over the left eye's 25.0 % is above the maximum 20.0 %"),
            std::string::npos)
      << c->message;
  EXPECT_EQ(c->reproduce.rfind("stereobench bench ", 0), 0u) << c->reproduce;
  // Null (no stage serves the left eye alone) is a skip; so is a record written before the share.
  second["right_over_left_median"] = nullptr;
  first.erase("right_over_left_median");
  r = evaluate(cells, {}, config);
  EXPECT_EQ(find_check(r, "repro-rt", "right_share", 0)->verdict, Verdict::skip);
  EXPECT_EQ(find_check(r, "repro-rt", "right_share", 1)->verdict, Verdict::skip);
  EXPECT_NE(find_check(r, "repro-rt", "right_share", 1)->message.find("is null"), std::string::npos);
  // A warning level above the failure level of a maximum could never be raised: bad input.
  EXPECT_THROW((void)validation::parse_gate_config(kConfig + "max_right_share = 0.2\nwarn_right_share = 0.3\n", "g.toml"),
               InputError);
}

TEST(GateEval, ALeftEyeSynthesizedInPartIsCheckedWhereItWasMeasured) {
  // Limits for every pipeline (a rule after kConfig's repro-rt rule), so that plain-rt's null left
  // eye is where the check is left out, not a missing limit.
  const std::string config =
      kConfig + "[[rule]]\npipeline = \"*\"\nmin_left_psnr = 30\nwarn_left_psnr = 33\nmin_left_ssim = 0.95\n";
  std::vector<json> cells = passing_cells();
  // repro-rt of cell 0 as a left eye warped in part (as bidir-warp's is), plain-rt's rendered whole
  // (left_eye null), and cell 1's repro-rt from a record written before left eyes were measured.
  auto& measured = cells[0]["pipelines"]["repro-rt"]["validation"];
  cells[0]["pipelines"]["plain-rt"]["validation"]["left_eye"] = nullptr;
  cells[1]["pipelines"]["plain-rt"]["validation"]["left_eye"] = nullptr;
  for (const auto& [psnr, verdict] : std::vector<std::pair<double, Verdict>>{
           {40.0, Verdict::pass}, {33.0, Verdict::pass}, {31.0, Verdict::warn}, {29.9, Verdict::fail}}) {
    measured["left_eye"] = {{"reference", "plain-rt"}, {"synthesized_pixels", 100}, {"metrics", {{"psnr", psnr}, {"ssim", 0.99}}}};
    const validation::GateReport r = evaluate(cells, {}, config);
    const validation::GateCheck* c = find_check(r, "repro-rt", "left_psnr");
    ASSERT_NE(c, nullptr);
    EXPECT_EQ(c->verdict, verdict) << psnr << ": " << c->message;
    EXPECT_DOUBLE_EQ(c->measured, psnr);
    EXPECT_EQ(find_check(r, "repro-rt", "left_ssim")->verdict, Verdict::pass);
    // A left eye rendered whole has nothing to check: no check, not a skip.
    EXPECT_EQ(find_check(r, "plain-rt", "left_psnr"), nullptr);
    EXPECT_EQ(find_check(r, "plain-rt", "left_psnr", 1), nullptr);
    EXPECT_EQ(find_check(r, "repro-rt", "left_psnr", 1)->verdict, Verdict::skip) << "absent: an older record";
  }
  validation::GateReport r = evaluate(cells, {}, config);
  EXPECT_NE(find_check(r, "repro-rt", "left_psnr")->message.find("left eye's PSNR 29.90 dB is below the minimum 30.00 dB"),
            std::string::npos)
      << find_check(r, "repro-rt", "left_psnr")->message;
  EXPECT_EQ(find_check(r, "repro-rt", "left_psnr")->reproduce.rfind("stereobench validate ", 0), 0u)
      << "validate prints the left eye's measure";
  measured["left_eye"]["metrics"]["ssim"] = 0.94;
  r = evaluate(cells, {}, config);
  EXPECT_EQ(find_check(r, "repro-rt", "left_ssim")->verdict, Verdict::fail);
  // Without its left_eye field at all (an older record), plain-rt's check is made and skipped.
  cells[0]["pipelines"]["plain-rt"]["validation"].erase("left_eye");
  r = evaluate(cells, {}, config);
  EXPECT_EQ(find_check(r, "plain-rt", "left_psnr")->verdict, Verdict::skip);
  EXPECT_THROW((void)validation::parse_gate_config(kConfig + "min_left_ssim = 1.5\n", "g.toml"), InputError);
}

TEST(GateEval, WarnLevelsAndEveryMetric) {
  std::vector<json> cells = passing_cells();
  // PSNR 33 dB: above the 30 dB failure level, below the 35 dB warning level.
  test::set_psnr(cells[0]["pipelines"]["plain-rt"]["validation"]["metrics"], 33.0);
  validation::GateReport r = evaluate(cells);
  EXPECT_EQ(find_check(r, "plain-rt", "psnr")->verdict, Verdict::warn);
  EXPECT_EQ(r.worst, Verdict::warn);
  EXPECT_EQ(validation::exit_code(r.worst), 1);

  // Each remaining metric beyond its failure level fails on its own.
  cells = passing_cells();
  auto& e = cells[1]["pipelines"]["repro-rt"];
  e["validation"]["metrics"]["ssim"] = 0.98;                     // min 0.99
  e["validation"]["holes"]["hole_fraction"] = 0.06;              // max 0.05
  e["validation"]["holes"]["not_reprojected"]["recall"] = 0.95;  // min 0.99
  e["timing"]["speedup_median"] = 1.1;                           // min 1.2
  r = evaluate(cells);
  for (const char* check : {"ssim", "hole_fraction", "disocclusion_recall", "speedup"})
    EXPECT_EQ(find_check(r, "repro-rt", check, 1)->verdict, Verdict::fail) << check;
  EXPECT_EQ(find_check(r, "repro-rt", "psnr", 1)->verdict, Verdict::pass);

  // PSNR "inf" (identical images) passes any minimum; a null value is reported as a skip.
  cells = passing_cells();
  test::set_psnr(cells[0]["pipelines"]["plain-rt"]["validation"]["metrics"], "inf");
  cells[0]["pipelines"]["repro-rt"]["validation"]["holes"]["not_reprojected"]["recall"] = nullptr;
  r = evaluate(cells);
  EXPECT_EQ(find_check(r, "plain-rt", "psnr")->verdict, Verdict::pass);
  EXPECT_EQ(find_check(r, "repro-rt", "disocclusion_recall")->verdict, Verdict::skip);
  // A value of the wrong type is bad input.
  cells[0]["pipelines"]["repro-rt"]["validation"]["metrics"]["ssim"] = "high";
  EXPECT_THROW((void)evaluate(cells), InputError);
}

TEST(GateEval, TimeRegressionAgainstTheBaseline) {
  std::vector<json> cells = passing_cells();
  const std::string id = cells[0]["cell_id"];
  validation::Baseline baseline;
  baseline.cells[id]["repro-rt"].samples_s = {0.010, 0.0102, 0.0098, 0.0101, 0.0099};
  baseline.cells[id]["repro-rt"].median_s = 0.010;
  // A run's samples, one per repetition.
  const auto run_samples = [&](std::vector<double> samples) {
    json& timing = cells[0]["pipelines"]["repro-rt"]["timing"];
    timing["repetitions"] = samples.size();
    timing["samples_s"] = std::move(samples);
  };

  // 20 % slower in every one of five repetitions: beyond the 10 % tolerance; exact one-sided p =
  // 1/C(10,5) = 0.004 < 0.05: failure.
  run_samples({0.012, 0.0121, 0.0119, 0.0122, 0.0118});
  validation::GateReport r = evaluate(cells, baseline);
  const validation::GateCheck* reg = find_check(r, "repro-rt", "time_regression");
  ASSERT_NE(reg, nullptr);
  EXPECT_EQ(reg->verdict, Verdict::fail) << reg->message;
  EXPECT_NEAR(reg->measured, 0.2, 1e-9);
  EXPECT_NE(reg->message.find("p = 0.00397"), std::string::npos) << reg->message;

  // Median 20 % slower but samples interleaved with the baseline's (U = 15 of 25, exact p = 0.345):
  // beyond the tolerance, not significant: warning.
  run_samples({0.012, 0.0095, 0.0125, 0.0097, 0.013});
  r = evaluate(cells, baseline);
  EXPECT_EQ(find_check(r, "repro-rt", "time_regression")->verdict, Verdict::warn);

  // 5 % slower, significant: within the tolerance, a pass.
  run_samples({0.0105, 0.0106, 0.0104, 0.0107, 0.0103});
  r = evaluate(cells, baseline);
  EXPECT_EQ(find_check(r, "repro-rt", "time_regression")->verdict, Verdict::pass);

  // Two repetitions where three are needed: "not enough repetitions", a warning.
  run_samples({0.010, 0.010});
  r = evaluate(cells, baseline);
  reg = find_check(r, "repro-rt", "time_regression");
  EXPECT_EQ(reg->verdict, Verdict::warn);
  EXPECT_NE(reg->message.find("not enough repetitions"), std::string::npos) << reg->message;

  // A baseline measured with another thread count is not compared: a warning to store one of
  // this machine (a 4-thread baseline against a 2-thread run read as a regression).
  baseline.cells[id]["repro-rt"].threads = 4;
  cells[0]["threads"] = 2;
  run_samples({0.02, 0.0201, 0.0199, 0.0202, 0.0198});
  const validation::GateReport other_threads = evaluate(cells, baseline);
  reg = find_check(other_threads, "repro-rt", "time_regression");
  EXPECT_EQ(reg->verdict, Verdict::warn) << reg->message;
  EXPECT_NE(reg->message.find("not comparable: the baseline was measured with 4 threads, this cell with 2"),
            std::string::npos)
      << reg->message;
  cells[0]["threads"] = 4;
  EXPECT_EQ(find_check(evaluate(cells, baseline), "repro-rt", "time_regression")->verdict, Verdict::fail);
  baseline.cells[id]["repro-rt"].threads.reset();
  run_samples({0.010, 0.010});

  // The other cell and pipeline have no baseline entry.
  EXPECT_EQ(find_check(r, "repro-rt", "time_regression", 1)->message, "no baseline");
  EXPECT_EQ(find_check(r, "plain-rt", "time_regression")->message, "no baseline");
  for (const std::string& n : r.notes) EXPECT_EQ(n.find("no entry for any"), std::string::npos) << n;

  // A record without its samples, where the baseline has an entry: damaged, and it fails (it was
  // skipped, so a damaged file passed).
  cells[0]["pipelines"]["repro-rt"]["timing"].erase("samples_s");
  const validation::GateReport damaged = evaluate(cells, baseline);
  reg = find_check(damaged, "repro-rt", "time_regression");
  EXPECT_EQ(reg->verdict, Verdict::fail);
  EXPECT_NE(reg->message.find("though the baseline has an entry for it"), std::string::npos) << reg->message;

  // A baseline of another sweep: every time check is skipped, and a note says why.
  validation::Baseline other;
  other.cells["elsewhere|320x180"]["repro-rt"] = baseline.cells[id]["repro-rt"];
  r = evaluate(passing_cells(), other);
  ASSERT_FALSE(r.notes.empty());
  EXPECT_NE(r.notes.back().find("the baseline has no entry for any (cell, pipeline) of results.jsonl (its 1 cell(s) "
                                "include 'elsewhere|320x180'"),
            std::string::npos)
      << r.notes.back();
}

TEST(GateEval, CellsAreGatedInCellOrderWhateverOrderTheyFinishedIn) {
  // Parallel jobs append cells as they finish: the same cells give the same report.
  std::vector<json> reversed = passing_cells();
  std::swap(reversed[0], reversed[1]);
  const validation::GateReport a = evaluate(passing_cells()), b = evaluate(reversed);
  EXPECT_EQ(validation::junit_xml(a, "gate"), validation::junit_xml(b, "gate"));
  ASSERT_FALSE(b.checks.empty());
  EXPECT_EQ(b.checks.front().cell_id, passing_cells()[0]["cell_id"].get<std::string>());
}

TEST(GateEval, ABaselineUpdateRefusesATimeOfZeroItsReaderWouldRefuse) {
  std::vector<json> cells = passing_cells();
  json& timing = cells[0]["pipelines"]["repro-rt"]["timing"];
  timing["repetitions"] = 3;
  timing["samples_s"] = {0.0, 0.01, 0.01};
  validation::Baseline baseline;
  try {
    (void)validation::update_baseline(baseline, validation::gate_results(cells, {}, "results.jsonl"),
                                      validation::BaselineSelection{{"repro-rt"}, ""});
    ADD_FAILURE() << "a zero time was stored";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("pipeline repro-rt: timing.samples_s holds a time of 0 s"), std::string::npos)
        << e.what();
  }
  EXPECT_TRUE(baseline.empty());
}

TEST(GateEval, AGateThatChecksNothingIsBadInputNotAPass) {
  // Only [regression], and no baseline entry to compare with: every check is skipped.
  const std::string regression_only = "[regression]\ntolerance = 0.1\n";
  try {
    (void)evaluate(passing_cells(), {}, regression_only);
    ADD_FAILURE() << "a gate that checked nothing passed";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("test.toml: none of its checks applies to results.jsonl (2 cells)"), std::string::npos) << m;
    EXPECT_NE(m.find("4 x time_regression: no baseline"), std::string::npos) << m;
    EXPECT_NE(m.find("--update-baseline"), std::string::npos) << m;
  }
  // Limits only for a pipeline the results do not hold: no check at all (without [regression] no
  // time regression is checked either).
  try {
    (void)evaluate(passing_cells(), {}, "[[rule]]\npipeline = \"bidir-warp\"\nmin_psnr = 30\n");
    ADD_FAILURE() << "a gate that checked nothing passed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no limit of it applies to them"), std::string::npos) << e.what();
  }
  // With [regression] the time regressions remain, all skipped without a baseline.
  try {
    (void)evaluate(passing_cells(), {},
                   "[regression]\n[[rule]]\npipeline = \"bidir-warp\"\nmin_psnr = 30\n");
    ADD_FAILURE() << "a gate that checked nothing passed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("every one was skipped (4 x time_regression: no baseline)"), std::string::npos)
        << e.what();
  }
  // Every limit turned off by a rule: no check at all, said as such (it read "skipped ()").
  try {
    (void)evaluate(passing_cells(), {},
                   "[defaults]\nmin_psnr = 30\n[regression]\ntolerance = 0.1\n[[rule]]\nmin_psnr = false\n"
                   "regression_tolerance = false\n");
    ADD_FAILURE() << "a gate that checked nothing passed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("(2 cells): no limit of it applies to them (its rules turn them off"), std::string::npos)
        << e.what();
  }
  // An unfinished sweep whose cells all skip fails its completeness check instead.
  const validation::GateReport incomplete = evaluate({passing_cells()[0]}, {}, regression_only);
  EXPECT_EQ(incomplete.worst, Verdict::fail);
  EXPECT_EQ(validation::exit_code(incomplete.worst), 2);
  // With a baseline entry the regression is measured, and the gate stands.
  const std::vector<json> cells = passing_cells();
  validation::Baseline baseline;
  baseline.cells[cells[0]["cell_id"]]["repro-rt"] = {{0.4, 0.4, 0.4}, 0.4, "earlier", "host"};
  EXPECT_NO_THROW((void)evaluate(cells, baseline, regression_only));

  // Through the command, with a baseline that has no entry for these cells: exit 3, and no JUnit
  // file that could read as a pass.
  ScratchDir dir;
  write_results(dir / "results.jsonl", cells);
  validation::save_baseline(dir / "baseline.json", validation::Baseline{});
  std::ofstream(dir / "gate.toml") << regression_only;
  const CliRun run = run_cli("gate --config " + (dir / "gate.toml").string() + " --results " +
                             (dir / "results.jsonl").string() + " --baseline " + (dir / "baseline.json").string() +
                             " --junit " + (dir / "gate.xml").string());
  EXPECT_EQ(run.code, 3) << run.out;
  EXPECT_NE(run.out.find("none of its checks applies"), std::string::npos) << run.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "gate.xml"));
}

TEST(GateEval, BaselineUpdateTouchesOnlyWhatIsNamed) {
  ScratchDir dir;
  std::vector<json> cells = passing_cells();
  const std::string id0 = cells[0]["cell_id"], id1 = cells[1]["cell_id"];
  // An existing baseline with an entry of each pipeline in cell 0.
  validation::Baseline old;
  old.cells[id0]["plain-rt"] = {{0.5, 0.5, 0.5}, 0.5, "earlier", "oldhost"};
  old.cells[id0]["repro-rt"] = {{0.4, 0.4, 0.4}, 0.4, "earlier", "oldhost"};
  validation::save_baseline(dir / "baseline.json", old);
  // Fields of its own a hand gave an entry stay while the entry is not rewritten (they were
  // dropped from every entry, "every other entry unchanged" notwithstanding).
  json with_notes = json::parse(read_text(dir / "baseline.json"));
  with_notes[id0]["plain-rt"]["note"] = "accepted after the BVH change";
  with_notes["old-cell|x"]["plain-rt"] = {{"samples_s", {1.0}}, {"note", "kept"}};
  write_file(dir / "baseline.json", with_notes.dump(2) + "\n");
  cells[0]["threads"] = 2;  // stored with the entry: a baseline of another thread count is not compared
  write_results(dir / "results.jsonl", cells);

  // No selection: an error that says how to name what to update; the file is unchanged.
  const std::string before = read_text(dir / "baseline.json");
  CliRun run = run_cli("gate --update-baseline --results " + (dir / "results.jsonl").string() + " --baseline " +
                       (dir / "baseline.json").string());
  EXPECT_EQ(run.code, 3) << run.out;
  EXPECT_NE(run.out.find("--only"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("--cells"), std::string::npos) << run.out;
  EXPECT_EQ(read_text(dir / "baseline.json"), before);

  // --only repro-rt: both cells' repro-rt entries rewritten, plain-rt's entry kept as it was.
  run = run_cli("gate --update-baseline --only repro-rt --results " + (dir / "results.jsonl").string() +
                " --baseline " + (dir / "baseline.json").string());
  ASSERT_EQ(run.code, 0) << run.out;
  validation::Baseline now = validation::load_baseline(dir / "baseline.json");
  EXPECT_EQ(now.find(id0, "plain-rt")->samples_s, std::vector<double>({0.5, 0.5, 0.5}));
  EXPECT_EQ(now.find(id0, "plain-rt")->host, "oldhost");
  const json written = json::parse(read_text(dir / "baseline.json"));
  EXPECT_EQ(written[id0]["plain-rt"].value("note", ""), "accepted after the BVH change");
  EXPECT_EQ(written["old-cell|x"]["plain-rt"].value("note", ""), "kept");
  EXPECT_EQ(now.find(id0, "repro-rt")->samples_s, std::vector<double>({0.010, 0.011, 0.012}));
  EXPECT_DOUBLE_EQ(now.find(id0, "repro-rt")->median_s, 0.011);
  EXPECT_EQ(now.find(id0, "repro-rt")->host, "testhost");
  EXPECT_EQ(now.find(id0, "repro-rt")->recorded, "2026-11-21T19:20:00Z");
  EXPECT_EQ(now.find(id0, "repro-rt")->threads, 2);
  EXPECT_EQ(written[id0]["repro-rt"]["threads"], 2);
  EXPECT_FALSE(written[id0]["repro-rt"]["other"].is_object()) << "threads is a field, not kept as a note";
  ASSERT_NE(now.find(id1, "repro-rt"), nullptr);
  EXPECT_EQ(now.find(id1, "plain-rt"), nullptr);
  // Three samples each: as many as the rank test needs, so no warning.
  EXPECT_EQ(run.out.find("warning:"), std::string::npos) << run.out;

  // --cells: only the matching cell, every pipeline in it.
  run = run_cli("gate --update-baseline --cells '*|e=0.12m|*' --results " + (dir / "results.jsonl").string() +
                " --baseline " + (dir / "baseline.json").string());
  ASSERT_EQ(run.code, 0) << run.out;
  now = validation::load_baseline(dir / "baseline.json");
  EXPECT_NE(now.find(id1, "plain-rt"), nullptr);
  EXPECT_EQ(now.find(id0, "plain-rt")->host, "oldhost");

  // A pipeline no cell has, and a pattern that matches nothing: errors.
  run = run_cli("gate --update-baseline --only repro-rtx --results " + (dir / "results.jsonl").string() +
                " --baseline " + (dir / "baseline.json").string());
  EXPECT_EQ(run.code, 3) << run.out;
  EXPECT_NE(run.out.find("repro-rtx"), std::string::npos) << run.out;
  run = run_cli("gate --update-baseline --cells 'spheres|*' --results " + (dir / "results.jsonl").string() +
                " --baseline " + (dir / "baseline.json").string());
  EXPECT_EQ(run.code, 3) << run.out;
  run = run_cli("gate --update-baseline --cells '[lit-plane|*' --results " + (dir / "results.jsonl").string() +
                " --baseline " + (dir / "baseline.json").string());
  EXPECT_EQ(run.code, 3) << run.out;
  EXPECT_NE(run.out.find("--cells '[lit-plane|*' is not a valid glob: the '[' at character 1 opens a set"),
            std::string::npos)
      << run.out;
  // --junit and --json belong to a gate run: refused beside --update-baseline, not ignored.
  const std::string kept = read_text(dir / "baseline.json");
  run = run_cli("gate --update-baseline --only repro-rt --results " + (dir / "results.jsonl").string() +
                " --baseline " + (dir / "baseline.json").string() + " --junit " + (dir / "j.xml").string());
  EXPECT_EQ(run.code, 3) << run.out;
  EXPECT_NE(run.out.find("--junit writes a gate run's checks; --update-baseline only rewrites the baseline"),
            std::string::npos)
      << run.out;
  EXPECT_EQ(read_text(dir / "baseline.json"), kept);

  // A damaged entry is mended by an update that rewrites it (its remedy used to fail on the same
  // damage), and stops one that does not, leaving the file as it was.
  {
    json damaged = json::parse(kept);
    damaged[id0]["repro-rt"]["samples_s"] = "x";
    write_file(dir / "damaged.json", damaged.dump(2));
    run = run_cli("gate --update-baseline --cells '*|e=0.12m|*' --results " + (dir / "results.jsonl").string() +
                  " --baseline " + (dir / "damaged.json").string());
    EXPECT_EQ(run.code, 3) << run.out;
    EXPECT_NE(run.out.find(fmt::format("'{}' / repro-rt: samples_s must be a non-empty array of seconds", id0)),
              std::string::npos)
        << run.out;
    EXPECT_NE(run.out.find("this update does not rewrite it"), std::string::npos) << run.out;
    EXPECT_EQ(read_text(dir / "damaged.json"), damaged.dump(2));
    run = run_cli("gate --update-baseline --only repro-rt --results " + (dir / "results.jsonl").string() +
                  " --baseline " + (dir / "damaged.json").string());
    ASSERT_EQ(run.code, 0) << run.out;
    EXPECT_EQ(validation::load_baseline(dir / "damaged.json").find(id0, "repro-rt")->samples_s,
              std::vector<double>({0.010, 0.011, 0.012}));
  }

  // One timing sample (a smoke sweep's): stored as asked, with a warning that every time check
  // against it can only warn, and how many samples the config's rank test needs.
  std::vector<json> single = passing_cells();
  for (json& cell : single) {
    for (auto& [name, entry] : cell["pipelines"].items()) {
      entry["timing"]["samples_s"] = json::array({0.02});
      entry["timing"]["repetitions"] = 1;
    }
  }
  write_results(dir / "single.jsonl", single);
  write_file(dir / "gate.toml", "[regression]\nmin_repetitions = 5\n");
  run = run_cli("gate --update-baseline --only repro-rt --results " + (dir / "single.jsonl").string() +
                " --baseline " + (dir / "baseline.json").string() + " --config " + (dir / "gate.toml").string());
  ASSERT_EQ(run.code, 0) << run.out;
  EXPECT_EQ(validation::load_baseline(dir / "baseline.json").find(id0, "repro-rt")->samples_s,
            std::vector<double>({0.02}));
  EXPECT_NE(run.out.find("warning: 2 of the 2 stored entries hold fewer than the 5 timing samples the rank test "
                         "needs ([regression] min_repetitions in " +
                         (dir / "gate.toml").string() + "; the fewest: 1)"),
            std::string::npos)
      << run.out;
  // The way out names where repetitions are set (sweep run has no --repetitions option).
  EXPECT_NE(run.out.find("set repetitions = 5 or more in the [timing] table of the sweep's definition"),
            std::string::npos)
      << run.out;
}

TEST(GateJunit, TextBecomesXmlCharactersOnly) {
  // The file declares UTF-8: characters pass, anything that is no XML character (a control
  // character, U+FFFE, an encoded surrogate, a broken or cut-off sequence) becomes '?'.
  EXPECT_EQ(validation::xml_escape("a<b>&\"'", true), "a&lt;b&gt;&amp;&quot;&apos;");
  EXPECT_EQ(validation::xml_escape("\xC3\xA9 \xE2\x82\xAC \xF0\x9F\x98\x80", false), "\xC3\xA9 \xE2\x82\xAC \xF0\x9F\x98\x80");
  for (const char* bad : {"\xEF\xBF\xBE", "\xEF\xBF\xBF", "\xED\xA0\x80", "\x01"})
    EXPECT_EQ(validation::xml_escape(bad, false), "?") << bad;
  EXPECT_EQ(validation::xml_escape("\xC0\xAF", false), "??");        // overlong '/'
  EXPECT_EQ(validation::xml_escape("x\xE2\x82", false), "x??");      // cut off
  EXPECT_EQ(validation::xml_escape("\x80y", false), "?y");            // a lone continuation byte
}

TEST(GateEval, BaselineUpdatesTakeTurns) {
  // Two updates of one baseline at once each read the file and wrote it back, so the one that
  // wrote last dropped the other's entries. An update now waits for the one before it.
  ScratchDir dir;
  write_results(dir / "results.jsonl", passing_cells());
  const std::filesystem::path baseline = dir / "baseline.json";
  const std::string update = "gate --update-baseline --results " + quoted(dir / "results.jsonl") + " --baseline " +
                             quoted(baseline) + " --only ";
  io::FileLock held = io::FileLock::acquire(baseline.string() + ".lock");
  start_cli_in_background(update + "plain-rt", dir / "first.log");
  ASSERT_TRUE(wait_for_lock_waiter(baseline.string() + ".lock")) << read_text(dir / "first.log");
  // While the first waits, another update writes repro-rt's entries.
  held.release();
  const CliRun second = run_cli(update + "repro-rt");
  EXPECT_EQ(second.code, 0) << second.out;
  const CliRun first = wait_for_background(dir / "first.log");
  EXPECT_EQ(first.code, 0) << first.out;
  EXPECT_NE(first.out.find("waiting for another update of " + baseline.string()), std::string::npos) << first.out;
  const validation::Baseline both = validation::load_baseline(baseline);
  for (const auto& [cell, entries] : both.cells) {
    EXPECT_TRUE(entries.count("plain-rt")) << cell;
    EXPECT_TRUE(entries.count("repro-rt")) << cell;
  }
  EXPECT_EQ(both.cells.size(), 2u);
  EXPECT_FALSE(std::filesystem::exists(baseline.string() + ".lock")) << "the lock file stays behind";
}

TEST(GateCli, ExitCodesAndOutputs) {
  ScratchDir dir;
  write_file(dir / "gate.toml", kConfig);
  const std::string config = " --config " + (dir / "gate.toml").string();
  // An empty baseline file: no entries, so no default ci/baseline.json is picked up by accident.
  write_file(dir / "baseline.json", "{}\n");
  const std::string baseline = " --baseline " + (dir / "baseline.json").string();

  // All pass: 0.
  write_results(dir / "pass.jsonl", passing_cells());
  CliRun run = run_cli("gate" + config + baseline + " --results " + (dir / "pass.jsonl").string());
  EXPECT_EQ(run.code, 0) << run.out;
  EXPECT_NE(run.out.find("0 fail"), std::string::npos) << run.out;

  // A warning only: 1.
  std::vector<json> cells = passing_cells();
  test::set_psnr(cells[1]["pipelines"]["plain-rt"]["validation"]["metrics"], 33.0);
  write_results(dir / "warn.jsonl", cells);
  run = run_cli("gate" + config + baseline + " --results " + (dir / "warn.jsonl").string());
  EXPECT_EQ(run.code, 1) << run.out;
  EXPECT_NE(run.out.find("WARN"), std::string::npos) << run.out;

  // A failure: 2, with the reproduce command in the table, the JSON and the JUnit XML.
  test::set_psnr(cells[0]["pipelines"]["repro-rt"]["validation"]["metrics"], 39.0);  // min 40
  write_results(dir / "fail.jsonl", cells);
  run = run_cli("gate" + config + baseline + " --results " + (dir / "fail.jsonl").string() + " --junit " +
                (dir / "junit.xml").string() + " --json " + (dir / "gate.json").string());
  EXPECT_EQ(run.code, 2) << run.out;
  const std::string repro =
      "stereobench validate --scene box-wall --pipelines repro-rt --truth full --resolution 320x180 --interaxial "
      "0.064 --convergence 2";
  EXPECT_NE(run.out.find("reproduce: " + repro), std::string::npos) << run.out;
  const json gate = json::parse(read_text(dir / "gate.json"));
  EXPECT_EQ(gate["exit_code"], 2);
  EXPECT_EQ(gate["counts"]["fail"], 1);
  EXPECT_EQ(gate["counts"]["warn"], 1);
  bool found = false;
  for (const json& c : gate["checks"])
    if (c["verdict"] == "fail") {
      found = true;
      EXPECT_EQ(c["reproduce"], repro);
      EXPECT_EQ(c["measured"], 39.0);
      EXPECT_EQ(c["fail_limit"], 40.0);
    }
  EXPECT_TRUE(found);
  const std::string xml = read_text(dir / "junit.xml");
  EXPECT_NE(xml.find("<failure message=\"PSNR 39.00 dB is below the minimum 40.00 dB\""), std::string::npos) << xml;

  // The reports never replace the gate's inputs (--json over the results file used to succeed).
  const std::string kept = read_text(dir / "fail.jsonl");
  for (const std::string& out :
       {" --json " + (dir / "fail.jsonl").string(), " --junit " + (dir / "." / "fail.jsonl").string()}) {
    run = run_cli("gate" + config + baseline + " --results " + (dir / "fail.jsonl").string() + out);
    EXPECT_EQ(run.code, 3) << out << "\n" << run.out;
    EXPECT_NE(run.out.find("names the same file as --results"), std::string::npos) << run.out;
  }
  EXPECT_EQ(read_text(dir / "fail.jsonl"), kept);
  EXPECT_NE(xml.find(repro), std::string::npos);

  // The JUnit XML validates against the schema CI systems read (xmllint from libxml2-utils; its
  // absence is a failure, install it with ci/install-deps.sh).
  ASSERT_EQ(std::system("command -v xmllint >/dev/null 2>&1"), 0)
      << "xmllint is missing: run ci/install-deps.sh (package libxml2-utils)";
  const std::string xsd = std::string(SB_SOURCE_DIR) + "/ci/junit.xsd";
  const int lint = std::system(("xmllint --noout --schema " + xsd + " " + (dir / "junit.xml").string() + " > " +
                                (dir / "xmllint.log").string() + " 2>&1")
                                   .c_str());
  EXPECT_EQ(lint, 0) << read_text(dir / "xmllint.log");
  // ... and the schema is not a pushover: a testcase without a name is rejected.
  std::string broken = xml;
  broken.replace(broken.find("<testcase name="), 15, "<testcase nam=");
  write_file(dir / "broken.xml", broken);
  EXPECT_NE(std::system(
                ("xmllint --noout --schema " + xsd + " " + (dir / "broken.xml").string() + " >/dev/null 2>&1").c_str()),
            0);
}

TEST(GateCli, BadInputIsExitThree) {
  ScratchDir dir;
  write_file(dir / "gate.toml", kConfig);
  const std::string config = " --config " + (dir / "gate.toml").string();

  // Malformed JSON in the middle of the file.
  write_file(dir / "bad.jsonl", passing_cells()[0].dump() + "\n{\"kind\": \"stereobench.sweep_cell\", \n" +
                                    passing_cells()[1].dump() + "\n");
  CliRun run = run_cli("gate" + config + " --results " + (dir / "bad.jsonl").string());
  EXPECT_EQ(run.code, 3) << run.out;
  EXPECT_NE(run.out.find("bad.jsonl:2"), std::string::npos) << run.out;

  // An empty results file is bad input, not a pass.
  write_file(dir / "empty.jsonl", "");
  run = run_cli("gate" + config + " --results " + (dir / "empty.jsonl").string());
  EXPECT_EQ(run.code, 3) << run.out;
  EXPECT_NE(run.out.find("no finished cell"), std::string::npos) << run.out;

  // A missing results file, a missing config, a config with an unknown key, a duplicated cell.
  run = run_cli("gate" + config + " --results " + (dir / "missing.jsonl").string());
  EXPECT_EQ(run.code, 3) << run.out;
  write_results(dir / "pass.jsonl", passing_cells());
  run = run_cli("gate --config " + (dir / "nope.toml").string() + " --results " + (dir / "pass.jsonl").string());
  EXPECT_EQ(run.code, 3) << run.out;
  write_file(dir / "typo.toml", "[defaults]\nmin_pnsr = 30\n");
  run = run_cli("gate --config " + (dir / "typo.toml").string() + " --results " + (dir / "pass.jsonl").string());
  EXPECT_EQ(run.code, 3) << run.out;
  EXPECT_NE(run.out.find("typo.toml:2"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("min_pnsr"), std::string::npos) << run.out;
  // "-" is no report file (it made one named "-").
  run = run_cli("gate" + config + " --results " + (dir / "pass.jsonl").string() + " --json -");
  EXPECT_EQ(run.code, 3) << run.out;
  EXPECT_NE(run.out.find("--json -: the gate writes its report to a file"), std::string::npos) << run.out;
  EXPECT_FALSE(std::filesystem::exists("-"));
  write_results(dir / "dup.jsonl", {passing_cells()[0], passing_cells()[0]});
  run = run_cli("gate" + config + " --results " + (dir / "dup.jsonl").string());
  EXPECT_EQ(run.code, 3) << run.out;
  EXPECT_NE(run.out.find("appears twice"), std::string::npos) << run.out;
  // A value no measurement gives (a damaged or hand-edited line) is refused, not gated.
  std::vector<json> damaged = passing_cells();
  damaged[1]["pipelines"]["repro-rt"]["validation"]["metrics"]["ssim"] = 5;
  write_results(dir / "damaged.jsonl", damaged);
  run = run_cli("gate" + config + " --results " + (dir / "damaged.jsonl").string());
  EXPECT_EQ(run.code, 3) << run.out;
  EXPECT_NE(run.out.find("damaged.jsonl:2: field 'pipelines.repro-rt.validation.metrics.ssim' is 5"),
            std::string::npos)
      << run.out;

  // A torn last line (killed writer) is skipped with a warning; the rest is gated, and the sweep
  // it left unfinished fails: one of its two cells has results.
  const std::string torn = passing_cells()[0].dump() + "\n" + passing_cells()[1].dump().substr(0, 200);
  write_file(dir / "torn.jsonl", torn);
  write_file(dir / "baseline.json", "{}\n");
  run = run_cli("gate" + config + " --baseline " + (dir / "baseline.json").string() + " --results " +
                (dir / "torn.jsonl").string());
  EXPECT_EQ(run.code, 2) << run.out;
  EXPECT_NE(run.out.find("torn.jsonl:2"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("holds 1 of the sweep's 2 cells"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("sweep_complete            1  >= 2"), std::string::npos) << run.out;  // a minimum

  // A folder given as the config, and a config without a single threshold, are bad input: both
  // passed every results file before.
  run = run_cli("gate --config " + dir.path().string() + " --results " + (dir / "pass.jsonl").string());
  EXPECT_EQ(run.code, 3) << run.out;
  EXPECT_NE(run.out.find("is a folder"), std::string::npos) << run.out;
  write_file(dir / "empty.toml", "# nothing\n");
  run = run_cli("gate --config " + (dir / "empty.toml").string() + " --results " + (dir / "pass.jsonl").string());
  EXPECT_EQ(run.code, 3) << run.out;
  EXPECT_NE(run.out.find("sets no threshold"), std::string::npos) << run.out;

  // A run stopped by bad input leaves no JUnit or JSON file: an earlier run's passing verdict at
  // those paths is removed, so a CI step that publishes them cannot show it as this run's.
  const std::string outputs = " --junit " + (dir / "junit.xml").string() + " --json " + (dir / "gate.json").string();
  run = run_cli("gate" + config + " --results " + (dir / "pass.jsonl").string() + outputs);
  ASSERT_EQ(run.code, 0) << run.out;
  ASSERT_TRUE(std::filesystem::exists(dir / "junit.xml"));
  ASSERT_TRUE(std::filesystem::exists(dir / "gate.json"));
  run = run_cli("gate" + config + " --results " + (dir / "damaged.jsonl").string() + outputs);
  EXPECT_EQ(run.code, 3) << run.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "junit.xml"));
  EXPECT_FALSE(std::filesystem::exists(dir / "gate.json"));
  // So does a run refused for its options before any input is read (--only without
  // --update-baseline; one file named by both outputs; a mistyped option and an empty value,
  // refused by the command-line parser before the gate starts): these used to leave the earlier
  // files.
  for (const std::string& refused :
       {outputs + " --only repro-rt",
        " --junit " + (dir / "junit.xml").string() + " --json " + (dir / "junit.xml").string(),
        outputs + " --confg " + (dir / "empty.toml").string(), outputs + " --baseline ''",
        // --junit twice: the first file named used to stay.
        outputs + " --junit " + (dir / "other.xml").string()}) {
    run = run_cli("gate" + config + " --results " + (dir / "pass.jsonl").string() + outputs);
    ASSERT_EQ(run.code, 0) << run.out;
    run = run_cli("gate" + config + " --results " + (dir / "pass.jsonl").string() + refused);
    EXPECT_EQ(run.code, 3) << refused << "\n" << run.out;
    EXPECT_FALSE(std::filesystem::exists(dir / "junit.xml")) << refused;
    // gate.json is this refused run's output in every case but the one naming junit.xml twice.
    EXPECT_EQ(std::filesystem::exists(dir / "gate.json"), refused.find("gate.json") == std::string::npos) << refused;
  }
  // An output naming an input is refused and the input kept.
  const std::string pass_before = read_text(dir / "pass.jsonl");
  run = run_cli("gate" + config + " --results " + (dir / "pass.jsonl").string() + " --junit " +
                (dir / "pass.jsonl").string());
  EXPECT_EQ(run.code, 3) << run.out;
  EXPECT_EQ(read_text(dir / "pass.jsonl"), pass_before);
  // An output that cannot be written is exit 4 and leaves no output either: the JUnit file, written
  // first, used to stay when the JSON's folder was a file.
  write_file(dir / "notafolder", "x\n");
  run = run_cli("gate" + config + " --results " + (dir / "pass.jsonl").string() + " --junit " +
                (dir / "junit.xml").string() + " --json " + (dir / "notafolder" / "gate.json").string());
  EXPECT_EQ(run.code, 4) << run.out;
  EXPECT_NE(run.out.find("--json " + (dir / "notafolder" / "gate.json").string()), std::string::npos) << run.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "junit.xml"));
  // An output that fails only when it is written (/dev/full: a full disk): the table's verdict line
  // ("-> PASS (exit 0)") used to end standard output of a run that exited 4.
  run = run_cli("gate" + config + " --results " + (dir / "pass.jsonl").string() + " --junit /dev/full");
  EXPECT_EQ(run.code, 4) << run.out;
  EXPECT_NE(run.out.find("gate: the verdict above does not stand: its report files could not be written (exit 4)"),
            std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("--junit: cannot write /dev/full: No space left on device"), std::string::npos) << run.out;
  EXPECT_EQ(run.out.find("wrote /dev/full"), std::string::npos) << run.out;
  // A folder given as an output is bad input naming it.
  run = run_cli("gate" + config + " --results " + (dir / "pass.jsonl").string() + " --junit " + dir.path().string());
  EXPECT_EQ(run.code, 3) << run.out;
  EXPECT_NE(run.out.find("--junit: " + dir.path().string() + " is a folder; give the name of the file to write"),
            std::string::npos)
      << run.out;
}

TEST(GateEval, AnUnfinishedSweepFails) {
  const validation::GateReport whole = evaluate(passing_cells());
  const validation::GateReport part = evaluate({passing_cells()[1]});
  const auto complete = [](const validation::GateReport& r) -> const validation::GateCheck* {
    for (const validation::GateCheck& c : r.checks)
      if (c.check == validation::kCompleteCheck) return &c;
    return nullptr;
  };
  ASSERT_NE(complete(whole), nullptr);
  EXPECT_EQ(complete(whole)->verdict, Verdict::pass);
  ASSERT_NE(complete(part), nullptr);
  EXPECT_EQ(complete(part)->verdict, Verdict::fail);
  EXPECT_EQ(complete(part)->measured, 1.0);
  EXPECT_EQ(complete(part)->fail_limit, 2.0);
  EXPECT_EQ(part.worst, Verdict::fail);
  // The command resumes the file that was gated: sweep run reads <out>/results.jsonl unless told.
  EXPECT_EQ(complete(part)->reproduce.find("--results"), std::string::npos) << complete(part)->reproduce;
  const validation::GateReport other =
      validation::evaluate_gate(validation::parse_gate_config(kConfig, "test.toml"),
                                validation::gate_results({passing_cells()[1]}, {}, "runs/partial.jsonl"), {});
  ASSERT_NE(complete(other), nullptr);
  EXPECT_NE(complete(other)->reproduce.find("--out runs --results runs/partial.jsonl"), std::string::npos)
      << complete(other)->reproduce;
  // In JUnit the sweep's own check is of class "gate.sweep" in a suite without a scene property
  // (it was "gate..(all)", an empty segment, beside scene "").
  const std::string xml = validation::junit_xml(part, "gate");
  EXPECT_NE(xml.find("classname=\"gate.sweep\""), std::string::npos) << xml;
  EXPECT_EQ(xml.find("gate.."), std::string::npos) << xml;
  EXPECT_EQ(xml.find("value=\"\""), std::string::npos) << xml;
  // Lines that do not say how many cells the sweep has cannot vouch for it: the check fails (it
  // used to vanish, and a cut file passed).
  std::vector<json> uncounted = passing_cells();
  for (json& c : uncounted) c.erase("cell_count");  // the reader refuses a file where only some lines lack it
  const validation::GateReport unknown = evaluate(uncounted);
  ASSERT_NE(complete(unknown), nullptr);
  EXPECT_EQ(complete(unknown)->verdict, Verdict::fail);
  EXPECT_NE(complete(unknown)->message.find("its lines do not say how many cells the sweep has (no cell_count"),
            std::string::npos)
      << complete(unknown)->message;
}

TEST(GateJunit, AClassNameHasOneSegmentPerSceneAndPipeline) {
  // A scene file's path and a variant's decimal point opened packages in CI viewers, which split
  // class names at dots: "gate.sc/light.gltf.repro-rt:threshold_arcmin=2.5".
  validation::GateReport report;
  validation::GateCheck check;
  check.cell_id = "sc/light.gltf|e=0.064m|c=default|160x90|lights=all|full";
  check.scene = "sc/light.gltf";
  check.pipeline = "repro-rt:threshold_arcmin=2.5";
  check.check = "psnr";
  report.checks.push_back(check);
  check.scene = "box-wall";
  check.pipeline = "repro-rt";
  check.cell_id = "box-wall|e=0.064m|c=default|160x90|lights=all|full";
  report.checks.push_back(check);
  const std::string xml = validation::junit_xml(report, "gate");
  EXPECT_NE(xml.find("classname=\"gate.sc_light_gltf.repro-rt:threshold_arcmin=2_5\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("classname=\"gate.box-wall.repro-rt\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("<property name=\"scene\" value=\"sc/light.gltf\"/>"), std::string::npos) << xml;
}

TEST(GateJunit, CellsOfOneSceneAndPipelineAreDistinctTestCases) {
  // CI viewers know a test case by class name and name; the cells of an interaxial sweep shared
  // both and were merged into one test's history.
  validation::GateReport report;
  validation::GateCheck check;
  check.scene = "spheres";
  check.pipeline = "repro-rt";
  check.check = "psnr";
  for (const char* e : {"0.064", "0.12"}) {
    check.cell_id = fmt::format("spheres|e={}m|c=default|320x180|lights=all|full", e);
    report.checks.push_back(check);
  }
  check.cell_id = "spheres:count=500|e=0.064m|c=default|320x180|lights=all|full";  // a generated variant
  report.checks.push_back(check);
  check.scene.clear();
  check.pipeline = "(all)";
  check.cell_id = "(all cells)";
  check.check = "sweep_complete";
  report.checks.push_back(check);
  const std::string xml = validation::junit_xml(report, "gate");
  for (const char* e : {"0.064", "0.12"})
    EXPECT_NE(xml.find(fmt::format("<testcase name=\"repro-rt psnr [e={}m|c=default|320x180|lights=all|full]\" "
                                   "classname=\"gate.spheres.repro-rt\"",
                                   e)),
              std::string::npos)
        << xml;
  EXPECT_NE(xml.find("<testcase name=\"repro-rt psnr [count=500|e=0.064m|c=default|320x180|lights=all|full]\""),
            std::string::npos)
      << xml;
  EXPECT_NE(xml.find("<testcase name=\"(all) sweep_complete\" classname=\"gate.sweep\""), std::string::npos) << xml;
}

TEST(GateEval, ReproduceGivesTheLightCountTheCellUsed) {
  // A cell asking for 7 lights of a 5-light scene keeps the scene's 5; validate refuses --lights 7.
  json cell = fake_cell(1, 0.064, {FakePipeline{}});
  cell["cell"]["lights"] = 7;
  cell["pipelines"][FakePipeline{}.name]["validation"]["scene"] = {{"lights", 5}};
  const validation::GateCell gc{cell["cell_id"], "box-wall", cell};
  const std::string command = validation::reproduce_command(gc, FakePipeline{}.name, {});
  EXPECT_NE(command.find("--lights 5"), std::string::npos) << command;
  cell["cell"]["lights"] = 3;
  cell["pipelines"][FakePipeline{}.name]["validation"]["scene"] = {{"lights", 3}};
  const validation::GateCell fewer{cell["cell_id"], "box-wall", cell};
  EXPECT_NE(validation::reproduce_command(fewer, FakePipeline{}.name, {}).find("--lights 3"), std::string::npos);
}

TEST(GateEval, ReproduceNamesAVariantWithoutRepeatingItsOwnOptions) {
  FakePipeline variant;
  variant.name = "bidir-warp:occlusion=ztest";
  json cell = fake_cell(1, 0.064, {variant});
  cell["pipelines"][variant.name]["validation"]["options"] = {
      {"occlusion", "ztest"}, {"max_crack", "3"}, {"tile", "64"}};
  const validation::GateCell gc{cell["cell_id"], "box-wall", cell};
  validation::ReproduceSettings settings;
  settings.pipeline_defaults["bidir-warp"] = {{"occlusion", "none"}, {"max_crack", "2"}, {"tile", "64"}};
  const std::string command = validation::reproduce_command(gc, variant.name, settings);
  EXPECT_NE(command.find("--pipelines bidir-warp:occlusion=ztest "), std::string::npos) << command;
  EXPECT_NE(command.find("--option max_crack=3"), std::string::npos) << "given for the pipeline: " << command;
  EXPECT_EQ(command.find("--option occlusion"), std::string::npos) << "fixed by the name: " << command;
  EXPECT_EQ(command.find("--option tile"), std::string::npos) << "at its default: " << command;
}

TEST(GateEval, ReproduceNamesTheSceneFileTheSweepLoaded) {
  // A definition in defs/ lists "../scenes/bw.gltf": relative to its own folder, which is not where
  // the gate runs. The command names the file the sweep loaded; a built-in keeps its name.
  json cell = fake_cell(1, 0.064, {FakePipeline{}}, "../scenes/bw.gltf");
  cell["pipelines"][FakePipeline{}.name]["validation"]["scene"] = {{"path", "/work/scenes/bw.gltf"}};
  const validation::GateCell file{cell["cell_id"], "../scenes/bw.gltf", cell};
  const std::string command = validation::reproduce_command(file, FakePipeline{}.name, {});
  EXPECT_NE(command.find("--scene /work/scenes/bw.gltf "), std::string::npos) << command;
  json builtin = fake_cell(1, 0.064, {FakePipeline{}});
  builtin["pipelines"][FakePipeline{}.name]["validation"]["scene"] = {{"path", "/cache/box-wall.gltf"}};
  const validation::GateCell named{builtin["cell_id"], "box-wall", builtin};
  EXPECT_NE(validation::reproduce_command(named, FakePipeline{}.name, {}).find("--scene box-wall "), std::string::npos);
}

TEST(GateEval, TimesAreReproducedByBenchAndTheBaselineHasNoSpeedupCheck) {
  json cell =
      fake_cell(0, 0.064, {{"plain-rt", 90, 1.0, 0, 0, 1, 1.0}, {"repro-rt", 45, 0.998, 0.001, 0.01, 1.0, 1.1}});
  cell["cell_count"] = 1;
  cell["threads"] = 2;
  const std::string config = kConfig + "[[rule]]\nmin_speedup = 1.2\n";  // every pipeline, the baseline too
  const validation::GateReport r = evaluate({cell}, {}, config);
  const validation::GateCheck* speedup = find_check(r, "repro-rt", "speedup");
  ASSERT_NE(speedup, nullptr);
  EXPECT_EQ(speedup->verdict, Verdict::fail);
  EXPECT_EQ(speedup->reproduce,
            "stereobench bench --scene box-wall --pipelines repro-rt --baseline plain-rt --repetitions 3 --warmup 1 "
            "--threads 2 --resolution 320x180 --interaxial 0.064 --convergence 2")
      << "a speed-up is measured by timing, not by validate; warm, as the cell's warmup 0 timed warm runs";
  const validation::GateCheck* regression = find_check(r, "repro-rt", "time_regression");
  ASSERT_NE(regression, nullptr);
  EXPECT_EQ(regression->reproduce, speedup->reproduce);
  const validation::GateCheck* psnr = find_check(r, "repro-rt", "psnr");
  ASSERT_NE(psnr, nullptr);
  EXPECT_EQ(psnr->reproduce.rfind("stereobench validate --scene box-wall --pipelines repro-rt --truth full", 0), 0u)
      << psnr->reproduce;
  // plain-rt is the cell's baseline: its speed-up over itself is 1, so the rule does not apply.
  EXPECT_EQ(find_check(r, "plain-rt", "speedup"), nullptr);
  EXPECT_NE(find_check(r, "plain-rt", "psnr"), nullptr);
}

TEST(GateEval, BenchCommandsNameThePipelineOfEachOptionAndRun) {
  // bench takes PIPELINE.NAME=VALUE (it times the baseline beside the pipeline): a bare NAME=VALUE
  // made the command exit 3. The baseline's own options go with it; validate keeps NAME=VALUE.
  json cell = fake_cell(0, 0.064, {{"plain-raster", 90, 1.0, 0, 0, 1, 1.0}, {"repro-rt"}});
  cell["baseline"] = "plain-raster";
  cell["cell"]["resolution"] = "64x36";  // small enough to run the command below
  cell["cell_id"] = "box-wall|e=0.064m|c=default|64x36|lights=all|full";
  cell["cell_count"] = 1;
  cell["threads"] = 1;
  cell["pipelines"]["repro-rt"]["validation"]["options"] = {{"threshold_arcmin", "2"}, {"tile", "64"}};
  const std::string config = kConfig + "[[rule]]\npipeline = \"repro-rt\"\nwarn_speedup = 5\nwarn_psnr = 50\n";
  const auto evaluate_cell = [&] {
    return validation::evaluate_gate(validation::parse_gate_config(config, "test.toml"),
                                     validation::gate_results({cell}, {}, "results.jsonl"), {},
                                     validation::registered_reproduce_settings());
  };
  validation::GateReport r = evaluate_cell();
  const validation::GateCheck* speedup = find_check(r, "repro-rt", "speedup");
  ASSERT_NE(speedup, nullptr);
  EXPECT_EQ(speedup->verdict, Verdict::warn) << speedup->message;
  EXPECT_NE(speedup->reproduce.find("--option repro-rt.threshold_arcmin=2"), std::string::npos) << speedup->reproduce;
  EXPECT_EQ(speedup->reproduce.find("tile"), std::string::npos) << "at its default: " << speedup->reproduce;
  const validation::GateCheck* psnr = find_check(r, "repro-rt", "psnr");
  ASSERT_NE(psnr, nullptr);
  EXPECT_NE(psnr->reproduce.find("--option threshold_arcmin=2"), std::string::npos) << psnr->reproduce;

  // The baseline's options, named by the baseline.
  cell["pipelines"]["plain-raster"]["validation"]["options"] = {{"tile", "8"}};
  r = evaluate_cell();
  speedup = find_check(r, "repro-rt", "speedup");
  ASSERT_NE(speedup, nullptr);
  EXPECT_NE(speedup->reproduce.find("--option repro-rt.threshold_arcmin=2 --option plain-raster.tile=8"),
            std::string::npos)
      << speedup->reproduce;

  // The terminal shows a warned check's command too, and the command runs.
  const std::string table = validation::format_gate_table(r);
  EXPECT_NE(table.find("reproduce: " + speedup->reproduce), std::string::npos) << table;
  ScratchDir dir("gate_bench_reproduce");
  std::string command = speedup->reproduce.substr(std::string("stereobench ").size());
  command += " --scenes-dir " + quoted(dir / "scenes");
  const CliRun run = run_cli(command);
  EXPECT_EQ(run.code, 0) << command << "\n" << run.out;
  EXPECT_NE(run.out.find("speed-up"), std::string::npos) << run.out;
}

TEST(GateEval, AWarningLevelBeyondTheFailureLevelInForceIsNoted) {
  // kConfig's [defaults] warn at 35 dB, its repro-rt rule fails below 40 dB: for repro-rt a PSNR
  // of 38 fails without a warning level ever in force. One note, though two cells have repro-rt;
  // plain-rt (defaults only: fail 30, warn 35) gets none.
  const validation::GateReport r = evaluate(passing_cells());
  std::vector<std::string> notes;
  for (const std::string& n : r.notes)
    if (n.find("can never be raised") != std::string::npos) notes.push_back(n);
  ASSERT_EQ(notes.size(), 1u) << fmt::format("{}", fmt::join(r.notes, "\n"));
  EXPECT_EQ(notes[0],
            "test.toml: for pipeline repro-rt on scene box-wall, warn_psnr = 35 ([defaults]) is looser than "
            "min_psnr = 40 (the [[rule]] at line 10): that warning can never be raised there, a value beyond "
            "min_psnr fails at once; set warn_psnr in the same table as min_psnr");
  // Setting the warning level in the rule as well resolves it.
  const validation::GateReport fixed = evaluate(passing_cells(), {}, kConfig + "warn_psnr = 42\n");
  for (const std::string& n : fixed.notes) EXPECT_EQ(n.find("can never be raised"), std::string::npos) << n;
}

TEST(GateEval, ARuleThatMatchesNothingIsNoted) {
  const auto notes_about_rules = [](const validation::GateReport& r) {
    std::vector<std::string> out;
    for (const std::string& n : r.notes)
      if (n.find(" to no cell of ") != std::string::npos) out.push_back(n);
    return out;
  };
  EXPECT_TRUE(notes_about_rules(evaluate(passing_cells())).empty()) << "kConfig's rule matches repro-rt";
  const validation::GateReport typo =
      evaluate(passing_cells(), {}, kConfig + "[[rule]]\npipeline = \"repro_rt\"\nmin_psnr = 99\n");
  const std::vector<std::string> notes = notes_about_rules(typo);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("test.toml: 1 [[rule]] table applies to no cell of results.jsonl (rules for another "
                          "sweep, or misspelt globs), so its limits are not checked: pipeline 'repro_rt' matches none "
                          "of its pipelines (plain-rt, repro-rt) (line 15)"),
            std::string::npos)
      << notes[0];
  // Several rules: grouped by the glob that matches nothing, each group with its lines. A rule
  // whose globs each match something, but never together, says so.
  std::vector<json> cells = passing_cells();
  cells.push_back(fake_cell(2, 0.064, {{"plain-rt", 90, 1.0, 0, 0, 1, 1.0}}, "spheres"));
  for (json& c : cells) c["cell_count"] = 3;
  const validation::GateReport several = evaluate(
      cells, {},
      kConfig + "[[rule]]\nscene = \"atrium\"\nmin_psnr = 99\n[[rule]]\nscene = \"atrium\"\n"
                "pipeline = \"plain-*\"\nmin_psnr = 99\n[[rule]]\npipeline = \"repro_rt\"\nmin_psnr = 99\n"
                "[[rule]]\npipeline = \"plain-rt\"\ncell = \"nowhere*\"\nmin_psnr = 99\n"
                "[[rule]]\npipeline = \"repro-rt\"\nscene = \"spheres\"\nmin_psnr = 99\n");
  const std::vector<std::string> grouped = notes_about_rules(several);
  ASSERT_EQ(grouped.size(), 1u);
  EXPECT_NE(grouped[0].find("5 [[rule]] tables apply to no cell"), std::string::npos) << grouped[0];
  EXPECT_NE(grouped[0].find("so their limits are not checked: scene 'atrium' matches none of its scenes (box-wall, "
                            "spheres) (lines 15, 18); pipeline 'repro_rt' matches none of its pipelines (plain-rt, "
                            "repro-rt) (line 22); cell 'nowhere*' matches none of its cell ids (line 25); pipeline "
                            "'repro-rt', scene 'spheres' and cell '*' each match, but never in the same cell (line 29)"),
            std::string::npos)
      << grouped[0];
  EXPECT_EQ(typo.worst, evaluate(passing_cells()).worst) << "a note, not a verdict";
  EXPECT_EQ(typo.checks.size(), evaluate(passing_cells()).checks.size());
}

TEST(GateEval, RuleLimitsThatCheckNothingAreNoted) {
  const auto notes_about_limits = [](const validation::GateReport& r) {
    std::vector<std::string> out;
    for (const std::string& n : r.notes)
      if (n.find("limits that check nothing") != std::string::npos) out.push_back(n);
    return out;
  };
  EXPECT_TRUE(notes_about_limits(evaluate(passing_cells())).empty())
      << fmt::format("{}", fmt::join(evaluate(passing_cells()).notes, "\n"));
  // A stricter rule before a broader one: the broader one's limit is in force wherever both
  // match, so repro-rt's 45 dB minimum never checks (its PSNR of 44 passed against 20), nor does
  // kConfig's 40 dB. A minimum speed-up for the baseline pipeline has nothing to check.
  const validation::GateReport r =
      evaluate(passing_cells(), {},
               kConfig + "[[rule]]\npipeline = \"repro-rt\"\nmin_psnr = 45\n[[rule]]\nscene = \"*\"\nmin_psnr = 20\n"
                         "[[rule]]\npipeline = \"plain-rt\"\nmin_speedup = 5\n");
  const std::vector<std::string> notes = notes_about_limits(r);
  ASSERT_EQ(notes.size(), 1u) << fmt::format("{}", fmt::join(r.notes, "\n"));
  EXPECT_EQ(notes[0],
            "test.toml: [[rule]] limits that check nothing, so are not in force: a later [[rule]] sets them wherever "
            "their rule matches: min_psnr (line 10), min_psnr (line 15); no record its rule matches has that measure "
            "(a left eye's for a pipeline that renders its own, a speed-up of the baseline pipeline): min_speedup "
            "(line 21)");
  EXPECT_EQ(find_check(r, "repro-rt", "psnr")->fail_limit, 20.0) << "the later rule is in force";
}

TEST(GateEval, AFrameOfAPathIsReproducedByRunningItsCellAgain) {
  json cell = fake_cell(1, 0.064, {FakePipeline{}});
  cell["cell"]["frame"] = 2;
  cell["cell_count"] = 6;
  cell["definition"] = "ci/presets/animated-spheres.toml";
  const validation::GateCell gc{cell["cell_id"], "box-wall", cell};
  const std::string command = validation::reproduce_command(gc, FakePipeline{}.name, {});
  EXPECT_EQ(command, "stereobench sweep run ci/presets/animated-spheres.toml --out out/reproduce --shard 1/6") << command;
  cell["cell"].erase("frame");
  const validation::GateCell still{cell["cell_id"], "box-wall", cell};
  EXPECT_EQ(validation::reproduce_command(still, FakePipeline{}.name, {}).rfind("stereobench validate", 0), 0u);
}

}  // namespace
}  // namespace sb::test
