// Camera paths and rigid node animation.
#include "renderer/animation.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <tuple>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "renderer/error.hpp"

namespace sb {

namespace {

bool finite(const dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// Rotation by `radians` about the unit `axis` (Rodrigues).
dmat3 rotation(const dvec3& axis, double radians) {
  const double c = std::cos(radians), s = std::sin(radians), t = 1.0 - c;
  const double x = axis.x, y = axis.y, z = axis.z;
  // Column-major: m[col][row].
  return dmat3(t * x * x + c, t * x * y + s * z, t * x * z - s * y,   //
               t * x * y - s * z, t * y * y + c, t * y * z + s * x,   //
               t * x * z + s * y, t * y * z - s * x, t * z * z + c);
}

/// Where `frame` lies on a path of two or more keys spread evenly over `frames` frames: between
/// keys `segment` and `segment + 1`, at parameter `t` in [0, 1].
struct PathPlace {
  size_t segment = 0;
  double t = 0.0;
};

PathPlace place_of(size_t keys, int frames, int frame) {
  // keys_between_frames() follows from this spreading.
  // frame (keys - 1) is exact, so a frame whose place is a key stands exactly there.
  const double u = static_cast<double>(frame) * static_cast<double>(keys - 1) / static_cast<double>(frames - 1);
  const size_t i = std::min(static_cast<size_t>(u), keys - 2);
  return {i, u - static_cast<double>(i)};
}

/// The centre camera's position and target at a place of the path: piecewise linear.
CameraKey interpolated_key(const std::vector<CameraKey>& keys, const PathPlace& at) {
  const CameraKey& a = keys[at.segment];
  const CameraKey& b = keys[at.segment + 1];
  return {glm::mix(a.position, b.position, at.t), glm::mix(a.target, b.target, at.t)};
}

bool looks_at_itself(const CameraKey& k) { return glm::length(k.target - k.position) < 1e-9; }

/// The unit vector along `axis`, scaled by its largest component first so that neither a huge
/// axis (1e300, whose length overflows) nor a tiny one (1e-300, whose square underflows) is lost;
/// nothing for a zero or non-finite axis.
std::optional<dvec3> unit_axis(const dvec3& axis) {
  if (!finite(axis)) return std::nullopt;
  const double largest = std::max({std::abs(axis.x), std::abs(axis.y), std::abs(axis.z)});
  if (!(largest > 0.0)) return std::nullopt;
  return glm::normalize(axis / largest);
}

}  // namespace

void PathSpec::validate() const {
  if (frames < 1 || frames > 100000)
    throw InputError(fmt::format("path frames {} is out of range; give 1..100000", frames));
  for (size_t i = 0; i < camera_keys.size(); ++i) {
    const CameraKey& k = camera_keys[i];
    if (!finite(k.position) || !finite(k.target))
      throw InputError(fmt::format("camera key {} has a non-finite coordinate", i + 1));
    if (looks_at_itself(k))
      throw InputError(fmt::format("camera key {} looks at its own position; give a target elsewhere", i + 1));
  }
  // Between two valid keys the camera may still pass through its target (keys that swap position
  // and target): every frame's pose must have a view direction.
  if (camera_keys.size() >= 2 && frames > 1)
    for (int f = 0; f < frames; ++f) {
      const PathPlace at = place_of(camera_keys.size(), frames, f);
      if (looks_at_itself(interpolated_key(camera_keys, at)))
        throw InputError(fmt::format("frame {} of {}: the camera reaches its target between camera keys {} and {} "
                                     "(position and target cross), so it has no view direction; move a target "
                                     "or add a key between them",
                                     f, frames, at.segment + 1, at.segment + 2));
    }
  // Between frames too: the view direction target - position is linear along a segment; where it
  // passes through zero the camera turns about instantly, between two frames however close.
  for (size_t i = 0; i + 1 < camera_keys.size() && frames > 1; ++i) {
    const dvec3 from = camera_keys[i].target - camera_keys[i].position;
    const dvec3 change = camera_keys[i + 1].target - camera_keys[i + 1].position - from;
    const double len2 = glm::dot(change, change);
    const double t = len2 > 0.0 ? std::clamp(-glm::dot(from, change) / len2, 0.0, 1.0) : 0.0;
    if (glm::length(from + t * change) < 1e-9)
      throw InputError(fmt::format("the camera passes through its target between camera keys {} and {} ({:.0f} % of "
                                   "the way; position and target cross), where its view direction turns about "
                                   "between two frames; move a target or add a key between them",
                                   i + 1, i + 2, 100.0 * t));
  }
  if (gltf_animation && (!camera_keys.empty() || spin))
    throw InputError(fmt::format("a path plays the scene's glTF animation or {}, not both; drop one",
                                 spin ? "a spin" : "camera keys"));
  if (!gltf_clip.empty() && !gltf_animation)
    throw InputError(fmt::format("the glTF clip '{}' is chosen, but the path does not play the scene's glTF "
                                 "animation; ask for it too",
                                 gltf_clip));
  if (spin) {
    if (!unit_axis(spin->axis))
      throw InputError("the spin axis is zero or not finite; give a direction such as 0,1,0");
    // More than a turn per frame is the same motion as its remainder, and large values would
    // overflow frame x angle.
    if (!(std::abs(spin->degrees_per_frame) <= 360.0))
      throw InputError(fmt::format("the spin angle per frame {} is not within ±360 degrees (one turn per frame); give "
                                   "the angle turned between two frames",
                                   spin->degrees_per_frame));
    if (spin->pivot && !within_scene_range(*spin->pivot))
      throw InputError(fmt::format("the spin pivot ({:g}, {:g}, {:g}) m is not finite or lies beyond the ±{:g} m a "
                                   "scene may span; give a point in the scene, in metres",
                                   spin->pivot->x, spin->pivot->y, spin->pivot->z, kMaxSceneCoordinate));
  }
}

SceneAnimator::SceneAnimator(Scene& scene, const PathSpec& path) : scene_(scene), path_(path) {
  path_.validate();
  if (path_.gltf_animation) {
    if (scene.animation.empty())
      throw InputError(fmt::format("scene '{}' has no glTF node animation (translation, rotation or scale channels) "
                                   "to play along the path; give camera keys or a spin instead",
                                   scene.name));
    play_clips(scene.animation);
    const NodeAnimation& a = played_;
    std::vector<int> moved;  // the nodes of what moves: meshes, lights and the camera
    for (size_t m = 0; m < scene.meshes.size(); ++m)
      if (!scene.meshes[m].local_positions.empty() && a.moves(scene.meshes[m].node)) {
        turning_.push_back(m);
        moved.push_back(scene.meshes[m].node);
      }
    for (size_t l = 0; l < scene.lights.size(); ++l)
      if (scene.lights[l].node >= 0 && a.moves(scene.lights[l].node)) lights_.push_back(l);
    // Every light of the file counts for what moves, kept or not (--lights): the frames show the
    // same animation times whatever the light count.
    for (const int node : a.light_nodes)
      if (a.moves(node)) moved.push_back(node);
    if (!scene.cameras.empty() && a.moves(scene.cameras.front().node)) {
      camera_node_ = scene.cameras.front().node;
      moved.push_back(camera_node_);
    }
    if (moved.empty())
      throw InputError(fmt::format("the glTF animation of scene '{}' ({}) moves none of its meshes, none of its lights "
                                   "and not its camera (its channels key other nodes); nothing would change along the "
                                   "path",
                                   scene.name, clip_));
    std::tie(start_, end_) = a.time_range(moved);
    // Every frame's camera has a pose: a scale keyed to 0 would stop the path half-way.
    if (camera_node_ >= 0)
      for (int f = 0; f < path_.frames; ++f) try {
          (void)camera_at(f, CameraPose{});
        } catch (const InputError& e) {
          throw InputError(fmt::format("{}: the animated camera (node {}) at frame {} (t = {:g} s): {}", scene.path,
                                       camera_node_, f, time_of(f), e.what()));
        }
    return;
  }
  if (!path_.spin) return;
  Bounds3 bounds;
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const Mesh& mesh = scene.meshes[m];
    if (mesh.name.rfind(path_.spin->mesh_prefix, 0) != 0) continue;
    turning_.push_back(m);
    base_positions_.push_back(mesh.positions);
    base_normals_.push_back(mesh.normals);
    for (const vec3& p : mesh.positions) bounds.extend(p);
  }
  if (turning_.empty())
    throw InputError(fmt::format("the spin's mesh prefix '{}' matches no mesh of scene '{}'", path_.spin->mesh_prefix,
                                 scene.name));
  pivot_ = path_.spin->pivot ? *path_.spin->pivot : dvec3(0.5f * (bounds.lo + bounds.hi));
}

void SceneAnimator::play_clips(const NodeAnimation& all) {
  played_ = all;
  played_.channels.clear();
  std::optional<size_t> chosen;
  const std::string& name = path_.gltf_clip;
  if (name.empty()) {
    clip_ = all.clips.size() == 1 ? all.clip_label(0) : "every clip";
  } else {
    // "#N" is an index, as messages label a clip; a bare number is a name first, then an index.
    const bool hash = name[0] == '#';
    std::vector<size_t> named;
    for (size_t c = 0; c < all.clips.size() && !hash; ++c)
      if (all.clips[c] == name) named.push_back(c);
    if (named.size() > 1)
      throw InputError(fmt::format("scene '{}' has {} glTF animations named '{}' (#{} and #{}); choose one by its "
                                   "#index",
                                   scene_.name, named.size(), name, named[0], named[1]));
    if (named.empty()) {
      const char* const first = name.data() + (hash ? 1 : 0);
      const char* const last = name.data() + name.size();
      size_t index = 0;
      const auto [end, ec] = std::from_chars(first, last, index);
      if (ec != std::errc() || end != last || index >= all.clips.size())
        throw InputError(fmt::format("scene '{}' has no glTF animation '{}'; its animations are {} (choose one by "
                                     "name, or by #index)",
                                     scene_.name, name, all.clip_list()));
      named.push_back(index);
    }
    chosen = named.front();
    clip_ = all.clip_label(*chosen);
  }
  // Two clips that key one property of a node (the idle and the walk of one character) cannot
  // play at once.
  std::map<std::pair<int, int>, int> keyed;  // (node, property) -> clip
  for (const NodeAnimation::Channel& c : all.channels) {
    if (chosen && static_cast<size_t>(c.clip) != *chosen) continue;
    const auto [it, first] = keyed.emplace(std::pair(c.node, static_cast<int>(c.property)), c.clip);
    if (!first)
      throw InputError(fmt::format("the glTF animations {} and {} of scene '{}' both key node {}'s {}, so they "
                                   "cannot play at once; choose one clip",
                                   all.clip_label(static_cast<size_t>(it->second)),
                                   all.clip_label(static_cast<size_t>(c.clip)), scene_.name, c.node,
                                   c.property == NodeAnimation::Property::translation ? "translation"
                                   : c.property == NodeAnimation::Property::rotation  ? "rotation"
                                                                                      : "scale"));
    played_.channels.push_back(c);
  }
}

void SceneAnimator::apply(int frame) {
  if (frame < 0 || frame >= path_.frames)
    throw InputError(fmt::format("frame {} is outside the path's 0..{}", frame, path_.frames - 1));
  if (path_.gltf_animation) {
    const double t = time_of(frame);
    for (const size_t l : lights_) scene_.lights[l].place(played_.world(scene_.lights[l].node, t));
    for (const size_t m : turning_) {
      Mesh& mesh = scene_.meshes[m];
      // The node's world transform at t places its own geometry; normals by its inverse transpose.
      const dmat4 w = played_.world(mesh.node, t);
      // From the file's placement: a node scaled to nothing at rest has no inverse, and no
      // transform takes its collapsed geometry to this frame's (every entry then NaN or infinite).
      const dmat4 rest = played_.rest_world(mesh.node);
      mesh.moved = glm::determinant(dmat3(rest)) != 0.0 ? w * glm::inverse(rest)
                                                        : dmat4(std::numeric_limits<double>::quiet_NaN());
      const double det = glm::determinant(dmat3(w));
      for (size_t i = 0; i < mesh.local_positions.size(); ++i)
        mesh.positions[i] = vec3(dvec3(w * dvec4(dvec3(mesh.local_positions[i]), 1.0)));
      // A transform scaled to nothing leaves no area to shade: its normals stay as they were.
      if (det != 0.0 && std::isfinite(det)) {
        const dmat3 n = glm::transpose(glm::inverse(dmat3(w)));
        for (size_t i = 0; i < mesh.local_normals.size(); ++i) {
          const dvec3 v = n * dvec3(mesh.local_normals[i]);
          const double len = glm::length(v);
          if (len > 0.0) mesh.normals[i] = vec3(v / len);
        }
      }
      // A mirroring transform reverses the triangles, so that they face the way the file says.
      // An instance's local_positions are already the instance's: the node's transform mirrors
      // them when exactly one of the two does.
      const bool instance_mirrors =
          mesh.instance >= 0 &&
          glm::determinant(dmat3(scene_.instances.at(mesh.node)[static_cast<size_t>(mesh.instance)])) < 0.0;
      if (const bool mirrors = (det < 0.0) != instance_mirrors; mirrors != mesh.mirrored) {
        for (size_t k = 0; k < mesh.indices.size(); k += 3) std::swap(mesh.indices[k + 1], mesh.indices[k + 2]);
        mesh.mirrored = mirrors;
      }
    }
    return;
  }
  if (turning_.empty()) return;
  const double radians = degrees_to_radians(path_.spin->degrees_per_frame * frame);
  const dmat3 r = rotation(*unit_axis(path_.spin->axis), radians);
  // p -> pivot + r (p - pivot), from the positions as loaded.
  dmat4 turn(r);
  turn[3] = dvec4(pivot_ - r * pivot_, 1.0);
  for (size_t k = 0; k < turning_.size(); ++k) {
    Mesh& mesh = scene_.meshes[turning_[k]];
    mesh.moved = turn;
    const std::vector<vec3>& p0 = base_positions_[k];
    for (size_t i = 0; i < p0.size(); ++i) mesh.positions[i] = vec3(pivot_ + r * (dvec3(p0[i]) - pivot_));
    const std::vector<vec3>& n0 = base_normals_[k];
    for (size_t i = 0; i < n0.size(); ++i) mesh.normals[i] = vec3(r * dvec3(n0[i]));
  }
}

double SceneAnimator::time_of(int frame) const {
  if (!path_.gltf_animation) return 0.0;
  return path_.frames == 1 ? start_ : start_ + (end_ - start_) * frame / static_cast<double>(path_.frames - 1);
}

CameraPose SceneAnimator::camera_at(int frame, const CameraPose& base) const {
  if (camera_node_ >= 0) return CameraPose::from_matrix(played_.world(camera_node_, time_of(frame)));
  const std::vector<CameraKey>& keys = path_.camera_keys;
  if (keys.empty()) return base;
  if (keys.size() == 1 || path_.frames == 1) return CameraPose::look_at(keys.front().position, keys.front().target);
  const CameraKey k = interpolated_key(keys, place_of(keys.size(), path_.frames, frame));
  return CameraPose::look_at(k.position, k.target);
}

std::optional<std::string> camera_key_problem(const CameraKey& key) {
  for (const auto& [what, p] : {std::pair{"position", key.position}, std::pair{"target", key.target}})
    if (!within_scene_range(p))
      return fmt::format("its {} ({:g}, {:g}, {:g}) m lies beyond the ±{:g} m a scene may span", what, p.x, p.y, p.z,
                         kMaxSceneCoordinate);
  if (key.position == key.target) return "its target equals its position: it has no viewing direction";
  return std::nullopt;
}

std::vector<size_t> PathSpec::keys_between_frames() const {
  std::vector<size_t> passed;
  if (frames < 2 || camera_keys.size() < 2) return passed;
  const size_t gaps = camera_keys.size() - 1, steps = static_cast<size_t>(frames) - 1;
  for (size_t j = 1; j < gaps; ++j)
    if (j * steps % gaps != 0) passed.push_back(j + 1);
  return passed;
}

std::optional<std::string> PathSpec::unshown_keys_warning(const std::string& frames_setting) const {
  const size_t keys = camera_keys.size();
  if (keys > 1 && frames == 1)
    return fmt::format("with 1 frame the camera stands at the first of the {} camera keys; give {} {} or more to "
                       "move through them",
                       keys, frames_setting, keys);
  const std::vector<size_t> passed = keys_between_frames();
  if (passed.empty()) return std::nullopt;
  const size_t gaps = keys - 1, steps = static_cast<size_t>(frames) - 1;
  return fmt::format("the {} frames are spread evenly over the path, so camera key{} {} fall{} between frames and {} "
                     "never shown; give {} {} (or any number one more than a multiple of {}) to stand at every key",
                     frames, passed.size() == 1 ? "" : "s", fmt::join(passed, ", "), passed.size() == 1 ? "s" : "",
                     passed.size() == 1 ? "is" : "are", frames_setting, (steps + gaps - 1) / gaps * gaps + 1, gaps);
}

std::vector<CameraKey> parse_camera_keys(const std::string& text) {
  std::vector<CameraKey> keys;
  std::stringstream list(text);
  std::string item;
  const auto vec = [&](const std::string& part, size_t key) {
    dvec3 v;
    char c1 = 0, c2 = 0;
    std::stringstream in(part);
    if (!(in >> v.x >> c1 >> v.y >> c2 >> v.z) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof())
      throw InputError(fmt::format("camera key {} '{}': '{}' is not x,y,z (meters)", key, item, part));
    return v;
  };
  while (std::getline(list, item, ';')) {
    if (item.empty())
      throw InputError(fmt::format("camera key {} is empty (two ';' in a row?); give "
                                   "POSITION>TARGET;POSITION>TARGET...",
                                   keys.size() + 1));
    const size_t arrow = item.find('>');
    if (arrow == std::string::npos)
      throw InputError(fmt::format("camera key {} '{}' is not POSITION>TARGET, e.g. 0,1.6,3>0,1.2,0", keys.size() + 1, item));
    keys.push_back({vec(item.substr(0, arrow), keys.size() + 1), vec(item.substr(arrow + 1), keys.size() + 1)});
    if (const auto why = camera_key_problem(keys.back()))
      throw InputError(fmt::format("camera key {} '{}': {}", keys.size(), item, *why));
  }
  if (keys.empty()) throw InputError("no camera key given; give POSITION>TARGET;POSITION>TARGET...");
  // getline drops an empty last item: a trailing ';' (a key left out at the end) is said too.
  if (text.back() == ';')
    throw InputError(fmt::format("camera key {} is empty (a ';' ends the list); give POSITION>TARGET;POSITION>TARGET... "
                                 "with no ';' after the last key",
                                 keys.size() + 1));
  return keys;
}

}  // namespace sb
