// The command line: --version, --help with defaults, and bad arguments exiting with code 3 and a
// message that says what was wrong.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

#include "support/mini_gltf.hpp"
#include "support/scratch_dir.hpp"

namespace sb {
namespace {

struct CliRun {
  int code = -1;
  std::string out;  ///< stdout and stderr together
};

CliRun run(const std::string& args) {
  const std::string cmd = std::string(SB_CLI_PATH) + " " + args + " 2>&1";
  FILE* pipe = ::popen(cmd.c_str(), "r");
  CliRun r;
  std::array<char, 1024> buf{};
  while (pipe && std::fgets(buf.data(), buf.size(), pipe)) r.out += buf.data();
  const int status = pipe ? ::pclose(pipe) : -1;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
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
      {"scenes generate no-such-scene --out '" + dir.path().string() + "'", "unknown scene generator 'no-such-scene'"},
      {"scenes info " + scene + " --interaxial -0.064", "--interaxial -0.064 is not a positive finite number"},
      {"scenes info " + scene + " --interaxial 0", "--interaxial 0 is not a positive"},
      {"scenes info " + scene + " --interaxial nan", "--interaxial nan is not a positive"},
      {"scenes info " + scene + " --convergence 0", "--convergence 0 is not a positive"},
      {"scenes info " + scene + " --convergence inf", "--convergence inf is not a positive"},
      {"scenes info " + scene + " --max-disparity -3", "--max-disparity -3 is not a positive"},
      {"scenes info " + scene + " --resolution 0x100", "resolution 0x100 is out of range"},
      {"scenes info " + scene + " --resolution 16385x100", "resolution 16385x100 is out of range"},
      {"scenes info " + scene + " --resolution banana", "resolution 'banana' is not WIDTHxHEIGHT"},
      {"scenes info " + scene + " --vfov 180", "--vfov 180 is out of range"},
      {"scenes info " + scene + " --interaxial 0.06 --max-disparity 20", "excludes"},
      {"scenes info " + scene + " --interaxial abc", "--interaxial"},
      {"scenes generate spheres --param count=0 --out '" + dir.path().string() + "'", "count"},
      {"scenes generate spheres --param nonsense=1 --out '" + dir.path().string() + "'", "nonsense"},
      {"scenes generate spheres --param count=abc --out '" + dir.path().string() + "'", "not a finite number"},
      {"scenes generate --out '" + dir.path().string() + "'", "name the scenes"},
      {"scenes frobnicate", "frobnicate"},
      {"", "subcommand"},
  };
  for (const Case& c : cases) {
    const CliRun r = run(c.args);
    EXPECT_EQ(r.code, 3) << c.args << "\n" << r.out;
    EXPECT_NE(r.out.find(c.expect), std::string::npos) << c.args << "\nexpected: " << c.expect << "\ngot: " << r.out;
  }
}

TEST(Cli, SceneInfoPrintsRigAndDisparities) {
  test::ScratchDir dir("cliinfo");
  test::MiniGltf g;
  g.add_triangle();
  g.write_gltf(dir / "tri.gltf");
  const CliRun r = run("scenes info '" + (dir / "tri.gltf").string() + "' --resolution 640x360 --max-disparity 20 --convergence 2");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("1 triangles"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("640x360"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("max disparity 20.00 px"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace sb
