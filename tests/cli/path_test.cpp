// `stereobench path`: one JSON line per frame with the BVH update timed per frame, and bad input.
#include <gtest/gtest.h>

#include <sstream>

#include <nlohmann/json.hpp>

#include "scenes/gltf_builder.hpp"
#include "support/run_cli.hpp"
#include "support/scratch_dir.hpp"

namespace sb {
namespace {

using nlohmann::json;

std::string args(const test::ScratchDir& dir) {
  return "path --scene box-wall --resolution 96x54 --threads 2 --scenes-dir '" +
         (std::filesystem::path(SB_BINARY_DIR) / "Testing" / "scenes-cache").string() + "' --out '" +
         (dir / "out").string() + "'";
}

/// The JSON lines of a path file.
std::vector<json> frame_lines(const std::filesystem::path& file) {
  std::stringstream lines(test::read_text(file));
  std::vector<json> frames;
  for (std::string line; std::getline(lines, line);) frames.push_back(json::parse(line));
  return frames;
}

/// A box on a floor before a wall, lit by a lamp, its camera keyed 0.5 m along +X in 2 s; with
/// `box_moves` the box too, 1 m along +X. Written to `file`.
void write_keyed_box_scene(const std::filesystem::path& file, bool box_moves) {
  scenes::GltfBuilder b("path-animation-test", 1);
  const int grey = b.add_material("grey", vec3(0.6f));
  const int box = b.add_node("box", b.add_mesh("box", scenes::make_box(vec3(-0.3f, 0.0f, -0.3f), vec3(0.3f, 0.6f, 0.3f)), grey));
  b.add_node("wall", b.add_mesh("wall", scenes::make_box(vec3(-3.0f, 0.0f, -2.2f), vec3(3.0f, 2.5f, -2.0f)), grey));
  b.add_node("floor", b.add_mesh("floor", scenes::make_box(vec3(-3.0f, -0.1f, -2.0f), vec3(3.0f, 0.0f, 2.0f)), grey));
  b.add_point_light("lamp", vec3(1.0f, 2.0f, 2.0f), vec3(1.0f), 15.0f);
  RigDefaults rig;
  rig.width = 96;
  rig.height = 54;
  const int camera = b.set_camera("camera", CameraPose::look_at(dvec3(0.0, 1.0, 4.0), dvec3(0.0, 0.6, 4.0 - 1.0)), 0.8,
                                  0.05, 0.0, rig);
  const std::vector<float> times = {0.0f, 2.0f};
  if (box_moves) {
    const std::vector<float> box_keys = {0, 0, 0, 1, 0, 0};
    b.add_animation_channel(box, "translation", times, box_keys);
  }
  const std::vector<float> camera_keys = {0, 1, 4, 0.5f, 1, 4};
  b.add_animation_channel(camera, "translation", times, camera_keys);
  b.write(file);
}

TEST(PathCommand, ABvhUpdateIsRefusedWhereTheAnimationMovesNoMesh) {
  test::ScratchDir dir;
  // Only the camera is keyed: no mesh moves, so no BVH is ever updated.
  write_keyed_box_scene(dir / "camera-only.gltf", false);
  const std::string base = "path --scene '" + (dir / "camera-only.gltf").string() + "' --out '" +
                           (dir / "out").string() + "' --frames 2 --pipelines plain-rt --gltf-animation";
  const test::CliRun refused = test::run_cli(base + " --bvh rebuild");
  EXPECT_EQ(refused.code, 3) << refused.out;
  EXPECT_NE(refused.out.find("--bvh rebuild: the path moves none of the scene's meshes (its glTF animation"),
            std::string::npos)
      << refused.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
  const test::CliRun plain = test::run_cli(base);
  EXPECT_EQ(plain.code, 0) << plain.out;
  EXPECT_NE(plain.out.find(": 2 frames, "), std::string::npos) << plain.out;
  EXPECT_EQ(frame_lines(dir / "out" / "camera-only_path.jsonl")[1]["bvh"], "static");
}

TEST(PathCommand, TheScenesGltfAnimationMovesItsMeshAndCamera) {
  test::ScratchDir dir;
  write_keyed_box_scene(dir / "moving.gltf", true);
  const std::string base = "path --scene '" + (dir / "moving.gltf").string() + "' --threads 2 --out '" +
                           (dir / "out").string() + "' --frames 3";
  const test::CliRun r = test::run_cli(base + " --gltf-animation --pipelines plain-rt,repro-rt");
  ASSERT_EQ(r.code, 0) << r.out;
  // Standard output and error go to one pipe here: the heading comes before the frames' lines (it
  // came after all of them, held in standard output's buffer).
  ASSERT_NE(r.out.find("path on "), std::string::npos) << r.out;
  ASSERT_NE(r.out.find("frame    0"), std::string::npos) << r.out;
  EXPECT_LT(r.out.find("path on "), r.out.find("frame    0")) << r.out;
  EXPECT_NE(r.out.find("the scene's glTF animation ('animation') from 0 s to 2 s, 1 mesh(es) and 0 light(s) moving "
                       "(BVH refit)"),
            std::string::npos)
      << r.out;
  const std::vector<json> frames = frame_lines(dir / "out" / "moving_path.jsonl");
  ASSERT_EQ(frames.size(), 3u);
  for (int f = 0; f < 3; ++f) {
    EXPECT_EQ(frames[f]["animation"]["gltf_animation"], true);
    EXPECT_DOUBLE_EQ(frames[f]["animation_time_s"].get<double>(), 1.0 * f);
    EXPECT_NEAR(frames[f]["camera"]["position"][0].get<double>(), 0.25 * f, 1e-9) << "frame " << f;
    EXPECT_EQ(frames[f]["pipelines"]["plain-rt"]["metrics"]["psnr"], "inf") << "the truth renders the moved scene";
    EXPECT_GT(frames[f]["pipelines"]["repro-rt"]["metrics"]["psnr"].get<double>(), 30.0);
  }
  EXPECT_EQ(frames[1]["bvh"], "refit") << "the box moves";
  EXPECT_EQ(frames[0]["animation"]["gltf_clip"], nullptr) << "every clip";
  // One clip by name, which implies --gltf-animation; the record names it.
  const test::CliRun clip = test::run_cli(base + " --gltf-clip animation --pipelines plain-rt");
  ASSERT_EQ(clip.code, 0) << clip.out;
  EXPECT_EQ(frame_lines(dir / "out" / "moving_path.jsonl")[0]["animation"]["gltf_clip"], "animation");
  // The truth of the same frame without the animation differs: the box and camera did move.
  EXPECT_NE(frames[0]["true_disocclusion_fraction"], frames[2]["true_disocclusion_fraction"]);
  // With camera keys or a spin the path has two masters; the file has no clip 'walk'.
  for (const char* bad : {" --gltf-animation --spin-deg 5",
                          " --gltf-animation --camera-keys '0,1,6>0,0.5,0'", " --gltf-clip walk"}) {
    const test::CliRun refused = test::run_cli(base + bad + " --pipelines plain-rt");
    EXPECT_EQ(refused.code, 3) << bad << "\n" << refused.out;
  }
  // A scene without node animations has nothing to play.
  const test::CliRun none = test::run_cli(args(dir) + " --frames 2 --gltf-animation --pipelines plain-rt");
  EXPECT_EQ(none.code, 3) << none.out;
  EXPECT_NE(none.out.find("has no glTF node animation"), std::string::npos) << none.out;
}

TEST(PathCommand, AnAnimationThatMovesGeometryOutOfRangeNamesTheFrame) {
  // A box keyed to 1e16 m at 2 s: refused at the frame that moves it there, which the message now
  // names (it named neither frame nor time).
  test::ScratchDir dir;
  scenes::GltfBuilder b("far-animation-test", 1);
  const int grey = b.add_material("grey", vec3(0.6f));
  const int box = b.add_node("box", b.add_mesh("box", scenes::make_box(vec3(-0.3f, 0.0f, -0.3f), vec3(0.3f, 0.6f, 0.3f)), grey));
  b.add_point_light("lamp", vec3(1.0f, 2.0f, 2.0f), vec3(1.0f), 15.0f);
  const std::vector<float> times = {0.0f, 2.0f};
  const std::vector<float> keys = {0, 0, 0, 1e16f, 0, 0};
  b.add_animation_channel(box, "translation", times, keys);
  b.write(dir / "far.gltf");
  const test::CliRun r = test::run_cli("path --scene '" + (dir / "far.gltf").string() + "' --threads 2 --out '" +
                                       (dir / "out").string() +
                                       "' --frames 3 --gltf-animation --pipelines plain-rt --resolution 32x18");
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find("frame 1 of the path (animation time 1 s): "), std::string::npos) << r.out;
}

TEST(PathCommand, FramesWithSpinAndCameraKeys) {
  test::ScratchDir dir;
  const test::CliRun r =
      test::run_cli(args(dir) +
                    " --frames 3 --spin-deg 10 --pipelines plain-rt,repro-rt,repro-rt:discontinuity_px=1e6"
                    " --camera-keys '0,1,6>0,0.5,0;1,1,6>0,0.5,0'");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("BVH refit per frame"), std::string::npos) << r.out;
  const std::vector<json> frames = frame_lines(dir / "out" / "box-wall_path.jsonl");
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[0]["bvh"], "build");
  EXPECT_EQ(frames[1]["bvh"], "refit");
  EXPECT_GT(frames[2]["bvh_update_s"].get<double>(), 0.0);
  EXPECT_EQ(frames[2]["frame"], 2);
  EXPECT_NE(frames[0]["camera"]["position"], frames[2]["camera"]["position"]);
  // The frames went to a ".partial" file, renamed once the last was in.
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "box-wall_path.jsonl.partial"));
  for (const json& f : frames) {
    // Each line says what made it: a file from another run, or a cut one, shows as such.
    EXPECT_EQ(f["kind"], "stereobench.path_frame");
    EXPECT_EQ(f["frames"], 3);
    EXPECT_EQ(f["scene"]["name"], "box-wall");
    EXPECT_EQ(f["rig"]["width"], 96);
    EXPECT_EQ(f["truth"]["provider"], "full");
    EXPECT_EQ(f["animation"]["spin"]["degrees_per_frame"], 10.0);
    EXPECT_EQ(f["animation"]["camera_keys"].size(), 2u);
    EXPECT_EQ(f["animation"]["bvh_update"], "refit");
    EXPECT_EQ(f["pipelines"]["repro-rt:discontinuity_px=1e6"]["options"]["discontinuity_px"], "1e6");
    EXPECT_GT(f["pipelines"]["repro-rt"]["precision"].get<double>(), 0.0);
    EXPECT_EQ(f["pipelines"]["plain-rt"]["metrics"]["psnr"], "inf") << "plain-rt is the built-in ground truth";
    EXPECT_GT(f["pipelines"]["repro-rt"]["total_s"].get<double>(), 0.0);
    // Measured 38.4-43.5 dB over the three frames; below 30 dB the frame's truth or rig is wrong.
    EXPECT_GT(f["pipelines"]["repro-rt"]["metrics"]["psnr"].get<double>(), 30.0);
    // The variant without disocclusion detection misses most true disocclusions.
    EXPECT_LT(f["pipelines"]["repro-rt:discontinuity_px=1e6"]["recall"].get<double>(),
              f["pipelines"]["repro-rt"]["recall"].get<double>());
  }
}

TEST(PathCommand, BadInput) {
  test::ScratchDir dir;
  EXPECT_EQ(test::run_cli(args(dir) + " --bvh sometimes").code, 3);
  EXPECT_EQ(test::run_cli(args(dir) + " --frames 0").code, 3);
  const test::CliRun variant = test::run_cli(args(dir) + " --pipelines repro-rt:threshold_arcmin=-1");
  EXPECT_EQ(variant.code, 3) << variant.out;
  EXPECT_NE(variant.out.find("pipeline entry 'repro-rt:threshold_arcmin=-1'"), std::string::npos) << variant.out;
  const test::CliRun twice = test::run_cli(args(dir) + " --pipelines plain-rt,plain-rt");
  EXPECT_EQ(twice.code, 3) << twice.out;
  // 'all' stands for every registered pipeline, so naming one of them beside it is a repeat too.
  const test::CliRun beside_all = test::run_cli(args(dir) + " --pipelines all,repro-rt");
  EXPECT_EQ(beside_all.code, 3) << beside_all.out;
  EXPECT_NE(beside_all.out.find("'repro-rt' is one of the pipelines 'all' includes"), std::string::npos)
      << beside_all.out;
  EXPECT_EQ(test::run_cli(args(dir) + " --camera-keys '1,2,3'").code, 3);
  EXPECT_EQ(test::run_cli(args(dir) + " --camera-keys ''").code, 3);
  const test::CliRun empty_key = test::run_cli(args(dir) + " --camera-keys '0,1,6>0,0.5,0;;1,1,6>0,0.5,0'");
  EXPECT_EQ(empty_key.code, 3) << empty_key.out;
  EXPECT_NE(empty_key.out.find("camera key 2 is empty"), std::string::npos) << empty_key.out;
  const test::CliRun far_key = test::run_cli(args(dir) + " --camera-keys '0,1,6>0,0.5,0;1,1,6>0,1e300,0'");
  EXPECT_EQ(far_key.code, 3) << far_key.out;
  EXPECT_NE(far_key.out.find("camera key 2 '1,1,6>0,1e300,0': its target (0, 1e+300, 0) m lies beyond"),
            std::string::npos)
      << far_key.out;
  EXPECT_EQ(test::run_cli(args(dir) + " --spin-deg 5 --spin-prefix nothing-like-this").code, 3);
  // An axis with trailing junk, and spin settings without a spin, are refused, not ignored.
  const test::CliRun junk = test::run_cli(args(dir) + " --spin-deg 5 --spin-axis 0,1,0junk");
  EXPECT_EQ(junk.code, 3) << junk.out;
  EXPECT_NE(junk.out.find("--spin-axis '0,1,0junk' is not x,y,z"), std::string::npos) << junk.out;
  const test::CliRun alone = test::run_cli(args(dir) + " --spin-axis 1,0,0");
  EXPECT_EQ(alone.code, 3) << alone.out;
  EXPECT_NE(alone.out.find("--spin-axis requires --spin-deg"), std::string::npos) << alone.out;
  // Nothing moves without a spin: a BVH update asked for would be recorded but never done.
  const test::CliRun still = test::run_cli(args(dir) + " --bvh rebuild");
  EXPECT_EQ(still.code, 3) << still.out;
  EXPECT_NE(still.out.find("--bvh requires --spin-deg or --gltf-animation"), std::string::npos) << still.out;
  // Camera keys beyond the first need frames to move through.
  const test::CliRun one = test::run_cli(args(dir) + " --frames 1 --pipelines plain-rt --camera-keys "
                                         "'0,1,6>0,0.5,0;1,1,6>0,0.5,0'");
  EXPECT_EQ(one.code, 0) << one.out;
  EXPECT_NE(one.out.find("warning: with 1 frame the camera stands at the first of the 2 camera keys"),
            std::string::npos)
      << one.out;
  // Frames spread over the keys pass some keys by, also when there are more frames than keys (4
  // frames over 3 keys stand at 0, 2/3, 4/3 and 2: the middle key is never shown); said, with a
  // count of frames that stands at every key.
  const std::string three_keys = " --pipelines plain-rt --camera-keys '0,1,6>0,0.5,0;1,1,6>0,0.5,0;2,1,6>0,0.5,0'";
  for (const auto& [frames, fix] : {std::pair{2, 3}, std::pair{4, 5}}) {
    const test::CliRun r = test::run_cli(args(dir) + " --frames " + std::to_string(frames) + three_keys);
    EXPECT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("warning: the " + std::to_string(frames) +
                         " frames are spread evenly over the path, so camera key 2 falls between frames and is never "
                         "shown; give --frames " + std::to_string(fix)),
              std::string::npos)
        << r.out;
  }
  const test::CliRun five = test::run_cli(args(dir) + " --frames 5" + three_keys);
  EXPECT_EQ(five.code, 0) << five.out;
  EXPECT_EQ(five.out.find("warning:"), std::string::npos) << "frames 0, 2 and 4 stand at the keys: " << five.out;
  // Camera keys that swap position and target: the camera would stand on its target at frame 1.
  const test::CliRun cross = test::run_cli(args(dir) + " --frames 3 --camera-keys '0,1,4>0,1,3;0,1,3>0,1,4'");
  EXPECT_EQ(cross.code, 3) << cross.out;
  EXPECT_NE(cross.out.find("frame 1 of 3: the camera reaches its target"), std::string::npos) << cross.out;
}

}  // namespace
}  // namespace sb
