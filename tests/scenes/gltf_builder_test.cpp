// Tests of the glTF builder: the GLB container and the embedded .gltf, accessor bounds, index
// types, alignment, textures, lights, camera and scene extras, instancing counts and errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "gltf_reader_support.hpp"
#include "renderer/error.hpp"
#include "renderer/io/image_io.hpp"
#include "sb_version.hpp"
#include "support/scratch_dir.hpp"
#include "scenes/gltf_builder.hpp"
#include "scenes/textures.hpp"

namespace sb::scenes {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using test::ScratchDir;
using test::file_bytes;

uint32_t u32(const std::vector<unsigned char>& b, size_t at) {
  return uint32_t{b[at]} | (uint32_t{b[at + 1]} << 8) | (uint32_t{b[at + 2]} << 16) | (uint32_t{b[at + 3]} << 24);
}

/// A small scene exercising every builder feature.
GltfBuilder sample_builder() {
  GltfBuilder b("sample", 42, {{"size", 2.0}});
  TextureImage img = checker_texture(16, 4, vec3(0.8f), vec3(0.1f));
  const int tex = add_texture(b, "checker", img);
  const int textured = b.add_material("textured", vec3(1.0f), tex);
  const int red = b.add_material("red", vec4(0.8f, 0.1f, 0.1f, 1.0f), -1, false);
  const int box = b.add_mesh("box", make_box({-1, 0, -1}, {1, 2, 1}), textured);
  const int ball = b.add_mesh("ball", make_uv_sphere(0.5f, 16, 8), red);
  const int parent = b.add_node("group", -1, NodeTransform::trs({0.0, 0.0, -5.0}, 0.5));
  b.add_node("box", box, {}, parent);
  b.add_node("ball_a", ball, NodeTransform::at({2.0, 1.0, 0.0}), parent);
  b.add_node("ball_b", ball, NodeTransform::trs({-2.0, 1.0, 0.0}, 0.0, 2.0), parent);
  b.add_point_light("lamp", {0.0f, 3.0f, -4.0f}, vec3(1.0f, 0.9f, 0.8f), 10.0f);
  b.add_directional_light("sun", {0.0f, -1.0f, -1.0f}, vec3(1.0f), 2.0f);
  RigDefaults rig;
  rig.interaxial = 0.064;
  rig.convergence = 5.0;
  rig.width = 1920;
  rig.height = 1080;
  b.set_camera("camera", CameraPose::look_at({0.0, 1.5, 2.0}, {0.0, 1.0, -5.0}), 0.7, 0.05, 500.0, rig);
  b.set_background({0.1f, 0.2f, 0.3f});
  b.set_ambient(0.05);
  return b;
}

TEST(GltfBuilder, WritesAWellFormedGlb) {
  const ScratchDir dir;
  const GltfBuilder b = sample_builder();
  const size_t size = b.write(dir / "sample.glb");
  const std::vector<unsigned char> bytes = file_bytes(dir / "sample.glb");
  ASSERT_EQ(bytes.size(), size);
  EXPECT_EQ(u32(bytes, 0), 0x46546C67u);  // glTF
  EXPECT_EQ(u32(bytes, 4), 2u);
  EXPECT_EQ(u32(bytes, 8), bytes.size());
  const uint32_t json_len = u32(bytes, 12);
  EXPECT_EQ(json_len % 4, 0u);
  EXPECT_EQ(u32(bytes, 16), 0x4E4F534Au);  // JSON
  EXPECT_EQ(u32(bytes, 20 + json_len + 4), 0x004E4942u);  // BIN
  EXPECT_EQ(u32(bytes, 20 + json_len) % 4, 0u);

  const test::ReadGltf g = test::read_gltf(dir / "sample.glb");
  EXPECT_EQ(g.doc["asset"]["version"], "2.0");
  EXPECT_EQ(g.doc["asset"]["generator"], "stereobench " SB_VERSION_STRING);
  EXPECT_EQ(g.doc["buffers"][0]["byteLength"].get<size_t>(), g.bin.size());
  for (const json& v : g.doc["bufferViews"]) EXPECT_EQ(v["byteOffset"].get<size_t>() % 4, 0u);
  // Vertex and index views carry their targets; the image view carries none.
  size_t targeted = 0;
  for (const json& v : g.doc["bufferViews"]) targeted += v.contains("target") ? 1 : 0;
  EXPECT_EQ(targeted, g.doc["bufferViews"].size() - 1);
  // POSITION min/max are exactly the data's bounds.
  for (const json& mesh : g.doc["meshes"])
    for (const json& prim : mesh["primitives"]) {
      const json& acc = g.doc["accessors"][prim["attributes"]["POSITION"].get<size_t>()];
      ASSERT_TRUE(acc.contains("min") && acc.contains("max"));
    }
  // Instancing: the ball mesh is placed twice, so its triangles count twice.
  EXPECT_EQ(b.stats().triangles, 12u + 2u * (2u * 16u * 7u));
  EXPECT_EQ(g.triangle_count(), b.stats().triangles);
  EXPECT_EQ(g.vertex_count(), b.stats().vertices);
  EXPECT_EQ(b.stats().lights, 2u);
  EXPECT_EQ(g.light_count("point"), 1u);
  EXPECT_EQ(g.light_count("directional"), 1u);
  // The scaled instance reaches twice as far.
  EXPECT_NEAR(g.bounds().hi.y, 2.0f, 1e-5f);
}

TEST(GltfBuilder, EmbeddedGltfHoldsTheSamePayload) {
  const ScratchDir dir;
  const GltfBuilder b = sample_builder();
  b.write(dir / "sample.glb");
  b.write(dir / "sample.gltf");
  const json doc = json::parse(file_bytes(dir / "sample.gltf"));
  const std::string uri = doc["buffers"][0]["uri"];
  EXPECT_EQ(uri.rfind("data:application/octet-stream;base64,", 0), 0u);
  EXPECT_EQ(test::read_binary_payload(dir / "sample.gltf"), test::read_binary_payload(dir / "sample.glb"));
  // Everything but the buffer's URI is the same document.
  json without = doc;
  without["buffers"][0].erase("uri");
  EXPECT_EQ(without, b.document());
  EXPECT_THROW(b.write(dir / "sample.obj"), InputError);
}

TEST(GltfBuilder, AccessorBoundsMatchTheData) {
  const ScratchDir dir;
  GltfBuilder b("bounds", 1);
  const int m = b.add_material("m", vec3(0.5f));
  MeshData mesh = make_uv_sphere(0.3f, 24, 12);
  transform_mesh(mesh, translation({0.1f, 0.2f, 0.3f}));
  b.add_node("s", b.add_mesh("s", mesh, m));
  b.write(dir / "b.glb");
  const test::ReadGltf g = test::read_gltf(dir / "b.glb");
  const json& acc = g.doc["accessors"][0];
  const Bounds3 bb = mesh.bounds();
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(acc["min"][static_cast<size_t>(k)].get<double>(), static_cast<double>(bb.lo[k]));
    EXPECT_EQ(acc["max"][static_cast<size_t>(k)].get<double>(), static_cast<double>(bb.hi[k]));
  }
  // Untextured: no TEXCOORD_0 is written.
  EXPECT_FALSE(g.doc["meshes"][0]["primitives"][0]["attributes"].contains("TEXCOORD_0"));
}

TEST(GltfBuilder, PicksTheIndexType) {
  GltfBuilder b("indices", 1);
  const MeshData small = make_plane({1.0f, 1.0f}, {4, 4});
  const MeshData large = make_plane({1.0f, 1.0f}, {300, 300});  // 90601 vertices
  const int a = b.add_geometry(small);
  const int c = b.add_geometry(large);
  const int d = b.add_geometry(small, true, IndexType::uint32);
  const json doc = b.document();
  const auto index_type = [&](int geometry) {
    // Geometries store POSITION, NORMAL, TEXCOORD_0 and indices in this order.
    return doc["accessors"][static_cast<size_t>(geometry * 4 + 3)]["componentType"].get<int>();
  };
  EXPECT_EQ(index_type(a), 5123);
  EXPECT_EQ(index_type(c), 5125);
  EXPECT_EQ(index_type(d), 5125);
  EXPECT_THROW((void)b.add_geometry(large, true, IndexType::uint16), std::logic_error);
}

TEST(GltfBuilder, CameraLightsAndExtras) {
  const GltfBuilder b = sample_builder();
  const json doc = b.document();
  // Camera: perspective with the rig's aspect; the node's -Z looks at the target.
  const json& cam = doc["cameras"][0]["perspective"];
  EXPECT_NEAR(cam["aspectRatio"].get<double>(), 16.0 / 9.0, 1e-12);
  EXPECT_EQ(cam["yfov"].get<double>(), 0.7);
  int camera_node = -1;
  for (size_t i = 0; i < doc["nodes"].size(); ++i)
    if (doc["nodes"][i].contains("camera")) camera_node = static_cast<int>(i);
  ASSERT_GE(camera_node, 0);
  const json& node = doc["nodes"][static_cast<size_t>(camera_node)];
  const json& sbx = node["extras"]["stereobench"];
  EXPECT_EQ(sbx["interaxial"].get<double>(), 0.064);
  EXPECT_EQ(sbx["convergence"].get<double>(), 5.0);
  EXPECT_EQ(sbx["width"].get<int>(), 1920);
  EXPECT_EQ(sbx["height"].get<int>(), 1080);
  const json& r = node["rotation"];
  const dquat q(r[3].get<double>(), r[0].get<double>(), r[1].get<double>(), r[2].get<double>());
  EXPECT_NEAR(glm::length(q), 1.0, 1e-12);
  const dvec3 view = q * dvec3(0.0, 0.0, -1.0);
  const dvec3 expected = glm::normalize(dvec3(0.0, 1.0, -5.0) - dvec3(0.0, 1.5, 2.0));
  EXPECT_NEAR(glm::length(view - expected), 0.0, 1e-9);

  // Lights: the extension is declared; the directional light's node points -Z along travel.
  EXPECT_EQ(doc["extensionsUsed"], json::array({"KHR_lights_punctual"}));
  const json& lights = doc["extensions"]["KHR_lights_punctual"]["lights"];
  ASSERT_EQ(lights.size(), 2u);
  EXPECT_EQ(lights[0]["type"], "point");
  EXPECT_EQ(lights[0]["intensity"].get<double>(), 10.0);
  for (const json& n : doc["nodes"])
    if (n.contains("extensions") && lights[n["extensions"]["KHR_lights_punctual"]["light"].get<size_t>()]["type"] == "directional") {
      const json& lr = n["rotation"];
      const dquat lq(lr[3].get<double>(), lr[0].get<double>(), lr[1].get<double>(), lr[2].get<double>());
      EXPECT_NEAR(glm::length(lq * dvec3(0, 0, -1) - glm::normalize(dvec3(0, -1, -1))), 0.0, 1e-9);
    }

  // Scene extras.
  const json& extras = doc["scenes"][0]["extras"]["stereobench"];
  EXPECT_EQ(extras["generator"], "sample");
  EXPECT_EQ(extras["seed"].get<uint64_t>(), 42u);
  EXPECT_EQ(extras["params"]["size"].get<double>(), 2.0);
  EXPECT_EQ(extras["ambient"].get<double>(), 0.05);
  EXPECT_EQ(extras["background"].size(), 3u);
  // Materials: Lambertian factors, double-sided by default.
  EXPECT_EQ(doc["materials"][0]["doubleSided"], true);
  EXPECT_FALSE(doc["materials"][1].contains("doubleSided"));
  EXPECT_EQ(doc["materials"][0]["pbrMetallicRoughness"]["metallicFactor"].get<double>(), 0.0);
}

TEST(GltfBuilder, EmbedsTexturesAsPng) {
  const ScratchDir dir;
  const GltfBuilder b = sample_builder();
  b.write(dir / "t.glb");
  const test::ReadGltf g = test::read_gltf(dir / "t.glb");
  const json& image = g.doc["images"][0];
  EXPECT_EQ(image["mimeType"], "image/png");
  const json& sampler = g.doc["samplers"][0];
  EXPECT_EQ(sampler["wrapS"].get<int>(), 10497);
  EXPECT_EQ(sampler["wrapT"].get<int>(), 10497);
  EXPECT_EQ(sampler["minFilter"].get<int>(), 9987);
  EXPECT_EQ(sampler["magFilter"].get<int>(), 9729);
  const json& view = g.doc["bufferViews"][image["bufferView"].get<size_t>()];
  const io::DecodedImage decoded = io::decode_image(
      std::span<const unsigned char>(g.bin.data() + view["byteOffset"].get<size_t>(), view["byteLength"].get<size_t>()), "test");
  ASSERT_EQ(decoded.width, 16);
  ASSERT_EQ(decoded.channels, 3);  // opaque RGBA is stored as RGB
  const TextureImage expected = checker_texture(16, 4, vec3(0.8f), vec3(0.1f));
  for (int i = 0; i < 16 * 16; ++i)
    EXPECT_EQ(std::lround(decoded.values[static_cast<size_t>(i) * 3] * 255.0f), expected.rgba[static_cast<size_t>(i) * 4]);
}

TEST(GltfBuilder, RejectsInconsistentInput) {
  GltfBuilder b("bad", 1);
  std::vector<uint8_t> pixels(10, 0);
  EXPECT_THROW((void)b.add_texture("t", 4, 4, pixels), std::logic_error);
  EXPECT_THROW((void)b.add_material("m", vec3(1.0f), 3), std::logic_error);
  const int m = b.add_material("m", vec3(1.0f));
  MeshData broken = make_box({0, 0, 0}, {1, 1, 1});
  broken.indices.push_back(99);
  broken.indices.push_back(0);
  broken.indices.push_back(1);
  EXPECT_THROW((void)b.add_mesh("broken", broken, m), std::logic_error);
  MeshData no_normals = make_box({0, 0, 0}, {1, 1, 1});
  no_normals.normals.pop_back();
  EXPECT_THROW((void)b.add_mesh("nn", no_normals, m), std::logic_error);
  EXPECT_THROW((void)b.add_node("n", 7), std::logic_error);
  const int textured = b.add_material("tex", vec3(1.0f), add_texture(b, "t", checker_texture(4, 2, vec3(1.0f), vec3(0.0f))));
  MeshData no_uvs = make_box({0, 0, 0}, {1, 1, 1});
  no_uvs.uvs.clear();
  EXPECT_THROW((void)b.add_mesh("no_uvs", no_uvs, textured), std::logic_error);
  RigDefaults rig;
  b.set_camera("c", CameraPose{}, 0.7, 0.1, 10.0, rig);
  EXPECT_THROW(b.set_camera("c", CameraPose{}, 0.7, 0.1, 10.0, rig), std::logic_error);
}

TEST(GltfBuilder, SameCallsGiveIdenticalBytes) {
  const ScratchDir dir;
  sample_builder().write(dir / "a.glb");
  sample_builder().write(dir / "b.glb");
  EXPECT_EQ(file_bytes(dir / "a.glb"), file_bytes(dir / "b.glb"));
}

}  // namespace
}  // namespace sb::scenes
