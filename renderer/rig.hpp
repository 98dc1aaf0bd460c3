// The stereo rig of DESIGN §2: two eyes at ±e/2 along the camera's right axis, parallel optical
// axes, off-axis (sensor-shifted) frusta with zero disparity on the plane at distance c.
#pragma once

#include <optional>
#include <string>

#include "renderer/math.hpp"

namespace sb {

struct Scene;

enum class Eye { left, right, center };
[[nodiscard]] const char* eye_name(Eye eye);

/// Largest image side the suite accepts, per axis.
constexpr int kMaxImageSide = 16384;

/// Largest disparity at infinity (f_px·e/c, pixels) a rig may have: a million pixels, a sensor
/// shift hundreds of image widths wide. Beyond it (a convergence of nanometres, an interaxial of
/// light years) the eyes' frusta hold no common point and the ray setup loses its precision.
constexpr double kMaxDisparityPx = 1e6;

/// Largest focal length (pixels) a rig may have: a field of view of about 1e-6 degrees at 16384 px.
/// The rasterizer projects in single precision, which a vanishing field of view (1e-100 degrees,
/// 1e102 px) overflows: it drew nothing where the ray tracer saw the scene.
constexpr double kMaxFocalPx = 1e12;
/// The widest angle between the optical axis and an image corner's ray a rig may have, in degrees.
/// Nearer to 90 the rays' forward component drowns in single precision: a vertical field of view
/// within a hair of 180 degrees rendered a black image with depths of the wrong sign.
constexpr double kMaxCornerAngleDeg = 89.9;

/// The rig's parameters. Lengths are meters, angles radians.
struct RigParams {
  double interaxial = 0.064;
  double convergence = 2.0;
  int width = 1920;
  int height = 1080;
  double vfov = 0.6981317007977318;  ///< 40 degrees
  double znear = 0.05;
  double zfar = 10000.0;

  /// Throws InputError naming the first parameter out of range.
  void validate() const;
};

/// A camera pose: position and an orthonormal basis (right, up, back = -viewing direction).
struct CameraPose {
  dvec3 position{0.0};
  dvec3 right{1.0, 0.0, 0.0};
  dvec3 up{0.0, 1.0, 0.0};
  dvec3 back{0.0, 0.0, 1.0};

  /// From a world-from-camera matrix (scale and shear removed by orthonormalisation).
  static CameraPose from_matrix(const dmat4& world_from_camera);
  /// A camera at `eye` looking at `target` with +Y up.
  static CameraPose look_at(const dvec3& eye, const dvec3& target, const dvec3& up = {0, 1, 0});
};

/// One eye's pinhole camera. Pixel coordinates are continuous: x to the right, y down, the centre
/// of pixel (i, j) at (i + 0.5, j + 0.5). Depth is the linear view-space distance along -Z.
struct EyeCamera {
  dvec3 origin{0.0};
  dvec3 right{1.0, 0.0, 0.0};
  dvec3 up{0.0, 1.0, 0.0};
  dvec3 back{0.0, 0.0, 1.0};
  double f_px = 1.0;  ///< focal length in pixels
  double cx = 0.0;    ///< principal point (pixels), shifted for off-axis eyes
  double cy = 0.0;
  int width = 1;
  int height = 1;
  double znear = 0.05;
  double zfar = 10000.0;

  /// World point -> (x_px, y_px, depth). Depth <= 0 means behind the camera.
  [[nodiscard]] dvec3 project(const dvec3& world) const;
  /// Inverse of project(): the world point at continuous pixel (x, y) and linear depth.
  [[nodiscard]] dvec3 unproject(double x_px, double y_px, double depth) const;
  /// Unit direction of the primary ray through continuous pixel (x, y).
  [[nodiscard]] dvec3 ray_direction(double x_px, double y_px) const;
  /// camera_from_world (OpenGL view matrix).
  [[nodiscard]] dmat4 view_matrix() const;
  /// Off-axis OpenGL-style projection: NDC x right, y up, z in [-1, 1] between znear and zfar.
  [[nodiscard]] dmat4 projection_matrix() const;
};

/// The stereo rig: a centre pose plus parameters.
class StereoRig {
 public:
  StereoRig(const CameraPose& pose, const RigParams& params);  ///< validates params

  [[nodiscard]] const RigParams& params() const { return params_; }
  [[nodiscard]] const CameraPose& pose() const { return pose_; }
  [[nodiscard]] EyeCamera eye(Eye which) const;

  /// f_px = (H/2) / tan(vfov/2).
  [[nodiscard]] double focal_px() const;
  /// Disparity x_right - x_left in pixels of a point at depth Z: f_px e (1/c - 1/Z).
  [[nodiscard]] double disparity_px(double depth) const;
  /// Disparity at Z -> infinity: f_px e / c.
  [[nodiscard]] double max_disparity_px() const;

 private:
  CameraPose pose_;
  RigParams params_;
};

/// f_px of a vertical field of view and image height.
[[nodiscard]] double focal_px(double vfov, int height);
/// Interaxial (m) that gives `max_disparity_px` at infinity: e = d_max c / f_px.
[[nodiscard]] double interaxial_from_max_disparity(double max_disparity_px, double convergence,
                                                   double vfov, int height);
/// Max disparity (px) of an interaxial: f_px e / c.
[[nodiscard]] double max_disparity_from_interaxial(double interaxial, double convergence,
                                                   double vfov, int height);

/// Rig settings a user may override on the command line; unset fields come from the scene.
struct RigOverrides {
  std::optional<double> interaxial;
  std::optional<double> max_disparity_px;  ///< alternative to interaxial
  std::optional<double> convergence;
  std::optional<int> width;
  std::optional<int> height;
  std::optional<double> vfov;  ///< radians
};

/// The scene's default rig (its first camera and `extras.stereobench`), with overrides applied.
/// Without a camera the pose frames the scene's bounds from +Z. Throws InputError on bad values.
[[nodiscard]] StereoRig resolve_rig(const Scene& scene, const RigOverrides& overrides);

/// Parses "WxH" or a name (any case): hd / fhd / 1080p (1920x1080, the papers' HD), 4k / uhd
/// (3840x2160), 720p (1280x720), qhd (2560x1440), 8k (7680x4320). InputError for anything else or a side outside 1..16384.
[[nodiscard]] ivec2 parse_resolution(const std::string& text);

/// One-line human description: "1920x1080, vfov 40.0°, e 0.0640 m, c 2.000 m, max disparity 47.9 px".
[[nodiscard]] std::string describe(const StereoRig& rig);

}  // namespace sb
