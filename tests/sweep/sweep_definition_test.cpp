// Sweep definitions: every key parsed, every mistake rejected with its key path and line, cells
// expanded in a fixed order with stable ids, and every shipped definition loads.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "renderer/error.hpp"
#include "renderer/pipeline.hpp"
#include "support/scratch_dir.hpp"
#include "validation/gate.hpp"
#include "validation/sweep.hpp"

namespace sb {
namespace {

namespace fs = std::filesystem;
using validation::parse_sweep;
using validation::SweepDefinition;

/// The message of the InputError `text` raises (empty when it loads).
std::string error_of(const std::string& text, const fs::path& file = "def.toml") {
  try {
    (void)parse_sweep(text, file);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SweepDefinition, ParsesEveryKey) {
  const SweepDefinition d = parse_sweep(R"(
[sweep]
name = "all-keys"
description = "every key"
scenes = ["box-wall", "complexity:triangles=1e6", "spheres:segments=8,count=10"]
pipelines = ["repro-rt", "bw-warp"]
baseline = "plain-raster"
interaxial_m = [0.05, 0.1]
convergence_m = [1.5, 3]
resolutions = ["96x54", "hd"]
lights = [1, 2]
truths = ["full", "povray"]

[timing]
repetitions = 4
warmup = 2

[options.repro-rt]
threshold_arcmin = 2

[options.bw-warp]
iterations = 6
start = "far"

[output]
images = true
exr = true
)",
                                        "dir/def.toml");
  EXPECT_EQ(d.name, "all-keys");
  EXPECT_EQ(d.description, "every key");
  ASSERT_EQ(d.scenes.size(), 3u);
  EXPECT_EQ(d.scenes[0].label, "box-wall");
  EXPECT_EQ(d.scenes[1].label, "complexity:triangles=1000000");  // normalised number
  EXPECT_EQ(d.scenes[1].params.at("triangles"), 1e6);
  EXPECT_EQ(d.scenes[2].label, "spheres:count=10,segments=8");  // keys sorted
  // Sorted, the baseline added because it was not listed.
  EXPECT_EQ(d.pipelines, (std::vector<std::string>{"bw-warp", "plain-raster", "repro-rt"}));
  EXPECT_EQ(d.baseline, "plain-raster");
  EXPECT_FALSE(d.baseline_listed);
  EXPECT_EQ(d.interaxial_m.size(), 2u);
  EXPECT_EQ(*d.interaxial_m[1], 0.1);
  EXPECT_FALSE(d.max_disparity_px.front().has_value());
  EXPECT_EQ(*d.convergence_m[1], 3.0);
  ASSERT_EQ(d.resolutions.size(), 2u);
  EXPECT_EQ(d.resolutions[1]->label, "1920x1080");
  EXPECT_EQ(*d.lights[1], 2);
  EXPECT_EQ(d.truths, (std::vector<std::string>{"full", "povray"}));
  EXPECT_EQ(d.repetitions, 4);
  EXPECT_EQ(d.warmup, 2);
  EXPECT_EQ(d.options.at("repro-rt").at("threshold_arcmin"), "2");
  EXPECT_EQ(d.options.at("bw-warp").at("start"), "far");
  EXPECT_TRUE(d.exr);
  EXPECT_EQ(d.sha256.size(), 64u);
  EXPECT_EQ(validation::expand_cells(d).size(), 3u * 2 * 2 * 2 * 2 * 2);
}

TEST(SweepDefinition, DefaultsForOmittedAxes) {
  const SweepDefinition d = parse_sweep("[sweep]\n", "ci/some-name.toml");
  EXPECT_EQ(d.name, "some-name");  // the file's stem
  ASSERT_EQ(d.scenes.size(), 1u);
  EXPECT_EQ(d.scenes[0].label, "spheres");
  EXPECT_EQ(d.pipelines.size(), pipelines().size());  // every registered pipeline
  EXPECT_TRUE(d.baseline_listed);
  EXPECT_EQ(d.baseline, "plain-rt");
  EXPECT_EQ(d.truths, (std::vector<std::string>{"full"}));
  const auto cells = validation::expand_cells(d);
  ASSERT_EQ(cells.size(), 1u);
  EXPECT_EQ(cells[0].id, "spheres|e=default|c=default|res=default|lights=all|full");
}

TEST(SweepDefinition, UnknownKeysNameTheKeyAndLine) {
  const std::string top = error_of("[sweep]\nname = \"x\"\n\n[timings]\nrepetitions = 1\n");
  EXPECT_NE(top.find("def.toml:4: timings: unknown key"), std::string::npos) << top;
  EXPECT_NE(top.find("sweep, timing, options, output"), std::string::npos) << top;

  const std::string in_sweep = error_of("[sweep]\nname = \"x\"\nscene = [\"spheres\"]\n");
  EXPECT_NE(in_sweep.find("def.toml:3: sweep.scene: unknown key"), std::string::npos) << in_sweep;
  EXPECT_NE(in_sweep.find("scenes"), std::string::npos) << in_sweep;  // the valid keys are listed

  const std::string in_timing = error_of("[sweep]\n[timing]\nrepetition = 3\n");
  EXPECT_NE(in_timing.find("def.toml:3: timing.repetition: unknown key"), std::string::npos) << in_timing;
  const std::string in_output = error_of("[sweep]\n[output]\npng = true\n");
  EXPECT_NE(in_output.find("def.toml:3: output.png: unknown key"), std::string::npos) << in_output;
  const std::string in_gate = error_of("[sweep]\n[gate]\nthresholds = \"g.toml\"\n");
  EXPECT_NE(in_gate.find("def.toml:3: gate.thresholds: unknown key"), std::string::npos) << in_gate;
  const std::string gate_type = error_of("[sweep]\n[gate]\nconfig = 3\n");
  EXPECT_NE(gate_type.find("def.toml:3: gate.config: must be a string"), std::string::npos) << gate_type;

  const std::string option = error_of("[sweep]\npipelines = [\"repro-rt\"]\n[options.repro-rt]\nthreshold = 2\n");
  EXPECT_NE(option.find("def.toml:4: options.repro-rt.threshold"), std::string::npos) << option;
  EXPECT_NE(option.find("no option 'threshold'"), std::string::npos) << option;

  const std::string other = error_of("[sweep]\npipelines = [\"repro-rt\"]\n[options.fw-warp]\ntile = 32\n");
  EXPECT_NE(other.find("def.toml:3: options.fw-warp: options for a pipeline the sweep does not run"),
            std::string::npos)
      << other;
}

TEST(SweepDefinition, OptionValuesAreCheckedBeforeAnyCellRuns) {
  // Each value as the pipeline reads it, at its line: a range, a type, a choice.
  const std::string range = error_of("[sweep]\npipelines = [\"repro-rt\"]\n[options.repro-rt]\nthreshold_arcmin = -5\n");
  EXPECT_NE(range.find("def.toml:4: options.repro-rt.threshold_arcmin"), std::string::npos) << range;
  EXPECT_NE(range.find("threshold_arcmin=-5 must be positive"), std::string::npos) << range;
  const std::string type = error_of("[sweep]\npipelines = [\"bw-warp\"]\n[options.bw-warp]\niterations = \"many\"\n");
  EXPECT_NE(type.find("def.toml:4: options.bw-warp.iterations"), std::string::npos) << type;
  EXPECT_NE(type.find("iterations=many is not a finite number"), std::string::npos) << type;
  const std::string choice = error_of("[sweep]\npipelines = [\"fw-warp\"]\n[options.fw-warp]\nwarp = \"fast\"\n");
  EXPECT_NE(choice.find("def.toml:4: options.fw-warp.warp"), std::string::npos) << choice;
  const std::string depth = error_of("[sweep]\npipelines = [\"rt-buffer\"]\n[options.rt-buffer]\ndepth = 5000\n");
  EXPECT_NE(depth.find("depth=5000 is out of range"), std::string::npos) << depth;
  // A table named by a variant (it was called options for a pipeline the sweep does not run, and
  // the variant listed among the pipelines it runs).
  const std::string variant =
      error_of("[sweep]\npipelines = [\"fw-warp:warp=rows\"]\n[options.\"fw-warp:warp=rows\"]\nmax_crack = 1\n");
  EXPECT_NE(variant.find("def.toml:3: options.fw-warp:warp=rows: a table of options is named by a pipeline, not a "
                         "variant"),
            std::string::npos)
      << variant;
  EXPECT_NE(variant.find("[options.fw-warp] applies to fw-warp and all its variants"), std::string::npos) << variant;
}

TEST(SweepDefinition, VariantsRunBesideTheirPipeline) {
  const SweepDefinition d = parse_sweep(
      "[sweep]\npipelines = [\"bidir-warp\", \"bidir-warp:occlusion=ztest\", \"fw-warp:max_crack=1\"]\n"
      "baseline = \"plain-raster\"\n[options.bidir-warp]\nmax_crack = 3\n[options.fw-warp]\nmax_crack = 2\n",
      "def.toml");
  EXPECT_EQ(d.pipelines, (std::vector<std::string>{"bidir-warp", "bidir-warp:occlusion=ztest", "fw-warp:max_crack=1",
                                                   "plain-raster"}));
  EXPECT_EQ(d.options.at("fw-warp").at("max_crack"), "2") << "options of a pipeline run only as a variant";
  // A variant that fixes a default differs from its pipeline run with other given options.
  const SweepDefinition given = parse_sweep(
      "[sweep]\npipelines = [\"bidir-warp\", \"bidir-warp:occlusion=none\"]\nbaseline = \"bidir-warp\"\n"
      "[options.bidir-warp]\nocclusion = \"ztest\"\n",
      "def.toml");
  EXPECT_EQ(given.pipelines, (std::vector<std::string>{"bidir-warp", "bidir-warp:occlusion=none"}));
  // A variant's options are checked at its line; the options table under each variant's own.
  const std::string value = error_of("[sweep]\npipelines = [\"plain-rt\",\n \"bidir-warp:occlusion=zbuf\"]\n");
  EXPECT_NE(value.find("def.toml:3: sweep.pipelines: pipeline entry 'bidir-warp:occlusion=zbuf'"), std::string::npos)
      << value;
  const std::string pair = error_of("[sweep]\npipelines = [\"bidir-warp:ztest\"]\n");
  EXPECT_NE(pair.find("'ztest' is not KEY=VALUE"), std::string::npos) << pair;
  const std::string twice = error_of("[sweep]\npipelines = [\"bidir-warp:tile=8\", \"bidir-warp:tile=8\"]\n");
  EXPECT_NE(twice.find("lists 'bidir-warp:tile=8' twice"), std::string::npos) << twice;
  const std::string under =
      error_of("[sweep]\npipelines = [\"bidir-warp:occlusion=ztest\"]\n[options.bidir-warp]\nocclusions = \"none\"\n");
  EXPECT_NE(under.find("def.toml:4: options.bidir-warp.occlusions"), std::string::npos) << under;
  const std::string baseline = error_of("[sweep]\nbaseline = \"plain-rt:tile=0\"\n");
  EXPECT_NE(baseline.find("def.toml:2: sweep.baseline: pipeline entry 'plain-rt:tile=0'"), std::string::npos)
      << baseline;
  // A baseline listed under another spelling of its variant is that entry (as bench --baseline
  // takes it); it used to be added a second time and refused as the same variant named twice.
  const SweepDefinition reordered = parse_sweep(
      "[sweep]\npipelines = [\"fw-warp:max_crack=1:warp=rows\", \"plain-rt\"]\nbaseline = \"fw-warp:warp=rows:max_crack=1\"\n",
      "def.toml");
  EXPECT_EQ(reordered.baseline, "fw-warp:max_crack=1:warp=rows");
  EXPECT_TRUE(reordered.baseline_listed);
  EXPECT_EQ(reordered.pipelines, (std::vector<std::string>{"fw-warp:max_crack=1:warp=rows", "plain-rt"}));
  // Different values stay different variants.
  const SweepDefinition distinct = parse_sweep(
      "[sweep]\npipelines = [\"rt-atomic:confirm=true\", \"rt-atomic:confirm=false\", \"repro-rt:tile=16\", "
      "\"repro-rt:tile=32\"]\n",
      "def.toml");
  EXPECT_EQ(distinct.pipelines.size(), 5u);  // and the baseline
}

TEST(SweepDefinition, BothInteraxialKindsRejected) {
  const std::string e = error_of("[sweep]\ninteraxial_m = [0.064]\nmax_disparity_px = [30]\n");
  EXPECT_NE(e.find("def.toml:3: sweep.max_disparity_px"), std::string::npos) << e;
  EXPECT_NE(e.find("line 2"), std::string::npos) << e;
}

TEST(SweepDefinition, BadValuesRejected) {
  const struct {
    const char* toml;
    const char* expected;
  } cases[] = {
      {"[sweep]\ninteraxial_m = [\"0.064\"]\n", "sweep.interaxial_m: must be a number, not a string"},
      {"[sweep]\ninteraxial_m = []\n", "sweep.interaxial_m: is empty"},
      {"[sweep]\ninteraxial_m = [-1]\n", "not a positive number"},
      {"[sweep]\ninteraxial_m = [0.064, 1e300]\n",
       "sweep.interaxial_m: 1e+300 is beyond the largest value a rig takes, 1e+15"},
      {"[sweep]\nmax_disparity_px = [1e9]\n",
       "sweep.max_disparity_px: 1000000000 is beyond the largest value a rig takes"},
      {"[sweep]\nconvergence_m = [2, 2.0]\n", "lists 2 twice"},
      {"[sweep]\nlights = [1.5]\n", "sweep.lights: must be an integer, not a float"},
      {"[sweep]\nlights = [0]\n", "sweep.lights: 0 is outside 1..100000"},
      {"[sweep]\nlights = [1000000]\n", "sweep.lights: 1000000 is outside 1..100000"},
      {"[sweep]\nresolutions = [\"huge\"]\n", "sweep.resolutions"},
      {"[sweep]\nresolutions = [\"hd\", \"1920x1080\"]\n", "lists 1920x1080 twice"},
      {"[sweep]\nlights = [1, 2, 1]\n", "sweep.lights: lists 1 twice"},
      {"[sweep]\nscenes = [\"nowhere\"]\n", "unknown"},
      {"[sweep]\nscenes = [\"complexity:triangles=5\"]\n", "outside"},
      {"[sweep]\nscenes = [\"complexity:size=5\"]\n", "has no parameter 'size'"},
      {"[sweep]\nscenes = [\"spheres:count=0x10\"]\n", "count=0x10 is not a decimal number"},
      {"[sweep]\nscenes = [\"lit-plane:directional=0\", \"lit-plane:directional=-0\"]\n", "lists 'lit-plane:directional=0' twice"},
      {"[sweep]\nscenes = [\"missing/scene.gltf\"]\n", "does not exist"},
      {"[sweep]\nscenes = [\"spheres\", \"spheres\"]\n", "lists 'spheres' twice"},
      // The default count written out is the same scene (the cells used to run twice).
      {"[sweep]\nscenes = [\"spheres\", \"spheres:count=1000\"]\n",
       "lists one scene twice: 'spheres' and 'spheres:count=1000' differ only by parameters at their defaults"},
      {"[sweep]\npipelines = [\"repro-rtx\"]\n", "sweep.pipelines"},
      {"[sweep]\npipelines = [\"all\", \"repro-rt\"]\n",
       "sweep.pipelines: 'repro-rt' is one of the pipelines 'all' includes; drop one of them"},
      {"[sweep]\npipelines = [\"all\", \"all\"]\n", "sweep.pipelines: 'all' is named twice"},
      {"[sweep]\npipelines = []\n",
       "sweep.pipelines: is empty; give at least one value, or leave the key out for its default"},
      // One variant under two names (its options in another order) used to be measured twice.
      {"[sweep]\npipelines = [\"fw-warp:max_crack=1:warp=rows\", \"fw-warp:warp=rows:max_crack=1\"]\n",
       "def.toml:2: sweep.pipelines: 'fw-warp:max_crack=1:warp=rows' and 'fw-warp:warp=rows:max_crack=1' "
       "name the same variant of fw-warp; name it once"},
      // So did one under two spellings of a value the pipeline reads alike.
      {"[sweep]\npipelines = [\"rt-atomic:confirm=yes\", \"rt-atomic:confirm=true\"]\n",
       "'rt-atomic:confirm=yes' and 'rt-atomic:confirm=true' name the same variant of rt-atomic"},
      {"[sweep]\npipelines = [\"repro-rt:threshold_arcmin=2\", \"repro-rt:threshold_arcmin=2.0\"]\n",
       "name the same variant of repro-rt"},
      {"[sweep]\nbaseline = \"nope\"\n", "sweep.baseline"},
      {"[sweep]\ntruths = [\"mitsuba\"]\n", "unknown ground-truth provider 'mitsuba'"},
      {"[sweep]\nname = 3\n", "sweep.name: must be a string, not an integer"},
      {"[sweep]\nname = \"..\"\n", "sweep.name: must be a non-empty name without '/'"},
      {"[sweep]\nname = \"a\\u0007b\"\n", "sweep.name: must be a non-empty name without '/'"},
      {"[sweep]\n[timing]\nrepetitions = 0\n", "timing.repetitions: 0 is outside"},
      {"[sweep]\n[output]\nimages = \"yes\"\n", "output.images: must be true or false"},
      {"[sweep]\n[output]\nimages = false\nexr = true\n", "EXR images need"},
      {"sweep = 3\n", "sweep: must be a table"},
      {"[timing]\nrepetitions = 1\n", "no [sweep] table"},
      {"[sweep\n", "not valid TOML"},
  };
  for (const auto& c : cases) {
    const std::string e = error_of(c.toml);
    EXPECT_NE(e.find(c.expected), std::string::npos) << c.toml << "\n -> " << e;
    EXPECT_EQ(e.rfind("def.toml", 0), 0u) << "the message starts with the file: " << e;
  }
}

TEST(SweepDefinition, GltfScenesResolveAgainstTheDefinitionsFolder) {
  test::ScratchDir dir;
  fs::create_directories(dir / "defs" / "scenes");
  { std::ofstream(dir / "defs" / "scenes" / "a.gltf") << "{}"; }
  const SweepDefinition d = parse_sweep("[sweep]\nscenes = [\"scenes/a.gltf\"]\n", dir / "defs" / "x.toml");
  ASSERT_EQ(d.scenes.size(), 1u);
  EXPECT_FALSE(d.scenes[0].builtin);
  EXPECT_EQ(d.scenes[0].file, dir / "defs" / "scenes" / "a.gltf");
  EXPECT_EQ(d.scenes[0].label, "scenes/a.gltf");  // ids do not depend on where the checkout is
  // A definition named relative to the working folder still gives an absolute, normal file path.
  const fs::path relative = fs::relative(dir / "defs" / "x.toml");
  const SweepDefinition r = parse_sweep("[sweep]\nscenes = [\"../defs/scenes/a.gltf\"]\n", relative);
  ASSERT_EQ(r.scenes.size(), 1u);
  EXPECT_EQ(r.scenes[0].file, fs::absolute(dir / "defs" / "scenes" / "a.gltf").lexically_normal());
  // An upper-case extension is a scene file too (it was taken for a generator's name), and a
  // folder is not one.
  { std::ofstream(dir / "defs" / "scenes" / "UP.GLB") << "glTF"; }
  const SweepDefinition upper = parse_sweep("[sweep]\nscenes = [\"UP.GLB\"]\n", dir / "defs" / "scenes" / "x.toml");
  ASSERT_EQ(upper.scenes.size(), 1u);
  EXPECT_FALSE(upper.scenes[0].builtin);
  EXPECT_EQ(upper.scenes[0].file, dir / "defs" / "scenes" / "UP.GLB");
  fs::create_directories(dir / "defs" / "folder.gltf");
  try {
    (void)parse_sweep("[sweep]\nscenes = [\"folder.gltf\"]\n", dir / "defs" / "x.toml");
    ADD_FAILURE() << "a folder was taken as a scene file";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("folder.gltf is a folder; give a .gltf/.glb file"), std::string::npos)
        << e.what();
  }
  // One file under two spellings is one scene listed twice.
  try {
    (void)parse_sweep("[sweep]\nscenes = [\"scenes/a.gltf\", \"./scenes/../scenes/a.gltf\"]\n", dir / "defs" / "x.toml");
    ADD_FAILURE() << "a scene file listed twice was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("x.toml:2: sweep.scenes: lists one scene file twice: 'scenes/a.gltf' and "
                                         "'./scenes/../scenes/a.gltf' are both"),
              std::string::npos)
        << e.what();
  }
}

TEST(SweepDefinition, GateConfigResolvesAgainstTheDefinitionsFolder) {
  const SweepDefinition d = parse_sweep("[sweep]\n[gate]\nconfig = \"gates/g.toml\"\n", fs::path("/defs/x.toml"));
  ASSERT_TRUE(d.gate_config.has_value());
  EXPECT_EQ(*d.gate_config, fs::path("/defs/gates/g.toml"));
  EXPECT_FALSE(parse_sweep("[sweep]\n", fs::path("/defs/x.toml")).gate_config.has_value());
}

TEST(SweepDefinition, CellOrderAndIdsAreStable) {
  const SweepDefinition d = parse_sweep(R"([sweep]
scenes = ["box-wall", "thin-pole"]
max_disparity_px = [10, 20.5]
resolutions = ["96x54"]
lights = [1]
)",
                                        "def.toml");
  const auto cells = validation::expand_cells(d);
  ASSERT_EQ(cells.size(), 4u);
  EXPECT_EQ(cells[0].id, "box-wall|e=10px|c=default|96x54|lights=1|full");
  EXPECT_EQ(cells[1].id, "box-wall|e=20.5px|c=default|96x54|lights=1|full");
  EXPECT_EQ(cells[2].id, "thin-pole|e=10px|c=default|96x54|lights=1|full");
  EXPECT_EQ(cells[3].id, "thin-pole|e=20.5px|c=default|96x54|lights=1|full");
  for (size_t i = 0; i < cells.size(); ++i) EXPECT_EQ(cells[i].index, i);
  EXPECT_EQ(*cells[1].max_disparity_px, 20.5);
  EXPECT_FALSE(cells[1].interaxial_m.has_value());
  const nlohmann::json j = validation::cell_to_json(cells[1]);
  EXPECT_EQ(j["scene"], "box-wall");
  EXPECT_EQ(j["max_disparity_px"], 20.5);
  EXPECT_TRUE(j["interaxial_m"].is_null());
  EXPECT_EQ(j["resolution"], "96x54");
  // Expanding again (or from a re-parsed text) gives the same ids.
  const auto again = validation::expand_cells(parse_sweep(
      "[sweep]\nscenes = [\"box-wall\", \"thin-pole\"]\nmax_disparity_px = [10, 20.5]\nresolutions = "
      "[\"96x54\"]\nlights = [1]\n",
      "other.toml"));
  for (size_t i = 0; i < cells.size(); ++i) EXPECT_EQ(again[i].id, cells[i].id);
}

TEST(SweepDefinition, ParsesThePath) {
  const SweepDefinition d = parse_sweep(R"([sweep]
scenes = ["box-wall"]

[path]
frames = 12
camera_keys = [[0, 1.2, 1.5, 0, 0.4, -2.5], [1, 1.2, 1.5, 0, 0.4, -2.5]]
bvh = "rebuild"

[path.spin]
axis = [0, 0, 2]
degrees_per_frame = -2.5
pivot = [0, 0.4, -2.5]
mesh_prefix = "box"
)",
                                        "def.toml");
  ASSERT_TRUE(d.path.has_value());
  EXPECT_EQ(d.path->frames, 12);
  ASSERT_EQ(d.path->camera_keys.size(), 2u);
  EXPECT_EQ(d.path->camera_keys[1].position, dvec3(1.0, 1.2, 1.5));
  EXPECT_EQ(d.path->camera_keys[1].target, dvec3(0.0, 0.4, -2.5));
  ASSERT_TRUE(d.path->spin.has_value());
  EXPECT_EQ(d.path->spin->axis, dvec3(0.0, 0.0, 2.0));
  EXPECT_EQ(d.path->spin->degrees_per_frame, -2.5);
  ASSERT_TRUE(d.path->spin->pivot.has_value());
  EXPECT_EQ(*d.path->spin->pivot, dvec3(0.0, 0.4, -2.5));
  EXPECT_EQ(d.path->spin->mesh_prefix, "box");
  EXPECT_FALSE(d.path_refit);

  // Defaults: no keys, no spin, refit; no [path] at all: no frames.
  const SweepDefinition minimal = parse_sweep("[sweep]\n[path]\nframes = 3\n[path.spin]\n", "def.toml");
  ASSERT_TRUE(minimal.path.has_value());
  EXPECT_TRUE(minimal.path->camera_keys.empty());
  ASSERT_TRUE(minimal.path->spin.has_value());
  EXPECT_EQ(minimal.path->spin->axis, dvec3(0.0, 1.0, 0.0));
  EXPECT_EQ(minimal.path->spin->degrees_per_frame, 1.0);
  EXPECT_FALSE(minimal.path->spin->pivot.has_value());
  EXPECT_TRUE(minimal.path_refit);
  EXPECT_FALSE(parse_sweep("[sweep]\n", "def.toml").path.has_value());
}

TEST(SweepDefinition, CameraKeysNoFrameStandsAtAreAWarning) {
  // Frames spread evenly over 4 keys: 5 frames stand at keys 1 and 4 only; the definition loads
  // and says so, naming a frame count that stands at every key.
  const std::string keys = "camera_keys = [[0, 1, 3, 0, 1, 0], [1, 1, 3, 0, 1, 0], [2, 1, 3, 0, 1, 0], [3, 1, 3, 0, 1, 0]]\n";
  const SweepDefinition five = parse_sweep("[sweep]\n[path]\nframes = 5\n" + keys, "def.toml");
  ASSERT_EQ(five.warnings.size(), 1u);
  EXPECT_EQ(five.warnings[0],
            "def.toml:3: path.frames: the 5 frames are spread evenly over the path, so camera keys 2, 3 fall between "
            "frames and are never shown; give path.frames = 7 (or any number one more than a multiple of 3) to stand "
            "at every key");
  EXPECT_TRUE(parse_sweep("[sweep]\n[path]\nframes = 7\n" + keys, "def.toml").warnings.empty());
  EXPECT_TRUE(parse_sweep("[sweep]\n[path]\nframes = 4\n" + keys, "def.toml").warnings.empty());
  const SweepDefinition one = parse_sweep("[sweep]\n[path]\nframes = 1\n" + keys, "def.toml");
  ASSERT_EQ(one.warnings.size(), 1u);
  EXPECT_NE(one.warnings[0].find("with 1 frame the camera stands at the first of the 4 camera keys; give path.frames "
                                 "= 4 or more"),
            std::string::npos)
      << one.warnings[0];
}

TEST(SweepDefinition, RejectsBadPaths) {
  const struct {
    const char* toml;
    const char* expected;
  } cases[] = {
      {"[sweep]\n[path]\nframes = 3\nframe = 2\n", "def.toml:4: path.frame: unknown key; valid keys in [path]: frames"},
      {"[sweep]\n[path]\nframes = 3\n[path.spin]\nspeed = 2\n",
       "def.toml:5: path.spin.speed: unknown key; valid keys in [path.spin]: axis"},
      {"[sweep]\n[path]\nframes = 0\n", "def.toml:3: path.frames: 0 is outside 1..100000"},
      {"[sweep]\n[path]\nframes = 2.5\n", "def.toml:3: path.frames: must be an integer"},
      {"[sweep]\n[path]\ncamera_keys = [[0, 1, 2, 0, 0, 0]]\n", "def.toml:2: path.frames: is missing"},
      {"[sweep]\n[path]\nframes = 3\ncamera_keys = [[0, 1, 2, 0, 0]]\n",
       "def.toml:4: path.camera_keys: must be an array of 6 numbers, e.g. [0, 1.6, 4, 0, 1, 0] (position, then "
       "target, meters), not 5 values"},
      {"[sweep]\n[path]\nframes = 3\ncamera_keys = [[0, 1, 2, 0, 1, 2]]\n",
       "def.toml:4: path.camera_keys: a key pose: its target equals its position"},
      // Checked when the definition loads (it used to stop the sweep at its first cell, naming no file).
      {"[sweep]\n[path]\nframes = 2\ncamera_keys = [[1e300, 1, 4, 0, 1, 0]]\n",
       "def.toml:4: path.camera_keys: a key pose: its position (1e+300, 1, 4) m lies beyond"},
      {"[sweep]\n[path]\nframes = 3\ncamera_keys = []\n", "def.toml:4: path.camera_keys: must be a non-empty array"},
      {"[sweep]\n[path]\nframes = 3\nbvh = \"refresh\"\n", "def.toml:4: path.bvh: 'refresh' is neither"},
      // Nothing moves the meshes: the update it asks for would never be done (as `path --bvh`).
      {"[sweep]\n[path]\nframes = 3\nbvh = \"rebuild\"\n",
       "def.toml:4: path.bvh: needs path.spin or path.gltf_animation (nothing else moves the scene's meshes)"},
      {"[sweep]\n[path]\nframes = 3\n[path.spin]\naxis = [0, 0, 0]\n", "def.toml:5: path.spin.axis: is zero"},
      {"[sweep]\n[path]\nframes = 3\n[path.spin]\naxis = [0, 1]\n",
       "def.toml:5: path.spin.axis: must be an array of 3 numbers"},
      {"[sweep]\n[path]\nframes = 3\ngltf_animation = \"yes\"\n", "def.toml:4: path.gltf_animation: must be"},
      {"[sweep]\n[path]\nframes = 3\ngltf_clip = \"\"\n", "def.toml:4: path.gltf_clip: is empty"},
      {"[sweep]\n[path]\nframes = 3\ngltf_clip = 2\n", "def.toml:4: path.gltf_clip: must be a string"},
      {"[sweep]\n[path]\nframes = 3\ngltf_animation = false\ngltf_clip = \"walk\"\n",
       "def.toml:5: path.gltf_clip: chooses a glTF animation, but gltf_animation = false"},
      // A definition whose cells would not fit in memory.
      {"[sweep]\nconvergence_m = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11]\n[path]\nframes = 100000\n",
       "def.toml: the sweep has 1100000 cells (1 scene(s) x 1 interaxial(s) x 11 convergence(s) x 1 resolution(s) x 1 "
       "light count(s) x 1 truth(s) x 100000 frame(s)), more than the 1000000 a sweep may hold"},
      {"[sweep]\n[path]\nframes = 3\ngltf_animation = true\n[path.spin]\n", "plays the scene's glTF animation or a spin, not both"},
      {"[sweep]\n[path]\nframes = 3\n[path.spin]\nmesh_prefix = 4\n", "def.toml:5: path.spin.mesh_prefix: must be a string"},
      {"[sweep]\n[path]\nframes = 3\n[path.spin]\npivot = [1e300, 0, 0]\n",
       "def.toml:5: path.spin.pivot: (1e+300, 0, 0) lies beyond the ±1e+15 m a scene may span"},
      {"[sweep]\n[path]\nframes = 3\n[path.spin]\ndegrees_per_frame = 1e308\n",
       "def.toml:5: path.spin.degrees_per_frame: 1e+308 is not within ±360"},
      {"[sweep]\n[path]\nframes = 3\ncamera_keys = [[0, 1, 4, 0, 1, 3], [0, 1, 3, 0, 1, 4]]\n",
       "def.toml:2: path: frame 1 of 3: the camera reaches its target between camera keys 1 and 2"},
  };
  for (const auto& c : cases) {
    const std::string e = error_of(c.toml);
    EXPECT_NE(e.find(c.expected), std::string::npos) << c.toml << "\n -> " << e;
  }
}

TEST(SweepDefinition, PathExpandsEveryCombinationIntoFrames) {
  const SweepDefinition d = parse_sweep(R"([sweep]
scenes = ["box-wall"]
interaxial_m = [0.05, 0.1]
resolutions = ["64x36"]

[path]
frames = 3
[path.spin]
mesh_prefix = "box"
)",
                                        "def.toml");
  const std::vector<validation::SweepCell> cells = validation::expand_cells(d);
  ASSERT_EQ(cells.size(), 2u * 3u);  // 2 interaxial distances × 3 frames
  const std::vector<std::string> ids = {
      "box-wall|e=0.05m|c=default|64x36|lights=all|full|frame=0", "box-wall|e=0.05m|c=default|64x36|lights=all|full|frame=1",
      "box-wall|e=0.05m|c=default|64x36|lights=all|full|frame=2", "box-wall|e=0.1m|c=default|64x36|lights=all|full|frame=0",
      "box-wall|e=0.1m|c=default|64x36|lights=all|full|frame=1",  "box-wall|e=0.1m|c=default|64x36|lights=all|full|frame=2"};
  for (size_t i = 0; i < cells.size(); ++i) {
    EXPECT_EQ(cells[i].index, i);
    EXPECT_EQ(cells[i].id, ids[i]);
    ASSERT_TRUE(cells[i].frame.has_value());
    EXPECT_EQ(*cells[i].frame, static_cast<int>(i % 3));
    EXPECT_EQ(validation::cell_to_json(cells[i])["frame"], i % 3);
  }
  // Without a path the cells carry no frame.
  const std::vector<validation::SweepCell> still = validation::expand_cells(parse_sweep("[sweep]\n", "def.toml"));
  ASSERT_EQ(still.size(), 1u);
  EXPECT_FALSE(still[0].frame.has_value());
  EXPECT_FALSE(validation::cell_to_json(still[0]).contains("frame"));
}

TEST(SweepDefinition, ShippedDefinitionsLoad) {
  const fs::path ci = fs::path(SB_SOURCE_DIR) / "ci";
  const size_t n_pipelines = pipelines().size();
  const struct {
    const char* file;
    size_t cells;
    size_t pipelines;  // 0: every registered pipeline
  } shipped[] = {
      {"smoke.toml", 2, n_pipelines + 1},               // spheres × 2 interaxial; every pipeline and a variant
      {"nightly.toml", 6 * 3 * 2, n_pipelines + 1},     // 6 scenes × 3 disparities × 2 resolutions; and a variant
      {"full.toml", 10 * 3 * 3 * 3 * 3, n_pipelines + 1},  // 10 scenes × 3 e × 3 c × 3 resolutions × 3 truths
      {"presets/wissmann-table2.toml", 3 * 2, 5},       // 3 scenes × HD, 4K
      {"presets/kim-table2.toml", 3, 6},                // 3 focal distances
      {"presets/kim-table3.toml", 3, 4},                // 3 triangle counts; Table 3's four methods
      {"presets/al-hagri-dimensions.toml", 6 * 27, 6},  // 6 scenes × 200..1500 step 50
      {"presets/al-hagri-interaxial.toml", 10, 6},      // 10..100 px
      {"presets/al-hagri-lights.toml", 10, 6},          // 1..10 lights
      {"presets/animated-spheres.toml", 30, 6},         // 30 frames of the turning spheres
      {"presets/wissmann-path.toml", 61, 4},            // 61 frames along the bistro path
  };
  size_t checked = 0;
  for (const auto& s : shipped) {
    const SweepDefinition d = validation::load_sweep(ci / s.file);
    const std::vector<validation::SweepCell> cells = validation::expand_cells(d);
    EXPECT_EQ(cells.size(), s.cells) << s.file;
    EXPECT_EQ(d.pipelines.size(), s.pipelines ? s.pipelines : n_pipelines) << s.file;
    // Nothing it asks goes unseen (a camera key between frames).
    for (const std::string& w : d.warnings) ADD_FAILURE() << w;
    // A results line's cell fields give back the cell's id (check_cell_record compares them).
    for (const validation::SweepCell& cell : cells)
      EXPECT_EQ(validation::cell_id_from_json(validation::cell_to_json(cell)), std::optional<std::string>(cell.id))
          << s.file;
    // The gate config it is checked with puts no warning level beyond a failure level in force.
    const validation::GateConfig gate = validation::load_gate_config(d.gate_config.value_or(ci / "gate.toml"));
    for (const validation::SweepCell& cell : cells)
      for (const std::string& pipeline : d.pipelines) {
        std::map<std::string, std::string> origins;
        const validation::ThresholdValues t =
            validation::thresholds_for(gate, pipeline, cell.scene.label, cell.id, nullptr, &origins);
        for (const std::string& note : validation::unreachable_warning_levels(t, origins, pipeline, cell.scene.label))
          ADD_FAILURE() << s.file << ", " << cell.id << ": " << note;
      }
    ++checked;
  }
  // Every TOML shipped under ci/ (besides the gate's) is in the list above.
  size_t on_disk = 0;
  for (const fs::path& dir : {ci, ci / "presets"})
    for (const auto& entry : fs::directory_iterator(dir))
      if (entry.path().extension() == ".toml" && !entry.path().filename().string().starts_with("gate")) ++on_disk;
  EXPECT_EQ(on_disk, checked);

  // The nightly names its own gate thresholds, and they load.
  const SweepDefinition nightly = validation::load_sweep(ci / "nightly.toml");
  ASSERT_TRUE(nightly.gate_config.has_value());
  EXPECT_EQ(*nightly.gate_config, ci / "gate-nightly.toml");
  const validation::GateConfig gate = validation::load_gate_config(*nightly.gate_config);
  EXPECT_GE(gate.rules.size(), 6u * 3u * nightly.pipelines.size()) << "a rule per scene, max disparity and pipeline";
  // Every pipeline (the variant too) has measured thresholds in every cell, not just the defaults.
  for (const validation::SweepCell& cell : validation::expand_cells(nightly))
    for (const std::string& pipeline : nightly.pipelines) {
      std::vector<bool> used(gate.rules.size(), false);
      (void)validation::thresholds_for(gate, pipeline, cell.scene.label, cell.id, &used);
      EXPECT_NE(std::find(used.begin(), used.end(), true), used.end()) << pipeline << " in " << cell.id;
    }
}

}  // namespace
}  // namespace sb
