// Output files of a render run.
#include "renderer/io/render_output.hpp"

#include <algorithm>
#include <array>
#include <filesystem>
#include <string_view>

#include <fmt/format.h>

#include "renderer/embree/ray_scene.hpp"
#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/gltf_loader.hpp"
#include "renderer/io/image_io.hpp"
#include "renderer/io/json_text.hpp"
#include "renderer/stereo_output.hpp"
#include "sb_version.hpp"

namespace sb::io {

namespace fs = std::filesystem;
using nlohmann::json;

json rig_to_json(const StereoRig& rig) {
  const RigParams& p = rig.params();
  return {{"width", p.width},           {"height", p.height},       {"vfov_deg", radians_to_degrees(p.vfov)},
          {"interaxial_m", p.interaxial}, {"convergence_m", p.convergence}, {"focal_px", rig.focal_px()},
          {"max_disparity_px", rig.max_disparity_px()}, {"znear", p.znear}, {"zfar", p.zfar}};
}

json versions_json() {
  return {{"stereobench", SB_VERSION_STRING},
          {"embree", RayScene::version()},
          {"openimageio", oiio_version()},
          {"gltf", gltf_loader_version()}};
}

json timings_to_json(const Timings& timings) {
  json out = json::object();
  for (const StageTime& s : timings.stages()) out[s.name] = s.seconds;
  return out;
}

json stage_eyes_to_json(const Timings& timings) {
  json out = json::object();
  for (const StageTime& s : timings.stages()) out[s.name] = stage_eye_name(s.eye);
  return out;
}

json result_to_json(const std::string& pipeline, const RenderScene& scene, const StereoRig& rig,
                    const StereoResult& result, int threads, const PipelineOptions& options) {
  json counters = json::object();
  for (const auto& [name, value] : result.counters.snapshot()) counters[name] = value;
  return {{"pipeline", pipeline},
          {"options", options.values()},
          {"scene", {{"name", scene.scene().name}, {"path", scene.scene().path}, {"triangles", scene.scene().triangle_count()}}},
          {"rig", rig_to_json(rig)},
          {"threads", threads},
          {"timings_s", timings_to_json(result.timings)},
          {"stage_eyes", stage_eyes_to_json(result.timings)},
          {"total_s", result.timings.total()},
          {"counters", counters},
          {"bvh", {{"build_s", scene.bvh_build_seconds()}, {"memory_bytes", scene.rays().memory_bytes()}}},
          {"versions", versions_json()}};
}

json holes_to_json(const HoleAnalysis& a) {
  return {{"not_reprojected_pixels", a.scores.hole_pixels},
          {"true_disocclusions", a.truth.count()},
          {"outside_frustum", a.truth.outside_frustum},
          {"hidden", a.truth.hidden},
          {"true_positives", a.scores.true_positives},
          {"recall", a.scores.recall},
          {"precision", a.scores.precision},
          {"analysis_s", a.seconds}};
}

namespace {

/// A stereo image a render can write: its name (in --stereo, and its file <stem>_<name>.png), the
/// StereoViews flag that asks for it, where RenderFiles keeps its path, and how it is made.
struct StereoView {
  std::string_view name;
  bool StereoViews::*asked;
  std::optional<fs::path> RenderFiles::*file;
  Image (*make)(const Image& left, const Image& right);
};

const StereoView kStereoViews[] = {
    {"anaglyph", &StereoViews::anaglyph, &RenderFiles::anaglyph_png, &anaglyph_dubois},
    {"sbs", &StereoViews::side_by_side, &RenderFiles::side_by_side_png, &side_by_side},
    {"ou", &StereoViews::over_under, &RenderFiles::over_under_png, &over_under},
};

}  // namespace

StereoViews StereoViews::from_names(const std::vector<std::string>& names, const std::string& option) {
  StereoViews v{false, false, false};
  if (names.size() == 1 && names.front() == "none") return v;
  for (const std::string& name : names) {
    if (name == "none")
      throw InputError(fmt::format("{} none: 'none' writes no stereo image and stands alone; drop it or the other "
                                   "names",
                                   option));
    const auto view = std::find_if(std::begin(kStereoViews), std::end(kStereoViews),
                                   [&](const StereoView& s) { return s.name == name; });
    if (view == std::end(kStereoViews))
      throw InputError(fmt::format("{} {}: not a stereo image; give anaglyph (Dubois red-cyan), sbs (side by side), "
                                   "ou (over/under), several of them comma-separated, or none",
                                   option, name));
    if (v.*view->asked)
      throw InputError(fmt::format("{}: '{}' is named twice; name each stereo image once", option, name));
    v.*view->asked = true;
  }
  return v;
}

std::vector<std::filesystem::path> RenderFiles::all() const {
  std::vector<std::filesystem::path> files{exr, left_png, right_png};
  for (const StereoView& view : kStereoViews)
    if (this->*view.file) files.push_back(*(this->*view.file));
  if (holes_png) files.push_back(*holes_png);
  files.insert(files.end(), extras.begin(), extras.end());
  files.push_back(stats_json);
  return files;
}

namespace {

/// InputError unless every extra's name makes a file name of its own beside the standard outputs.
void check_extra_names(const StereoResult& result) {
  static constexpr std::array<std::string_view, 7> reserved = {"left",  "right", "anaglyph", "sbs",
                                                                "ou",    "stats", "holes"};
  for (size_t i = 0; i < result.extras.size(); ++i) {
    const std::string& name = result.extras[i].first;
    const bool valid = !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
      return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
    });
    if (!valid || std::find(reserved.begin(), reserved.end(), name) != reserved.end())
      throw InputError(fmt::format("a pipeline returned a diagnostic image named '{}'; names must be lowercase "
                                   "letters, digits and '_', and not one of left, right, anaglyph, sbs, ou, stats, holes",
                                   name));
    for (size_t k = 0; k < i; ++k)
      if (result.extras[k].first == name)
        throw InputError(fmt::format("a pipeline returned two diagnostic images named '{}'", name));
  }
}

/// The file names an earlier render's stats JSON lists for its set (see write_render_outputs):
/// only plain names of this stem's outputs, so that a damaged or edited file cannot name another.
std::vector<std::string> earlier_files(const fs::path& stats_json, const std::string& stem) {
  std::vector<std::string> out;
  std::error_code ec;
  if (!fs::is_regular_file(stats_json, ec)) return out;
  try {
    const json j = parse_json(read_file(stats_json));
    if (!j.is_object() || !j.contains("files") || !j["files"].is_array()) return out;
    for (const json& name : j["files"])
      if (name.is_string()) {
        const std::string n = name.get<std::string>();
        if (n.starts_with(stem + "_") && n.find('/') == std::string::npos && n.ends_with(".png")) out.push_back(n);
      }
  } catch (const std::exception&) {
  }
  return out;
}

}  // namespace

RenderFiles render_file_names(const std::filesystem::path& dir, const std::string& stem, const StereoViews& views) {
  RenderFiles f;
  f.exr = dir / (stem + ".exr");
  f.left_png = dir / (stem + "_left.png");
  f.right_png = dir / (stem + "_right.png");
  for (const StereoView& view : kStereoViews)
    if (views.*view.asked) f.*view.file = dir / (stem + "_" + std::string(view.name) + ".png");
  f.holes_png = dir / (stem + "_holes.png");
  f.stats_json = dir / (stem + "_stats.json");
  return f;
}

void check_no_folder_at(const std::vector<fs::path>& files, const std::string& where) {
  for (const fs::path& file : files) {
    std::error_code ec;
    if (fs::is_directory(file, ec))
      throw IoError(fmt::format("cannot write {}: a folder of that name is in the way; remove it or {}",
                                file.string(), where));
  }
}

RenderFiles write_render_outputs(const std::filesystem::path& dir, const std::string& stem,
                                 const StereoResult& result, const json& record, const Image* holes_overlay,
                                 const StereoViews& views, const Executor& executor) {
  check_extra_names(result);
  RenderFiles f = render_file_names(dir, stem, views);
  if (!holes_overlay) f.holes_png.reset();
  for (const auto& [name, image] : result.extras) f.extras.push_back(dir / (stem + "_" + name + ".png"));
  check_no_folder_at(f.all(), "write to another folder");
  // Every file is made whole under its temporary name first, and only then are all renamed into
  // place, the stats JSON last (it marks a complete set): a failure on the way (a full disk) leaves
  // an earlier render's set as it was. The earlier stats JSON goes before the first rename, so
  // that a run stopped among the renames leaves no mixed set looking complete.
  std::vector<std::pair<fs::path, const Image*>> pngs{{f.left_png, &result.left}, {f.right_png, &result.right}};
  std::vector<Image> views_made;
  views_made.reserve(std::size(kStereoViews));  // the pointers into it stay valid
  for (const StereoView& view : kStereoViews)
    if (f.*view.file) pngs.emplace_back(*(f.*view.file), &views_made.emplace_back(view.make(result.left, result.right)));
  if (holes_overlay) pngs.emplace_back(*f.holes_png, holes_overlay);
  for (size_t k = 0; k < result.extras.size(); ++k) pngs.emplace_back(f.extras[k], &result.extras[k].second);
  // The set's file names go into the stats JSON: the next render of this stem removes those of
  // this set it does not write again (a diagnostic image an option asked for).
  json stats = record;
  std::vector<std::string> names;
  for (const fs::path& file : f.all()) names.push_back(file.filename().string());
  stats["files"] = names;
  const std::vector<std::string> earlier = earlier_files(f.stats_json, stem);
  // The EXR's header holds the stats JSON's content, its file list included.
  ImageMetadata meta;
  meta["stereobench/record"] = json_text(stats);  // a scene path need not be UTF-8

  // The EXR and the PNGs are encoded side by side (most of a large render's writing is their
  // compression); the set removes what a failure leaves.
  std::vector<FileWriter> writers{
      {f.exr, [&](const fs::path& tmp) { write_exr_stereo(tmp, result.left, result.right, meta); }}};
  for (const auto& [file, image] : pngs)
    writers.push_back({file, [image = image](const fs::path& tmp) { write_png_preview(tmp, *image); }});
  StagedFiles set;
  set.add_side_by_side(writers, executor);
  set.add(f.stats_json, [&](const fs::path& tmp) { write_text_atomically(tmp, json_text(stats, 2) + "\n"); });
  for (const std::string& name : earlier)
    if (std::find(names.begin(), names.end(), name) == names.end()) set.retire(dir / name);
  set.commit();  // the stats JSON, added last, is the set's marker
  return f;
}

}  // namespace sb::io
