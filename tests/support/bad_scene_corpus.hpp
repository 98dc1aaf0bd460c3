// The corpus of broken scene files: each must fail with InputError (exit code 3 from the CLI) and a
// message naming the file and the JSON pointer of the fault, never a crash. The loader's tests
// load them through the library, the command-line tests through `stereobench scenes info`. Its
// helpers live in a namespace of their own (sb::test::bad_scene), apart from the other support
// headers' (write_text, for one).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/mini_gltf.hpp"
#include "support/scratch_dir.hpp"

namespace sb::test::bad_scene {

using nlohmann::json;

struct BadCase {
  std::string name;
  std::string file;                                  ///< file name written into the temp folder
  std::function<void(const std::filesystem::path&)> make;  ///< writes the broken file
  std::string expect;                                ///< substring of the message (JSON pointer etc.)
};

/// Adds a perspective camera node (a root unless `root` is false) with `node` merged in; returns its index.
inline int add_camera(MiniGltf& g, const json& node, bool root = true) {
  g.doc["cameras"] = json::array({{{"type", "perspective"}, {"perspective", {{"yfov", 0.7}, {"znear", 0.1}}}}});
  json n = {{"camera", 0}, {"translation", {0, 0, 3}}};
  n.update(node);
  if (n.contains("matrix")) n.erase("translation");  // a node has a matrix or TRS, not both
  return g.add_node(n, root);
}

/// A valid one-triangle scene with `edit` applied to its JSON before writing.
inline std::function<void(const std::filesystem::path&)> edited(std::function<void(MiniGltf&)> edit,
                                                           int form = 0) {
  return [edit, form](const std::filesystem::path& p) {
    MiniGltf g;
    g.add_triangle();
    edit(g);
    if (form == 0) g.write_gltf(p);
    if (form == 1) g.write_gltf_embedded(p);
    if (form == 2) g.write_glb(p);
  };
}

inline void write_text(const std::filesystem::path& p, const std::string& s) { MiniGltf::write_text(p, s); }

/// Every broken scene file the loader must refuse, with the part of the message naming its fault.
inline std::vector<BadCase> bad_scene_corpus() {
  std::vector<BadCase> c;
  c.push_back({"not_json", "a.gltf", [](auto& p) { write_text(p, "{ \"asset\": { \"version\": \"2.0\" "); }, "not valid JSON at byte 31: parse error at line 1, column 31: syntax error while parsing object - unexpected end of input; expected '}'; the file is cut short or damaged there: export it again, or mend the JSON"});
  c.push_back({"image_as_scene", "a.png", [](auto& p) { write_text(p, std::string("\x89PNG\r\n\x1a\n\0\0\0\rIHDR", 16)); },
               "not a glTF scene (neither glTF JSON nor binary .glb)"});
  c.push_back({"strip_of_two_vertices", "a.gltf", [](auto& p) {
                 MiniGltf g;
                 const int pos = g.add_positions({0, 0, 0, 1, 0, 0});
                 g.add_node({{"mesh", g.add_mesh(json::array({{{"attributes", {{"POSITION", pos}}}, {"mode", 5}}}))}});
                 g.write_gltf(p);
               },
               "/meshes/0/primitives/0: a TRIANGLE_STRIP of 2 vertices has no triangle; it is skipped"});
  c.push_back({"empty_file", "a.gltf", [](auto& p) { write_text(p, ""); }, "empty"});
  c.push_back({"top_level_array", "a.gltf", [](auto& p) { write_text(p, "[1,2,3]"); }, "expected a JSON object"});
  c.push_back({"no_asset", "a.gltf", [](auto& p) { write_text(p, "{}"); }, "/asset: required property is missing"});
  c.push_back({"version_1", "a.gltf", [](auto& p) { write_text(p, R"({"asset":{"version":"1.0"}})"); }, "/asset/version"});
  // glTF: a 2.0 reader must not load a file whose minVersion is later (it loaded, exit 0).
  c.push_back({"min_version_2_1", "a.gltf", edited([](MiniGltf& g) { g.doc["asset"]["minVersion"] = "2.1"; }),
               "/asset/minVersion: the file needs glTF 2.1 at least"});
  c.push_back({"min_version_not_a_version", "a.gltf", edited([](MiniGltf& g) { g.doc["asset"]["minVersion"] = "2"; }),
               "/asset/minVersion: '2' is not a glTF version"});
  c.push_back({"empty_scene", "a.gltf", [](auto& p) { write_text(p, R"({"asset":{"version":"2.0"}})"); }, "no triangles"});
  c.push_back({"empty_node_list", "a.gltf", [](auto& p) { write_text(p, R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[]}],"scene":0})"); }, "no triangles"});
  // Triangles of zero area render as background only, which every comparison passes.
  c.push_back({"all_triangles_zero_area", "a.gltf", edited([](MiniGltf& g) {
    std::vector<uint16_t> idx = {0, 0, 0, 1, 1, 2};
    g.doc["meshes"][0]["primitives"][0]["indices"] = g.add_accessor(g.add_view(idx), 5123, 6, "SCALAR");
  }), "the scene has no triangles to render: every one of its 2 triangles has zero area"});
  c.push_back({"all_triangles_flattened_to_lines", "a.gltf", edited([](MiniGltf& g) { g.doc["nodes"][0]["scale"] = {1, 0, 1}; }),
               "every one of its 1 triangles has zero area"});
  c.push_back({"count_is_string", "a.gltf", edited([](MiniGltf& g) { g.doc["accessors"][0]["count"] = "three"; }), "/accessors/0/count: must be an integer"});
  c.push_back({"count_is_float", "a.gltf", edited([](MiniGltf& g) { g.doc["accessors"][0]["count"] = 3.5; }), "/accessors/0/count"});
  c.push_back({"count_negative", "a.gltf", edited([](MiniGltf& g) { g.doc["accessors"][0]["count"] = -3; }), "/accessors/0/count"});
  c.push_back({"mesh_is_string", "a.gltf", edited([](MiniGltf& g) { g.doc["nodes"][0]["mesh"] = "tri"; }), "/nodes/0/mesh"});
  c.push_back({"translation_wrong_length", "a.gltf", edited([](MiniGltf& g) { g.doc["nodes"][0]["translation"] = {1, 2}; }), "/nodes/0/translation: must have 3 elements"});
  c.push_back({"matrix_has_string", "a.gltf", edited([](MiniGltf& g) { g.doc["nodes"][0]["matrix"] = json::array({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, "x", 0, 1}); }), "/nodes/0/matrix/13"});
  // glTF node matrices are affine; a projective last row was used as it stood.
  c.push_back({"matrix_w_zero", "a.gltf", edited([](MiniGltf& g) { g.doc["nodes"][0]["matrix"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0}; }),
               "/nodes/0/matrix: its last row (elements 3, 7, 11 and 15; glTF matrices are column-major) is (0, 0, 0, 0), not (0, 0, 0, 1)"});
  c.push_back({"matrix_projective_row", "a.gltf", edited([](MiniGltf& g) { g.doc["nodes"][0]["matrix"] = {1, 0, 0, 0.5, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; }),
               "/nodes/0/matrix: its last row (elements 3, 7, 11 and 15; glTF matrices are column-major) is (0.5, 0, 0, 1)"});
  // Node animations: structure and references checked before any is read.
  const json channel0 = {{"sampler", 0}, {"target", {{"node", 0}, {"path", "translation"}}}};
  c.push_back({"animation_channels_not_array", "a.gltf", edited([](MiniGltf& g) { g.doc["animations"] = {{{"channels", 5}, {"samplers", json::array()}}}; }),
               "/animations/0/channels: expected a JSON array"});
  c.push_back({"animation_sampler_out_of_range", "a.gltf", edited([channel0](MiniGltf& g) { g.doc["animations"] = {{{"channels", json::array({channel0})}, {"samplers", json::array()}}}; }),
               "/animations/0/channels/0/sampler: refers to sampler 0 but the animation has 0"});
  c.push_back({"animation_input_out_of_range", "a.gltf", edited([channel0](MiniGltf& g) { g.doc["animations"] = {{{"channels", json::array({channel0})}, {"samplers", {{{"input", 9}, {"output", 0}}}}}}; }),
               "/animations/0/samplers/0/input: refers to accessors[9]"});
  c.push_back({"animation_input_not_scalar", "a.gltf", edited([channel0](MiniGltf& g) { g.doc["animations"] = {{{"channels", json::array({channel0})}, {"samplers", {{{"input", 0}, {"output", 0}}}}}}; }),
               "/animations/0/samplers/0/input: accessor 0 has type VEC3, but SCALAR is needed here"});
  c.push_back({"animation_target_node_out_of_range", "a.gltf", edited([channel0](MiniGltf& g) {
                 json ch = channel0;
                 ch["target"]["node"] = 5;
                 g.doc["animations"] = {{{"channels", json::array({ch})}, {"samplers", {{{"input", 0}, {"output", 0}}}}}};
               }),
               "/animations/0/channels/0/target/node: refers to nodes[5]"});
  c.push_back({"primitives_not_array", "a.gltf", edited([](MiniGltf& g) { g.doc["meshes"][0]["primitives"] = json::object(); }), "/meshes/0/primitives: expected a JSON array"});
  c.push_back({"attributes_missing", "a.gltf", edited([](MiniGltf& g) { g.doc["meshes"][0]["primitives"][0].erase("attributes"); }), "/meshes/0/primitives/0/attributes: required"});
  c.push_back({"no_position", "a.gltf", edited([](MiniGltf& g) { g.doc["meshes"][0]["primitives"][0]["attributes"] = json::object(); }), "/meshes/0/primitives/0/attributes: primitive has no POSITION"});
  c.push_back({"node_mesh_out_of_range", "a.gltf", edited([](MiniGltf& g) { g.doc["nodes"][0]["mesh"] = 7; }), "/nodes/0/mesh: refers to meshes[7]"});
  c.push_back({"scene_node_out_of_range", "a.gltf", edited([](MiniGltf& g) { g.doc["scenes"][0]["nodes"] = {4}; }), "/scenes/0/nodes/0: refers to nodes[4]"});
  c.push_back({"attribute_accessor_out_of_range", "a.gltf", edited([](MiniGltf& g) { g.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 9; }), "/meshes/0/primitives/0/attributes/POSITION: refers to accessors[9]"});
  c.push_back({"material_out_of_range", "a.gltf", edited([](MiniGltf& g) { g.doc["meshes"][0]["primitives"][0]["material"] = 0; }), "/meshes/0/primitives/0/material: refers to materials[0]"});
  c.push_back({"buffer_view_out_of_range", "a.gltf", edited([](MiniGltf& g) { g.doc["accessors"][0]["bufferView"] = 3; }), "/accessors/0/bufferView"});
  c.push_back({"accessor_past_view", "a.gltf", edited([](MiniGltf& g) { g.doc["accessors"][0]["count"] = 4; }), "/accessors/0: 4 elements"});
  c.push_back({"absurd_count", "a.gltf", edited([](MiniGltf& g) { g.doc["accessors"][0]["count"] = 9007199254740992ull; }), "/accessors/0"});
  c.push_back({"count_beyond_2p53", "a.gltf", edited([](MiniGltf& g) { g.doc["accessors"][0]["count"] = 18446744073709551615ull; }), "/accessors/0/count: value"});
  c.push_back({"accessor_offset_past_view", "a.gltf", edited([](MiniGltf& g) { g.doc["accessors"][0]["byteOffset"] = 4; }), "/accessors/0"});
  c.push_back({"view_past_buffer", "a.gltf", edited([](MiniGltf& g) { g.doc["bufferViews"][0]["byteLength"] = 4096; }), "/bufferViews/0"});
  c.push_back({"stride_too_small", "a.gltf", edited([](MiniGltf& g) { g.doc["bufferViews"][0]["byteStride"] = 8; }), "/bufferViews/0/byteStride"});
  c.push_back({"stride_out_of_range", "a.gltf", edited([](MiniGltf& g) { g.doc["bufferViews"][0]["byteStride"] = 2; }), "/bufferViews/0/byteStride: value 2 is out of range"});
  c.push_back({"bad_component_type", "a.gltf", edited([](MiniGltf& g) { g.doc["accessors"][0]["componentType"] = 5124; }), "/accessors/0/componentType"});
  c.push_back({"bad_accessor_type", "a.gltf", edited([](MiniGltf& g) { g.doc["accessors"][0]["type"] = "VEC5"; }), "/accessors/0/type"});
  c.push_back({"position_wrong_type", "a.gltf", edited([](MiniGltf& g) { g.doc["accessors"][0]["type"] = "VEC2"; }), "/meshes/0/primitives/0/attributes/POSITION: accessor 0 is VEC2 of component type 5126; POSITION must be VEC3"});
  c.push_back({"index_value_out_of_range", "a.gltf", edited([](MiniGltf& g) {
    std::vector<uint16_t> idx = {0, 1, 7, 0};
    const int a = g.add_accessor(g.add_view(idx), 5123, 3, "SCALAR");
    g.doc["meshes"][0]["primitives"][0]["indices"] = a;
  }), "index value 7 at element 2 is out of range"});
  c.push_back({"float_indices", "a.gltf", edited([](MiniGltf& g) {
    std::vector<float> idx = {0, 1, 2};
    const int a = g.add_accessor(g.add_view(idx), 5126, 3, "SCALAR");
    g.doc["meshes"][0]["primitives"][0]["indices"] = a;
  }), "/meshes/0/primitives/0/indices: index accessor 1 has component type 5126"});
  c.push_back({"triangle_count_not_multiple", "a.gltf", edited([](MiniGltf& g) {
    std::vector<uint16_t> idx = {0, 1, 2, 0};
    const int a = g.add_accessor(g.add_view(idx), 5123, 4, "SCALAR");
    g.doc["meshes"][0]["primitives"][0]["indices"] = a;
  }), "not a multiple of 3"});
  c.push_back({"nan_position", "a.gltf", edited([](MiniGltf& g) {
    float nan = std::nanf("");
    std::memcpy(g.bin.data() + 4, &nan, 4);
  }), "non-finite"});
  // Finite but beyond the coordinates rays can use (Embree aborted on such ray origins).
  c.push_back({"scale_beyond_range", "a.gltf", edited([](MiniGltf& g) { g.doc["nodes"][0]["scale"] = {1e25, 1e25, 1e25}; }), "/nodes/0: places vertex"});
  c.push_back({"translation_beyond_range", "a.gltf", edited([](MiniGltf& g) { g.doc["nodes"][0]["translation"] = {0, 0, 1e19}; }), "beyond the"});
  c.push_back({"node_cycle", "a.gltf", edited([](MiniGltf& g) { g.doc["nodes"][0]["children"] = {0}; }), "/nodes/0: node is reached twice"});
  c.push_back({"missing_bin", "a.gltf", [](const std::filesystem::path& p) {
    MiniGltf g;
    g.add_triangle();
    g.write_gltf(p);
    std::filesystem::remove(p.parent_path() / "a.bin");
  }, "/buffers/0/uri: referenced file"});
  // "%00" decoded to a NUL that ended the file name: "a.bin%00.txt" read a.bin.
  c.push_back({"uri_with_nul", "a.gltf", [](const std::filesystem::path& p) {
    MiniGltf g;
    g.add_triangle();
    g.write_gltf(p);
    g.doc["buffers"][0]["uri"] = "a.bin%00.txt";
    MiniGltf::write_text(p, g.doc.dump());
  }, "/buffers/0/uri: 'a.bin%00.txt' decodes to a path with a NUL byte"});
  c.push_back({"truncated_bin", "a.gltf", [](const std::filesystem::path& p) {
    MiniGltf g;
    g.add_triangle();
    g.write_gltf(p);
    std::filesystem::resize_file(p.parent_path() / "a.bin", 10);
  }, "/buffers/0/uri: '"});
  c.push_back({"buffer_length_is_string", "a.gltf", edited([](MiniGltf& g) { g.doc["buffers"] = json::array({{{"byteLength", "36"}}}); }, 2), "/buffers/0/byteLength"});
  c.push_back({"base64_too_short", "a.gltf", [](const std::filesystem::path& p) {
    MiniGltf g;
    g.add_triangle();
    g.finish_buffer("data:application/octet-stream;base64," + MiniGltf::base64(std::vector<unsigned char>(12, 0)));
    MiniGltf::write_text(p, g.doc.dump());
  }, "/buffers/0"});
  c.push_back({"base64_too_long", "a.gltf", [](const std::filesystem::path& p) {
    MiniGltf g;
    g.add_triangle();
    g.finish_buffer("");
    const size_t length = g.doc["buffers"][0]["byteLength"].get<size_t>();
    g.doc["buffers"][0]["uri"] =
        "data:application/octet-stream;base64," + MiniGltf::base64(std::vector<unsigned char>(length + 12, 0));
    MiniGltf::write_text(p, g.doc.dump());
  }, "/buffers/0: the data URI holds"});  // the loader's own message quoted the whole URI
  c.push_back({"truncated_glb", "a.glb", [](const std::filesystem::path& p) {
    MiniGltf g;
    g.add_triangle();
    g.write_glb(p);
    std::filesystem::resize_file(p, std::filesystem::file_size(p) - 16);
  }, "truncated"});
  c.push_back({"glb_header_only", "a.glb", [](auto& p) { write_text(p, std::string("glTF\x02\0\0\0", 8)); }, "truncated .glb"});
  c.push_back({"glb_json_chunk_past_end", "a.glb", [](const std::filesystem::path& p) {
    MiniGltf g;
    g.add_triangle();
    g.write_glb(p);
    std::string bytes = MiniGltf::base64({});  // unused; read and patch the JSON length
    std::ifstream in(p, std::ios::binary);
    std::vector<unsigned char> data((std::istreambuf_iterator<char>(in)), {});
    data[12] = 0xFF; data[13] = 0xFF; data[14] = 0x00; data[15] = 0x00;
    MiniGltf::write_bytes(p, data);
  }, "JSON chunk"});
  c.push_back({"required_extension", "a.gltf", edited([](MiniGltf& g) { g.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"}; }), "/extensionsRequired/0: extension 'KHR_draco_mesh_compression'"});
  // Compressed geometry leaves the core fields without data (Draco: accessors with no bufferView;
  // meshopt: a fallback buffer with no uri). The unsupported extension is named first, not those
  // fields, which the extension makes legal.
  c.push_back({"required_draco_without_views", "a.gltf", edited([](MiniGltf& g) {
    g.doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
    g.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
    for (json& a : g.doc["accessors"]) a.erase("bufferView");
  }), "/extensionsRequired/0: extension 'KHR_draco_mesh_compression' is required by the file but not supported"});
  c.push_back({"required_meshopt_fallback_buffer", "a.gltf", edited([](MiniGltf& g) {
    g.doc["extensionsUsed"] = {"EXT_meshopt_compression"};
    g.doc["extensionsRequired"] = {"EXT_meshopt_compression"};
    g.doc["buffers"].push_back({{"byteLength", 64}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}});
  }), "/extensionsRequired/0: extension 'EXT_meshopt_compression' is required by the file but not supported"});
  // Skins and GPU instancing: joints form a cycle outside the loaded scene, a skin without joints,
  // joint indices as floats, an instance rotation of the wrong type.
  c.push_back({"skin_joint_cycle", "a.gltf", edited([](MiniGltf& g) {
    g.doc["nodes"][0]["skin"] = 0;
    g.add_node({{"children", {2}}}, false);
    g.add_node({{"children", {1}}}, false);
    g.doc["skins"] = json::array({{{"joints", {1}}}});
  }), "/nodes/1: the node's ancestors form a cycle"});
  c.push_back({"skin_without_joints", "a.gltf", edited([](MiniGltf& g) {
    g.doc["nodes"][0]["skin"] = 0;
    g.doc["skins"] = json::array({{{"joints", json::array()}}});
  }), "/skins/0/joints: is empty; glTF requires a skin to have at least one joint"});
  c.push_back({"skin_float_joints", "a.gltf", edited([](MiniGltf& g) {
    const std::vector<float> four = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    g.doc["meshes"][0]["primitives"][0]["attributes"]["JOINTS_0"] = g.add_accessor(g.add_view(four), 5126, 3, "VEC4");
    g.doc["meshes"][0]["primitives"][0]["attributes"]["WEIGHTS_0"] = g.add_accessor(g.add_view(four), 5126, 3, "VEC4");
  }), "/meshes/0/primitives/0/attributes/JOINTS_0: accessor 1 is VEC4 of component type 5126; it must be VEC4 of UNSIGNED_BYTE"});
  c.push_back({"instancing_rotation_mat2", "a.gltf", edited([](MiniGltf& g) {
    const std::vector<float> m = {1, 0, 0, 1};
    g.doc["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["ROTATION"] =
        g.add_accessor(g.add_view(m), 5126, 1, "MAT2");
  }), "/nodes/0/extensions/EXT_mesh_gpu_instancing/attributes/ROTATION: accessor 1 is MAT2 of component type 5126; it must be VEC4"});
  c.push_back({"light_reference_out_of_range", "a.gltf", edited([](MiniGltf& g) { g.doc["nodes"][0]["extensions"]["KHR_lights_punctual"]["light"] = 2; }), "/nodes/0/extensions/KHR_lights_punctual/light: refers to lights[2]"});
  c.push_back({"light_bad_type", "a.gltf", edited([](MiniGltf& g) { g.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array({{{"type", "area"}}}); }), "/extensions/KHR_lights_punctual/lights/0/type"});
  c.push_back({"light_negative_intensity", "a.gltf", edited([](MiniGltf& g) { g.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array({{{"type", "point"}, {"intensity", -1}}}); }), "/extensions/KHR_lights_punctual/lights/0/intensity"});
  // Values a float cannot hold or a light cannot have: found by the loader, not as NaN pixels.
  c.push_back({"light_huge_intensity", "a.gltf", edited([](MiniGltf& g) { g.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array({{{"type", "point"}, {"intensity", 1e300}}}); }), "/extensions/KHR_lights_punctual/lights/0/intensity"});
  c.push_back({"light_negative_colour", "a.gltf", edited([](MiniGltf& g) { g.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array({{{"type", "point"}, {"color", {-1, -1, -1}}}}); }), "/extensions/KHR_lights_punctual/lights/0/color/0"});
  c.push_back({"light_name_number", "a.gltf", edited([](MiniGltf& g) { g.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array({{{"type", "point"}, {"name", 5}}}); }), "/extensions/KHR_lights_punctual/lights/0/name"});
  c.push_back({"spot_cone_order", "a.gltf", edited([](MiniGltf& g) { g.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array({{{"type", "spot"}, {"spot", {{"innerConeAngle", 0.6}, {"outerConeAngle", 0.5}}}}}); }), "/extensions/KHR_lights_punctual/lights/0/spot: innerConeAngle 0.6 must be less than outerConeAngle 0.5"});
  c.push_back({"spot_cone_wide", "a.gltf", edited([](MiniGltf& g) { g.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array({{{"type", "spot"}, {"spot", {{"outerConeAngle", 2}}}}}); }), "/extensions/KHR_lights_punctual/lights/0/spot/outerConeAngle"});
  c.push_back({"camera_zero_fov", "a.gltf", edited([](MiniGltf& g) { g.doc["cameras"] = json::array({{{"type", "perspective"}, {"perspective", {{"yfov", 0}, {"znear", 0.1}}}}}); }), "/cameras/0/perspective/yfov"});
  c.push_back({"rig_extras_wrong_type", "a.gltf", edited([](MiniGltf& g) { g.doc["nodes"][0]["extras"]["stereobench"]["interaxial"] = "wide"; }), "/nodes/0/extras/stereobench/interaxial"});
  c.push_back({"texture_out_of_range", "a.gltf", edited([](MiniGltf& g) { g.doc["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 3}}}}}}}); }), "/materials/0/pbrMetallicRoughness/baseColorTexture/index: refers to textures[3]"});
  c.push_back({"corrupt_image", "a.gltf", edited([](MiniGltf& g) {
    std::vector<unsigned char> junk(64, 0x42);
    g.doc["images"] = json::array({{{"bufferView", g.add_view(junk.data(), junk.size())}, {"mimeType", "image/png"}}});
    g.doc["textures"] = json::array({{{"source", 0}}});
    g.doc["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}});
    g.doc["meshes"][0]["primitives"][0]["material"] = 0;
  }), "/images/0: cannot decode"});
  // Camera transforms without a viewing direction failed later, in the rig, naming neither file nor node.
  c.push_back({"camera_zero_scale", "a.gltf", edited([](MiniGltf& g) { add_camera(g, {{"scale", {0, 0, 0}}}); }),
               "/nodes/1: the camera's transform (this node's with its parents') cannot place the rig: camera transform is degenerate (zero scale)"});
  c.push_back({"camera_parent_zero_scale", "a.gltf", edited([](MiniGltf& g) {
    const int cam = add_camera(g, json::object(), false);
    g.add_node({{"scale", {1, 1, 0}}, {"children", {cam}}});
  }), "/nodes/1: the camera's transform (this node's with its parents') cannot place the rig: camera transform is degenerate (zero scale)"});
  c.push_back({"camera_up_along_view", "a.gltf", edited([](MiniGltf& g) {
    add_camera(g, {{"matrix", {1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 3, 1}}});
  }), "/nodes/1: the camera's transform (this node's with its parents') cannot place the rig: camera transform is degenerate (up parallel to view direction)"});
  c.push_back({"rig_extras_huge_interaxial", "a.gltf", edited([](MiniGltf& g) { add_camera(g, {{"extras", {{"stereobench", {{"interaxial", 1e20}}}}}}); }),
               "/nodes/1/extras/stereobench/interaxial: value 1e+20 m is beyond the 1e+15 m a scene may span"});
  c.push_back({"rig_extras_negative_convergence", "a.gltf", edited([](MiniGltf& g) { g.doc["nodes"][0]["extras"]["stereobench"]["convergence"] = -1; }), "/nodes/0/extras/stereobench/convergence: value -1 must be positive"});
  // The reader keeps sparse counts and offsets in 32 bits: 2^32 + 1 was read as 1, silently.
  c.push_back({"sparse_count_beyond_32_bits", "a.gltf", edited([](MiniGltf& g) {
    g.doc["accessors"][0]["sparse"] = {{"count", 4294967297ULL},
                                       {"indices", {{"bufferView", 0}, {"componentType", 5123}}},
                                       {"values", {{"bufferView", 0}}}};
  }), "/accessors/0/sparse/count: value 4294967297 is out of range [1, 2147483647]"});
  c.push_back({"sparse_offset_beyond_32_bits", "a.gltf", edited([](MiniGltf& g) {
    g.doc["accessors"][0]["sparse"] = {{"count", 1},
                                       {"indices", {{"bufferView", 0}, {"componentType", 5123}, {"byteOffset", 4294967296ULL}}},
                                       {"values", {{"bufferView", 0}}}};
  }), "/accessors/0/sparse/indices/byteOffset: value 4294967296 is out of range [0, 2147483647]"});
  // Sparse indices must increase strictly: with one given twice, which value wins was the reader's
  // choice (it loaded, exit 0).
  c.push_back({"sparse_indices_not_increasing", "a.gltf", edited([](MiniGltf& g) {
    const int indices = g.add_view(std::vector<uint16_t>{2, 1});
    const int values = g.add_view(std::vector<float>{0, 0, 0, 1, 1, 1});
    g.doc["accessors"][0]["sparse"] = {{"count", 2},
                                       {"indices", {{"bufferView", indices}, {"componentType", 5123}}},
                                       {"values", {{"bufferView", values}}}};
  }), "/accessors/0/sparse/indices: sparse index 1 at element 1 follows 2"});
  // Sampler enums: 2^32 + 33071 was read as CLAMP_TO_EDGE.
  c.push_back({"sampler_wrap_not_an_enum", "a.gltf", edited([](MiniGltf& g) { g.doc["samplers"] = json::array({{{"wrapS", 4294967296ULL + 33071}}}); }),
               "/samplers/0/wrapS: 4295000367 is not one of 33071 CLAMP_TO_EDGE"});
  // A float image (a Radiance file here, its texels at 255 * 2^119) reached the images as colour
  // far beyond 1, or as NaN and infinity.
  c.push_back({"texture_beyond_one", "a.gltf", [](const std::filesystem::path& p) {
    write_text(p.parent_path() / "huge.hdr", std::string("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 2\n") + std::string(16, '\xff'));
    edited([](MiniGltf& g) {
      g.doc["images"] = json::array({{{"uri", "huge.hdr"}}});
      g.doc["textures"] = json::array({{{"source", 0}}});
      g.doc["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}});
      g.doc["meshes"][0]["primitives"][0]["material"] = 0;
    })(p);
  }, "/images/0: texel (0, 0) channel 0 is "});
  // A key-time accessor running past its buffer view was refused as too large for memory (exit 4).
  c.push_back({"animation_input_beyond_its_view", "a.gltf", edited([](MiniGltf& g) {
    g.doc["accessors"].push_back({{"bufferView", 0}, {"componentType", 5126}, {"count", 1ULL << 50}, {"type", "SCALAR"}});
    const int times = static_cast<int>(g.doc["accessors"].size()) - 1;
    g.doc["animations"] = json::array({{{"samplers", json::array({{{"input", times}, {"output", 0}}})},
                                        {"channels", json::array({{{"sampler", 0}, {"target", {{"node", 0}, {"path", "translation"}}}}})}}});
  }), "the count is wrong or the buffer is truncated (used by /animations/0/samplers/0/input)"});
  c.push_back({"zero_quaternion", "a.gltf", edited([](MiniGltf& g) { g.doc["nodes"][0]["rotation"] = {0, 0, 0, 0}; }), "/nodes/0/rotation: the quaternion has length zero"});
  c.push_back({"base_color_above_one", "a.gltf", edited([](MiniGltf& g) { g.doc["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorFactor", {2, 0.5, 0.5, 1}}}}}}); }), "/materials/0/pbrMetallicRoughness/baseColorFactor/0: value 2 is out of range [0, 1]"});
  // Misspelt keys of the suite's own extras used to leave their defaults in place silently.
  c.push_back({"rig_extras_misspelt", "a.gltf", edited([](MiniGltf& g) { g.doc["nodes"][0]["extras"]["stereobench"]["interaxal"] = 0.2; }),
               "/nodes/0/extras/stereobench/interaxal: unknown key 'interaxal'; a camera node's extras.stereobench holds convergence, height, interaxial, width"});
  c.push_back({"scene_extras_misspelt", "a.gltf", edited([](MiniGltf& g) { g.doc["scenes"][0]["extras"]["stereobench"]["backgrund"] = {1, 0, 0}; }),
               "/scenes/0/extras/stereobench/backgrund: unknown key 'backgrund'; a scene's extras.stereobench holds ambient, background, generator, params, seed"});
  c.push_back({"rig_extras_on_the_scene", "a.gltf", edited([](MiniGltf& g) { g.doc["scenes"][0]["extras"]["stereobench"]["convergence"] = 5; }),
               "/scenes/0/extras/stereobench/convergence: 'convergence' belongs in the camera node's extras.stereobench, not the scene's"});
  c.push_back({"negative_ambient", "a.gltf", edited([](MiniGltf& g) { g.doc["scenes"][0]["extras"]["stereobench"]["ambient"] = -0.5; }), "/scenes/0/extras/stereobench/ambient: value -0.5 is out of range"});
  c.push_back({"glb_bad_magic", "a.glb", [](auto& p) { write_text(p, std::string("XglT\x02\0\0\0", 8) + std::string(40, ' ')); }, "not a binary glTF file: it starts with 'XglT'"});
  c.push_back({"syntax_error_in_data_uri", "a.gltf", [](auto& p) { write_text(p, "{\"asset\": {\"version\": \"2.0\"}, \"buffers\": [{\"uri\": \"data:" + std::string(3000, 'A') + "}"); }, "'\"data:AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA...' (3007 characters)"});
  c.push_back({"long_token_before_expected", "a.gltf", [](auto& p) { write_text(p, "{\"asset\": {\"version\" \"" + std::string(100, 'A')); }, "...' (101 characters); expected ':'"});
  // Deep nesting crashed the glTF library's recursive parser (stack overflow), 20000 levels here.
  c.push_back({"nesting_too_deep", "a.gltf", [](auto& p) { write_text(p, "{\"asset\":{\"version\":\"2.0\"},\"extras\":" + std::string(20000, '[') + std::string(20000, ']') + "}"); }, "nesting deeper than 256 levels"});
  // A number beyond a double's range was an internal error (exit 4) naming no file.
  c.push_back({"number_overflows_double", "a.gltf", [](auto& p) { write_text(p, R"({"asset":{"version":"2.0"},"extras":{"count":35e400}})"); }, "its JSON exceeds what the reader accepts: number overflow parsing '35e400'"});
  // A folder or a device named as a file was reported as a file that does not exist.
  c.push_back({"image_uri_is_a_folder", "a.gltf", edited([](MiniGltf& g) { g.doc["images"] = json::array({{{"uri", "."}}}); }), "is a folder, not a regular file"});
  c.push_back({"buffer_uri_is_a_device", "a.gltf", [](auto& p) {
                 std::filesystem::create_symlink("/dev/zero", p.parent_path() / "zero.bin");
                 write_text(p, R"({"asset":{"version":"2.0"},"buffers":[{"uri":"zero.bin","byteLength":12}]})");
               },
               "is a device, pipe or socket, not a regular file"});
  // glTF fills an accessor without a bufferView with zeros: every vertex at the origin, nothing to
  // see. The primitive is skipped (it may declare any count), and the empty scene says why.
  c.push_back({"positions_without_data", "a.gltf", edited([](MiniGltf& g) { g.doc["accessors"][0].erase("bufferView"); g.doc["accessors"][0]["count"] = 300000000; }),
               "/meshes/0/primitives/0/attributes/POSITION: accessor 0 has no bufferView and no sparse values, so every vertex is at the origin"});
  c.push_back({"buffer_without_uri", "a.gltf", edited([](MiniGltf& g) { g.finish_buffer(""); }),
               "/buffers/0: has no uri, which only the first buffer of a .glb may omit"});
  c.push_back({"glb_without_bin_chunk", "a.glb", [](auto& p) {
                 MiniGltf g;
                 g.add_triangle();
                 g.finish_buffer("");
                 g.bin.clear();  // the buffer stays declared, its chunk goes
                 g.write_glb(p);
               },
               "/buffers/0: has no uri, so it is the .glb's BIN chunk, but the file has none"});
  // An empty BIN chunk got the glTF library's own words ("Insufficient storage space for Chunk1").
  c.push_back({"glb_empty_bin_chunk", "a.glb", [](auto& p) {
                 MiniGltf g;
                 g.add_triangle();
                 g.finish_buffer("");
                 g.bin.clear();
                 g.write_glb(p);
                 std::string bytes = test::read_text(p);
                 bytes += std::string("\0\0\0\0BIN\0", 8);  // a chunk header of length 0
                 const auto total = static_cast<uint32_t>(bytes.size());
                 for (int i = 0; i < 4; ++i) bytes[8 + i] = static_cast<char>(total >> (8 * i));
                 write_text(p, bytes);
               },
               "the .glb's BIN chunk (at byte "});
  // One rule for buffers and images, checked before any file is looked at: paths relative to the
  // scene's folder or data: URIs. An absolute path to a file that exists was read by some routes
  // and refused with the glTF library's words by others.
  for (const char* url : {"file:///etc/passwd", "https://example.com/a.bin"})
    c.push_back({std::string("buffer_url_") + url[0], "a.gltf",
                 edited([url](MiniGltf& g) { g.doc["buffers"] = json::array({{{"byteLength", 36}, {"uri", url}}}); }),
                 fmt::format("/buffers/0/uri: '{}' is a {} URI; buffers and images are read from paths relative to "
                             "the scene file's folder", url, std::string(url).substr(0, std::string(url).find(':') + 1))});
  c.push_back({"image_url", "a.gltf", edited([](MiniGltf& g) { g.doc["images"] = json::array({{{"uri", "http://example.com/t.png"}}}); }),
               "/images/0/uri: 'http://example.com/t.png' is a http: URI"});
  c.push_back({"buffer_absolute_path_that_exists", "a.gltf", [](const std::filesystem::path& p) {
                 MiniGltf g;
                 g.add_triangle();
                 g.write_gltf(p);
                 g.doc["buffers"][0]["uri"] = std::filesystem::absolute(p.parent_path() / "a.bin").string();
                 write_text(p, g.doc.dump());
               },
               "is an absolute path; buffers and images are read from paths relative"});
  c.push_back({"buffer_absolute_path", "a.gltf", [](auto& p) { write_text(p, R"({"asset":{"version":"2.0"},"buffers":[{"uri":"/etc/passwd","byteLength":12}]})"); },
               "/buffers/0/uri: '/etc/passwd' is an absolute path; buffers and images are read from paths relative to "
               "the scene file's folder (subfolders and '..' are allowed) or from base64 data: URIs — make the URI "
               "relative to the scene file's folder"});
  c.push_back({"buffer_percent_encoded_absolute_path", "a.gltf", [](auto& p) { write_text(p, R"({"asset":{"version":"2.0"},"buffers":[{"uri":"%2Fetc%2Fpasswd","byteLength":12}]})"); },
               "/buffers/0/uri: '%2Fetc%2Fpasswd' is an absolute path"});
  c.push_back({"buffer_windows_drive", "a.gltf", [](auto& p) { write_text(p, R"({"asset":{"version":"2.0"},"buffers":[{"uri":"C:/scene/a.bin","byteLength":12}]})"); },
               "/buffers/0/uri: 'C:/scene/a.bin' is an absolute path"});
  c.push_back({"image_absolute_path", "a.gltf", edited([](MiniGltf& g) { g.doc["images"] = json::array({{{"uri", "/etc/hostname"}}}); }),
               "/images/0/uri: '/etc/hostname' is an absolute path"});
  c.push_back({"missing_image_file", "a.gltf", edited([](MiniGltf& g) { g.doc["images"] = json::array({{{"uri", "nope.png"}}}); }), "/images/0/uri: referenced file"});
  // A top-level array of another type is named as such (it read as an index past its end).
  c.push_back({"buffers_not_an_array", "a.gltf", edited([](MiniGltf& g) { g.doc["buffers"] = json{{"a", g.doc["buffers"][0]}}; }),
               "/buffers: expected a JSON array, found object"});
  c.push_back({"accessors_not_an_array", "a.gltf", edited([](MiniGltf& g) { g.doc["accessors"] = 5; }),
               "/accessors: expected a JSON array, found number"});
  c.push_back({"lights_not_an_array", "a.gltf",
               edited([](MiniGltf& g) { g.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::object(); }),
               "/extensions/KHR_lights_punctual/lights: expected a JSON array"});
  // An image's bufferView outside its buffer was read out of bounds (a segmentation fault).
  c.push_back({"image_view_outside_buffer", "a.gltf", edited([](MiniGltf& g) {
    std::vector<unsigned char> png(16, 0x42);
    const int v = g.add_view(png.data(), png.size());
    g.doc["bufferViews"][v]["byteOffset"] = 100000000;
    g.doc["images"] = json::array({{{"bufferView", v}, {"mimeType", "image/png"}}});
  }), "/bufferViews/1: bytes [100000000, 100000016) lie outside buffer 0"});
  c.push_back({"stride_not_multiple_of_4", "a.gltf", edited([](MiniGltf& g) { g.doc["bufferViews"][0]["byteStride"] = 13; }),
               "/bufferViews/0/byteStride: 13 is not a multiple of 4"});
  c.push_back({"image_uri_and_view", "a.gltf", edited([](MiniGltf& g) {
    std::vector<unsigned char> png(16, 0x42);
    g.doc["images"] = json::array({{{"uri", "a.png"}, {"bufferView", g.add_view(png.data(), png.size())}, {"mimeType", "image/png"}}});
  }), "/images/0: image has both 'uri' and 'bufferView'"});
  c.push_back({"image_view_without_mime_type", "a.gltf", edited([](MiniGltf& g) {
    std::vector<unsigned char> png(16, 0x42);
    g.doc["images"] = json::array({{{"bufferView", g.add_view(png.data(), png.size())}}});
  }), "/images/0/mimeType: is required"});
  c.push_back({"orthographic_without_xmag", "a.gltf", edited([](MiniGltf& g) {
    g.doc["cameras"] = json::array({{{"type", "orthographic"}, {"orthographic", {{"ymag", 1}, {"znear", 0}, {"zfar", 9}}}}});
  }), "/cameras/0/orthographic/xmag: required"});
  c.push_back({"matrix_and_translation", "a.gltf", edited([](MiniGltf& g) {
    g.doc["nodes"][0]["matrix"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    g.doc["nodes"][0]["translation"] = {1, 0, 0};
  }), "/nodes/0/translation: the node has a matrix too"});
  // The second parent lies outside the scene: the traversal never meets the node twice.
  c.push_back({"two_parents_one_outside_the_scene", "a.gltf", edited([](MiniGltf& g) {
    g.add_node({{"children", {0}}}, false);
    g.add_node({{"children", {0}}});
    g.doc["scenes"][0]["nodes"] = {2};
  }), "/nodes/2/children/0: node 0 is already a child at /nodes/1/children/0"});
  c.push_back({"skin_out_of_range", "a.gltf", edited([](MiniGltf& g) { g.doc["nodes"][0]["skin"] = 3; }),
               "/nodes/0/skin: refers to skins[3]"});
  c.push_back({"morph_target_out_of_range", "a.gltf", edited([](MiniGltf& g) {
    g.doc["meshes"][0]["primitives"][0]["targets"] = json::array({{{"POSITION", 9}}});
  }), "/meshes/0/primitives/0/targets/0/POSITION: refers to accessors[9]"});
  c.push_back({"position_unsigned_byte", "a.gltf", edited([](MiniGltf& g) { g.doc["accessors"][0]["componentType"] = 5121; }),
               "POSITION must be VEC3 of FLOAT (5126) (integer types need KHR_mesh_quantization)"});
  c.push_back({"float_normalized", "a.gltf", edited([](MiniGltf& g) { g.doc["accessors"][0]["normalized"] = true; }),
               "/accessors/0/normalized: is true for component type FLOAT"});
  c.push_back({"misaligned_accessor", "a.gltf", edited([](MiniGltf& g) {
    g.doc["accessors"][0]["byteOffset"] = 1;
    g.doc["accessors"][0]["count"] = 2;
  }), "/accessors/0/byteOffset: the accessor starts at byte 1 of its buffer"});
  // A count far beyond POSITION's was read (gigabytes) before it was compared.
  c.push_back({"normal_count_beyond_positions", "a.gltf", edited([](MiniGltf& g) {
    g.doc["accessors"].push_back({{"componentType", 5126}, {"count", 100000000}, {"type", "VEC3"}});
    g.doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 1;
  }), "/meshes/0/primitives/0/attributes/NORMAL: accessor 1 has 100000000 elements but POSITION has 3"});
  // tinygltf's own messages named no JSON path, quoted whole payloads or misled.
  c.push_back({"glb_buffer_longer_than_bin", "a.glb", [](const std::filesystem::path& p) {
    MiniGltf g;
    g.add_triangle();
    g.finish_buffer("");
    g.doc["buffers"][0]["byteLength"] = 124;
    g.write_glb(p);
  }, "/buffers/0/byteLength: 124 bytes, but the .glb's BIN chunk holds 36"});
  c.push_back({"base64_bad_character", "a.gltf", [](const std::filesystem::path& p) {
    MiniGltf g;
    g.add_triangle();
    std::string payload = MiniGltf::base64(g.bin);
    payload[5] = '!';
    g.finish_buffer("data:application/octet-stream;base64," + payload);
    MiniGltf::write_text(p, g.doc.dump());
  }, "/buffers/0/uri: the data URI's base64 payload has the character '!' at position 5"});
  c.push_back({"data_uri_without_media_type", "a.gltf", [](const std::filesystem::path& p) {
    MiniGltf g;
    g.add_triangle();
    g.finish_buffer("data:;base64," + MiniGltf::base64(g.bin));
    MiniGltf::write_text(p, g.doc.dump());
  }, "/buffers/0/uri: data URI of media type ''; buffers take 'data:application/octet-stream;base64,...'"});
  c.push_back({"channel_without_node", "a.gltf", edited([](MiniGltf& g) {
    std::vector<float> t = {0.0f};
    std::vector<float> v = {0, 0, 0};
    const int in = g.add_accessor(g.add_view(t), 5126, 1, "SCALAR");
    g.doc["accessors"][in]["min"] = {0};
    g.doc["accessors"][in]["max"] = {0};
    const int out = g.add_accessor(g.add_view(v), 5126, 1, "VEC3");
    g.doc["animations"] = json::array({{{"samplers", {{{"input", in}, {"output", out}}}},
                                        {"channels", {{{"sampler", 0}, {"target", {{"path", "translation"}}}}}}}});
  }), "/animations/0/channels/0/target: a channel without a node"});
  c.push_back({"index_accessor_without_view", "a.gltf", edited([](MiniGltf& g) {
    g.doc["accessors"].push_back({{"componentType", 5123}, {"count", 3}, {"type", "SCALAR"}});
    g.doc["meshes"][0]["primitives"][0]["indices"] = 1;
  }), "/meshes/0/primitives/0/indices: accessor 1 has no bufferView"});
  return c;
}

/// Writes a case's broken file into its own folder under `dir` and returns its path.
inline std::filesystem::path write_case(const ScratchDir& dir, const BadCase& bc) {
  const auto folder = dir / bc.name;
  std::filesystem::create_directories(folder);
  const auto path = folder / bc.file;
  bc.make(path);
  return path;
}

}  // namespace sb::test::bad_scene
