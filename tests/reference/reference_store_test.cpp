// The reference store: generate with provenance, verify bit for bit, detect a damaged image and a
// changed scene, rewrite only failing references, and report a missing tool as unavailable.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <tuple>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "reference/store.hpp"
#include "renderer/io/file_lock.hpp"
#include "renderer/io/image_io.hpp"
#include "renderer/text.hpp"
#include "scenes/catalog.hpp"
#include "support/lock_wait.hpp"
#include "support/run_cli.hpp"
#include "support/scratch_dir.hpp"

namespace sb::reference {
namespace {

namespace fs = std::filesystem;
using test::quoted;
using nlohmann::json;

const fs::path kScenes = fs::path(SB_BINARY_DIR) / "Testing" / "scenes-cache";

/// `stereobench reference <sub> ...` on the test's own store.
std::string ref(const test::ScratchDir& dir, const std::string& sub) {
  return "reference " + sub + " --store " + quoted(dir / "store") + " --scenes-dir " + quoted(kScenes);
}

/// A scene file's path as the store records it: its folders' links resolved, its own name kept.
std::string recorded(const fs::path& file) { return (fs::weakly_canonical(file.parent_path()) / file.filename()).string(); }

void damage(const fs::path& file) {
  std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
  f.seekp(-8, std::ios::end);
  f.write("damaged!", 8);
}

TEST(ReferenceStore, CommittedReferencesStillHold) {
  // The small references committed under reference/store (box-wall at 160x90 by every provider),
  // verified in a copy so that the source tree is never written. Renders here are bit-identical
  // to them; 50 dB leaves room for another CPU whose Embree kernels round differently.
  test::ScratchDir dir;
  fs::copy(fs::path(SB_SOURCE_DIR) / "reference" / "store", dir / "store", fs::copy_options::recursive);
  const ReferenceStore store(dir / "store");
  ASSERT_EQ(store.ids().size(), 3u) << "reference/store should hold the box-wall references of full, blender, povray";
  const test::CliRun r = test::run_cli(ref(dir, "verify") + " --min-psnr 50");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("3 of 3 reference(s) verified"), std::string::npos) << r.out;
}

TEST(ReferenceStore, GenerateWritesImageAndProvenance) {
  test::ScratchDir dir;
  const test::CliRun gen = test::run_cli(ref(dir, "generate") + " --scene box-wall --resolution 64x36 --threads 1");
  ASSERT_EQ(gen.code, 0) << gen.out;
  const ReferenceStore store(dir / "store");
  ASSERT_EQ(store.ids().size(), 1u);
  const std::string id = store.ids()[0];
  EXPECT_EQ(id, "box-wall_full_64x36_e64.0mm_c4.08m");
  EXPECT_TRUE(fs::exists(dir / "store" / id / "right.exr"));
  EXPECT_TRUE(fs::exists(dir / "store" / id / "right.png"));
  const json p = store.provenance(id);
  EXPECT_EQ(p["provider"]["name"], "full");
  EXPECT_FALSE(p["provider"]["tool_version"].get<std::string>().empty());
  // The built-in provider runs no tool in a work folder, so the provenance names none.
  EXPECT_FALSE(p["provider"].contains("work_folder")) << p["provider"].dump();
  EXPECT_EQ(p["scene"]["content_sha256"].get<std::string>().size(), 64u);
  EXPECT_EQ(p["scene"]["file_sha256"].get<std::string>().size(), 64u);
  EXPECT_EQ(p["image"]["sha256"].get<std::string>().size(), 64u);
  EXPECT_EQ(p["rig"]["width"], 64);
  EXPECT_NE(p["command_line"].get<std::string>().find("--scene box-wall"), std::string::npos);
  EXPECT_EQ(p["date"].get<std::string>().size(), 20u);  // 2026-01-02T03:04:05Z
  // Nothing but complete entries in the store.
  for (const auto& e : fs::directory_iterator(dir / "store")) EXPECT_EQ(e.path().filename().string(), id);
  // The entry's folder is readable as any folder made under the same umask (it was private, 0700).
  fs::create_directory(dir / "plain");
  EXPECT_EQ(fs::status(dir / "store" / id).permissions(), fs::status(dir / "plain").permissions());
}

TEST(ReferenceStore, AFullDiskNamesTheEntryNotItsRemovedWorkingFolder) {
  // A disk that fills as the image is written (a file-size limit of 8 KiB; the signal sent at the
  // limit ignored, so the write fails as on a full disk). The message named the hidden working
  // folder, removed by the time it was read.
  test::ScratchDir dir;
  ASSERT_EQ(test::run_cli(ref(dir, "generate") + " --scene box-wall --resolution 32x18 --threads 1").code, 0);
  const test::CliRun r = test::run_shell("trap '' XFSZ; ulimit -f 8; " + std::string(SB_CLI_PATH) + " " +
                                         ref(dir, "generate") + " --scene box-wall --resolution 64x36 --threads 1");
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find((dir / "store" / "box-wall_full_64x36_e64.0mm_c4.08m").string() + "/"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("(reference 'box-wall_full_64x36_e64.0mm_c4.08m' was not stored)"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find(".new-"), std::string::npos) << r.out;
  std::vector<std::string> entries;
  for (const auto& e : fs::directory_iterator(dir / "store")) entries.push_back(e.path().filename().string());
  EXPECT_EQ(entries, std::vector<std::string>{"box-wall_full_32x18_e64.0mm_c4.08m"});
}

TEST(ReferenceStore, VerifyUpdateOnlyFailingAndCorruption) {
  test::ScratchDir dir;
  ASSERT_EQ(test::run_cli(ref(dir, "generate") + " --scene box-wall --resolution 64x36").code, 0);
  ASSERT_EQ(test::run_cli(ref(dir, "generate") + " --scene thin-pole --resolution 48x32").code, 0);
  const ReferenceStore store(dir / "store");
  ASSERT_EQ(store.ids().size(), 2u);

  const test::CliRun ok = test::run_cli(ref(dir, "verify") + " --json " + quoted(dir / "verdicts.json"));
  EXPECT_EQ(ok.code, 0) << ok.out;
  const json verdicts = json::parse(test::read_text(dir / "verdicts.json"));
  ASSERT_EQ(verdicts.size(), 2u);
  for (const json& v : verdicts) {
    EXPECT_EQ(v["status"], "ok");
    EXPECT_TRUE(v["bit_identical"].get<bool>()) << "the built-in provider is deterministic";
  }

  const std::string pole = "thin-pole_full_48x32_e64.0mm_c2m";
  const std::string box = "box-wall_full_64x36_e64.0mm_c4.08m";
  const std::string box_date = store.provenance(box)["date"];
  const auto box_time = fs::last_write_time(dir / "store" / box / "provenance.json");
  damage(dir / "store" / pole / "right.exr");
  const test::CliRun bad = test::run_cli(ref(dir, "verify") + " --no-render");
  EXPECT_EQ(bad.code, 2) << bad.out;
  EXPECT_NE(bad.out.find("corrupt"), std::string::npos) << bad.out;
  EXPECT_NE(bad.out.find(pole), std::string::npos) << bad.out;

  const test::CliRun upd = test::run_cli(ref(dir, "update") + " --only-failing");
  EXPECT_EQ(upd.code, 0) << upd.out;
  EXPECT_NE(upd.out.find("1 reference(s) rewritten"), std::string::npos) << upd.out;
  EXPECT_EQ(fs::last_write_time(dir / "store" / box / "provenance.json"), box_time) << "a passing reference was rewritten";
  EXPECT_EQ(store.provenance(box)["date"], box_date);
  EXPECT_EQ(test::run_cli(ref(dir, "verify")).code, 0);

  // An entry named twice is refused (it was checked twice, "2 of 2 verified").
  const test::CliRun twice = test::run_cli(ref(dir, "verify") + " --no-render " + box + " " + box);
  EXPECT_EQ(twice.code, 3) << twice.out;
  EXPECT_NE(twice.out.find("reference '" + box + "' is named twice"), std::string::npos) << twice.out;
  // A file given as the store is bad input (exit 3), not an I/O failure.
  std::ofstream(dir / "a-file") << "x";
  const test::CliRun file = test::run_cli("reference generate --store " + quoted(dir / "a-file") + " --scenes-dir " +
                                          quoted(kScenes) + " --scene box-wall --resolution 32x18");
  EXPECT_EQ(file.code, 3) << file.out;
  EXPECT_NE(file.out.find("is a file, not a folder"), std::string::npos) << file.out;
}

TEST(ReferenceStore, DamagedProvenanceIsAFindingNotAStop) {
  test::ScratchDir dir;
  ASSERT_EQ(test::run_cli(ref(dir, "generate") + " --scene box-wall --resolution 64x36").code, 0);
  ASSERT_EQ(test::run_cli(ref(dir, "generate") + " --scene thin-pole --resolution 48x32").code, 0);
  const std::string box = "box-wall_full_64x36_e64.0mm_c4.08m";
  const std::string pole = "thin-pole_full_48x32_e64.0mm_c2m";
  // The first entry's provenance is not JSON; the second records a rig of the wrong type.
  std::ofstream(dir / "store" / box / "provenance.json", std::ios::trunc) << "{\"kind\": \"stereobench.ref";
  json p = json::parse(test::read_text(dir / "store" / pole / "provenance.json"));
  p["rig"] = "wide";
  std::ofstream(dir / "store" / pole / "provenance.json", std::ios::trunc) << p.dump(2);

  // The listing stays whole, the damaged entry flagged (it used to stop at the first).
  const test::CliRun list = test::run_cli(ref(dir, "list"));
  EXPECT_EQ(list.code, 0) << list.out;
  EXPECT_NE(list.out.find("damaged: " + (dir / "store" / box / "provenance.json").string() + " is not valid JSON"),
            std::string::npos)
      << list.out;
  EXPECT_NE(list.out.find(pole), std::string::npos) << list.out;
  EXPECT_NE(list.out.find("1 of 2 reference(s) damaged"), std::string::npos) << list.out;

  const test::CliRun r = test::run_cli(ref(dir, "verify") + " --no-render");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("corrupt        " + box), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("is not valid JSON"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("reference generate"), std::string::npos) << "update cannot rewrite it: " << r.out;
  EXPECT_NE(r.out.find("corrupt        " + pole), std::string::npos) << "verification went on past the first: " << r.out;
  EXPECT_NE(r.out.find("the recorded rig \"wide\" is not a rig record"), std::string::npos) << r.out;
  // The summary sends the entry whose spec is readable to update and the other to generate.
  // The command given runs on this store with this scenes folder, as typed.
  EXPECT_NE(r.out.find("0 of 2 reference(s) verified; 1 did not (rewrite them with `stereobench reference update "
                       "--only-failing --store " + shell_quote((dir / "store").string()) + " --scenes-dir " +
                       shell_quote(kScenes.string()) + "`); 1 lost their spec with their provenance"),
            std::string::npos)
      << r.out;

  // An id the store does not hold is named as such, not as an entry without a spec.
  for (const char* sub : {"update", "verify --no-render"}) {
    const test::CliRun typo = test::run_cli(ref(dir, sub) + " nosuch");
    EXPECT_EQ(typo.code, 3) << typo.out;
    EXPECT_NE(typo.out.find("no reference 'nosuch' in " + (dir / "store").string() + " (it holds 2 references); run "
                            "`stereobench reference list`"),
              std::string::npos)
        << sub << ": " << typo.out;
  }

  // Updating the failing entries rewrites the one whose spec is readable and names the other.
  const test::CliRun upd = test::run_cli(ref(dir, "update") + " --only-failing");
  EXPECT_EQ(upd.code, 3) << upd.out;
  EXPECT_NE(upd.out.find("1 reference(s) rewritten"), std::string::npos) << upd.out;
  EXPECT_NE(upd.out.find("1 reference(s) could not be rewritten"), std::string::npos) << upd.out;
  EXPECT_NE(upd.out.find(box + " ("), std::string::npos) << upd.out;
  EXPECT_TRUE(json::parse(test::read_text(dir / "store" / pole / "provenance.json"))["rig"].is_object());

  // A provenance naming no provider is corrupt, found by the verification (it used to stop it).
  json unknown = json::parse(test::read_text(dir / "store" / pole / "provenance.json"));
  unknown["spec"]["provider"] = "nope";
  std::ofstream(dir / "store" / pole / "provenance.json", std::ios::trunc) << unknown.dump(2);
  const test::CliRun nope = test::run_cli(ref(dir, "verify") + " --no-render " + pole);
  EXPECT_EQ(nope.code, 2) << nope.out;
  EXPECT_NE(nope.out.find("corrupt        " + pole), std::string::npos) << nope.out;
  EXPECT_NE(nope.out.find("spec.provider 'nope' is not a ground-truth provider"), std::string::npos) << nope.out;
  // One without a spec at all says so and what to do (it showed the JSON library's out-of-range text).
  std::ofstream(dir / "store" / pole / "provenance.json", std::ios::trunc) << "{}\n";
  const test::CliRun bare = test::run_cli(ref(dir, "verify") + " --no-render " + pole);
  EXPECT_EQ(bare.code, 2) << bare.out;
  EXPECT_NE(bare.out.find("provenance.json: has no field 'spec'"), std::string::npos) << bare.out;
  EXPECT_EQ(bare.out.find("json.exception"), std::string::npos) << bare.out;
  unknown["spec"]["provider"] = "nope";
  std::ofstream(dir / "store" / pole / "provenance.json", std::ios::trunc) << unknown.dump(2);

  // The verdicts are not written into the store, where they could replace a reference's files.
  const test::CliRun inside = test::run_cli(ref(dir, "verify") + " --no-render --json " +
                                            quoted(dir / "store" / pole / "provenance.json"));
  EXPECT_EQ(inside.code, 3) << inside.out;
  EXPECT_NE(inside.out.find("lies inside the reference store"), std::string::npos) << inside.out;
  EXPECT_EQ(json::parse(test::read_text(dir / "store" / pole / "provenance.json"))["spec"]["provider"], "nope");

  // update renders what it rewrites: --no-render belongs with --only-failing.
  const test::CliRun render_less = test::run_cli(ref(dir, "update") + " --no-render " + pole);
  EXPECT_EQ(render_less.code, 3) << render_less.out;
  EXPECT_NE(render_less.out.find("--no-render only shapes the check of --only-failing"), std::string::npos)
      << render_less.out;

  // A store that is missing or a file is named as such by every command, not taken as empty.
  const std::pair<fs::path, const char*> stores[] = {{dir / "nostore", "does not exist"},
                                                     {dir / "store" / pole / "provenance.json", "is not a folder"}};
  for (const auto& [store, why] : stores)
    for (const char* command : {"list", "verify", "update"}) {
      const test::CliRun none = test::run_cli(fmt::format("reference {} --store {}", command, quoted(store)));
      EXPECT_EQ(none.code, 3) << none.out;
      EXPECT_NE(none.out.find("the reference store " + store.string() + " " + why), std::string::npos)
          << command << ": " << none.out;
    }

  const test::CliRun negative = test::run_cli(ref(dir, "verify") + " --min-psnr -1");
  EXPECT_EQ(negative.code, 3) << negative.out;
  EXPECT_NE(negative.out.find("--min-psnr -1 is not a PSNR in dB"), std::string::npos) << negative.out;
}

TEST(ReferenceStore, VerifyOnlyReadsTheStoreAndLeavesNoEarlierVerdicts) {
  test::ScratchDir dir;
  ASSERT_EQ(test::run_cli(ref(dir, "generate") + " --scene box-wall --resolution 32x18 --threads 1").code, 0);
  const std::string box = "box-wall_full_32x18_e64.0mm_c4.08m";
  // Rendering again writes nothing into the store (it made its scratch folder there, so a
  // read-only store could not be verified): the folder's modification time stays, and the
  // scratch folder is the temporary folder's.
  const auto store_time = fs::last_write_time(dir / "store");
  const test::CliRun ok = test::run_cli(ref(dir, "verify") + " --json " + quoted(dir / "v.json"));
  EXPECT_EQ(ok.code, 0) << ok.out;
  EXPECT_EQ(fs::last_write_time(dir / "store"), store_time) << "verify wrote into the store";
  std::ofstream(dir / "not-a-folder") << "x\n";
  ::setenv("TMPDIR", (dir / "not-a-folder").c_str(), 1);
  const test::CliRun no_tmp = test::run_cli(ref(dir, "verify"));
  ::unsetenv("TMPDIR");
  EXPECT_EQ(no_tmp.code, 4) << no_tmp.out;
  EXPECT_NE(no_tmp.out.find("cannot create a scratch folder"), std::string::npos) << no_tmp.out;
  EXPECT_NE(no_tmp.out.find("set TMPDIR to a folder you can write"), std::string::npos) << no_tmp.out;

  // A run that stops leaves no verdicts of an earlier run behind (CI would read them as its own).
  ASSERT_TRUE(fs::exists(dir / "v.json"));
  const test::CliRun typo = test::run_cli(ref(dir, "verify") + " --json " + quoted(dir / "v.json") + " nosuch");
  EXPECT_EQ(typo.code, 3) << typo.out;
  EXPECT_FALSE(fs::exists(dir / "v.json")) << "the earlier verdicts outlived a failed run";
  // A --json that cannot be written is refused before anything is rendered again.
  const test::CliRun blocked =
      test::run_cli(ref(dir, "verify") + " --json " + quoted(dir / "not-a-folder" / "v.json"));
  EXPECT_EQ(blocked.code, 4) << blocked.out;
  EXPECT_NE(blocked.out.find("--json"), std::string::npos) << blocked.out;
  EXPECT_EQ(blocked.out.find(box), std::string::npos) << "verified before the output was checked: " << blocked.out;

  // --min-psnr decides what --only-failing rewrites; without it, it would be ignored.
  const test::CliRun psnr = test::run_cli(ref(dir, "update") + " --min-psnr 30");
  EXPECT_EQ(psnr.code, 3) << psnr.out;
  EXPECT_NE(psnr.out.find("--min-psnr 30 only shapes the check of --only-failing"), std::string::npos) << psnr.out;
}

TEST(ReferenceStore, ImpossibleSpecValuesAndAnImageOfAnotherSizeAreCorrupt) {
  test::ScratchDir dir;
  ASSERT_EQ(test::run_cli(ref(dir, "generate") + " --scene box-wall --resolution 32x18 --threads 1").code, 0);
  ASSERT_EQ(test::run_cli(ref(dir, "generate") + " --scene thin-pole --resolution 48x32 --threads 1").code, 0);
  const std::string box = "box-wall_full_32x18_e64.0mm_c4.08m";
  const std::string pole = "thin-pole_full_48x32_e64.0mm_c2m";
  const fs::path prov = dir / "store" / box / "provenance.json";
  const std::string original = test::read_text(prov);
  // Values no command line gives: each is a damaged provenance naming the field (a negative width
  // was reported as a changed scene, whose advised update then failed; 32.7 was read as 32).
  // A negative interaxial, a zero convergence and a field of view beyond pi were "scene-changed".
  const std::pair<const char*, json> edits[] = {{"width", -32}, {"width", 32.7}, {"width", 4294967328.0},
                                                {"height", "18"}, {"convergence_m", "inf"}, {"interaxial_m", -1},
                                                {"convergence_m", 0}, {"vfov_rad", 100}};
  for (const auto& [field, value] : edits) {
    json p = json::parse(original);
    p["spec"]["rig_overrides"][field] = value;
    std::ofstream(prov, std::ios::trunc) << p.dump(2);
    const test::CliRun r = test::run_cli(ref(dir, "verify") + " --no-render " + box);
    EXPECT_EQ(r.code, 2) << field << " " << value << ": " << r.out;
    EXPECT_NE(r.out.find("corrupt        " + box), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(fmt::format("spec.rig_overrides.{} is {}", field, value.dump())), std::string::npos) << r.out;
  }
  json p = json::parse(original);
  p["spec"]["lights"] = 0;
  std::ofstream(prov, std::ios::trunc) << p.dump(2);
  const test::CliRun lights = test::run_cli(ref(dir, "verify") + " --no-render " + box);
  EXPECT_EQ(lights.code, 2) << lights.out;
  EXPECT_NE(lights.out.find("spec.lights is 0, not a whole number"), std::string::npos) << lights.out;
  // A spec that is no object, and a provenance version this stereobench does not write.
  for (const auto& [field, value, said] :
       {std::tuple<const char*, json, const char*>{"spec", nullptr, "field 'spec' is null, not an object"},
        {"version", 2, "version 2 is not the provenance version this stereobench writes and reads (1)"}}) {
    json q = json::parse(original);
    q[field] = value;
    std::ofstream(prov, std::ios::trunc) << q.dump(2);
    const test::CliRun r = test::run_cli(ref(dir, "verify") + " --no-render " + box);
    EXPECT_EQ(r.code, 2) << field << ": " << r.out;
    EXPECT_NE(r.out.find(said), std::string::npos) << r.out;
  }
  std::ofstream(prov, std::ios::trunc) << original;

  // Another entry's image with its hash recorded: the hash holds, the size does not (it stopped
  // the whole verification with a message about resizing images).
  fs::copy_file(dir / "store" / pole / "right.exr", dir / "store" / box / "right.exr",
                fs::copy_options::overwrite_existing);
  json swapped = json::parse(original);
  swapped["image"]["sha256"] = json::parse(test::read_text(dir / "store" / pole / "provenance.json"))["image"]["sha256"];
  std::ofstream(prov, std::ios::trunc) << swapped.dump(2);
  test::CliRun r = test::run_cli(ref(dir, "verify"));
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("right.exr is 48x32, but its rig renders 32x18"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("ok             " + pole), std::string::npos) << "the verification went on: " << r.out;
  // A file that is no EXR at all, with its own hash recorded.
  std::ofstream(dir / "store" / box / "right.exr", std::ios::trunc | std::ios::binary) << "not an image\n";
  const test::CliRun sum = test::run_shell("sha256sum " + quoted(dir / "store" / box / "right.exr"));
  ASSERT_EQ(sum.code, 0) << sum.out;
  swapped["image"]["sha256"] = sum.out.substr(0, 64);
  std::ofstream(prov, std::ios::trunc) << swapped.dump(2);
  r = test::run_cli(ref(dir, "verify") + " --no-render");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("corrupt        " + box), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("right.exr cannot be read"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("ok             " + pole), std::string::npos) << r.out;
}

TEST(ReferenceStore, AnEntryThatContradictsItsFolderIsCorrupt) {
  test::ScratchDir dir;
  ASSERT_EQ(test::run_cli(ref(dir, "generate") + " --scene box-wall --resolution 64x36").code, 0);
  ASSERT_EQ(test::run_cli(ref(dir, "generate") + " --scene thin-pole --resolution 48x32").code, 0);
  const fs::path store = dir / "store";
  const std::string box = "box-wall_full_64x36_e64.0mm_c4.08m";
  const std::string pole = "thin-pole_full_48x32_e64.0mm_c2m";
  const json original = json::parse(test::read_text(store / pole / "provenance.json"));
  const auto verify_all = [&] { return test::run_cli(ref(dir, "verify") + " --no-render"); };
  const auto expect_corrupt = [&](const test::CliRun& r, const std::string& why) {
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find("corrupt        " + pole), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(why), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("1 of 2 reference(s) verified"), std::string::npos) << r.out;
  };

  // An entry whose provenance is gone is still an entry: reported, never passed over.
  fs::rename(store / pole / "provenance.json", dir / "kept.json");
  expect_corrupt(verify_all(), (store / pole / "provenance.json").string() + " is missing");
  const test::CliRun list = test::run_cli(ref(dir, "list"));
  EXPECT_NE(list.out.find("2 reference(s)"), std::string::npos) << list.out;
  EXPECT_NE(list.out.find("1 of 2 reference(s) damaged"), std::string::npos) << list.out;
  fs::rename(dir / "kept.json", store / pole / "provenance.json");

  // A path, or "." / "..", is no id: not taken for a (damaged) entry of the store.
  for (const char* not_an_id : {"..", ".", "../store", "a/b"}) {
    const test::CliRun r = test::run_cli(ref(dir, "verify") + " --no-render " + quoted(not_an_id));
    EXPECT_EQ(r.code, 3) << not_an_id << ": " << r.out;
    EXPECT_NE(r.out.find("is not a reference id"), std::string::npos) << r.out;
  }

  // Fields that contradict the folder, the stored image or the spec.
  const std::pair<const char*, std::pair<json, const char*>> edits[] = {
      {"id", {box, "it records id 'box-wall_full_64x36_e64.0mm_c4.08m' but lies in folder"}},
      {"image", {json{{"file", "../../elsewhere.exr"}}, "it names image file '../../elsewhere.exr'"}},
      {"provider", {json{{"name", "nope"}}, "provider.name 'nope' is not its spec's provider 'full'"}},
      {"kind", {json("whatever"), "its kind is 'whatever', not 'stereobench.reference'"}},
  };
  for (const auto& [key, edit] : edits) {
    json p = original;
    if (edit.first.is_object()) {
      p[key].update(edit.first);
    } else {
      p[key] = edit.first;
    }
    std::ofstream(store / pole / "provenance.json", std::ios::trunc) << p.dump(2);
    expect_corrupt(verify_all(), edit.second);
  }

  // The preview people look at must show the stored image: repainted, or gone, it is corrupt.
  std::ofstream(store / pole / "provenance.json", std::ios::trunc) << original.dump(2);
  const fs::path preview = store / pole / "right.png";
  fs::copy_file(preview, dir / "preview.png");
  {
    std::vector<uint8_t> red(48 * 32 * 3, 0);
    for (size_t i = 0; i < red.size(); i += 3) red[i] = 255;
    io::write_png_rgb8(preview, red, 48, 32);
  }
  expect_corrupt(verify_all(), preview.string() + " does not show");
  fs::remove(preview);
  expect_corrupt(verify_all(), "the preview cannot be read");
  fs::copy_file(dir / "preview.png", preview);
  EXPECT_EQ(verify_all().code, 0);

  // A folder renamed away from the id its spec gives, provenance edited to match.
  const std::string renamed = "thin-pole_full_renamed";
  fs::rename(store / pole, store / renamed);
  json moved = original;
  moved["id"] = renamed;
  std::ofstream(store / renamed / "provenance.json", std::ios::trunc) << moved.dump(2);
  const test::CliRun r = test::run_cli(ref(dir, "verify") + " --no-render " + renamed);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("its spec makes the reference '" + pole + "' (the id names the scene file"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("but the entry lies in folder '" + renamed + "'; `stereobench reference update " + renamed +
                       " --store " + shell_quote(store.string()) + " --scenes-dir " + shell_quote(kScenes.string()) +
                       "` writes it"),
            std::string::npos)
      << r.out;
  // update writes that reference under its own id and says that the folder stays as it was,
  // instead of reporting it mended.
  fs::remove_all(store / pole);
  const test::CliRun update = test::run_cli(ref(dir, "update") + " --only-failing --no-render");
  EXPECT_EQ(update.code, 3) << update.out;
  EXPECT_NE(update.out.find("not named by the id their spec makes"), std::string::npos) << update.out;
  EXPECT_NE(update.out.find(renamed + " (its spec's reference was written to " + pole + ")"), std::string::npos)
      << update.out;
  EXPECT_TRUE(fs::exists(store / pole / "provenance.json"));
}

TEST(ReferenceStore, SceneFileNamesGiveVisibleFoldersAndAMissingSceneDoesNotStopAnUpdate) {
  // The scene file's stem goes into the id as a folder name of the store itself: never a hidden
  // folder (listed by nothing) or a name too long for the file system. The name inside the file
  // plays no part: Blender names every scene "Scene", and two such files would share one id.
  test::ScratchDir dir;
  const json original = json::parse(test::read_text(scenes::resolve_scene("box-wall", kScenes)));
  const std::pair<std::string, std::string> names[] = {
      {".hidden", "_hidden_full_"},
      {"two words", "two_words_full_"},
      {std::string(200, 'n'), std::string(64, 'n') + "_full_"},
      {"kitchen", "kitchen_full_"},
      {"office", "office_full_"},
  };
  const std::string args = " --resolution 16x9 --threads 1";
  for (const auto& [stem, start] : names) {
    json scene = original;
    scene["scenes"][0]["name"] = "Scene";
    const fs::path file = dir / (stem + ".gltf");
    std::ofstream(file) << scene.dump();
    const test::CliRun r = test::run_cli(ref(dir, "generate") + " --scene " + quoted(file) + args);
    EXPECT_EQ(r.code, 0) << stem << ": " << r.out;
  }
  const ReferenceStore store(dir / "store");
  const std::vector<std::string> ids = store.ids();
  ASSERT_EQ(ids.size(), std::size(names)) << fmt::format("{}", fmt::join(ids, ", "));
  for (const auto& [stem, start] : names)
    EXPECT_TRUE(std::any_of(ids.begin(), ids.end(), [&](const std::string& id) { return id.starts_with(start); }))
        << start;

  // One entry's scene file gone: the others are still rewritten, and the run names that one.
  fs::remove(dir / ".hidden.gltf");
  const test::CliRun update = test::run_cli(ref(dir, "update"));
  EXPECT_EQ(update.code, 3) << update.out;
  EXPECT_NE(update.out.find(fmt::format("{} reference(s) rewritten", std::size(names) - 1)), std::string::npos)
      << update.out;
  EXPECT_NE(update.out.find("1 reference(s) could not be rendered again from their spec"), std::string::npos)
      << update.out;
  EXPECT_NE(update.out.find("_hidden_full_"), std::string::npos) << update.out;
}

TEST(ReferenceStore, AnotherSceneOfTheSameNameDoesNotReplaceAnEntry) {
  test::ScratchDir dir;
  // A copy of box-wall as a file of its own in another folder: the same file name, hence the same id.
  fs::create_directories(dir / "mine");
  const fs::path copy = dir / "mine" / "box-wall.gltf";
  fs::copy_file(scenes::resolve_scene("box-wall", kScenes), copy);
  const std::string args = " --resolution 32x18 --threads 1";
  ASSERT_EQ(test::run_cli(ref(dir, "generate") + " --scene " + quoted(copy) + args).code, 0);
  const ReferenceStore store(dir / "store");
  ASSERT_EQ(store.ids().size(), 1u);
  const std::string id = store.ids()[0];
  EXPECT_EQ(store.spec_of(id).scene, recorded(copy)) << "a file is recorded by its absolute path";
  const std::string before = test::read_text(dir / "store" / id / "provenance.json");
  const test::CliRun other = test::run_cli(ref(dir, "generate") + " --scene box-wall" + args);
  EXPECT_EQ(other.code, 3) << other.out;
  EXPECT_NE(other.out.find("reference '" + id + "' in " + (dir / "store").string() + " was made from scene " +
                           recorded(copy) + ", not box-wall"),
            std::string::npos)
      << other.out;
  EXPECT_EQ(test::read_text(dir / "store" / id / "provenance.json"), before);
  // The same scene again replaces its entry, as `reference update` does.
  EXPECT_EQ(test::run_cli(ref(dir, "generate") + " --scene " + quoted(copy) + args).code, 0);
  EXPECT_EQ(store.ids().size(), 1u);
}

TEST(ReferenceStore, AProjectMovedWithItsStoreAndScenesStillVerifies) {
  // A store committed beside its scene files is checked out elsewhere: the entry finds its scene
  // by the path relative to the store (it knew only the absolute one, which no longer exists, and
  // neither verify nor update could mend it).
  test::ScratchDir dir;
  const fs::path project = dir / "projA";
  fs::create_directories(project / "scenes");
  fs::copy_file(scenes::resolve_scene("box-wall", kScenes), project / "scenes" / "mybox.gltf");
  const std::string generate = "cd " + quoted(project) + " && " + SB_CLI_PATH +
                               " reference generate --store refs --scene scenes/mybox.gltf --resolution 32x18 "
                               "--threads 1";
  ASSERT_EQ(test::run_shell(generate).code, 0);
  const ReferenceStore before(project / "refs");
  ASSERT_EQ(before.ids().size(), 1u);
  const std::string id = before.ids()[0];
  const json spec = json::parse(test::read_text(project / "refs" / id / "provenance.json"))["spec"];
  EXPECT_EQ(spec["scene"], recorded(project / "scenes" / "mybox.gltf"));
  EXPECT_EQ(spec["scene_from_store"], "../scenes/mybox.gltf");
  fs::rename(project, dir / "projB");
  const std::string verify = "cd " + quoted(dir / "projB") + " && " + SB_CLI_PATH + " reference verify --store refs";
  const test::CliRun moved = test::run_shell(verify);
  EXPECT_EQ(moved.code, 0) << moved.out;
  EXPECT_NE(moved.out.find("1 of 1 reference(s) verified"), std::string::npos) << moved.out;
  EXPECT_EQ(ReferenceStore(dir / "projB" / "refs").spec_of(id).scene, recorded(dir / "projB" / "scenes" / "mybox.gltf"));
  // The store moved alone still finds the scene by its absolute path.
  fs::rename(dir / "projB" / "refs", dir / "refs");
  fs::rename(dir / "projB", project);
  const test::CliRun alone = test::run_cli("reference verify --store " + quoted(dir / "refs"));
  EXPECT_EQ(alone.code, 0) << alone.out;
}

TEST(ReferenceStore, AScenePathIsRecordedWithItsLinksResolvedAndInUtf8) {
  test::ScratchDir dir;
  fs::create_directories(dir / "sc" / "sub");
  fs::copy_file(scenes::resolve_scene("box-wall", kScenes), dir / "sc" / "mybox.gltf");
  fs::create_directory_symlink(dir / "sc" / "sub", dir / "deep");
  const std::string args = " --resolution 32x18 --threads 1";
  // "deep/../mybox.gltf" is sc/mybox.gltf (deep links to sc/sub); it was taken as the file beside
  // deep, which does not exist.
  const test::CliRun linked = test::run_cli(ref(dir, "generate") + " --scene " + quoted(dir / "deep" / ".." / "mybox.gltf") + args);
  ASSERT_EQ(linked.code, 0) << linked.out;
  const ReferenceStore store(dir / "store");
  ASSERT_EQ(store.ids().size(), 1u);
  EXPECT_EQ(store.spec_of(store.ids()[0]).scene, recorded(dir / "sc" / "mybox.gltf"));
  EXPECT_EQ(test::run_cli(ref(dir, "verify")).code, 0);
  // A linked scene file keeps its own name (the id's) and its place (its buffers lie beside it):
  // only its folders' links are resolved.
  fs::create_symlink(dir / "sc" / "mybox.gltf", dir / "sc" / "linked.gltf");
  const test::CliRun link = test::run_cli(ref(dir, "generate") + " --scene " + quoted(dir / "sc" / "linked.gltf") + args);
  ASSERT_EQ(link.code, 0) << link.out;
  ASSERT_EQ(store.ids().size(), 2u);
  EXPECT_EQ(store.ids()[0].rfind("linked_full_", 0), 0u) << store.ids()[0];
  EXPECT_EQ(store.spec_of(store.ids()[0]).scene, recorded(dir / "sc" / "linked.gltf"));
  // A path that is not UTF-8 is refused: the provenance recorded it with U+FFFD in place of the
  // byte, and the entry could then never be verified.
  const fs::path odd = dir / "b\xffx.gltf";
  fs::copy_file(dir / "sc" / "mybox.gltf", odd);
  const test::CliRun refused = test::run_cli(ref(dir, "generate") + " --scene " + quoted(odd) + args);
  EXPECT_EQ(refused.code, 3) << refused.out;
  EXPECT_NE(refused.out.find("is not valid UTF-8, and the provenance (JSON) could not record it"), std::string::npos)
      << refused.out;
  EXPECT_EQ(store.ids().size(), 2u);
}

TEST(ReferenceStore, AFieldOfViewTheSceneCameraComesToShareKeepsItsEntryValid) {
  // The id names a field of view other than the scene camera's. Given as 50 degrees and the
  // camera's changed to 50 since, rig and image are as recorded: the entry was called corrupt.
  test::ScratchDir dir;
  const fs::path scene = dir / "fov.gltf";
  fs::copy_file(scenes::resolve_scene("box-wall", kScenes), scene);
  ASSERT_EQ(test::run_cli(ref(dir, "generate") + " --scene " + quoted(scene) + " --resolution 32x18 --vfov 50").code, 0);
  const ReferenceStore store(dir / "store");
  ASSERT_EQ(store.ids().size(), 1u);
  EXPECT_NE(store.ids()[0].find("_v50deg"), std::string::npos) << store.ids()[0];
  json gltf = json::parse(test::read_text(scene));
  ASSERT_TRUE(gltf["cameras"][0]["perspective"].contains("yfov"));
  gltf["cameras"][0]["perspective"]["yfov"] = 50.0 * 3.141592653589793 / 180.0;
  std::ofstream(scene, std::ios::trunc) << gltf.dump(2);
  const test::CliRun r = test::run_cli(ref(dir, "verify"));
  EXPECT_EQ(r.code, 0) << r.out;
  // The same spec generated or updated again goes into that entry, not a second one beside it.
  const std::string id = store.ids()[0];
  EXPECT_EQ(test::run_cli(ref(dir, "generate") + " --scene " + quoted(scene) + " --resolution 32x18 --vfov 50").code, 0);
  const test::CliRun updated = test::run_cli(ref(dir, "update") + " " + id);
  EXPECT_EQ(updated.code, 0) << updated.out;
  EXPECT_EQ(store.ids(), std::vector<std::string>{id});
}

TEST(ReferenceStore, AnotherRigDoesNotReplaceAnEntry) {
  test::ScratchDir dir;
  const std::string args = " --scene box-wall --resolution 32x18 --threads 1";
  ASSERT_EQ(test::run_cli(ref(dir, "generate") + args).code, 0);
  const ReferenceStore store(dir / "store");
  const std::string id = "box-wall_full_32x18_e64.0mm_c4.08m";
  ASSERT_EQ(store.ids(), std::vector<std::string>{id});
  const std::string before = test::read_text(dir / "store" / id / "provenance.json");
  // Another field of view is another reference, beside the first.
  ASSERT_EQ(test::run_cli(ref(dir, "generate") + args + " --vfov 60").code, 0);
  EXPECT_EQ(store.ids(), (std::vector<std::string>{id, "box-wall_full_32x18_e64.0mm_c4.08m_v60deg"}));
  // An interaxial or convergence the id rounds to the same text is refused, the entry kept.
  // The message names the field that differs (it showed both records cut at 120 characters).
  for (const auto& [rig, field] : {std::pair{" --interaxial 0.06404", "(interaxial_m: recorded 0.064, now 0.06404;"},
                                   std::pair{" --convergence 4.081", "(convergence_m: recorded 4.079"}}) {
    const test::CliRun other = test::run_cli(ref(dir, "generate") + args + rig);
    EXPECT_EQ(other.code, 3) << rig << ": " << other.out;
    EXPECT_NE(other.out.find("reference '" + id + "' in " + (dir / "store").string() + " was made with another rig " +
                             field),
              std::string::npos)
        << other.out;
  }
  EXPECT_EQ(test::read_text(dir / "store" / id / "provenance.json"), before);
  // The default interaxial given explicitly is the same rig: the entry is made again.
  EXPECT_EQ(test::run_cli(ref(dir, "generate") + args + " --interaxial 0.064").code, 0);
  EXPECT_EQ(store.ids().size(), 2u);
  // So is the scene's own light count (box-wall has one): it made a second entry "..._l1".
  const test::CliRun all_lights = test::run_cli(ref(dir, "generate") + args + " --lights 1");
  EXPECT_EQ(all_lights.code, 0) << all_lights.out;
  EXPECT_EQ(store.ids().size(), 2u);
  const test::CliRun verified = test::run_cli(ref(dir, "verify") + " --no-render");
  EXPECT_EQ(verified.code, 0) << verified.out;
}

TEST(ReferenceStore, WorkingFoldersOfAKilledRunAreClearedUp) {
  test::ScratchDir dir;
  const std::string args = " --resolution 32x18 --threads 1";
  ASSERT_EQ(test::run_cli(ref(dir, "generate") + " --scene box-wall" + args).code, 0);
  ASSERT_EQ(test::run_cli(ref(dir, "generate") + " --scene thin-pole" + args).code, 0);
  const fs::path store = dir / "store";
  const std::string pole = "thin-pole_full_32x18_e64.0mm_c2m";
  // What generates and verifies killed mid-way leave: working folders, one still held by a running
  // process (locked here), and an entry moved aside whose new version never took its place; and
  // hidden folders of other kinds, which are not the store's to remove.
  fs::rename(store / pole, store / ("." + pole + ".old-4245-Zz09aB"));
  for (const char* name : {".a_full_32x18.new-4242-abcdef", ".a_full_32x18.verify-4244-ABCDEF",
                           ".b_full_32x18.new-77-xyzXYZ", ".notes", ".backup.old-2024"})
    fs::create_directories(store / name / "work");
  const int held = ::open((store / ".b_full_32x18.new-77-xyzXYZ").c_str(), O_RDONLY | O_DIRECTORY);
  ASSERT_GE(held, 0);
  ASSERT_EQ(::flock(held, LOCK_EX | LOCK_NB), 0);
  // An id's lock file left by a killed generate, and one a running generate holds.
  std::ofstream(store / ".a_full_32x18.lock").flush();
  std::ofstream(store / ".b_full_32x18.lock").flush();
  const int held_lock = ::open((store / ".b_full_32x18.lock").c_str(), O_RDWR);
  ASSERT_GE(held_lock, 0);
  ASSERT_EQ(::flock(held_lock, LOCK_EX | LOCK_NB), 0);
  // Replacing an entry swaps it with the new one, and clears up first.
  ASSERT_EQ(test::run_cli(ref(dir, "generate") + " --scene box-wall" + args).code, 0);
  ::close(held);
  ::close(held_lock);
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(store)) left.push_back(e.path().filename().string());
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{".b_full_32x18.lock", ".b_full_32x18.new-77-xyzXYZ", ".backup.old-2024", ".notes",
                                            "box-wall_full_32x18_e64.0mm_c4.08m", pole}));
  const test::CliRun verify = test::run_cli(ref(dir, "verify"));
  EXPECT_EQ(verify.code, 0) << verify.out;
  EXPECT_NE(verify.out.find("ok             " + pole), std::string::npos) << "moved back whole: " << verify.out;
}

TEST(ReferenceStore, ChangedSceneIsReported) {
  test::ScratchDir dir;
  // A scene file of our own, changed after the reference was made.
  const fs::path scene = dir / "plane.gltf";
  fs::copy_file(scenes::resolve_scene("lit-plane", kScenes), scene);
  ASSERT_EQ(test::run_cli(ref(dir, "generate") + " --scene " + quoted(scene) + " --resolution 32x18").code, 0);
  const std::string original = test::read_text(scene);
  // A moved camera: the scene hash holds, the rig does not, and the field that moved is named.
  json moved = json::parse(original);
  for (json& node : moved["nodes"])
    if (node.contains("camera")) node["translation"] = {0.25, 0.0, 0.0};
  std::ofstream(scene, std::ios::binary | std::ios::trunc) << moved.dump();
  const test::CliRun camera = test::run_cli(ref(dir, "verify") + " --no-render");
  EXPECT_EQ(camera.code, 2) << camera.out;
  EXPECT_NE(camera.out.find("another rig than the recorded one (rig pose.position[0]: recorded 0"), std::string::npos)
      << camera.out;
  std::ofstream(scene, std::ios::binary | std::ios::trunc) << original;
  std::string text = original;
  const size_t at = text.find("\"intensity\"");
  ASSERT_NE(at, std::string::npos);
  const size_t colon = text.find(':', at);
  const size_t end = text.find_first_of(",}", colon);
  text.replace(colon + 1, end - colon - 1, "123.5");
  std::ofstream(scene, std::ios::binary | std::ios::trunc) << text;
  const test::CliRun r = test::run_cli(ref(dir, "verify"));
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("scene-changed"), std::string::npos) << r.out;
}

TEST(ReferenceStore, MissingToolIsUnavailableNotAPass) {
  test::ScratchDir dir;
  EXPECT_EQ(test::run_cli(ref(dir, "verify")).code, 3) << "an empty store is not a pass";
  EXPECT_EQ(test::run_cli(ref(dir, "generate") + " --scene box-wall --truth nosuchtool --resolution 32x18").code, 3);
  // A POV-Ray reference, then POV-Ray gone: generating is an error, verifying is "unavailable".
  const test::CliRun gen = test::run_cli(ref(dir, "generate") + " --scene box-wall --truth povray --resolution 32x18");
  ASSERT_EQ(gen.code, 0) << gen.out << "\n(POV-Ray is installed by ci/install-deps.sh povray)";
  ::setenv("STEREOBENCH_POVRAY", "/nonexistent/povray", 1);
  const test::CliRun again = test::run_cli(ref(dir, "generate") + " --scene box-wall --truth povray --resolution 32x18");
  const test::CliRun verify = test::run_cli(ref(dir, "verify"));
  ::unsetenv("STEREOBENCH_POVRAY");
  EXPECT_EQ(again.code, 4) << again.out;
  EXPECT_EQ(verify.code, 4) << verify.out;
  EXPECT_NE(verify.out.find("unavailable"), std::string::npos) << verify.out;
  EXPECT_NE(verify.out.find("0 of 1 reference(s) verified; 1 could not be checked here (their tool is missing"),
            std::string::npos)
      << verify.out;
  EXPECT_EQ(verify.out.find("update --only-failing"), std::string::npos) << "update cannot render without the tool";

  // Updating the failing entries rewrites those whose tool is here and names the others (it
  // stopped at the first it could not check and rewrote nothing).
  ASSERT_EQ(test::run_cli(ref(dir, "generate") + " --scene box-wall --resolution 32x18").code, 0);
  const std::string full = "box-wall_full_32x18_e64.0mm_c4.08m";
  damage(dir / "store" / full / "right.exr");
  ::setenv("STEREOBENCH_POVRAY", "/nonexistent/povray", 1);
  const test::CliRun update = test::run_cli(ref(dir, "update") + " --only-failing");
  ::unsetenv("STEREOBENCH_POVRAY");
  EXPECT_EQ(update.code, 4) << update.out;
  EXPECT_NE(update.out.find("1 reference(s) rewritten"), std::string::npos) << update.out;
  EXPECT_NE(update.out.find("1 reference(s) could not be checked, so not updated"), std::string::npos) << update.out;
  EXPECT_NE(update.out.find("box-wall_povray_32x18"), std::string::npos) << update.out;
  EXPECT_EQ(test::run_cli(ref(dir, "verify") + " " + full).code, 0) << "the damaged full entry was rewritten";
}


TEST(ReferenceStore, AFailingOrMissingToolIsNamedAndTheOtherEntriesAreStillHandled) {
  // A tool that is there but fails stopped verify at its entry, and a missing one stopped a plain
  // update: the entries after it were never checked or rewritten.
  test::ScratchDir dir;
  ASSERT_EQ(test::run_cli(ref(dir, "generate") + " --scene box-wall --truth povray --resolution 32x18").code, 0)
      << "(POV-Ray is installed by ci/install-deps.sh povray)";
  ASSERT_EQ(test::run_cli(ref(dir, "generate") + " --scene box-wall --resolution 32x18").code, 0);
  const std::string full = "box-wall_full_32x18_e64.0mm_c4.08m";
  const fs::path fake = dir / "fake-povray";
  std::ofstream(fake) << "#!/bin/sh\nif [ \"$1\" = --version ]; then echo 'POV-Ray 3.7.0.10'; exit 0; fi\n"
                         "echo 'Parse Error: the fake fails' >&2\nexit 1\n";
  fs::permissions(fake, fs::perms::owner_all);
  ::setenv("STEREOBENCH_POVRAY", fake.c_str(), 1);
  const test::CliRun verify = test::run_cli(ref(dir, "verify") + " --json " + quoted(dir / "verdicts.json"));
  ::unsetenv("STEREOBENCH_POVRAY");
  EXPECT_EQ(verify.code, 4) << verify.out;
  EXPECT_NE(verify.out.find("povray could not render it again here"), std::string::npos) << verify.out;
  EXPECT_NE(verify.out.find("Parse Error: the fake fails"), std::string::npos) << verify.out;
  EXPECT_NE(verify.out.find(full + ": a new render is bit-identical"), std::string::npos)
      << "the entry after it is still verified: " << verify.out;
  EXPECT_NE(verify.out.find("1 of 2 reference(s) verified; 1 could not be checked here"), std::string::npos)
      << verify.out;
  EXPECT_TRUE(fs::exists(dir / "verdicts.json")) << "the verdicts are written";

  const std::string full_provenance = test::read_text(dir / "store" / full / "provenance.json");
  ::setenv("STEREOBENCH_POVRAY", "/nonexistent/povray", 1);
  const test::CliRun update = test::run_cli(ref(dir, "update"));
  ::unsetenv("STEREOBENCH_POVRAY");
  EXPECT_EQ(update.code, 4) << update.out;
  EXPECT_NE(update.out.find("1 reference(s) rewritten"), std::string::npos) << update.out;
  EXPECT_NE(update.out.find("1 reference(s) could not be rewritten because their tool is missing or failed"),
            std::string::npos)
      << update.out;
  EXPECT_NE(test::read_text(dir / "store" / full / "provenance.json"), full_provenance)
      << "the full entry was rewritten (its provenance has the update's command line)";
}

TEST(ReferenceStore, WithoutMinPsnrAChangeBelowTheEightBitLevelFails) {
  // The stored image is linear float; a change that the 8-bit sRGB encoding does not show gave
  // PSNR inf and passed the default check, which demands identical images.
  test::ScratchDir dir;
  ASSERT_EQ(test::run_cli(ref(dir, "generate") + " --scene box-wall --resolution 32x18").code, 0);
  const std::string id = "box-wall_full_32x18_e64.0mm_c4.08m";
  const fs::path exr = dir / "store" / id / "right.exr";
  Image image = io::read_exr(exr);
  for (float& v : image.plane("rgb").f32()) v = std::nextafter(v, 2.0f * v + 1.0f);
  io::write_exr(exr, image);
  const test::CliRun sum = test::run_shell("sha256sum " + quoted(exr));
  ASSERT_EQ(sum.code, 0) << sum.out;
  json p = json::parse(test::read_text(dir / "store" / id / "provenance.json"));
  p["image"]["sha256"] = sum.out.substr(0, 64);
  std::ofstream(dir / "store" / id / "provenance.json", std::ios::trunc) << p.dump(2);
  const test::CliRun r = test::run_cli(ref(dir, "verify"));
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("a new render differs from the stored float image, though not in its 8-bit sRGB encoding"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(r.out.find("(-1, -1)"), std::string::npos) << "no position of a largest error that is none: " << r.out;
  EXPECT_EQ(test::run_cli(ref(dir, "verify") + " --min-psnr 60").code, 0) << "a tolerance accepts it";
  // The advice to rewrite a damaged preview names this store, not the default one, and the scenes
  // folder the run was given (it was left out, and the command then missed the scene).
  io::write_png_rgb8(dir / "store" / id / "right.png", std::vector<uint8_t>(32 * 18 * 3, 0), 32, 18);
  const test::CliRun preview = test::run_cli(ref(dir, "verify") + " --no-render");
  EXPECT_EQ(preview.code, 2) << preview.out;
  EXPECT_NE(preview.out.find("`stereobench reference update " + id + " --store " + shell_quote((dir / "store").string()) +
                             " --scenes-dir " + shell_quote(kScenes.string()) + "` writes it again"),
            std::string::npos)
      << preview.out;
  // Verdicts go to a file; '-' is not one.
  const test::CliRun dash = test::run_cli(ref(dir, "verify") + " --json -");
  EXPECT_EQ(dash.code, 3) << dash.out;
  EXPECT_NE(dash.out.find("--json -: reference verify writes its verdicts to a file"), std::string::npos) << dash.out;
  EXPECT_FALSE(fs::exists("-"));
}

TEST(ReferenceStore, AnotherRigGeneratedMeanwhileDoesNotReplaceAnEntry) {
  // Two generates of one id with different rigs at once: the check and the replacement are made
  // under the id's lock, held here. The second generate waits at it; the entry of the other rig
  // put in place meanwhile (as the generate holding the lock would) is then found and the waiting
  // one refused, as when it starts after (it used to pass the check and replace that entry).
  test::ScratchDir dir;
  const std::string args = " --scene box-wall --resolution 32x18 --threads 1";
  const std::string id = "box-wall_full_32x18_e64.0mm_c4.08m";
  ASSERT_EQ(test::run_cli("reference generate --store " + quoted(dir / "first") + " --scenes-dir " + quoted(kScenes) +
                          args)
                .code,
            0);
  ASSERT_TRUE(fs::is_directory(dir / "first" / id));
  fs::create_directories(dir / "store");
  const fs::path lock_file = dir / "store" / ("." + id + ".lock");
  {
    const io::FileLock held = io::FileLock::acquire(lock_file);
    test::start_cli_in_background(ref(dir, "generate") + args + " --interaxial 0.06404", dir / "second.log");
    ASSERT_TRUE(test::wait_for_lock_waiter(lock_file)) << test::read_text(dir / "second.log");
    fs::copy(dir / "first" / id, dir / "store" / id, fs::copy_options::recursive);
  }
  const test::CliRun second = test::wait_for_background(dir / "second.log");
  EXPECT_EQ(second.code, 3) << second.out;
  EXPECT_NE(second.out.find("reference '" + id + "' in " + (dir / "store").string() +
                            " was made with another rig (interaxial_m: recorded 0.064, now 0.06404;"),
            std::string::npos)
      << second.out;
  EXPECT_EQ(test::read_text(dir / "store" / id / "provenance.json"),
            test::read_text(dir / "first" / id / "provenance.json"))
      << "the entry made meanwhile is kept";
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(dir / "store")) left.push_back(e.path().filename().string());
  EXPECT_EQ(left, std::vector<std::string>{id}) << "the id's lock file goes with the generate";
}

}  // namespace
}  // namespace sb::reference
