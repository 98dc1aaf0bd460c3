// The command line: --version, --help with defaults, and bad arguments exiting with code 3 and a
// message that says what was wrong.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "renderer/io/image_io.hpp"
#include "renderer/pipeline.hpp"

#include "support/mini_gltf.hpp"
#include "support/run_cli.hpp"
#include "support/scratch_dir.hpp"

namespace sb {
namespace {

using test::CliRun;

CliRun run(const std::string& args) { return test::run_cli(args); }

TEST(Cli, OutputStandardOutputCannotTakeIsAnIoError) {
  // Standard output on a full disk: the commands whose output is their result exit 4 saying so
  // (they exited 0 with nothing written, or 4 as an "internal error").
  ASSERT_TRUE(std::filesystem::exists("/dev/full")) << "the test writes to /dev/full";
  const std::string cache = (std::filesystem::path(SB_BINARY_DIR) / "Testing" / "scenes-cache").string();
  for (const std::string& command :
       std::vector<std::string>{"scenes list", "scenes info box-wall --scenes-dir '" + cache + "'", "pipelines",
                                "--help", "render --help", "--version"}) {
    const CliRun r = test::run_shell("{ " + std::string(SB_CLI_PATH) + " " + command + " >/dev/full; }");
    EXPECT_EQ(r.code, 4) << command << ": " << r.out;
    EXPECT_NE(r.out.find("stereobench: error: cannot write to"), std::string::npos) << command << ": " << r.out;
    EXPECT_EQ(r.out.find("internal error"), std::string::npos) << command << ": " << r.out;
  }
}

TEST(Cli, VersionAndHelp) {
  const CliRun v = run("--version");
  EXPECT_EQ(v.code, 0);
  EXPECT_NE(v.out.find("stereobench 0."), std::string::npos) << v.out;
  for (const char* args : {"--help", "scenes --help", "scenes generate --help", "scenes info --help", "scenes list --help"}) {
    const CliRun h = run(args);
    EXPECT_EQ(h.code, 0) << args;
    EXPECT_NE(h.out.find("Usage"), std::string::npos) << args << ": " << h.out;
  }
  // Defaults are shown.
  EXPECT_NE(run("scenes generate --help").out.find("out/scenes"), std::string::npos);
  EXPECT_NE(run("scenes info --help").out.find("--max-disparity"), std::string::npos);
}

TEST(Cli, BadArgumentsExitWith3AndSayWhy) {
  test::ScratchDir dir("cli");
  test::MiniGltf g;
  g.add_triangle();
  g.write_gltf(dir / "tri.gltf");
  const std::string scene = "'" + (dir / "tri.gltf").string() + "'";
  const std::string sd = " --scenes-dir '" + dir.path().string() + "'";
  struct Case { std::string args; std::string expect; };
  const Case cases[] = {
      {"scenes info no-such-scene" + sd, "unknown scene 'no-such-scene'"},
      {"scenes info spheres:count=5" + sd,
       "parameters in a scene's name are read by sweep definitions only; write the variant with `stereobench scenes "
       "generate spheres --param KEY=VALUE`"},
      {"scenes generate no-such-scene --out '" + dir.path().string() + "'", "unknown scene generator 'no-such-scene'"},
      {"scenes info " + scene + " --interaxial -0.064", "--interaxial -0.064 is not a positive finite number"},
      {"scenes info " + scene + " --interaxial 0", "--interaxial 0 is not a positive"},
      {"scenes info " + scene + " --interaxial nan", "--interaxial nan is not a positive"},
      {"scenes info " + scene + " --convergence 0", "--convergence 0 is not a positive"},
      {"scenes info " + scene + " --convergence inf", "--convergence inf is not a positive"},
      {"scenes info " + scene + " --max-disparity -3", "--max-disparity -3 is not a positive"},
      {"scenes info " + scene + " --resolution 0x100", "--resolution 0x100 is out of range"},
      {"scenes info " + scene + " --resolution 16385x100", "--resolution 16385x100 is out of range"},
      {"scenes info " + scene + " --resolution banana", "--resolution 'banana' is not WIDTHxHEIGHT"},
      {"scenes info " + scene + " --vfov 180", "--vfov 180 is out of range"},
      {"scenes info " + scene + " --interaxial 0.06 --max-disparity 20",
       "--interaxial and --max-disparity exclude each other; give one of them"},
      {"scenes info " + scene + " --interaxial abc", "--interaxial"},
      {"scenes generate spheres --param count=0 --out '" + dir.path().string() + "'", "count"},
      {"scenes generate spheres --param nonsense=1 --out '" + dir.path().string() + "'", "nonsense"},
      {"scenes generate spheres --param count=abc --out '" + dir.path().string() + "'", "not a finite decimal number"},
      {"scenes generate spheres --param count=0x10 --out '" + dir.path().string() + "'",
       "--param count: '0x10' is not a finite decimal number"},
      {"scenes generate --out '" + dir.path().string() + "'", "name the scenes"},
      {"scenes frobnicate", "'frobnicate' is not a command of stereobench scenes; its commands: list, generate, info"},
      {"frobnicate", "'frobnicate' is not a command of stereobench; its commands: scenes, render"},
      {"sweep runn x.toml", "'runn' is not a command of stereobench sweep; its commands: run"},
      {"", "stereobench needs a command: scenes, render, pipelines"},
      {"sweep", "stereobench sweep needs a command: run, cells, csv, collect"},
      {"reference", "stereobench reference needs a command: "},
      {"scenes generate spheres --seed -1 --out '" + dir.path().string() + "'",
       "--seed: a seed is a whole number from 0 to 18446744073709551615, not -1"},
      {"scenes generate spheres --seed 18446744073709551616 --out '" + dir.path().string() + "'",
       "not 18446744073709551616"},  // 2^64: saturated to 2^64 - 1 before
      {"scenes generate spheres --seed 1e3 --out '" + dir.path().string() + "'", "--seed: '1e3' is not a decimal integer"},
      // Decimal, but more than the option's integer holds: said so, with where to find its range.
      {"render --lights 99999999999", "--lights 99999999999 is too large in magnitude for the option to hold; give a smaller number"},
      // A folder where a file is to be written: refused before the work, not when writing it.
      {"bench --scene " + scene + " --resolution 16x9 --pipelines plain-rt --json '" + dir.path().string() + "'",
       "--json: " + dir.path().string() + " is a folder; give the name of the file to write"},
      {"sweep collect '" + dir.path().string() + "' a.jsonl",
       "out: " + dir.path().string() + " is a folder; give the name of the file to write"},
      {"gate --results a.jsonl --junit '" + dir.path().string() + "'",
       "--junit: " + dir.path().string() + " is a folder"},
      // A folder not made yet (a trailing '/'): refused before its folders are made.
      {"compare a.png b.png --json '" + (dir / "new" / "folder").string() + "/'",
       "--json: " + (dir / "new" / "folder").string() + "/ names a folder (it ends in '/'); give the name of the file"},
      {"sweep run x.toml --executor slurm --shards -1", "--shards: Value -1 not in range 1 to 1001"},
      {"sweep run x.toml --executor slurm --shards 0", "--shards: Value 0 not in range 1 to 1001"},
      // The parser's own usage errors, in the words of the others (it said "--resolution: At Most
      // 1 required but received 2", "--threads: 1 required INT missing", "inputs is required").
      {"scenes info " + scene + " -r 64x36 -r 32x18", "--resolution is given 2 times; give it once"},
      {"scenes info " + scene + " --vfov", "--vfov needs a value after it (FLOAT); give --vfov X"},
      {"render --threads", "--threads needs a value after it (INT); give --threads N"},
      {"sweep run x.toml --executor slurm --shards",
       "--shards needs a value after it (UINT:UINT in [1 - 1001]); give --shards N"},
      {"sweep collect x.jsonl", "the argument inputs is missing; give it"},
      {"gate", "--results is required; give it"},
      {"scenes info " + scene + " --bogus",
       "unexpected argument(s) --bogus: an option this command does not have, or a value given without its option"},
  };
  for (const Case& c : cases) {
    const CliRun r = run(c.args);
    EXPECT_EQ(r.code, 3) << c.args << "\n" << r.out;
    EXPECT_NE(r.out.find(c.expect), std::string::npos) << c.args << "\nexpected: " << c.expect << "\ngot: " << r.out;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "new")) << "a refused run makes no folder";
}

TEST(Cli, ListOptionsRefuseEmptyEntries) {
  // A doubled or stray comma used to drop an entry silently: 'plain-rt,,plain-raster' ran two
  // pipelines where three may have been meant, and a gate --only list stored fewer baselines.
  test::ScratchDir dir("emptyentry");
  const std::string common = " --scenes-dir '" + (dir / "scenes").string() + "' --resolution 32x18 --out '" +
                             dir.path().string() + "'";
  const std::string entries[] = {"plain-rt,,plain-raster", "plain-rt,", ",plain-rt"};
  for (const std::string& list : entries)
    for (const std::string& command : {std::string("validate"), std::string("path -n 1"), std::string("bench")}) {
      const std::string args = command + " --scene box-wall --pipelines '" + list + "'" +
                               (command == "bench" ? " --resolution 32x18 --scenes-dir '" + (dir / "scenes").string() + "'"
                                                   : common);
      const CliRun r = run(args);
      EXPECT_EQ(r.code, 3) << args << "\n" << r.out;
      EXPECT_NE(r.out.find("--pipelines '" + list + "' has an empty entry"), std::string::npos) << args << "\n" << r.out;
    }
  const CliRun gate = run("gate --results '" + (dir / "none.jsonl").string() + "' --update-baseline --only 'plain-rt,,repro-rt'");
  EXPECT_EQ(gate.code, 3) << gate.out;
  EXPECT_NE(gate.out.find("--only 'plain-rt,,repro-rt' has an empty entry"), std::string::npos) << gate.out;
  // Comma-separated and repeated entries still combine.
  const CliRun ok = run("validate --scene box-wall --pipelines plain-rt --pipelines plain-raster,repro-rt" + common);
  EXPECT_EQ(ok.code, 0) << ok.out;
  EXPECT_NE(ok.out.find("validating 3 pipeline(s)"), std::string::npos) << ok.out;
}

TEST(Cli, SceneInfoPrintsRigAndDisparities) {
  test::ScratchDir dir("cliinfo");
  test::MiniGltf g;
  g.add_triangle();
  // Two lights, listed with the values the shading reads (their units checkable there).
  g.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  g.doc["extensions"]["KHR_lights_punctual"]["lights"] = nlohmann::json::array(
      {{{"type", "point"}, {"name", "lamp"}, {"intensity", 54.35}},
       {{"type", "spot"}, {"name", "cone"}, {"intensity", 2}, {"color", {1, 0.5, 0.25}},
        {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.5}}}}});
  g.add_node({{"translation", {0, 2, 1}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  g.add_node({{"translation", {1, 2, 1}}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
  g.write_gltf(dir / "tri.gltf");
  const CliRun r = run("scenes info '" + (dir / "tri.gltf").string() + "' --resolution 640x360 --max-disparity 20 --convergence 2");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("1 triangles"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("point 'lamp': intensity 54.35 W/sr, colour (1, 1, 1), at (0.000, 2.000, 1.000) m"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("spot 'cone': intensity 2 W/sr, colour (1, 0.5, 0.25), at (1.000, 2.000, 1.000) m, cone "
                       "11.5..28.6 deg"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("640x360"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("max disparity 20.00 px"), std::string::npos) << r.out;
}

TEST(Cli, SceneInfoCountsZeroAreaTriangles) {
  test::ScratchDir dir("clizero");
  test::MiniGltf g;
  const int pos = g.add_positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  std::vector<uint16_t> idx = {0, 1, 2, 1, 1, 1};
  const int ia = g.add_accessor(g.add_view(idx), 5123, idx.size(), "SCALAR");
  g.add_node({{"mesh", g.add_mesh(nlohmann::json::array({{{"attributes", {{"POSITION", pos}}}, {"indices", ia}}}))}});
  g.write_gltf(dir / "z.gltf");
  const CliRun r = run("scenes info '" + (dir / "z.gltf").string() + "'");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("2 triangles (1 of zero area), 3 vertices"), std::string::npos) << r.out;
}

TEST(Cli, MoreThreadsThanCoresAreTheCoresAndSaySo) {
  test::ScratchDir dir("threads");
  const CliRun r = run("render --scene box-wall --pipeline plain-rt --resolution 32x18 --threads 1024 --scenes-dir " +
                       test::quoted(dir / "scenes") + " --out " + test::quoted(dir / "r"));
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("note: --threads 1024 is more than the"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("TBB Warning"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("1024 threads"), std::string::npos) << "the count run is recorded, not the count asked: " << r.out;
}

TEST(Cli, AFileLargerThanTheMemoryLimitIsAnIoErrorNotATruncatedFile) {
  // A 4 GiB file (sparse: no disk used) read under a 3 GB address-space limit: the read fails
  // for memory (exit 4) instead of returning the file cut short, which the reader reported as a
  // damaged file (exit 3).
  test::ScratchDir dir("bigread");
  const std::filesystem::path big = dir / "big.toml";
  { std::ofstream(big).put(' '); }
  std::filesystem::resize_file(big, uintmax_t{4} << 30);
  const CliRun r = test::run_shell("ulimit -v 3000000 && " + std::string(SB_CLI_PATH) + " gate --config " +
                                   test::quoted(big) + " --results " + test::quoted(big));
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("not enough memory to read " + big.string() + " (4294967296 bytes)"), std::string::npos)
      << r.out;
  // A scene file is refused by its size before it is read: beyond 4 GiB no glTF reader takes it.
  const std::filesystem::path scene = dir / "big.glb";
  { std::ofstream(scene).put(' '); }
  std::filesystem::resize_file(scene, uintmax_t{4} << 30);
  const CliRun s = test::run_cli("scenes info " + test::quoted(scene));
  EXPECT_EQ(s.code, 3) << s.out;
  EXPECT_NE(s.out.find(scene.string() + ": 4294967296 bytes; a glTF file is at most 4 GiB"), std::string::npos)
      << s.out;
}

TEST(Cli, ATerminatedWriteLeavesNoTemporaryFile) {
  // SIGTERM (a job's time limit, `kill`) while a 4K render writes its EXR: the hidden temporary
  // file (some 500 MB) stayed for good unless the same file was written again. The process still
  // ends by the signal. (SIGINT behaves alike; a shell's background job ignores it, so the test
  // sends SIGTERM.)
  test::ScratchDir dir("sigterm");
  const std::string out = test::quoted(dir / "out");
  const CliRun r = test::run_shell(
      std::string(SB_CLI_PATH) + " render --scene lit-plane --pipeline plain-raster --resolution 4k --stereo none " +
      "--scenes-dir " + test::quoted(dir / "scenes") + " --out " + out + " & pid=$!; seen=0; " +
      "for i in $(seq 1 2400); do if ls -A " + out + " 2>/dev/null | grep -q 'tmp-'; then seen=1; break; fi; " +
      "sleep 0.05; done; kill -TERM $pid; wait $pid; echo \"seen=$seen status=$?\"; ls -A " + out);
  ASSERT_NE(r.out.find("seen=1"), std::string::npos) << "no temporary file was seen while the render wrote: " << r.out;
  EXPECT_NE(r.out.find("status=143"), std::string::npos) << r.out;  // 128 + SIGTERM
  EXPECT_EQ(r.out.find(".tmp-"), std::string::npos) << r.out;
}

TEST(Cli, ADeviceGivenAsAnInputFileIsBadInputNotReadWithoutEnd) {
  // Every text input goes through one reader, which read /dev/zero until memory ran out.
  for (const std::string args : {"gate --config /dev/zero --results /dev/zero", "scenes info /dev/zero",
                                 "report /dev/zero --out /dev/null/never"}) {
    const CliRun r = test::run_shell("ulimit -v 4000000 && timeout 60 " + std::string(SB_CLI_PATH) + " " + args);
    EXPECT_EQ(r.code, 3) << args << "\n" << r.out;
    EXPECT_NE(r.out.find("/dev/zero"), std::string::npos) << args << "\n" << r.out;
  }
}

TEST(Cli, APathUnderProcThatIsNoOpenFileIsAnUnwritableFolderNamedByItsOption) {
  // Only /proc/self/fd/N and its kin are a process's open files; /proc/x was written "in place"
  // (after the whole timing, for bench --json) and failed naming neither option nor remedy.
  CliRun r = test::run_cli("bench --scene lit-plane --resolution 32x18 --repetitions 1 --pipelines plain-rt --json "
                           "/proc/x/y.json");
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("--json /proc/x/y.json: its folder /proc/x"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("per-stage"), std::string::npos) << "refused before the timing: " << r.out;
  // An --out there is refused before the scene is even looked up: the check made before the work
  // tries the folder (it asked access(), which lets root pass /proc, and the refusal came once the
  // scene had loaded).
  r = test::run_cli("render --scene no-such-scene --resolution 32x18 --out /proc/x/out");
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("--out /proc/x/out: cannot create the folder"), std::string::npos) << r.out;
  test::ScratchDir dir("procscenes");
  r = test::run_cli("render --scene lit-plane --resolution 32x18 --scenes-dir /proc/x --out " + test::quoted(dir / "o"));
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("the scenes folder /proc/x (--scenes-dir, or $STEREOBENCH_SCENES) cannot hold the generated "
                       "scene 'lit-plane'"),
            std::string::npos)
      << r.out;
}

TEST(Cli, AFileSystemRefusalNamesThePathAndItsReason) {
  // A store behind a link that loops, and a working folder deleted under the command: refusals of
  // the file system, exit 4, with the path or the reason, never advice about full disks and pipes
  // (a path no command checked first was reported as "filesystem error: status: ..." that way).
  test::ScratchDir dir("loop");
  std::filesystem::create_symlink("loop2", dir / "loop1");
  std::filesystem::create_symlink("loop1", dir / "loop2");
  CliRun r = test::run_cli("reference generate --scene lit-plane --resolution 32x18 --store " +
                           test::quoted(dir / "loop1"));
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find((dir / "loop1").string()), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Too many levels of symbolic links"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("closed pipe"), std::string::npos) << r.out;

  std::filesystem::create_directories(dir / "gone");
  r = test::run_shell("cd " + test::quoted(dir / "gone") + " && rmdir ../gone && " + SB_CLI_PATH + " sweep run " +
                      test::quoted(std::filesystem::path(SB_SOURCE_DIR) / "ci" / "smoke.toml") +
                      " --executor slurm --out " + test::quoted(dir / "out") + " --cache ''");
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("No such file or directory"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("closed pipe"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("internal error"), std::string::npos) << r.out;
}

TEST(Cli, RenderWritesEveryOutputAndBenchPrintsATable) {
  test::ScratchDir dir("render");
  const std::string common = " --scenes-dir '" + (dir / "scenes").string() + "' --resolution 64x36";
  const CliRun r = run("render --scene box-wall --pipeline plain-raster --out '" + dir.path().string() + "'" + common);
  ASSERT_EQ(r.code, 0) << r.out;
  for (const char* suffix : {".exr", "_left.png", "_right.png", "_anaglyph.png", "_sbs.png", "_stats.json"})
    EXPECT_TRUE(std::filesystem::exists(dir / (std::string("box-wall_plain-raster") + suffix))) << suffix;
  const std::string stats = test::read_text(dir / "box-wall_plain-raster_stats.json");
  const auto j = nlohmann::json::parse(stats);
  EXPECT_GT(j.at("timings_s").at("left_gbuffer").get<double>(), 0.0);
  EXPECT_GT(j.at("counters").at("shadow_rays").get<uint64_t>(), 0u);
  EXPECT_EQ(j.at("rig").at("width").get<int>(), 64);
  // The EXR's header holds the stats JSON's content, its file list included (it was left out).
  EXPECT_EQ(nlohmann::json::parse(io::read_exr_metadata(dir / "box-wall_plain-raster.exr").at("stereobench/record")), j);

  // A render that stops while writing (here: the side-by-side image's path is a link into a folder
  // that does not exist) places none of its files: every file is made whole before any takes its
  // name, so the earlier render's set stays as it was (it used to lose its stats and the files the
  // new render wrote first), and no temporary file is left.
  const std::string stem = "box-wall_plain-raster";
  std::filesystem::remove(dir / (stem + "_sbs.png"));
  std::filesystem::create_symlink(dir / "nowhere" / "sbs.png", dir / (stem + "_sbs.png"));
  std::map<std::string, std::string> before;
  for (const char* suffix : {".exr", "_left.png", "_right.png", "_anaglyph.png", "_stats.json"})
    before[suffix] = test::read_text(dir / (stem + suffix));
  const std::string again = "render --scene box-wall --pipeline plain-raster --out '" + dir.path().string() +
                            "' --scenes-dir '" + (dir / "scenes").string() + "' --resolution 48x27";
  const CliRun stopped = run(again);
  EXPECT_EQ(stopped.code, 4) << stopped.out;
  EXPECT_NE(stopped.out.find(stem + "_sbs.png: it is a link to"), std::string::npos) << stopped.out;
  for (const auto& [suffix, text] : before) EXPECT_EQ(test::read_text(dir / (stem + suffix)), text) << suffix;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path()))
    EXPECT_NE(entry.path().filename().string()[0], '.') << entry.path();
  std::filesystem::remove(dir / (stem + "_sbs.png"));
  // A folder where an output goes is found before the render (exit 4: the names are generated,
  // none was given; it was exit 3, "give the name of the file to write", after the render).
  std::filesystem::create_directories(dir / (stem + "_sbs.png"));
  const CliRun blocked = run(again);
  EXPECT_EQ(blocked.code, 4) << blocked.out;
  EXPECT_NE(blocked.out.find("cannot write " + (dir / (stem + "_sbs.png")).string() +
                             ": a folder of that name is in the way; remove it or give another --out"),
            std::string::npos)
      << blocked.out;
  EXPECT_EQ(blocked.out.find("plain-raster on box-wall"), std::string::npos) << "rendered first: " << blocked.out;
  for (const auto& [suffix, text] : before) EXPECT_EQ(test::read_text(dir / (stem + suffix)), text) << suffix;
  std::filesystem::remove(dir / (stem + "_sbs.png"));

  // A diagnostic image an option asked for goes with the next render of the stem that does not
  // ask for it (it stayed, from another resolution, beside the new set).
  const std::string repro = "render --scene box-wall --pipeline repro-rt --out '" + dir.path().string() + "'" + common;
  const CliRun maybe = run(repro + " --option grid_overlay=maybe");
  EXPECT_EQ(maybe.code, 3) << maybe.out;
  EXPECT_NE(maybe.out.find("option grid_overlay=maybe is not a boolean: give true or false (also 1/0, on/off, yes/no)"),
            std::string::npos)
      << maybe.out;
  ASSERT_EQ(run(repro + " --option grid_overlay=on").code, 0);
  ASSERT_TRUE(std::filesystem::exists(dir / "box-wall_repro-rt_grid.png"));
  ASSERT_EQ(run(repro).code, 0);
  ASSERT_EQ(run(repro + " --option grid_overlay=true").code, 0);
  ASSERT_TRUE(std::filesystem::exists(dir / "box-wall_repro-rt_grid.png"));
  ASSERT_EQ(run(repro).code, 0);
  EXPECT_FALSE(std::filesystem::exists(dir / "box-wall_repro-rt_grid.png"));
  EXPECT_TRUE(std::filesystem::exists(dir / "box-wall_repro-rt_holes.png"));

  // A variant renders under its own name; its files say which options it fixed.
  const CliRun v =
      run("render --scene box-wall --pipeline plain-raster:tile=8 --out '" + dir.path().string() + "'" + common);
  ASSERT_EQ(v.code, 0) << v.out;
  EXPECT_EQ(v.out.rfind("plain-raster:tile=8 on box-wall", 0), 0u) << v.out;
  const auto jv = nlohmann::json::parse(test::read_text(dir / "box-wall_plain-raster@tile=8_stats.json"));
  EXPECT_EQ(jv.at("options").at("tile"), "8");
  EXPECT_TRUE(std::filesystem::exists(dir / "box-wall_plain-raster@tile=8_right.png"));

  const CliRun b = run("bench --scene box-wall --pipelines plain-rt,ideal-copy --baseline plain-rt -n 2 -w 0" + common);
  ASSERT_EQ(b.code, 0) << b.out;
  EXPECT_NE(b.out.find("ideal-copy"), std::string::npos) << b.out;
  EXPECT_NE(b.out.find("speed-up"), std::string::npos) << b.out;
  // --json -: the JSON alone on standard output; the tables go to standard error.
  const CliRun json_only = test::run_shell("(" + std::string(SB_CLI_PATH) +
                                           " bench --scene box-wall --pipelines plain-rt --baseline plain-rt -n 1 -w 0"
                                           " --json -" + common + " 2>/dev/null)");
  ASSERT_EQ(json_only.code, 0) << json_only.out;
  EXPECT_EQ(nlohmann::json::parse(json_only.out).at("baseline"), "plain-rt") << json_only.out;
  EXPECT_EQ(nlohmann::json::parse(json_only.out).at("kind"), "stereobench.bench") << json_only.out;
  EXPECT_EQ(nlohmann::json::parse(json_only.out).at("schema_version"), 1) << json_only.out;
  EXPECT_FALSE(std::filesystem::exists("-"));
  // Numbers are decimal: a leading zero does not make an integer octal (010 is ten, not eight).
  const CliRun zeros = run("bench --scene box-wall --pipelines plain-rt --baseline plain-rt -n 010 -w 00" + common);
  ASSERT_EQ(zeros.code, 0) << zeros.out;
  EXPECT_NE(zeros.out.find("0 warm-up + 10 repetitions"), std::string::npos) << zeros.out;
  // One of a thing is not "1 threads" or "1 repetitions".
  const CliRun one = run("bench --scene box-wall --pipelines plain-rt --baseline plain-rt -n 1 -w 0 --threads 1" + common);
  ASSERT_EQ(one.code, 0) << one.out;
  EXPECT_NE(one.out.find(", 1 thread, 0 warm-up + 1 repetition\n"), std::string::npos) << one.out;
  // 'all' times every registered pipeline, beside a variant named after it.
  const CliRun every =
      run("bench --scene box-wall --pipelines all,bidir-warp:occlusion=ztest --baseline plain-rt -n 1 -w 0" + common);
  ASSERT_EQ(every.code, 0) << every.out;
  for (const std::string& name : pipeline_names())
    EXPECT_NE(every.out.find("\n" + name + " "), std::string::npos) << name << "\n" << every.out;
  EXPECT_NE(every.out.find("\nbidir-warp:occlusion=ztest "), std::string::npos) << every.out;

  const CliRun l = run("pipelines");
  EXPECT_EQ(l.code, 0);
  for (const char* name : {"plain-rt", "plain-raster", "ideal-copy"}) EXPECT_NE(l.out.find(name), std::string::npos);
}

TEST(Cli, RenderWritesTheStereoImagesAskedFor) {
  test::ScratchDir dir("stereo_views");
  const std::string stem = "box-wall_plain-raster";
  const std::string render = "render --scene box-wall --pipeline plain-raster --resolution 64x36 --out '" +
                             dir.path().string() + "' --scenes-dir '" + (dir / "scenes").string() + "'";
  const auto written = [&] {
    std::map<std::string, bool> w;
    for (const char* view : {"anaglyph", "sbs", "ou"})
      w[view] = std::filesystem::exists(dir / (stem + "_" + view + ".png"));
    return w;
  };
  ASSERT_EQ(run(render).code, 0);
  EXPECT_EQ(written(), (std::map<std::string, bool>{{"anaglyph", true}, {"sbs", true}, {"ou", false}}));

  // Over/under: the left eye on top of the right, twice the height. The earlier set's stereo
  // images that this render does not write go with it (its stats JSON lists the set).
  const CliRun ou = run(render + " --stereo ou");
  ASSERT_EQ(ou.code, 0) << ou.out;
  EXPECT_NE(ou.out.find(stem + "_ou.png"), std::string::npos) << ou.out;
  EXPECT_EQ(written(), (std::map<std::string, bool>{{"anaglyph", false}, {"sbs", false}, {"ou", true}}));
  const io::DecodedImage stacked = io::read_image(dir / (stem + "_ou.png"));
  const io::DecodedImage left = io::read_image(dir / (stem + "_left.png"));
  const io::DecodedImage right = io::read_image(dir / (stem + "_right.png"));
  ASSERT_EQ(stacked.width, 64);
  ASSERT_EQ(stacked.height, 72);
  const size_t half = left.values.size();
  ASSERT_EQ(stacked.values.size(), 2 * half);
  EXPECT_TRUE(std::equal(left.values.begin(), left.values.end(), stacked.values.begin())) << "left eye on top";
  EXPECT_TRUE(std::equal(right.values.begin(), right.values.end(), stacked.values.begin() + static_cast<long>(half)))
      << "right eye below";

  ASSERT_EQ(run(render + " --stereo sbs --stereo anaglyph,ou").code, 0);
  EXPECT_EQ(written(), (std::map<std::string, bool>{{"anaglyph", true}, {"sbs", true}, {"ou", true}}));
  ASSERT_EQ(run(render + " --stereo none").code, 0);
  EXPECT_EQ(written(), (std::map<std::string, bool>{{"anaglyph", false}, {"sbs", false}, {"ou", false}}));

  for (const auto& [value, says] : std::map<std::string, std::string>{
           {"stereo", "--stereo stereo: not a stereo image; give anaglyph (Dubois red-cyan), sbs"},
           {"none,sbs", "--stereo none: 'none' writes no stereo image and stands alone"},
           {"ou,ou", "--stereo: 'ou' is named twice"}}) {
    const CliRun bad = run(render + " --stereo " + value);
    EXPECT_EQ(bad.code, 3) << value << ": " << bad.out;
    EXPECT_NE(bad.out.find(says), std::string::npos) << value << ": " << bad.out;
    EXPECT_EQ(bad.out.find("plain-raster on box-wall"), std::string::npos) << "rendered first: " << bad.out;
  }
}

TEST(Cli, ScenesInfoGivesTheDisparityOfTheSurfacesTheCameraSees) {
  // thin-pole: a pole at the convergence distance (2 m) before a wall at 4 m. The range used to
  // come from the vertices inside the frame, which missed the pole (its vertices lie above and
  // below the picture) and gave 4 m to 4 m.
  test::ScratchDir dir("info");
  const CliRun r = run("scenes info thin-pole --scenes-dir '" + (dir / "scenes").string() + "'");
  ASSERT_EQ(r.code, 0) << r.out;
  const size_t at = r.out.find("at the nearest visible surface (");
  ASSERT_NE(at, std::string::npos) << r.out;
  const double nearest = std::stod(r.out.substr(at + std::string("at the nearest visible surface (").size()));
  EXPECT_NEAR(nearest, 2.0, 0.01) << r.out;
  EXPECT_NE(r.out.find("at the farthest (4.0"), std::string::npos) << r.out;
  // A bad parameter is refused before the output folder is made.
  const CliRun bad = run("scenes generate thin-pole --param nope=1 --out '" + (dir / "made").string() + "'");
  EXPECT_EQ(bad.code, 3) << bad.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "made"));
}

TEST(Cli, OutputsAreNamedByTheSceneFileAndStayInTheOutputFolder) {
  // The scene file's stem starts every output file name, whatever the scene calls itself inside
  // (glTF scenes[0].name: Blender names every scene "Scene", and a file may give a path out of the
  // folder, a dot file, a newline). A file name's own characters are made safe too.
  test::ScratchDir dir("names");
  const std::string common = " --scenes-dir '" + (dir / "scenes").string() + "' --resolution 32x18";
  ASSERT_EQ(run("scenes generate box-wall --out '" + (dir / "scenes").string() + "'").code, 0);
  auto doc = nlohmann::json::parse(test::read_text(dir / "scenes" / "box-wall.gltf"));
  struct Case { const char* file; const char* inner; const char* stem; };
  const Case cases[] = {{"kitchen.gltf", "Scene", "kitchen"},
                        {"office.gltf", "Scene", "office"},
                        {"copy.gltf", "../escaped", "copy"},
                        {"plain.gltf", "/tmp/abs", "plain"},
                        {".hidden\nline.gltf", ".hidden", "_hidden_line"},
                        {"two words.gltf", "", "two_words"}};
  const std::string out = (dir / "out").string();
  for (const Case& c : cases) {
    doc["scenes"][0]["name"] = c.inner;
    { std::ofstream(dir / c.file) << doc.dump(); }
    const std::string scene = " --scene '" + (dir / c.file).string() + "' --out '" + out + "'";
    const CliRun r = run("render --pipeline plain-rt" + scene + common);
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / (std::string(c.stem) + "_plain-rt_stats.json"))) << c.file;
    const CliRun v = run("validate --pipelines ideal-copy" + scene + common);
    ASSERT_EQ(v.code, 0) << v.out;
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / (std::string(c.stem) + "_full_summary.json"))) << c.file;
  }
  // Every file's outputs are there side by side (two scenes both called "Scene" used to share
  // names, the second run's replacing the first's), and nothing lies outside the output folder.
  std::set<std::string> summaries;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir / "out")) {
    EXPECT_EQ(e.path().parent_path(), dir / "out") << e.path();
    if (e.path().string().ends_with("_full_summary.json")) summaries.insert(e.path().filename().string());
  }
  EXPECT_EQ(summaries.size(), std::size(cases));
  for (const auto& e : std::filesystem::directory_iterator(dir.path()))
    EXPECT_TRUE(e.path().filename() == "scenes" || e.path().filename() == "out" ||
                e.path().extension() == ".gltf")
        << "written beside the output folder: " << e.path();

  // A scene file that is one of the render's outputs, by name or through a link, is not replaced
  // by it (the stats JSON used to take its place). A stem is cut at 64 bytes, so a file of a long
  // name can be named as its own output; a name no output takes renders.
  const std::filesystem::path own = dir / "out" / (std::string(64, 'n') + "_plain-rt_stats.json");
  { std::ofstream(own) << doc.dump(); }
  std::filesystem::create_symlink(own, dir / (std::string(64, 'n') + "_plain-rt_stats.gltf"));
  for (const std::filesystem::path& scene : {own, dir / (std::string(64, 'n') + "_plain-rt_stats.gltf")}) {
    const CliRun over = run("render --pipeline plain-rt --scene '" + scene.string() + "' --out '" + out + "'" + common);
    EXPECT_EQ(over.code, 3) << over.out;
    EXPECT_NE(over.out.find("the scene file is this render's output"), std::string::npos) << over.out;
    EXPECT_EQ(nlohmann::json::parse(test::read_text(own)), doc);
  }
  // ... and an output name that is a link to the scene.
  const std::filesystem::path elsewhere = dir / "elsewhere.gltf";
  { std::ofstream(elsewhere) << doc.dump(); }
  std::filesystem::create_symlink("../elsewhere.gltf", dir / "out" / "elsewhere_plain-rt_stats.json");
  const CliRun through =
      run("render --pipeline plain-rt --scene '" + elsewhere.string() + "' --out '" + out + "'" + common);
  EXPECT_EQ(through.code, 3) << through.out;
  EXPECT_EQ(nlohmann::json::parse(test::read_text(elsewhere)), doc);
  std::filesystem::remove(dir / "out" / "elsewhere_plain-rt_stats.json");
  EXPECT_EQ(run("render --pipeline plain-rt --scene '" + elsewhere.string() + "' --out '" + out + "'" + common).code,
            0);
}

TEST(Cli, AnOutputNeverTakesThePlaceOfAFileTheSceneReads) {
  // A texture beside the scene named as an output of the run was replaced by that output, the
  // run ending in success; render refuses before rendering, validate before any file is placed.
  test::ScratchDir dir("reads");
  const std::string common = " --scenes-dir '" + (dir / "scenes").string() + "' --resolution 32x18";
  ASSERT_EQ(run("scenes generate textured-plane --out '" + (dir / "scenes").string() + "'").code, 0);
  ASSERT_EQ(run("render --pipeline plain-rt --scene textured-plane --out '" + (dir / "png").string() + "'" + common)
                .code,
            0);
  auto doc = nlohmann::json::parse(test::read_text(dir / "scenes" / "textured-plane.gltf"));
  const std::string texture = test::read_text(dir / "png" / "textured-plane_plain-rt_left.png");
  const auto scene_reading = [&](const std::string& stem, const std::string& image) {
    doc["images"][0] = {{"uri", image}};
    std::ofstream(dir / (stem + ".gltf")) << doc.dump();
    std::ofstream(dir / image, std::ios::binary) << texture;
    return " --scene '" + (dir / (stem + ".gltf")).string() + "' --out '" + dir.path().string() + "'";
  };
  struct Case { const char* command; const char* stem; const char* image; const char* run; };
  for (const Case& c : {Case{"render --pipeline plain-rt", "t", "t_plain-rt_left.png", "render"},
                        Case{"validate --pipelines plain-rt", "v", "v_truth-full.png", "validation"}}) {
    const CliRun r = run(c.command + scene_reading(c.stem, c.image) + common);
    EXPECT_EQ(r.code, 3) << r.out;
    EXPECT_NE(r.out.find("the file " + (dir / c.image).string() + " the scene reads (a buffer or an image) is this " +
                         c.run + "'s output"),
              std::string::npos)
        << r.out;
    EXPECT_EQ(r.out.find("truth: full"), std::string::npos) << "refused before the truth renders";
    EXPECT_EQ(test::read_text(dir / c.image), texture);
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "v_full_summary.json"));

  // A scene path that is not UTF-8 renders: the stats JSON holds it with U+FFFD (it was an
  // internal error once the render had finished, and nothing was written).
  std::filesystem::copy_file(dir / "scenes" / "textured-plane.gltf", dir / "bad\xff.gltf");
  const CliRun bad = run("render --pipeline plain-rt --scene '" + (dir / "bad\xff.gltf").string() + "' --out '" +
                         (dir / "bad").string() + "'" + common);
  ASSERT_EQ(bad.code, 0) << bad.out;
  bool found = false;
  for (const auto& e : std::filesystem::directory_iterator(dir / "bad"))
    if (e.path().string().ends_with("_plain-rt_stats.json")) {
      found = true;
      EXPECT_NE(nlohmann::json::parse(test::read_text(e.path()))["scene"]["path"].get<std::string>().find("\xEF\xBF\xBD"),
                std::string::npos);
    }
  EXPECT_TRUE(found);
}

TEST(Cli, AGeneratedVariantNeverTakesTheDefaultScenesFile) {
  // Commands naming `spheres` load <scenes>/spheres.glb; another seed or parameter written there
  // would be rendered and recorded as the default scene.
  test::ScratchDir dir("variants");
  const std::string out = " --out '" + dir.path().string() + "'";
  ASSERT_EQ(run("scenes generate lit-plane" + out).code, 0);
  const std::string before = test::read_text(dir / "lit-plane.gltf");
  const CliRun seeded = run("scenes generate lit-plane --seed 35 --param albedo=0.25" + out);
  ASSERT_EQ(seeded.code, 0) << seeded.out;
  EXPECT_TRUE(std::filesystem::exists(dir / "lit-plane_seed-35_albedo-0.25.gltf")) << seeded.out;
  EXPECT_EQ(test::read_text(dir / "lit-plane.gltf"), before);
  ASSERT_EQ(run("scenes generate lit-plane --param albedo=0.25" + out).code, 0);
  EXPECT_TRUE(std::filesystem::exists(dir / "lit-plane_albedo-0.25.gltf"));
  EXPECT_EQ(test::read_text(dir / "lit-plane.gltf"), before);
  // Values equal to six digits are two variants with two files: printed with six digits, the
  // second replaced the first and a sweep ran both cells on one scene.
  ASSERT_EQ(run("scenes generate lit-plane --param albedo=0.25000001" + out).code, 0);
  EXPECT_TRUE(std::filesystem::exists(dir / "lit-plane_albedo-0.25000001.gltf"));
  // The first variant's file is still the first's: its extras record the parameters it was made with.
  const auto params = [&](const char* file) {
    return nlohmann::json::parse(test::read_text(dir / file))["scenes"][0]["extras"]["stereobench"]["params"]["albedo"].get<double>();
  };
  EXPECT_EQ(params("lit-plane_albedo-0.25.gltf"), 0.25);
  EXPECT_EQ(params("lit-plane_albedo-0.25000001.gltf"), 0.25000001);
}

TEST(Cli, RenderScoresHolesOnlyWhenPixelsAreReprojected) {
  test::ScratchDir dir("holes");
  const std::string common = " --scenes-dir '" + (dir / "scenes").string() + "' --resolution 64x36 --out '" +
                             dir.path().string() + "'";
  // ideal-copy reprojects every right pixel and fills nothing: every true disocclusion is missed.
  const CliRun r = run("render --scene box-wall --pipeline ideal-copy" + common);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("true disocclusions"), std::string::npos) << r.out;
  EXPECT_TRUE(std::filesystem::exists(dir / "box-wall_ideal-copy_holes.png"));
  const auto j = nlohmann::json::parse(test::read_text(dir / "box-wall_ideal-copy_stats.json"));
  const auto& holes = j.at("holes");
  EXPECT_EQ(holes.at("not_reprojected_pixels").get<uint64_t>(), 0u);
  EXPECT_GT(holes.at("true_disocclusions").get<uint64_t>(), 0u);
  EXPECT_EQ(holes.at("true_disocclusions").get<uint64_t>(),
            holes.at("outside_frustum").get<uint64_t>() + holes.at("hidden").get<uint64_t>());
  EXPECT_EQ(holes.at("recall").get<double>(), 0.0);
  EXPECT_TRUE(holes.at("precision").is_null()) << "nothing flagged: no precision to speak of";
  EXPECT_NE(r.out.find("not reprojected        recall 0.00 %, precision - (0 pixels, 0 of them"), std::string::npos)
      << r.out;
  for (const char* key : {"true_positives", "analysis_s"}) EXPECT_TRUE(holes.contains(key)) << key;

  // plain-rt traces every pixel: no holes section, no overlay.
  const CliRun p = run("render --scene box-wall --pipeline plain-rt" + common);
  ASSERT_EQ(p.code, 0) << p.out;
  EXPECT_EQ(p.out.find("true disocclusions"), std::string::npos) << p.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "box-wall_plain-rt_holes.png"));
  EXPECT_FALSE(nlohmann::json::parse(test::read_text(dir / "box-wall_plain-rt_stats.json")).contains("holes"));
}

TEST(Cli, AFarSceneAndARigThatSeesNothingAreWarnedAbout) {
  test::ScratchDir dir("far");
  // A triangle and its camera 100 km from the origin: float positions there put shadow rays 1.5 m
  // off the surfaces, and small objects lost their shadows without a word.
  // A triangle `size` m across at x, and its camera looking at it from `size` m away.
  const auto write_scene = [&](const std::string& file, double x, double size) {
    test::MiniGltf g;
    g.add_triangle();
    g.doc["nodes"][0]["translation"] = {x, 0.0, 0.0};
    g.doc["nodes"][0]["scale"] = {size, size, size};
    g.add_node({{"camera", 0}, {"translation", {x + 0.2 * size, 0.2 * size, size}}});
    g.doc["cameras"] = {
        {{"type", "perspective"}, {"perspective", {{"yfov", 1.0}, {"znear", 0.01 * size}, {"zfar", 100.0}}}}};
    g.doc["scenes"][0]["extras"] = {{"stereobench", {{"ambient", 1.0}}}};
    g.write_gltf(dir / file);
  };
  write_scene("far.gltf", 100000.0, 1.0);
  write_scene("near.gltf", 0.0, 1.0);
  // A triangle of 1 mm seen from 1 mm: the default rig's eyes stand 32 mm either side and both miss
  // it (a scene in millimetres rendered black without a word).
  write_scene("tiny.gltf", 0.0, 0.001);
  const auto render = [&](const std::string& file) {
    return run("render --pipeline plain-rt --scene " + test::quoted(dir / file) + " --resolution 32x18 --out " +
               test::quoted(dir / "out"));
  };
  const CliRun far = render("far.gltf");
  ASSERT_EQ(far.code, 0) << far.out;
  EXPECT_NE(far.out.find("warning: scene 'far' reaches 100001 m from the origin and is 1.41421 m across: positions are "
                         "floats, so shadow rays start 1.53 m off the surfaces"),
            std::string::npos)
      << far.out;
  const CliRun near = render("near.gltf");
  ASSERT_EQ(near.code, 0) << near.out;
  EXPECT_EQ(near.out.find("from the origin"), std::string::npos) << near.out;
  EXPECT_EQ(near.out.find("neither eye sees a surface"), std::string::npos) << near.out;
  const CliRun black = render("tiny.gltf");
  ASSERT_EQ(black.code, 0) << black.out;
  EXPECT_NE(black.out.find("warning: neither eye sees a surface: every pixel is background. The eyes stand 0.032 m "
                           "either side of the centre camera"),
            std::string::npos)
      << black.out;
}

TEST(Cli, GeometryBeforeTheNearPlaneIsWarnedAbout) {
  // A triangle 1 m in front of a camera whose near plane is at 2 m: the rasterizer clips it, rays
  // see it. The warning counts the pixels, and they are exactly those where the two renders differ.
  test::ScratchDir dir("near");
  const auto write_scene = [&](double znear) {
    test::MiniGltf g;
    g.add_triangle();
    g.add_node({{"camera", 0}, {"translation", {0.2, 0.2, 1.0}}});
    g.doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 1.0}, {"znear", znear}, {"zfar", 100.0}}}}};
    g.doc["scenes"][0]["extras"] = {{"stereobench", {{"ambient", 1.0}}}};
    g.write_gltf(dir / "near.gltf");
  };
  const std::string args = " --scene " + test::quoted(dir / "near.gltf") + " --resolution 160x90 --out " +
                           test::quoted(dir / "out");
  write_scene(2.0);
  const CliRun raster = run("render --pipeline plain-raster" + args);
  ASSERT_EQ(raster.code, 0) << raster.out;
  EXPECT_NE(raster.out.find("warning: 3111 pixels of the left eye and 3172 of the right see geometry nearer than the "
                            "camera's near plane (znear 2 m)"),
            std::string::npos)
      << raster.out;
  ASSERT_EQ(run("render --pipeline plain-rt" + args).code, 0);
  const CliRun cmp = run("compare " + test::quoted(dir / "out" / "near_plain-raster_right.png") + " " +
                         test::quoted(dir / "out" / "near_plain-rt_right.png"));
  EXPECT_NE(cmp.out.find("(3172 pixels with a channel difference"), std::string::npos) << cmp.out;
  // scenes info counts those rays apart: their disparity is no surface's a pipeline shows.
  const CliRun info = run("scenes info " + test::quoted(dir / "near.gltf") + " --resolution 160x90");
  ASSERT_EQ(info.code, 0) << info.out;
  EXPECT_NE(info.out.find("hit a surface nearer than the near plane (2 m), which rasterizing pipelines clip"),
            std::string::npos)
      << info.out;

  write_scene(0.5);
  const CliRun near = run("render --pipeline plain-raster" + args);
  ASSERT_EQ(near.code, 0) << near.out;
  EXPECT_EQ(near.out.find("near plane"), std::string::npos) << near.out;
}

TEST(Cli, AnOutputFolderThatCannotBeMadeFailsBeforeAnyWork) {
  test::ScratchDir dir("outbad");
  const std::filesystem::path file = dir / "a-file";
  std::ofstream(file) << "not a folder\n";
  const std::string scenes = " --scenes-dir '" + (dir / "scenes").string() + "'";
  const std::string out = (file / "results").string(), json = (file / "bench.json").string();
  const std::string out_args = " --out '" + out + "'", json_args = " --json '" + json + "'";
  const std::string out_error =
      "--out " + out + ": cannot create the folder (Not a directory); give a folder you can write";
  // bench writes --json after every repetition of every pipeline (of every preset row).
  const std::string json_error = "--json " + json + ": its folder " + file.string() +
                                 ": cannot create the folder (Not a directory); give a path you can write";
  const std::pair<std::string, std::string> cases[] = {
      {"render --scene box-wall --pipeline plain-rt --resolution 32x18" + scenes + out_args, out_error},
      {"validate --scene box-wall --pipelines plain-rt --resolution 32x18" + scenes + out_args, out_error},
      {"path --scene box-wall --pipelines plain-rt --resolution 32x18" + scenes + out_args, out_error},
      {"scenes generate box-wall" + out_args, out_error},
      {"bench --scene box-wall --pipelines plain-rt --baseline plain-rt" + scenes + json_args, json_error},
      {"bench --preset kim-focal --preset-rows 1" + scenes + json_args, json_error},
  };
  for (const auto& [args, error] : cases) {
    const CliRun r = run(args);
    EXPECT_EQ(r.code, 4) << args << "\n" << r.out;
    EXPECT_NE(r.out.find(error), std::string::npos) << args << "\n" << r.out;
    // Refused before the scene was generated, let alone rendered.
    EXPECT_FALSE(std::filesystem::exists(dir / "scenes")) << args;
  }
}

TEST(Cli, ARefusedInputLeavesNoEmptyOutputFolder) {
  // The folder is made once the scene has loaded and every pipeline accepted the rig.
  test::ScratchDir dir("outlate");
  const std::string scenes = " --scenes-dir '" + (dir / "scenes").string() + "'";
  const std::pair<std::string, std::string> cases[] = {
      {"render --scene '" + (dir / "none.gltf").string() + "'", "does not exist"},
      {"render --scene box-wall --pipeline rt-buffer --resolution 64x36 --max-disparity 5000" + scenes,
       "rt-buffer"},
      {"validate --scene '" + (dir / "none.gltf").string() + "' --pipelines plain-rt", "does not exist"},
      {"path --scene '" + (dir / "none.gltf").string() + "' --pipelines plain-rt", "does not exist"},
  };
  for (const auto& [args, error] : cases) {
    const CliRun r = run(args + " --out '" + (dir / "out" / "a" / "b").string() + "'");
    EXPECT_EQ(r.code, 3) << args << "\n" << r.out;
    EXPECT_NE(r.out.find(error), std::string::npos) << args << "\n" << r.out;
    EXPECT_FALSE(std::filesystem::exists(dir / "out")) << args;
  }
}

TEST(Cli, ScenesGenerateRefusesAFolderInTheWayOfAnyFileBeforeWritingOne) {
  // The stamp of the second scene is blocked: the first is not written either, and the message is
  // render's (the generator picks the names, so "give the name of the file" was no help).
  test::ScratchDir dir("genblocked");
  std::filesystem::create_directories(dir / "box-wall.gltf.stamp");
  const CliRun r = run("scenes generate lit-plane box-wall --out '" + dir.path().string() + "'");
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("cannot write " + (dir / "box-wall.gltf.stamp").string() +
                       ": a folder of that name is in the way; remove it or give another --out"),
            std::string::npos)
      << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "lit-plane.gltf"));
  EXPECT_FALSE(std::filesystem::exists(dir / "box-wall.gltf"));
}

TEST(Cli, RenderAndBenchRejectBadArguments) {
  test::ScratchDir dir("renderbad");
  const std::string bench_common = " --scenes-dir '" + (dir / "scenes").string() + "' --resolution 32x18";
  const std::string common = bench_common + " --out '" + dir.path().string() + "'";
  struct Case { std::string args; std::string expect; };
  const Case cases[] = {
      {"render --scene box-wall --pipeline warp-drive" + common, "unknown pipeline 'warp-drive'"},
      {"render --scene box-wall --pipeline plain-rt,plain-raster" + common, "render renders one pipeline"},
      {"render --scene box-wall --pipeline all" + common, "`stereobench validate` or `stereobench bench`"},
      {"render --scene box-wall --pipeline plain-raster --option tile=3" + common, "tile=3 is out of range"},
      {"render --scene box-wall --pipeline plain-raster --option tiles=32" + common, "has no option 'tiles'"},
      // The variant's value and another by --option contradict (the option was ignored in silence).
      {"render --scene box-wall --pipeline bidir-warp:occlusion=ztest --option occlusion=none" + common,
       "--option occlusion=none: the variant bidir-warp:occlusion=ztest fixes occlusion=ztest; give the option once"},
      {"render --scene box-wall --pipeline plain-raster:tile=3" + common,
       "pipeline entry 'plain-raster:tile=3': plain-raster: option tile=3 is out of range"},
      {"render --scene box-wall --pipeline plain-rt --threads -1" + common, "--threads -1 is out of range"},
      {"bench --scene box-wall -n 0 --pipelines plain-rt --baseline plain-rt" + bench_common, "--repetitions 0"},
      {"bench --scene box-wall --pipelines plain-rt --baseline plain-rt --option tile=4" + bench_common,
       "PIPELINE.OPTION"},
      // Option values are checked as the pipeline reads them, before any scene loads.
      {"bench --scene box-wall --pipelines bw-warp --baseline bw-warp --option bw-warp.iterations=99" + bench_common,
       "option iterations=99 is out of range 0..64"},
      {"render --scene box-wall --pipeline bw-warp --option iterations=2000000000" + common,
       "iterations=2000000000 is beyond the ±1e9"},
      {"render --scene box-wall --pipeline plain-raster --option tile=8 --option tile=16" + common,
       "--option gives tile twice (8 and 16)"},
      {"render --scene box-wall --pipeline plain-rt --resolution 32x18 --out ''", "--out: is empty; give a name"},
      // An empty --scenes-dir would generate scenes into the current folder.
      {"render --scene box-wall --pipeline plain-rt --scenes-dir '' --out '" + dir.path().string() + "'",
       "--scenes-dir: is empty; give a name"},
      {"bench --scene box-wall --pipelines plain-rt --json ''" + bench_common, "--json: is empty; give a name"},
      // '-' is standard output for file options; as a folder it made one named '-'.
      {"render --scene box-wall --pipeline plain-rt --resolution 32x18 --out -", "--out: names a folder, and '-'"},
      {"reference list --store -", "--store: names a folder, and '-'"},
      // An empty clip or BVH mode was taken as not given: a static path, a refit BVH.
      {"path --scene box-wall --frames 1 --gltf-clip ''" + common, "--gltf-clip: is empty"},
      {"path --scene box-wall --frames 1 --spin-deg 1 --bvh ''" + common, "--bvh: is empty"},
      // The results used to replace the scene file they were measured on.
      {"bench --scene box-wall --pipelines plain-rt --json '" + (dir / "scenes" / "box-wall.gltf").string() + "'" +
           bench_common,
       "names the same file as the scene file"},
      // An empty list used to time every registered pipeline.
      {"bench --scene box-wall --pipelines ''" + bench_common, "--pipelines is given an empty value"},
      {"bench --scene box-wall -n 20000 --pipelines plain-rt --baseline plain-rt" + bench_common,
       "--repetitions 20000 is outside 1..10000"},
      {"bench --scene box-wall --pipelines plain-rt,plain-rt --baseline plain-rt" + bench_common,
       "--pipelines names 'plain-rt' twice"},
      {"bench --scene box-wall --pipelines all,ideal-copy --baseline plain-rt" + bench_common,
       "--pipelines: 'ideal-copy' is one of the pipelines 'all' includes; drop one of them"},
  };
  for (const Case& c : cases) {
    const CliRun r = run(c.args);
    EXPECT_EQ(r.code, 3) << c.args << "\n" << r.out;
    EXPECT_NE(r.out.find(c.expect), std::string::npos) << c.args << "\nexpected: " << c.expect << "\ngot: " << r.out;
  }
  // The variant's own value written another way is the same value (it was refused as another).
  const CliRun same = run("render --scene box-wall --pipeline repro-rt:threshold_arcmin=4 --option "
                          "threshold_arcmin=4.0" + common);
  EXPECT_EQ(same.code, 0) << same.out;
}

}  // namespace
}  // namespace sb
