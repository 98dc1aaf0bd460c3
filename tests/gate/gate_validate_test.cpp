// The gate on real validations: repro-rt on box-wall at 320x180 (a cell of ci/smoke.toml) measured
// against the built-in ground truth, once as shipped and once made worse by an option, gated with
// the shipped ci/gate.toml; and the reproduce command of a failure re-measures the same numbers.
#include <gtest/gtest.h>

#include <map>
#include <regex>
#include <string>

#include <fmt/format.h>

#include "gate/gate_fixture.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/render_scene.hpp"
#include "scenes/catalog.hpp"
#include "support/run_cli.hpp"
#include "support/scratch_dir.hpp"
#include "validation/truth.hpp"
#include "validation/validate.hpp"

namespace sb::test {
namespace {

using nlohmann::json;

const std::filesystem::path kScenes = std::filesystem::path(SB_BINARY_DIR) / "Testing" / "scenes-cache";

/// Validates pipelines on box-wall at 320x180, interaxial 0.064 m, and returns the results line
/// of that cell (docs/sweeps.md), one repetition timed by the validation itself.
json validated_cell(const std::vector<std::pair<std::string, std::map<std::string, std::string>>>& runs) {
  const std::filesystem::path file = scenes::resolve_scene("box-wall", kScenes);
  const scenes::LoadedScene loaded = scenes::load_scene("box-wall", kScenes);
  RigOverrides o;
  o.width = 320;
  o.height = 180;
  o.interaxial = 0.064;
  const StereoRig rig = resolve_rig(loaded.scene, o);
  const RenderScene prepared(loaded.scene);
  const Executor executor(2);
  const auto provider = validation::make_truth_provider("full");
  const validation::ValidationTarget target =
      validation::prepare_target(prepared, file, rig, *provider, nullptr, kScenes / "gate-work", executor);
  json cell = fake_cell(0, 0.064, {});
  cell["cell_count"] = 1;  // the results files below hold this one cell: a whole sweep
  cell["rig"] = json::object();
  cell["baseline"] = runs.front().first;  // a cell's baseline is one of its pipelines
  for (const auto& [name, options] : runs) {
    const PipelineEntry entry = parse_pipeline_entry(name);
    const validation::PipelineValidation v =
        validation::validate_pipeline(target, entry, entry.options(options), executor);
    const double total = v.result.timings.total();
    cell["pipelines"][name] = {
        {"validation", validation::validation_record(target, v, executor.threads(), json::object())},
        {"timing",
         {{"repetitions", 1}, {"warmup", 0}, {"median_s", total}, {"samples_s", {total}}, {"speedup_median", 1.0}}}};
    cell["rig"] = cell["pipelines"][name]["validation"]["rig"];
  }
  return cell;
}

/// The shipped thresholds without the speed-up warnings: one timed repetition at 320x180 on a
/// shared machine is noise (DESIGN §8: timings are never assertions in tests).
std::string shipped_config_without_speedups(const ScratchDir& dir) {
  const std::string text = io::read_file(std::filesystem::path(SB_SOURCE_DIR) / "ci" / "gate.toml") +
                           "\n[[rule]]\nwarn_speedup = false\nmin_speedup = false\n";
  write_file(dir / "gate.toml", text);
  return (dir / "gate.toml").string();
}

TEST(GateValidate, ShippedPipelinePassesAndAWorseOptionFails) {
  ScratchDir dir;
  const std::string config = shipped_config_without_speedups(dir);
  write_file(dir / "baseline.json", "{}\n");
  const std::string common = "gate --config " + config + " --baseline " + (dir / "baseline.json").string();

  // As shipped: repro-rt measured 48.34 dB, SSIM 0.9989, recall 1.0 (ci/gate.toml: min 46 dB,
  // 0.997, 0.99) and plain-rt identical to the truth: the gate passes.
  const json good = validated_cell({{"plain-rt", {}}, {"repro-rt", {}}});
  write_results(dir / "good.jsonl", {good});
  CliRun run = run_cli(common + " --results " + (dir / "good.jsonl").string());
  EXPECT_EQ(run.code, 0) << run.out;

  // discontinuity_px = 1e6 (default 0.05): no disocclusion is ever detected, the warp stretches
  // over every hole and nothing is traced. The holes show wrong surfaces: measured PSNR 40.11 dB
  // and recall 0.7338 (from 48.34 dB and 1.0), below the shipped minimums 46 dB and 0.99.
  const json bad = validated_cell({{"plain-rt", {}}, {"repro-rt", {{"discontinuity_px", "1000000"}}}});
  const json& m = bad["pipelines"]["repro-rt"]["validation"];
  const double psnr = m["metrics"]["psnr"].get<double>();
  const double recall = m["holes"]["not_reprojected"]["recall"].get<double>();
  EXPECT_LT(psnr, 46.0);
  EXPECT_LT(recall, 0.99);
  write_results(dir / "bad.jsonl", {bad});
  run = run_cli(common + " --results " + (dir / "bad.jsonl").string() + " --junit " + (dir / "junit.xml").string());
  EXPECT_EQ(run.code, 2) << run.out;
  EXPECT_NE(run.out.find("FAIL"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("disocclusion_recall"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("psnr"), std::string::npos) << run.out;
  // The reproduce command names the cell's scene, rig, truth and the option that differs from the
  // pipeline's default.
  const std::string repro =
      "reproduce: stereobench validate --scene box-wall --pipelines repro-rt --truth full --resolution 320x180 "
      "--interaxial 0.064 --convergence ";
  EXPECT_NE(run.out.find(repro), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("--option discontinuity_px=1000000"), std::string::npos) << run.out;
  EXPECT_NE(read_text(dir / "junit.xml").find("<failure"), std::string::npos);
  ::testing::Test::RecordProperty("degraded_psnr", std::to_string(psnr));
  ::testing::Test::RecordProperty("degraded_recall", std::to_string(recall));
}

TEST(GateValidate, SmokeSweepPassesTheShippedGate) {
  // The smoke sweep as CI runs it (ci/smoke.toml: every pipeline on spheres at 320x180, two
  // interaxials), gated with the shipped thresholds, which were set from these cells.
  ScratchDir dir;
  const std::string config = shipped_config_without_speedups(dir);
  CliRun run = run_cli("sweep run " + std::string(SB_SOURCE_DIR) + "/ci/smoke.toml --out " + (dir / "smoke").string() +
                       " --threads 2 --scenes-dir " + kScenes.string());
  ASSERT_EQ(run.code, 0) << run.out;
  write_file(dir / "baseline.json", "{}\n");
  run = run_cli("gate --config " + config + " --baseline " + (dir / "baseline.json").string() + " --results " +
                (dir / "smoke" / "results.jsonl").string() + " --junit " + (dir / "junit.xml").string());
  EXPECT_EQ(run.code, 0) << run.out;
  EXPECT_NE(run.out.find(" 0 fail"), std::string::npos) << run.out;
  EXPECT_NE(read_text(dir / "junit.xml").find("<testsuite name=\"spheres|e=0.064m"), std::string::npos);
}

TEST(GateValidate, ReproduceCommandReMeasuresTheFailure) {
  ScratchDir dir;
  const json cell = validated_cell({{"repro-rt", {}}});
  write_results(dir / "results.jsonl", {cell});
  const double psnr = cell["pipelines"]["repro-rt"]["validation"]["metrics"]["psnr"].get<double>();
  // A minimum 1 dB above the measured value must fail.
  write_file(dir / "gate.toml", fmt::format("[[rule]]\npipeline = \"repro-rt\"\nmin_psnr = {}\n", psnr + 1.0));
  write_file(dir / "baseline.json", "{}\n");
  const CliRun run =
      run_cli("gate --config " + (dir / "gate.toml").string() + " --baseline " + (dir / "baseline.json").string() +
              " --results " + (dir / "results.jsonl").string() + " --json " + (dir / "gate.json").string());
  ASSERT_EQ(run.code, 2) << run.out;
  std::string command;
  const json gate = json::parse(read_text(dir / "gate.json"));
  for (const json& c : gate["checks"])
    if (c["verdict"] == "fail") command = c["reproduce"];
  ASSERT_EQ(command.rfind("stereobench validate ", 0), 0u) << command;

  // Run it with this build's binary, output into the scratch folder: it prints the same PSNR.
  const CliRun again = run_cli(command.substr(std::string("stereobench ").size()) + " --out " +
                               (dir / "validate").string() + " --scenes-dir " + kScenes.string() + " --threads 2");
  ASSERT_EQ(again.code, 0) << again.out;
  const std::regex row("\\nrepro-rt +([0-9.]+) ");
  std::smatch match;
  ASSERT_TRUE(std::regex_search(again.out, match, row)) << again.out;
  EXPECT_EQ(match[1].str(), fmt::format("{:.2f}", psnr)) << again.out;
}

}  // namespace
}  // namespace sb::test
