// The corpus of broken scene files (support/bad_scene_corpus.hpp) through `stereobench scenes
// info`: exit code 3 and a message naming the fault. The library side is
// tests/loader/bad_scene_test.cpp.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "support/bad_scene_corpus.hpp"
#include "support/mini_gltf.hpp"
#include "support/run_cli.hpp"
#include "support/scratch_dir.hpp"

namespace sb {
namespace {

using test::bad_scene::add_camera;
using test::bad_scene::bad_scene_corpus;
using test::bad_scene::BadCase;
using test::MiniGltf;
using test::ScratchDir;
using test::bad_scene::write_case;

/// Runs `stereobench scenes info` on a scene file.
test::CliRun scene_info(const std::filesystem::path& scene) { return test::run_cli("scenes info '" + scene.string() + "'"); }

TEST(BadScenes, CommandLineExitsWithCode3AndNamesTheFault) {
  ScratchDir dir("badcli");
  for (const BadCase& bc : bad_scene_corpus()) {
    SCOPED_TRACE(bc.name);
    const auto [code, err] = scene_info(write_case(dir, bc));
    EXPECT_EQ(code, 3) << err;
    EXPECT_NE(err.find(bc.expect), std::string::npos) << err;
  }
}

TEST(BadScenes, RigExtrasOutOfRangeNameTheSceneAndTheirKeyAndOptionsTheirOption) {
  ScratchDir dir("rigextras");
  MiniGltf g;
  g.add_triangle();
  add_camera(g, {{"extras", {{"stereobench", {{"convergence", 1e-9}}}}}});
  const auto path = dir / "tiny.gltf";
  g.write_gltf(path);
  const auto [code, err] = scene_info(path);
  EXPECT_EQ(code, 3) << err;
  EXPECT_NE(err.find(path.string() + ": /nodes/1/extras/stereobench/convergence: the scene's rig: interaxial 0.064 m "
                                     "with convergence 1e-09 m gives a disparity at infinity of"),
            std::string::npos) << err;
  EXPECT_NE(err.find("fix it in the scene (in metres), or override it with --convergence"), std::string::npos) << err;
  // An option overrides the scene's value, and an option's own fault is worded as the option's.
  const auto overridden = test::run_cli("scenes info '" + path.string() + "' --convergence 2");
  EXPECT_EQ(overridden.code, 0) << overridden.out;
  const auto option = test::run_cli("scenes info '" + path.string() + "' --convergence 2 --interaxial 1e9");
  EXPECT_EQ(option.code, 3) << option.out;
  EXPECT_EQ(option.out.find("/extras/"), std::string::npos) << option.out;
  EXPECT_NE(option.out.find("interaxial 1e+09 m"), std::string::npos) << option.out;
  // With the scene's convergence and an option's interaxial, the option is at fault, not the scene.
  const auto mixed = test::run_cli("scenes info '" + path.string() + "' --interaxial 1e5");
  EXPECT_EQ(mixed.code, 3) << mixed.out;
  EXPECT_EQ(mixed.out.find("/extras/"), std::string::npos) << mixed.out;
  // Both values from the scene: both keys named.
  g.doc["nodes"][1]["extras"]["stereobench"]["interaxial"] = 0.07;
  g.write_gltf(path);
  const auto [both_code, both] = scene_info(path);
  EXPECT_EQ(both_code, 3) << both;
  EXPECT_NE(both.find("/nodes/1/extras/stereobench/interaxial and /nodes/1/extras/stereobench/convergence: the scene's "
                      "rig: interaxial 0.07 m with convergence 1e-09 m"),
            std::string::npos)
      << both;
}

TEST(BadScenes, NonExistentPathOnTheCommandLine) {
  ScratchDir dir("nopath");
  const auto [code, err] = scene_info(dir / "missing.gltf");
  EXPECT_EQ(code, 3);
  EXPECT_NE(err.find("does not exist"), std::string::npos) << err;
}

}  // namespace
}  // namespace sb
