// The results file: atomic appends, a torn last line tolerated and cut before the next append,
// duplicates rejected, shards merged, CSV export.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <string>
#include <tuple>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "support/file_size_limit.hpp"
#include "support/image_metrics.hpp"
#include "support/scratch_dir.hpp"
#include "validation/results_file.hpp"

namespace sb {
namespace {

using nlohmann::json;
using namespace validation;

json cell(size_t index, const std::string& id, double psnr = 40.0) {
  return {{"kind", kSweepCellKind},
          {"schema_version", kSweepSchemaVersion},
          {"sweep", "t"},
          {"definition_sha256", "abc"},
          {"cell_id", id},
          {"cell_index", index},
          {"cell_count", 10},
          {"cell",
           {{"scene", "box-wall"}, {"scene_params", {{"size", 0.5}}}, {"resolution", "96x54"}, {"truth", "full"}}},
          {"rig", {{"width", 96}, {"height", 54}, {"interaxial_m", 0.064}, {"max_disparity_px", 3.5},
                   {"convergence_m", 2.0}}},
          {"baseline", "plain-rt"},
          {"pipelines",
           {{"plain-rt",
             {{"validation",
               {{"scene", {{"lights", 1}}},
                {"metrics", {{"psnr", psnr}, {"ssim", 0.99}, {"mse", test::mse_of_psnr(psnr)}, {"error_fraction", 0.01}}},
                {"holes", {{"hole_fraction", 0.0}, {"not_reprojected", {{"recall", 1.0}, {"precision", 0.02}}}}}}},
              {"timing", {{"median_s", 0.01}, {"speedup_median", 1.0}, {"right_over_left_median", 0.98}}}}}}}};
}

void append_text(const std::filesystem::path& file, const std::string& text) {
  std::ofstream(file, std::ios::app | std::ios::binary) << text;
}

TEST(ResultsFile, AppendAndReadBack) {
  test::ScratchDir dir;
  const auto file = dir / "sub" / "results.jsonl";
  EXPECT_TRUE(read_results(file).cells.empty());  // a missing file reads as empty
  append_result(file, cell(0, "a"));
  append_result(file, cell(1, "b", std::numeric_limits<double>::infinity()));
  const std::string text = test::read_text(file);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 2);  // one line per cell
  const ResultsFile r = read_results(file);
  ASSERT_EQ(r.cells.size(), 2u);
  EXPECT_TRUE(r.warnings.empty());
  EXPECT_EQ(r.cells[0]["cell_id"], "a");
  EXPECT_EQ(r.cells[1]["pipelines"]["plain-rt"]["validation"]["metrics"]["psnr"], "inf");
}

TEST(ResultsFile, NonFiniteNumbers) {
  const json j = finite_json({{"a", std::numeric_limits<double>::infinity()},
                              {"b", {-std::numeric_limits<double>::infinity(), std::nan("")}},
                              {"c", 1.5}});
  EXPECT_EQ(j["a"], "inf");
  EXPECT_EQ(j["b"][0], "-inf");
  EXPECT_TRUE(j["b"][1].is_null());
  EXPECT_EQ(j["c"], 1.5);
}

TEST(ResultsFile, TornLastLineSkippedThenCut) {
  test::ScratchDir dir;
  const auto file = dir / "results.jsonl";
  append_result(file, cell(0, "a"));
  const std::string whole = cell(1, "b").dump();
  append_text(file, whole.substr(0, whole.size() / 2));  // a writer killed mid-line
  const ResultsFile r = read_results(file);
  ASSERT_EQ(r.cells.size(), 1u);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("results.jsonl:2: unterminated last line"), std::string::npos) << r.warnings[0];

  // The next append removes the torn tail first, so the lines do not run together.
  append_result(file, cell(1, "b"));
  const ResultsFile after = read_results(file);
  ASSERT_EQ(after.cells.size(), 2u);
  EXPECT_TRUE(after.warnings.empty());
  EXPECT_EQ(after.cells[1], cell(1, "b"));
}

TEST(ResultsFile, AnAppendThatFailsLeavesNoPartOfItsLine) {
  test::ScratchDir dir;
  const auto file = dir / "results.jsonl";
  append_result(file, cell(0, "a"));
  const std::string before = test::read_text(file);
  bool failed = false;
  {
    // A disk that fills mid-line, 100 bytes past the current end.
    const test::FileSizeLimit limit(before.size() + 100);
    ASSERT_TRUE(limit.ok());
    try {
      append_result(file, cell(1, "b"));
    } catch (const IoError& e) {
      failed = true;
      EXPECT_NE(std::string(e.what()).find("cannot append to the results file"), std::string::npos) << e.what();
    }
  }
  EXPECT_TRUE(failed);
  EXPECT_EQ(test::read_text(file), before) << "the first 100 bytes of the line were written, then taken back";
}

TEST(ResultsFile, OneWriterPerCell) {
  test::ScratchDir dir;
  const auto file = dir / "r.jsonl";
  std::filesystem::create_symlink("r.jsonl", dir / "link.jsonl");
  {
    const ResultsWriterLock shard0(file, {0, 2, 4});
    const ResultsWriterLock shard1(file, {1, 3});  // disjoint cells: side by side
    // Any shared cell is refused, under any spelling of the file.
    for (const auto& other : {file, dir / "link.jsonl", dir / "." / "r.jsonl"}) {
      try {
        const ResultsWriterLock all(other, {0, 1, 2, 3, 4});
        ADD_FAILURE() << "a second writer of cell 0 took the lock through " << other;
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(" is being written by another stereobench run, which holds cell 0"),
                  std::string::npos)
            << e.what();
      }
    }
  }
  const ResultsWriterLock after(file, {0, 1, 2, 3, 4});  // released with their holders
}

TEST(ResultsFile, BadLinesAndDuplicatesRejected) {
  test::ScratchDir dir;
  const auto dup = dir / "dup.jsonl";
  append_result(dup, cell(0, "a"));
  append_result(dup, cell(1, "b"));
  append_result(dup, cell(0, "a"));
  try {
    (void)read_results(dup);
    FAIL() << "a duplicate cell_id was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("dup.jsonl:3: cell_id 'a' appears twice (also on line 1)"),
              std::string::npos)
        << e.what();
  }

  const auto bad = dir / "bad.jsonl";
  append_text(bad, "{not json}\n");
  append_result(bad, cell(0, "a"));
  EXPECT_THROW((void)read_results(bad), InputError);  // a broken line that is not the last

  const auto other = dir / "other.jsonl";
  append_text(other, R"({"kind": "something.else", "schema_version": 1})" "\n");
  EXPECT_THROW((void)read_results(other), InputError);

  // Every reader (resume, collect, gate, report) sees the same checks: a field of the wrong type or
  // outside what any measurement gives, a second cell with the same index, a cell of another
  // definition in the same file.
  const auto expect_refused = [&](const json& second, const std::string& expected) {
    const auto file = dir / "checked.jsonl";
    std::filesystem::remove(file);
    append_result(file, cell(0, "a"));
    append_result(file, second);
    try {
      (void)read_results(file);
      ADD_FAILURE() << "accepted: " << second.dump();
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  json wrong_type = cell(1, "b");
  wrong_type["rig"]["width"] = "96";
  expect_refused(wrong_type, "checked.jsonl:2: field 'rig.width' is \"96\" but must be an integer");
  json ssim_5 = cell(1, "b");
  ssim_5["pipelines"]["plain-rt"]["validation"]["metrics"]["ssim"] = 5;
  expect_refused(ssim_5, "checked.jsonl:2: field 'pipelines.plain-rt.validation.metrics.ssim' is 5, outside [-1, 1]");
  expect_refused(cell(0, "b"), "checked.jsonl:2: cell_index '0' appears twice (also on line 1)");
  json other_definition = cell(1, "b");
  other_definition["definition_sha256"] = "def";
  expect_refused(other_definition, "checked.jsonl:2: a cell of sweep 't' (definition sha256 def), but line 1 is of "
                                   "sweep 't' (sha256 abc); a results file holds the cells of one sweep definition");
  json no_baseline = cell(1, "b");
  no_baseline["baseline"] = "repro-rt";
  expect_refused(no_baseline, "checked.jsonl:2: baseline \"repro-rt\" is not among the cell's pipelines");
  // Values no measurement gives, which the gate used to judge as measured (a PSNR of -5 failed the
  // check instead of being refused as a damaged file; the report took negative times).
  for (const json& psnr : {json(-5.0), json("-inf")}) {
    json broken = cell(1, "b");
    broken["pipelines"]["plain-rt"]["validation"]["metrics"]["psnr"] = psnr;
    expect_refused(broken, "checked.jsonl:2: field 'pipelines.plain-rt.validation.metrics.psnr' is " + psnr.dump() +
                            ", outside [0, inf]");
  }
  // A PSNR its MSE does not give (edited to pass a minimum): the gate judged the PSNR alone.
  for (const json& psnr : {json("inf"), json(1e308), json(45.0), json(nullptr)}) {
    json broken = cell(1, "b");
    broken["pipelines"]["plain-rt"]["validation"]["metrics"]["psnr"] = psnr;
    expect_refused(broken, "checked.jsonl:2: field 'pipelines.plain-rt.validation.metrics.psnr' is " + psnr.dump() +
                               ", but its mse 6.5025 gives 40.000000");
  }
  json ssim_inf = cell(1, "b");
  ssim_inf["pipelines"]["plain-rt"]["validation"]["metrics"]["ssim"] = "inf";
  expect_refused(ssim_inf, "field 'pipelines.plain-rt.validation.metrics.ssim' is \"inf\", outside [-1, 1]");
  for (const json& sample : {json(-1.0), json(nullptr)}) {
    json broken = cell(1, "b");
    broken["pipelines"]["plain-rt"]["timing"]["samples_s"] = {0.01, sample};
    expect_refused(broken, "checked.jsonl:2: field 'pipelines.plain-rt.timing.samples_s' holds " + sample.dump() +
                            ", not a time in seconds");
  }
  // Stage times, the cell's wall time and the order of min, median and max (a negative stage time
  // reached the per-stage bars), and the definition's hash a string (a number was an internal error).
  for (const json& t : {json(-0.5), json("fast"), json(nullptr)}) {
    json stage = cell(1, "b");
    stage["pipelines"]["plain-rt"]["timing"]["stages_median_s"] = {{"hole_fill", t}};
    expect_refused(stage, "checked.jsonl:2: field 'pipelines.plain-rt.timing.stages_median_s.hole_fill' holds " +
                              t.dump() + ", not a time in seconds");
    json validated = cell(1, "b");
    validated["pipelines"]["plain-rt"]["validation"]["timings_s"] = {{"trace", t}};
    expect_refused(validated, "field 'pipelines.plain-rt.validation.timings_s.trace' holds " + t.dump());
  }
  json wall = cell(1, "b");
  wall["wall_s"] = -3.0;
  expect_refused(wall, "checked.jsonl:2: field 'wall_s' is -3.0, outside [0,");
  json unordered = cell(1, "b");
  unordered["pipelines"]["plain-rt"]["timing"].update({{"min_s", 0.02}, {"max_s", 0.03}});
  expect_refused(unordered, "'pipelines.plain-rt.timing.min_s', 'median_s' and 'max_s' are 0.02, 0.01 and 0.03, not "
                            "in order");
  json sha = cell(1, "b");
  sha["definition_sha256"] = 7;
  expect_refused(sha, "checked.jsonl:2: field 'definition_sha256' is 7 but must be a string");
  // cell_index within cell_count, and one cell_count per file.
  json beyond = cell(10, "z");
  expect_refused(beyond, "checked.jsonl:2: cell_index 10 is not below cell_count 10");
  json recounted = cell(1, "b");
  recounted["cell_count"] = 5;
  expect_refused(recounted, "checked.jsonl:2: cell_count 5, but line 1 of the same definition says 10");
  // One sample per repetition, and the same pipelines in every cell: a cell without one would let
  // the gate pass that pipeline there unchecked.
  json short_of_samples = cell(1, "b");
  short_of_samples["pipelines"]["plain-rt"]["timing"]["repetitions"] = 3;
  short_of_samples["pipelines"]["plain-rt"]["timing"]["samples_s"] = json::array();
  expect_refused(short_of_samples,
                 "checked.jsonl:2: field 'pipelines.plain-rt.timing.samples_s' holds 0 time(s) but timing.repetitions "
                 "is 3");
  // A timed pipeline ran at least once: no repetitions and no samples is no timing.
  json untimed = cell(1, "b");
  untimed["pipelines"]["plain-rt"]["timing"]["repetitions"] = 0;
  untimed["pipelines"]["plain-rt"]["timing"]["samples_s"] = json::array();
  expect_refused(untimed, "checked.jsonl:2: field 'pipelines.plain-rt.timing.repetitions' is 0, but a timed pipeline");
  // A cell_id that tells another cell than the fields do: the gate would look its baseline and
  // rules up under one cell and read the scene of another.
  json axes = cell(1, "box-wall:size=0.5|e=0.064m|c=default|96x54|lights=all|full");
  axes["cell"].update({{"interaxial_m", 0.064}, {"max_disparity_px", nullptr}, {"convergence_m", nullptr},
                       {"lights", nullptr}});
  {
    const auto file = dir / "axes.jsonl";
    append_result(file, cell(0, "a"));
    append_result(file, axes);
    EXPECT_EQ(read_results(file).cells.size(), 2u) << "an id that matches its fields";
  }
  {
    // A sweep without a resolutions axis renders the scene's own size and writes resolution null:
    // its own file was refused by every reader.
    json scene_size = axes;
    scene_size["cell"]["resolution"] = nullptr;
    scene_size["cell_id"] = "box-wall:size=0.5|e=0.064m|c=default|res=default|lights=all|full";
    const auto file = dir / "scene-size.jsonl";
    append_result(file, cell(0, "a"));
    append_result(file, scene_size);
    EXPECT_EQ(read_results(file).cells.size(), 2u);
  }
  json relabelled = axes;
  relabelled["cell"]["interaxial_m"] = 0.12;
  expect_refused(relabelled, "checked.jsonl:2: cell_id \"box-wall:size=0.5|e=0.064m|c=default|96x54|lights=all|full\" "
                             "does not match the cell's fields, which give \"box-wall:size=0.5|e=0.12m|c=default|"
                             "96x54|lights=all|full\"");
  // An axis of the wrong type or out of range, which the gate turned into a reproduce command
  // (`--interaxial -1`) or passed over.
  for (const auto& [key, value, want] :
       {std::tuple<const char*, json, const char*>{"interaxial_m", -1.0, "a positive number, or null"},
        {"interaxial_m", "abc", "a positive number, or null"},
        {"lights", -3, "an integer of at least 1, or null"},
        {"scene_params", json::array({1}), "an object of numbers"},
        {"frame", "a", "a frame number"}}) {
    json broken = axes;
    broken["cell"][key] = value;
    expect_refused(broken, fmt::format("checked.jsonl:2: cell.{} is {}; it must be {}", key, value.dump(), want));
  }
  json negative_rig = cell(1, "b");
  negative_rig["rig"]["convergence_m"] = -2.0;
  expect_refused(negative_rig, "checked.jsonl:2: field 'rig.convergence_m' is -2.0; a rig's interaxial, convergence");
  json left_text = cell(1, "b");
  left_text["pipelines"]["plain-rt"]["validation"]["left_eye"] = {{"metrics", {{"psnr", "x"}, {"ssim", 0.9}, {"mse", 1.0}}}};
  expect_refused(left_text, "checked.jsonl:2: field 'pipelines.plain-rt.validation.left_eye.metrics.psnr'");
  json more = cell(1, "b");
  more["pipelines"]["repro-rt"] = more["pipelines"]["plain-rt"];
  expect_refused(more, "checked.jsonl:2: the cell validates pipelines plain-rt, repro-rt, but line 1 of the same "
                       "definition validates plain-rt; every cell of a sweep validates every pipeline");
}

TEST(ResultsFile, RebasingMovesTheCellsAndEachPipelinesImagePaths) {
  json c = cell(0, "a");
  c["images"] = {{"truth_png", "cells/0000/scene_truth-full.png"},
                 {"pipelines", {{"plain-rt", {{"right_png", "cells/0000/plain-rt_right.png"}}}}}};
  c["pipelines"]["plain-rt"]["validation"]["images"] = {{"right_png", "cells/0000/plain-rt_right.png"},
                                                        {"truth_exr", nullptr}};
  rebase_image_paths(c, "/data/sweep/slurm", "/data/sweep");
  EXPECT_EQ(c["images"]["truth_png"], "slurm/cells/0000/scene_truth-full.png");
  EXPECT_EQ(c["images"]["pipelines"]["plain-rt"]["right_png"], "slurm/cells/0000/plain-rt_right.png");
  EXPECT_EQ(c["pipelines"]["plain-rt"]["validation"]["images"]["right_png"], "slurm/cells/0000/plain-rt_right.png");
  EXPECT_TRUE(c["pipelines"]["plain-rt"]["validation"]["images"]["truth_exr"].is_null());
}

TEST(ResultsFile, CollectMergesShards) {
  test::ScratchDir dir;
  append_result(dir / "s0.jsonl", cell(2, "c"));
  append_result(dir / "s0.jsonl", cell(0, "a"));
  append_result(dir / "s1.jsonl", cell(1, "b"));
  append_result(dir / "s1.jsonl", cell(0, "a"));  // identical duplicate: collapses
  const std::vector<json> merged = collect_results({dir / "s0.jsonl", dir / "s1.jsonl"}, dir / "merged.jsonl");
  ASSERT_EQ(merged.size(), 3u);
  EXPECT_EQ(merged[0]["cell_id"], "a");
  EXPECT_EQ(merged[1]["cell_id"], "b");
  EXPECT_EQ(merged[2]["cell_id"], "c");
  // The merged text reads back as a results file.
  std::ofstream(dir / "all.jsonl") << results_text(merged);
  EXPECT_EQ(read_results(dir / "all.jsonl").cells, merged);
  // The cells hold 3 of the sweep's 10: said, with the missing indices (a shard left out).
  std::vector<std::string> warnings;
  (void)collect_results({dir / "s0.jsonl", dir / "s1.jsonl"}, dir / "merged.jsonl", &warnings);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0], "the 2 file(s) hold 3 of the sweep's 10 cells (missing cell_index 3, 4, 5, 6, 7, 8, 9): a "
                         "shard is left out or unfinished; the gate fails the merge until every cell is in it");

  append_result(dir / "s2.jsonl", cell(1, "b", 12.0));  // the same cell, other numbers
  try {
    (void)collect_results({dir / "s0.jsonl", dir / "s1.jsonl", dir / "s2.jsonl"}, dir / "merged.jsonl");
    FAIL() << "a conflicting duplicate was merged";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cell_id 'b' is recorded differently"), std::string::npos) << e.what();
  }

  json foreign = cell(5, "z");
  foreign["definition_sha256"] = "def";
  append_result(dir / "s3.jsonl", foreign);
  try {
    (void)collect_results({dir / "s0.jsonl", dir / "s3.jsonl"}, dir / "merged.jsonl");
    FAIL() << "shards of two definitions were merged";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("s3.jsonl holds cells of sweep 't' (definition def), "), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("collect only shards of one definition"), std::string::npos) << e.what();
  }
}

TEST(ResultsFile, CsvRowsAndQuoting) {
  json c = cell(0, "box-wall|e=0.064m,\"x\"");
  const std::string csv = results_csv({c});
  const size_t eol = csv.find("\r\n");
  ASSERT_NE(eol, std::string::npos);
  EXPECT_EQ(csv.substr(0, 24), "cell_index,cell_id,sweep");
  const std::string row = csv.substr(eol + 2);
  EXPECT_EQ(row,
            "0,\"box-wall|e=0.064m,\"\"x\"\"\",t,box-wall,size=0.5,96,54,0.064,3.5,2,1,,,full,plain-rt,plain-rt,40,0.99,"
            "6.5025,0.01,0,1,0.02,0.01,1,0.98\r\n");
  // A frame of a camera path: its frame number and BVH update time.
  json f = cell(3, "spheres|frame=2");
  f["animation"] = {{"frame", 2}, {"bvh_update_s", 0.038}};
  const std::string path_csv = results_csv({f});
  EXPECT_NE(path_csv.find(",frame,bvh_update_s,"), std::string::npos);
  EXPECT_NE(path_csv.find(",1,2,0.038,full,"), std::string::npos) << path_csv;
  // Rows follow cell_index, not the order parallel jobs wrote the lines in.
  const std::string ordered = results_csv({cell(2, "c"), cell(0, "a"), cell(1, "b")});
  const size_t a = ordered.find("\r\n0,a,"), b = ordered.find("\r\n1,b,"), cc = ordered.find("\r\n2,c,");
  ASSERT_NE(cc, std::string::npos) << ordered;
  EXPECT_LT(a, b);
  EXPECT_LT(b, cc);
}

}  // namespace
}  // namespace sb
