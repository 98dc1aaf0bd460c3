// A ground-truth tool that hangs is stopped at $STEREOBENCH_TOOL_TIMEOUT with a ToolError (exit
// code 4) that names the tool, the limit, the scene and the variable; stand-in executables that
// answer `--version` and then sleep play Blender and POV-Ray.
#include <gtest/gtest.h>

#include <signal.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "renderer/error.hpp"
#include "renderer/render_scene.hpp"
#include "scenes/catalog.hpp"
#include "support/render_support.hpp"
#include "support/run_cli.hpp"
#include "support/scoped_env.hpp"
#include "support/scratch_dir.hpp"
#include "validation/truth.hpp"

namespace sb {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using test::ScopedEnv;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// A stand-in executable: a shell script with the given body.
fs::path fake_tool(const test::ScratchDir& dir, const std::string& name, const std::string& body) {
  const fs::path p = dir / name;
  std::ofstream(p) << "#!/bin/sh\n" << body;
  fs::permissions(p, fs::perms::owner_all);
  return p;
}

/// POV-Ray 3.7 for `--version`, a render that prints a line and never ends otherwise.
const char* kHangingPovray =
    "if [ \"$1\" = --version ]; then echo 'POV-Ray 3.7.0.10'; exit 0; fi\n"
    "echo 'Parsing scene.pov'\nsleep 100\n";

/// Blender 3.4 for `--version`; a render that ignores SIGTERM, so that only SIGKILL stops it.
const char* kHangingBlender =
    "case \"$*\" in *--version*) echo 'Blender 3.4.1'; exit 0;; esac\n"
    "echo 'Read prefs'\ntrap '' TERM\nsleep 100\n";

fs::path builtin_file(const std::string& name) {
  return scenes::resolve_builtin(name, {}, fs::path(SB_BINARY_DIR) / "Testing" / "scenes-cache");
}

validation::TruthRender render_lit_plane(const validation::TruthProvider& provider, const fs::path& work_dir) {
  const fs::path file = builtin_file("lit-plane");
  const Scene scene = io::load_gltf(file);
  const RenderScene prepared(scene);
  const validation::TruthRequest request{prepared, file, test::rig_at(scene, 32, 18), work_dir, 1};
  return provider.render(request);
}

/// Renders the lit plane with `provider`, which must fail with a ToolError (exit code 4); checks
/// that the message holds each of `mentions` and returns the seconds the render took.
double expect_tool_error(const validation::TruthProvider& provider, const fs::path& work_dir,
                         const std::vector<std::string>& mentions) {
  EXPECT_FALSE(provider.unavailable_reason().has_value()) << *provider.unavailable_reason();
  const auto start = Clock::now();
  try {
    (void)render_lit_plane(provider, work_dir);
    ADD_FAILURE() << "the hanging " << provider.name() << " stand-in did not throw";
  } catch (const ToolError& e) {
    EXPECT_EQ(static_cast<int>(e.code()), 4);
    for (const std::string& m : mentions) EXPECT_NE(std::string(e.what()).find(m), std::string::npos) << m;
  }
  return seconds_since(start);
}

TEST(ToolTimeout, HangingPovrayIsStoppedWithAToolError) {
  const test::ScratchDir dir;
  const ScopedEnv exe("STEREOBENCH_POVRAY", fake_tool(dir, "fake-povray", kHangingPovray).string());
  const ScopedEnv limit("STEREOBENCH_TOOL_TIMEOUT", std::string("2"));
  const double seconds =
      expect_tool_error(*validation::make_truth_provider("povray"), dir / "work",
                        {"POV-Ray did not finish rendering", "within 2 s", (dir / "work" / "scene.pov").string(),
                         "STEREOBENCH_TOOL_TIMEOUT=<seconds>", "Parsing scene.pov" /* the output so far */});
  EXPECT_GE(seconds, 2.0);
  EXPECT_LT(seconds, 8.0) << "the limit is 2 s and SIGTERM stops the stand-in";
  EXPECT_EQ(test::read_text(dir / "work" / "povray.log"), "Parsing scene.pov\n");
}

TEST(ToolTimeout, HangingBlenderIgnoringSigtermIsKilled) {
  const test::ScratchDir dir;
  const ScopedEnv exe("STEREOBENCH_BLENDER", fake_tool(dir, "fake-blender", kHangingBlender).string());
  const ScopedEnv limit("STEREOBENCH_TOOL_TIMEOUT", std::string("1.5"));
  const double seconds = expect_tool_error(*validation::make_truth_provider("blender"), dir / "work",
                                           {"Blender 3.4.1 did not finish rendering", "within 1.5 s",
                                            builtin_file("lit-plane").string(), "STEREOBENCH_TOOL_TIMEOUT=1.5",
                                            "blender_render.py", "Read prefs"});
  EXPECT_GE(seconds, 3.5) << "1.5 s, then 2 s of grace before SIGKILL";
  EXPECT_LT(seconds, 9.0);
}

TEST(ToolTimeout, MalformedLimitIsAnInputErrorBeforeTheToolRuns) {
  const test::ScratchDir dir;
  const ScopedEnv exe("STEREOBENCH_POVRAY", fake_tool(dir, "fake-povray", kHangingPovray).string());
  const ScopedEnv limit("STEREOBENCH_TOOL_TIMEOUT", std::string("10 minutes"));
  const auto povray = validation::make_truth_provider("povray");
  const auto start = Clock::now();
  try {
    (void)render_lit_plane(*povray, dir / "work");
    ADD_FAILURE() << "a malformed limit was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(static_cast<int>(e.code()), 3);
    EXPECT_NE(std::string(e.what()).find("STEREOBENCH_TOOL_TIMEOUT='10 minutes'"), std::string::npos) << e.what();
  }
  EXPECT_LT(seconds_since(start), 5.0);
  EXPECT_FALSE(fs::exists(dir / "work" / "povray.log")) << "the tool was not started";
}

TEST(ToolTimeout, ValidateExitsWithFourForAHangingTool) {
  const test::ScratchDir dir;
  const fs::path povray = fake_tool(dir, "fake-povray", kHangingPovray);
  const std::string args = "validate --scene lit-plane --resolution 32x18 --threads 1 --pipelines plain-rt "
                           "--truth povray --no-cache --scenes-dir " +
                           test::quoted(fs::path(SB_BINARY_DIR) / "Testing" / "scenes-cache") + " --out " +
                           test::quoted(dir / "out");
  const std::string env = "STEREOBENCH_POVRAY=" + test::quoted(povray) + " ";
  const test::CliRun hung =
      test::run_shell(env + "STEREOBENCH_TOOL_TIMEOUT=1 " + std::string(SB_CLI_PATH) + " " + args);
  EXPECT_EQ(hung.code, 4) << hung.out;
  EXPECT_NE(hung.out.find("did not finish rendering"), std::string::npos) << hung.out;
  EXPECT_NE(hung.out.find("within 1 s"), std::string::npos) << hung.out;
  const test::CliRun bad =
      test::run_shell(env + "STEREOBENCH_TOOL_TIMEOUT=soon " + std::string(SB_CLI_PATH) + " " + args);
  EXPECT_EQ(bad.code, 3) << bad.out;
  EXPECT_NE(bad.out.find("STEREOBENCH_TOOL_TIMEOUT='soon'"), std::string::npos) << bad.out;
}

/// Whether process `pid` is still running (a zombie whose parent is gone counts as ended).
bool running(long pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string text;
  if (!std::getline(stat, text)) return false;
  const size_t close = text.rfind(')');
  return close != std::string::npos && close + 2 < text.size() && text[close + 2] != 'Z';
}

TEST(ToolStop, StoppingStereobenchStopsTheToolItRuns) {
  // SIGTERM to stereobench (a job's end, `kill`) or Ctrl-C: the tool is in a process group of its
  // own, so without stereobench passing it on it would go on rendering into the work folder.
  const test::ScratchDir dir;
  const fs::path pid_file = dir / "tool.pid";
  const fs::path povray = fake_tool(dir, "fake-povray",
                                    "if [ \"$1\" = --version ]; then echo 'POV-Ray 3.7.0.10'; exit 0; fi\n"
                                    "echo $$ > " + test::quoted(pid_file) + "\nexec sleep 100\n");
  // (A shell starts background jobs with SIGINT ignored, which stays ignored: HUP stands in.)
  for (const char* sig : {"TERM", "HUP"}) {
    fs::remove(pid_file);
    const std::string run = "STEREOBENCH_POVRAY=" + test::quoted(povray) + " " + std::string(SB_CLI_PATH) +
                            " validate --scene lit-plane --resolution 32x18 --threads 1 --pipelines plain-rt "
                            "--truth povray --no-cache --scenes-dir " +
                            test::quoted(fs::path(SB_BINARY_DIR) / "Testing" / "scenes-cache") + " --out " +
                            test::quoted(dir / "out");
    // The shell waits for the tool's pid file, then signals stereobench alone.
    const test::CliRun r = test::run_shell("sh -c '" + run + " & sb=$!; n=0; while [ ! -s " + test::quoted(pid_file) +
                                           " ] && [ $n -lt 600 ]; do sleep 0.05; n=$((n+1)); done; kill -" + sig +
                                           " $sb; wait $sb; echo exit=$?'");
    ASSERT_TRUE(fs::exists(pid_file)) << r.out;
    long pid = 0;
    std::ifstream(pid_file) >> pid;
    ASSERT_GT(pid, 0);
    const auto start = Clock::now();
    while (running(pid) && seconds_since(start) < 5.0) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    EXPECT_FALSE(running(pid)) << "SIG" << sig << ": the tool (pid " << pid << ") still runs\n" << r.out;
    EXPECT_NE(r.out.find(std::string("exit=") + (std::string(sig) == "TERM" ? "143" : "129")), std::string::npos)
        << "stereobench ends as the signal says\n" << r.out;
    if (running(pid)) ::kill(static_cast<pid_t>(pid), SIGKILL);
  }
}

}  // namespace
}  // namespace sb
