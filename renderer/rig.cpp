// Stereo rig geometry (DESIGN §2).
#include "renderer/rig.hpp"

#include <cctype>
#include <cmath>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "renderer/error.hpp"
#include "renderer/scene.hpp"
#include "renderer/text.hpp"

namespace sb {

const char* eye_name(Eye eye) {
  switch (eye) {
    case Eye::left: return "left";
    case Eye::right: return "right";
    case Eye::center: return "center";
  }
  return "?";
}

namespace {

void require_positive(double value, const char* name, const char* hint) {
  if (!std::isfinite(value) || value <= 0.0)
    throw InputError(fmt::format("{} must be a positive finite number, got {}; {}", name, value, hint));
}

/// InputError when the disparity at infinity exceeds what a rig may have.
void check_disparity(const RigParams& p) {
  const double disparity = max_disparity_from_interaxial(p.interaxial, p.convergence, p.vfov, p.height);
  if (!(disparity <= kMaxDisparityPx))
    throw InputError(fmt::format("interaxial {:g} m with convergence {:g} m gives a disparity at infinity of {:g} px "
                                 "at {} px height and a vertical field of view of {:g} degrees, beyond the {:g} px a "
                                 "rig may have; increase the convergence distance, reduce the interaxial or widen the "
                                 "field of view",
                                 p.interaxial, p.convergence, disparity, p.height, radians_to_degrees(p.vfov),
                                 kMaxDisparityPx));
}

}  // namespace

void RigParams::validate() const {
  require_positive(interaxial, "interaxial", "give the eye separation in meters, e.g. 0.064");
  if (interaxial > kMaxSceneCoordinate)
    throw InputError(fmt::format("interaxial {:g} m is beyond the ±{:g} m a scene may span; give the eye separation "
                                 "in meters, e.g. 0.064",
                                 interaxial, kMaxSceneCoordinate));
  require_positive(convergence, "convergence",
                   "give the zero-parallax distance in meters, e.g. 2.0");
  if (convergence > kMaxSceneCoordinate)
    throw InputError(fmt::format("convergence {:g} m is beyond the ±{:g} m a scene may span; give the zero-parallax "
                                 "distance in meters, e.g. 2.0",
                                 convergence, kMaxSceneCoordinate));
  if (width < 1 || width > kMaxImageSide || height < 1 || height > kMaxImageSide)
    throw InputError(fmt::format("resolution {}x{} is out of range; each side must be 1..{}", width,
                                 height, kMaxImageSide));
  if (!std::isfinite(vfov) || vfov <= 0.0 || vfov >= kPi)
    throw InputError(fmt::format("vertical field of view {} degrees is out of range (0, 180)",
                                 radians_to_degrees(vfov)));
  if (const double f = focal_px(vfov, height); !(f <= kMaxFocalPx))
    throw InputError(fmt::format("vertical field of view {:g} degrees at {} px height gives a focal length of {:g} px, "
                                 "beyond the {:g} px a rig may have; widen the field of view",
                                 radians_to_degrees(vfov), height, f, kMaxFocalPx));
  if (const double corner = radians_to_degrees(std::atan(0.5 * std::hypot(double(width), double(height)) /
                                                         focal_px(vfov, height)));
      !(corner <= kMaxCornerAngleDeg))
    throw InputError(fmt::format("vertical field of view {:g} degrees at {}x{} px puts the image corners {:.5f} "
                                 "degrees off the optical axis, beyond the {:g} a rig's rays hold in single "
                                 "precision; narrow the field of view",
                                 radians_to_degrees(vfov), width, height, corner, kMaxCornerAngleDeg));
  check_disparity(*this);
  require_positive(znear, "znear", "the near plane must lie in front of the camera");
  if (!std::isfinite(zfar) || zfar <= znear)
    throw InputError(fmt::format("zfar {} must be finite and greater than znear {}", zfar, znear));
}

CameraPose CameraPose::from_matrix(const dmat4& m) {
  CameraPose p;
  p.position = dvec3(m[3]);
  if (!within_scene_range(p.position))
    throw InputError(fmt::format("camera position ({:g}, {:g}, {:g}) m lies beyond the ±{:g} m a scene may span; "
                                 "check the camera's translation and its units",
                                 p.position.x, p.position.y, p.position.z, kMaxSceneCoordinate));
  dvec3 back = dvec3(m[2]);
  dvec3 up = dvec3(m[1]);
  if (glm::length(back) == 0.0 || glm::length(up) == 0.0)
    throw InputError("camera transform is degenerate (zero scale); fix the camera node's transform");
  p.back = glm::normalize(back);
  p.right = glm::cross(up, p.back);
  if (glm::length(p.right) < 1e-12)
    throw InputError("camera transform is degenerate (up parallel to view direction); fix the camera node's transform");
  p.right = glm::normalize(p.right);
  p.up = glm::cross(p.back, p.right);
  return p;
}

CameraPose CameraPose::look_at(const dvec3& eye, const dvec3& target, const dvec3& up) {
  dmat4 m(1.0);
  dvec3 back = glm::normalize(eye - target);
  dvec3 right = glm::cross(up, back);
  // Looking along `up` (straight down or up): the right vector a view tilted there from the
  // default one (looking down −z, right +x) keeps, +x made orthogonal to the view. (It was
  // z × back, −x looking down: a path through the overhead point rolled 180° at that frame.)
  if (glm::length(right) < 1e-12) right = dvec3(1, 0, 0) - back.x * back;
  if (glm::length(right) < 1e-12) right = glm::cross(dvec3(0, 0, 1), back);  // `up` along x
  right = glm::normalize(right);
  m[0] = dvec4(right, 0.0);
  m[1] = dvec4(glm::cross(back, right), 0.0);
  m[2] = dvec4(back, 0.0);
  m[3] = dvec4(eye, 1.0);
  return from_matrix(m);
}

dvec3 EyeCamera::project(const dvec3& world) const {
  const dvec3 d = world - origin;
  const double x = glm::dot(d, right);
  const double y = glm::dot(d, up);
  const double z = -glm::dot(d, back);  // depth along the viewing direction
  return {cx + f_px * x / z, cy - f_px * y / z, z};
}

dvec3 EyeCamera::unproject(double x_px, double y_px, double depth) const {
  const double x = (x_px - cx) * depth / f_px;
  const double y = (cy - y_px) * depth / f_px;
  return origin + x * right + y * up - depth * back;
}

dvec3 EyeCamera::ray_direction(double x_px, double y_px) const {
  return glm::normalize((x_px - cx) / f_px * right + (cy - y_px) / f_px * up - back);
}

dmat4 EyeCamera::view_matrix() const {
  dmat4 m(1.0);
  // Rows of the rotation are the basis vectors (glm is column-major: m[col][row]).
  for (int i = 0; i < 3; ++i) {
    m[i][0] = right[i];
    m[i][1] = up[i];
    m[i][2] = back[i];
  }
  m[3][0] = -glm::dot(right, origin);
  m[3][1] = -glm::dot(up, origin);
  m[3][2] = -glm::dot(back, origin);
  return m;
}

dmat4 EyeCamera::projection_matrix() const {
  // x_ndc = 2 x_px / W - 1 with x_px = cx + f X / Z and Z = -z_view; y_ndc = 1 - 2 y_px / H.
  dmat4 p(0.0);
  p[0][0] = 2.0 * f_px / width;
  p[1][1] = 2.0 * f_px / height;
  p[2][0] = -(2.0 * cx / width - 1.0);
  p[2][1] = (2.0 * cy / height - 1.0);
  p[2][2] = -(zfar + znear) / (zfar - znear);
  p[2][3] = -1.0;
  p[3][2] = -2.0 * zfar * znear / (zfar - znear);
  return p;
}

double focal_px(double vfov, int height) { return 0.5 * height / std::tan(0.5 * vfov); }

double interaxial_from_max_disparity(double max_disparity_px, double convergence, double vfov,
                                     int height) {
  return max_disparity_px * convergence / focal_px(vfov, height);
}

double max_disparity_from_interaxial(double interaxial, double convergence, double vfov,
                                     int height) {
  return focal_px(vfov, height) * interaxial / convergence;
}

StereoRig::StereoRig(const CameraPose& pose, const RigParams& params) : pose_(pose), params_(params) {
  params_.validate();
}

double StereoRig::focal_px() const { return sb::focal_px(params_.vfov, params_.height); }

double StereoRig::disparity_px(double depth) const {
  return focal_px() * params_.interaxial * (1.0 / params_.convergence - 1.0 / depth);
}

double StereoRig::max_disparity_px() const {
  return focal_px() * params_.interaxial / params_.convergence;
}

EyeCamera StereoRig::eye(Eye which) const {
  // The eye sits at offset s along the right axis; shifting its principal point by f s / c keeps
  // every point of the plane at distance c where the centre camera sees it (zero parallax).
  const double s = which == Eye::left    ? -0.5 * params_.interaxial
                   : which == Eye::right ? 0.5 * params_.interaxial
                                         : 0.0;
  EyeCamera cam;
  cam.origin = pose_.position + s * pose_.right;
  cam.right = pose_.right;
  cam.up = pose_.up;
  cam.back = pose_.back;
  cam.f_px = focal_px();
  cam.cx = 0.5 * params_.width + cam.f_px * s / params_.convergence;
  cam.cy = 0.5 * params_.height;
  cam.width = params_.width;
  cam.height = params_.height;
  cam.znear = params_.znear;
  cam.zfar = params_.zfar;
  return cam;
}

StereoRig resolve_rig(const Scene& scene, const RigOverrides& o) {
  RigParams p;
  CameraPose pose;
  const Bounds3 b = scene.bounds();
  const double radius = b.empty() ? 1.0 : 0.5 * glm::length(dvec3(b.extent()));
  if (!scene.cameras.empty()) {
    const SceneCamera& cam = scene.cameras.front();
    pose = CameraPose::from_matrix(cam.world_from_camera);
    p.vfov = cam.yfov;
    p.znear = cam.znear;
    if (cam.zfar > 0.0) p.zfar = cam.zfar;
  } else {
    // Frame the bounding sphere from +Z.
    const dvec3 c = b.empty() ? dvec3(0.0) : dvec3(b.center());
    const double dist = radius / std::sin(0.5 * p.vfov) + 1e-3;
    pose = CameraPose::look_at(c + dvec3(0.0, 0.0, dist), c);
    p.znear = std::max(1e-3, 1e-4 * dist);
    p.convergence = dist;
  }
  if (scene.rig.height) p.height = *scene.rig.height;
  if (o.height) p.height = *o.height;
  if (scene.rig.width) {
    p.width = *scene.rig.width;
  } else if (!o.width && !scene.cameras.empty() && scene.cameras.front().aspect > 0.0) {
    // The camera's aspect ratio sets the width, at the height the rig has (the scene's extras may
    // give one), unless the scene's extras or an override give the width.
    const double aspect = scene.cameras.front().aspect;
    const double width = p.height * aspect;
    if (!(width >= 0.5 && width < kMaxImageSide + 0.5))
      throw InputError(fmt::format("scene '{}': its camera's aspectRatio {:g} gives a width of {:g} px at {} px "
                                   "height, outside 1..{}; fix the camera's aspectRatio, or give --resolution",
                                   scene.name, aspect, width, p.height, kMaxImageSide));
    p.width = static_cast<int>(std::lround(width));
  }
  if (scene.rig.interaxial) p.interaxial = *scene.rig.interaxial;
  if (scene.rig.convergence) p.convergence = *scene.rig.convergence;
  if (o.width) p.width = *o.width;
  if (o.vfov) p.vfov = *o.vfov;
  if (o.convergence) p.convergence = *o.convergence;
  if (o.interaxial && o.max_disparity_px)
    throw InputError("give either --interaxial or --max-disparity, not both");
  if (o.interaxial) p.interaxial = *o.interaxial;
  if (o.max_disparity_px) {
    require_positive(*o.max_disparity_px, "max disparity",
                     "give the disparity at infinity in pixels, e.g. 30");
    if (*o.max_disparity_px > kMaxDisparityPx)
      throw InputError(fmt::format("max disparity {:g} px is beyond the {:g} px a rig may have; give the disparity at "
                                   "infinity in pixels, e.g. 30",
                                   *o.max_disparity_px, kMaxDisparityPx));
    require_positive(p.convergence, "convergence", "give the zero-parallax distance in meters");
    p.interaxial = interaxial_from_max_disparity(*o.max_disparity_px, p.convergence, p.vfov, p.height);
  }
  // A disparity out of range that the scene's extras alone set up (no option gave the interaxial,
  // the convergence, the field of view or the image height, which all enter it) is named by file
  // and JSON path: the message must not read as if an option were at fault. Where an option took
  // part, RigParams::validate names the values.
  const bool options_set_rig = o.interaxial || o.max_disparity_px || o.convergence || o.vfov || o.height;
  const bool vfov_ok = std::isfinite(p.vfov) && p.vfov > 0.0 && p.vfov < kPi;
  if (!options_set_rig && (scene.rig.interaxial || scene.rig.convergence) && !scene.rig.where.empty() && vfov_ok) {
    try {
      check_disparity(p);
    } catch (const InputError& e) {
      std::vector<std::string> keys;
      if (scene.rig.interaxial) keys.push_back(scene.rig.where + "/interaxial");
      if (scene.rig.convergence) keys.push_back(scene.rig.where + "/convergence");
      throw InputError(fmt::format("{}: {}: the scene's rig: {}; fix it in the scene (in metres), or override it with "
                                   "--convergence or --interaxial",
                                   scene.path, fmt::join(keys, " and "), e.what()));
    }
  }
  // Far plane far enough for the whole scene as seen from the camera.
  const double reach = glm::length(pose.position - dvec3(b.empty() ? vec3(0.0f) : b.center())) + radius;
  p.zfar = std::max(p.zfar, 2.0 * reach);
  return StereoRig(pose, p);
}

ivec2 parse_resolution(const std::string& text) {
  static const std::pair<const char*, ivec2> named[] = {
      {"hd", {1920, 1080}}, {"fhd", {1920, 1080}}, {"1080p", {1920, 1080}}, {"720p", {1280, 720}},
      {"qhd", {2560, 1440}}, {"4k", {3840, 2160}},  {"uhd", {3840, 2160}},  {"8k", {7680, 4320}}};
  const std::string lower = lowercase(text);
  for (const auto& [name, size] : named)
    if (lower == name) return size;
  const size_t x = lower.find('x');
  auto parse_side = [&](const std::string& s) -> long {
    if (s.empty() || s.size() > 9 || s.find_first_not_of("0123456789") != std::string::npos) return -1;
    return std::stol(s);
  };
  const long w = x == std::string::npos ? -1 : parse_side(lower.substr(0, x));
  const long h = x == std::string::npos ? -1 : parse_side(lower.substr(x + 1));
  if (w < 0 || h < 0)
    throw InputError(fmt::format("resolution '{}' is not WIDTHxHEIGHT (e.g. 1920x1080) or one of hd, fhd, 1080p, "
                                 "720p, qhd, 4k, uhd, 8k (any case)",
                                 text));
  if (w < 1 || h < 1 || w > kMaxImageSide || h > kMaxImageSide)
    throw InputError(fmt::format("resolution {}x{} is out of range; each side must be 1..{}", w, h, kMaxImageSide));
  return {static_cast<int>(w), static_cast<int>(h)};
}

std::string describe(const StereoRig& rig) {
  const RigParams& p = rig.params();
  // `decimals` places, or three significant digits for a value those places would show as 0.
  const auto number = [](double v, int decimals) {
    return v != 0.0 && std::abs(v) < 0.5 * std::pow(10.0, -decimals) ? fmt::format("{:.3g}", v)
                                                                     : fmt::format("{:.{}f}", v, decimals);
  };
  return fmt::format("{}x{}, vfov {} deg, interaxial {} m, convergence {} m, f {:.1f} px, max disparity {} px",
                     p.width, p.height, number(radians_to_degrees(p.vfov), 2), number(p.interaxial, 4),
                     number(p.convergence, 3), rig.focal_px(), number(rig.max_disparity_px(), 2));
}

}  // namespace sb
