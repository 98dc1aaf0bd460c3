// The local executor of sweeps: cells validated and timed by parallel workers, one results line
// each.
#include "validation/sweep_run.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <exception>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "renderer/animation.hpp"
#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/file_lock.hpp"
#include "renderer/io/gltf_loader.hpp"
#include "renderer/io/json_text.hpp"
#include "renderer/io/render_output.hpp"
#include "renderer/parallel.hpp"
#include "renderer/pipeline.hpp"
#include "renderer/text.hpp"
#include "scenes/catalog.hpp"
#include "validation/benchmark.hpp"
#include "validation/content_hash.hpp"
#include "validation/path_run.hpp"
#include "validation/results_file.hpp"
#include "validation/truth.hpp"
#include "validation/truth_cache.hpp"
#include "validation/validate.hpp"
#include "validation/validation_images.hpp"

namespace sb::validation {

namespace fs = std::filesystem;
using nlohmann::json;

Shard parse_shard(const std::string& text) {
  const size_t slash = text.find('/');
  Shard s;
  bool ok = slash != std::string::npos && slash > 0 && slash + 1 < text.size() &&
            text.find_first_not_of("0123456789/") == std::string::npos && text.find('/', slash + 1) == std::string::npos;
  if (ok) {
    try {
      s.index = std::stoul(text.substr(0, slash));
      s.count = std::stoul(text.substr(slash + 1));
    } catch (const std::exception&) {
      ok = false;
    }
  }
  if (!ok || s.count == 0 || s.index >= s.count)
    throw InputError(fmt::format("--shard '{}' is not I/N with 0 <= I < N (e.g. 0/4 for the first of four shards)", text));
  return s;
}

std::string cell_dir_name(size_t index, size_t cell_count) {
  const size_t digits = std::max<size_t>(4, fmt::format("{}", cell_count > 0 ? cell_count - 1 : 0).size());
  return fmt::format("{:0{}}", index, digits);
}

int threads_per_cell(const SweepRunOptions& options) {
  if (options.threads > 0) return options.threads;
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return std::max(1, cores / std::max(1, options.jobs));
}

std::vector<size_t> shard_cells(size_t cell_count, const Shard& shard) {
  std::vector<size_t> out;
  // Stops before a step past the end, which a count near SIZE_MAX would wrap round to cell 0.
  for (size_t i = shard.index; i < cell_count; i += shard.count) {
    out.push_back(i);
    if (cell_count - i <= shard.count) break;
  }
  return out;
}

std::optional<std::string> why_not_resumable(const SweepDefinition& definition, size_t cell_count,
                                             const json& first) {
  const std::string sweep = first["sweep"], sha = first.value("definition_sha256", "");
  if (sweep != definition.name && sha == definition.sha256)
    return fmt::format("they are cells of sweep '{}', and this definition ({}) has the same content but is named '{}' "
                       "(without sweep.name a sweep is named by its file): resume with the definition under its "
                       "first name, {}.toml",
                       sweep, definition.file.string(), definition.name, sweep);
  if (sweep != definition.name || sha != definition.sha256)
    return fmt::format("they are cells of sweep '{}' (definition sha256 {}), not of this definition '{}' ({}, sha256 "
                       "{}): the definition changed since those cells ran",
                       sweep, sha.substr(0, 12), definition.name, definition.file.string(),
                       definition.sha256.substr(0, 12));
  const std::vector<std::string> recorded = recorded_pipelines(first);
  if (recorded != definition.pipelines)
    return fmt::format("those cells validate the pipelines {}, but this build runs {} for {}: the pipelines this "
                       "build registers differ from those of the build that ran them (a definition listing \"all\" "
                       "follows the build), and every cell of a results file validates the same pipelines",
                       fmt::join(recorded, ", "), fmt::join(definition.pipelines, ", "), definition.file.string());
  if (first.value("baseline", "") != definition.baseline)
    return fmt::format("those cells were timed against the baseline '{}', but this build takes '{}' for {}",
                       first.value("baseline", "?"), definition.baseline, definition.file.string());
  if (!first.contains("cell_count"))
    return "those cells predate the cell_count the lines now record (an older version wrote them), and every line "
           "of a results file records the same";
  if (first["cell_count"] != json(cell_count))
    return fmt::format("those cells belong to a sweep of {} cells, but {} expands to {} cells in this build",
                       first["cell_count"].dump(), definition.file.string(), cell_count);
  return std::nullopt;
}

SweepPlan plan_sweep(const SweepDefinition& definition, const fs::path& results, const Shard& shard) {
  SweepPlan plan;
  plan.cells = expand_cells(definition);
  ResultsFile existing = read_results(results);
  plan.warnings = std::move(existing.warnings);
  std::set<std::string> known, done;
  for (const SweepCell& c : plan.cells) known.insert(c.id);
  // read_results holds a file to one definition, so its first line speaks for all.
  if (!existing.cells.empty())
    if (const auto why = why_not_resumable(definition, plan.cells.size(), existing.cells.front()))
      throw InputError(fmt::format("{} holds cells that this run cannot join: {}; give another --out, or delete the "
                                   "sweep's output folder (and this file, where --results put it elsewhere) to start "
                                   "over",
                                   results.string(), *why));
  for (const json& line : existing.cells) {
    const std::string id = line["cell_id"];
    if (!known.count(id))
      throw InputError(fmt::format("{}: cell '{}' is not a cell of {}", results.string(), id, definition.file.string()));
    done.insert(id);
  }
  for (const size_t i : shard_cells(plan.cells.size(), shard)) {
    ++plan.in_shard;
    if (done.count(plan.cells[i].id))
      ++plan.finished;
    else
      plan.todo.push_back(plan.cells[i].index);
  }
  return plan;
}

namespace {

std::string host_name() {
  char buf[256] = {};
  if (::gethostname(buf, sizeof buf - 1) != 0) return "unknown";
  return buf;
}

fs::path scene_file(const SweepScene& scene, const fs::path& scenes_dir) {
  return scene.builtin ? scenes::resolve_builtin(scene.name, scene.params, scenes_dir) : scene.file;
}

/// The rig a cell asks of its scene.
RigOverrides cell_overrides(const SweepCell& cell) {
  RigOverrides overrides;
  overrides.interaxial = cell.interaxial_m;
  overrides.max_disparity_px = cell.max_disparity_px;
  overrides.convergence = cell.convergence_m;
  if (cell.resolution) {
    overrides.width = cell.resolution->width;
    overrides.height = cell.resolution->height;
  }
  return overrides;
}

/// How a frame cell's scene reached its frame: the animation and BVH update, timed.
struct FrameUpdate {
  double animate_s = 0.0;
  double bvh_update_s = 0.0;
  std::string bvh;  ///< "build" (prepared anew at this frame), "refit", "rebuild" or "static"
};

/// How many of a scene's `in_file` lights a cell keeps: its light count, capped at the scene's (a
/// count above the scene's keeps all of its lights, and the record says how many), or all of them.
size_t kept_lights(std::optional<int> lights, size_t in_file) {
  return lights ? std::min(static_cast<size_t>(*lights), in_file) : in_file;
}

/// The prepared scene of the worker's current cell, kept while consecutive cells share the file
/// and light count (cells are ordered scene first), so loading and the BVH build happen once.
/// With a path, the kept scene is animated from whatever frame it shows to the cell's frame and
/// its BVH refit or rebuilt; frame k is always frame 0 turned by k steps (SceneAnimator), so the
/// geometry does not depend on the order frames run in.
class SceneCache {
 public:
  struct Entry {
    const RenderScene& prepared;
    fs::path file;
    std::string content_sha256;  ///< hash_scene of the file as loaded (every light, at rest)
    size_t lights_in_file;
    const SceneAnimator* animator;  ///< set with a path
    std::optional<FrameUpdate> update;  ///< set with a path
  };

  Entry get(const fs::path& file, std::optional<int> lights, const std::optional<PathSpec>& path, bool refit,
            std::optional<int> frame) {
    if (!loaded_ || file != file_) {
      reset();
      loaded_ = std::make_unique<Scene>(io::load_gltf(file));
      content_sha256_ = hash_scene(*loaded_);
      if (warned_.insert(file).second)  // once per file, however often the cells switch scenes
        print_warnings(loaded_->warnings);
      file_ = file;
    }
    const size_t keep = kept_lights(lights, loaded_->lights.size());
    const bool animated = path.has_value() && frame.has_value();
    const bool reusable = prepared_ && used_->lights.size() == keep && animated == (animator_ != nullptr) &&
                          (!animated || refit == refit_);
    std::optional<FrameUpdate> update;
    if (!reusable) {
      reset();
      used_ = std::make_unique<Scene>(*loaded_);
      used_->lights.resize(keep);
      if (animated) {
        refit_ = refit;
        const auto t0 = std::chrono::steady_clock::now();
        animator_ = std::make_unique<SceneAnimator>(*used_, *path);
        animator_->apply(*frame);
        const double animate_s = seconds_since(t0);
        prepared_ = std::make_unique<RenderScene>(*used_, refit && animator_->moves_geometry());
        update = FrameUpdate{animate_s, prepared_->bvh_build_seconds(), "build"};
      } else {
        prepared_ = std::make_unique<RenderScene>(*used_);
      }
    } else if (animated) {
      const auto t0 = std::chrono::steady_clock::now();
      animator_->apply(*frame);
      const double animate_s = seconds_since(t0);
      if (animator_->moves_geometry())
        update = FrameUpdate{animate_s, prepared_->update_geometry(animator_->moving_mesh_indices()),
                             refit ? "refit" : "rebuild"};
      else
        update = FrameUpdate{animate_s, 0.0, "static"};
    }
    return {*prepared_, file_, content_sha256_, loaded_->lights.size(), animator_.get(), update};
  }

 private:
  static double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  void reset() {
    prepared_.reset();
    animator_.reset();
    used_.reset();
  }

  fs::path file_;
  std::string content_sha256_;
  std::set<fs::path> warned_;  ///< files whose loader warnings were printed
  bool refit_ = true;
  std::unique_ptr<Scene> loaded_;
  std::unique_ptr<Scene> used_;
  std::unique_ptr<SceneAnimator> animator_;
  std::unique_ptr<RenderScene> prepared_;
};

/// `path` (written under `dir`) as a path relative to the results file's folder.
std::string relative_to(const fs::path& path, const fs::path& base) {
  return fs::absolute(path).lexically_normal().lexically_relative(fs::absolute(base).lexically_normal()).generic_string();
}

json relative_images(const json& files, const fs::path& base) {
  json out = json::object();
  for (const auto& [name, path] : files.items()) out[name] = relative_to(path.get<std::string>(), base);
  return out;
}

json timing_json(const PipelineBench& b, const BenchResult& r, int warmup) {
  const Summary total = summarize(b.total_seconds);
  const std::optional<Summary> share = b.right_over_left();
  json stages = json::object();
  for (const std::string& stage : b.stage_order) stages[stage] = summarize(b.stage_seconds.at(stage)).median;
  return {{"repetitions", r.repetitions},   {"warmup", warmup},
          {"median_s", total.median},       {"min_s", total.min},
          {"max_s", total.max},             {"samples_s", b.total_seconds},
          {"stages_median_s", stages},      {"speedup_median", b.speedup.median},
          {"speedup_min", b.speedup.min},   {"speedup_max", b.speedup.max},
          {"eyes_median_s",
           {{"left", summarize(b.left_seconds).median},
            {"right", summarize(b.right_seconds).median},
            {"both", summarize(b.both_seconds).median}}},
          {"right_over_left_median",
           share ? json(share->median) : json(nullptr)}};
}

/// The timing of a cell: the definition's pipelines, baseline, repetitions and options.
BenchConfig bench_config(const SweepDefinition& d) {
  BenchConfig bench;
  bench.pipelines = d.pipelines;
  bench.baseline = d.baseline;
  bench.warmup = d.warmup;
  bench.repetitions = d.repetitions;
  bench.options = d.options;
  return bench;
}

/// Validates and times every pipeline of the definition in one cell; returns its results line.
json run_cell(const SweepDefinition& d, const SweepCell& cell, size_t cell_count, const SweepRunOptions& options,
              SceneCache& scenes_cache, const Executor& executor) {
  const auto start = std::chrono::steady_clock::now();
  const std::string started = utc_now();
  const fs::path file = scene_file(cell.scene, options.scenes_dir);
  const SceneCache::Entry scene = scenes_cache.get(file, cell.lights, d.path, d.path_refit, cell.frame);

  const StereoRig resolved = resolve_rig(scene.prepared.scene(), cell_overrides(cell));
  // On a path the centre camera stands where the path puts it at this frame.
  const StereoRig rig = scene.animator ? StereoRig(scene.animator->camera_at(*cell.frame, resolved.pose()), resolved.params())
                                       : resolved;

  const std::string dir_name = cell_dir_name(cell.index, cell_count);
  const fs::path results_dir = options.results.has_parent_path() ? options.results.parent_path() : fs::path(".");
  const fs::path cell_dir = options.out_dir / "cells" / dir_name;
  const std::unique_ptr<TruthProvider> provider = make_truth_provider(cell.truth);
  const std::optional<TruthCache> cache =
      options.truth_cache ? std::optional<TruthCache>(TruthCache(*options.truth_cache)) : std::nullopt;
  const ValidationTarget target = prepare_target(scene.prepared, file, rig, *provider, cache ? &*cache : nullptr,
                                                 options.out_dir / "work" / dir_name / cell.truth, executor);
  // What makes this cell's truth differ from the scene, or blind to errors (over-exposed), as
  // validate says it.
  for (const std::string& w : truth_warnings(target.truth.render))
    print_warnings({fmt::format("cell {} ({}): {}", cell.index, cell_id(cell), w)});

  // Quality: each pipeline rendered once and measured.
  const ImageFileOptions image_options{d.exr};
  json images = nullptr, target_images = json::object();
  if (d.images) {
    target_images =
        relative_images(write_target_images(cell_dir, "scene", target, executor, image_options), results_dir);
    images = {{"dir", relative_to(cell_dir, results_dir)},
              {"truth_png", target_images["truth_png"]},
              {"disocclusions_png", target_images["true_disocclusions_png"]},
              {"pipelines", json::object()}};
    if (target_images.contains("truth_exr")) images["truth_exr"] = target_images["truth_exr"];
  }
  // The timing run's configuration; each pipeline is measured with the options it is timed with.
  const BenchConfig bench = bench_config(d);
  json pipelines = json::object();
  for (const BenchEntry& entry : bench.entries()) {
    const std::string& name = entry.entry.name;
    const PipelineValidation v = validate_pipeline(target, entry.entry, entry.options, executor);
    const std::string stem = entry_file_stem(name);
    json record_images = json::object();
    if (d.images) {
      const json files =
          relative_images(write_pipeline_images(cell_dir, stem, target, v, executor, image_options), results_dir);
      images["pipelines"][name] = files;
      record_images = files;
      record_images.update(target_images);
      // The cell's left eye: the baseline's, or plain-rt's where the baseline synthesized part of it.
      if (name == d.baseline) images["left_png"] = relative_to(write_left_image(cell_dir, stem, target, v), results_dir);
    }
    pipelines[name]["validation"] = validation_record(target, v, executor.threads(), record_images);
  }

  // Time: every pipeline side by side, speed-ups against the baseline paired per repetition.
  const BenchResult timed = run_bench(scene.prepared, rig, bench, executor);
  for (const PipelineBench& b : timed.pipelines) pipelines[b.name]["timing"] = timing_json(b, timed, d.warmup);

  const Scene& s = scene.prepared.scene();
  json animation = nullptr;
  if (scene.update)
    animation = {{"frame", *cell.frame},
                 {"frames", d.path->frames},
                 {"bvh", scene.update->bvh},
                 {"bvh_update_s", scene.update->bvh_update_s},
                 {"animate_s", scene.update->animate_s},
                 {"turning_meshes", scene.animator->turning_meshes()},
                 {"moving_lights", scene.animator->moving_lights()},
                 {"gltf_clip", d.path->gltf_clip.empty() ? json(nullptr) : json(d.path->gltf_clip)},
                 {"animation_time_s", d.path->gltf_animation ? json(scene.animator->time_of(*cell.frame)) : json(nullptr)},
                 {"camera",
                  {{"position", {rig.pose().position.x, rig.pose().position.y, rig.pose().position.z}},
                   {"back", {rig.pose().back.x, rig.pose().back.y, rig.pose().back.z}}}}};
  return {{"kind", kSweepCellKind},
          {"schema_version", kSweepSchemaVersion},
          {"sweep", d.name},
          {"description", d.description},
          {"definition", options.definition_label},
          // Where the run was told to write, and its shard: what the gate's command to finish the
          // sweep repeats (a shard's file alone is not the sweep).
          {"out", options.out_dir.string()},
          {"shard", {{"index", options.shard.index}, {"count", options.shard.count}}},
          {"definition_sha256", d.sha256},
          {"cell_id", cell.id},
          {"cell_index", cell.index},
          {"cell_count", cell_count},
          {"cell", cell_to_json(cell)},
          {"scene",
           {{"name", s.name},
            {"file", file.string()},
            {"triangles", s.triangle_count()},
            {"lights", s.lights.size()},
            {"lights_in_file", scene.lights_in_file},
            {"bvh_build_s", scene.prepared.bvh_build_seconds()},
            {"content_sha256", scene.content_sha256}}},
          {"rig", io::rig_to_json(rig)},
          {"animation", animation},
          {"baseline", d.baseline},
          {"baseline_listed", d.baseline_listed},
          {"pipelines", pipelines},
          {"images", images},
          {"jobs", options.jobs},
          {"threads", executor.threads()},
          {"host", host_name()},
          {"started", started},
          {"finished", utc_now()},
          {"wall_s", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()},
          {"versions", io::versions_json()}};
}

/// The marker that gives an output folder to one sweep definition.
constexpr const char* kOutMarker = ".stereobench-sweep.json";

/// Shows that the output folder and the results file's folder can be written (IoError otherwise),
/// before any work; with cells to run, also the results file they are appended to.
void check_out_folders(const SweepRunOptions& options, bool cells_to_run) {
  for (const fs::path& dir : {options.out_dir, options.results.has_parent_path() ? options.results.parent_path()
                                                                                  : fs::path(".")}) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (!fs::is_directory(dir))
      throw IoError(fmt::format("cannot use {} as an output folder: {}; give --out (or --results) a folder you can "
                                "write",
                                dir.string(), ec ? ec.message() : "it exists and is not a folder"));
    if (::access(dir.c_str(), W_OK) != 0)
      throw IoError(fmt::format("cannot write into {}: {}; give --out (or --results) a folder you can write",
                                dir.string(), std::strerror(errno)));
  }
  // Checked once the folders exist: --results naming --out's folder (or one inside it) is a folder
  // only from here on.
  std::error_code ec;
  if (fs::is_directory(options.results, ec))
    throw InputError(fmt::format("--results {} is a folder; give the results file (JSON Lines), e.g. {}",
                                 options.results.string(), (options.results / "results.jsonl").string()));
  // A results file there already is appended to after the first cell: one it cannot write would
  // be found only once that cell's work is done.
  if (cells_to_run && fs::exists(options.results, ec) && ::access(options.results.c_str(), W_OK) != 0)
    throw IoError(fmt::format("cannot write the results file {}: {}; make it writable, or give another --out (or "
                              "--results)",
                              options.results.string(), std::strerror(errno)));
}

/// The sweep marker of `out_dir`: none when there is none, null when it is damaged (not an object
/// with the strings "sweep", "definition_sha256" and "definition"), else its record.
std::optional<json> read_out_marker(const fs::path& out_dir) {
  const fs::path marker = out_dir / kOutMarker;
  std::error_code ec;
  if (!fs::exists(marker, ec)) return std::nullopt;
  json theirs;
  try {
    theirs = io::parse_json(io::read_file(marker));
  } catch (const io::JsonTextError&) {
    return json();
  }
  if (!theirs.is_object() || !theirs.value("sweep", json()).is_string() ||
      !theirs.value("definition_sha256", json()).is_string() || !theirs.value("definition", json()).is_string())
    return json();
  return theirs;
}

/// Whether a marker record names this definition.
bool marks_definition(const json& theirs, const SweepDefinition& d) {
  return theirs.is_object() && theirs.value("sweep", "") == d.name && theirs.value("definition_sha256", "") == d.sha256;
}

/// Claims the output folder for this definition before any cell runs: a folder made for another
/// definition (its marker names it) is refused, since the cells' images, whose folders are named by
/// cell index, would overwrite that sweep's; the shards of one sweep share it. Called once every
/// check of the definition has passed, so that a definition refused and then fixed still finds
/// the folder its own.
void claim_out_folder(const SweepDefinition& d, const SweepRunOptions& options) {
  const fs::path marker = options.out_dir / kOutMarker;
  const json mine = {{"sweep", d.name}, {"definition_sha256", d.sha256}, {"definition", d.file.string()}};
  // Checked and written under a lock on the folder: two sweeps started together into one new folder
  // would otherwise both find no marker and both claim it.
  const io::FileLock lock = io::FileLock::acquire(options.out_dir);
  if (const std::optional<json> found = read_out_marker(options.out_dir)) {
    const json& theirs = *found;
    if (theirs.is_null())
      throw InputError(fmt::format("{} holds a damaged sweep marker {} (not the record a sweep writes), so which "
                                   "sweep's cells are there is unknown; its images could be overwritten: give another "
                                   "--out, or delete the folder to start over",
                                   options.out_dir.string(), marker.string()));
    if (marks_definition(theirs, d)) return;
    throw InputError(fmt::format(
        "{} holds the cells of sweep '{}' ({}, sha256 {}), not of this definition '{}' ({}, sha256 {}); its images "
        "would be overwritten: give another --out, or delete the folder to start over",
        options.out_dir.string(), theirs.value("sweep", "?"), theirs.value("definition", "?"),
        theirs.value("definition_sha256", "?").substr(0, 12), d.name, d.file.string(), d.sha256.substr(0, 12)));
  }
  io::write_text_atomically(marker, io::json_text(mine, 2) + "\n");
}

/// The scene content (hash_scene as recorded) each scene's finished cells of `results` were
/// measured on, by scene label: the first such cell's hash and id.
std::map<std::string, std::pair<std::string, std::string>> measured_scenes(const std::vector<SweepCell>& cells,
                                                                          const fs::path& results) {
  std::map<std::string, std::pair<std::string, std::string>> out;
  std::error_code ec;
  if (!fs::exists(results, ec)) return out;
  std::map<std::string, const SweepCell*> by_id;
  for (const SweepCell& c : cells) by_id.emplace(c.id, &c);
  for (const json& line : read_results(results).cells) {
    const auto scene = line.find("scene");
    if (scene == line.end() || !scene->is_object() || !scene->contains("content_sha256")) continue;  // older lines
    const auto cell = by_id.find(line["cell_id"].get<std::string>());
    if (cell != by_id.end() && (*scene)["content_sha256"].is_string())
      out.try_emplace(cell->second->scene.label, (*scene)["content_sha256"].get<std::string>(), cell->first);
  }
  return out;
}

/// Every cell's rig resolved against its scene, its scene checked by its ground truth's provider,
/// and a path's spin against the scene's meshes, each scene resolved (a built-in one generated)
/// and loaded once: an impossible rig (a convergence so near that the disparity exceeds any
/// image), a scene the truth cannot render (a spot light for POV-Ray) or a spin prefix that
/// matches nothing is refused before the first cell runs, naming the definition and the cell,
/// instead of stopping the sweep when that cell comes; so is a scene whose content differs from
/// the one the results file's finished cells of it were measured on.
void check_cells(const SweepDefinition& d, const std::vector<SweepCell>& cells, const std::vector<size_t>& todo,
                 const fs::path& scenes_dir, const std::map<std::string, std::unique_ptr<TruthProvider>>& providers,
                 const fs::path& results) {
  const auto measured = measured_scenes(cells, results);
  std::map<std::string, fs::path> file_of;  // by scene label
  std::map<fs::path, std::vector<size_t>> by_file;
  for (size_t i : todo) {
    const auto [at, first] = file_of.try_emplace(cells[i].scene.label);
    if (first) at->second = scene_file(cells[i].scene, scenes_dir);
    by_file[at->second].push_back(i);
  }
  const std::vector<BenchEntry> entries = bench_config(d).entries();  // as run_cell runs them
  for (const auto& [file, indices] : by_file) {
    Scene scene;
    const auto naming_cells = [&](const std::exception& e) {
      const SweepCell& first = cells[indices.front()];
      return fmt::format("{}: scene '{}' of {} cell{} (the first: cell {} '{}'): {}; fix the scene file or the "
                         "definition (no cell has run)",
                         d.file.string(), first.scene.label, indices.size(), indices.size() == 1 ? "" : "s",
                         first.index, first.id, e.what());
    };
    try {
      scene = io::load_gltf(file);
    } catch (const InputError& e) {
      throw InputError(naming_cells(e));
    } catch (const IoError& e) {
      throw IoError(naming_cells(e));
    }
    // Cells measured on this scene as it was: new cells beside them must see the same content.
    std::optional<std::string> content;
    for (size_t i : indices)
      if (const auto it = measured.find(cells[i].scene.label); it != measured.end()) {
        if (!content) content = hash_scene(scene);
        if (*content != it->second.first)
          throw InputError(fmt::format(
              "{}: cell '{}' was measured on scene '{}' with content sha256 {}, but {} now holds {}: the scene "
              "changed since those cells ran, and the results would mix the two; give another --out, or delete "
              "the results file to start over",
              results.string(), it->second.second, cells[i].scene.label, it->second.first.substr(0, 12),
              file.string(), content->substr(0, 12)));
      }
    const std::vector<Light> lights = scene.lights;
    for (size_t i : indices) {
      try {
        const StereoRig rig = resolve_rig(scene, cell_overrides(cells[i]));
        for (const BenchEntry& e : entries) e.entry.check_rig(e.options, rig);
        // The lights the cell keeps (as SceneCache::get keeps them), for the truth's check.
        scene.lights.assign(lights.begin(),
                            lights.begin() + static_cast<std::ptrdiff_t>(kept_lights(cells[i].lights, lights.size())));
        providers.at(cells[i].truth)->check_scene(scene, file);
      } catch (const InputError& e) {
        throw InputError(fmt::format("{}: cell {} '{}': {}; fix the definition (no cell has run)", d.file.string(),
                                     cells[i].index, cells[i].id, e.what()));
      }
    }
    if (d.path) {
      try {
        (void)SceneAnimator(scene, *d.path);
        std::set<std::string> truths;
        for (size_t i : indices) truths.insert(cells[i].truth);
        for (const std::string& truth : truths) check_path_truth(*providers.at(truth), scene, *d.path, file);
      } catch (const InputError& e) {
        throw InputError(fmt::format("{}: [path] on scene '{}': {}; fix the definition (no cell has run)",
                                     d.file.string(), cells[indices.front()].scene.label, e.what()));
      }
    }
  }
}

}  // namespace

bool out_folder_is_for(const SweepDefinition& definition, const fs::path& out_dir) {
  const std::optional<json> marker = read_out_marker(out_dir);
  return !marker || marks_definition(*marker, definition);
}

void prepare_sweep(const SweepDefinition& d, const std::vector<SweepCell>& cells, const std::vector<size_t>& todo,
                   const SweepRunOptions& options) {
  // One provider per truth the cells to run name, each available.
  std::map<std::string, std::unique_ptr<TruthProvider>> providers;
  for (size_t i : todo) {
    std::unique_ptr<TruthProvider>& provider = providers[cells[i].truth];
    if (provider) continue;
    provider = make_truth_provider(cells[i].truth);
    if (auto why = provider->unavailable_reason())
      throw ToolError(fmt::format("{}: truth '{}' is unavailable: {}", d.file.string(), cells[i].truth, *why));
  }
  check_out_folders(options, !todo.empty());
  check_cells(d, cells, todo, options.scenes_dir, providers, options.results);
  claim_out_folder(d, options);
}

void run_cells(const SweepDefinition& d, const std::vector<SweepCell>& cells, const std::vector<size_t>& todo,
               const SweepRunOptions& options, const std::function<void(const CellProgress&)>& progress) {
  if (options.jobs < 1) throw InputError(fmt::format("--jobs {} must be at least 1", options.jobs));
  const int threads = threads_per_cell(options);
  std::atomic<size_t> next{0};
  std::atomic<bool> stop{false};
  std::mutex report_mutex;
  size_t finished = 0;
  std::exception_ptr first_error;

  const auto worker = [&] {
    SceneCache scenes_cache;
    const Executor executor(threads);
    while (!stop) {
      const size_t k = next++;
      if (k >= todo.size()) return;
      const SweepCell& cell = cells[todo[k]];
      try {
        const auto start = std::chrono::steady_clock::now();
        const json line = run_cell(d, cell, cells.size(), options, scenes_cache, executor);
        append_result(options.results, line);
        const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const std::lock_guard<std::mutex> lock(report_mutex);
        ++finished;
        if (progress) progress(CellProgress{cell, finished, todo.size(), wall});
      } catch (...) {
        std::exception_ptr error = std::current_exception();
        try {
          std::rethrow_exception(error);
        } catch (const Error& e) {
          // Name the cell; keep the kind of error (and with it the exit code).
          error = std::make_exception_ptr(Error(e.code(), fmt::format("cell {} '{}': {}", cell.index, cell.id, e.what())));
        } catch (...) {
        }
        const std::lock_guard<std::mutex> lock(report_mutex);
        if (!first_error) first_error = error;
        stop = true;
        return;
      }
    }
  };

  const size_t workers = std::min(todo.size(), static_cast<size_t>(options.jobs));
  if (workers <= 1) {
    worker();
  } else {
    std::vector<std::thread> pool;
    for (size_t i = 0; i < workers; ++i) pool.emplace_back(worker);
    for (std::thread& t : pool) t.join();
  }
  if (first_error) std::rethrow_exception(first_error);
}

}  // namespace sb::validation
