// Animation along a path of frames (DESIGN §7): a camera moving through key poses and rigid node
// animation (meshes turning about an axis, e.g. Al-Hagri's "Animated Spheres" turning about Y).
// Frames are applied to a Scene in place; RenderScene::update_geometry() then refits the BVH.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "renderer/math.hpp"
#include "renderer/rig.hpp"
#include "renderer/scene.hpp"

namespace sb {

/// A camera key pose: where the centre camera stands and the point it looks at (+Y up).
struct CameraKey {
  dvec3 position{0.0};
  dvec3 target{0.0, 0.0, -1.0};
};

/// Rigid rotation of meshes about an axis through a pivot, by a fixed angle per frame.
struct Spin {
  dvec3 axis{0.0, 1.0, 0.0};
  /// The pivot; unset = the centre of the turning meshes' bounds at frame 0.
  std::optional<dvec3> pivot;
  double degrees_per_frame = 1.0;
  /// Meshes whose name starts with this prefix turn ("" = every mesh).
  std::string mesh_prefix;
};

/// A path of `frames` frames: the camera along `camera_keys` (none: the rig's own pose; one: that
/// pose; more: piecewise linear in position and target, the keys spread evenly over the frames,
/// the first at frame 0 and the last at frame frames-1) and an optional spin; or, with
/// `gltf_animation`, the scene file's own node animations (Scene::animation; every clip, or the
/// one `gltf_clip` names) played from their first key time to their last, spread evenly over the
/// frames: the meshes of animated nodes move rigidly with their nodes, lights on animated nodes
/// with them, and an animated scene camera moves the rig.
struct PathSpec {
  int frames = 1;
  std::vector<CameraKey> camera_keys;
  std::optional<Spin> spin;
  bool gltf_animation = false;
  /// The glTF animation (clip) to play: by name, by "#index", or by a bare index where no clip has
  /// that name; empty: every clip at once.
  std::string gltf_clip;

  /// InputError naming the field: frames outside 1..100000, a key whose target equals its
  /// position, a zero spin axis, a non-finite angle, gltf_animation with camera keys or a spin, a
  /// gltf_clip without gltf_animation.
  void validate() const;
  /// The camera keys (numbered from 1) that no frame stands at: the frames are spread evenly over
  /// the keys, so with F frames and K keys key j is a frame's place only where (j - 1)(F - 1) is
  /// a multiple of K - 1. None with fewer than two frames or keys.
  [[nodiscard]] std::vector<size_t> keys_between_frames() const;
  /// What to tell the user when a camera key is never shown: one frame stands at the first of
  /// several keys, or keys_between_frames() is not empty; with a frame count that stands at every
  /// key, given as `frames_setting` ("--frames", "path.frames ="). None when every key is shown.
  [[nodiscard]] std::optional<std::string> unshown_keys_warning(const std::string& frames_setting) const;
};

/// Applies the frames of a path to a scene. Frame k is always computed from the scene as loaded (a
/// spin from the frame-0 positions it keeps, a glTF animation from the meshes' node-local
/// geometry), so it does not depend on the frames before it (no drift).
class SceneAnimator {
 public:
  /// InputError when the spin's prefix matches no mesh, or gltf_animation is asked of a scene
  /// without node animations, of a clip the scene does not have, or of clips that key one
  /// property of a node twice (the clips of one character: choose one with gltf_clip).
  SceneAnimator(Scene& scene, const PathSpec& path);

  [[nodiscard]] int frames() const { return path_.frames; }
  [[nodiscard]] bool moves_geometry() const { return !turning_.empty(); }
  /// The meshes that move along the path (turning, or on animated nodes).
  [[nodiscard]] size_t turning_meshes() const { return turning_.size(); }
  /// Their indices in the scene's meshes (ascending): the meshes whose BVH data a frame changes.
  [[nodiscard]] const std::vector<size_t>& moving_mesh_indices() const { return turning_; }
  /// The lights that move along the path (on animated nodes).
  [[nodiscard]] size_t moving_lights() const { return lights_.size(); }
  /// What plays: the clip's label ("'walk'", "#2"), or "every clip" (empty without gltf_animation).
  [[nodiscard]] const std::string& clip() const { return clip_; }
  /// The animation time of `frame` (seconds; 0 without gltf_animation).
  [[nodiscard]] double time_of(int frame) const;

  /// Sets the moving meshes' positions and normals, and the moving lights' positions and
  /// directions, to those of `frame` (0 <= frame < frames()).
  void apply(int frame);
  /// The centre camera pose at `frame`; `base` when the path has no camera keys and no animated
  /// scene camera.
  [[nodiscard]] CameraPose camera_at(int frame, const CameraPose& base) const;

 private:
  /// Sets played_ to the channels of the clips that play (path_.gltf_clip) and clip_ to its label.
  void play_clips(const NodeAnimation& all);

  Scene& scene_;
  PathSpec path_;
  dvec3 pivot_{0.0};
  std::vector<size_t> turning_;  ///< indices of the moving meshes
  std::vector<size_t> lights_;   ///< indices of the moving lights
  std::vector<std::vector<vec3>> base_positions_, base_normals_;
  NodeAnimation played_;  ///< the scene's animation, its channels those of the clips that play
  std::string clip_;
  int camera_node_ = -1;  ///< the scene camera's node when the glTF animation moves it
  double start_ = 0.0, end_ = 0.0;  ///< the glTF animation's time range over what it moves
};

/// What makes a key pose unusable, if anything: a position or target that is not finite or lies
/// beyond the ±kMaxSceneCoordinate a scene may span, or a target equal to the position (no
/// viewing direction).
[[nodiscard]] std::optional<std::string> camera_key_problem(const CameraKey& key);

/// Parses camera keys "px,py,pz>tx,ty,tz;px,py,pz>tx,ty,tz;..." (meters). InputError naming the
/// key and what is wrong (camera_key_problem included).
[[nodiscard]] std::vector<CameraKey> parse_camera_keys(const std::string& text);

}  // namespace sb
