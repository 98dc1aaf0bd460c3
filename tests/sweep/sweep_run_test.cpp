// `stereobench sweep run` end to end: resumption after SIGKILL, shards merged by collect equal an
// unsharded run, CSV export, and the shipped smoke sweep.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <thread>

#include "renderer/io/file_lock.hpp"
#include "scenes/gltf_builder.hpp"
#include "support/lock_wait.hpp"
#include "support/run_cli.hpp"
#include "support/scratch_dir.hpp"
#include "validation/results_file.hpp"
#include "validation/sweep_run.hpp"

extern char** environ;

namespace sb {
namespace {

namespace fs = std::filesystem;
using test::quoted;
using nlohmann::json;

/// Six cells at 96x54 on the box in front of a wall: 3 interaxial distances × 2 sizes.
constexpr const char* kTinySweep = R"([sweep]
name = "tiny"
scenes = ["box-wall"]
pipelines = ["plain-rt", "plain-raster", "repro-rt", "rt-atomic", "bidir-warp"]
interaxial_m = [0.04, 0.064, 0.1]
resolutions = ["96x54", "128x72"]

[timing]
repetitions = 2
warmup = 0
)";

/// The complete (newline-terminated) lines of a file; a torn tail is left out.
std::vector<std::string> lines_of(const fs::path& file) {
  std::string text = test::read_text(file);
  text.resize(text.rfind('\n') == std::string::npos ? 0 : text.rfind('\n') + 1);
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

/// What must agree between two runs of a cell: everything measured except time.
json measured(const json& cell) {
  json out = {{"cell", cell["cell"]}, {"rig", cell["rig"]}};
  for (const auto& [name, p] : cell["pipelines"].items()) {
    const json& v = p["validation"];
    out[name] = {{"metrics", v["metrics"]}, {"regions", v["regions"]}, {"holes", v["holes"]},
                 {"counters", v["counters"]}, {"options", v["options"]}};
  }
  return out;
}

std::map<std::string, json> measured_by_id(const fs::path& file) {
  std::map<std::string, json> out;
  for (const json& c : validation::read_results(file).cells) out[c["cell_id"]] = measured(c);
  return out;
}

TEST(SweepRun, ResumesAfterKillWithoutLosingOrDuplicatingCells) {
  test::ScratchDir dir;
  std::ofstream(dir / "tiny.toml") << kTinySweep;
  const fs::path results = dir / "out" / "results.jsonl";
  const std::string cli = SB_CLI_PATH;
  const std::string def = (dir / "tiny.toml").string(), out = (dir / "out").string(),
                    scenes = (dir / "scenes").string(), log = (dir / "first.log").string();
  // Generate the scene first, so that the run killed below spends its time in cells.
  ASSERT_EQ(test::run_cli("scenes generate box-wall --out " + quoted(dir / "scenes")).code, 0);

  std::vector<std::string> args = {cli, "sweep", "run", def, "--out", out, "--scenes-dir", scenes, "--threads", "1"};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, cli.c_str(), &actions, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&actions);

  // Kill it once the first cell is recorded, while later cells are running.
  bool exited = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (std::chrono::steady_clock::now() < deadline) {
    if (lines_of(results).size() >= 1) break;
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) {
      exited = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  if (!exited) {
    ASSERT_EQ(kill(pid, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(WIFSIGNALED(status)) << "the run ended before it was killed; it must still have been running";
  }
  ASSERT_FALSE(exited) << "the run finished (or failed) before the kill: " << test::read_text(log);
  const std::vector<std::string> before = lines_of(results);
  ASSERT_GE(before.size(), 1u);
  ASSERT_LT(before.size(), 6u) << "every cell finished before the kill";

  // Resume: only the missing cells run.
  const test::CliRun resumed = test::run_cli("sweep run " + quoted(dir / "tiny.toml") + " --out " + quoted(dir / "out") +
                                             " --scenes-dir " + quoted(dir / "scenes") + " --threads 1");
  ASSERT_EQ(resumed.code, 0) << resumed.out;
  EXPECT_NE(resumed.out.find(std::to_string(before.size()) + " finished already, " +
                             std::to_string(6 - before.size()) + " to run"),
            std::string::npos)
      << resumed.out;
  const std::vector<std::string> after = lines_of(results);
  const validation::ResultsFile r = validation::read_results(results);  // throws on a duplicate cell_id
  EXPECT_TRUE(r.warnings.empty());
  ASSERT_EQ(r.cells.size(), 6u);
  std::set<size_t> indices;
  for (const json& c : r.cells) indices.insert(c["cell_index"].get<size_t>());
  EXPECT_EQ(indices, (std::set<size_t>{0, 1, 2, 3, 4, 5}));
  // The cells recorded before the kill are unchanged, in their places.
  for (size_t i = 0; i < before.size(); ++i) EXPECT_EQ(after[i], before[i]) << "line " << i + 1;

  // A third run has nothing to do.
  const test::CliRun again = test::run_cli("sweep run " + quoted(dir / "tiny.toml") + " --out " + quoted(dir / "out") +
                                           " --scenes-dir " + quoted(dir / "scenes"));
  ASSERT_EQ(again.code, 0) << again.out;
  EXPECT_NE(again.out.find("6 finished already, 0 to run"), std::string::npos) << again.out;
  EXPECT_EQ(lines_of(results), after);

  // Images of a finished cell exist where its line says.
  const json& first = r.cells.front();
  for (const char* key : {"left_png", "truth_png", "disocclusions_png"})
    EXPECT_TRUE(fs::exists(results.parent_path() / first["images"][key].get<std::string>())) << key;
  for (const auto& [name, files] : first["images"]["pipelines"].items())
    for (const auto& [kind, path] : files.items())
      EXPECT_TRUE(fs::exists(results.parent_path() / path.get<std::string>())) << name << " " << kind;

  // While another run holds the results file, a second one is refused before it plans anything
  // (two runs used to find the same cells unfinished and record each twice).
  {
    const validation::ResultsWriterLock held(results, {3});
    const test::CliRun second = test::run_cli("sweep run " + quoted(dir / "tiny.toml") + " --out " +
                                              quoted(dir / "out") + " --scenes-dir " + quoted(dir / "scenes"));
    EXPECT_EQ(second.code, 3) << second.out;
    EXPECT_NE(second.out.find("is being written by another stereobench run, which holds cell 3 of this run"),
              std::string::npos)
        << second.out;
    // A shard without cell 3 (cells 1 and 4) runs beside it; it has nothing left to do here.
    const test::CliRun shard =
        test::run_cli("sweep run " + quoted(dir / "tiny.toml") + " --out " + quoted(dir / "out") +
                      " --shard 1/3 --scenes-dir " + quoted(dir / "scenes"));
    EXPECT_EQ(shard.code, 0) << shard.out;
  }
  EXPECT_EQ(lines_of(results), after);

  // A changed definition is not mixed into these results.
  std::ofstream(dir / "tiny.toml", std::ios::app) << "\n# edited\n";
  const test::CliRun changed = test::run_cli("sweep run " + quoted(dir / "tiny.toml") + " --out " +
                                             quoted(dir / "out") + " --scenes-dir " + quoted(dir / "scenes"));
  EXPECT_EQ(changed.code, 3) << changed.out;
  EXPECT_NE(changed.out.find("the definition changed"), std::string::npos) << changed.out;
  // Nor does it share the folder through a results file of its own: its cells' images would
  // overwrite these (their folders are named by cell index).
  const test::CliRun beside = test::run_cli("sweep run " + quoted(dir / "tiny.toml") + " --out " + quoted(dir / "out") +
                                            " --results " + quoted(dir / "other.jsonl") + " --scenes-dir " +
                                            quoted(dir / "scenes"));
  EXPECT_EQ(beside.code, 3) << beside.out;
  EXPECT_NE(beside.out.find("holds the cells of sweep 'tiny'"), std::string::npos) << beside.out;
  EXPECT_NE(beside.out.find("its images would be overwritten: give another --out"), std::string::npos) << beside.out;
  EXPECT_FALSE(fs::exists(dir / "other.jsonl"));
}

TEST(SweepRun, ShardsCollectedEqualAnUnshardedRun) {
  test::ScratchDir dir;
  std::ofstream(dir / "tiny.toml") << kTinySweep;
  const std::string common = " --scenes-dir " + quoted(dir / "scenes") + " --threads 1";
  const std::string def = quoted(dir / "tiny.toml");
  const test::CliRun whole = test::run_cli("sweep run " + def + " --out " + quoted(dir / "whole") + common);
  ASSERT_EQ(whole.code, 0) << whole.out;
  for (const char* shard : {"0/2", "1/2"}) {
    const std::string name = std::string("shard") + shard[0];
    const test::CliRun r = test::run_cli("sweep run " + def + " --shard " + shard + " --out " + quoted(dir / name) + common);
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_EQ(validation::read_results(dir / name / "results.jsonl").cells.size(), 3u) << shard;
  }
  const test::CliRun collected =
      test::run_cli("sweep collect " + quoted(dir / "merged.jsonl") + " " + quoted(dir / "shard1" / "results.jsonl") +
                    " " + quoted(dir / "shard0" / "results.jsonl"));
  ASSERT_EQ(collected.code, 0) << collected.out;
  // More shards than cells: a shard with none still leaves its (empty) results file, so that
  // collecting every shard's file works whatever the split.
  const test::CliRun none =
      test::run_cli("sweep run " + def + " --shard 6/7 --out " + quoted(dir / "shard6") + common);
  ASSERT_EQ(none.code, 0) << none.out;
  EXPECT_NE(none.out.find("shard 6/7: 0 cells"), std::string::npos) << none.out;
  EXPECT_EQ(test::read_text(dir / "shard6" / "results.jsonl"), "");
  const test::CliRun with_empty = test::run_cli("sweep collect " + quoted(dir / "merged7.jsonl") + " " +
                                                quoted(dir / "shard6" / "results.jsonl") + " " +
                                                quoted(dir / "merged.jsonl"));
  ASSERT_EQ(with_empty.code, 0) << with_empty.out;
  EXPECT_EQ(test::read_text(dir / "merged7.jsonl"), test::read_text(dir / "merged.jsonl"));

  const std::vector<json> merged = validation::read_results(dir / "merged.jsonl").cells;
  ASSERT_EQ(merged.size(), 6u);
  for (size_t i = 0; i < merged.size(); ++i) EXPECT_EQ(merged[i]["cell_index"], i);  // ordered by cell_index
  const auto a = measured_by_id(dir / "whole" / "results.jsonl");
  const auto b = measured_by_id(dir / "merged.jsonl");
  ASSERT_EQ(a.size(), 6u);
  for (const auto& [id, m] : a) {
    ASSERT_TRUE(b.count(id)) << id;
    EXPECT_EQ(b.at(id), m) << id;
  }

  // Collecting a shard with a conflicting copy of a cell fails, naming the cell.
  std::vector<std::string> lines = lines_of(dir / "shard0" / "results.jsonl");
  json changed = json::parse(lines[0]);
  changed["wall_s"] = changed["wall_s"].get<double>() + 1.0;
  std::ofstream(dir / "conflict.jsonl") << changed.dump() << "\n";
  const test::CliRun conflict = test::run_cli("sweep collect " + quoted(dir / "bad.jsonl") + " " +
                                              quoted(dir / "shard0" / "results.jsonl") + " " +
                                              quoted(dir / "conflict.jsonl"));
  EXPECT_EQ(conflict.code, 3) << conflict.out;
  EXPECT_NE(conflict.out.find(changed["cell_id"].get<std::string>()), std::string::npos) << conflict.out;
  EXPECT_FALSE(fs::exists(dir / "bad.jsonl"));

  // CSV export: a header and one row per (cell, pipeline).
  const test::CliRun csv = test::run_cli("sweep csv " + quoted(dir / "merged.jsonl") + " --out " + quoted(dir / "m.csv"));
  ASSERT_EQ(csv.code, 0) << csv.out;
  const std::string text = test::read_text(dir / "m.csv");
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1 + 6 * 5);
  EXPECT_EQ(text.rfind("cell_index,cell_id,", 0), 0u);

  // The export never replaces its input (it used to turn the results file into CSV).
  const std::string merged_text = test::read_text(dir / "merged.jsonl");
  const test::CliRun over =
      test::run_cli("sweep csv " + quoted(dir / "merged.jsonl") + " --out " + quoted(dir / "." / "merged.jsonl"));
  EXPECT_EQ(over.code, 3) << over.out;
  EXPECT_NE(over.out.find("names the same file as results"), std::string::npos) << over.out;
  EXPECT_EQ(test::read_text(dir / "merged.jsonl"), merged_text);

  // A results file without a finished cell is nothing to export or merge.
  std::ofstream(dir / "empty.jsonl").flush();
  const test::CliRun empty_csv = test::run_cli("sweep csv " + quoted(dir / "empty.jsonl") + " --out " + quoted(dir / "e.csv"));
  EXPECT_EQ(empty_csv.code, 3) << empty_csv.out;
  EXPECT_NE(empty_csv.out.find("holds no finished cell"), std::string::npos) << empty_csv.out;
  EXPECT_FALSE(fs::exists(dir / "e.csv"));
  const test::CliRun empty_merge =
      test::run_cli("sweep collect " + quoted(dir / "e.jsonl") + " " + quoted(dir / "empty.jsonl"));
  EXPECT_EQ(empty_merge.code, 3) << empty_merge.out;
  EXPECT_NE(empty_merge.out.find("hold no finished cell"), std::string::npos) << empty_merge.out;
  EXPECT_FALSE(fs::exists(dir / "e.jsonl"));
}

TEST(SweepRun, SmokeSweepRunsAndEveryLineIsWellFormed) {
  test::ScratchDir dir;
  const fs::path smoke = fs::path(SB_SOURCE_DIR) / "ci" / "smoke.toml";
  const auto start = std::chrono::steady_clock::now();
  const test::CliRun r =
      test::run_cli("sweep run " + quoted(smoke) + " --out " + quoted(dir / "smoke") + " --scenes-dir " + quoted(dir / "scenes"));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(r.code, 0) << r.out;
  std::printf("smoke sweep: %.1f s wall\n", seconds);  // a measurement, not an assertion (DESIGN §8)

  const test::CliRun listed = test::run_cli("sweep cells " + quoted(smoke));
  ASSERT_EQ(listed.code, 0) << listed.out;
  const std::vector<json> cells = validation::read_results(dir / "smoke" / "results.jsonl").cells;
  const test::CliRun pipelines = test::run_cli("pipelines");
  size_t registered = 0;
  for (std::istringstream in(pipelines.out); !in.eof();) {
    std::string line;
    std::getline(in, line);
    if (line.find(" source: ") != std::string::npos) ++registered;  // one such line per pipeline
  }
  ASSERT_EQ(cells.size(), 2u);
  for (const json& c : cells) {
    SCOPED_TRACE(c["cell_id"].get<std::string>());
    EXPECT_EQ(c["kind"], "stereobench.sweep_cell");
    EXPECT_EQ(c["schema_version"], 1);
    EXPECT_EQ(c["sweep"], "smoke");
    EXPECT_EQ(c["definition_sha256"].get<std::string>().size(), 64u);
    EXPECT_EQ(c["cell_count"], 2);
    EXPECT_EQ(c["rig"]["width"], 320);
    EXPECT_EQ(c["jobs"], 1);
    EXPECT_GT(c["wall_s"].get<double>(), 0.0);
    EXPECT_EQ(c["pipelines"].size(), registered + 1) << "every pipeline, and bidir-warp:occlusion=ztest";
    EXPECT_EQ(c["pipelines"]["bidir-warp:occlusion=ztest"]["validation"]["options"]["occlusion"], "ztest");
    for (const auto& [name, p] : c["pipelines"].items()) {
      SCOPED_TRACE(name);
      const json& v = p["validation"];
      EXPECT_EQ(v["kind"], "stereobench.validation");
      EXPECT_EQ(v["pipeline"], name);
      EXPECT_TRUE(v["metrics"]["ssim"].is_number());
      EXPECT_TRUE(v["metrics"]["psnr"].is_number() || v["metrics"]["psnr"] == "inf");
      const json& t = p["timing"];
      EXPECT_EQ(t["repetitions"], 1);
      EXPECT_EQ(t["samples_s"].size(), 1u);
      EXPECT_GT(t["median_s"].get<double>(), 0.0);
      EXPECT_GT(t["speedup_median"].get<double>(), 0.0);
      // The right eye's share of the left's, where the stages split between the eyes.
      const bool shared = name.rfind("bidir-warp", 0) == 0;
      ASSERT_TRUE(t.contains("right_over_left_median")) << t.dump();
      EXPECT_EQ(t.at("right_over_left_median").is_null(), shared) << t.dump();
      if (!shared) {
        EXPECT_GT(t.at("right_over_left_median").get<double>(), 0.0);
      }
      // The validation run names the eye of each of its stages.
      ASSERT_TRUE(v.contains("stage_eyes") && v.at("stage_eyes").is_object()) << v.dump();
      EXPECT_EQ(v.at("stage_eyes").size(), v.at("timings_s").size());
      for (const auto& [stage, eye] : v.at("stage_eyes").items()) {
        EXPECT_TRUE(v.at("timings_s").contains(stage)) << stage;
        EXPECT_TRUE(eye == "left" || eye == "right" || eye == "both") << stage << " " << eye;
      }
      if (name == "plain-rt") {
        EXPECT_EQ(t["speedup_median"], 1.0);
        EXPECT_EQ(v["metrics"]["psnr"], "inf");  // plain-rt's right eye is the built-in truth
      }
      for (const char* kind : {"right_png", "diff_png", "ssim_png", "holes_png"})
        EXPECT_TRUE(fs::exists(dir / "smoke" / c["images"]["pipelines"][name][kind].get<std::string>())) << kind;
    }
  }
  EXPECT_NE(cells[0]["rig"]["interaxial_m"], cells[1]["rig"]["interaxial_m"]);
}

/// Runs a one-cell sweep (box-wall at 96x54, one repetition, no warm-up) with `sweep_keys` in its
/// [sweep] table and `tables` after it into dir/out, and returns its cell; the test fails (and the
/// cell is null) where it does not run.
json run_one_cell(const test::ScratchDir& dir, const std::string& sweep_keys, const std::string& tables = "") {
  const fs::path def = dir / "one-cell.toml";
  std::ofstream(def) << "[sweep]\nscenes = [\"box-wall\"]\nresolutions = [\"96x54\"]\n"
                     << sweep_keys << "[timing]\nrepetitions = 1\nwarmup = 0\n" << tables;
  const test::CliRun r = test::run_cli("sweep run " + quoted(def) + " --out " + quoted(dir / "out") + " --scenes-dir " +
                                       quoted(dir / "scenes"));
  EXPECT_EQ(r.code, 0) << r.out;
  if (r.code != 0) return nullptr;
  const std::vector<json> cells = validation::read_results(dir / "out" / "results.jsonl").cells;
  EXPECT_EQ(cells.size(), 1u);
  return cells.size() == 1 ? cells[0] : json(nullptr);
}

TEST(SweepRun, VariantsAreValidatedAndTimedUnderTheirOwnName) {
  test::ScratchDir dir;
  const json c = run_one_cell(dir, R"(name = "variants"
pipelines = ["plain-raster", "bidir-warp", "bidir-warp:occlusion=ztest"]
baseline = "plain-raster"
)",
                              "[options.bidir-warp]\nmax_crack = 3\n");
  ASSERT_TRUE(c.is_object());
  ASSERT_EQ(c["pipelines"].size(), 3u);
  const json& plain = c["pipelines"]["bidir-warp"];
  const json& ztest = c["pipelines"]["bidir-warp:occlusion=ztest"];
  EXPECT_EQ(ztest["validation"]["pipeline"], "bidir-warp:occlusion=ztest");
  EXPECT_EQ(ztest["validation"]["options"]["occlusion"], "ztest");
  EXPECT_EQ(ztest["validation"]["options"]["max_crack"], "3");
  EXPECT_EQ(plain["validation"]["options"]["occlusion"], "none");
  EXPECT_EQ(ztest["timing"]["samples_s"].size(), 1u);
  EXPECT_NE(ztest["validation"]["counters"], plain["validation"]["counters"]) << "two different renders";
  const std::string right = c["images"]["pipelines"]["bidir-warp:occlusion=ztest"]["right_png"];
  EXPECT_EQ(fs::path(right).filename(), "bidir-warp@occlusion=ztest_right.png");
  EXPECT_TRUE(fs::exists(dir / "out" / right));
}

TEST(SweepRun, AnOverExposedTruthIsSaidForItsCell) {
  // A wall and floor under a lamp a thousand times too bright: most of the truth clips at 255,
  // where no pipeline's error can show. The sweep says so, naming the cell, as validate does.
  test::ScratchDir dir;
  scenes::GltfBuilder b("bright", 1);
  const int grey = b.add_material("grey", vec3(0.6f));
  b.add_node("wall", b.add_mesh("wall", scenes::make_box(vec3(-3.0f, 0.0f, -2.2f), vec3(3.0f, 2.5f, -2.0f)), grey));
  b.add_node("floor", b.add_mesh("floor", scenes::make_box(vec3(-3.0f, -0.1f, -2.0f), vec3(3.0f, 0.0f, 2.0f)), grey));
  b.add_point_light("lamp", vec3(0.0f, 2.0f, 2.0f), vec3(1.0f), 15000.0f);
  b.set_camera("camera", CameraPose::look_at(dvec3(0.0, 1.2, 2.5), dvec3(0.0, 1.0, -2.0)), 0.8, 0.05, 0.0,
               RigDefaults{});
  b.write(dir / "bright.gltf");
  std::ofstream(dir / "bright.toml") << "[sweep]\nname = \"bright\"\nscenes = [\"bright.gltf\"]\nresolutions = [\"64x36\"]\n"
                                        "pipelines = [\"plain-rt\"]\n[timing]\nrepetitions = 1\nwarmup = 0\n";
  const test::CliRun r = test::run_cli("sweep run " + quoted(dir / "bright.toml") + " --out " + quoted(dir / "out"));
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("cell 0 (bright.gltf|"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("full truth: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("of the right eye's pixels are over-exposed"), std::string::npos) << r.out;
}

TEST(SweepRun, ABaselineThatSynthesizesItsLeftEyeShowsPlainRtsBesideEveryRightEye) {
  test::ScratchDir dir;
  const json cell = run_one_cell(dir, R"(name = "bidir-baseline"
pipelines = ["bidir-warp", "repro-rt"]
baseline = "bidir-warp"
)");
  ASSERT_TRUE(cell.is_object());
  const json& images = cell["images"];
  // The cell's left eye is plain-rt's traced one; bidir-warp's own goes with its images.
  const std::string left = images["left_png"];
  EXPECT_EQ(fs::path(left).filename(), "left-eye_plain-rt.png");
  const std::string own = images["pipelines"]["bidir-warp"]["left_png"];
  EXPECT_EQ(fs::path(own).filename(), "bidir-warp_left.png");
  EXPECT_FALSE(images["pipelines"]["repro-rt"].contains("left_png"));
  const test::CliRun render = test::run_cli("render --pipeline plain-rt --scene box-wall --resolution 96x54 --stereo none --out " +
                                            quoted(dir / "eyes") + " --scenes-dir " + quoted(dir / "scenes"));
  ASSERT_EQ(render.code, 0) << render.out;
  const auto psnr_of = [&](const fs::path& a, const fs::path& b) {
    const fs::path report = dir / "compare.json";
    const test::CliRun c = test::run_cli("compare " + quoted(a) + " " + quoted(b) + " --json " + quoted(report));
    EXPECT_LE(c.code, 2) << c.out;
    return json::parse(test::read_text(report))["metrics"]["psnr"];
  };
  EXPECT_EQ(psnr_of(dir / "out" / left, dir / "eyes" / "box-wall_plain-rt_left.png"), "inf");
  EXPECT_NE(psnr_of(dir / "out" / own, dir / "eyes" / "box-wall_plain-rt_left.png"), "inf");
}

TEST(SweepRun, AGltfAnimationPlaysAlongThePath) {
  test::ScratchDir dir;
  // One box keyed 1 m along +X over 3 s before a still wall; the camera stays.
  scenes::GltfBuilder b("keyed-box", 1);
  const int grey = b.add_material("grey", vec3(0.6f));
  const int box = b.add_node("box", b.add_mesh("box", scenes::make_box(vec3(-0.3f), vec3(0.3f)), grey));
  b.add_node("wall", b.add_mesh("wall", scenes::make_box(vec3(-3.0f, -1.0f, -2.2f), vec3(3.0f, 2.0f, -2.0f)), grey));
  b.add_point_light("lamp", vec3(0.0f, 2.0f, 3.0f), vec3(1.0f), 15.0f);
  b.set_camera("camera", CameraPose::look_at(dvec3(0.0, 0.0, 4.0), dvec3(0.0)), 0.8, 0.05, 0.0, RigDefaults{});
  const std::vector<float> times = {0.0f, 3.0f}, keys = {0, 0, 0, 1, 0, 0};
  b.add_animation_channel(box, "translation", times, keys);
  b.write(dir / "keyed.gltf");
  std::ofstream(dir / "keyed.toml") << "[sweep]\nscenes = [\"keyed.gltf\"]\npipelines = [\"repro-rt\"]\n"
                                       "resolutions = [\"96x54\"]\n[timing]\nrepetitions = 1\nwarmup = 0\n"
                                       "[path]\nframes = 2\ngltf_animation = true\n";
  const test::CliRun r = test::run_cli("sweep run " + quoted(dir / "keyed.toml") + " --out " + quoted(dir / "out"));
  ASSERT_EQ(r.code, 0) << r.out;
  const std::vector<json> cells = validation::read_results(dir / "out" / "results.jsonl").cells;
  ASSERT_EQ(cells.size(), 2u);
  for (int f = 0; f < 2; ++f) {
    const json& a = cells[static_cast<size_t>(f)]["animation"];
    EXPECT_DOUBLE_EQ(a["animation_time_s"].get<double>(), 3.0 * f) << "frames spread over the keys' 0..3 s";
    EXPECT_EQ(a["turning_meshes"], 1) << "the box moves, the wall does not";
    EXPECT_EQ(a["moving_lights"], 0);
  }
  EXPECT_NE(test::read_text(dir / "out" / cells[0]["images"]["truth_png"].get<std::string>()),
            test::read_text(dir / "out" / cells[1]["images"]["truth_png"].get<std::string>()))
      << "the box moved between the frames";
}

/// Three frames of the box turning about the vertical through its centre, 64x36, two pipelines.
constexpr const char* kSpinSweep = R"([sweep]
name = "spin"
scenes = ["box-wall"]
pipelines = ["plain-rt", "repro-rt"]
resolutions = ["64x36"]

[path]
frames = 3
bvh = "refit"

[path.spin]
axis = [0, 1, 0]
degrees_per_frame = 20
mesh_prefix = "box"

[timing]
repetitions = 1
warmup = 0
)";

TEST(SweepRun, PathFramesAnimateTheSceneAndResumeMidPath) {
  test::ScratchDir dir;
  std::ofstream(dir / "spin.toml") << kSpinSweep;
  const std::string run = "sweep run " + quoted(dir / "spin.toml") + " --out " + quoted(dir / "out") +
                          " --scenes-dir " + quoted(dir / "scenes") + " --threads 1";
  const fs::path results = dir / "out" / "results.jsonl";
  const test::CliRun first = test::run_cli(run);
  ASSERT_EQ(first.code, 0) << first.out;
  const std::vector<std::string> lines = lines_of(results);
  ASSERT_EQ(lines.size(), 3u);
  std::vector<json> cells;
  for (const std::string& line : lines) cells.push_back(json::parse(line));
  for (int k = 0; k < 3; ++k) {
    SCOPED_TRACE(k);
    const json& c = cells[static_cast<size_t>(k)];
    EXPECT_EQ(c["cell"]["frame"], k);
    EXPECT_EQ(c["cell_id"], "box-wall|e=default|c=default|64x36|lights=all|full|frame=" + std::to_string(k));
    const json& a = c["animation"];
    EXPECT_EQ(a["frame"], k);
    EXPECT_EQ(a["frames"], 3);
    EXPECT_EQ(a["turning_meshes"], 1);
    EXPECT_GT(a["bvh_update_s"].get<double>(), 0.0);
    EXPECT_GE(a["animate_s"].get<double>(), 0.0);
    // One process runs the frames in order: frame 0 builds the BVH, later frames refit it.
    EXPECT_EQ(a["bvh"], k == 0 ? "build" : "refit");
  }
  // The box moved: the right eye of each frame differs, and with it what repro-rt gets wrong.
  for (int k = 1; k < 3; ++k) {
    SCOPED_TRACE(k);
    EXPECT_NE(measured(cells[static_cast<size_t>(k)])["repro-rt"]["metrics"],
              measured(cells[static_cast<size_t>(k - 1)])["repro-rt"]["metrics"]);
    EXPECT_NE(test::read_text(dir / "out" / cells[static_cast<size_t>(k)]["images"]["truth_png"].get<std::string>()),
              test::read_text(dir / "out" / cells[static_cast<size_t>(k - 1)]["images"]["truth_png"].get<std::string>()));
  }

  // Resumed mid-path: frame 2 alone, on a scene prepared anew at frame 2, measures the same.
  std::ofstream(results, std::ios::trunc) << lines[0] << "\n" << lines[1] << "\n";
  const test::CliRun resumed = test::run_cli(run);
  ASSERT_EQ(resumed.code, 0) << resumed.out;
  EXPECT_NE(resumed.out.find("2 finished already, 1 to run"), std::string::npos) << resumed.out;
  const std::vector<std::string> after = lines_of(results);
  ASSERT_EQ(after.size(), 3u);
  EXPECT_EQ(after[0], lines[0]);
  EXPECT_EQ(after[1], lines[1]);
  const json again = json::parse(after[2]);
  EXPECT_EQ(again["cell_id"], cells[2]["cell_id"]);
  EXPECT_EQ(again["animation"]["bvh"], "build");  // the timing says the BVH was built, not refit
  EXPECT_EQ(measured(again), measured(cells[2]));
  EXPECT_EQ(again["rig"], cells[2]["rig"]);
}

TEST(SweepRun, PathCameraKeysMoveTheCamera) {
  test::ScratchDir dir;
  std::ofstream(dir / "walk.toml") << R"([sweep]
name = "walk"
scenes = ["box-wall"]
pipelines = ["repro-rt"]
resolutions = ["64x36"]

[path]
frames = 3
camera_keys = [[-1, 1.2, 1.5, 0, 0.4, -2.5], [1, 1.2, 1.5, 0, 0.4, -2.5]]

[timing]
repetitions = 1
warmup = 0

[output]
images = false
)";
  const test::CliRun r = test::run_cli("sweep run " + quoted(dir / "walk.toml") + " --out " + quoted(dir / "out") +
                                       " --scenes-dir " + quoted(dir / "scenes") + " --threads 1");
  ASSERT_EQ(r.code, 0) << r.out;
  const std::vector<json> cells = validation::read_results(dir / "out" / "results.jsonl").cells;
  ASSERT_EQ(cells.size(), 3u);
  // Two keys over three frames: x = -1, 0, 1 (linear in position); nothing turns, the BVH stays.
  const double expected_x[] = {-1.0, 0.0, 1.0};
  for (size_t k = 0; k < 3; ++k) {
    SCOPED_TRACE(k);
    const json& a = cells[k]["animation"];
    EXPECT_NEAR(a["camera"]["position"][0].get<double>(), expected_x[k], 1e-12);
    EXPECT_NEAR(a["camera"]["position"][1].get<double>(), 1.2, 1e-12);
    EXPECT_EQ(a["turning_meshes"], 0);
    EXPECT_EQ(a["bvh"], k == 0 ? "build" : "static");
  }
  EXPECT_NE(cells[0]["pipelines"]["repro-rt"]["validation"]["metrics"],
            cells[2]["pipelines"]["repro-rt"]["validation"]["metrics"]);
}

TEST(SweepRun, BadDefinitionAndShardAreUsageErrors) {
  test::ScratchDir dir;
  std::ofstream(dir / "bad.toml") << "[sweep]\nscenes = [\"box-wall\"]\nresolution = [\"96x54\"]\n";
  const test::CliRun bad = test::run_cli("sweep run " + quoted(dir / "bad.toml") + " --out " + quoted(dir / "o"));
  EXPECT_EQ(bad.code, 3) << bad.out;
  EXPECT_NE(bad.out.find("bad.toml:3: sweep.resolution: unknown key"), std::string::npos) << bad.out;
  EXPECT_FALSE(fs::exists(dir / "o" / "results.jsonl"));
  std::ofstream(dir / "ok.toml") << kTinySweep;
  const test::CliRun shard = test::run_cli("sweep run " + quoted(dir / "ok.toml") + " --shard 2/2 --out " + quoted(dir / "o"));
  EXPECT_EQ(shard.code, 3) << shard.out;
  // A shard count near SIZE_MAX: the step past the last cell wrapped round to cell 0, another
  // shard's.
  EXPECT_EQ(validation::shard_cells(6, validation::parse_shard("1/18446744073709551615")), std::vector<size_t>{1});
  EXPECT_EQ(validation::shard_cells(6, validation::parse_shard("5/18446744073709551615")), std::vector<size_t>{5});
  EXPECT_EQ(validation::shard_cells(7, validation::parse_shard("2/3")), (std::vector<size_t>{2, 5}));
  EXPECT_EQ(validation::shard_cells(6, validation::parse_shard("0/1")), (std::vector<size_t>{0, 1, 2, 3, 4, 5}));
  // An output folder that cannot be one fails before any cell runs.
  std::ofstream(dir / "afile") << "x";
  const test::CliRun unusable =
      test::run_cli("sweep run " + quoted(dir / "ok.toml") + " --out " + quoted(dir / "afile") + " --results " +
                    quoted(dir / "r.jsonl") + " --scenes-dir " + quoted(dir / "scenes"));
  EXPECT_EQ(unusable.code, 4) << unusable.out;
  EXPECT_NE(unusable.out.find("cannot use " + (dir / "afile").string() + " as an output folder"), std::string::npos)
      << unusable.out;
  EXPECT_EQ(unusable.out.find("[1/6]"), std::string::npos) << "no cell may run: " << unusable.out;
  EXPECT_FALSE(fs::exists(dir / "r.jsonl"));
  // --results naming --out's folder, which only the run creates, is refused before any cell runs
  // (the first cell's results used to fail to append).
  const test::CliRun same = test::run_cli("sweep run " + quoted(dir / "ok.toml") + " --out " + quoted(dir / "both") +
                                          " --results " + quoted(dir / "both") + " --scenes-dir " +
                                          quoted(dir / "scenes"));
  EXPECT_EQ(same.code, 3) << same.out;
  EXPECT_NE(same.out.find("--results " + (dir / "both").string() + " is a folder"), std::string::npos) << same.out;
  EXPECT_EQ(same.out.find("[1/6]"), std::string::npos) << "no cell may run: " << same.out;
  EXPECT_FALSE(fs::exists(dir / "both" / "cells"));
  // The same definition under another file name is another sweep (the name is the file's): the
  // message says so, rather than that the definition changed.
  std::string nameless = kTinySweep;
  nameless.erase(nameless.find("name = "), std::string("name = \"tiny\"\n").size());
  std::ofstream(dir / "nameless.toml") << nameless;
  const test::CliRun first = test::run_cli("sweep run " + quoted(dir / "nameless.toml") + " --shard 0/6 --out " +
                                           quoted(dir / "named") + " --scenes-dir " + quoted(dir / "scenes"));
  ASSERT_EQ(first.code, 0) << first.out;
  fs::copy_file(dir / "nameless.toml", dir / "renamed.toml");
  const test::CliRun renamed = test::run_cli("sweep run " + quoted(dir / "renamed.toml") + " --out " +
                                             quoted(dir / "named") + " --scenes-dir " + quoted(dir / "scenes"));
  EXPECT_EQ(renamed.code, 3) << renamed.out;
  EXPECT_NE(renamed.out.find("has the same content but is named 'renamed'"), std::string::npos) << renamed.out;
  // A damaged marker (valid JSON, not an object) names no definition: refused as another's, not
  // an internal error.
  fs::create_directories(dir / "marked");
  std::ofstream(dir / "marked" / ".stereobench-sweep.json") << "[1]\n";
  const test::CliRun damaged = test::run_cli("sweep run " + quoted(dir / "ok.toml") + " --out " +
                                             quoted(dir / "marked") + " --scenes-dir " + quoted(dir / "scenes"));
  EXPECT_EQ(damaged.code, 3) << damaged.out;
  EXPECT_NE(damaged.out.find("holds a damaged sweep marker " + (dir / "marked" / ".stereobench-sweep.json").string()),
            std::string::npos)
      << damaged.out;
  // A definition with a cell that cannot run is refused before the first cell runs, naming the
  // cell (the last of two here); it used to stop the sweep only when its turn came.
  const auto refused = [&](const std::string& name, const std::string& axes, const std::string& message) {
    std::ofstream(dir / (name + ".toml")) << "[sweep]\nname = \"" << name << "\"\nscenes = [\"box-wall\"]\n" << axes
                                          << "resolutions = [\"96x54\"]\n";
    const test::CliRun r = test::run_cli("sweep run " + quoted(dir / (name + ".toml")) + " --out " +
                                         quoted(dir / name) + " --scenes-dir " + quoted(dir / "scenes"));
    EXPECT_EQ(r.code, 3) << r.out;
    EXPECT_NE(r.out.find((dir / (name + ".toml")).string() + ": cell 1 "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(message), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("[1/2]"), std::string::npos) << "no cell may run: " << r.out;
    EXPECT_FALSE(fs::exists(dir / name / "results.jsonl"));
  };
  // A rig that cannot be: a convergence that puts the disparity at infinity beyond any image.
  refused("near", "pipelines = [\"plain-rt\"]\nconvergence_m = [2.0, 1e-300]\n",
          "fix the definition (no cell has run)");
  // A rig a pipeline cannot work with: at a convergence of 1 mm the max disparity at 96x54 is some
  // 3000 px, and rt-buffer's default depth 2e exceeds its limit.
  refused("deep", "pipelines = [\"plain-rt\", \"rt-buffer\"]\nconvergence_m = [2.0, 0.001]\n",
          "rt-buffer: the default depth t = 2 x max disparity");
  // A damaged scene file: refused naming the definition, the scene and its cells, then the file.
  std::ofstream(dir / "cut.gltf") << "{\"asset\": {\"version\": \"2.0\"}, \"buffers\": [";
  std::ofstream(dir / "cut.toml") << "[sweep]\nname = \"cut\"\nscenes = [\"box-wall\", \"cut.gltf\"]\n"
                                     "pipelines = [\"plain-rt\"]\nresolutions = [\"96x54\", \"32x18\"]\n";
  const test::CliRun cut = test::run_cli("sweep run " + quoted(dir / "cut.toml") + " --out " + quoted(dir / "cut") +
                                         " --scenes-dir " + quoted(dir / "scenes"));
  EXPECT_EQ(cut.code, 3) << cut.out;
  EXPECT_NE(cut.out.find((dir / "cut.toml").string() + ": scene 'cut.gltf' of 2 cells (the first: cell 2 'cut.gltf|"),
            std::string::npos)
      << cut.out;
  EXPECT_NE(cut.out.find((dir / "cut.gltf").string() + ": not valid JSON"), std::string::npos) << cut.out;
  EXPECT_NE(cut.out.find("fix the scene file or the definition (no cell has run)"), std::string::npos) << cut.out;
  EXPECT_EQ(cut.out.find("[1/4]"), std::string::npos) << "no cell may run: " << cut.out;
  // Fixed, it runs into the same folder: the refused run did not claim it for the old definition.
  std::ofstream(dir / "near.toml", std::ios::trunc)
      << "[sweep]\nname = \"near\"\nscenes = [\"box-wall\"]\npipelines = [\"plain-rt\"]\n"
         "convergence_m = [2.0, 3.0]\nresolutions = [\"96x54\"]\n[timing]\nrepetitions = 1\nwarmup = 0\n";
  const test::CliRun fixed = test::run_cli("sweep run " + quoted(dir / "near.toml") + " --out " + quoted(dir / "near") +
                                           " --scenes-dir " + quoted(dir / "scenes"));
  EXPECT_EQ(fixed.code, 0) << fixed.out;
}


TEST(SweepRun, AFolderNameThatIsNotUtf8IsWrittenNotAnInternalError) {
  // A definition in a folder named in another encoding: its path goes into the folder marker and
  // the results lines as JSON, which holds UTF-8 only (the marker's write was an internal error).
  test::ScratchDir dir;
  const fs::path folder = dir / "latin\xe9";
  fs::create_directories(folder);
  std::ofstream(folder / "t.toml") << "[sweep]\nscenes = [\"box-wall\"]\npipelines = [\"plain-rt\"]\n"
                                      "resolutions = [\"32x18\"]\n[timing]\nrepetitions = 1\nwarmup = 0\n";
  const test::CliRun r = test::run_cli("sweep run " + quoted(folder / "t.toml") + " --out " + quoted(folder / "o") +
                                       " --scenes-dir " + quoted(dir / "scenes") + " --cache ''");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(validation::read_results(folder / "o" / "results.jsonl").cells.size(), 1u);
  EXPECT_NE(test::read_text(folder / "o" / ".stereobench-sweep.json").find("latin\ufffd"), std::string::npos);
  // A definition named by such a file name would be named alike in every line: refused, saying how.
  fs::copy_file(folder / "t.toml", folder / "caf\xe9.toml");
  const test::CliRun named = test::run_cli("sweep run " + quoted(folder / "caf\xe9.toml") + " --out " +
                                           quoted(folder / "o2") + " --scenes-dir " + quoted(dir / "scenes"));
  EXPECT_EQ(named.code, 3) << named.out;
  EXPECT_NE(named.out.find("whose name is not UTF-8; rename the file, or give the sweep a name"), std::string::npos)
      << named.out;
}

TEST(SweepRun, TwoDefinitionsStartedTogetherIntoOneFolderDoNotBothRun) {
  // A sweep checks the folder's marker and writes its own under a lock on the folder. Held here,
  // the sweep waits at the check; the marker of another definition written meanwhile (as the sweep
  // holding the lock would) is then found, and the waiting sweep is refused, as it is when it
  // starts after (both used to find no marker, run, and overwrite each other's images).
  test::ScratchDir dir;
  std::ofstream(dir / "b.toml") << "[sweep]\nname = \"b\"\nscenes = [\"box-wall\"]\npipelines = [\"plain-rt\"]\n"
                                   "resolutions = [\"64x36\"]\n[timing]\nrepetitions = 1\nwarmup = 0\n";
  fs::create_directories(dir / "out");
  {
    io::FileLock held = io::FileLock::acquire(dir / "out");
    test::start_cli_in_background("sweep run " + quoted(dir / "b.toml") + " --out " + quoted(dir / "out") +
                                      " --results " + quoted(dir / "b.jsonl") + " --threads 1 --scenes-dir " +
                                      quoted(dir / "scenes"),
                                  dir / "b.log");
    ASSERT_TRUE(test::wait_for_lock_waiter(dir / "out")) << test::read_text(dir / "b.log");
    std::ofstream(dir / "out" / ".stereobench-sweep.json")
        << json{{"sweep", "a"}, {"definition_sha256", std::string(64, '0')}, {"definition", "a.toml"}}.dump(2) << "\n";
  }
  const test::CliRun b = test::wait_for_background(dir / "b.log");
  EXPECT_EQ(b.code, 3) << b.out;
  EXPECT_NE(b.out.find("holds the cells of sweep 'a'"), std::string::npos) << b.out;
  EXPECT_FALSE(fs::exists(dir / "out" / "cells")) << "no cell ran";
  EXPECT_EQ(json::parse(test::read_text(dir / "out" / ".stereobench-sweep.json"))["sweep"], "a");
}

/// Writes DIR/two.toml: two cells (two interaxial distances) of plain-rt and repro-rt at 64x36 on
/// `scene`; "scene.gltf" is first generated there as box-wall, which the caller may then change.
void write_two_cell_sweep(const test::ScratchDir& dir, const std::string& scene) {
  if (scene == "scene.gltf") {
    ASSERT_EQ(test::run_cli("scenes generate box-wall --out " + quoted(dir / "gen")).code, 0);
    fs::copy_file(dir / "gen" / "box-wall.gltf", dir / "scene.gltf");
  }
  std::ofstream(dir / "two.toml") << "[sweep]\nname = \"two\"\nscenes = [\"" << scene
                                  << "\"]\npipelines = [\"plain-rt\", \"repro-rt\"]\ninteraxial_m = [0.04, 0.064]\n"
                                     "resolutions = [\"64x36\"]\n[timing]\nrepetitions = 1\nwarmup = 0\n";
}

TEST(SweepRun, AResumeRefusesNewCellsOfASceneThatChanged) {
  // Two cells on a scene file; the first measured, then the file regenerated with a larger box.
  test::ScratchDir dir;
  write_two_cell_sweep(dir, "scene.gltf");
  const std::string run = "sweep run " + quoted(dir / "two.toml") + " --out " + quoted(dir / "out") + " --threads 1";
  ASSERT_EQ(test::run_cli(run).code, 0);
  const fs::path results = dir / "out" / "results.jsonl";
  const std::vector<std::string> lines = lines_of(results);
  ASSERT_EQ(lines.size(), 2u);
  const std::string recorded = json::parse(lines[0])["scene"]["content_sha256"];
  EXPECT_EQ(recorded.size(), 64u);
  std::ofstream(results, std::ios::trunc) << lines[0] << "\n";

  ASSERT_EQ(test::run_cli("scenes generate box-wall --param size=0.9 --out " + quoted(dir / "gen")).code, 0);
  fs::path changed;
  for (const auto& e : fs::directory_iterator(dir / "gen"))
    if (e.path().extension() == ".gltf" && e.path().filename() != "box-wall.gltf") changed = e.path();
  ASSERT_FALSE(changed.empty());
  fs::copy_file(changed, dir / "scene.gltf", fs::copy_options::overwrite_existing);
  const test::CliRun refused = test::run_cli(run);
  EXPECT_EQ(refused.code, 3) << refused.out;
  EXPECT_NE(refused.out.find("was measured on scene 'scene.gltf' with content sha256 " + recorded.substr(0, 12)),
            std::string::npos)
      << refused.out;
  EXPECT_NE(refused.out.find("the scene changed since those cells ran"), std::string::npos) << refused.out;
  EXPECT_EQ(lines_of(results).size(), 1u) << "no cell ran";

  // The scene as it was: the resume runs the cell left.
  fs::copy_file(dir / "gen" / "box-wall.gltf", dir / "scene.gltf", fs::copy_options::overwrite_existing);
  const test::CliRun resumed = test::run_cli(run);
  EXPECT_EQ(resumed.code, 0) << resumed.out;
  EXPECT_EQ(lines_of(results).size(), 2u);
}

TEST(SweepRun, ShardsOfAnotherSceneContentOrPipelineSetDoNotJoin) {
  // Two shards of one definition, each in its own results file (as Slurm's tasks write them): the
  // scene file is regenerated between them, so only a merge can see the two contents.
  test::ScratchDir dir;
  write_two_cell_sweep(dir, "scene.gltf");
  const auto shard = [&](int i) {
    return "sweep run " + quoted(dir / "two.toml") + " --out " + quoted(dir / "out") + " --threads 1 --shard " +
           std::to_string(i) + "/2 --results " + quoted(dir / ("s" + std::to_string(i) + ".jsonl"));
  };
  ASSERT_EQ(test::run_cli(shard(0)).code, 0);
  // Gated alone, a shard's file is not the sweep: the gate says so, and its command to finish
  // runs that shard into that file (it ran every cell into it, and the merge then failed).
  std::ofstream(dir / "gate.toml") << "[defaults]\nmin_psnr = 20\n";
  const test::CliRun one_shard =
      test::run_cli("gate --config " + quoted(dir / "gate.toml") + " --results " + quoted(dir / "s0.jsonl"));
  EXPECT_EQ(one_shard.code, 2) << one_shard.out;
  EXPECT_NE(one_shard.out.find("it is the results file of shard 0/2, which has all of its 1 cells; merge every "
                               "shard's results file with `stereobench sweep collect`"),
            std::string::npos)
      << one_shard.out;
  EXPECT_NE(one_shard.out.find(" --out " + (dir / "out").string() + " --shard 0/2 --results " +
                               (dir / "s0.jsonl").string()),
            std::string::npos)
      << one_shard.out;
  ASSERT_EQ(test::run_cli("scenes generate box-wall --param size=0.9 --out " + quoted(dir / "gen")).code, 0);
  for (const auto& e : fs::directory_iterator(dir / "gen"))
    if (e.path().extension() == ".gltf" && e.path().filename() != "box-wall.gltf")
      fs::copy_file(e.path(), dir / "scene.gltf", fs::copy_options::overwrite_existing);
  ASSERT_EQ(test::run_cli(shard(1)).code, 0);
  const std::string collect =
      "sweep collect " + quoted(dir / "all.jsonl") + " " + quoted(dir / "s0.jsonl") + " " + quoted(dir / "s1.jsonl");
  const test::CliRun mixed = test::run_cli(collect);
  EXPECT_EQ(mixed.code, 3) << mixed.out;
  EXPECT_NE(mixed.out.find("was measured on scene 'scene.gltf' with content sha256"), std::string::npos) << mixed.out;
  EXPECT_NE(mixed.out.find("the scene changed between the runs of one sweep"), std::string::npos) << mixed.out;
  EXPECT_FALSE(fs::exists(dir / "all.jsonl"));
  // Joined into one file by hand, the gate refuses the two contents as well.
  std::ofstream(dir / "joined.jsonl") << test::read_text(dir / "s0.jsonl") << test::read_text(dir / "s1.jsonl");
  const test::CliRun gated =
      test::run_cli("gate --config " + quoted(dir / "gate.toml") + " --results " + quoted(dir / "joined.jsonl"));
  EXPECT_EQ(gated.code, 3) << gated.out;
  EXPECT_NE(gated.out.find("the scene changed between the runs of one sweep"), std::string::npos) << gated.out;

  // Shard 1 as a build without repro-rt recorded it (the definition listing "all" pipelines, say):
  // a merge refuses it, and a resume of it by this build is refused before any cell runs.
  fs::copy_file(dir / "gen" / "box-wall.gltf", dir / "scene.gltf", fs::copy_options::overwrite_existing);
  fs::remove(dir / "s1.jsonl");
  ASSERT_EQ(test::run_cli(shard(1)).code, 0);
  json older = json::parse(lines_of(dir / "s1.jsonl").at(0));
  older["pipelines"].erase("repro-rt");
  std::ofstream(dir / "s1.jsonl", std::ios::trunc) << older.dump() << "\n";
  const test::CliRun other_set = test::run_cli(collect);
  EXPECT_EQ(other_set.code, 3) << other_set.out;
  EXPECT_NE(other_set.out.find("the cell validates pipelines plain-rt, but " + (dir / "s0.jsonl").string() +
                               " line 1 of the same definition validates plain-rt, repro-rt"),
            std::string::npos)
      << other_set.out;
  EXPECT_FALSE(fs::exists(dir / "all.jsonl"));
  fs::copy_file(dir / "s1.jsonl", dir / "s1-before.jsonl");
  const test::CliRun resumed = test::run_cli(shard(1));
  EXPECT_EQ(resumed.code, 3) << resumed.out;
  EXPECT_NE(resumed.out.find("those cells validate the pipelines plain-rt, but this build runs plain-rt, repro-rt"),
            std::string::npos)
      << resumed.out;
  EXPECT_EQ(test::read_text(dir / "s1.jsonl"), test::read_text(dir / "s1-before.jsonl")) << "no cell ran";

  // '-' is standard output for the merge and the CSV, not a file of that name.
  fs::remove(dir / "s1.jsonl");
  ASSERT_EQ(test::run_cli(shard(1)).code, 0);
  const test::CliRun to_stdout = test::run_cli("sweep collect - " + quoted(dir / "s0.jsonl") + " " +
                                               quoted(dir / "s1.jsonl"));
  EXPECT_EQ(to_stdout.code, 0) << to_stdout.out;
  EXPECT_NE(to_stdout.out.find("\"kind\":\"stereobench.sweep_cell\""), std::string::npos) << to_stdout.out;
  EXPECT_NE(to_stdout.out.find("merged 2 cells from 2 files"), std::string::npos) << to_stdout.out;
  const test::CliRun csv = test::run_cli("sweep csv " + quoted(dir / "s0.jsonl") + " --out -");
  EXPECT_EQ(csv.code, 0) << csv.out;
  EXPECT_NE(csv.out.find("cell_index,cell_id,sweep"), std::string::npos) << csv.out;
  EXPECT_FALSE(fs::exists("-"));
}

TEST(SweepRun, TwoVariantsOfOneGeneratorAreTwoScenesWithContentsOfTheirOwn) {
  // Kim's complexity preset sweeps one generator at three triangle counts: each variant has its
  // own content, which the one-content-per-scene check must not take for an edited scene.
  test::ScratchDir dir;
  std::ofstream(dir / "variants.toml") << R"([sweep]
name = "variants"
scenes = ["box-wall:size=0.5", "box-wall:size=0.9"]
pipelines = ["plain-rt", "repro-rt"]
resolutions = ["32x18"]
[timing]
repetitions = 1
warmup = 0
)";
  const test::CliRun ran = test::run_cli("sweep run " + quoted(dir / "variants.toml") + " --out " +
                                         quoted(dir / "out") + " --threads 1 --scenes-dir " + quoted(dir / "scenes"));
  ASSERT_EQ(ran.code, 0) << ran.out;
  const std::vector<json> cells = validation::read_results(dir / "out" / "results.jsonl").cells;
  ASSERT_EQ(cells.size(), 2u);
  EXPECT_NE(cells[0]["scene"]["content_sha256"], cells[1]["scene"]["content_sha256"]);
  const test::CliRun csv = test::run_cli("sweep csv " + quoted(dir / "out" / "results.jsonl"));
  EXPECT_EQ(csv.code, 0) << csv.out;
}

TEST(SweepRun, TheGateSendsASlurmTasksResultsFileToTheExecutor) {
  // A task's file (results-I.jsonl in <out>/slurm) gated alone: the command to finish the sweep is
  // the Slurm executor's, with the sweep's --out and shard count (it named <out>/slurm as --out,
  // then left out --shards).
  test::ScratchDir dir;
  write_two_cell_sweep(dir, "box-wall");
  const test::CliRun task = test::run_cli("sweep run " + quoted(dir / "two.toml") + " --out " + quoted(dir / "out") +
                                          " --threads 1 --shard 1/2 --results " +
                                          quoted(dir / "out" / "slurm" / "results-1.jsonl") + " --scenes-dir " +
                                          quoted(dir / "scenes"));
  ASSERT_EQ(task.code, 0) << task.out;
  std::ofstream(dir / "gate.toml") << "[defaults]\nmin_psnr = 20\n";
  const test::CliRun gated = test::run_cli("gate --config " + quoted(dir / "gate.toml") + " --results " +
                                           quoted(dir / "out" / "slurm" / "results-1.jsonl"));
  EXPECT_EQ(gated.code, 2) << gated.out;
  EXPECT_NE(gated.out.find("it is the results file of Slurm task 1 of 2, not the sweep's; gate " +
                           (dir / "out" / "results.jsonl").string()),
            std::string::npos)
      << gated.out;
  // With the shard count the sweep was submitted with: the default (a shard per cell) is refused
  // by a folder that holds results of another count.
  EXPECT_NE(gated.out.find("--out " + (dir / "out").string() + " --executor slurm --wait --shards 2"),
            std::string::npos)
      << gated.out;

  // Shards sharing the sweep's own results file: with one shard run, that file is the sweep's,
  // unfinished, and the command resumes the whole sweep (it named the shard, which had no cell
  // left to run).
  ASSERT_EQ(test::run_cli("sweep run " + quoted(dir / "two.toml") + " --out " + quoted(dir / "shared") +
                          " --threads 1 --shard 0/2 --scenes-dir " + quoted(dir / "scenes"))
                .code,
            0);
  const test::CliRun shared = test::run_cli("gate --config " + quoted(dir / "gate.toml") + " --results " +
                                            quoted(dir / "shared" / "results.jsonl"));
  EXPECT_EQ(shared.code, 2) << shared.out;
  EXPECT_NE(shared.out.find("holds 1 of the sweep's 2 cells: the sweep did not finish"), std::string::npos)
      << shared.out;
  EXPECT_NE(shared.out.find("--out " + (dir / "shared").string() + "\n"), std::string::npos) << shared.out;
  EXPECT_EQ(shared.out.find("--shard"), std::string::npos) << shared.out;
}

TEST(SweepRun, AnOutFolderThatCannotBeMadeIsNamed) {
  // A folder that cannot be created is named as such, not as a lock file that does not exist.
  test::ScratchDir dir;
  std::ofstream(dir / "blocker") << "a file where a folder should be\n";
  const test::CliRun r = test::run_cli("sweep run " + quoted(fs::path(SB_SOURCE_DIR) / "ci" / "smoke.toml") +
                                       " --out " + quoted(dir / "blocker" / "new"));
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("cannot create the folder " + (dir / "blocker" / "new").string()), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("give --out (or --results) a folder you can write"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("lock file"), std::string::npos) << r.out;
}

TEST(SweepRun, TheLocalExecutorRefusesAFolderSubmittedToSlurm) {
  // Its array may still be running the same cells, and the next merge would refuse a results file
  // it did not write; the Slurm tasks themselves (results in the log folder) still run.
  test::ScratchDir dir;
  fs::create_directories(dir / "out" / "slurm");
  std::ofstream(dir / "out" / "slurm" / "submission.json") << R"({"job_id": "4711", "shards": 2})";
  const std::string smoke = quoted(fs::path(SB_SOURCE_DIR) / "ci" / "smoke.toml");
  const test::CliRun r = test::run_cli("sweep run " + smoke + " --out " + quoted(dir / "out"));
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find((dir / "out").string() + " was submitted to Slurm as job 4711"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("continue it with `sweep run --executor slurm`"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "out" / "results.jsonl"));
  // A task's run: shard 39 of 40 (no cell of the smoke sweep), its results beside the submission.
  const test::CliRun task = test::run_cli("sweep run " + smoke + " --out " + quoted(dir / "out") +
                                          " --shard 39/40 --results " + quoted(dir / "out" / "slurm" / "results-39.jsonl"));
  EXPECT_EQ(task.code, 0) << task.out;
  // The Slurm folder itself as --out (the folder of a task's results file, which the gate named
  // as --out): it took cells/ and work/ beside the tasks' files.
  const test::CliRun into_slurm = test::run_cli("sweep run " + smoke + " --out " + quoted(dir / "out" / "slurm") +
                                                " --results " + quoted(dir / "out" / "slurm" / "results-0.jsonl"));
  EXPECT_EQ(into_slurm.code, 3) << into_slurm.out;
  EXPECT_NE(into_slurm.out.find((dir / "out" / "slurm").string() + " is the Slurm folder of the sweep submitted into " +
                                (dir / "out").string()),
            std::string::npos)
      << into_slurm.out;
  EXPECT_FALSE(fs::exists(dir / "out" / "slurm" / "cells"));
  EXPECT_FALSE(fs::exists(dir / "out" / "slurm" / "results-0.jsonl"));
}

}  // namespace
}  // namespace sb
