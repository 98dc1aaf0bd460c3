// The on-disk cache of ground-truth renders.
#include "validation/truth_cache.hpp"

#include <fcntl.h>

#include <cerrno>
#include <cmath>
#include <functional>
#include <mutex>
#include <optional>
#include <set>

#include <fmt/format.h>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/image_io.hpp"
#include "renderer/io/json_text.hpp"
#include "renderer/io/unique_fd.hpp"
#include "validation/content_hash.hpp"

namespace sb::validation {

using nlohmann::json;

namespace {

/// An exclusive lock on the work folder an external tool renders in, held while it renders: two
/// runs sharing the folder would read each other's passes. The lock is an open-file-description
/// lock on ".stereobench-render.lock" in the folder (fcntl locks also hold on NFS, where a Slurm
/// sweep's folders may lie). A run that finds it held says so and waits. Where locks are
/// unavailable, or the lock file cannot be made (the provider then reports the folder), nothing is
/// held.
class WorkFolderLock {
 public:
  WorkFolderLock(const std::filesystem::path& dir, const std::string& provider) {
    if (dir.empty() || provider == "full") return;  // the built-in renderer writes no files
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    fd_.reset(::open((dir / ".stereobench-render.lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666));  // the umask decides
    if (!fd_.valid()) return;
    struct flock whole {};
    whole.l_type = F_WRLCK;
    whole.l_whence = SEEK_SET;
    if (::fcntl(fd_.get(), F_OFD_SETLK, &whole) == 0 || (errno != EAGAIN && errno != EACCES)) return;
    fmt::print(stderr, "stereobench: another run is rendering a '{}' ground truth in {}; waiting for it\n", provider,
               dir.string());
    int rc = 0;
    while ((rc = ::fcntl(fd_.get(), F_OFD_SETLKW, &whole)) != 0 && errno == EINTR) {
    }
    waited_ = rc == 0;
  }
  /// Whether another run held the folder first (its render may be the one wanted, now cached).
  [[nodiscard]] bool waited() const { return waited_; }

 private:
  io::UniqueFd fd_;
  bool waited_ = false;
};

/// Prints on standard error, once per scene file and provider, the warning `text` makes (nothing
/// where it makes none): `text` runs only the first time, so that a costly look at the scene is
/// not repeated for every cell and frame.
void warn_once(const Scene& scene, const std::string& provider, const char* topic,
               const std::function<std::optional<std::string>()>& text) {
  static std::mutex mutex;
  static std::set<std::string> said;
  const std::lock_guard lock(mutex);
  if (!said.insert(scene.path + "\n" + provider + "\n" + topic).second) return;
  if (const std::optional<std::string> warning = text()) print_warning(*warning);
}

/// Says once per scene file and provider, on standard error, that an external tool shows what
/// this suite's renderer culls: glTF's single-sided materials (doubleSided false, the default)
/// hide their back faces from camera rays here, while Cycles and POV-Ray draw both sides. Closed
/// meshes wound outwards (spheres, boxes) are left out: no eye outside them sees a back face.
void note_single_sided(const Scene& scene, const std::string& provider) {
  if (provider == "full") return;
  warn_once(scene, provider, "single-sided", [&]() -> std::optional<std::string> {
    size_t meshes = 0;
    for (const Mesh& m : scene.meshes)
      if (m.material >= 0 && !scene.materials[static_cast<size_t>(m.material)].double_sided && m.triangle_count() > 0 &&
          !m.is_closed())
        ++meshes;
    if (meshes == 0) return std::nullopt;
    return fmt::format("{} mesh(es) of {} use single-sided materials: this suite's renderer hides their back faces "
                       "from the eye, as glTF asks, while the {} ground truth shows them; where an eye sees one, the "
                       "images differ for that reason (mark the materials doubleSided to compare like with like)",
                       meshes, scene.path, provider);
  });
}

/// Says once per scene file and provider that an external tool samples textures without
/// mip-mapping: on a textured scene the per-pixel metrics against it measure mostly that
/// (docs/ground_truth.md, "the textured gap").
void note_textured(const Scene& scene, const std::string& provider) {
  if (provider == "full") return;
  warn_once(scene, provider, "textured", [&]() -> std::optional<std::string> {
    size_t meshes = 0;
    for (const Mesh& m : scene.meshes)
      if (m.material >= 0 && scene.materials[static_cast<size_t>(m.material)].base_color_texture >= 0 &&
          m.triangle_count() > 0)
        ++meshes;
    if (meshes == 0) return std::nullopt;
    return fmt::format("{} mesh(es) of {} are textured: the {} ground truth takes one bilinear texture sample per "
                       "pixel, without the mip-mapping this suite's renderers use, so minified textures alias there "
                       "and the per-pixel metrics measure mostly that (docs/ground_truth.md, the textured gap); "
                       "compare textured scenes against --truth full",
                       meshes, scene.path, provider);
  });
}

}  // namespace


std::string truth_key(const TruthProvider& provider, const TruthRequest& request) {
  Sha256 sha;
  sha.add("stereobench-truth-key 1");
  sha.add(hash_scene(request.scene.scene()));
  const RigParams& p = request.rig.params();
  for (double v : {p.interaxial, p.convergence, p.vfov, p.znear, p.zfar}) sha.add_value(v);
  sha.add_value(p.width);
  sha.add_value(p.height);
  const CameraPose& pose = request.rig.pose();
  for (const dvec3& v : {pose.position, pose.right, pose.up, pose.back}) sha.add_value(v);
  sha.add(provider.name());
  sha.add(provider.revision());
  sha.add(provider.tool_version());
  return sha.hex();
}

namespace {

/// The samples of a ground truth's rgb plane that no radiance has, counted in one pass.
struct BadSamples {
  bool has_rgb = false;
  size_t nan = 0, inf = 0, negative = 0, total = 0;

  explicit BadSamples(const Image& truth) : has_rgb(truth.has_plane(planes::rgb)) {
    if (!has_rgb) return;
    const float* v = truth.data_f32(planes::rgb);
    total = truth.pixel_count() * 3;
    for (size_t i = 0; i < total; ++i) {
      nan += std::isnan(v[i]) ? 1 : 0;
      inf += std::isinf(v[i]) ? 1 : 0;
      negative += v[i] < 0.0f ? 1 : 0;
    }
  }
  [[nodiscard]] std::optional<std::string> why() const {
    if (!has_rgb) return "it has no rgb plane";
    if (nan + inf + negative == 0) return std::nullopt;
    return fmt::format("{} NaN, {} infinite and {} negative sample(s) of {}", nan, inf, negative, total);
  }
};

}  // namespace

std::optional<std::string> unusable_samples(const Image& truth) { return BadSamples(truth).why(); }

void check_truth_samples(const TruthRender& render, const std::filesystem::path& work_dir, bool caching) {
  const BadSamples counts(render.right);
  const auto bad = counts.why();
  if (!bad) return;
  const std::string kept = caching ? "; it was not stored in the cache" : "";
  if (render.provider == "povray" && counts.inf > 0)
    throw InputError(fmt::format("the 'povray' ground truth has {}{}: POV-Ray writes half floats, whose largest value "
                                 "is 65504, and the scene's lights make brighter pixels; scale the light intensities "
                                 "down, or use the full or blender provider",
                                 *bad, kept));
  if (render.provider == "full")
    throw ToolError(fmt::format("the 'full' ground truth has {}: this suite's renderer produced them; report it with "
                                "the scene",
                                *bad));
  throw ToolError(fmt::format("the '{}' ground truth ({}) has {}{}; look at the tool's output in {}", render.provider,
                              render.tool_version, *bad, kept, work_dir.string()));
}

std::filesystem::path TruthCache::image_path(const std::string& provider, const std::string& key) const {
  return dir_ / provider / (key + ".exr");
}

std::optional<TruthRender> TruthCache::load(const std::string& provider, const std::string& key) const {
  const std::filesystem::path exr = image_path(provider, key);
  std::filesystem::path meta = exr;
  meta.replace_extension(".json");
  std::error_code ec;
  if (!std::filesystem::exists(meta, ec) || !std::filesystem::exists(exr, ec)) return std::nullopt;
  try {
    const json j = io::parse_json(io::read_file(meta));
    TruthRender r;
    r.right = rgb_plane_only(io::read_exr(exr));
    if (hash_image(r.right) != j.at("image_sha256").get<std::string>()) return std::nullopt;
    // An entry made for another request (copied or renamed by hand) is no answer to this one.
    if (j.at("key").get<std::string>() != key || j.at("provider").get<std::string>() != provider ||
        unusable_samples(r.right))
      return std::nullopt;
    r.provider = j.at("provider").get<std::string>();
    r.tool_version = j.at("tool_version").get<std::string>();
    r.settings = j.at("settings");
    r.command = j.at("command").get<std::string>();
    r.seconds = j.at("seconds").get<double>();
    return r;
  } catch (const Error&) {
    return std::nullopt;  // unreadable entry: render again and overwrite it
  } catch (const io::JsonTextError&) {
    return std::nullopt;
  } catch (const json::exception&) {
    return std::nullopt;
  }
}

void TruthCache::prepare(const std::string& provider, const std::string& key) const {
  const std::filesystem::path folder = dir_ / provider;
  if (const auto why = io::unwritable_folder(folder))
    throw IoError(
        fmt::format("the ground-truth cache {} cannot hold {} renders: {}: {}; give --cache a folder you "
                    "can write, or --cache '' to render without it",
                    dir_.string(), provider, folder.string(), *why));
  std::filesystem::path meta = image_path(provider, key);
  meta.replace_extension(".json");
  for (const std::filesystem::path& entry : {image_path(provider, key), meta}) {
    std::error_code ec;
    if (std::filesystem::is_directory(entry, ec))
      throw IoError(fmt::format("the ground-truth cache {} cannot store this render: {} is a folder; remove it, or "
                                "give --cache another folder (--cache '' renders without it)",
                                dir_.string(), entry.string()));
  }
}

void TruthCache::store(const std::string& key, const TruthRender& render) const {
  const std::filesystem::path exr = image_path(render.provider, key);
  std::filesystem::path meta = exr;
  meta.replace_extension(".json");
  const Image rgb = rgb_plane_only(render.right);
  io::write_exr(exr, rgb);
  const json j = {{"provider", render.provider}, {"tool_version", render.tool_version},
                  {"settings", render.settings},  {"command", render.command},
                  {"seconds", render.seconds},    {"image_sha256", hash_image(rgb)},
                  {"key", key}};
  try {
    io::write_text_atomically(meta, io::json_text(j, 2) + "\n");
  } catch (const Error&) {
    std::error_code ec;
    std::filesystem::remove(exr, ec);  // an image without its record is no entry, only used space
    throw;
  }
}

ResolvedTruth resolve_truth(const TruthProvider& provider, const TruthRequest& request, const TruthCache* cache) {
  if (auto why = provider.unavailable_reason())
    throw ToolError(fmt::format("ground-truth provider '{}' is unavailable: {}", provider.name(), *why));
  // Before the cache: an entry an older provider rendered of a scene it now refuses is not served.
  provider.check_scene(request.scene.scene(), request.scene_file);
  note_single_sided(request.scene.scene(), provider.name());
  note_textured(request.scene.scene(), provider.name());
  ResolvedTruth out;
  const bool use_cache = cache != nullptr && provider.name() != "full";
  // A hit's command names the work folder of the run that rendered it; where asked, the export is
  // made ready in this request's folder (under its lock: another run may be rendering there) and
  // the command is that folder's.
  const auto served = [&](TruthRender hit, bool locked) {
    out.render = std::move(hit);
    out.cached = true;
    if (request.prepare_on_cache_hit) {
      std::optional<WorkFolderLock> lock;
      if (!locked) lock.emplace(request.work_dir, provider.name());
      if (auto command = provider.prepare(request)) out.render.command = *command;
    }
    return std::move(out);
  };
  if (use_cache) {
    out.key = truth_key(provider, request);
    if (auto hit = cache->load(provider.name(), out.key)) return served(std::move(*hit), false);
  }
  if (use_cache) cache->prepare(provider.name(), out.key);
  // Two runs may share a work folder (two validations into one --out): the second waits for the
  // first's render there, and may then find it in the cache.
  const WorkFolderLock lock(request.work_dir, provider.name());
  if (use_cache && lock.waited())
    if (auto hit = cache->load(provider.name(), out.key)) return served(std::move(*hit), true);
  out.render = provider.render(request);
  // A radiance no renderer gives is never stored for later runs.
  check_truth_samples(out.render, request.work_dir, use_cache);
  if (use_cache) {
    // The cache only saves later renders: this run has its truth, so one that cannot be kept (a
    // full disk) is said and the run goes on.
    try {
      cache->store(out.key, out.render);
    } catch (const Error& e) {
      print_warning(fmt::format(
                 "the {} render is not kept in the ground-truth cache: {}; this run goes on "
                 "without storing it (make room there, or give --cache '' to render without the cache)",
                 provider.name(), e.what()));
    }
  }
  return out;
}

}  // namespace sb::validation
