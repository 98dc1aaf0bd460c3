// glTF node animations played along a path: the loader reads translation, rotation and scale
// channels with their interpolation, a path moves the animated meshes rigidly with their nodes
// (a child with its parent) and the rig with an animated camera, and bad animations are refused
// naming the JSON path.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "renderer/animation.hpp"
#include "renderer/error.hpp"
#include "renderer/io/gltf_loader.hpp"
#include "renderer/parallel.hpp"
#include "renderer/render_scene.hpp"
#include "renderer/stages/trace.hpp"
#include "scenes/gltf_builder.hpp"
#include "support/mini_gltf.hpp"
#include "support/render_support.hpp"
#include "support/scratch_dir.hpp"

namespace sb {
namespace {

/// A unit box on node "mover" (keyed by `channels`), a child box 2 m to its right on node
/// "rider", a still box on node "still", a light and a camera at (0, 1, 6) looking down -Z.
struct AnimatedScene {
  scenes::GltfBuilder builder{"animated-test", 1};
  int mover = -1, rider = -1, still = -1, camera = -1;

  AnimatedScene() {
    const int material = builder.add_material("grey", vec3(0.5f));
    const int box = builder.add_mesh("box", scenes::make_box(vec3(-0.5f), vec3(0.5f)), material);
    mover = builder.add_node("mover", box);
    rider = builder.add_node("rider", box, scenes::NodeTransform::at(dvec3(2.0, 0.0, 0.0)), mover);
    still = builder.add_node("still", box, scenes::NodeTransform::at(dvec3(0.0, 0.0, -3.0)));
    builder.add_point_light("lamp", vec3(0.0f, 4.0f, 2.0f), vec3(1.0f), 20.0f);
    RigDefaults rig;
    rig.width = 64;
    rig.height = 36;
    camera = builder.set_camera("camera", CameraPose::look_at(dvec3(0.0, 1.0, 6.0), dvec3(0.0, 1.0, 0.0)), 0.8, 0.05,
                                0.0, rig);
  }

  Scene load(const test::ScratchDir& dir, const std::string& name = "animated.gltf") const {
    builder.write(dir / name);
    return io::load_gltf(dir / name);
  }
};

/// The centre of mesh `name`'s vertices.
/// The largest x of the vertices of the meshes on `node` (a box centred on x = 0: half its width).
double max_x_of(const Scene& scene, int node) {
  double x = 0.0;
  for (const Mesh& m : scene.meshes)
    if (m.node == node)
      for (const vec3& p : m.positions) x = std::max(x, static_cast<double>(p.x));
  return x;
}

dvec3 centre_of(const Scene& scene, const std::string& node_name, int node) {
  for (const Mesh& m : scene.meshes) {
    if (m.node != node) continue;
    dvec3 sum(0.0);
    for (const vec3& p : m.positions) sum += dvec3(p);
    return sum / static_cast<double>(m.positions.size());
  }
  ADD_FAILURE() << "no mesh on node " << node_name;
  return dvec3(0.0);
}

/// A path of `frames` frames that plays the scene's glTF animation.
PathSpec gltf_path(int frames) {
  PathSpec path;
  path.frames = frames;
  path.gltf_animation = true;
  return path;
}

/// Whether one of the scene's load warnings holds `text`.
bool warned(const Scene& scene, const std::string& text) {
  return std::any_of(scene.warnings.begin(), scene.warnings.end(),
                     [&](const std::string& w) { return w.find(text) != std::string::npos; });
}

void expect_near(const dvec3& got, const dvec3& want, double tolerance, const std::string& what) {
  EXPECT_NEAR(got.x, want.x, tolerance) << what;
  EXPECT_NEAR(got.y, want.y, tolerance) << what;
  EXPECT_NEAR(got.z, want.z, tolerance) << what;
}

TEST(GltfAnimation, TranslationMovesTheNodeItsChildAndTheCameraOverTheFrames) {
  test::ScratchDir dir;
  AnimatedScene a;
  const std::vector<float> times = {0.0f, 2.0f};
  const std::vector<float> moves = {0, 0, 0, 4, 0, 0};  // 4 m along +X in 2 s
  a.builder.add_animation_channel(a.mover, "translation", times, moves);
  const std::vector<float> camera_times = {0.0f, 1.0f};  // ends before the meshes' keys: it stays
  const std::vector<float> camera_moves = {0, 1, 6, 1, 1, 6};
  a.builder.add_animation_channel(a.camera, "translation", camera_times, camera_moves);
  Scene scene = a.load(dir);
  ASSERT_EQ(scene.animation.channels.size(), 2u);
  // A still image shows the rest pose, and says that a path plays the animation.
  expect_near(centre_of(scene, "mover", a.mover), dvec3(0.0), 1e-6, "at rest");
  EXPECT_TRUE(warned(scene, "a path plays them"));

  PathSpec path = gltf_path(5);
  SceneAnimator animator(scene, path);
  EXPECT_EQ(animator.turning_meshes(), 2u) << "mover and its child rider; not the still box";
  for (int f = 0; f < 5; ++f) {
    EXPECT_DOUBLE_EQ(animator.time_of(f), 0.5 * f);
    animator.apply(f);
    expect_near(centre_of(scene, "mover", a.mover), dvec3(1.0 * f, 0.0, 0.0), 1e-5, "mover, frame " + std::to_string(f));
    expect_near(centre_of(scene, "rider", a.rider), dvec3(2.0 + 1.0 * f, 0.0, 0.0), 1e-5, "rider");
    expect_near(centre_of(scene, "still", a.still), dvec3(0.0, 0.0, -3.0), 1e-6, "still");
  }
  const CameraPose base = CameraPose::look_at(dvec3(9.0), dvec3(0.0));
  expect_near(animator.camera_at(1, base).position, dvec3(0.5, 1.0, 6.0), 1e-9, "camera at t = 0.5 s");
  expect_near(animator.camera_at(4, base).position, dvec3(1.0, 1.0, 6.0), 1e-9, "camera after its last key");
  expect_near(animator.camera_at(4, base).back, dvec3(0.0, 0.0, 1.0), 1e-9, "camera still looks down -Z");
  animator.apply(0);
  expect_near(centre_of(scene, "mover", a.mover), dvec3(0.0), 1e-6, "frame 0 again: no drift");

  // Camera keys or a spin beside the animation: one or the other.
  path.camera_keys = {CameraKey{dvec3(0.0, 1.0, 5.0), dvec3(0.0)}};
  EXPECT_THROW(SceneAnimator(scene, path), InputError);
}

/// Six times the signed volume a closed mesh's triangles enclose: positive where they are wound
/// outwards (counter-clockwise seen from outside), negative where they are turned inside out.
double signed_volume(const Mesh& m) {
  double v = 0.0;
  for (size_t t = 0; t < m.indices.size(); t += 3)
    v += glm::dot(dvec3(m.positions[m.indices[t]]),
                  glm::cross(dvec3(m.positions[m.indices[t + 1]]), dvec3(m.positions[m.indices[t + 2]])));
  return v;
}

TEST(GltfAnimation, GpuInstancesMoveWithTheirAnimatedNodeAndKeepFacingOutwards) {
  // The mover draws its box twice by EXT_mesh_gpu_instancing: in place, and 2 m up mirrored in x
  // (scale -1, 1, 1). The animation moves the node 4 m along +X in 2 s; both instances follow,
  // and the mirrored one stays wound outwards in every frame.
  test::ScratchDir dir;
  AnimatedScene a;
  const std::vector<float> times = {0.0f, 2.0f};
  const std::vector<float> moves = {0, 0, 0, 4, 0, 0};
  a.builder.add_animation_channel(a.mover, "translation", times, moves);
  a.builder.write(dir / "plain.gltf");
  nlohmann::json doc = nlohmann::json::parse(std::ifstream(dir / "plain.gltf"));
  const auto add_floats = [&](const std::vector<float>& values, const char* type, size_t count) {
    std::vector<unsigned char> bytes(values.size() * sizeof(float));
    std::memcpy(bytes.data(), values.data(), bytes.size());
    doc["buffers"].push_back({{"byteLength", bytes.size()},
                              {"uri", "data:application/octet-stream;base64," + test::MiniGltf::base64(bytes)}});
    doc["bufferViews"].push_back({{"buffer", doc["buffers"].size() - 1}, {"byteLength", bytes.size()}});
    doc["accessors"].push_back(
        {{"bufferView", doc["bufferViews"].size() - 1}, {"componentType", 5126}, {"count", count}, {"type", type}});
    return doc["accessors"].size() - 1;
  };
  doc["nodes"][a.mover]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"] = {
      {"TRANSLATION", add_floats({0, 0, 0, 0, 2, 0}, "VEC3", 2)}, {"SCALE", add_floats({1, 1, 1, -1, 1, 1}, "VEC3", 2)}};
  doc["extensionsUsed"].push_back("EXT_mesh_gpu_instancing");
  std::ofstream(dir / "instanced.gltf") << doc.dump();
  Scene scene = io::load_gltf(dir / "instanced.gltf");
  std::vector<size_t> instances;
  for (size_t m = 0; m < scene.meshes.size(); ++m)
    if (scene.meshes[m].node == a.mover) instances.push_back(m);
  ASSERT_EQ(instances.size(), 2u);
  const auto centre = [&](size_t m) {
    dvec3 sum(0.0);
    for (const vec3& p : scene.meshes[m].positions) sum += dvec3(p);
    return sum / static_cast<double>(scene.meshes[m].positions.size());
  };
  SceneAnimator animator(scene, gltf_path(3));
  for (int f = 0; f < 3; ++f) {
    animator.apply(f);
    const std::string frame = "frame " + std::to_string(f);
    expect_near(centre(instances[0]), dvec3(2.0 * f, 0.0, 0.0), 1e-5, "instance 0, " + frame);
    expect_near(centre(instances[1]), dvec3(2.0 * f, 2.0, 0.0), 1e-5, "instance 1, " + frame);
    EXPECT_GT(signed_volume(scene.meshes[instances[0]]), 0.0) << frame;
    EXPECT_GT(signed_volume(scene.meshes[instances[1]]), 0.0) << "the mirrored instance, " << frame;
  }
}

TEST(GltfAnimation, RotationSlerpsStepHoldsAndCubicSplineFollowsHermite) {
  test::ScratchDir dir;
  AnimatedScene a;
  // A quarter turn about +Y in 2 s, its end key written as the negated quaternion (the same
  // rotation: slerp must take the short way): at 0.5 s the rider (2 m along +X from the mover) is
  // 22.5° round; a normalized linear blend would give 21.6°.
  const float s = static_cast<float>(std::sqrt(0.5));
  const std::vector<float> times = {0.0f, 2.0f};
  const std::vector<float> quarter = {0, 0, 0, 1, 0, -s, 0, -s};
  a.builder.add_animation_channel(a.mover, "rotation", times, quarter);
  // The still box's scale steps from 1 to 3 at 1 s.
  const std::vector<float> scales = {1, 1, 1, 3, 3, 3}, scale_times = {0.0f, 1.0f};
  a.builder.add_animation_channel(a.still, "scale", scale_times, scales, "STEP");
  Scene scene = a.load(dir);
  SceneAnimator animator(scene, gltf_path(5));
  animator.apply(1);
  const double angle = 22.5 * std::acos(-1.0) / 180.0;
  expect_near(centre_of(scene, "rider", a.rider), dvec3(2.0 * std::cos(angle), 0.0, -2.0 * std::sin(angle)), 1e-5,
              "rider at 22.5 degrees");
  // STEP (keys at 0 s and 1 s): until the second key the first value holds, from it the second.
  EXPECT_NEAR(max_x_of(scene, a.still), 0.5, 1e-6) << "the box keeps its 1 m size at 0.5 s";
  animator.apply(2);  // 1 s: the scale keys' end, where STEP switches
  EXPECT_NEAR(max_x_of(scene, a.still), 1.5, 1e-5) << "scaled 3x from the second key";

  // Key times are float32 in the file, frame times doubles: 45 frames over keys at 0, 1/24, 5/24
  // and 44/24 s (Blender frames 0, 1, 5 and 44 at 24 fps) put frame 1 at 1/24 s a few float ulps
  // below the stored key, and a STEP change showed a frame late. Frame k now shows key k.
  test::ScratchDir dir_step("stepframes");
  AnimatedScene st;
  const std::vector<float> step_times = {0.0f, 1.0f / 24.0f, 5.0f / 24.0f, 44.0f / 24.0f};
  const std::vector<float> step_scales = {1, 1, 1, 3, 3, 3, 1, 1, 1, 3, 3, 3};
  st.builder.add_animation_channel(st.still, "scale", step_times, step_scales, "STEP");
  Scene stepped = st.load(dir_step);
  SceneAnimator step_animator(stepped, gltf_path(45));
  ASSERT_LT(step_animator.time_of(1), static_cast<double>(1.0f / 24.0f)) << "the case this guards against";
  for (const auto& [frame, size] : {std::pair{0, 0.5}, std::pair{1, 1.5}, std::pair{4, 1.5}, std::pair{5, 0.5},
                                    std::pair{43, 0.5}, std::pair{44, 1.5}}) {
    step_animator.apply(frame);
    EXPECT_NEAR(max_x_of(stepped, st.still), size, 1e-5) << "frame " << frame;
  }

  // Keys that are not unit (normalized BYTE keys are unit only to their quantization; here twice
  // as long) turn the same way: glm's slerp of the raw keys fell back to a linear blend, 133
  // pixels off at 160x90 a quarter of the way.
  test::ScratchDir dir_long("longkeys");
  AnimatedScene l;
  std::vector<float> doubled = quarter;
  for (float& v : doubled) v *= 2.0f;
  l.builder.add_animation_channel(l.mover, "rotation", times, doubled);
  Scene long_keys = l.load(dir_long);
  SceneAnimator long_animator(long_keys, gltf_path(5));
  long_animator.apply(1);
  expect_near(centre_of(long_keys, "rider", l.rider), dvec3(2.0 * std::cos(angle), 0.0, -2.0 * std::sin(angle)), 1e-5,
              "rider at 22.5 degrees with keys of length 2");

  // Cubic spline over 2 s: in-tangent a, value v, out-tangent b per key, tangents scaled by the
  // interval. Key 0: v = 0, b = 1 m/s; key 1: a = 2 m/s, v = 2 m (a of key 0 and b of key 1 play
  // no part). At u = 0.5: 0.125 * 2 s * 1 m/s + 0.5 * 2 m - 0.125 * 2 s * 2 m/s = 0.75 m; at the
  // last key, its value.
  test::ScratchDir dir2("cubic");
  AnimatedScene c;
  const std::vector<float> spline = {9, 0, 0, 0, 0, 0, 1, 0, 0,   // key 0: a, v, b
                                     2, 0, 0, 2, 0, 0, 7, 0, 0};  // key 1
  c.builder.add_animation_channel(c.mover, "translation", times, spline, "CUBICSPLINE");
  Scene cubic = c.load(dir2);
  SceneAnimator cubic_animator(cubic, gltf_path(3));
  cubic_animator.apply(1);
  expect_near(centre_of(cubic, "mover", c.mover), dvec3(0.75, 0.0, 0.0), 1e-5, "Hermite at u = 0.5");
  cubic_animator.apply(2);
  expect_near(centre_of(cubic, "mover", c.mover), dvec3(2.0, 0.0, 0.0), 1e-5, "the last key's value");
}

/// Whether every triangle of the meshes on `node` turns its front (by its vertex order) the way
/// its vertices' normals point.
bool triangles_face_their_normals(const Scene& scene, int node) {
  for (const Mesh& m : scene.meshes) {
    if (m.node != node) continue;
    for (size_t t = 0; t < m.indices.size(); t += 3) {
      const vec3 &p0 = m.positions[m.indices[t]], &p1 = m.positions[m.indices[t + 1]], &p2 = m.positions[m.indices[t + 2]];
      if (glm::dot(glm::cross(p1 - p0, p2 - p0), m.normals[m.indices[t]]) <= 0.0f) return false;
    }
  }
  return true;
}

TEST(GltfAnimation, MirroringScaleZeroRestScaleAndTheTimeRangeOfWhatMoves) {
  test::ScratchDir dir;
  AnimatedScene a;
  // The mover mirrors in X from 1 s; the still box pops in from scale 0 at rest to 1 at 2 s.
  const std::vector<float> step_times = {0.0f, 1.0f}, mirror = {1, 1, 1, -1, 1, 1};
  a.builder.add_animation_channel(a.mover, "scale", step_times, mirror, "STEP");
  const std::vector<float> pop_times = {0.0f, 2.0f}, pop = {0, 0, 0, 1, 1, 1};
  a.builder.add_animation_channel(a.still, "scale", pop_times, pop);
  Scene scene = a.load(dir);
  const PathSpec path = gltf_path(3);
  SceneAnimator animator(scene, path);
  EXPECT_DOUBLE_EQ(animator.time_of(2), 2.0);
  animator.apply(0);
  EXPECT_TRUE(triangles_face_their_normals(scene, a.mover));
  animator.apply(2);
  EXPECT_TRUE(triangles_face_their_normals(scene, a.mover)) << "mirrored, the triangles are reversed";
  EXPECT_TRUE(triangles_face_their_normals(scene, a.rider)) << "and its child's";
  expect_near(centre_of(scene, "rider", a.rider), dvec3(-2.0, 0.0, 0.0), 1e-5, "the child mirrored with it");
  // The popped-in box has its size and lies where its node is.
  expect_near(centre_of(scene, "still", a.still), dvec3(0.0, 0.0, -3.0), 1e-5, "popped in");
  EXPECT_TRUE(triangles_face_their_normals(scene, a.still));
  animator.apply(0);
  EXPECT_TRUE(triangles_face_their_normals(scene, a.mover)) << "back at frame 0";

  // A camera scaled to nothing has no pose: refused before the first frame, naming frame and time.
  test::ScratchDir dir2("camera");
  AnimatedScene c;
  const std::vector<float> shrink = {1, 1, 1, 0, 0, 0};
  c.builder.add_animation_channel(c.camera, "scale", pop_times, shrink);
  Scene shrinking = c.load(dir2);
  try {
    SceneAnimator refused(shrinking, path);
    FAIL() << "a camera without a pose was played";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fmt::format("the animated camera (node {}) at frame 2 (t = 2 s)", c.camera)),
              std::string::npos)
        << e.what();
  }
}

TEST(GltfAnimation, ARefitBvhOfAMirroredSmoothMeshShadesAsAFreshOne) {
  // A smooth sphere mirrored in X from 1 s: its triangles are reversed, and a refit BVH must hand
  // back barycentrics in the new vertex order, or the interpolated normals (and so the shading)
  // differ from those of a BVH built for the mirrored scene.
  test::ScratchDir dir;
  AnimatedScene a;
  const int grey = a.builder.add_material("smooth", vec3(0.7f), -1, false);
  const int ball = a.builder.add_node("ball", a.builder.add_mesh("ball", scenes::make_uv_sphere(0.8f, 12, 6), grey),
                                      scenes::NodeTransform::at(dvec3(-1.2, 1.0, 1.0)));
  const std::vector<float> times = {0.0f, 1.0f}, mirror = {1, 1, 1, -1, 1, 1};
  a.builder.add_animation_channel(ball, "scale", times, mirror, "STEP");
  Scene scene = a.load(dir);
  SceneAnimator animator(scene, gltf_path(2));
  RenderScene refit(scene, true);
  animator.apply(1);
  (void)refit.update_geometry(animator.moving_mesh_indices());
  const RenderScene fresh(scene);
  const StereoRig rig = test::rig_at(scene, 96, 54);
  const Executor executor(2);
  TraceCounts counts;
  const Image updated = traced_eye(refit, rig.eye(Eye::left), executor, counts);
  const Image rebuilt = traced_eye(fresh, rig.eye(Eye::left), executor, counts);
  const std::span<const float> u(updated.data_f32(planes::rgb), 3 * updated.pixel_count());
  const std::span<const float> r(rebuilt.data_f32(planes::rgb), 3 * rebuilt.pixel_count());
  EXPECT_TRUE(std::equal(u.begin(), u.end(), r.begin()));
  EXPECT_GT(std::count_if(u.begin(), u.end(), [](float x) { return x > 0.0f; }), 0) << "something is lit";
}

/// The traced left eye of `scene` through the rig of its camera, 96x54.
Image traced_left(const Scene& scene) {
  const RenderScene prepared(scene);
  const StereoRig rig = test::rig_at(scene, 96, 54);
  TraceCounts counts;
  return traced_eye(prepared, rig.eye(Eye::left), Executor(2), counts);
}

const Light& light_named(const Scene& scene, const std::string& name) {
  for (const Light& l : scene.lights)
    if (l.name == name) return l;
  throw std::logic_error("no light " + name);
}

bool same_radiance(const Image& a, const Image& b) {
  const std::span<const float> x(a.data_f32(planes::rgb), 3 * a.pixel_count());
  const std::span<const float> y(b.data_f32(planes::rgb), 3 * b.pixel_count());
  return x.size() == y.size() && std::equal(x.begin(), x.end(), y.begin());
}

TEST(GltfAnimation, LightsOnAnimatedNodesMoveAndShineAsIfPlacedThere) {
  // A lamp on a mesh-less node that carries it 2 m along +X, and a spot on the mover turning a
  // quarter about +Y: only lights move, so the path is valid and refits nothing.
  test::ScratchDir dir;
  AnimatedScene a;
  const int holder = a.builder.add_node("holder", -1, scenes::NodeTransform::at(dvec3(-1.0, 0.0, 1.0)));
  a.builder.add_point_light("carried", vec3(0.0f, 2.0f, 0.0f), vec3(1.0f, 0.8f, 0.6f), 15.0f, holder);
  const std::vector<float> times = {0.0f, 1.0f}, carry = {-1, 0, 1, 1, 0, 1};
  a.builder.add_animation_channel(holder, "translation", times, carry);
  Scene scene = a.load(dir);
  ASSERT_EQ(scene.lights.size(), 2u);
  EXPECT_FALSE(warned(scene, "stay where they are")) << "lights follow their nodes now";
  SceneAnimator animator(scene, gltf_path(2));
  EXPECT_EQ(animator.moving_lights(), 1u);
  EXPECT_EQ(animator.turning_meshes(), 0u);
  EXPECT_FALSE(animator.moves_geometry());
  {
    // The carried lamp dropped (--lights 1): nothing visible moves, and the frames keep their times.
    Scene one_light = scene;
    keep_first_lights(one_light, 1);
    ASSERT_EQ(one_light.lights.front().name, "lamp");
    const SceneAnimator kept(one_light, gltf_path(2));
    EXPECT_EQ(kept.moving_lights(), 0u);
    EXPECT_DOUBLE_EQ(kept.time_of(1), animator.time_of(1));
  }
  const Image at_rest = traced_left(scene);
  animator.apply(1);
  expect_near(dvec3(light_named(scene, "carried").position), dvec3(1.0, 2.0, 1.0), 1e-6, "carried lamp at frame 1");
  expect_near(dvec3(light_named(scene, "lamp").position), dvec3(0.0, 4.0, 2.0), 1e-6, "the root lamp stays");
  const Image moved = traced_left(scene);
  EXPECT_FALSE(same_radiance(at_rest, moved)) << "the moved lamp lights the boxes differently";

  // The same lamp placed there in a still file shades bit-identically.
  test::ScratchDir dir2("still");
  AnimatedScene b;
  const int fixed = b.builder.add_node("holder", -1, scenes::NodeTransform::at(dvec3(1.0, 0.0, 1.0)));
  b.builder.add_point_light("carried", vec3(0.0f, 2.0f, 0.0f), vec3(1.0f, 0.8f, 0.6f), 15.0f, fixed);
  EXPECT_TRUE(same_radiance(moved, traced_left(b.load(dir2))));

  // A directional light turns with its node: a quarter turn about +Y takes -Z to -X.
  test::ScratchDir dir3("sun");
  AnimatedScene c;
  c.builder.add_directional_light("sun", vec3(0.0f, 0.0f, -1.0f), vec3(1.0f), 2.0f, c.mover);
  const float h = static_cast<float>(std::sqrt(0.5));
  const std::vector<float> quarter = {0, 0, 0, 1, 0, h, 0, h};
  c.builder.add_animation_channel(c.mover, "rotation", times, quarter);
  Scene turning = c.load(dir3);
  SceneAnimator sunrise(turning, gltf_path(2));
  EXPECT_EQ(sunrise.moving_lights(), 1u);
  sunrise.apply(1);
  expect_near(dvec3(light_named(turning, "sun").direction), dvec3(-1.0, 0.0, 0.0), 1e-6, "the sun's direction, turned");
}

TEST(GltfAnimation, OneClipPlaysByNameOrIndexAndClipsKeyingOnePropertyCannotPlayTogether) {
  test::ScratchDir dir;
  AnimatedScene a;
  const std::vector<float> times = {0.0f, 2.0f};
  const std::vector<float> walk = {0, 0, 0, 4, 0, 0}, hop = {0, 0, 0, 0, 2, 0};
  a.builder.add_animation_channel(a.mover, "translation", times, walk, "LINEAR", "walk");
  a.builder.add_animation_channel(a.mover, "translation", times, hop, "LINEAR", "hop");
  const std::vector<float> late = {3.0f, 4.0f}, grow = {1, 1, 1, 2, 2, 2};
  a.builder.add_animation_channel(a.still, "scale", late, grow, "LINEAR", "hop");
  Scene scene = a.load(dir);
  ASSERT_EQ(scene.animation.clips, (std::vector<std::string>{"walk", "hop"}));
  EXPECT_TRUE(warned(scene, "2 animation(s) ('walk', 'hop')")) << "the load names the clips";

  // Every clip at once: both key the mover's translation.
  try {
    SceneAnimator both(scene, gltf_path(3));
    FAIL() << "two clips keying one property played together";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fmt::format("'walk' and 'hop' of scene 'animated-test' both key node {}'s "
                                                     "translation",
                                                     a.mover)),
              std::string::npos)
        << e.what();
  }

  PathSpec path = gltf_path(3);
  path.gltf_clip = "walk";
  {
    SceneAnimator walking(scene, path);
    EXPECT_EQ(walking.clip(), "'walk'");
    EXPECT_EQ(walking.turning_meshes(), 2u) << "the mover and its rider, not the still box of the other clip";
    EXPECT_DOUBLE_EQ(walking.time_of(2), 2.0) << "the time range is the clip's own";
    walking.apply(2);
    expect_near(centre_of(scene, "mover", a.mover), dvec3(4.0, 0.0, 0.0), 1e-5, "walked");
  }
  path.gltf_clip = "#0";  // by index, as messages label a clip
  EXPECT_EQ(SceneAnimator(scene, path).clip(), "'walk'");
  path.gltf_clip = "1";  // no clip has that name: the index
  {
    SceneAnimator hopping(scene, path);
    EXPECT_EQ(hopping.clip(), "'hop'");
    EXPECT_EQ(hopping.turning_meshes(), 3u);
    EXPECT_DOUBLE_EQ(hopping.time_of(0), 0.0);
    EXPECT_DOUBLE_EQ(hopping.time_of(2), 4.0);
    hopping.apply(1);
    expect_near(centre_of(scene, "mover", a.mover), dvec3(0.0, 2.0, 0.0), 1e-5, "hopped, at t = 2 s");
  }
  path.gltf_clip = "#2";
  EXPECT_THROW(SceneAnimator(scene, path), InputError);
  for (const std::string bad : {"run", "2", "-1"}) {
    path.gltf_clip = bad;
    try {
      SceneAnimator none(scene, path);
      FAIL() << bad;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fmt::format("has no glTF animation '{}'; its animations are 'walk', 'hop'",
                                                       bad)),
                std::string::npos)
          << e.what();
    }
  }
  // A clip chosen without playing the animation is a contradiction.
  PathSpec keys_only;
  keys_only.frames = 2;
  keys_only.gltf_clip = "walk";
  EXPECT_THROW(keys_only.validate(), InputError);
}

TEST(GltfAnimation, BadAnimationsAndScenesWithoutOneAreRefused) {
  test::ScratchDir dir;
  {
    AnimatedScene a;  // one clip keying a property twice: glTF forbids it
    const std::vector<float> times = {0.0f, 1.0f}, moves = {0, 0, 0, 1, 0, 0};
    a.builder.add_animation_channel(a.mover, "translation", times, moves);
    a.builder.add_animation_channel(a.mover, "translation", times, moves);
    a.builder.write(dir / "twice.gltf");
    try {
      (void)io::load_gltf(dir / "twice.gltf");
      FAIL() << "a clip keying one property twice was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("/animations/0/channels/1/target: keys node 0's translation as "
                                           "/animations/0/channels/0 does"),
                std::string::npos)
          << e.what();
    }
  }
  {
    AnimatedScene a;
    const std::vector<float> times = {1.0f, 0.5f};  // decreasing
    const std::vector<float> moves = {0, 0, 0, 1, 0, 0};
    a.builder.add_animation_channel(a.mover, "translation", times, moves);
    a.builder.write(dir / "decreasing.gltf");
    try {
      (void)io::load_gltf(dir / "decreasing.gltf");
      FAIL() << "decreasing key times were accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("/animations/0/samplers/0/input: key times must increase"), std::string::npos)
          << e.what();
    }
  }
  {
    // A key rotation of length zero: refused as a node's rotation is (it was played as none).
    AnimatedScene a;
    const std::vector<float> times = {0.0f, 1.0f};
    const std::vector<float> turns = {0, 0, 0, 1, 0, 0, 0, 0};
    a.builder.add_animation_channel(a.mover, "rotation", times, turns);
    a.builder.write(dir / "zero-rotation.gltf");
    try {
      (void)io::load_gltf(dir / "zero-rotation.gltf");
      FAIL() << "a zero quaternion key was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("/animations/0/samplers/0/output: the rotation of key 1 (at 1 s) is a "
                                           "quaternion of length zero"),
                std::string::npos)
          << e.what();
    }
  }
  {
    AnimatedScene a;  // no animation at all
    Scene scene = a.load(dir, "still.gltf");
    try {
      SceneAnimator animator(scene, gltf_path(3));
      FAIL() << "a scene without animation was played";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("has no glTF node animation"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace sb
