// Work the machine cannot hold is refused before it is allocated: a resolution, a scene whose
// accessors declare hundreds of millions of vertices, an image whose header declares gigapixels.
// Each runs under a 3 GB address-space limit (ulimit -v), so the outcome is the same on any
// machine, and must exit 4 at once with a message naming the work, the need and the bound, and
// leave no output behind. Without the check the first two are not refused by the allocator under
// Linux overcommit but end in the OOM killer, and the images fail late as "damaged" (exit 3).
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "support/mini_gltf.hpp"
#include "support/run_cli.hpp"
#include "support/scratch_dir.hpp"

namespace sb {
namespace {

using test::CliRun;

/// `stereobench ARGS` with the address space limited to about 2.9 GiB.
CliRun run_limited(const std::string& args) {
  return test::run_shell("ulimit -v 3000000 && " + std::string(SB_CLI_PATH) + " " + args);
}

/// Files (not folders) under `dir`.
size_t files_under(const std::filesystem::path& dir) {
  size_t n = 0;
  if (!std::filesystem::exists(dir)) return 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir)) n += e.is_regular_file() ? 1 : 0;
  return n;
}

uint32_t crc32(const unsigned char* data, size_t n) {
  uint32_t c = 0xFFFFFFFFu;
  for (size_t i = 0; i < n; ++i) {
    c ^= data[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
  }
  return ~c;
}

void put_u32(std::vector<unsigned char>& out, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<unsigned char>(v >> s));
}

void put_chunk(std::vector<unsigned char>& out, const char* type, const std::vector<unsigned char>& data) {
  put_u32(out, static_cast<uint32_t>(data.size()));
  std::vector<unsigned char> body(type, type + 4);
  body.insert(body.end(), data.begin(), data.end());
  out.insert(out.end(), body.begin(), body.end());
  put_u32(out, crc32(body.data(), body.size()));
}

/// A 200-byte PNG whose header declares a 60000 x 60000 RGBA image (its pixel data is one byte
/// long): decoded as float it would take 53.6 GiB.
std::vector<unsigned char> huge_png(uint32_t side = 60000) {
  std::vector<unsigned char> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  std::vector<unsigned char> ihdr;
  put_u32(ihdr, side);
  put_u32(ihdr, side);
  ihdr.insert(ihdr.end(), {8, 6, 0, 0, 0});  // 8 bits, RGBA, deflate, adaptive filters, no interlace
  put_chunk(png, "IHDR", ihdr);
  // A zlib stream of one stored block holding one zero byte.
  put_chunk(png, "IDAT", {0x78, 0x01, 0x01, 0x01, 0x00, 0xfe, 0xff, 0x00, 0x00, 0x01, 0x00, 0x01});
  put_chunk(png, "IEND", {});
  return png;
}

TEST(MemoryLimit, AResolutionBeyondTheMemoryIsRefusedBeforeRendering) {
  test::ScratchDir dir;
  const std::string common = " --scene lit-plane --resolution 16384x16384 --scenes-dir " +
                             test::quoted(dir / "scenes");
  const struct {
    std::string args, expect;
  } cases[] = {
      {"render --pipeline plain-rt --out " + test::quoted(dir / "render"),
       "render plain-rt at 16384x16384 needs about 80.00 GiB of memory, but only"},
      {"validate --pipelines repro-rt --no-cache --out " + test::quoted(dir / "validate"),
       "validation at 16384x16384 needs about 80.00 GiB of memory, but only"},
      {"bench --pipelines plain-rt,repro-rt --baseline plain-rt -n 1", "benchmark at 16384x16384 needs about"},
  };
  for (const auto& c : cases) {
    const CliRun r = run_limited(c.args + common);
    EXPECT_EQ(r.code, 4) << c.args << "\n" << r.out;
    EXPECT_NE(r.out.find(c.expect), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("(ulimit -v); lower the resolution, or run on a machine with more memory"), std::string::npos)
        << r.out;
  }
  EXPECT_EQ(files_under(dir / "render") + files_under(dir / "validate"), 0u) << "nothing is written";
  // Nor is the output folder left, made before the refusal and empty (it was).
  EXPECT_FALSE(std::filesystem::exists(dir / "render"));
  EXPECT_FALSE(std::filesystem::exists(dir / "validate"));
}

TEST(MemoryLimit, ASceneDeclaringMoreVerticesThanTheMemoryHoldsIsRefusedBeforeReadingThem) {
  // 3e8 vertices of which one is given (a sparse accessor over zeros): a 1 KB file asking for
  // 18 GiB while it is read.
  test::ScratchDir dir;
  test::MiniGltf g;
  g.add_triangle();
  const float moved[3] = {0.0f, 0.0f, 1.0f};
  const uint32_t index = 2;
  const int values = g.add_view(moved, sizeof moved);
  const int indices = g.add_view(&index, sizeof index);
  g.doc["accessors"].push_back({{"componentType", 5126},
                                {"count", 300000000},
                                {"type", "VEC3"},
                                {"min", {0, 0, 0}},
                                {"max", {0, 0, 1}},
                                {"sparse",
                                 {{"count", 1},
                                  {"indices", {{"bufferView", indices}, {"componentType", 5125}}},
                                  {"values", {{"bufferView", values}}}}}});
  g.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 1;
  g.write_gltf(dir / "huge.gltf");
  const CliRun r = run_limited("render --pipeline plain-rt --resolution 32x18 --scene " + test::quoted(dir / "huge.gltf") +
                               " --out " + test::quoted(dir / "out"));
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("loading " + (dir / "huge.gltf").string() + ": 100000000 triangles, 300000000 vertices needs "
                       "about 17.88 GiB of memory"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("check the accessors' counts"), std::string::npos) << r.out;
  EXPECT_EQ(files_under(dir / "out"), 0u);
}

TEST(MemoryLimit, ASceneFileLargerThanAThirdOfTheMemoryIsRefusedBeforeItIsRead) {
  // A 1.2 GB .glb (sparse on disk): read, copied for the reader and decoded, it is held about
  // three times, 3.6 GB under a 2.9 GiB limit; it ended in "out of memory" naming nothing.
  test::ScratchDir dir;
  const std::filesystem::path big = dir / "big.glb";
  test::MiniGltf::write_bytes(big, {});
  std::filesystem::resize_file(big, 1200000000);
  const CliRun r = run_limited("render --pipeline plain-rt --resolution 32x18 --scene " + test::quoted(big) +
                               " --out " + test::quoted(dir / "out"));
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("loading " + big.string() + " (1144.4 MiB, held about three times while it is read) needs"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(files_under(dir / "out"), 0u);
}

TEST(MemoryLimit, AnImageDeclaringGigapixelsIsRefusedBeforeDecoding) {
  test::ScratchDir dir;
  test::MiniGltf::write_bytes(dir / "huge.png", huge_png());

  // As a texture of a scene.
  test::MiniGltf g;
  g.add_triangle();
  g.doc["images"] = {{{"uri", "huge.png"}}};
  g.doc["textures"] = {{{"source", 0}}};
  g.doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
  g.doc["meshes"][0]["primitives"][0]["material"] = 0;
  g.write_gltf(dir / "textured.gltf");
  CliRun r = run_limited("scenes info " + test::quoted(dir / "textured.gltf"));
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("decoding image " + (dir / "textured.gltf").string() +
                       " /images/0 (60000x60000, 4 channels) and what is made of it needs about 221.28 GiB of memory"),
            std::string::npos)
      << r.out;
  // One whose decoded values fit (0.73 GiB) but not with the texture and mip chain made of them
  // (3.0 GiB): each stage checked alone fitted, and together took the whole machine.
  test::MiniGltf::write_bytes(dir / "huge.png", huge_png(7000));
  r = run_limited("scenes info " + test::quoted(dir / "textured.gltf"));
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("/images/0 (7000x7000, 4 channels) and what is made of it needs about 3.01 GiB of memory"),
            std::string::npos)
      << r.out;
  test::MiniGltf::write_bytes(dir / "huge.png", huge_png());

  // As an image to compare.
  r = run_limited("compare " + test::quoted(dir / "huge.png") + " " + test::quoted(dir / "huge.png"));
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("(60000x60000, 4 channels) needs about 53.64 GiB of memory"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace sb
