// The reference store: generate, read back and verify reference right eyes.
#include "reference/store.hpp"

#include <algorithm>
#include <cmath>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <regex>
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/file.h>
#include <unistd.h>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/file_lock.hpp"
#include "renderer/io/image_io.hpp"
#include "renderer/io/json_text.hpp"
#include "renderer/io/render_output.hpp"
#include "renderer/io/unique_fd.hpp"
#include "renderer/render_scene.hpp"
#include "renderer/rig.hpp"
#include "renderer/text.hpp"
#include "sb_version.hpp"
#include "scenes/catalog.hpp"
#include "validation/content_hash.hpp"
#include "validation/image_files.hpp"
#include "validation/metric_images.hpp"
#include "validation/truth.hpp"
#include "validation/truth_cache.hpp"

namespace sb::reference {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr const char* kProvenance = "provenance.json";
constexpr const char* kImage = "right.exr";
constexpr const char* kPreview = "right.png";
constexpr const char* kKind = "stereobench.reference";
/// Stands in the provenance for the provider's scratch folder, which is removed once stored.
constexpr const char* kWorkPlaceholder = "$WORK";

template <class T>
json optional_json(const std::optional<T>& v) {
  return v ? json(*v) : json(nullptr);
}

/// An optional count of a spec: absent or null, else an integer in [1, max]; InputError naming the
/// field ("spec.lights") otherwise (a value the command line could never have given: the provenance
/// was edited or damaged, and nlohmann's get<int> would truncate 64.7 or wrap 4294967360).
std::optional<int> optional_count(const json& j, const char* key, const char* field, int max) {
  if (!j.contains(key) || j.at(key).is_null()) return std::nullopt;
  const json& v = j.at(key);
  if (!v.is_number_integer() || v.get<double>() < 1.0 || v.get<double>() > max)
    throw InputError(fmt::format("{} is {}, not a whole number in 1..{}", field, v.dump(), max));
  return v.get<int>();
}

/// An optional quantity of a spec: absent or null, else a finite number; InputError naming the field.
/// An optional positive quantity below `below` (a rig's interaxial, disparity, convergence,
/// field of view).
std::optional<double> optional_quantity(const json& j, const char* key, const char* field,
                                        double below = std::numeric_limits<double>::infinity()) {
  if (!j.contains(key) || j.at(key).is_null()) return std::nullopt;
  const json& v = j.at(key);
  if (!v.is_number() || !(v.get<double>() > 0.0 && v.get<double>() < below))
    throw InputError(fmt::format("{} is {}, not a positive finite number{}", field, v.dump(),
                                 std::isinf(below) ? std::string() : fmt::format(" below {:g}", below)));
  return v.get<double>();
}

/// `path` with its folder's links and ".." resolved and its own name kept: a linked scene file is the
/// link (its name gives the id, its buffers and textures lie beside it), and "link/../x" is the x
/// beside the link's target. The path as given, made absolute and normal, where the folder cannot
/// be resolved.
fs::path with_folder_resolved(const fs::path& path) {
  std::error_code ec;
  const fs::path folder = fs::weakly_canonical(path.parent_path(), ec);
  return ec ? path.lexically_normal() : folder / path.filename();
}

json spec_to_json_fields(const ReferenceSpec& s) {
  return {{"scene", s.scene},
          {"lights", optional_json(s.lights)},
          {"provider", s.provider},
          {"rig_overrides",
           {{"interaxial_m", optional_json(s.rig.interaxial)},
            {"max_disparity_px", optional_json(s.rig.max_disparity_px)},
            {"convergence_m", optional_json(s.rig.convergence)},
            {"width", optional_json(s.rig.width)},
            {"height", optional_json(s.rig.height)},
            {"vfov_rad", optional_json(s.rig.vfov)}}}};
}

/// The spec as a provenance in the store at `root` records it. A scene file is given by its absolute
/// path and, as "scene_from_store", relative to the store, so that a project moved or checked out
/// elsewhere with its store and scenes still finds it (spec_in prefers that one).
json spec_to_json(const ReferenceSpec& s, const fs::path& root) {
  json out = spec_to_json_fields(s);
  if (scenes::is_scene_file_spec(s.scene)) {
    std::error_code ec;
    // The folder relative to the store's, the file's own name kept (a linked scene file is the link).
    const fs::path scene(s.scene);
    const fs::path folder = fs::relative(scene.parent_path(), root, ec);
    if (!ec && !folder.empty()) out["scene_from_store"] = (folder / scene.filename()).generic_string();
  }
  return out;
}

/// The rig as a provenance records it: its parameters and the camera pose.
json rig_record(const StereoRig& rig) {
  json out = io::rig_to_json(rig);
  const CameraPose& pose = rig.pose();
  out["pose"] = {{"position", {pose.position.x, pose.position.y, pose.position.z}},
                 {"right", {pose.right.x, pose.right.y, pose.right.z}},
                 {"up", {pose.up.x, pose.up.y, pose.up.z}},
                 {"back", {pose.back.x, pose.back.y, pose.back.z}}};
  return out;
}

/// Whether a recorded rig has the shape rig_record writes (the keys that fix the view, each a number,
/// and the pose's four vectors); an edited or damaged record does not.
bool well_formed_rig(const json& rig) {
  if (!rig.is_object()) return false;
  for (const char* key : {"width", "height", "vfov_deg", "interaxial_m", "convergence_m"})
    if (!rig.contains(key) || !rig[key].is_number()) return false;
  if (!rig.contains("pose") || !rig["pose"].is_object()) return false;
  for (const char* key : {"position", "right", "up", "back"}) {
    const json& v = rig["pose"].value(key, json());
    if (!v.is_array() || v.size() != 3) return false;
    for (const json& c : v)
      if (!c.is_number()) return false;
  }
  return true;
}

/// Where a recorded record and one computed now first differ, as "FIELD: recorded X, now Y"
/// (FIELD a dotted path below `at`, e.g. "pose.position[1]"), or nothing when they agree: every
/// value the recorded one holds equal in type, strings and booleans, numbers within 1e-9
/// (relative). Keys only the new record has (fields added to the record since) are not compared.
std::optional<std::string> record_difference(const json& recorded, const json& now, const std::string& at = "") {
  const auto differ = [&] {
    return fmt::format("{}: recorded {}, now {}", at.empty() ? "the record" : at, recorded.dump(), now.dump());
  };
  if (recorded.is_number() && now.is_number()) {
    const double x = recorded.get<double>(), y = now.get<double>();
    if (std::fabs(x - y) <= 1e-9 * std::max({1.0, std::fabs(x), std::fabs(y)})) return std::nullopt;
    return differ();
  }
  if (recorded.type() != now.type()) return differ();
  if (recorded.is_object()) {
    for (auto it = recorded.begin(); it != recorded.end(); ++it) {
      const std::string field = at.empty() ? it.key() : at + "." + it.key();
      if (!now.contains(it.key())) return fmt::format("{}: recorded {}, now absent", field, it.value().dump());
      if (auto why = record_difference(it.value(), now[it.key()], field)) return why;
    }
    return std::nullopt;
  }
  if (recorded.is_array()) {
    if (recorded.size() != now.size()) return differ();
    for (size_t i = 0; i < recorded.size(); ++i)
      if (auto why = record_difference(recorded[i], now[i], fmt::format("{}[{}]", at, i))) return why;
    return std::nullopt;
  }
  if (recorded == now) return std::nullopt;
  return differ();
}

/// Whether a recorded record agrees with one computed now (record_difference).
bool same_record(const json& recorded, const json& now) { return !record_difference(recorded, now); }

/// A record's JSON cut to 120 characters, for a message.
std::string brief(const json& j) {
  const std::string text = j.dump();
  return text.size() <= 120 ? text : text.substr(0, 117) + "...";
}

ReferenceSpec spec_from_json(const json& j) {
  ReferenceSpec s;
  s.scene = j.at("scene").get<std::string>();
  s.lights = optional_count(j, "lights", "spec.lights", std::numeric_limits<int>::max());
  s.provider = j.at("provider").get<std::string>();
  const json& r = j.at("rig_overrides");
  if (!r.is_object()) throw InputError(fmt::format("spec.rig_overrides is {}, not an object", brief(r)));
  s.rig.interaxial = optional_quantity(r, "interaxial_m", "spec.rig_overrides.interaxial_m");
  s.rig.max_disparity_px = optional_quantity(r, "max_disparity_px", "spec.rig_overrides.max_disparity_px");
  s.rig.convergence = optional_quantity(r, "convergence_m", "spec.rig_overrides.convergence_m");
  s.rig.width = optional_count(r, "width", "spec.rig_overrides.width", kMaxImageSide);
  s.rig.height = optional_count(r, "height", "spec.rig_overrides.height", kMaxImageSide);
  s.rig.vfov = optional_quantity(r, "vfov_rad", "spec.rig_overrides.vfov_rad", 3.141592653589793);
  return s;
}

/// The spec a provenance (read from `file`) records; InputError naming the file when it is malformed.
ReferenceSpec spec_in(const json& provenance, const fs::path& file) {
  ReferenceSpec spec;
  if (!provenance.is_object() || !provenance.contains("spec"))
    throw InputError(fmt::format("{}: has no field 'spec' (what the reference renders), so it cannot be rendered again; "
                                 "generate the reference anew (stereobench reference generate)",
                                 file.string()));
  if (!provenance.at("spec").is_object())
    throw InputError(fmt::format("{}: field 'spec' is {}, not an object; the provenance is damaged: remove the entry "
                                 "and generate it again",
                                 file.string(), brief(provenance.at("spec"))));
  if (provenance.value("version", json(nullptr)) != 1)
    throw InputError(fmt::format("{}: version {} is not the provenance version this stereobench writes and reads (1); "
                                 "use the stereobench that wrote it, or remove the entry and generate it again",
                                 file.string(), brief(provenance.value("version", json(nullptr)))));
  try {
    spec = spec_from_json(provenance.at("spec"));
  } catch (const json::exception& e) {
    throw InputError(fmt::format("{}: field 'spec' is malformed ({})", file.string(), e.what()));
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}; the provenance is damaged: remove the entry and generate it again",
                                 file.string(), e.what()));
  }
  // A scene file the store's own relative path still finds is the one meant, wherever the project
  // (store and scenes) has moved; else the recorded absolute path.
  const json& recorded = provenance.at("spec");
  if (recorded.contains("scene_from_store") && recorded.at("scene_from_store").is_string()) {
    std::error_code ec;
    const fs::path relative(recorded.at("scene_from_store").get<std::string>());
    const fs::path beside = with_folder_resolved(file.parent_path().parent_path() / relative);
    if (!relative.filename().empty() && fs::is_regular_file(beside, ec)) spec.scene = beside.string();
  }
  const std::vector<std::string> providers = validation::truth_provider_names();
  if (std::find(providers.begin(), providers.end(), spec.provider) == providers.end())
    throw InputError(fmt::format("{}: spec.provider '{}' is not a ground-truth provider ({})", file.string(),
                                 spec.provider, fmt::join(providers, ", ")));
  return spec;
}

/// Every occurrence of `from` in `text` replaced by `to`.
std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  if (from.empty()) return text;
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

/// `text` with the scratch folder written as kWorkPlaceholder: its absolute path as the providers
/// write it (fs::absolute, not normalized: a store given as a/../b keeps its ".."), then the
/// path as given, which the absolute one contains.
std::string without_scratch_path(std::string text, const fs::path& scratch) {
  text = replace_all(std::move(text), fs::absolute(scratch).string(), kWorkPlaceholder);
  return replace_all(std::move(text), scratch.string(), kWorkPlaceholder);
}

/// `value` with the scratch folder written as kWorkPlaceholder in every string.
json without_scratch_path(const json& value, const fs::path& scratch) {
  if (value.is_string()) return without_scratch_path(value.get<std::string>(), scratch);
  if (!value.is_structured()) return value;
  json out = value;
  for (auto& item : out.items()) item.value() = without_scratch_path(item.value(), scratch);
  return out;
}

/// The ids an entry of this spec may lie under. The first is the id an entry is made under: the
/// scene (its file_stem: a name safe in a path, never hidden), provider, size, interaxial and
/// convergence; the field of view and the light count where they are not the scene's
/// (`lights_in_file`: the scene's own count). Then those naming a field of view or light count the
/// spec gives explicitly although the scene has come to share it: the id was made when the scene's
/// own differed, and the rig is as recorded.
std::vector<std::string> reference_ids(const Scene& scene, const ReferenceSpec& spec, const StereoRig& rig,
                                       size_t lights_in_file) {
  const RigParams& p = rig.params();
  const bool vfov_named = p.vfov != resolve_rig(scene, {}).params().vfov;
  const bool lights_named = spec.lights && static_cast<size_t>(*spec.lights) != lights_in_file;
  const std::string base = fmt::format("{}_{}_{}x{}_e{:.1f}mm_c{:.3g}m", scene.file_stem(), spec.provider, p.width,
                                       p.height, p.interaxial * 1e3, p.convergence);
  std::vector<std::string> ids;
  for (const bool vfov : {vfov_named, spec.rig.vfov.has_value()})
    for (const bool lights : {lights_named, spec.lights.has_value()}) {
      std::string id = base;
      if (vfov) id += fmt::format("_v{:.4g}deg", radians_to_degrees(p.vfov));
      if (lights) id += fmt::format("_l{}", *spec.lights);
      if (std::find(ids.begin(), ids.end(), id) == ids.end()) ids.push_back(id);
    }
  return ids;
}

/// A folder of its own in the temporary folder (TMPDIR, else /tmp), "PREFIX-XXXXXX", removed with
/// everything in it when the object goes.
class ScratchFolder {
 public:
  explicit ScratchFolder(const std::string& prefix) {
    std::error_code ec;
    const fs::path tmp = fs::temp_directory_path(ec);
    if (ec) {
      const char* env = std::getenv("TMPDIR");
      throw IoError(fmt::format("cannot create a scratch folder: the temporary folder {} is not a folder ({}); set "
                                "TMPDIR to a folder you can write",
                                env != nullptr ? fmt::format("TMPDIR={}", env) : std::string("/tmp"), ec.message()));
    }
    std::string made = (tmp / (prefix + "-XXXXXX")).string();
    if (::mkdtemp(made.data()) == nullptr) {
      const int err = errno;
      throw IoError(fmt::format("cannot create a scratch folder {}: {}; set TMPDIR to a folder you can write",
                                made, std::strerror(err)));
    }
    path_ = made;
  }
  ScratchFolder(const ScratchFolder&) = delete;
  ScratchFolder& operator=(const ScratchFolder&) = delete;
  ~ScratchFolder() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  [[nodiscard]] const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

/// A working folder of the store, ".ID.KIND-PID-XXXXXX" (KIND new or old; "verify", a kind stores
/// written by older versions may hold, is cleared up too), held under an exclusive lock (flock)
/// while the generate that made it runs: remove_stale_folders leaves a locked one alone, whichever
/// process, container or machine holds it.
struct WorkingFolder {
  fs::path path;
  io::UniqueFd fd;
};

/// The pattern of working folder names, ".ID.KIND-PID-XXXXXX": group 1 the id, group 2 the kind.
const std::regex& working_name() {
  static const std::regex pattern(R"(\.(.+)\.(new|old|verify)-[0-9]+-[A-Za-z0-9]{6})");
  return pattern;
}

/// The process's file mode creation mask (umask), read without changing it; 022 where the kernel
/// does not report it.
mode_t current_umask() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("Umask:", 0) == 0) return static_cast<mode_t>(std::strtoul(line.c_str() + 6, nullptr, 8));
  return 022;
}

/// Makes a new working folder of `kind` for entry `id`: made (mkdtemp) and locked under a name the
/// clean-up does not look at, then renamed, so that no other run can find it unlocked. The store
/// exists (generate makes it).
void make_working_folder(const fs::path& root, const std::string& id, const char* kind, WorkingFolder& out) {
  std::string made = (root / fmt::format(".{}.mk-XXXXXX", id)).string();
  if (::mkdtemp(made.data()) == nullptr) {
    const int err = errno;
    throw IoError(fmt::format("cannot create a working folder in the reference store {}: {}; give a --store you "
                              "can write",
                              root.string(), std::strerror(err)));
  }
  // mkdtemp makes it private (0700); once an entry, it is read like any folder the user makes.
  (void)::chmod(made.c_str(), 0777 & ~current_umask());
  out.fd.reset(::open(made.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  // Unlocked, another run's clean-up could take it; only a file system without locks is let be.
  if (!out.fd.valid() || (::flock(out.fd.get(), LOCK_EX | LOCK_NB) != 0 && errno != ENOLCK && errno != EOPNOTSUPP)) {
    const int err = errno;
    std::error_code ignored;
    fs::remove_all(made, ignored);
    throw IoError(fmt::format("cannot lock a working folder in the reference store {}: {}; give a --store you can "
                              "write",
                              root.string(), std::strerror(err)));
  }
  out.path = root / fmt::format(".{}.{}-{}-{}", id, kind, getpid(), made.substr(made.size() - 6));
  std::error_code ec;
  fs::rename(made, out.path, ec);
  if (ec) {
    const std::string why = ec.message();
    fs::remove_all(made, ec);
    throw IoError(fmt::format("cannot create a working folder in the reference store {}: {}; give a --store you can "
                              "write",
                              root.string(), why));
  }
}

/// Clears up after a generate (or verify) that was killed (SIGKILL, a job's time limit): its working
/// folders and id lock files (".ID.lock") that no lock holds are removed, except an entry moved
/// aside (".ID.old-…") whose id names no entry any more, which is moved back. Best effort: errors leave folders where they are.
void remove_stale_folders(const fs::path& root) {
  // A folder being made (".ID.mk-XXXXXX") is locked and renamed within microseconds; one a minute
  // old was left by a kill in between.
  static const std::regex being_made(R"(\..+\.mk-[A-Za-z0-9]{6})");
  static const std::regex lock_name(R"(\..+\.lock)");
  const auto now = fs::file_time_type::clock::now();
  std::error_code ec;
  for (fs::directory_iterator it(root, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    std::smatch m;
    std::error_code dir_ec;
    if (std::regex_match(name, lock_name) && it->is_regular_file(dir_ec)) {
      // An id's lock file left by a generate killed while it held it; one held now stays.
      if (std::optional<io::FileLock> left = io::FileLock::try_acquire(it->path())) left->remove_when_released();
      continue;
    }
    const bool made_here = std::regex_match(name, being_made);
    if ((!made_here && !std::regex_match(name, m, working_name())) || !it->is_directory(dir_ec)) continue;
    const io::UniqueFd fd(::open(it->path().c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
    if (!fd.valid()) continue;
    const bool free = ::flock(fd.get(), LOCK_EX | LOCK_NB) == 0;
    std::error_code ignored;
    if (!free) {
      // held by a running generate or verify
    } else if (made_here) {
      const auto made = fs::last_write_time(it->path(), dir_ec);
      if (!dir_ec && now - made > std::chrono::minutes(1)) fs::remove_all(it->path(), ignored);
    } else if (m[2] == "old" && fs::exists(it->path() / kProvenance, ignored) &&
               !fs::exists(root / m[1].str(), ignored)) {
      fs::rename(it->path(), root / m[1].str(), ignored);  // an entry moved aside whose replacement never came
    } else {
      fs::remove_all(it->path(), ignored);
    }
  }
}

/// Replaces `dir` by `staged` (a complete working folder of kind "new" beside it, made by
/// make_working_folder). An existing entry is swapped
/// with the staged one in a single rename (RENAME_EXCHANGE), so that the id names the old or the
/// new entry at every moment, and the old one is then removed under the staged name; where the
/// file system cannot swap, the old entry is moved aside (".ID.old-…", locked) first and moved back
/// should the new one not take its place (remove_stale_folders moves it back after a kill).
void replace_folder(const fs::path& staged, const fs::path& dir) {
  std::error_code ec;
  if (fs::exists(dir)) {
    if (::renameat2(AT_FDCWD, staged.c_str(), AT_FDCWD, dir.c_str(), RENAME_EXCHANGE) == 0) {
      fs::remove_all(staged, ec);
      return;
    }
    const int err = errno;
    // ENOENT: the entry went meanwhile; the new one is put in place below.
    if (err != EINVAL && err != ENOSYS && err != ENOTSUP && err != ENOENT)
      throw IoError(fmt::format("cannot put the new reference in place of '{}': {}", dir.string(), std::strerror(err)));
  }
  // The old entry goes aside under the staged folder's name with its kind "new" made "old" (the
  // same run's suffix), a name remove_stale_folders knows.
  std::string old_name = staged.filename().string();
  old_name.replace(old_name.rfind(".new-"), 5, ".old-");
  const fs::path old = dir.parent_path() / old_name;
  WorkingFolder hold;
  hold.fd.reset(::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (hold.fd.valid()) (void)::flock(hold.fd.get(), LOCK_EX | LOCK_NB);
  if (fs::exists(dir)) {
    fs::rename(dir, old, ec);
    if (ec) throw IoError(fmt::format("cannot move the old reference '{}' aside: {}", dir.string(), ec.message()));
  }
  fs::rename(staged, dir, ec);
  if (ec) {
    std::error_code restore;
    if (fs::exists(old)) fs::rename(old, dir, restore);
    throw IoError(fmt::format("cannot move the new reference into '{}': {}", dir.string(), ec.message()));
  }
  fs::remove_all(old, ec);
}

/// The scene argument as the store records and compares it: a glTF path absolute with its folder
/// resolved (with_folder_resolved: `verify` and `update` find it from any working folder), a
/// built-in name as given. A path that is not UTF-8 cannot be recorded in the provenance (JSON) as
/// it is, and is refused.
std::string stored_scene(const std::string& scene) {
  if (!scenes::is_scene_file_spec(scene)) return scene;
  // Not normalized as text first: "link/.." is the link target's folder, not the link's.
  const std::string stored = with_folder_resolved(fs::absolute(scene)).string();
  if (!io::is_utf8(stored))
    throw InputError(fmt::format("--scene {}: the path {} is not valid UTF-8, and the provenance (JSON) could not "
                                 "record it as it is; rename the file or its folders",
                                 printable(scene), printable(stored)));
  return stored;
}

struct Prepared {
  scenes::LoadedScene loaded;
  std::optional<StereoRig> rig;
};

Prepared prepare(const ReferenceSpec& spec, const fs::path& scenes_dir) {
  Prepared p{scenes::load_scene(spec.scene, scenes_dir, spec.lights), std::nullopt};
  p.rig.emplace(resolve_rig(p.loaded.scene, spec.rig));
  return p;
}

/// Why provenance `prov` of the entry in folder `id` contradicts itself or its folder, if it does:
/// it names another id, another image file, or another provider than its spec.
std::optional<std::string> inconsistent_provenance(const json& prov, const std::string& id, const ReferenceSpec& spec) {
  const auto text = [&prov](const char* object, const char* key) -> std::optional<std::string> {
    const json* o = object == nullptr ? &prov : (prov.contains(object) ? &prov.at(object) : nullptr);
    if (o == nullptr || !o->is_object() || !o->contains(key) || !o->at(key).is_string()) return std::nullopt;
    return o->at(key).get<std::string>();
  };
  const std::optional<std::string> kind = text(nullptr, "kind");
  if (kind != kKind)
    return fmt::format("its kind is {}, not '{}'", kind ? "'" + *kind + "'" : "(none)", kKind);
  const std::optional<std::string> recorded_id = text(nullptr, "id");
  if (recorded_id != id)
    return fmt::format("it records id {} but lies in folder '{}'", recorded_id ? "'" + *recorded_id + "'" : "(none)", id);
  const std::optional<std::string> image = text("image", "file");
  if (image != kImage)
    return fmt::format("it names image file {}, the store keeps '{}'", image ? "'" + *image + "'" : "(none)", kImage);
  const std::optional<std::string> provider = text("provider", "name");
  if (provider != spec.provider)
    return fmt::format("provider.name {} is not its spec's provider '{}'", provider ? "'" + *provider + "'" : "(none)",
                       spec.provider);
  return std::nullopt;
}

/// An id names one visible folder of the store: not a path, not "." or "..", not hidden.
void check_entry_name(const std::string& id) {
  if (id.empty() || id[0] == '.' || id.find_first_of("/\\") != std::string::npos)
    throw InputError(fmt::format("'{}' is not a reference id (a folder name of the store, as `stereobench reference "
                                 "list` prints it)",
                                 id));
}

}  // namespace

fs::path default_store_dir() { return fs::path(SB_SOURCE_DIR) / "reference" / "store"; }

std::string ReferenceStore::store_option() const {
  if (fs::absolute(root_).lexically_normal() == fs::absolute(default_store_dir()).lexically_normal()) return "";
  return " --store " + shell_quote(root_.string());
}

std::string ReferenceStore::scenes_dir_option(const fs::path& scenes_dir) {
  if (scenes_dir.empty() || scenes_dir.lexically_normal() == scenes::default_scenes_dir().lexically_normal()) return "";
  return " --scenes-dir " + shell_quote(scenes_dir.string());
}

std::string ReferenceStore::update_command(const std::string& id, const fs::path& scenes_dir) const {
  return "stereobench reference update " + shell_quote(id) + store_option() + scenes_dir_option(scenes_dir);
}

const char* to_string(Status s) {
  switch (s) {
    case Status::ok: return "ok";
    case Status::drift: return "drift";
    case Status::corrupt: return "corrupt";
    case Status::scene_changed: return "scene-changed";
    case Status::unavailable: return "unavailable";
  }
  return "?";
}

std::vector<std::string> ReferenceStore::ids() const {
  std::vector<std::string> out;
  std::error_code ec;
  if (!fs::is_directory(root_, ec))
    throw InputError(
        fmt::format("the reference store {} {}; give --store the folder that `stereobench reference "
                    "generate` wrote",
                    root_.string(), fs::exists(root_, ec) ? "is not a folder" : "does not exist"));
  for (const fs::directory_entry& e : fs::directory_iterator(root_)) {
    const std::string name = e.path().filename().string();
    // Every visible folder is an entry: one without its provenance is a damaged entry, which
    // verify reports, not a folder to pass over.
    if (e.is_directory() && name[0] != '.') out.push_back(name);
  }
  std::sort(out.begin(), out.end());
  return out;
}

void ReferenceStore::require(const std::string& id) const {
  check_entry_name(id);
  std::error_code ec;
  if (fs::is_directory(root_ / id, ec)) return;
  const std::vector<std::string> known = ids();
  throw InputError(fmt::format("no reference '{}' in {} ({}); run `stereobench reference list`", id, root_.string(),
                               known.empty() ? "the store is empty" : fmt::format("it holds {} references", known.size())));
}

json ReferenceStore::provenance(const std::string& id) const {
  require(id);
  const fs::path file = root_ / id / kProvenance;
  std::error_code ec;
  if (!fs::exists(file, ec))
    throw InputError(fmt::format("{} is missing: the entry's spec is lost with it; remove {} and make the reference "
                                 "again with `stereobench reference generate` and its scene and rig",
                                 file.string(), (root_ / id).string()));
  try {
    return io::parse_json(io::read_file(file));
  } catch (const io::JsonTextError& e) {
    // Its spec is lost with it, so `reference update` cannot render it again.
    throw InputError(fmt::format("{} is not valid JSON ({}); remove {} and make the reference again with "
                                 "`stereobench reference generate` and its scene and rig",
                                 file.string(), e.what(), (root_ / id).string()));
  }
}

ReferenceSpec ReferenceStore::spec_of(const std::string& id) const {
  return spec_in(provenance(id), root_ / id / kProvenance);
}

std::string ReferenceStore::generate(const ReferenceSpec& spec, const fs::path& scenes_dir,
                                     const std::string& command_line, const Executor& executor) const {
  const std::unique_ptr<validation::TruthProvider> provider = validation::make_truth_provider(spec.provider);
  if (auto why = provider->unavailable_reason())
    throw ToolError(fmt::format("cannot generate a '{}' reference: {}", spec.provider, *why));
  ReferenceSpec stored = spec;
  stored.scene = stored_scene(spec.scene);
  const Prepared p = prepare(stored, scenes_dir);
  const Scene& scene = p.loaded.scene;
  // An entry made when the scene's field of view or light count differed from the spec's keeps its
  // folder (reference_ids); otherwise the first of reference_ids, the id an entry is made under.
  const std::vector<std::string> candidates = reference_ids(scene, stored, *p.rig, p.loaded.lights_in_file);
  const auto existing = std::find_if(candidates.begin(), candidates.end(),
                                     [&](const std::string& c) { return fs::exists(root_ / c / kProvenance); });
  const std::string id = existing != candidates.end() ? *existing : candidates.front();
  // The id names the scene by its file's name alone and the rig rounded: another file (or a
  // built-in) of that name, or a rig that differs by less than the id shows, would silently take
  // the entry's place. Regenerating from the same scene and spec replaces it (also when the scene's camera has
  // changed since, as `reference update` does), as does an entry whose provenance cannot be read.
  // The check and the replacement are made under a lock on the id (".ID.lock" in the store, removed
  // when done), so that a generate of the same id running meanwhile is waited for, and then checked
  // against.
  std::error_code made_root;
  if (fs::exists(root_, made_root) && !fs::is_directory(root_, made_root))
    throw InputError(fmt::format("the reference store {} is a file, not a folder; give --store a folder (a new one is "
                                 "made)",
                                 root_.string()));
  fs::create_directories(root_, made_root);  // a new store
  if (made_root)
    throw IoError(fmt::format("cannot create the reference store {}: {}; give a --store you can write",
                              root_.string(), made_root.message()));
  const fs::path lock_file = root_ / fmt::format(".{}.lock", id);
  io::FileLock id_lock = io::FileLock::acquire(lock_file, [&] {
    fmt::print(stderr, "note: another run is generating reference {} (it holds {}); waiting for it to finish\n", id,
               lock_file.string());
  });
  id_lock.remove_when_released();  // the store keeps entries only
  if (fs::exists(root_ / id / kProvenance)) {
    std::optional<ReferenceSpec> before;
    json before_rig;
    try {
      const json prov = provenance(id);
      before = spec_in(prov, root_ / id / kProvenance);
      before_rig = prov.value("rig", json());
    } catch (const InputError&) {
    }
    if (before && stored_scene(before->scene) != stored.scene)
      throw InputError(fmt::format(
          "reference '{}' in {} was made from scene {}, not {} (the id names only the scene file's name, '{}'); give "
          "this one another --store, or remove {} to replace it",
          id, root_.string(), before->scene, stored.scene, scene.file_stem(), (root_ / id).string()));
    const json rig_now = rig_record(*p.rig);
    if (before && well_formed_rig(before_rig) && !same_record(before_rig, rig_now) &&
        !same_record(spec_to_json_fields(*before), spec_to_json_fields(stored)))
      throw InputError(fmt::format(
          "reference '{}' in {} was made with another rig ({}; the id gives the interaxial to 0.1 mm and the "
          "convergence to 3 digits); give this one another --store, or remove {} to replace it",
          id, root_.string(), record_difference(before_rig, rig_now).value_or("?"), (root_ / id).string()));
  }
  remove_stale_folders(root_);
  WorkingFolder working;
  make_working_folder(root_, id, "new", working);
  const fs::path& staged = working.path;
  std::error_code ec;
  try {
    const RenderScene prepared(scene);
    const validation::TruthRequest request{prepared, p.loaded.file, *p.rig, staged / "work", executor.threads()};
    const validation::TruthRender render = provider->render(request);
    validation::check_truth_samples(render, request.work_dir, false);  // never stored as a reference
    const Image right = validation::rgb_plane_only(render.right);
    io::write_exr(staged / kImage, right);
    validation::write_png(staged / kPreview, validation::encode_srgb8(right, "the reference"));
    fs::remove_all(staged / "work", ec);
    json provenance = {
        {"kind", kKind},
        {"version", 1},
        {"id", id},
        {"spec", spec_to_json(stored, root_)},
        {"provider",
         {{"name", render.provider},
          {"tool_version", render.tool_version},
          {"revision", provider->revision()},
          {"settings", without_scratch_path(render.settings, request.work_dir)},
          {"command", without_scratch_path(render.command, request.work_dir)},
          {"seconds", render.seconds}}},
        {"scene",
         {{"name", scene.name},
          {"file", p.loaded.file.string()},
          {"file_sha256", validation::hash_file(p.loaded.file)},
          {"content_sha256", validation::hash_scene(scene)},
          {"triangles", scene.triangle_count()},
          {"lights", scene.lights.size()},
          {"lights_in_file", p.loaded.lights_in_file}}},
        {"rig", rig_record(*p.rig)},
        {"image",
         {{"file", kImage},
          {"preview", kPreview},
          {"width", right.width()},
          {"height", right.height()},
          {"sha256", validation::hash_file(staged / kImage)},
          {"content_sha256", validation::hash_image(right)}}},
        {"command_line", command_line},
        {"date", utc_now()},
        {"stereobench_version", SB_VERSION_STRING},
        {"versions", io::versions_json()}};
    // An external provider ran its tool in request.work_dir inside the staging folder, both gone
    // once the entry is stored: the provenance writes that folder as $WORK and says so. The
    // built-in provider runs no tool and uses no folder.
    if (!render.command.empty())
      provenance["provider"]["work_folder"] = fmt::format(
          "{} is the folder the provider exported the scene to and ran its tool in; it is removed once the reference "
          "is stored. `stereobench reference generate` with this spec makes it again (`stereobench validate --truth "
          "{} --out DIR` keeps its own under DIR/work/).",
          kWorkPlaceholder, render.provider);
    io::write_text_atomically(staged / kProvenance, io::json_text(provenance, 2) + "\n");
    replace_folder(staged, root_ / id);
  } catch (const IoError& e) {
    // The writers name the files in the working folder, which goes now: the message names the
    // entry they were for.
    fs::remove_all(staged, ec);
    const std::string message = replace_all(e.what(), staged.string(), (root_ / id).string());
    throw IoError(fmt::format("{} (reference '{}' was not stored{})", message, id,
                              fs::exists(root_ / id, ec) ? "; the earlier one of that id is kept" : ""));
  } catch (const ToolError& e) {
    fs::remove_all(staged, ec);
    throw ToolError(fmt::format("{}\n(the tool's work folder was inside the store's unfinished entry and is removed "
                                "with it; `stereobench validate --truth {} --out DIR` renders the same truth and keeps "
                                "its files in DIR/work/)",
                                e.what(), spec.provider));
  } catch (...) {
    fs::remove_all(staged, ec);
    throw;
  }
  return id;
}

VerifyResult ReferenceStore::verify(const std::string& id, const fs::path& scenes_dir, const VerifyOptions& options,
                                    const Executor& executor) const {
  check_entry_name(id);
  VerifyResult r;
  r.id = id;
  const fs::path prov_file = root_ / id / kProvenance;
  std::error_code ec;
  json prov;
  ReferenceSpec spec;
  try {
    prov = provenance(id);
    spec = spec_in(prov, prov_file);
  } catch (const InputError& e) {
    if (!fs::is_directory(root_ / id, ec)) throw;  // an id the store does not hold
    // A damaged entry is a finding of the verification, not a reason to stop it.
    r.status = Status::corrupt;
    r.detail = e.what();
    return r;
  }
  if (const std::optional<std::string> why = inconsistent_provenance(prov, id, spec)) {
    r.status = Status::corrupt;
    r.detail = fmt::format("{}: {}; remove {} and make the reference again with `stereobench reference generate`",
                           prov_file.string(), *why, (root_ / id).string());
    return r;
  }
  const fs::path image_file = root_ / id / kImage;
  std::string stored_hash;
  try {
    stored_hash = prov.at("image").at("sha256").get<std::string>();
  } catch (const json::exception&) {
    r.status = Status::corrupt;
    r.detail = fmt::format("{}: the provenance has no image hash (image.sha256)", prov_file.string());
    return r;
  }
  if (!fs::exists(image_file, ec)) {
    r.status = Status::corrupt;
    r.detail = fmt::format("{} is missing", image_file.string());
    return r;
  }
  const std::string file_hash = validation::hash_file(image_file);
  if (file_hash != stored_hash) {
    r.status = Status::corrupt;
    r.detail = fmt::format("{} has hash {} but its provenance records {}", image_file.string(), file_hash.substr(0, 12),
                           stored_hash.substr(0, 12));
    return r;
  }
  std::optional<Prepared> loaded;
  try {
    loaded.emplace(prepare(spec, scenes_dir));
  } catch (const InputError& e) {  // the scene is gone or no longer loads, or the spec's rig is invalid
    r.status = Status::scene_changed;
    r.detail = fmt::format("the scene or rig of its spec cannot be prepared: {}", e.what());
    return r;
  }
  const Prepared& p = *loaded;
  const std::string scene_hash = validation::hash_scene(p.loaded.scene);
  const json scene_record = prov.value("scene", json::object());
  const std::string recorded_scene = scene_record.is_object() && scene_record.contains("content_sha256") &&
                                             scene_record["content_sha256"].is_string()
                                         ? scene_record["content_sha256"].get<std::string>()
                                         : std::string();
  if (scene_hash != recorded_scene) {
    r.status = Status::scene_changed;
    r.detail = fmt::format("scene '{}' ({}) now hashes to {}, the reference was rendered from {}; regenerate it",
                           spec.scene, p.loaded.file.string(), scene_hash.substr(0, 12), recorded_scene.substr(0, 12));
    return r;
  }
  // The rig the spec resolves to now must be the one recorded: the stored image shows that view.
  // The scene hash covers geometry, materials and lights, not the camera, so a moved camera shows here.
  const json recorded_rig = prov.value("rig", json(nullptr));
  const json rig_now = rig_record(*p.rig);
  if (!well_formed_rig(recorded_rig)) {
    r.status = Status::corrupt;
    r.detail = fmt::format("{}: the recorded rig {} is not a rig record; regenerate the entry", prov_file.string(),
                           brief(recorded_rig));
    return r;
  }
  if (const std::optional<std::string> why = record_difference(recorded_rig, rig_now)) {
    r.status = Status::scene_changed;
    r.detail = fmt::format("its spec now resolves to another rig than the recorded one (rig {}): the scene's camera "
                           "or the rig defaults changed; regenerate the entry",
                           *why);
    return r;
  }
  // With scene and rig as recorded, the folder's name is the id its spec gives: a renamed folder
  // would be found under a name that `reference generate` never writes, and regenerated beside it.
  // A field of view (or light count) the spec gives explicitly that the scene's camera (or file) has
  // since come to share leaves the rig as recorded, and the id as it was made (reference_ids).
  if (const std::vector<std::string> ids = reference_ids(p.loaded.scene, spec, *p.rig, p.loaded.lights_in_file);
      std::find(ids.begin(), ids.end(), id) == ids.end()) {
    const std::string& expected = ids.front();
    r.status = Status::corrupt;
    // Also an entry of a store written when ids named a scene by the name inside its file, or
    // before they named a field of view other than the scene camera's.
    r.detail = fmt::format("{}: its spec makes the reference '{}' (the id names the scene file, the rig, and a field "
                           "of view or light count other than the scene's), but the entry lies in folder '{}'; "
                           "`{}` writes it under that id, or rename the folder to '{}' (and its provenance's \"id\")",
                           prov_file.string(), expected, id, update_command(id, scenes_dir), expected);
    return r;
  }
  // The hash matched, but the file may still be no image of this rig (both replaced together).
  Image stored;
  try {
    stored = validation::rgb_plane_only(io::read_exr(image_file));
  } catch (const ResourceError&) {
    throw;  // this machine's shortage (exit 4), not a damaged entry
  } catch (const std::exception& e) {
    r.status = Status::corrupt;
    r.detail = fmt::format("{} cannot be read ({}); remove {} and make the reference again with `stereobench "
                           "reference generate`",
                           image_file.string(), e.what(), (root_ / id).string());
    return r;
  }
  if (stored.width() != p.rig->params().width || stored.height() != p.rig->params().height) {
    r.status = Status::corrupt;
    r.detail = fmt::format("{} is {}x{}, but its rig renders {}x{}; remove {} and make the reference again with "
                           "`stereobench reference generate`",
                           image_file.string(), stored.width(), stored.height(), p.rig->params().width,
                           p.rig->params().height, (root_ / id).string());
    return r;
  }
  // The preview is what people look at: it must show the stored image (its bytes are not
  // recorded, so its pixels are compared with the image's sRGB encoding).
  const fs::path preview_file = root_ / id / kPreview;
  const std::string preview_fix = fmt::format("`{}` writes it again", update_command(id, scenes_dir));
  try {
    const validation::Srgb8Image preview = validation::read_srgb8_file(preview_file).image;
    const validation::Srgb8Image expected = validation::encode_srgb8(stored, "the stored reference");
    if (preview.width != expected.width || preview.height != expected.height || preview.rgb != expected.rgb) {
      r.status = Status::corrupt;
      r.detail = fmt::format("{} does not show {} ({}); {}", preview_file.string(), image_file.string(),
                             preview.width != expected.width || preview.height != expected.height
                                 ? fmt::format("it is {}x{}", preview.width, preview.height)
                                 : std::string("its pixels differ"),
                             preview_fix);
      return r;
    }
  } catch (const Error& e) {
    r.status = Status::corrupt;
    r.detail = fmt::format("the preview cannot be read: {}; {}", e.what(), preview_fix);
    return r;
  }
  if (!options.rerender) {
    r.detail = "image, preview, scene and rig match their records (not rendered again)";
    return r;
  }
  const std::unique_ptr<validation::TruthProvider> provider = validation::make_truth_provider(spec.provider);
  if (auto why = provider->unavailable_reason()) {
    r.status = Status::unavailable;
    r.detail = *why;
    return r;
  }
  const RenderScene prepared(p.loaded.scene);
  // The render goes to a scratch folder outside the store: verifying only reads the store, which
  // may be read-only (a checkout, another user's store).
  const ScratchFolder work(fmt::format("stereobench-verify-{}", id));
  const validation::TruthRequest request{prepared, p.loaded.file, *p.rig, work.path(), executor.threads()};
  Image fresh;
  try {
    const validation::TruthRender render = provider->render(request);
    validation::check_truth_samples(render, request.work_dir, false);
    fresh = validation::rgb_plane_only(render.right);
  } catch (const ToolError& e) {
    // The tool is there but failed (or wrote nothing readable): this entry is not checked, the
    // next ones still are.
    r.status = Status::unavailable;
    r.detail = fmt::format("{} could not render it again here: {}", spec.provider, e.what());
    return r;
  }
  r.bit_identical = fresh == stored;
  r.metrics = validation::compare_images(validation::encode_srgb8(fresh, "the new render"),
                                         validation::encode_srgb8(stored, "the stored reference"));
  const double psnr = r.metrics->psnr;
  // Without --min-psnr (infinite) only a bit-identical image passes: the stored image is linear
  // float, so a difference may vanish in the 8-bit sRGB encoding the PSNR is measured on.
  const bool within = r.bit_identical || (std::isfinite(options.min_psnr) && psnr >= options.min_psnr);
  r.status = within ? Status::ok : Status::drift;
  if (r.bit_identical)
    r.detail = "a new render is bit-identical";
  else if (r.metrics->max_error == 0)
    r.detail = fmt::format("a new render differs from the stored float image, though not in its 8-bit sRGB encoding "
                           "(PSNR inf dB){}",
                           within ? fmt::format(" (within --min-psnr {})", options.min_psnr)
                                  : std::string("; give --min-psnr to accept differences that small"));
  else
    r.detail = fmt::format("a new render differs: PSNR {:.2f} dB, max error {} at ({}, {}), {:.4f} % error pixels{}",
                           psnr, r.metrics->max_error, r.metrics->max_x, r.metrics->max_y,
                           100.0 * r.metrics->error_fraction,
                           within ? fmt::format(" (within --min-psnr {})", options.min_psnr) : "");
  return r;
}

}  // namespace sb::reference
