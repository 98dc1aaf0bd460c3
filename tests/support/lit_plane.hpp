// A test fixture around the built-in lit-plane scene — a fronto-parallel plane 4 m in front of the
// camera — with rigs that give the plane a chosen disparity, for exact warping tests.
#pragma once

#include <gtest/gtest.h>

#include "support/render_support.hpp"

namespace sb::test {

class LitPlane : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = new Scene(load_builtin("lit-plane"));
    prepared_ = new RenderScene(*scene_);
  }
  static void TearDownTestSuite() {
    delete prepared_;
    delete scene_;
  }

  /// The scene's rig at width x height whose disparity on the plane is `disparity` px:
  /// d(4 m) = f e (1/c - 1/4) solved for the convergence c.
  static StereoRig rig_with_plane_disparity(double disparity, int width = 320, int height = 180) {
    RigOverrides o;
    o.width = width;
    o.height = height;
    const StereoRig base = resolve_rig(*scene_, o);
    o.convergence = 1.0 / (disparity / (base.focal_px() * base.params().interaxial) + 1.0 / 4.0);
    return resolve_rig(*scene_, o);
  }

  static inline Scene* scene_ = nullptr;
  static inline RenderScene* prepared_ = nullptr;
};

}  // namespace sb::test
