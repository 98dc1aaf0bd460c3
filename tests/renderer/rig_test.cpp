// The stereo rig of DESIGN §2: zero parallax at the convergence plane, the disparity formula,
// the interaxial/max-disparity conversions, mirror symmetry, and rejection of bad parameters.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <utility>

#include "renderer/error.hpp"
#include "renderer/rig.hpp"
#include "renderer/scene.hpp"

namespace sb {
namespace {

StereoRig make_rig(double e = 0.064, double c = 2.0, int w = 1920, int h = 1080) {
  RigParams p;
  p.interaxial = e;
  p.convergence = c;
  p.width = w;
  p.height = h;
  p.vfov = degrees_to_radians(50.0);
  // A pose that is not axis-aligned, so that the test covers the general basis.
  return StereoRig(CameraPose::look_at({1.0, 2.0, 3.0}, {-2.0, 1.5, -4.0}), p);
}

TEST(Rig, ConvergencePlaneHasZeroDisparity) {
  const StereoRig rig = make_rig();
  const EyeCamera l = rig.eye(Eye::left), r = rig.eye(Eye::right), c = rig.eye(Eye::center);
  for (double x : {-0.7, 0.0, 0.45})
    for (double y : {-0.3, 0.2}) {
      // A point on the plane at distance c in front of the centre camera.
      const dvec3 p = c.unproject(960.0 + x * 1000.0, 540.0 + y * 1000.0, 2.0);
      const dvec3 pl = l.project(p), pr = r.project(p);
      EXPECT_NEAR(pl.x, pr.x, 1e-9);
      EXPECT_NEAR(pl.y, pr.y, 1e-9);
      EXPECT_NEAR(pl.z, 2.0, 1e-12);
    }
}

TEST(Rig, DisparityMatchesTheFormulaAtSeveralDepths) {
  for (double c : {0.3, 2.0, 6.0}) {
    const StereoRig rig = make_rig(0.064, c);
    const EyeCamera l = rig.eye(Eye::left), r = rig.eye(Eye::right), ctr = rig.eye(Eye::center);
    const double f = 540.0 / std::tan(degrees_to_radians(25.0));
    EXPECT_NEAR(rig.focal_px(), f, 1e-9);
    for (double z : {0.25, 0.5, 1.0, 2.0, 3.7, 10.0, 100.0, 1e4}) {
      const dvec3 p = ctr.unproject(700.0, 300.0, z);
      const double measured = r.project(p).x - l.project(p).x;
      const double formula = f * 0.064 * (1.0 / c - 1.0 / z);
      EXPECT_NEAR(measured, formula, 1e-4) << "c " << c << " z " << z;
      EXPECT_NEAR(rig.disparity_px(z), formula, 1e-9);
      EXPECT_NEAR(r.project(p).y, l.project(p).y, 1e-9);  // no vertical parallax
    }
    EXPECT_NEAR(rig.max_disparity_px(), f * 0.064 / c, 1e-9);
  }
}

TEST(Rig, InteraxialAndMaxDisparityRoundTrip) {
  const double vfov = degrees_to_radians(40.0);
  for (double d : {1.0, 15.0, 47.5, 100.0})
    for (double c : {0.3, 2.0, 6.0})
      for (int h : {270, 1080, 2160}) {
        const double e = interaxial_from_max_disparity(d, c, vfov, h);
        EXPECT_NEAR(max_disparity_from_interaxial(e, c, vfov, h), d, 1e-9 * d);
      }
  Scene empty;
  RigOverrides o;
  o.max_disparity_px = 30.0;
  o.convergence = 2.0;
  o.width = 600;
  o.height = 600;
  const StereoRig rig = resolve_rig(empty, o);
  EXPECT_NEAR(rig.max_disparity_px(), 30.0, 1e-9);
}

TEST(Rig, EyesAreMirrorImagesForASymmetricScene) {
  // Centre camera at the origin looking down -Z; points mirrored about its vertical plane.
  RigParams p;
  p.width = 640;
  p.height = 360;
  const StereoRig rig(CameraPose{}, p);
  const EyeCamera l = rig.eye(Eye::left), r = rig.eye(Eye::right);
  for (const dvec3& q : {dvec3(0.3, 0.1, -1.5), dvec3(1.2, -0.4, -4.0), dvec3(0.05, 0.2, -0.6)}) {
    const dvec3 mirrored(-q.x, q.y, q.z);
    const dvec3 a = l.project(q), b = r.project(mirrored);
    EXPECT_NEAR(a.x, 640.0 - b.x, 1e-9);  // x_left(q) mirrors x_right(mirror q) about the image centre
    EXPECT_NEAR(a.y, b.y, 1e-9);
  }
  EXPECT_NEAR(l.cx + r.cx, 640.0, 1e-9);
}

TEST(Rig, ProjectionMatrixAgreesWithProject) {
  const StereoRig rig = make_rig(0.064, 2.0, 800, 600);
  for (Eye e : {Eye::left, Eye::right}) {
    const EyeCamera cam = rig.eye(e);
    const dmat4 vp = cam.projection_matrix() * cam.view_matrix();
    const dvec3 world = cam.unproject(123.25, 456.5, 3.3);
    const dvec4 clip = vp * dvec4(world, 1.0);
    const double x_px = (clip.x / clip.w + 1.0) * 0.5 * 800.0;
    const double y_px = (1.0 - clip.y / clip.w) * 0.5 * 600.0;
    EXPECT_NEAR(x_px, 123.25, 1e-7);
    EXPECT_NEAR(y_px, 456.5, 1e-7);
    EXPECT_NEAR(clip.w, 3.3, 1e-9);
    // Ray through the pixel hits the same point.
    const dvec3 dir = cam.ray_direction(123.25, 456.5);
    const dvec3 to = glm::normalize(world - cam.origin);
    EXPECT_NEAR(glm::dot(dir, to), 1.0, 1e-12);
  }
}

TEST(Rig, BadParametersAreInputErrors) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (double e : {-0.064, 0.0, nan, inf}) EXPECT_THROW(make_rig(e), InputError) << e;
  for (double c : {-1.0, 0.0, nan}) EXPECT_THROW(make_rig(0.064, c), InputError) << c;
  EXPECT_THROW(make_rig(0.064, 2.0, 0, 1080), InputError);
  EXPECT_THROW(make_rig(0.064, 2.0, 1920, 16385), InputError);
  EXPECT_NO_THROW(make_rig(0.064, 2.0, 16384, 16384));
  try {
    make_rig(-1.0);
  } catch (const InputError& err) {
    EXPECT_NE(std::string(err.what()).find("interaxial"), std::string::npos);
  }
  Scene empty;
  RigOverrides both;
  both.interaxial = 0.06;
  both.max_disparity_px = 20.0;
  EXPECT_THROW((void)resolve_rig(empty, both), InputError);

  // Rigs whose rays cannot be set up: an interaxial beyond the span of a scene (1e20 m aborted the
  // ray tracer on NaN rays), a convergence so near that the sensor shift is infinite, a disparity
  // of a billion pixels. The largest accepted ones still render.
  // A convergence beyond that span is refused too (1e308 m printed as a 300-digit number).
  for (const auto& [e, c] :
       {std::pair{1e20, 2.0}, std::pair{1.0, 1e-6}, std::pair{0.064, 1e-300}, std::pair{0.064, 1e308}}) {
    try {
      make_rig(e, c);
      ADD_FAILURE() << "e " << e << " c " << c;
    } catch (const InputError& err) {
      const bool beyond_span = e > kMaxSceneCoordinate || c > kMaxSceneCoordinate;
      EXPECT_NE(std::string(err.what()).find(beyond_span ? "a scene may span" : "a rig may have"), std::string::npos)
          << err.what();
    }
  }
  EXPECT_NO_THROW(make_rig(1e15, 1e15));
  RigOverrides wide;
  wide.max_disparity_px = 1e9;
  EXPECT_THROW((void)resolve_rig(empty, wide), InputError);
  wide.max_disparity_px = kMaxDisparityPx;
  EXPECT_NO_THROW((void)resolve_rig(empty, wide));
  // A field of view so narrow that the focal length overflows the rasterizer's floats: plain-raster
  // drew an empty image where plain-rt saw the scene. Refused; a narrow one that renders is kept.
  RigOverrides narrow;
  narrow.vfov = degrees_to_radians(1e-100);
  narrow.interaxial = 1e-98;
  try {
    (void)resolve_rig(empty, narrow);
    ADD_FAILURE() << "a field of view of 1e-100 degrees was accepted";
  } catch (const InputError& err) {
    EXPECT_NE(std::string(err.what()).find("vertical field of view 1e-100 degrees at 1080 px height gives a focal "
                                           "length of"),
              std::string::npos)
        << err.what();
  }
  narrow.vfov = degrees_to_radians(1e-3);
  narrow.interaxial = 1e-6;
  EXPECT_NO_THROW((void)resolve_rig(empty, narrow));
  // One within a hair of 180 degrees: a focal length of a fraction of a pixel rendered a black
  // image (depths of the wrong sign) without a word. Refused; 170 degrees renders.
  RigOverrides wide_view;
  wide_view.height = 90;
  wide_view.width = 160;
  wide_view.vfov = degrees_to_radians(179.99);
  try {
    (void)resolve_rig(empty, wide_view);
    ADD_FAILURE() << "a field of view of 179.99 degrees at 90 px was accepted";
  } catch (const InputError& err) {
    EXPECT_NE(std::string(err.what()).find("puts the image corners 89.99"), std::string::npos) << err.what();
  }
  wide_view.vfov = degrees_to_radians(170.0);
  EXPECT_NO_THROW((void)resolve_rig(empty, wide_view));
}

TEST(Rig, ACameraAspectRatioBeyondAnyImageIsRefusedUnlessTheWidthIsGiven) {
  // 1080 * 1e30 px overflowed the integer width (reported as "resolution 0x1080").
  Scene scene;
  scene.name = "wide";
  SceneCamera cam;
  cam.aspect = 1e30;
  scene.cameras.push_back(cam);
  try {
    (void)resolve_rig(scene, RigOverrides{});
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("scene 'wide': its camera's aspectRatio 1e+30 gives a width of 1.08e+33 px at "
                                         "1080 px height, outside 1..16384"),
              std::string::npos)
        << e.what();
  }
  RigOverrides given;
  given.width = 320;
  given.height = 180;
  EXPECT_EQ(resolve_rig(scene, given).params().width, 320);
  scene.cameras[0].aspect = 16.0 / 9.0;
  EXPECT_EQ(resolve_rig(scene, RigOverrides{}).params().width, 1920);
  // The aspect ratio gives the width at the height the scene's extras give (it was taken at the
  // default 1080: aspect 2 at 720 px made 2160x720).
  scene.cameras[0].aspect = 2.0;
  scene.rig.height = 720;
  const RigParams at_720 = resolve_rig(scene, RigOverrides{}).params();
  EXPECT_EQ(at_720.width, 1440);
  EXPECT_EQ(at_720.height, 720);
}

TEST(Rig, ResolutionNamesAndErrors) {
  EXPECT_EQ(parse_resolution("hd"), ivec2(1920, 1080));
  EXPECT_EQ(parse_resolution("4K"), ivec2(3840, 2160));
  EXPECT_EQ(parse_resolution("640x360"), ivec2(640, 360));
  for (const char* bad : {"0x100", "100x0", "16385x10", "x", "12", "axb", "-5x5", "1e3x2", ""})
    EXPECT_THROW((void)parse_resolution(bad), InputError) << bad;
}

TEST(Rig, LookingStraightDownKeepsTheRightVectorOfAViewTiltedThere) {
  // A view tilted down from the default one (looking down -z, right +x) keeps right = +x up to
  // the overhead point; there the fallback gave -x, rolling a path's image 180 degrees at that frame.
  const CameraPose tilted = CameraPose::look_at(dvec3(0.0, 5.0, 0.0), dvec3(0.0, 0.0, -0.001));
  const CameraPose overhead = CameraPose::look_at(dvec3(0.0, 5.0, 0.0), dvec3(0.0, 0.0, 0.0));
  EXPECT_GT(tilted.right.x, 0.999);
  EXPECT_GT(overhead.right.x, 0.999);
  EXPECT_NEAR(glm::dot(overhead.up, tilted.up), 1.0, 1e-3);
  // Straight up likewise.
  EXPECT_GT(CameraPose::look_at(dvec3(0.0), dvec3(0.0, 5.0, 0.0)).right.x, 0.999);
}

}  // namespace
}  // namespace sb
