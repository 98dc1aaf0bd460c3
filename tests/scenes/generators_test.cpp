// Tests of the scene generators: the registry and its parameter checks, byte-identical output
// per seed, the counts each scene promises, sane bounds and a camera that looks at the content,
// and the Khronos glTF validator over every built-in scene.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include <sys/wait.h>

#include "gltf_reader_support.hpp"
#include "renderer/error.hpp"
#include "renderer/io/gltf_loader.hpp"
#include "scenes/catalog.hpp"
#include "scenes/generators.hpp"
#include "support/run_cli.hpp"
#include "support/scratch_dir.hpp"

namespace sb::scenes {
namespace {

namespace fs = std::filesystem;
using test::quoted;
using nlohmann::json;

const std::vector<std::string> kExpectedNames = {"spheres",   "atrium",    "bistro",         "temple",
                                                 "dragon",    "complexity", "lit-plane",     "box-wall",
                                                 "thin-pole", "textured-plane", "slanted-plane", "fence"};

using test::ScratchDir;
using test::file_bytes;

/// Expects `f` to throw InputError whose message contains every one of `parts`.
template <typename F>
void expect_input_error(F&& f, const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "no InputError thrown";
  } catch (const InputError& e) {
    for (const std::string& p : parts) EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what() << " lacks " << p;
  }
}

// ---------------------------------------------------------------------------------------------
// Registry and parameters

TEST(SceneRegistry, ListsEveryGeneratorInOrder) {
  std::vector<std::string> names;
  for (const GeneratorInfo& g : generators()) names.push_back(g.name);
  EXPECT_EQ(names, kExpectedNames);
  for (const GeneratorInfo& g : generators()) {
    SCOPED_TRACE(g.name);
    EXPECT_FALSE(g.description.empty());
    EXPECT_EQ(g.file_name, g.name + (g.analytic ? ".gltf" : ".glb"));
    // fence is generated on demand only (a stress case outside the pipelines' scene tests).
    EXPECT_EQ(g.builtin, g.name != "fence");
    for (const GeneratorParam& p : g.params) {
      EXPECT_LE(p.min_value, p.default_value);
      EXPECT_LE(p.default_value, p.max_value);
      EXPECT_FALSE(p.help.empty());
    }
  }
  EXPECT_TRUE(find_generator("lit-plane").analytic);
  EXPECT_FALSE(find_generator("dragon").analytic);
}

TEST(SceneRegistry, UnknownGeneratorListsTheKnownOnes) {
  expect_input_error([] { (void)find_generator("sponza"); }, {"sponza", "spheres", "slanted-plane"});
  expect_input_error([] { (void)generate("sponza", {}, fs::path(SB_BINARY_DIR) / "x.glb"); }, {"sponza"});
}

TEST(SceneRegistry, RejectsUnknownAndOutOfRangeParameters) {
  const ScratchDir dir;
  const fs::path out = dir / "s.glb";
  GenerateOptions o;
  o.params = {{"radius", 1.0}};
  expect_input_error([&] { (void)generate("spheres", o, out); }, {"radius", "spheres", "count", "segments"});
  o.params = {{"count", 0.0}};
  expect_input_error([&] { (void)generate("spheres", o, out); }, {"count", "0", "[1, 100000]"});
  o.params = {{"triangles", 1e9}};
  expect_input_error([&] { (void)generate("complexity", o, out); }, {"triangles", "1000000000", "[100000, 100000000]"});
  o.params = {{"segments", 12.5}};
  expect_input_error([&] { (void)generate("spheres", o, out); }, {"segments", "12.5", "whole number"});
  o.params = {{"triangles", 100000.5}};  // the value as given, not rounded to 6 digits
  expect_input_error([&] { (void)generate("complexity", o, out); }, {"triangles", "100000.5", "whole number"});
  o.params = {{"count", std::numeric_limits<double>::quiet_NaN()}};
  expect_input_error([&] { (void)generate("spheres", o, out); }, {"count", "nan"});
  o.params = {{"anything", 1.0}};
  expect_input_error([&] { (void)generate("atrium", o, out); }, {"anything", "none"});
  expect_input_error([&] { (void)generate("lit-plane", {}, dir / "plane.obj"); }, {"plane.obj", ".glb", ".gltf"});
  // Each parameter in range, together beyond what a scene may hold (the loader would refuse the
  // file): refused before anything is written. 100000 spheres of 256 x 128 segments.
  o.params = {{"count", 100000.0}, {"segments", 256.0}};
  expect_input_error([&] { (void)generate("spheres", o, out); },
                     {"count=100000 segments=256", "6502400000 triangles", "1500000000"});
  EXPECT_FALSE(fs::exists(out));
  // On the command line no empty table precedes the refusal (its header was printed first).
  const test::CliRun cli = test::run_cli("scenes generate spheres --param count=100000 --param segments=256 --out " +
                                         quoted(dir / "cli"));
  EXPECT_EQ(cli.code, 3) << cli.out;
  EXPECT_NE(cli.out.find("6502400000 triangles"), std::string::npos) << cli.out;
  EXPECT_EQ(cli.out.find("triangles   vertices"), std::string::npos) << cli.out;
  EXPECT_FALSE(fs::exists(dir / "cli")) << "an empty --out was left";
}

TEST(SceneRegistry, TheSpheresAreClosedDoubleSidedMeshesAsLoaded) {
  // Closed, so Kim's redirection culls their back faces (culled_meshes); double-sided, so the ray
  // tracer runs no back-face filter on them: both as the loader gives them.
  ScratchDir dir("closedspheres");
  GenerateOptions o;
  o.params = {{"count", 12.0}};
  const fs::path file = dir / "spheres.glb";
  (void)generate("spheres", o, file);
  const Scene scene = io::load_gltf(file);
  ASSERT_EQ(scene.meshes.size(), 12u);
  for (const Mesh& m : scene.meshes) {
    ASSERT_GE(m.material, 0) << m.name;
    EXPECT_TRUE(scene.materials[static_cast<size_t>(m.material)].double_sided) << m.name;
    EXPECT_TRUE(m.is_closed()) << m.name;
  }
}

TEST(SceneRegistry, AWriteThatFailsNamesTheFileAndLeavesNothing) {
  // A full disk, made by a file-size limit of 1 KiB (the signal sent at the limit ignored, so the
  // write fails with EFBIG): exit 4 naming the scene file and the cause, and no file left.
  const ScratchDir dir;
  const test::CliRun r = test::run_shell("trap '' XFSZ; ulimit -f 2 && " + std::string(SB_CLI_PATH) +
                                         " scenes generate box-wall --out " + quoted(dir / "gen"));
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("cannot write the scene file " + (dir / "gen" / "box-wall.gltf").string()), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("File too large"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "gen")) << "neither the file, its temporary nor the folder this run made stays";
}

TEST(SceneRegistry, ACachedSceneCutShortIsGeneratedAgain) {
  // It used to be loaded as it was and refused as broken JSON, its stamp still saying "cached".
  test::ScratchDir dir;
  const std::filesystem::path file = scenes::resolve_scene("box-wall", dir.path());
  const auto size = std::filesystem::file_size(file);
  std::filesystem::resize_file(file, size / 2);
  EXPECT_EQ(scenes::resolve_scene("box-wall", dir.path()), file);
  EXPECT_EQ(std::filesystem::file_size(file), size);
  EXPECT_NO_THROW((void)io::load_gltf(file));
}

TEST(SceneParams, TriangleCountsFollowTheParameter) {
  const ScratchDir dir;
  for (const double n : {250000.0, 1200000.0}) {
    GenerateOptions o;
    o.params["triangles"] = n;
    const GenerateResult r = generate("complexity", o, dir / "complexity.glb");
    EXPECT_NEAR(static_cast<double>(r.triangles), n, 0.01 * n);
    // From 10^6 triangles on, the objects use 32-bit indices.
    const test::ReadGltf g = test::read_gltf(r.path);
    size_t wide = 0;
    for (const json& a : g.doc["accessors"])
      if (a["type"] == "SCALAR" && a["componentType"] == 5125) ++wide;
    EXPECT_EQ(wide > 0, n >= 1e6) << n;
  }
  GenerateOptions o;
  o.params["triangles"] = 300000;
  const GenerateResult r = generate("dragon", o, dir / "dragon.glb");
  const test::ReadGltf g = test::read_gltf(r.path);
  size_t largest = 0;
  for (const test::ReadPrimitive& p : g.primitives) largest = std::max(largest, p.indices.size() / 3);
  EXPECT_NEAR(static_cast<double>(largest), 3e5, 3e3);
}

TEST(SceneParams, DragonLightsAddToTheDefaultFive) {
  const ScratchDir dir;
  // Lights 1..10: the first N of one list, so N lights are the first N of any larger count and the
  // geometry never changes with the count.
  std::vector<std::vector<vec3>> positions;
  std::vector<unsigned char> payload;
  for (const double n : {1.0, 5.0, 10.0}) {
    GenerateOptions o;
    o.params = {{"triangles", 50000.0}, {"lights", n}};
    const fs::path path = dir / ("dragon_" + std::to_string(static_cast<int>(n)) + ".glb");
    const GenerateResult r = generate("dragon", o, path);
    EXPECT_EQ(r.lights, static_cast<size_t>(n));
    const test::ReadGltf g = test::read_gltf(path);
    EXPECT_EQ(g.light_count("point"), static_cast<size_t>(n));
    positions.push_back(g.point_light_positions());
    if (payload.empty()) payload = test::read_binary_payload(path);
    EXPECT_EQ(test::read_binary_payload(path), payload) << n;
    // The added lights stay around the dragon: within 5 m of its middle, above the ground.
    for (const vec3& p : positions.back()) {
      EXPECT_LT(glm::length(p - vec3(0.25f, 0.8f, 0.0f)), 5.0f);
      EXPECT_GT(p.y, 0.3f);
    }
  }
  for (size_t k = 1; k < positions.size(); ++k)
    for (size_t i = 0; i < positions[k - 1].size(); ++i) EXPECT_EQ(positions[k][i], positions[k - 1][i]) << i;
  GenerateOptions o;
  o.params = {{"lights", 11.0}};
  expect_input_error([&] { (void)generate("dragon", o, dir / "d.glb"); }, {"lights", "11", "[1, 10]"});
}

// ---------------------------------------------------------------------------------------------
// Determinism: every generator, with parameters that keep it quick.

class SceneDeterminism : public ::testing::TestWithParam<std::string> {};

TEST_P(SceneDeterminism, SameSeedSameBytesOtherSeedOtherFile) {
  const std::string name = GetParam();
  const GeneratorInfo& info = find_generator(name);
  const ScratchDir dir;
  GenerateOptions o;
  o.seed = 7;
  if (name == "dragon") o.params["triangles"] = 100000;  // the full size is checked below
  const std::string ext = info.analytic ? ".gltf" : ".glb";
  (void)generate(name, o, dir / ("a" + ext));
  (void)generate(name, o, dir / ("b" + ext));
  EXPECT_EQ(file_bytes(dir / ("a" + ext)), file_bytes(dir / ("b" + ext)));
  o.seed = 8;
  (void)generate(name, o, dir / ("c" + ext));
  EXPECT_NE(file_bytes(dir / ("a" + ext)), file_bytes(dir / ("c" + ext)));  // the seed is recorded
  // Random scenes change their content (geometry, placements, colours, textures) with the seed;
  // analytic ones do not.
  const auto content = [](const fs::path& p) {
    json doc = test::read_gltf(p).doc;
    doc["scenes"][0]["extras"]["stereobench"].erase("seed");
    return std::pair{doc, test::read_binary_payload(p)};
  };
  EXPECT_EQ(content(dir / ("a" + ext)) == content(dir / ("c" + ext)), info.analytic);
  // The whole 64-bit seed counts: 7 + 2^32 is another scene (fence kept the low 32 bits).
  o.seed = 7 + (uint64_t{1} << 32);
  (void)generate(name, o, dir / ("d" + ext));
  EXPECT_EQ(content(dir / ("a" + ext)) == content(dir / ("d" + ext)), info.analytic);
}

INSTANTIATE_TEST_SUITE_P(AllGenerators, SceneDeterminism, ::testing::ValuesIn(kExpectedNames),
                         [](const auto& p) {
                           std::string s = p.param;
                           std::replace(s.begin(), s.end(), '-', '_');
                           return s;
                         });

// ---------------------------------------------------------------------------------------------
// Structure of every built-in scene at its defaults.

/// Whether a ray hits any triangle of the scene (Moller-Trumbore).
bool ray_hits(const test::ReadGltf& g, const dvec3& origin, const dvec3& dir) {
  for (const test::ReadPrimitive& p : g.primitives)
    for (size_t t = 0; t + 2 < p.indices.size(); t += 3) {
      const dvec3 a(p.positions[p.indices[t]]), b(p.positions[p.indices[t + 1]]), c(p.positions[p.indices[t + 2]]);
      const dvec3 e1 = b - a, e2 = c - a, q = glm::cross(dir, e2);
      const double det = glm::dot(e1, q);
      if (std::fabs(det) < 1e-14) continue;
      const dvec3 s = origin - a;
      const double u = glm::dot(s, q) / det;
      if (u < 0.0 || u > 1.0) continue;
      const dvec3 r = glm::cross(s, e1);
      const double v = glm::dot(dir, r) / det;
      if (v < 0.0 || u + v > 1.0) continue;
      if (glm::dot(e2, r) / det > 1e-4) return true;
    }
  return false;
}

/// What each scene promises.
struct Expectation {
  size_t min_triangles = 1;
  size_t max_triangles = std::numeric_limits<size_t>::max();
  size_t point_lights = 0;
  size_t directional_lights = 0;
  size_t min_textures = 0;
  bool grounded = true;  ///< stands on y = 0
};

Expectation expectation(const std::string& name) {
  if (name == "spheres") return {528000, 528000, 5, 0, 0, false};  // 1000 spheres x 2*24*11
  if (name == "atrium") return {200000, 900000, 8, 1, 4};
  if (name == "bistro") return {200000, 900000, 13, 1, 3};
  if (name == "temple") return {200000, 900000, 13, 1, 3};
  if (name == "dragon") return {1089000, 1111000 + 1000, 5, 0, 0};
  if (name == "complexity") return {99000, 101000, 2, 1, 0};
  if (name == "lit-plane") return {2, 1000, 1, 0, 0, false};
  if (name == "textured-plane") return {2, 10000, 0, 1, 1};
  if (name == "slanted-plane") return {2, 10000, 0, 1, 0, false};
  if (name == "fence") return {2, 10000, 1, 1, 4};
  return {2, 10000, 1, 0, 0};  // box-wall, thin-pole
}

class SceneStructure : public ::testing::TestWithParam<std::string> {};

TEST_P(SceneStructure, CountsBoundsAndCamera) {
  const std::string name = GetParam();
  const ScratchDir dir;
  const fs::path path = dir / find_generator(name).file_name;
  const GenerateResult r = generate(name, {}, path);
  std::printf("%-15s %9zu triangles %9zu vertices %3zu lights %10zu bytes %6.2f s\n", name.c_str(), r.triangles,
              r.vertices, r.lights, r.bytes, r.seconds);
  EXPECT_EQ(r.path, path);
  EXPECT_EQ(r.bytes, fs::file_size(path));
  EXPECT_GE(r.seconds, 0.0);

  const test::ReadGltf g = test::read_gltf(path);
  // The result agrees with the file, and the file with the scene's promise.
  EXPECT_EQ(g.triangle_count(), r.triangles);
  EXPECT_EQ(g.vertex_count(), r.vertices);
  const Expectation e = expectation(name);
  EXPECT_GE(r.triangles, e.min_triangles);
  EXPECT_LE(r.triangles, e.max_triangles);
  EXPECT_EQ(g.light_count("point"), e.point_lights);
  EXPECT_EQ(g.light_count("directional"), e.directional_lights);
  EXPECT_EQ(r.lights, e.point_lights + e.directional_lights);
  EXPECT_GE(g.doc.value("textures", json::array()).size(), e.min_textures);
  if (name == "dragon") {
    // One mesh carries (1.1 M +- 1 %) triangles; the rest is the ground plane.
    size_t largest = 0;
    for (const test::ReadPrimitive& p : g.primitives) largest = std::max(largest, p.indices.size() / 3);
    EXPECT_NEAR(static_cast<double>(largest), 1.1e6, 1.1e4);
  }
  if (name == "complexity") {
    EXPECT_NEAR(static_cast<double>(r.triangles), 1e5, 1e3);
  }

  // Bounds: finite and of a sensible size; the ground or floor at y = 0.
  const Bounds3 b = g.bounds();
  ASSERT_FALSE(b.empty());
  for (int k = 0; k < 3; ++k) {
    EXPECT_TRUE(std::isfinite(b.lo[k]) && std::isfinite(b.hi[k]));
    EXPECT_LT(b.extent()[k], 2000.0f);
  }
  EXPECT_GT(glm::length(b.extent()), 0.5f);
  if (e.grounded) {
    EXPECT_NEAR(b.lo.y, 0.0f, 1e-3f);
  }
  // Point lights sit within (a margin around) the scene.
  for (const vec3& p : g.point_light_positions())
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(p[k], b.lo[k] - 5.0f);
      EXPECT_LE(p[k], b.hi[k] + 5.0f);
    }

  // The camera: the rig defaults, and a view that has the content in front of it.
  const int cam = g.camera_node();
  ASSERT_GE(cam, 0);
  const json& sbx = g.doc["nodes"][static_cast<size_t>(cam)]["extras"]["stereobench"];
  EXPECT_EQ(sbx["interaxial"].get<double>(), 0.064);
  EXPECT_EQ(sbx["width"].get<int>(), 1920);
  EXPECT_EQ(sbx["height"].get<int>(), 1080);
  const double convergence = sbx["convergence"].get<double>();
  EXPECT_GT(convergence, 0.5);
  EXPECT_LT(convergence, 100.0);
  const json& persp = g.doc["cameras"][0]["perspective"];
  const double tan_v = std::tan(0.5 * persp["yfov"].get<double>());
  const double tan_h = tan_v * persp["aspectRatio"].get<double>();
  const dmat4 world_from_cam = g.node_world[static_cast<size_t>(cam)];
  const dmat4 cam_from_world = glm::inverse(world_from_cam);
  const auto in_view = [&](const vec3& p, double* depth) {
    const dvec3 c = dvec3(cam_from_world * dvec4(dvec3(p), 1.0));
    *depth = -c.z;
    return -c.z > 0.0 && std::fabs(c.x) <= tan_h * -c.z && std::fabs(c.y) <= tan_v * -c.z;
  };
  double depth = 0.0;
  const vec3 centre = b.center();
  EXPECT_TRUE(in_view(centre, &depth)) << "bounds centre " << centre.x << " " << centre.y << " " << centre.z;
  size_t front = 0, total = 0;
  for (const test::ReadPrimitive& p : g.primitives)
    for (const vec3& v : p.positions) {
      ++total;
      (void)in_view(v, &depth);
      front += depth > persp["znear"].get<double>() ? 1 : 0;
    }
  EXPECT_GT(static_cast<double>(front), 0.75 * static_cast<double>(total)) << "most geometry should lie in front of the camera";
  // Rays through a 7 x 7 grid over the image: most should hit the scene rather than the background.
  const dvec3 eye(world_from_cam[3]);
  int hits = 0;
  for (int j = 0; j < 7; ++j)
    for (int i = 0; i < 7; ++i) {
      const double x = (i - 3) / 3.5 * tan_h, y = (j - 3) / 3.5 * tan_v;
      hits += ray_hits(g, eye, glm::normalize(dvec3(world_from_cam * dvec4(x, y, -1.0, 0.0)))) ? 1 : 0;
    }
  EXPECT_GE(hits, 25) << "only " << hits << " of 49 view rays hit the scene";
}

INSTANTIATE_TEST_SUITE_P(BuiltinScenes, SceneStructure, ::testing::ValuesIn(kExpectedNames),
                         [](const auto& p) {
                           std::string s = p.param;
                           std::replace(s.begin(), s.end(), '-', '_');
                           return s;
                         });

// ---------------------------------------------------------------------------------------------
// The Khronos glTF validator over every built-in scene.

/// Runs a shell command, returning its exit status and output.
int run(const std::string& command, std::string& output) {
  output.clear();
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return -1;
  std::array<char, 4096> buf{};
  while (fgets(buf.data(), static_cast<int>(buf.size()), pipe) != nullptr) output += buf.data();
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

class KhronosValidator : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(fs::path(SB_SOURCE_DIR) / "ci" / "node_modules" / "gltf-validator" / "package.json"))
      // A missing validator is a failure, never a silent pass: ci/test.sh installs it.
      FAIL() << "the Khronos glTF validator is not installed (ci/node_modules/gltf-validator); "
                "install it with `bash ci/install-deps.sh validator`";
    script_ = fs::path(SB_SOURCE_DIR) / "tests" / "tools" / "validate_gltf.mjs";
  }
  fs::path script_;
};

TEST_F(KhronosValidator, EveryBuiltinSceneHasNoErrors) {
  const ScratchDir dir;
  std::string command = "node " + quoted(script_);
  std::printf("%-15s %9s %9s %6s %10s %7s\n", "scene", "triangles", "vertices", "lights", "bytes", "seconds");
  for (const GeneratorInfo& info : generators()) {
    if (!info.builtin) continue;
    const GenerateResult r = generate(info.name, {}, dir / info.file_name);  // complexity at its default 1e5
    std::printf("%-15s %9zu %9zu %6zu %10zu %7.2f\n", info.name.c_str(), r.triangles, r.vertices, r.lights, r.bytes, r.seconds);
    command += " " + quoted(dir / info.file_name);
  }
  std::string output;
  const int status = run(command, output);
  std::printf("%s", output.c_str());
  EXPECT_EQ(status, 0) << output;
  for (const GeneratorInfo& info : generators()) {
    if (info.builtin) {
      EXPECT_NE(output.find(info.file_name + ": 0 errors"), std::string::npos) << info.name;
    }
  }
}

TEST_F(KhronosValidator, ReportsAnInvalidFile) {
  const ScratchDir dir;
  (void)generate("lit-plane", {}, dir / "plane.gltf");
  json doc = json::parse(file_bytes(dir / "plane.gltf"));
  doc["meshes"][0]["primitives"][0]["material"] = 9;  // no such material
  doc["accessors"][0]["min"] = json::array({0, 0, 0});
  std::ofstream(dir / "broken.gltf") << doc.dump();
  std::string output;
  EXPECT_EQ(run("node " + quoted(script_) + " " + quoted(dir / "broken.gltf"), output), 1) << output;
  EXPECT_NE(output.find("/meshes/0/primitives/0/material"), std::string::npos) << output;
  EXPECT_NE(output.find("ACCESSOR_MIN_MISMATCH"), std::string::npos) << output;
}

}  // namespace
}  // namespace sb::scenes
