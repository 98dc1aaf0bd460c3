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
  return {{"hole_pixels", a.scores.hole_pixels},
          {"true_disocclusions", a.truth.count()},
          {"outside_frustum", a.truth.outside_frustum},
          {"hidden", a.truth.hidden},
          {"true_positives", a.scores.true_positives},
          {"recall", a.scores.recall},
          {"precision", a.scores.precision},
          {"analysis_s", a.seconds}};
}

std::vector<std::filesystem::path> RenderFiles::all() const {
  std::vector<std::filesystem::path> files{exr, left_png, right_png, anaglyph_png, side_by_side_png};
  if (holes_png) files.push_back(*holes_png);
  files.insert(files.end(), extras.begin(), extras.end());
  files.push_back(stats_json);
  return files;
}

namespace {

/// InputError unless every extra's name makes a file name of its own beside the standard outputs.
void check_extra_names(const StereoResult& result) {
  static constexpr std::array<std::string_view, 6> reserved = {"left", "right", "anaglyph", "sbs", "stats", "holes"};
  for (size_t i = 0; i < result.extras.size(); ++i) {
    const std::string& name = result.extras[i].first;
    const bool valid = !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
      return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
    });
    if (!valid || std::find(reserved.begin(), reserved.end(), name) != reserved.end())
      throw InputError(fmt::format("a pipeline returned a diagnostic image named '{}'; names must be lowercase "
                                   "letters, digits and '_', and not one of left, right, anaglyph, sbs, stats, holes",
                                   name));
    for (size_t k = 0; k < i; ++k)
      if (result.extras[k].first == name)
        throw InputError(fmt::format("a pipeline returned two diagnostic images named '{}'", name));
  }
}

}  // namespace

RenderFiles write_render_outputs(const std::filesystem::path& dir, const std::string& stem,
                                 const StereoResult& result, const json& record, const Image* holes_overlay) {
  check_extra_names(result);
  RenderFiles f;
  f.exr = dir / (stem + ".exr");
  f.left_png = dir / (stem + "_left.png");
  f.right_png = dir / (stem + "_right.png");
  f.anaglyph_png = dir / (stem + "_anaglyph.png");
  f.side_by_side_png = dir / (stem + "_sbs.png");
  f.stats_json = dir / (stem + "_stats.json");
  // The stats JSON, written last, marks a complete set: an earlier render's goes first, and a
  // failure on the way (a full disk) removes what this call wrote, so no set is left looking
  // complete.
  std::error_code ec;
  fs::remove(f.stats_json, ec);
  if (ec) throw IoError(fmt::format("cannot remove the earlier {}: {}", f.stats_json.string(), ec.message()));
  std::vector<fs::path> written;
  try {
    ImageMetadata meta;
    meta["stereobench/record"] = record.dump();
    write_exr_stereo(f.exr, result.left, result.right, meta);
    written.push_back(f.exr);
    const auto png = [&written](const fs::path& file, const Image& image) {
      write_png_preview(file, image);
      written.push_back(file);
    };
    png(f.left_png, result.left);
    png(f.right_png, result.right);
    png(f.anaglyph_png, anaglyph_dubois(result.left, result.right));
    png(f.side_by_side_png, side_by_side(result.left, result.right));
    if (holes_overlay) {
      f.holes_png = dir / (stem + "_holes.png");
      png(*f.holes_png, *holes_overlay);
    }
    for (const auto& [name, image] : result.extras) {
      f.extras.push_back(dir / (stem + "_" + name + ".png"));
      png(f.extras.back(), image);
    }
    write_text_atomically(f.stats_json, record.dump(2) + "\n");
  } catch (...) {
    for (const fs::path& file : written) fs::remove(file, ec);
    throw;
  }
  return f;
}

}  // namespace sb::io
