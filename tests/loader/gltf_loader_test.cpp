// glTF loading of well-formed files: hierarchy, every accessor layout, strips and fans, the three
// container forms, materials and textures, lights, cameras and the stereo-rig extras.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "renderer/color.hpp"
#include "renderer/error.hpp"
#include "renderer/io/gltf_loader.hpp"
#include "renderer/io/image_io.hpp"
#include "renderer/rig.hpp"
#include "support/input_error.hpp"
#include "support/mini_gltf.hpp"
#include "support/scratch_dir.hpp"

namespace sb {
namespace {

using nlohmann::json;
using test::MiniGltf;
using test::ScratchDir;

void expect_vec3(const vec3& a, const vec3& b, float tol = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

TEST(GltfLoader, NodeHierarchyComposesTransforms) {
  ScratchDir dir("hier");
  MiniGltf g;
  const int p = g.add_positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  const int m = g.add_mesh(json::array({{{"attributes", {{"POSITION", p}}}}}));
  // Child: rotate 90 degrees about Z, scale 2; parent: translate (10, 0, 0).
  const double s = std::sqrt(0.5);
  const int child = g.add_node({{"mesh", m}, {"rotation", {0, 0, s, s}}, {"scale", {2, 2, 2}}}, false);
  g.add_node({{"translation", {10, 0, 0}}, {"children", {child}}});
  g.write_gltf(dir / "h.gltf");
  const Scene scene = io::load_gltf(dir / "h.gltf");
  ASSERT_EQ(scene.meshes.size(), 1u);
  const Mesh& mesh = scene.meshes[0];
  expect_vec3(mesh.positions[0], {10, 0, 0});
  expect_vec3(mesh.positions[1], {10, 2, 0});   // x axis rotated onto y, scaled by 2
  expect_vec3(mesh.positions[2], {8, 0, 0});    // y axis rotated onto -x
  EXPECT_EQ(mesh.node, child);
}

TEST(GltfLoader, AQuaternionIsNormalizedWhateverItsScale) {
  // Components whose squares overflow (or underflow) a double turned nothing: the length was
  // infinite (or zero) and the node kept the identity.
  ScratchDir dir("quat");
  const double s = std::sqrt(0.5);
  std::vector<std::vector<vec3>> positions;
  for (const double scale : {1.0, 1e200, 1e-200}) {
    MiniGltf g;
    const int p = g.add_positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
    const int m = g.add_mesh(json::array({{{"attributes", {{"POSITION", p}}}}}));
    g.add_node({{"mesh", m}, {"rotation", {0, 0, s * scale, s * scale}}});
    g.write_gltf(dir / "q.gltf");
    positions.push_back(io::load_gltf(dir / "q.gltf").meshes.at(0).positions);
  }
  expect_vec3(positions[0][1], {0, 1, 0});  // 90 degrees about Z
  for (size_t k = 1; k < positions.size(); ++k)
    for (size_t v = 0; v < 3; ++v) expect_vec3(positions[k][v], positions[0][v], 1e-6f);
}

TEST(GltfLoader, MatrixTransformAndNegativeScaleKeepsFacing) {
  ScratchDir dir("mat");
  MiniGltf g;
  const int p = g.add_positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  const int m = g.add_mesh(json::array({{{"attributes", {{"POSITION", p}}}}}));
  g.add_node({{"mesh", m}, {"matrix", {-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 5, 6, 7, 1}}});
  g.write_gltf(dir / "m.gltf");
  const Scene scene = io::load_gltf(dir / "m.gltf");
  const Mesh& mesh = scene.meshes[0];
  expect_vec3(mesh.positions[1], {4, 6, 7});
  // Mirroring flips the winding so the geometric normal still faces +Z.
  const vec3 a = mesh.positions[mesh.indices[0]], b = mesh.positions[mesh.indices[1]], c = mesh.positions[mesh.indices[2]];
  EXPECT_GT(glm::cross(b - a, c - a).z, 0.0f);
}

TEST(GltfLoader, GpuInstancesArePlacedInTheirNodesSpace) {
  // EXT_mesh_gpu_instancing: instance k at node_world * T_k * R_k * S_k. The node moves by
  // (0, 0, -5); instance 0 moves by (2, 0, 0); instance 1 turns 90 degrees about Z (rotation as
  // normalized shorts, which the extension allows) and mirrors in x (scale -1, 1, 1).
  ScratchDir dir("inst");
  // The file, with `edit` applied to its instancing attributes before it is written.
  const auto write = [&](const std::string& name, const std::function<void(MiniGltf&, json&)>& edit) {
    MiniGltf g;
    const int p = g.add_positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
    const int m = g.add_mesh(json::array({{{"attributes", {{"POSITION", p}}}}}));
    const std::vector<float> t = {2, 0, 0, 0, 0, 0};
    const int16_t q = 23170;  // sqrt(0.5) as a normalized short
    const std::vector<int16_t> r = {0, 0, 0, 32767, 0, 0, q, q};
    const std::vector<float> sc = {1, 1, 1, -1, 1, 1};
    json attributes = {{"TRANSLATION", g.add_accessor(g.add_view(t), 5126, 2, "VEC3")},
                       {"ROTATION", g.add_accessor(g.add_view(r), 5122, 2, "VEC4", 0, true)},
                       {"SCALE", g.add_accessor(g.add_view(sc), 5126, 2, "VEC3")}};
    edit(g, attributes);
    g.add_node({{"mesh", m}, {"translation", {0, 0, -5}},
                {"extensions", {{"EXT_mesh_gpu_instancing", {{"attributes", attributes}}}}}});
    g.doc["extensionsUsed"] = {"EXT_mesh_gpu_instancing"};
    g.doc["extensionsRequired"] = {"EXT_mesh_gpu_instancing"};
    g.write_gltf(dir / name);
  };
  write("i.gltf", [](MiniGltf&, json&) {});
  const Scene scene = io::load_gltf(dir / "i.gltf");
  ASSERT_EQ(scene.meshes.size(), 2u);
  for (const std::string& w : scene.warnings) EXPECT_EQ(w.find("EXT_mesh_gpu_instancing"), std::string::npos) << w;
  const Mesh& a = scene.meshes[0];
  const Mesh& b = scene.meshes[1];
  EXPECT_EQ(a.instance, 0);
  EXPECT_EQ(b.instance, 1);
  EXPECT_EQ(a.node, 0);
  EXPECT_EQ(b.node, 0);
  expect_vec3(a.positions[1], {3, 0, -5});
  EXPECT_FALSE(a.mirrored);
  // (1, 0, 0) mirrors to (-1, 0, 0) and turns to (0, -1, 0); (0, 1, 0) turns to (-1, 0, 0).
  expect_vec3(b.positions[1], {0, -1, -5}, 1e-4f);
  expect_vec3(b.positions[2], {-1, 0, -5}, 1e-4f);
  EXPECT_TRUE(b.mirrored);
  ASSERT_EQ(scene.instances.at(0).size(), 2u);
  EXPECT_LT(glm::determinant(dmat3(scene.instances.at(0)[1])), 0.0);
  // Mirrored, the triangle is reversed so that it still faces +Z as the file says.
  const vec3 b0 = b.positions[b.indices[0]], b1 = b.positions[b.indices[1]], b2 = b.positions[b.indices[2]];
  EXPECT_GT(glm::cross(b1 - b0, b2 - b0).z, 0.0f);

  // Attributes of different counts, a rotation of length zero and an accessor out of range are
  // refused by path.
  write("counts.gltf", [](MiniGltf& g, json& attributes) {
    const std::vector<float> three = {0, 0, 0, 1, 0, 0, 2, 0, 0};
    attributes["TRANSLATION"] = g.add_accessor(g.add_view(three), 5126, 3, "VEC3");
  });
  EXPECT_NE(test::input_error([&] { (void)io::load_gltf(dir / "counts.gltf"); })
                .find("/nodes/0/extensions/EXT_mesh_gpu_instancing/attributes/ROTATION: has 2 instances where the "
                      "node's other instancing attributes have 3"),
            std::string::npos);
  write("zero.gltf", [](MiniGltf& g, json& attributes) {
    const std::vector<float> none = {0, 0, 0, 0, 0, 0, 0, 1};
    attributes["ROTATION"] = g.add_accessor(g.add_view(none), 5126, 2, "VEC4");
  });
  EXPECT_NE(test::input_error([&] { (void)io::load_gltf(dir / "zero.gltf"); })
                .find("ROTATION: instance 0's quaternion has length zero"),
            std::string::npos);
  write("range.gltf", [](MiniGltf&, json& attributes) { attributes["SCALE"] = 99; });
  EXPECT_NE(test::input_error([&] { (void)io::load_gltf(dir / "range.gltf"); })
                .find("/nodes/0/extensions/EXT_mesh_gpu_instancing/attributes/SCALE: refers to accessors[99]"),
            std::string::npos);
}

TEST(GltfLoader, ASkinnedTriangleKeepsFacingTheWayTheFileSaysUnderMirroringJoints) {
  // Bound to one joint scaled (-1, 1, 1), the triangle (facing +Z) mirrors; its corners are
  // reversed so that it still faces +Z. On a node scaled (-1, 1, 1) instead, which skinning
  // ignores, it neither mirrors nor is reversed.
  ScratchDir dir("skin-mirror");
  for (const bool joint_mirrors : {true, false}) {
    MiniGltf g;
    const int pos = g.add_positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
    const std::vector<uint8_t> joints(12, 0);
    const std::vector<float> weights = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    const int m = g.add_mesh(json::array({{{"attributes",
                                            {{"POSITION", pos},
                                             {"JOINTS_0", g.add_accessor(g.add_view(joints), 5121, 3, "VEC4")},
                                             {"WEIGHTS_0", g.add_accessor(g.add_view(weights), 5126, 3, "VEC4")}}}}}));
    g.add_node({{"mesh", m}, {"skin", 0}, {"scale", {joint_mirrors ? 1 : -1, 1, 1}}});
    g.add_node({{"scale", {joint_mirrors ? -1 : 1, 1, 1}}});
    g.doc["skins"] = json::array({{{"joints", {1}}}});
    g.write_gltf(dir / "m.gltf");
    const Scene scene = io::load_gltf(dir / "m.gltf");
    const Mesh& mesh = scene.meshes[0];
    expect_vec3(mesh.positions[1], {joint_mirrors ? -1.0f : 1.0f, 0, 0});
    const vec3 a = mesh.positions[mesh.indices[0]], b = mesh.positions[mesh.indices[1]], c = mesh.positions[mesh.indices[2]];
    EXPECT_GT(glm::cross(b - a, c - a).z, 0.0f) << (joint_mirrors ? "mirroring joint" : "mirroring node");
  }
}

TEST(GltfLoader, EveryComponentTypeStrideAndNormalisation) {
  ScratchDir dir("acc");
  MiniGltf g;
  // Interleaved position (3 floats) + normal (3 normalized bytes + 1 pad) with stride 16.
  struct V { float p[3]; int8_t n[4]; };
  std::vector<V> verts = {{{0, 0, 0}, {0, 0, 127, 0}}, {{1, 0, 0}, {0, 0, 127, 0}}, {{0, 1, 0}, {0, -128, 0, 0}}};
  const int view = g.add_view(verts.data(), verts.size() * sizeof(V), sizeof(V));
  const int pos = g.add_accessor(view, 5126, 3, "VEC3");
  g.doc["accessors"][pos]["min"] = {0, 0, 0};
  g.doc["accessors"][pos]["max"] = {1, 1, 0};
  const int nrm = g.add_accessor(view, 5120, 3, "VEC3", 12, true);
  // UVs as normalized unsigned shorts, then as normalized unsigned bytes.
  std::vector<uint16_t> uv16 = {0, 0, 65535, 0, 0, 32768};
  const int uv_a = g.add_accessor(g.add_view(uv16), 5123, 3, "VEC2", 0, true);
  std::vector<uint8_t> uv8 = {0, 0, 255, 0, 0, 51, 0, 0};
  const int uv_b = g.add_accessor(g.add_view(uv8), 5121, 3, "VEC2", 0, true);
  std::vector<uint8_t> i8 = {0, 1, 2, 0};
  std::vector<uint16_t> i16 = {2, 1, 0, 0};
  std::vector<uint32_t> i32 = {0, 2, 1};
  const int ia = g.add_accessor(g.add_view(i8), 5121, 3, "SCALAR");
  const int ib = g.add_accessor(g.add_view(i16), 5123, 3, "SCALAR");
  const int ic = g.add_accessor(g.add_view(i32), 5125, 3, "SCALAR");
  g.doc["materials"] = json::array({{{"name", "uv1"}, {"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 1}}}}}});
  const int m = g.add_mesh(json::array({
      {{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}, {"TEXCOORD_0", uv_a}}}, {"indices", ia}},
      {{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv_b}}}, {"indices", ib}},
      {{"attributes", {{"POSITION", pos}}}, {"indices", ic}, {"material", 0}},
  }));
  g.add_node({{"mesh", m}});
  // Normals of normalized bytes are KHR_mesh_quantization's; the core allows only floats.
  g.doc["extensionsUsed"] = {"KHR_mesh_quantization"};
  g.doc["extensionsRequired"] = {"KHR_mesh_quantization"};
  g.write_gltf(dir / "a.gltf");
  const Scene scene = io::load_gltf(dir / "a.gltf");
  ASSERT_EQ(scene.meshes.size(), 3u);
  const Mesh& a = scene.meshes[0];
  ASSERT_EQ(a.normals.size(), 3u);
  expect_vec3(a.normals[0], {0, 0, 1});
  expect_vec3(a.normals[2], {0, -1, 0});  // -128 clamps to -1
  ASSERT_EQ(a.uvs.size(), 3u);
  EXPECT_NEAR(a.uvs[1].x, 1.0f, 1e-6f);
  EXPECT_NEAR(a.uvs[2].y, 32768.0f / 65535.0f, 1e-6f);
  EXPECT_EQ(a.indices, (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_NEAR(scene.meshes[1].uvs[2].y, 0.2f, 1e-6f);
  EXPECT_EQ(scene.meshes[1].indices, (std::vector<uint32_t>{2, 1, 0}));
  EXPECT_EQ(scene.meshes[2].indices, (std::vector<uint32_t>{0, 2, 1}));
  EXPECT_EQ(scene.meshes[2].material, 0);
}

TEST(GltfLoader, SparseAccessorAndAccessorWithoutView) {
  ScratchDir dir("sparse");
  MiniGltf g;
  std::vector<float> base = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const int pos = g.add_positions(base);
  std::vector<uint16_t> sidx = {1, 0};
  std::vector<float> sval = {5, 5, 5};
  const int iv = g.add_view(sidx);
  const int vv = g.add_view(sval);
  g.doc["accessors"][pos]["sparse"] = {{"count", 1}, {"indices", {{"bufferView", iv}, {"componentType", 5123}}},
                                       {"values", {{"bufferView", vv}}}};
  g.doc["accessors"][pos]["max"] = {5, 5, 5};
  const int m = g.add_mesh(json::array({{{"attributes", {{"POSITION", pos}}}}}));
  g.add_node({{"mesh", m}});
  g.write_gltf(dir / "s.gltf");
  const Scene scene = io::load_gltf(dir / "s.gltf");
  expect_vec3(scene.meshes[0].positions[1], {5, 5, 5});
  expect_vec3(scene.meshes[0].positions[2], {0, 1, 0});
}

TEST(GltfLoader, SparseIndicesAreSubstituted) {
  // A quad's second triangle written as a copy of the first, corrected by sparse substitution
  // (glTF 2.0 §3.6.2.3 applies to every accessor, indices too).
  ScratchDir dir("sparse-indices");
  MiniGltf g;
  const int pos = g.add_positions({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});
  std::vector<uint16_t> dense = {0, 1, 2, 0, 1, 2};
  const int idx = g.add_accessor(g.add_view(dense), 5123, 6, "SCALAR");
  std::vector<uint8_t> where = {4, 5, 0, 0};
  std::vector<uint16_t> values = {2, 3};
  g.doc["accessors"][idx]["sparse"] = {{"count", 2},
                                       {"indices", {{"bufferView", g.add_view(where)}, {"componentType", 5121}}},
                                       {"values", {{"bufferView", g.add_view(values)}}}};
  g.add_node({{"mesh", g.add_mesh(json::array({{{"attributes", {{"POSITION", pos}}}, {"indices", idx}}}))}});
  g.write_gltf(dir / "q.gltf");
  const Scene scene = io::load_gltf(dir / "q.gltf");
  ASSERT_EQ(scene.meshes.size(), 1u);
  EXPECT_EQ(scene.meshes[0].indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
  for (const std::string& w : scene.warnings) EXPECT_EQ(w.find("sparse index"), std::string::npos) << w;
}

TEST(GltfLoader, ZeroLengthNormalsFallBackToTheGeometricNormalWithAWarning) {
  ScratchDir dir("zero-normals");
  MiniGltf g;
  const int pos = g.add_positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  std::vector<float> normals = {0, 0, 1, 0, 0, 0, 0, 0, 1};
  const int nrm = g.add_accessor(g.add_view(normals), 5126, 3, "VEC3");
  g.add_node({{"mesh", g.add_mesh(json::array({{{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}}}}}))}});
  g.write_gltf(dir / "z.gltf");
  const Scene scene = io::load_gltf(dir / "z.gltf");
  ASSERT_EQ(scene.meshes.size(), 1u);
  EXPECT_TRUE(scene.meshes[0].normals.empty()) << "shaded with the geometric normal";
  EXPECT_TRUE(scene.meshes[0].file_normals_dropped) << "a provider importing the file itself refuses it";
  const auto named = std::count_if(scene.warnings.begin(), scene.warnings.end(), [](const std::string& w) {
    return w.find("/meshes/0/primitives/0/attributes/NORMAL: 1 of the 3 vertex normals have length zero") !=
           std::string::npos;
  });
  EXPECT_EQ(named, 1) << fmt::format("{}", fmt::join(scene.warnings, "\n"));
}

TEST(GltfLoader, QuantizedPositionsLoadWithKhrMeshQuantization) {
  ScratchDir dir("quantized");
  MiniGltf g;
  // Integer positions (not normalized) scaled by the node, as KHR_mesh_quantization allows.
  std::vector<int16_t> xyz = {0, 0, 0, 1000, 0, 0, 0, 1000, 0, 0};
  const int pos = g.add_accessor(g.add_view(xyz.data(), 9 * sizeof(int16_t)), 5122, 3, "VEC3");
  g.doc["accessors"][pos]["min"] = {0, 0, 0};
  g.doc["accessors"][pos]["max"] = {1000, 1000, 0};
  g.add_node({{"mesh", g.add_mesh(json::array({{{"attributes", {{"POSITION", pos}}}}}))},
              {"scale", {0.001, 0.001, 0.001}}});
  g.write_gltf(dir / "plain.gltf");
  EXPECT_THROW((void)io::load_gltf(dir / "plain.gltf"), InputError) << "integer positions need the extension";
  g.doc["extensionsUsed"] = {"KHR_mesh_quantization"};
  g.doc["extensionsRequired"] = {"KHR_mesh_quantization"};
  g.write_gltf(dir / "q.gltf");
  const Scene scene = io::load_gltf(dir / "q.gltf");
  ASSERT_EQ(scene.meshes.size(), 1u);
  expect_vec3(scene.meshes[0].positions[1], {1, 0, 0});
  expect_vec3(scene.meshes[0].positions[2], {0, 1, 0});
}

TEST(GltfLoader, ASkinWithoutInverseBindMatricesLoads) {
  // inverseBindMatrices is optional in glTF 2.0 (identity matrices). A primitive without JOINTS_0
  // and WEIGHTS_0 stays in the skin's bind space, where its vertices are, with a note.
  ScratchDir dir("skin");
  for (const char* name : {"s.gltf", "s.glb"}) {
    MiniGltf g;
    g.add_triangle();
    g.add_node({{"translation", {0, 1, 0}}}, false);
    g.doc["nodes"][0]["skin"] = 0;
    g.doc["nodes"][0]["children"] = {1};
    g.doc["skins"] = json::array({{{"joints", {1}}}});
    if (std::string(name).ends_with(".glb")) g.write_glb(dir / name);
    else g.write_gltf(dir / name);
    const Scene scene = io::load_gltf(dir / name);
    ASSERT_EQ(scene.meshes.size(), 1u) << name;
    expect_vec3(scene.meshes[0].positions[1], {1, 0, 0});
    EXPECT_EQ(std::count_if(scene.warnings.begin(), scene.warnings.end(),
                            [](const std::string& w) {
                              return w.find("without JOINTS_0 and WEIGHTS_0 is placed in its skin's bind space") !=
                                     std::string::npos;
                            }),
              1)
        << name;
  }
}

TEST(GltfLoader, ASkinnedMeshIsPosedByItsJoints) {
  // glTF 2.0 §3.7.3: vertex v goes to sum_i w_i * world(joint_i) * inverseBind_i * v, and the
  // skinned node's own transform is not used. Joint 0 stands at (0, 0, 0), joint 1 at (0, 1, 0) is
  // turned 90 degrees about Z; both were bound where they stand unturned (inverse binds: identity
  // and a translation by (0, -1, 0)).
  ScratchDir dir("skin-pose");
  MiniGltf g;
  const int pos = g.add_positions({0, 0, 0, 1, 1, 0, 0, 2, 0});
  const std::vector<uint8_t> joints = {0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0};
  const std::vector<float> weights = {1, 0, 0, 0, 1, 0, 0, 0, 0.5f, 0.5f, 0, 0};
  const int ja = g.add_accessor(g.add_view(joints), 5121, 3, "VEC4");
  const int wa = g.add_accessor(g.add_view(weights), 5126, 3, "VEC4");
  const std::vector<float> ibm = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1,
                                  1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1};
  const int ia = g.add_accessor(g.add_view(ibm), 5126, 2, "MAT4");
  const int m = g.add_mesh(json::array({{{"attributes", {{"POSITION", pos}, {"JOINTS_0", ja}, {"WEIGHTS_0", wa}}}}}));
  // Node 0: the skinned mesh, moved by (100, 0, 0), which skinning ignores. Nodes 1 and 2: the joints.
  g.add_node({{"mesh", m}, {"skin", 0}, {"translation", {100, 0, 0}}});
  const double s = std::sqrt(0.5);
  g.add_node({{"children", {2}}});
  g.add_node({{"translation", {0, 1, 0}}, {"rotation", {0, 0, s, s}}}, false);
  g.doc["skins"] = json::array({{{"joints", {1, 2}}, {"inverseBindMatrices", ia}}});
  g.write_gltf(dir / "p.gltf");
  const Scene scene = io::load_gltf(dir / "p.gltf");
  ASSERT_EQ(scene.meshes.size(), 1u);
  const Mesh& mesh = scene.meshes[0];
  // Vertex 0 follows joint 0 (in place). Vertex 1, (1, 1, 0), is (1, 0, 0) from joint 1, which
  // turns it to (0, 1, 0) there: (0, 2, 0). Vertex 2, (0, 2, 0), is (0, 1, 0) from joint 1, turned
  // to (-1, 0, 0): (-1, 1, 0); half of that and half of (0, 2, 0) is (-0.5, 1.5, 0).
  expect_vec3(mesh.positions[0], {0, 0, 0});
  expect_vec3(mesh.positions[1], {0, 2, 0});
  expect_vec3(mesh.positions[2], {-0.5f, 1.5f, 0});
  for (const std::string& w : scene.warnings) {
    EXPECT_EQ(w.find("skeletal"), std::string::npos) << w;
    EXPECT_EQ(w.find("JOINTS_0"), std::string::npos) << w;
  }

  // Weights that do not sum to 1 are normalized (vertex 2's (2, 2) is its (0.5, 0.5)).
  std::vector<float> doubled = weights;
  for (float& w : doubled) w *= 2.0f;
  {
    MiniGltf h = g;
    h.doc["meshes"][0]["primitives"][0]["attributes"]["WEIGHTS_0"] = h.add_accessor(h.add_view(doubled), 5126, 3, "VEC4");
    h.doc.erase("buffers");
    h.write_gltf(dir / "doubled.gltf");
    const Scene d = io::load_gltf(dir / "doubled.gltf");
    expect_vec3(d.meshes[0].positions[2], {-0.5f, 1.5f, 0});
  }

  // A joint index past the skin's joints is refused by path.
  g.doc["skins"][0]["joints"] = {1};
  g.doc["skins"][0].erase("inverseBindMatrices");
  g.write_gltf(dir / "q.gltf");
  EXPECT_NE(test::input_error([&] { (void)io::load_gltf(dir / "q.gltf"); })
                .find("/meshes/0/primitives/0/attributes/JOINTS_0: vertex 1 names joint 1 of skin 0, which has 1 joints"),
            std::string::npos);
}

TEST(GltfLoader, AnImageDataUriOfAnExtensionsTypeLoads) {
  // EXT_texture_webp and KHR_texture_basisu name images of other types beside a PNG fallback.
  ScratchDir dir("webp");
  MiniGltf g;
  g.add_triangle();
  g.doc["images"] = json::array({{{"uri", "data:image/webp;base64,UklGRg=="}}});
  g.doc["extensionsUsed"] = {"EXT_texture_webp"};
  g.write_gltf(dir / "w.gltf");
  EXPECT_EQ(io::load_gltf(dir / "w.gltf").meshes.size(), 1u);
}

TEST(GltfLoader, APrimitiveWhosePositionsAreAllZeroIsSkippedWithAWarning) {
  // Without a bufferView or sparse values every vertex is (0, 0, 0): nothing of it can be seen,
  // whatever count it declares, so it is neither read nor rendered.
  ScratchDir dir("zeros");
  MiniGltf g;
  g.add_triangle();
  g.doc["accessors"].push_back({{"componentType", 5126}, {"count", 300000000}, {"type", "VEC3"}});
  g.doc["meshes"][0]["primitives"].push_back({{"attributes", {{"POSITION", 1}}}});
  g.write_gltf(dir / "z.gltf");
  const Scene scene = io::load_gltf(dir / "z.gltf");
  ASSERT_EQ(scene.meshes.size(), 1u);
  EXPECT_EQ(scene.triangle_count(), 1u);
  const auto named = std::count_if(scene.warnings.begin(), scene.warnings.end(), [](const std::string& w) {
    return w.find("/meshes/0/primitives/1/attributes/POSITION: accessor 1 has no bufferView") != std::string::npos;
  });
  EXPECT_EQ(named, 1) << fmt::format("{}", fmt::join(scene.warnings, "\n"));
}

TEST(GltfLoader, ZeroAreaTrianglesBesideRealOnesAreKeptAndCounted) {
  ScratchDir dir("zeroarea");
  MiniGltf g;
  const int pos = g.add_positions({0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0});
  std::vector<uint16_t> idx = {0, 1, 2, 0, 1, 3, 2, 2, 2};  // a triangle, one on a line, one at a point
  const int ia = g.add_accessor(g.add_view(idx), 5123, idx.size(), "SCALAR");
  g.add_node({{"mesh", g.add_mesh(json::array({{{"attributes", {{"POSITION", pos}}}, {"indices", ia}}}))}});
  g.write_gltf(dir / "z.gltf");
  const Scene scene = io::load_gltf(dir / "z.gltf");
  EXPECT_EQ(scene.triangle_count(), 3u);
  EXPECT_EQ(scene.zero_area_triangle_count(), 2u);
  EXPECT_TRUE(scene.has_triangle_with_area());
}

TEST(GltfLoader, StripsAndFansAreTriangulated) {
  ScratchDir dir("strip");
  MiniGltf g;
  const int pos = g.add_positions({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 2, 0, 0});
  std::vector<uint16_t> idx = {0, 1, 2, 3, 4};
  const int ia = g.add_accessor(g.add_view(idx), 5123, 5, "SCALAR");
  const int m = g.add_mesh(json::array({{{"attributes", {{"POSITION", pos}}}, {"indices", ia}, {"mode", 5}},
                                        {{"attributes", {{"POSITION", pos}}}, {"mode", 6}}}));
  g.add_node({{"mesh", m}});
  g.write_gltf(dir / "st.gltf");
  const Scene scene = io::load_gltf(dir / "st.gltf");
  ASSERT_EQ(scene.meshes.size(), 2u);
  EXPECT_EQ(scene.meshes[0].indices, (std::vector<uint32_t>{0, 1, 2, 2, 1, 3, 2, 3, 4}));
  EXPECT_EQ(scene.meshes[1].indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 0, 3, 4}));
  EXPECT_EQ(scene.triangle_count(), 6u);
}

TEST(GltfLoader, ExternalEmbeddedAndBinaryContainersAgree) {
  ScratchDir dir("forms");
  std::vector<Scene> scenes;
  for (int form = 0; form < 3; ++form) {
    MiniGltf g;
    g.add_triangle();
    const auto path = dir / ("f" + std::to_string(form) + (form == 2 ? ".glb" : ".gltf"));
    if (form == 0) g.write_gltf(path);
    if (form == 1) g.write_gltf_embedded(path);
    if (form == 2) g.write_glb(path);
    scenes.push_back(io::load_gltf(path));
  }
  for (const Scene& s : scenes) {
    ASSERT_EQ(s.meshes.size(), 1u);
    EXPECT_EQ(s.meshes[0].positions, scenes[0].meshes[0].positions);
    EXPECT_EQ(s.meshes[0].indices, scenes[0].meshes[0].indices);
  }
}

TEST(GltfLoader, UrisAreRelativeToTheSceneFolderWithSubfoldersAndDotDot) {
  ScratchDir dir("uris");
  std::filesystem::create_directories(dir / "pack" / "scenes");
  std::filesystem::create_directories(dir / "pack" / "data" / "bin");
  MiniGltf g;
  g.add_triangle();
  g.finish_buffer("../data/bin/tri%20angle.bin");
  MiniGltf::write_bytes(dir / "pack" / "data" / "bin" / "tri angle.bin", g.bin);
  MiniGltf::write_text(dir / "pack" / "scenes" / "up.gltf", g.doc.dump());
  EXPECT_EQ(io::load_gltf(dir / "pack" / "scenes" / "up.gltf").triangle_count(), 1u);

  g.doc["buffers"][0]["uri"] = "scenes/../data/bin/tri%20angle.bin";
  MiniGltf::write_text(dir / "pack" / "down.gltf", g.doc.dump());
  EXPECT_EQ(io::load_gltf(dir / "pack" / "down.gltf").triangle_count(), 1u);

  // A '+' in a URI's path is the character itself (RFC 3986), not a blank as in a query string.
  MiniGltf::write_bytes(dir / "pack" / "data" / "a+b.bin", g.bin);
  g.doc["buffers"][0]["uri"] = "data/a+b.bin";
  MiniGltf::write_text(dir / "pack" / "plus.gltf", g.doc.dump());
  EXPECT_EQ(io::load_gltf(dir / "pack" / "plus.gltf").triangle_count(), 1u);
}

TEST(GltfLoader, ATextureTransformIsAppliedToTheTextureCoordinates) {
  // KHR_texture_transform's example: rotation pi/2, scale 0.5, offset (0, 1) maps the unit square
  // onto the lower left quadrant of the image, (1, 0) -> (0, 0.5) and (0, 1) -> (0.5, 1). Its
  // texCoord picks TEXCOORD_1 over the textureInfo's TEXCOORD_0.
  ScratchDir dir("texture-transform");
  MiniGltf g;
  const int pos = g.add_positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  std::vector<float> uv0 = {9, 9, 9, 9, 9, 9}, uv1 = {0, 0, 1, 0, 0, 1};
  const int a0 = g.add_accessor(g.add_view(uv0), 5126, 3, "VEC2");
  const int a1 = g.add_accessor(g.add_view(uv1), 5126, 3, "VEC2");
  const uint8_t px[] = {255, 255, 255, 255};
  const std::vector<unsigned char> png = io::encode_png(px, 1, 1, 4);
  g.doc["images"] = json::array({{{"bufferView", g.add_view(png.data(), png.size())}, {"mimeType", "image/png"}}});
  g.doc["textures"] = json::array({{{"source", 0}}});
  g.doc["materials"] = json::array(
      {{{"pbrMetallicRoughness",
         {{"baseColorTexture",
           {{"index", 0},
            {"extensions",
             {{"KHR_texture_transform",
               {{"offset", {0, 1}}, {"rotation", 1.57079632679}, {"scale", {0.5, 0.5}}, {"texCoord", 1}}}}}}}}}}});
  g.add_node({{"mesh", g.add_mesh(json::array({{{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", a0}, {"TEXCOORD_1", a1}}},
                                                 {"material", 0}}}))}});
  g.doc["extensionsUsed"] = {"KHR_texture_transform"};
  g.doc["extensionsRequired"] = {"KHR_texture_transform"};
  g.write_gltf(dir / "t.gltf");
  const Scene scene = io::load_gltf(dir / "t.gltf");
  ASSERT_EQ(scene.meshes.size(), 1u);
  EXPECT_EQ(scene.materials[0].texcoord, 1);
  EXPECT_TRUE(scene.materials[0].has_uv_transform());
  const std::vector<vec2>& uv = scene.meshes[0].uvs;
  ASSERT_EQ(uv.size(), 3u);
  const vec2 want[] = {{0.0f, 1.0f}, {0.0f, 0.5f}, {0.5f, 1.0f}};
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(uv[i].x, want[i].x, 1e-6) << i;
    EXPECT_NEAR(uv[i].y, want[i].y, 1e-6) << i;
  }
  for (const std::string& w : scene.warnings) EXPECT_EQ(w.find("KHR_texture_transform"), std::string::npos) << w;

  // A finite transform that takes the coordinates beyond a float's range is refused by name (the
  // coordinates were infinite: POV-Ray failed on 'inf', the ray tracer read texel 0).
  g.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"]["scale"] =
      {1e39, 1};
  g.write_gltf(dir / "huge.gltf");
  const std::string huge = test::input_error([&] { (void)io::load_gltf(dir / "huge.gltf"); });
  EXPECT_NE(huge.find("KHR_texture_transform: takes the texture coordinates of /meshes/0/primitives/0 beyond the "
                      "range of a float"),
            std::string::npos)
      << huge;
  // A malformed transform names itself.
  g.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"]["scale"] =
      {1, 2, 3};
  g.write_gltf(dir / "bad.gltf");
  const std::string bad = test::input_error([&] { (void)io::load_gltf(dir / "bad.gltf"); });
  EXPECT_NE(bad.find("/materials/0/pbrMetallicRoughness/baseColorTexture/extensions/KHR_texture_transform/scale"),
            std::string::npos)
      << bad;
}

TEST(GltfLoader, AnImageThatIsNoImageIsNotQuotedInTheError) {
  ScratchDir dir("notimage");
  std::filesystem::create_directories(dir / "scene");
  MiniGltf::write_text(dir / "notes.txt", "user:secret-token:1000:1000\n");
  MiniGltf g;
  const int pos = g.add_positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  std::vector<float> uv = {0, 0, 1, 0, 0, 1};
  const int uva = g.add_accessor(g.add_view(uv), 5126, 3, "VEC2");
  g.doc["images"] = json::array({{{"uri", "../notes.txt"}}});
  g.doc["textures"] = json::array({{{"source", 0}}});
  g.doc["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}});
  const int m = g.add_mesh(json::array({{{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uva}}}, {"material", 0}}}));
  g.add_node({{"mesh", m}});
  g.write_gltf(dir / "scene" / "s.gltf");
  const std::string msg = test::input_error([&] { (void)io::load_gltf(dir / "scene" / "s.gltf"); });
  EXPECT_NE(msg.find("/images/0: cannot decode the image"), std::string::npos) << msg;
  EXPECT_NE(msg.find("it holds text, not image data"), std::string::npos) << msg;
  EXPECT_EQ(msg.find("secret-token"), std::string::npos) << "the file's contents are quoted: " << msg;
  EXPECT_EQ(msg.find("75 73 65 72"), std::string::npos) << "the file's contents are quoted: " << msg;
}

TEST(GltfLoader, OnlyTheRigsCameraNeedsAViewingDirection) {
  ScratchDir dir("cams");
  MiniGltf g;
  g.add_triangle();
  g.doc["cameras"] = json::array({{{"type", "perspective"}, {"perspective", {{"yfov", 0.7}, {"znear", 0.1}}}}});
  g.add_node({{"name", "main"}, {"camera", 0}, {"translation", {0, 0, 3}}});
  // A second camera hidden by a zero scale, as exporters do: not used, so not refused.
  g.add_node({{"name", "hidden"}, {"camera", 0}, {"scale", {0, 0, 0}}});
  g.write_gltf(dir / "two.gltf");
  const Scene scene = io::load_gltf(dir / "two.gltf");
  ASSERT_EQ(scene.cameras.size(), 2u);
  EXPECT_EQ(scene.cameras.front().name, "main");
}

TEST(GltfLoader, BaseColourFactorAndEmbeddedTextureAreLinear) {
  ScratchDir dir("tex");
  MiniGltf g;
  const int pos = g.add_positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  std::vector<float> uv = {0, 0, 1, 0, 0, 1};
  const int uva = g.add_accessor(g.add_view(uv), 5126, 3, "VEC2");
  // 2x1 sRGB texture: code 128 grey and pure red.
  const uint8_t px[] = {128, 128, 128, 255, 255, 0, 0, 255};
  const std::vector<unsigned char> png = io::encode_png(px, 2, 1, 4);
  const int iv = g.add_view(png.data(), png.size());
  g.doc["images"] = json::array({{{"bufferView", iv}, {"mimeType", "image/png"}}});
  g.doc["samplers"] = json::array({{{"wrapS", 33071}, {"wrapT", 10497}}});
  g.doc["textures"] = json::array({{{"source", 0}, {"sampler", 0}}});
  g.doc["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.25, 1, 1}},
                                                                {"baseColorTexture", {{"index", 0}}}}},
                                     {"doubleSided", true}}});
  const int m = g.add_mesh(json::array({{{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uva}}}, {"material", 0}}}));
  g.add_node({{"mesh", m}});
  g.write_glb(dir / "t.glb");
  const Scene scene = io::load_gltf(dir / "t.glb");
  ASSERT_EQ(scene.materials.size(), 1u);
  const Material& mat = scene.materials[0];
  EXPECT_EQ(mat.base_color, vec4(0.5f, 0.25f, 1.0f, 1.0f));
  EXPECT_TRUE(mat.double_sided);
  ASSERT_EQ(mat.base_color_texture, 0);
  const Texture& t = scene.textures[0];
  ASSERT_EQ(t.width, 2);
  ASSERT_EQ(t.height, 1);
  EXPECT_NEAR(t.rgba[0], srgb8_to_linear(128), 1e-6f);
  EXPECT_NEAR(t.rgba[4], 1.0f, 1e-6f);
  EXPECT_NEAR(t.rgba[5], 0.0f, 1e-6f);
  EXPECT_FALSE(t.repeat_s);
  EXPECT_TRUE(t.repeat_t);
  ASSERT_EQ(scene.meshes[0].uvs.size(), 3u);
}

TEST(GltfLoader, PunctualLightsCameraAndRigExtras) {
  ScratchDir dir("lights");
  MiniGltf g;
  g.add_triangle();
  g.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  g.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array({
      {{"type", "point"}, {"color", {1, 0.5, 0.25}}, {"intensity", 20}},
      {{"type", "directional"}, {"intensity", 3}},
      {{"type", "spot"}, {"spot", {{"innerConeAngle", 0.1}, {"outerConeAngle", 0.5}}}},
  });
  g.add_node({{"translation", {1, 2, 3}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  // Directional light rotated to point down -Y (90 degrees about +X turns -Z into -Y).
  const double s = std::sqrt(0.5);
  g.add_node({{"rotation", {-s, 0, 0, s}}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
  g.add_node({{"extensions", {{"KHR_lights_punctual", {{"light", 2}}}}}});
  g.doc["cameras"] = json::array({{{"type", "perspective"},
                                   {"perspective", {{"yfov", 0.5}, {"znear", 0.1}, {"zfar", 100}, {"aspectRatio", 2.0}}}}});
  g.add_node({{"name", "cam"}, {"camera", 0}, {"translation", {0, 0, 5}},
              {"extras", {{"stereobench", {{"interaxial", 0.07}, {"convergence", 3.0}, {"width", 640}, {"height", 320}}}}}});
  g.doc["scenes"][0]["extras"] = {{"stereobench", {{"background", {0.1, 0.2, 0.3}}, {"ambient", 0.05}}}};
  g.write_gltf(dir / "l.gltf");
  const Scene scene = io::load_gltf(dir / "l.gltf");
  ASSERT_EQ(scene.lights.size(), 3u);
  EXPECT_EQ(scene.lights[0].type, Light::Type::point);
  expect_vec3(scene.lights[0].position, {1, 2, 3});
  expect_vec3(scene.lights[0].color, {1, 0.5f, 0.25f});
  EXPECT_FLOAT_EQ(scene.lights[0].intensity, 20.0f);
  EXPECT_EQ(scene.lights[1].type, Light::Type::directional);
  expect_vec3(scene.lights[1].direction, {0, -1, 0});
  EXPECT_EQ(scene.lights[2].type, Light::Type::spot);
  EXPECT_FLOAT_EQ(scene.lights[2].outer_cone, 0.5f);
  ASSERT_EQ(scene.cameras.size(), 1u);
  EXPECT_EQ(scene.cameras[0].name, "cam");
  EXPECT_DOUBLE_EQ(scene.cameras[0].yfov, 0.5);
  EXPECT_EQ(scene.rig.width, 640);
  EXPECT_EQ(scene.rig.height, 320);
  EXPECT_DOUBLE_EQ(*scene.rig.interaxial, 0.07);
  expect_vec3(scene.background, {0.1f, 0.2f, 0.3f});
  EXPECT_FLOAT_EQ(scene.ambient, 0.05f);
  const StereoRig rig = resolve_rig(scene, {});
  EXPECT_EQ(rig.params().width, 640);
  EXPECT_DOUBLE_EQ(rig.params().convergence, 3.0);
  EXPECT_DOUBLE_EQ(rig.pose().position.z, 5.0);
}

TEST(GltfLoader, UnsupportedFeaturesAreNamedOnce) {
  ScratchDir dir("unsup");
  MiniGltf g;
  const int pos = g.add_positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  g.doc["materials"] = json::array(
      {{{"normalTexture", {{"index", 0}}}, {"occlusionTexture", {{"index", 0}}}},
       {{"normalTexture", {{"index", 0}}}, {"pbrMetallicRoughness", {{"metallicRoughnessTexture", {{"index", 0}}}}}}});
  std::vector<float> colours = {1, 0, 0, 1, 0, 0, 1, 0, 0};
  const int colour = g.add_accessor(g.add_view(colours), 5126, 3, "VEC3");
  const uint8_t px[] = {255, 255, 255, 255};
  const std::vector<unsigned char> png = io::encode_png(px, 1, 1, 4);
  g.doc["images"] = json::array({{{"bufferView", g.add_view(png.data(), png.size())}, {"mimeType", "image/png"}}});
  // A sampler asking for nearest texels (pixel art), which trilinear filtering smooths.
  g.doc["samplers"] = json::array({{{"magFilter", 9728}, {"minFilter", 9728}}});
  g.doc["textures"] = json::array({{{"source", 0}, {"sampler", 0}}});
  // One material with an extension the file lists in extensionsUsed: named once, not "2 occurrences".
  g.doc["materials"][1]["extensions"] = {{"KHR_materials_unlit", json::object()}};
  g.doc["materials"][0]["pbrMetallicRoughness"] = {{"baseColorTexture", {{"index", 0}}}};
  const int m = g.add_mesh(json::array({{{"attributes", {{"POSITION", pos}, {"COLOR_0", colour}}}, {"material", 0}},
                                        {{"attributes", {{"POSITION", pos}}}, {"material", 1}},
                                        {{"attributes", {{"POSITION", pos}}}, {"mode", 1}}}));
  // A node extension the file does not list in extensionsUsed (glTF requires it to): named too.
  g.add_node({{"mesh", m}, {"extensions", {{"EXT_unknown_thing", {{"a", 1}}}}}});
  g.doc["extensionsUsed"] = {"KHR_materials_unlit"};
  g.write_gltf(dir / "u.gltf");
  const Scene scene = io::load_gltf(dir / "u.gltf");
  EXPECT_EQ(scene.meshes.size(), 2u);
  int normal_warnings = 0, line_warnings = 0, ext_warnings = 0;
  for (const std::string& w : scene.warnings) {
    normal_warnings += w.find("normal textures") != std::string::npos;
    line_warnings += w.find("LINES") != std::string::npos;
    ext_warnings += w.find("KHR_materials_unlit") != std::string::npos;
  }
  EXPECT_EQ(normal_warnings, 1);
  EXPECT_EQ(line_warnings, 1);
  EXPECT_EQ(ext_warnings, 1);
  for (const std::string& w : scene.warnings)
    EXPECT_EQ(w.find("KHR_materials_unlit' is ignored (2 occurrences)"), std::string::npos) << w;
  // Inputs the Lambertian shading does not use are named too.
  for (const char* named : {"vertex colours (COLOR_n) are ignored", "occlusion textures are ignored",
                            "metallic-roughness textures are ignored",
                            "NEAREST texture filtering (textures are filtered trilinearly)",
                            "extension 'EXT_unknown_thing' is ignored (the file uses it without listing it in "
                            "extensionsUsed",
                            // the texture's material on a primitive without TEXCOORD_0
                            "primitives without the texture coordinates they read, TEXCOORD_0 (texture ignored there)"})
    EXPECT_EQ(std::count_if(scene.warnings.begin(), scene.warnings.end(),
                            [&](const std::string& w) { return w.find(named) != std::string::npos; }),
              1)
        << named << " in:\n" << fmt::format("{}", fmt::join(scene.warnings, "\n"));
  bool counted = false;
  for (const std::string& w : scene.warnings) counted |= w.find("normal textures") != std::string::npos && w.find("2 occurrences") != std::string::npos;
  EXPECT_TRUE(counted);
}

TEST(GltfLoader, NodesOutsideTheLoadedSceneAreCounted) {
  // A tool that imports the file whole (Blender) would render them; the loader says how many.
  ScratchDir dir("outside");
  MiniGltf g;
  g.add_triangle();
  const int p = g.add_positions({0, 0, 1, 1, 0, 1, 0, 1, 1});
  const int m = g.add_mesh(json::array({{{"attributes", {{"POSITION", p}}}}}));
  g.add_node({{"mesh", m}}, false);  // in no scene
  g.add_node({{"name", "empty"}}, false);  // nothing to render: not counted
  g.write_gltf(dir / "orphan.gltf");
  const Scene orphan = io::load_gltf(dir / "orphan.gltf");
  EXPECT_EQ(orphan.meshes.size(), 1u);
  EXPECT_EQ(orphan.nodes_not_loaded, 1u);
  EXPECT_NE(fmt::format("{}", fmt::join(orphan.warnings, "\n")).find("1 node(s) with a mesh or light are in no scene"),
            std::string::npos);
  // The same node in a second glTF scene.
  g.doc["scenes"].push_back({{"nodes", {1}}});
  g.write_gltf(dir / "two.gltf");
  const Scene two = io::load_gltf(dir / "two.gltf");
  EXPECT_EQ(two.nodes_not_loaded, 1u);
  MiniGltf one;
  one.add_triangle();
  one.write_gltf(dir / "one.gltf");
  EXPECT_EQ(io::load_gltf(dir / "one.gltf").nodes_not_loaded, 0u);

  // A camera on a node in no scene, and rig extras on a node without a camera: both were ignored
  // without a word, the rig framing the scene from +Z.
  MiniGltf cam;
  cam.add_triangle();
  cam.doc["cameras"] = json::array({{{"type", "perspective"}, {"perspective", {{"yfov", 0.7}, {"znear", 0.1}}}}});
  cam.add_node({{"camera", 0}, {"translation", {0, 0, 3}}}, false);
  cam.doc["nodes"][0]["extras"] = {{"stereobench", {{"interaxial", 0.1}}}};
  cam.write_gltf(dir / "camera.gltf");
  const Scene unplaced = io::load_gltf(dir / "camera.gltf");
  EXPECT_TRUE(unplaced.cameras.empty());
  const std::string said = fmt::format("{}", fmt::join(unplaced.warnings, "\n"));
  EXPECT_NE(said.find("the camera of node 1 is in no loaded scene and is not used"), std::string::npos) << said;
  EXPECT_NE(said.find("/nodes/0/extras/stereobench is on a node without a camera and is ignored"), std::string::npos)
      << said;
}

TEST(GltfLoader, AnUnlitSceneIsWarnedAbout) {
  const ScratchDir dir("unlit");
  const auto unlit_warning = [&](const std::function<void(MiniGltf&)>& edit) -> std::string {
    MiniGltf g;
    g.add_triangle();
    edit(g);
    g.write_gltf(dir / "s.gltf");
    for (const std::string& w : io::load_gltf(dir / "s.gltf").warnings)
      if (w.find("the scene is unlit") != std::string::npos) return w;
    return "";
  };
  const std::string dark = unlit_warning([](MiniGltf&) {});
  EXPECT_NE(dark.find("(no lights, ambient 0): every surface renders black"), std::string::npos) << dark;
  EXPECT_NE(dark.find("s.gltf"), std::string::npos) << dark;
  // The key it names is the one the loader reads (it named extras.ambient, which is ignored).
  EXPECT_NE(dark.find("set the scene's extras.stereobench.ambient"), std::string::npos) << dark;
  const auto light = [](double intensity) {
    return [intensity](MiniGltf& g) {
      g.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array({{{"type", "point"}, {"intensity", intensity}}});
      g.doc["nodes"][0]["extensions"]["KHR_lights_punctual"]["light"] = 0;
    };
  };
  const std::string off = unlit_warning(light(0.0));
  EXPECT_NE(off.find("every light has zero intensity or colour"), std::string::npos) << off;
  EXPECT_EQ(unlit_warning(light(5.0)), "") << "a lit scene";
  EXPECT_EQ(unlit_warning([](MiniGltf& g) { g.doc["scenes"][0]["extras"]["stereobench"]["ambient"] = 0.2; }), "")
      << "ambient light alone";
}

}  // namespace
}  // namespace sb
