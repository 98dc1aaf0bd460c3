// Animation along a path: rigid spins keep frame 0 exact (no drift), the camera follows its key
// poses, and a refit or rebuilt BVH sees the moved geometry exactly as a freshly built one does.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "renderer/animation.hpp"
#include "renderer/error.hpp"
#include "renderer/parallel.hpp"
#include "renderer/render_scene.hpp"
#include "renderer/stages/disocclusion.hpp"
#include "support/render_support.hpp"

namespace sb {
namespace {

TEST(Animation, SpinTurnsAboutThePivotWithoutDrift) {
  Scene scene = test::load_builtin("box-wall");
  const Scene original = scene;
  PathSpec path;
  path.frames = 5;
  path.spin = Spin{{0.0, 1.0, 0.0}, dvec3(0.0), 90.0, ""};
  SceneAnimator animator(scene, path);
  EXPECT_EQ(animator.turning_meshes(), scene.meshes.size());
  animator.apply(1);  // 90 degrees about +Y through the origin: (x, y, z) -> (z, y, -x)
  const vec3 p0 = original.meshes[0].positions[0], p1 = scene.meshes[0].positions[0];
  EXPECT_NEAR(p1.x, p0.z, 1e-5);
  EXPECT_NEAR(p1.y, p0.y, 1e-6);
  EXPECT_NEAR(p1.z, -p0.x, 1e-5);
  animator.apply(4);  // a full turn: back where it started, to float rounding
  for (size_t m = 0; m < scene.meshes.size(); ++m)
    for (size_t i = 0; i < scene.meshes[m].positions.size(); ++i)
      EXPECT_NEAR(glm::length(scene.meshes[m].positions[i] - original.meshes[m].positions[i]), 0.0f, 1e-5f);
  animator.apply(0);
  EXPECT_EQ(scene.meshes[0].positions, original.meshes[0].positions) << "frame 0 is the scene as loaded";
  EXPECT_THROW(animator.apply(5), InputError);

  // An axis is a direction, whatever its length: one whose length overflows (1e300) or whose
  // square underflows (1e-300) turns the scene as the unit axis does.
  for (const double scale : {1e300, 1e-300, 7.0}) {
    Scene turned = original;
    PathSpec scaled = path;
    scaled.spin->axis = dvec3(0.0, scale, 0.0);
    SceneAnimator a(turned, scaled);
    a.apply(1);
    animator.apply(1);
    EXPECT_EQ(turned.meshes[0].positions, scene.meshes[0].positions) << "axis length " << scale;
  }
  path.spin->axis = dvec3(0.0, 0.0, 0.0);
  EXPECT_THROW(path.validate(), InputError);
  path.spin->axis = dvec3(0.0, std::numeric_limits<double>::infinity(), 0.0);
  EXPECT_THROW(path.validate(), InputError);
}

TEST(Animation, CameraFollowsKeysAndBadPathsAreRejected) {
  Scene scene = test::load_builtin("box-wall");
  PathSpec path;
  path.frames = 5;
  path.camera_keys = parse_camera_keys("0,1,4>0,1,0;4,1,4>4,1,0;4,1,8>4,1,0");
  SceneAnimator animator(scene, path);
  const CameraPose base;
  EXPECT_NEAR(glm::length(animator.camera_at(0, base).position - dvec3(0, 1, 4)), 0.0, 1e-12);
  EXPECT_NEAR(glm::length(animator.camera_at(1, base).position - dvec3(2, 1, 4)), 0.0, 1e-12);
  EXPECT_NEAR(glm::length(animator.camera_at(3, base).position - dvec3(4, 1, 6)), 0.0, 1e-12);
  EXPECT_NEAR(glm::length(animator.camera_at(4, base).position - dvec3(4, 1, 8)), 0.0, 1e-12);
  EXPECT_NEAR(glm::length(animator.camera_at(2, base).back - dvec3(0, 0, 1)), 0.0, 1e-12);
  EXPECT_THROW((void)parse_camera_keys("0,1,4"), InputError);
  EXPECT_THROW((void)parse_camera_keys("0,1>0,1,0"), InputError);
  // Frames spread evenly over the keys stand at key j only where (j - 1)(F - 1) is a multiple of
  // K - 1: 4 frames over 3 keys stand at 0, 2/3, 4/3 and 2, never at key 2.
  PathSpec spread;
  spread.camera_keys = parse_camera_keys("0,1,4>0,1,0;4,1,4>4,1,0;4,1,8>4,1,0;0,1,8>0,1,0");
  spread.frames = 4;
  EXPECT_EQ(spread.keys_between_frames(), std::vector<size_t>{}) << "3 steps over 3 gaps: every key";
  spread.frames = 5;
  EXPECT_EQ(spread.keys_between_frames(), (std::vector<size_t>{2, 3}));
  spread.frames = 7;
  EXPECT_EQ(spread.keys_between_frames(), std::vector<size_t>{});
  spread.frames = 1;
  EXPECT_EQ(spread.keys_between_frames(), std::vector<size_t>{}) << "one frame: said otherwise";
  // A ';' after the last key leaves a key out, as two in a row do (it was accepted silently).
  for (const char* empty : {"0,1,4>0,1,0;", "0,1,4>0,1,0;;4,1,4>4,1,0"}) {
    try {
      (void)parse_camera_keys(empty);
      ADD_FAILURE() << empty;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("camera key 2 is empty"), std::string::npos) << e.what();
    }
  }
  PathSpec bad;
  bad.frames = 0;
  EXPECT_THROW(bad.validate(), InputError);
  bad.frames = 2;
  bad.camera_keys = {CameraKey{dvec3(1.0), dvec3(1.0)}};
  EXPECT_THROW(bad.validate(), InputError);
  PathSpec nothing;
  nothing.spin = Spin{{0.0, 1.0, 0.0}, std::nullopt, 1.0, "no-such-mesh"};
  EXPECT_THROW(SceneAnimator(scene, nothing), InputError);
}

TEST(Animation, APathWhoseCameraReachesItsTargetIsRejected) {
  // Each key is valid, but position and target swap places: frame 1 of 3 stands on its target.
  PathSpec crossing;
  crossing.frames = 3;
  crossing.camera_keys = parse_camera_keys("0,1,4>0,1,3;0,1,3>0,1,4");
  try {
    crossing.validate();
    ADD_FAILURE() << "a camera on its own target has no view direction";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("frame 1 of 3: the camera reaches its target between camera keys 1 and 2"),
              std::string::npos)
        << e.what();
  }
  // No frame on the target, but the path passes through it between two frames: the camera would
  // turn about between them. Refused for any number of frames, naming the keys.
  for (const int frames : {2, 10}) {
    crossing.frames = frames;
    crossing.camera_keys = parse_camera_keys("0,1,4>0,1,0;0,1,-4>0,1,0");
    try {
      crossing.validate();
      ADD_FAILURE() << frames << " frames: a path through its target was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("the camera passes through its target between camera keys 1 and 2 (50 % of "
                                           "the way"),
                std::string::npos)
          << e.what();
    }
  }
  // Passing beside the target is a path like any other.
  crossing.camera_keys = parse_camera_keys("0,1,4>0.01,1,0;0,1,-4>0.01,1,0");
  EXPECT_NO_THROW(crossing.validate());
}

TEST(Animation, SpinAnglesBeyondATurnPerFrameAndNonFiniteGeometryAreRejected) {
  PathSpec path;
  path.frames = 3;
  path.spin = Spin{{0.0, 1.0, 0.0}, std::nullopt, 360.0, ""};
  EXPECT_NO_THROW(path.validate());
  path.spin->degrees_per_frame = -360.5;
  EXPECT_THROW(path.validate(), InputError);
  path.spin->degrees_per_frame = 1e308;  // frame 2 would turn by inf degrees: NaN vertices
  EXPECT_THROW(path.validate(), InputError);

  // Geometry that became NaN (by any route) is an error when the BVH is updated, not an empty
  // image that would compare as identical to an equally empty truth.
  Scene scene = test::load_builtin("box-wall");
  RenderScene prepared(scene, true);
  scene.meshes[0].positions[3] = vec3(std::nanf(""), 0.0f, 0.0f);
  try {
    (void)prepared.update_geometry(std::vector<size_t>{0});
    ADD_FAILURE() << "a NaN vertex must not reach the BVH";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("vertex 3 of mesh '" + scene.meshes[0].name + "' is not a finite point"),
              std::string::npos)
        << e.what();
  }
}

/// What the right eye's primary rays hit after the meshes named `prefix...` moved: through an
/// updated BVH (refit or rebuilt; only the moved meshes' data is copied) and through one built
/// afresh for the moved scene.
void expect_update_matches_fresh_build(bool refit, const std::string& prefix = "") {
  Scene scene = test::load_builtin("box-wall");
  PathSpec path;
  path.frames = 3;
  path.spin = Spin{{0.0, 1.0, 0.0}, std::nullopt, 20.0, prefix};
  SceneAnimator animator(scene, path);
  RenderScene prepared(scene, refit);
  const StereoRig rig = test::rig_at(scene, 96, 54);
  const Executor executor(2);
  const VisibleSurfaces before = trace_visible_surfaces(prepared, rig.eye(Eye::right), executor);
  const float offset_before = prepared.ray_epsilon();
  animator.apply(2);
  EXPECT_GE(prepared.update_geometry(animator.moving_mesh_indices()), 0.0);
  const VisibleSurfaces updated = trace_visible_surfaces(prepared, rig.eye(Eye::right), executor);
  const RenderScene fresh(scene);
  const VisibleSurfaces rebuilt = trace_visible_surfaces(fresh, rig.eye(Eye::right), executor);
  // The shadow-ray offset follows the moved bounds (the turned wall reaches further out), as a
  // scene prepared at this frame has it: shading must not depend on the frame prepared first.
  if (prefix.empty()) {
    EXPECT_NE(offset_before, fresh.ray_epsilon()) << "the turn must change the bounds to test the offset";
  }
  EXPECT_EQ(prepared.ray_epsilon(), fresh.ray_epsilon());
  EXPECT_EQ(updated.prim, rebuilt.prim);
  EXPECT_EQ(updated.depth, rebuilt.depth);
  EXPECT_NE(updated.prim, before.prim) << "the scene turned 40 degrees; the image must change";
}

TEST(Animation, RefitBvhSeesTheMovedScene) { expect_update_matches_fresh_build(true); }
TEST(Animation, RebuiltBvhSeesTheMovedScene) { expect_update_matches_fresh_build(false); }
TEST(Animation, RefitOfOneMovedMeshSeesTheMovedScene) { expect_update_matches_fresh_build(true, "wall"); }
TEST(Animation, RebuildOfOneMovedMeshSeesTheMovedScene) { expect_update_matches_fresh_build(false, "wall"); }

}  // namespace
}  // namespace sb
