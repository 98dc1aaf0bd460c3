// glTF node animations played along a path: the loader reads translation, rotation and scale
// channels with their interpolation, a path moves the animated meshes rigidly with their nodes
// (a child with its parent) and the rig with an animated camera, and bad animations are refused
// naming the JSON path.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "renderer/animation.hpp"
#include "renderer/error.hpp"
#include "renderer/io/gltf_loader.hpp"
#include "scenes/gltf_builder.hpp"
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
  EXPECT_DOUBLE_EQ(scene.animation.start(), 0.0);
  EXPECT_DOUBLE_EQ(scene.animation.end(), 2.0);
  // A still image shows the rest pose, and says that a path plays the animation.
  expect_near(centre_of(scene, "mover", a.mover), dvec3(0.0), 1e-6, "at rest");
  bool said = false;
  for (const std::string& w : scene.warnings) said |= w.find("a path plays them") != std::string::npos;
  EXPECT_TRUE(said);

  PathSpec path;
  path.frames = 5;
  path.gltf_animation = true;
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

TEST(GltfAnimation, RotationSlerpsStepHoldsAndCubicSplineFollowsHermite) {
  test::ScratchDir dir;
  AnimatedScene a;
  // A quarter turn about +Y in 1 s: at 0.5 s the rider (2 m along +X from the mover) is 45° round.
  const float s = static_cast<float>(std::sqrt(0.5));
  const std::vector<float> times = {0.0f, 1.0f};
  const std::vector<float> quarter = {0, 0, 0, 1, 0, s, 0, s};
  a.builder.add_animation_channel(a.mover, "rotation", times, quarter);
  // The still box's scale steps from 1 to 3 at 1 s.
  const std::vector<float> scales = {1, 1, 1, 3, 3, 3};
  a.builder.add_animation_channel(a.still, "scale", times, scales, "STEP");
  Scene scene = a.load(dir);
  PathSpec path;
  path.frames = 3;
  path.gltf_animation = true;
  SceneAnimator animator(scene, path);
  animator.apply(1);
  const double r = 2.0 / std::sqrt(2.0);
  expect_near(centre_of(scene, "rider", a.rider), dvec3(r, 0.0, -r), 1e-5, "rider at 45 degrees");
  // STEP: half-way the first key's value holds (the box keeps its 1 m size).
  double extent = 0.0;
  for (const Mesh& m : scene.meshes)
    if (m.node == a.still)
      for (const vec3& p : m.positions) extent = std::max(extent, static_cast<double>(p.x));
  EXPECT_NEAR(extent, 0.5, 1e-6);
  animator.apply(2);
  extent = 0.0;
  for (const Mesh& m : scene.meshes)
    if (m.node == a.still)
      for (const vec3& p : m.positions) extent = std::max(extent, static_cast<double>(p.x));
  EXPECT_NEAR(extent, 1.5, 1e-5) << "scaled 3x at the last key";

  // Cubic spline: in-tangent, value, out-tangent per key. With the out-tangent 4 m/s at the first
  // key and zero elsewhere, at u = 0.5 of 1 s: 0.5 * 0 + 0.125 * 1 s * 4 m/s + 0.5 * 2 m = 1.5 m.
  test::ScratchDir dir2("cubic");
  AnimatedScene c;
  const std::vector<float> spline = {0, 0, 0, 0, 0, 0, 4, 0, 0,   // key 0: a, v, b
                                     0, 0, 0, 2, 0, 0, 0, 0, 0};  // key 1
  c.builder.add_animation_channel(c.mover, "translation", times, spline, "CUBICSPLINE");
  Scene cubic = c.load(dir2);
  SceneAnimator cubic_animator(cubic, path);
  cubic_animator.apply(1);
  expect_near(centre_of(cubic, "mover", c.mover), dvec3(1.5, 0.0, 0.0), 1e-5, "Hermite at u = 0.5");
}

TEST(GltfAnimation, BadAnimationsAndScenesWithoutOneAreRefused) {
  test::ScratchDir dir;
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
    AnimatedScene a;  // no animation at all
    Scene scene = a.load(dir, "still.gltf");
    PathSpec path;
    path.frames = 3;
    path.gltf_animation = true;
    try {
      SceneAnimator animator(scene, path);
      FAIL() << "a scene without animation was played";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("has no glTF node animation"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace sb
