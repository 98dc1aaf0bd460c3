// The reference store (DESIGN §6.4): ground-truth right eyes rendered once per (scene, rig,
// resolution, provider), kept as EXR with a provenance record, re-checked later for drift.
//
// Layout: <root>/<id>/right.exr, right.png and provenance.json, where <id> names the scene,
// provider, resolution, interaxial, convergence and light count. An entry is complete exactly when
// its folder exists: it is written into a temporary folder beside it and renamed into place.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/parallel.hpp"
#include "renderer/rig.hpp"
#include "validation/metrics.hpp"

namespace sb::reference {

/// What to render a reference of; stored in the provenance so that verify can render it again.
struct ReferenceSpec {
  std::string scene;  ///< a built-in scene name or a glTF path, as given
  std::optional<int> lights;
  RigOverrides rig;
  std::string provider = "full";
};

/// The default store: reference/store in the source tree.
[[nodiscard]] std::filesystem::path default_store_dir();

/// How a verified reference stands.
enum class Status {
  ok,             ///< the image matches its hash and a new render matches it (within tolerance)
  drift,          ///< a new render differs from the stored image beyond the tolerance
  corrupt,        ///< the stored image does not match the hash in its provenance (or is unreadable)
  scene_changed,  ///< the scene's content is no longer what the reference was rendered from
  unavailable,    ///< the provider's tool is missing here, or failed to render: not checked (never a pass)
};
[[nodiscard]] const char* to_string(Status status);
/// Whether a status fails a verification (everything but ok).
[[nodiscard]] inline bool failed(Status status) { return status != Status::ok; }

struct VerifyOptions {
  /// Render again and compare; without it only the stored image's hash and the scene are checked.
  bool rerender = true;
  /// A new render within this PSNR (8-bit sRGB) of the stored one counts as ok; infinity demands
  /// identical 8-bit images. The linear images are compared bit for bit first.
  double min_psnr = std::numeric_limits<double>::infinity();
};

struct VerifyResult {
  std::string id;
  Status status = Status::ok;
  std::string detail;  ///< what was found, with numbers
  std::optional<validation::ImageMetrics> metrics;  ///< new render vs stored, when rendered
  bool bit_identical = false;
};

class ReferenceStore {
 public:
  explicit ReferenceStore(std::filesystem::path root) : root_(std::move(root)) {}
  [[nodiscard]] const std::filesystem::path& root() const { return root_; }
  /// " --store ROOT" (shell-quoted) for a command that is to work on this store, empty for the
  /// default store: for the commands messages give.
  [[nodiscard]] std::string store_option() const;
  /// " --scenes-dir DIR" (shell-quoted) for a command that loads scenes from `scenes_dir`, empty for
  /// none given or the default folder.
  [[nodiscard]] static std::string scenes_dir_option(const std::filesystem::path& scenes_dir);
  /// The command that writes the entry `id` of this store again (its scenes from `scenes_dir`), for
  /// messages.
  [[nodiscard]] std::string update_command(const std::string& id, const std::filesystem::path& scenes_dir) const;

  /// The ids of complete entries, sorted. InputError when the store does not exist or is not a
  /// folder.
  [[nodiscard]] std::vector<std::string> ids() const;
  /// InputError unless `id` names an entry of the store (complete or damaged): a path or "."/"..",
  /// or a folder the store does not hold, is named as such.
  void require(const std::string& id) const;
  /// An entry's provenance; InputError naming the id and listing the store when it is absent.
  [[nodiscard]] nlohmann::json provenance(const std::string& id) const;

  /// Renders the reference and stores it, replacing an entry of the same id made from the same
  /// scene and spec (or rig); InputError when that entry was made from another scene of the same
  /// name, or from another spec whose rig differs by less than the id shows. A glTF path is stored
  /// absolute. Returns the id.
  std::string generate(const ReferenceSpec& spec, const std::filesystem::path& scenes_dir,
                       const std::string& command_line, const Executor& executor) const;

  /// Checks an entry: its image against its hash, its scene against the scene hash, and with
  /// options.rerender a new render against the stored image.
  [[nodiscard]] VerifyResult verify(const std::string& id, const std::filesystem::path& scenes_dir,
                                    const VerifyOptions& options, const Executor& executor) const;

  /// The spec an entry was generated from (read back from its provenance).
  [[nodiscard]] ReferenceSpec spec_of(const std::string& id) const;

 private:
  std::filesystem::path root_;
};

}  // namespace sb::reference
