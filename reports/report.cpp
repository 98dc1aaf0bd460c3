// The static HTML report of a sweep: the page data, the image copies and the page itself.
#include "reports/report.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/file_lock.hpp"
#include "renderer/io/image_io.hpp"
#include "renderer/io/json_text.hpp"
#include "sb_version.hpp"
#include "validation/results_file.hpp"

namespace sb::reports {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// Marks an index.html as ours, so that a later report may replace the folder's assets and images.
constexpr const char* kGenerator = "stereobench report";
/// The schema of the data embedded in the page (docs/report.md).
constexpr const char* kDataSchema = "stereobench.report 1";

/// Files the page needs from the assets folder; copied into OUT/assets/ except the template and
/// the paper numbers, which are read here.
constexpr const char* kTemplate = "report.html";
constexpr const char* kPapers = "papers.json";
constexpr const char* kCopiedAssets[] = {"report.js", "report.css", "chart.umd.min.js", "chart.js.LICENSE.md"};

/// The value at `key` or null.
json get_or_null(const json& j, const char* key) {
  if (!j.is_object()) return nullptr;
  const auto it = j.find(key);
  return it == j.end() ? json(nullptr) : *it;
}

/// The value at a path of keys or null.
json dig(const json& j, std::initializer_list<const char*> keys) {
  const json* at = &j;
  for (const char* k : keys) {
    if (!at->is_object()) return nullptr;
    const auto it = at->find(k);
    if (it == at->end()) return nullptr;
    at = &*it;
  }
  return *at;
}

/// A name safe as one path segment of a copied image, and distinct for distinct names: letters,
/// digits and '-' stay, every other byte is written "_HH" (its hex code), so that "repro-rt:x=1"
/// and "repro-rt_x_1" do not share a folder. The empty name is "_".
std::string path_segment(const std::string& name) {
  std::string s;
  for (const char c : name) {
    if (std::isalnum(static_cast<unsigned char>(c)) || c == '-')
      s += c;
    else
      s += fmt::format("_{:02X}", static_cast<unsigned char>(c));
  }
  return s.empty() ? "_" : s;
}

/// The metric subset of a region record.
json region_summary(const json& region) {
  if (!region.is_object()) return nullptr;
  return json{{"pixels", get_or_null(region, "pixels")},
              {"psnr", get_or_null(region, "psnr")},
              {"ssim", get_or_null(region, "ssim")},
              {"mse", get_or_null(region, "mse")}};
}

/// A single run's right-eye time over its left-eye time, from its stage timings and the eye each
/// stage serves; null without a left-eye stage or without the stages' eyes (older records).
json right_over_left(const json& timings, const json& eyes) {
  if (!timings.is_object() || !eyes.is_object()) return nullptr;
  double left = 0.0, right = 0.0;
  for (const auto& [stage, seconds] : timings.items()) {
    const json eye = get_or_null(eyes, stage.c_str());
    if (!seconds.is_number() || !eye.is_string()) continue;
    if (eye == "left") left += seconds.get<double>();
    if (eye == "right") right += seconds.get<double>();
  }
  return left > 0.0 ? json(right / left) : json(nullptr);
}

/// One pipeline of a cell: quality, holes, time, images.
json pipeline_summary(const json& p, const json& baseline_total) {
  const json& v = p["validation"];
  const json& m = v["metrics"];
  json out{{"psnr", m["psnr"]},
           {"ssim", m["ssim"]},
           {"mse", m["mse"]},
           {"error_fraction", m["error_fraction"]},
           {"hole_fraction", dig(v, {"holes", "hole_fraction"})},
           {"recall", dig(v, {"holes", "not_reprojected", "recall"})},
           {"precision", dig(v, {"holes", "not_reprojected", "precision"})},
           {"true_disocclusion_fraction", dig(v, {"holes", "true_disocclusions", "fraction"})}};
  // A left eye synthesized in part (bidir-warp's), measured against plain-rt's left eye; null for a
  // left eye the pipeline renders whole.
  const json left = get_or_null(v, "left_eye");
  const json left_pixels = dig(left, {"metrics", "pixels"});
  const json synthesized = get_or_null(left, "synthesized_pixels");
  out["left_psnr"] = dig(left, {"metrics", "psnr"});
  out["left_ssim"] = dig(left, {"metrics", "ssim"});
  out["left_mse"] = dig(left, {"metrics", "mse"});
  out["left_synthesized_fraction"] =
      synthesized.is_number() && left_pixels.is_number() && left_pixels.get<double>() > 0.0
          ? json(synthesized.get<double>() / left_pixels.get<double>())
          : json(nullptr);
  json regions = json::object();
  if (v.contains("regions") && v["regions"].is_object())
    for (const auto& [name, r] : v["regions"].items()) regions[name] = region_summary(r);
  out["regions"] = regions;

  // Time: the sweep's repeated measurement when present, else the validation's single run.
  const json timing = get_or_null(p, "timing");
  if (timing.is_object()) {
    out["time_s"] = get_or_null(timing, "median_s");
    out["min_s"] = get_or_null(timing, "min_s");
    out["max_s"] = get_or_null(timing, "max_s");
    out["repetitions"] = get_or_null(timing, "repetitions");
    out["speedup"] = get_or_null(timing, "speedup_median");
    out["stages_s"] = timing.contains("stages_median_s") ? timing["stages_median_s"] : get_or_null(v, "timings_s");
    out["right_over_left"] = get_or_null(timing, "right_over_left_median");
    out["timing_source"] = "median";
  } else {
    const json total = get_or_null(v, "total_s");
    out["time_s"] = total;
    out["min_s"] = total;
    out["max_s"] = total;
    out["repetitions"] = 1;
    const bool ratio = total.is_number() && baseline_total.is_number() && total.get<double>() > 0.0;
    out["speedup"] = ratio ? json(baseline_total.get<double>() / total.get<double>()) : json(nullptr);
    out["stages_s"] = get_or_null(v, "timings_s");
    out["right_over_left"] = right_over_left(out["stages_s"], get_or_null(v, "stage_eyes"));
    out["timing_source"] = "single run";
  }
  if (out["stages_s"].is_null()) out["stages_s"] = json::object();
  return out;
}

/// The distinct string values of `key` over all cells, in order of appearance.
std::vector<std::string> distinct(const ResultsFile& results, const char* key) {
  std::vector<std::string> out;
  for (const CellLine& c : results.cells) {
    const json v = get_or_null(c.json, key);
    if (!v.is_string()) continue;
    const std::string s = v.get<std::string>();
    if (std::find(out.begin(), out.end(), s) == out.end()) out.push_back(s);
  }
  return out;
}

/// A warning when the cells were measured under different `key` values (threads, jobs, versions:
/// a sweep resumed with other options or another build), each value with its cell count; their
/// times and speed-ups are then not comparable. Empty when all agree.
std::optional<std::string> mixed_conditions(const ResultsFile& results, const char* key) {
  std::vector<std::pair<std::string, size_t>> seen;
  for (const CellLine& c : results.cells) {
    const std::string v = get_or_null(c.json, key).dump();
    auto it = std::find_if(seen.begin(), seen.end(), [&v](const auto& p) { return p.first == v; });
    if (it == seen.end())
      seen.emplace_back(v, 1);
    else
      ++it->second;
  }
  if (seen.size() < 2) return std::nullopt;
  std::string values;
  for (const auto& [v, n] : seen) values += fmt::format("{}{} ({} cell{})", values.empty() ? "" : ", ", v, n, n == 1 ? "" : "s");
  return fmt::format("the cells were measured under different {}: {}; their times and speed-ups are not comparable "
                     "(a sweep resumed with other options or another build); the overview shows the first cell's",
                     key, values);
}

/// `text` with &, <, >, " escaped for HTML text and attribute values.
std::string html_escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

/// JSON safe inside <script type="application/json">: '<' only occurs inside strings there, so
/// writing it as \u003c keeps "</script>" and "<!--" out of the element without changing the value.
std::string script_json(const json& data) {
  const std::string dumped = data.dump(-1, ' ', false, json::error_handler_t::replace);
  std::string out;
  out.reserve(dumped.size());
  for (char c : dumped) {
    if (c == '<') out += "\\u003c";
    else out += c;
  }
  return out;
}

/// The template with each @@NAME@@ replaced by values[NAME] in one pass (a value is never scanned
/// again); ToolError naming the template for an unknown marker or a value never used.
std::string fill_template(const std::string& text, const std::map<std::string, std::string>& values,
                          const fs::path& template_path) {
  std::string out;
  std::set<std::string> used;
  size_t pos = 0;
  for (size_t at = text.find("@@"); at != std::string::npos; at = text.find("@@", pos)) {
    const size_t end = text.find("@@", at + 2);
    const std::string name = end == std::string::npos ? "" : text.substr(at + 2, end - at - 2);
    const auto it = values.find(name);
    if (it == values.end())
      throw ToolError(fmt::format("report template {} holds an unknown marker at byte {}; rebuild stereobench to "
                                  "restore the report assets",
                                  template_path.string(), at));
    out.append(text, pos, at - pos);
    out += it->second;
    used.insert(name);
    pos = end + 2;
  }
  out.append(text, pos, std::string::npos);
  for (const auto& [name, value] : values)
    if (!used.count(name))
      throw ToolError(fmt::format("report template {} lacks @@{}@@; rebuild stereobench to restore the report assets",
                                  template_path.string(), name));
  return out;
}

/// Written into a report folder before anything else, so that a report stopped half-way (a full
/// disk, a kill) is recognised as ours and replaced by the next run, although it has no index.
constexpr const char* kReportMarker = ".stereobench-report";

/// Whether a non-empty folder holds a stereobench report (its marker, or our index.html).
bool holds_report(const fs::path& out) {
  std::error_code ec;
  const fs::path index = out / "index.html";
  return fs::exists(out / kReportMarker, ec) ||
         (fs::exists(index, ec) &&
          io::read_file(index).find(fmt::format("content=\"{}", kGenerator)) != std::string::npos);
}

/// Where a report is written before it takes the place of the folder's earlier one: inside the
/// folder (one file system, so that taking its place is a few renames), so that a report that
/// cannot be written whole (a full disk, a kill) leaves the earlier one as it was.
constexpr const char* kStaging = ".stereobench-next";
/// The parts of a report, the index first: it goes first and comes last, so that the folder never
/// holds an index.html whose assets or images are gone.
constexpr const char* kReportParts[] = {"index.html", "assets", "images"};
/// The prefix of the names the earlier report's parts take while the new one takes their place.
constexpr const char* kEarlier = ".stereobench-earlier";
/// The prefix of the names of earlier parts that could not be removed once the new report was in
/// place; each such name is unique, so that it never stands in the way of a later report.
constexpr const char* kLeftover = ".stereobench-leftover";

/// Whether something is at `p`, a link counted as itself (not followed).
bool present(const fs::path& p) {
  std::error_code ec;
  return fs::exists(fs::symlink_status(p, ec));
}

/// The entries of `folder` whose names start with `prefix`.
std::vector<fs::path> entries_starting_with(const fs::path& folder, const std::string& prefix) {
  std::error_code ec;
  std::vector<fs::path> found;
  for (const fs::directory_entry& e : fs::directory_iterator(folder, ec))
    if (e.path().filename().string().starts_with(prefix)) found.push_back(e.path());
  return found;
}

/// Where the earlier report's part `part` waits while the new report takes its place: a name in
/// the same folder, since a folder renamed into another folder needs write permission on itself
/// (to change its "..") and one renamed in place does not.
fs::path set_aside(const fs::path& out, const char* part) { return out / fmt::format("{}-{}", kEarlier, part); }

/// Removes a set-aside earlier part once the new report is in place. One that cannot be removed
/// (its files not the user's to remove) takes a leftover name of its own, freeing the set-aside
/// name for the next report, and is warned of.
void discard_set_aside(const fs::path& out, const char* part, std::vector<std::string>& warnings) {
  const fs::path aside = set_aside(out, part);
  std::error_code ec;
  fs::remove_all(aside, ec);
  if (!ec) return;
  const std::string why = ec.message();
  fs::path leftover;
  for (int n = 1; n < 1000 && leftover.empty(); ++n) {
    const fs::path candidate = out / fmt::format("{}-{}-{}", kLeftover, part, n);
    if (present(candidate)) continue;
    fs::rename(aside, candidate, ec);
    if (!ec) leftover = candidate;
    else break;
  }
  warnings.push_back(fmt::format("cannot remove the earlier report's {}, left as {}: {}; the new report is in place; "
                                 "remove it by hand",
                                 part, (leftover.empty() ? aside : leftover).string(), why));
}

/// What a report stopped while replacing the folder's earlier one left (replace_report). Its
/// index comes last: without an index in place the new report never took the folder, and every
/// set-aside part goes back (index last, over a new part put in place before the stop); with one,
/// the set-aside parts are the replaced report's, and go. Leftovers earlier reports could not
/// remove are tried again.
void recover_set_aside(const fs::path& out, std::vector<std::string>& warnings) {
  const auto aside = [&](const char* part) { return present(set_aside(out, part)); };
  if (std::any_of(std::begin(kReportParts), std::end(kReportParts), aside) && !present(out / "index.html")) {
    for (auto it = std::rbegin(kReportParts); it != std::rend(kReportParts); ++it) {
      if (!aside(*it)) continue;
      std::error_code ec;
      fs::remove_all(out / *it, ec);
      if (!ec) fs::rename(set_aside(out, *it), out / *it, ec);
      if (ec)
        throw IoError(fmt::format("cannot put back {}, the earlier report's {} that a stopped report set aside: {}; "
                                  "move it to {} by hand",
                                  set_aside(out, *it).string(), *it, ec.message(), (out / *it).string()));
    }
  }
  for (const char* part : kReportParts)
    if (aside(part)) discard_set_aside(out, part, warnings);
  for (const fs::path& f : entries_starting_with(out, std::string(kLeftover) + "-")) {
    std::error_code ec;
    fs::remove_all(f, ec);
    if (ec)
      warnings.push_back(fmt::format("cannot remove {}, an earlier report's part left there: {}; remove it by hand",
                                     f.string(), ec.message()));
  }
}

/// Prepares the output folder: new, empty, or an earlier report (finished, or stopped before its
/// index was written), which stays in place until the new one is written whole (replace_report).
/// A folder holding anything else is refused (check_report_folder, naming it as `named`). Returns
/// the lock on the folder, held until the report is written: a second report into the folder
/// meanwhile is refused (InputError), since the two would replace each other's images and assets.
io::FileLock prepare_out_dir(const fs::path& out, const std::string& named, std::vector<std::string>& warnings) {
  check_report_folder(out, named);
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec) throw IoError(fmt::format("cannot create the report folder {}: {}", out.string(), ec.message()));
  std::optional<io::FileLock> lock = io::FileLock::try_acquire(out);
  if (!lock)
    throw InputError(fmt::format("{}: another report is being written there; wait for it to end, or give another "
                                 "folder",
                                 named));
  check_report_folder(out, named);  // again, under the lock
  // What a report stopped while it was being written left: its staging folder, or the temporary
  // index of a version that wrote the index straight into the folder.
  fs::remove_all(out / kStaging, ec);
  if (ec) throw IoError(fmt::format("cannot remove {}, left by a report that was stopped: {}",
                                    (out / kStaging).string(), ec.message()));
  for (const fs::path& f : entries_starting_with(out, ".index.html.tmp-")) fs::remove(f, ec);
  recover_set_aside(out, warnings);
  io::write_text_atomically(out / kReportMarker, fmt::format("{} {}\n", kGenerator, SB_VERSION_STRING));
  return std::move(*lock);
}

/// Whether `out` holds a part of an earlier report.
bool holds_earlier_report(const fs::path& out) {
  std::error_code ec;
  return std::any_of(std::begin(kReportParts), std::end(kReportParts),
                     [&](const char* part) { return fs::exists(out / part, ec); });
}

/// Puts the report written whole into `stage` in the place of the folder's earlier one, by renames
/// only (which neither a full disk nor a read-only part of the earlier report stops): the earlier
/// parts are set aside (index first), the new ones put in place (index last), then the earlier
/// ones removed. A rename that fails puts back what was moved, so that the earlier report stays
/// as it was (IoError saying so, or naming what could not be put back). An earlier part that
/// cannot be removed at the end (its files not the user's to remove) stays under a leftover name
/// (discard_set_aside), with a warning; the report is in place either way.
void replace_report(const fs::path& out, const fs::path& stage, std::vector<std::string>& warnings) {
  std::error_code ec;
  std::vector<const char*> aside;  // the earlier parts set aside, in order
  std::vector<const char*> placed;  // the new parts put in place, in order
  // Puts back what was moved; the problems of doing so, or none.
  const auto undo = [&]() {
    std::vector<std::string> problems;
    std::error_code undo_ec;
    for (auto p = placed.rbegin(); p != placed.rend(); ++p) {
      fs::rename(out / *p, stage / *p, undo_ec);
      if (undo_ec) problems.push_back(fmt::format("the new {} stays in {} ({})", *p, out.string(), undo_ec.message()));
    }
    for (auto p = aside.rbegin(); p != aside.rend(); ++p) {
      fs::rename(set_aside(out, *p), out / *p, undo_ec);
      if (undo_ec)
        problems.push_back(fmt::format("the earlier {} is at {} ({})", *p, set_aside(out, *p).string(),
                                       undo_ec.message()));
    }
    return problems;
  };
  const auto fail = [&](const std::string& what) {
    const std::vector<std::string> problems = undo();
    if (problems.empty())
      throw IoError(fmt::format("{}; the earlier report in {} is kept as it was", what, out.string()));
    throw IoError(fmt::format("{}; putting the earlier report back failed too: {}; move them by hand", what,
                              fmt::join(problems, "; ")));
  };
  for (const char* part : kReportParts) {
    if (!present(out / part)) continue;
    fs::rename(out / part, set_aside(out, part), ec);
    if (ec) fail(fmt::format("cannot move the earlier report's {} aside: {}", (out / part).string(), ec.message()));
    aside.push_back(part);
  }
  for (auto part = std::rbegin(kReportParts); part != std::rend(kReportParts); ++part) {
    if (!fs::exists(stage / *part, ec)) continue;  // no images copied (linked, or none named)
    fs::rename(stage / *part, out / *part, ec);
    if (ec) fail(fmt::format("cannot move the new report's {} into place: {}", (out / *part).string(), ec.message()));
    placed.push_back(*part);
  }
  io::sync_folder(out);
  for (const char* part : aside) discard_set_aside(out, part, warnings);
  fs::remove_all(stage, ec);  // empty by now
}

/// Removes the staging folder of a report that was not written whole, unless dismissed.
class StagingGuard {
 public:
  explicit StagingGuard(fs::path stage) : stage_(std::move(stage)) {}
  StagingGuard(const StagingGuard&) = delete;
  StagingGuard& operator=(const StagingGuard&) = delete;
  ~StagingGuard() {
    if (stage_.empty()) return;
    std::error_code ec;
    fs::remove_all(stage_, ec);
  }
  void dismiss() { stage_.clear(); }

 private:
  fs::path stage_;
};

/// Copies a file atomically (the destination's folders are created).
void copy_atomically(const fs::path& from, const fs::path& to) {
  const std::string bytes = io::read_file(from);
  io::write_file_atomically(
      to, std::span<const unsigned char>(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size()));
}

}  // namespace

void check_report_folder(const fs::path& out, const std::string& named) {
  std::error_code ec;
  if (fs::exists(out, ec) && !fs::is_directory(out, ec))
    throw InputError(fmt::format("{} is a file; give a folder for the report", named));
  if (fs::exists(out, ec) && !fs::is_empty(out, ec) && !holds_report(out))
    throw InputError(fmt::format("{} is not empty and holds no stereobench report; give a new or empty folder", named));
}

fs::path report_assets_dir() {
  if (const char* env = std::getenv("STEREOBENCH_REPORT_ASSETS"); env != nullptr && *env != '\0') return env;
  return SB_REPORT_ASSETS_DIR;
}

std::string paper_experiment(const std::string& sweep_name) {
  for (const char* name : {"wissmann-table2", "kim-table2", "kim-table3"})
    if (sweep_name == name) return name;
  if (sweep_name.rfind("al-hagri-", 0) == 0) return "al-hagri";
  return "";
}

json report_data(const ResultsFile& results, const std::string& title, const json& papers,
                 const std::function<std::string(const std::string&, const std::string&)>& image_path) {
  const json& first = results.cells.front().json;
  const std::string baseline = first["baseline"].get<std::string>();

  // Pipelines: the baseline first, then every other one in name order.
  std::set<std::string> names;
  for (const CellLine& c : results.cells)
    for (const auto& [name, p] : c.json["pipelines"].items()) names.insert(name);
  json pipelines = json::array({baseline});
  for (const std::string& n : names)
    if (n != baseline) pipelines.push_back(n);

  const auto image = [&image_path](const json& rel, const std::string& name) -> json {
    if (!rel.is_string() || rel.get<std::string>().empty()) return nullptr;
    const std::string p = image_path(rel.get<std::string>(), name);
    return p.empty() ? json(nullptr) : json(p);
  };

  json cells = json::array();
  double wall_total = 0.0;
  std::set<std::string> hosts;
  std::string started, finished;
  for (size_t i = 0; i < results.cells.size(); ++i) {
    const json& line = results.cells[i].json;
    const json& cell = line["cell"];
    const json& rig = line["rig"];
    const std::string folder = fmt::format("{:04d}", i);
    const json imgs = get_or_null(line, "images");
    const std::string cell_baseline = line["baseline"].get<std::string>();
    const json baseline_total = dig(line["pipelines"][cell_baseline], {"validation", "total_s"});

    json entry{{"id", line["cell_id"]},
               {"index", line["cell_index"]},
               {"line", results.cells[i].line},
               {"sweep", line["sweep"]},
               {"scene", cell["scene"]},
               {"scene_params", cell.contains("scene_params") ? cell["scene_params"] : json::object()},
               {"resolution", cell["resolution"]},
               {"width", rig["width"]},
               {"height", rig["height"]},
               {"interaxial_m", rig["interaxial_m"]},
               {"convergence_m", rig["convergence_m"]},
               {"max_disparity_px", rig["max_disparity_px"]},
               // The sweep's own interaxial axis: a disparity in pixels, or metres (null: the scene's).
               {"axis_max_disparity_px", get_or_null(cell, "max_disparity_px")},
               {"vfov_deg", get_or_null(rig, "vfov_deg")},
               {"lights", get_or_null(cell, "lights")},
               {"truth", cell["truth"]},
               {"path", get_or_null(cell, "path")},
               {"frame", get_or_null(cell, "frame")},
               {"baseline", cell_baseline},
               {"triangles", nullptr},
               {"wall_s", get_or_null(line, "wall_s")},
               {"threads", get_or_null(line, "threads")},
               {"host", get_or_null(line, "host")}};
    entry["images"] = json{{"left", image(get_or_null(imgs, "left_png"), folder + "/left.png")},
                           {"truth", image(get_or_null(imgs, "truth_png"), folder + "/truth.png")},
                           {"disocclusions", image(get_or_null(imgs, "disocclusions_png"), folder + "/disocclusions.png")}};
    if (const json tri = dig(line, {"scene", "triangles"}); tri.is_number_integer()) entry["triangles"] = tri;
    json per = json::object();
    for (const auto& [name, p] : line["pipelines"].items()) {
      json s = pipeline_summary(p, baseline_total);
      const json tri = dig(p, {"validation", "scene", "triangles"});
      if (entry["triangles"].is_null() && tri.is_number_integer()) entry["triangles"] = tri;
      const json pimgs = dig(imgs, {"pipelines", name.c_str()});
      const std::string base = folder + "/" + path_segment(name) + "/";
      s["images"] = json{{"right", image(get_or_null(pimgs, "right_png"), base + "right.png")},
                         {"diff", image(get_or_null(pimgs, "diff_png"), base + "diff.png")},
                         {"ssim", image(get_or_null(pimgs, "ssim_png"), base + "ssim.png")},
                         {"holes", image(get_or_null(pimgs, "holes_png"), base + "holes.png")}};
      // A left eye synthesized in part: the pipeline's own, and its difference to plain-rt's.
      if (pimgs.is_object() && pimgs.contains("left_png")) {
        s["images"]["left"] = image(pimgs["left_png"], base + "left.png");
        s["images"]["left_diff"] = image(get_or_null(pimgs, "left_diff_png"), base + "left_diff.png");
      }
      per[name] = std::move(s);
    }
    entry["pipelines"] = std::move(per);
    cells.push_back(std::move(entry));

    if (const json w = get_or_null(line, "wall_s"); w.is_number()) wall_total += w.get<double>();
    if (const json h = get_or_null(line, "host"); h.is_string()) hosts.insert(h.get<std::string>());
    if (const json s = get_or_null(line, "started"); s.is_string() && (started.empty() || s.get<std::string>() < started))
      started = s.get<std::string>();
    if (const json f = get_or_null(line, "finished"); f.is_string() && f.get<std::string>() > finished)
      finished = f.get<std::string>();
  }

  const std::vector<std::string> sweeps = distinct(results, "sweep");
  const std::string experiment = sweeps.size() == 1 ? paper_experiment(sweeps.front()) : "";
  json paper = nullptr;
  if (!experiment.empty() && papers.contains(experiment)) {
    paper = papers[experiment];
    paper["experiment"] = experiment;
  }
  return json{{"schema", kDataSchema},
              {"title", title},
              {"results_file", results.path.filename().string()},
              {"sweeps", sweeps},
              {"description", get_or_null(first, "description")},
              {"definition", get_or_null(first, "definition")},
              {"definition_sha256", get_or_null(first, "definition_sha256")},
              {"versions", get_or_null(first, "versions")},
              {"jobs", get_or_null(first, "jobs")},
              {"threads", get_or_null(first, "threads")},
              {"hosts", hosts},
              {"started", started.empty() ? json(nullptr) : json(started)},
              {"finished", finished.empty() ? json(nullptr) : json(finished)},
              {"cells_wall_s", wall_total},
              {"baseline", baseline},
              {"pipelines", pipelines},
              {"cells", cells},
              {"paper", paper},
              {"warnings", results.warnings}};
}

void check_report_assets(const fs::path& assets) {
  for (const char* f : {kTemplate, kPapers})
    if (!fs::exists(assets / f))
      throw ToolError(fmt::format("report asset {} is missing; rebuild stereobench (the build copies reports/assets "
                                  "into {}) or set STEREOBENCH_REPORT_ASSETS",
                                  (assets / f).string(), assets.string()));
  for (const char* f : kCopiedAssets)
    if (!fs::exists(assets / f))
      throw ToolError(fmt::format("report asset {} is missing: Chart.js comes from npm (ci/package.json); run "
                                  "`ci/install-deps.sh chromium` and rebuild stereobench",
                                  (assets / f).string()));
}

namespace {

/// Writes the report of `results` into `stage` as it will stand in `out` (write_report moves it
/// there): the copied images, the assets and the page.
ReportSummary write_report_into(const ResultsFile& results, const ReportOptions& options, const fs::path& assets,
                                const json& papers, const fs::path& out, const fs::path& stage) {
  ReportSummary summary;
  summary.warnings = results.warnings;

  // Images: copied under images/ (or linked), each checked to exist.
  // Image paths are relative to the results file itself: a link to it is followed, as the results
  // writer follows it.
  fs::path results_file = results.path;
  std::error_code resolved;
  if (fs::path real = fs::weakly_canonical(results.path, resolved); !resolved) results_file = std::move(real);
  const fs::path results_dir = results_file.has_parent_path() ? results_file.parent_path() : fs::path(".");
  // The page, which may be shared, names files by the results file's name and the paths its
  // lines give, never by this machine's folders; the terminal says where it looked.
  const std::string results_name = results.path.filename().string();
  std::vector<std::string> page_warnings;
  for (const std::string& w : summary.warnings)  // the reader's: "RESULTS:LINE: ..."
    page_warnings.push_back(w.rfind(results.path.string(), 0) == 0
                                ? results_name + w.substr(results.path.string().size())
                                : w);
  std::vector<std::pair<std::string, fs::path>> missing;  // (as the line names it, where it was looked for)
  size_t named = 0;  // images the lines name
  const auto image_path = [&](const std::string& rel, const std::string& name) -> std::string {
    ++named;
    const fs::path source = results_dir / rel;
    std::error_code ec;
    if (!fs::is_regular_file(source, ec)) {
      missing.emplace_back(rel, source);
      return "";
    }
    // Every image of a results line is a PNG the sweep wrote; anything else a path names (a
    // hand-edited line, a path into the system) is not copied into a report that may be shared.
    if (io::image_file_format(source) != "png") {
      summary.warnings.push_back(fmt::format("{}: image {} ({}) is not a PNG file; left out of the report",
                                             results.path.string(), rel, source.string()));
      page_warnings.push_back(
          fmt::format("{}: image {} is not a PNG file; left out of the report", results_name, rel));
      return "";
    }
    ++summary.images;
    if (options.images == ImageMode::link) {
      // Lexically, as a browser resolves a relative link from the page's path as given: through a
      // linked folder in --out, a path with links resolved would climb out of another folder.
      const fs::path relative =
          fs::absolute(source).lexically_normal().lexically_relative(fs::absolute(out).lexically_normal());
      if (relative.empty())
        throw IoError(fmt::format("cannot express {} relative to {}", source.string(), out.string()));
      return relative.generic_string();
    }
    copy_atomically(source, stage / "images" / name);
    return "images/" + name;
  };

  std::string title = options.title;
  if (title.empty()) {
    const std::vector<std::string> sweeps = distinct(results, "sweep");
    std::string joined;
    for (const std::string& s : sweeps) joined += (joined.empty() ? "" : ", ") + s;
    title = "stereobench report: " + joined;
  }
  json data = report_data(results, title, papers, image_path);
  // Missing images: a few named one by one, many (a results file copied without its cells/
  // folder) in one line.
  constexpr size_t kNamedMissing = 5;
  for (size_t i = 0; i < missing.size() && (missing.size() <= kNamedMissing || i < 3); ++i) {
    summary.warnings.push_back(fmt::format("{}: image {} is missing (looked for {}); the viewer shows it as "
                                           "unavailable",
                                           results.path.string(), missing[i].first, missing[i].second.string()));
    page_warnings.push_back(
        fmt::format("{}: image {} is missing; the viewer shows it as unavailable", results_name, missing[i].first));
  }
  if (missing.size() > kNamedMissing) {
    const std::string more = fmt::format("and {} more images are missing ({} of the {} the results name); was the "
                                         "results file moved without the cells/ folder beside it?",
                                         missing.size() - 3, missing.size(), named);
    summary.warnings.push_back(fmt::format("{}: {}", results.path.string(), more));
    page_warnings.push_back(fmt::format("{}: {}", results_name, more));
  }
  // A sweep still running, stopped, or one shard of several: its figures cover part of it.
  std::vector<const json*> records;
  for (const auto& c : results.cells) records.push_back(&c.json);
  if (const auto coverage = validation::cell_coverage(records); coverage && coverage->present < coverage->expected) {
    const std::string unfinished =
        fmt::format("{} of the {} cells of sweep '{}' are in the results: the sweep is unfinished (still running, "
                    "stopped, or one shard of several); the figures cover these cells only",
                    coverage->present, coverage->expected, results.cells.front().json["sweep"].get<std::string>());
    summary.warnings.push_back(fmt::format("{}: {}", results.path.string(), unfinished));
    page_warnings.push_back(fmt::format("{}: {}", results_name, unfinished));
  }
  for (const char* key : {"threads", "jobs", "versions"})
    if (const auto mixed = mixed_conditions(results, key)) {
      summary.warnings.push_back(fmt::format("{}: {}", results.path.string(), *mixed));
      page_warnings.push_back(fmt::format("{}: {}", results_name, *mixed));
    }
  // The page lists every warning the terminal shows: skipped lines, missing images, missing cells,
  // cells measured under different conditions.
  data["warnings"] = page_warnings;
  if (!options.history.is_null()) data["history"] = options.history;
  if (!options.history_note.empty()) data["history_note"] = options.history_note;
  summary.paper_experiment = data["paper"].is_object() ? data["paper"]["experiment"].get<std::string>() : "";
  summary.pipeline_names = data["pipelines"];
  summary.cells = data["cells"];

  for (const char* f : kCopiedAssets) copy_atomically(assets / f, stage / "assets" / f);

  const std::string page = fill_template(io::read_file(assets / kTemplate),
                                         {{"GENERATOR", html_escape(fmt::format("{} {}", kGenerator, SB_VERSION_STRING))},
                                          {"TITLE", html_escape(title)},
                                          {"DATA", script_json(data)}},
                                         assets / kTemplate);
  io::write_text_atomically(stage / "index.html", page);
  return summary;
}

}  // namespace

ReportSummary write_report(const ResultsFile& results, const ReportOptions& options) {
  const fs::path assets = options.assets_dir.empty() ? report_assets_dir() : options.assets_dir;
  check_report_assets(assets);
  json papers;
  try {
    papers = io::parse_json(io::read_file(assets / kPapers));
  } catch (const io::JsonTextError& e) {
    throw ToolError(fmt::format("report asset {} is not valid JSON: {}", (assets / kPapers).string(), e.what()));
  }

  const fs::path out = options.out_dir;
  std::vector<std::string> folder_warnings;
  const io::FileLock lock = prepare_out_dir(
      out, options.out_name.empty() ? fmt::format("--out {}", out.string()) : options.out_name, folder_warnings);
  const bool earlier = holds_earlier_report(out);
  // Everything is written into `stage` first and takes the earlier report's place at the end.
  const fs::path stage = out / kStaging;
  StagingGuard staging(stage);
  ReportSummary summary;
  try {
    summary = write_report_into(results, options, assets, papers, out, stage);
  } catch (const IoError& e) {
    if (!earlier) throw;
    throw IoError(fmt::format("{}; the earlier report in {} is kept as it was", e.what(), out.string()));
  }
  summary.warnings.insert(summary.warnings.begin(), folder_warnings.begin(), folder_warnings.end());
  replace_report(out, stage, summary.warnings);
  staging.dismiss();
  summary.index_html = out / "index.html";
  return summary;
}

}  // namespace sb::reports
