// Shared command-line options.
#include "apps/cli_common.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <optional>

#include <fmt/format.h>
#include <tbb/info.h>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/scene_geometry.hpp"
#include "renderer/stages/near_plane.hpp"
#include "scenes/catalog.hpp"

namespace sb::cli {

void RigCli::add_to(CLI::App& app) {
  auto* g = "Stereo rig (defaults come from the scene's camera)";
  app.add_option("--interaxial,-e", interaxial, "Eye separation in meters (default: the scene camera's, else 0.064)")->group(g);
  app.add_option("--max-disparity", max_disparity,
                 "Give the interaxial as the disparity at infinity in pixels, f_px*e/c")
      ->group(g)
      ->excludes("--interaxial");
  app.add_option("--convergence,-c", convergence,
                 "Zero-parallax distance in meters (default: the scene camera's extras.stereobench convergence, else "
                 "2.0; for a scene without a camera, the distance that frames it)")
      ->group(g);
  app.add_option("--resolution,-r", resolution,
                 "Image size per eye: WxH, or hd/fhd/1080p (1920x1080), 720p (1280x720), qhd (2560x1440), 4k/uhd "
                 "(3840x2160), 8k (7680x4320) (default: the scene camera's extras.stereobench width and height, the "
                 "width else from its aspectRatio; else 1920x1080)")
      ->group(g);
  app.add_option("--vfov", vfov_deg,
                 "Vertical field of view in degrees (default: the scene camera's yfov; 40 for a scene without a "
                 "camera)")
      ->group(g);
}

namespace {

double positive(double v, const char* option, const char* hint) {
  if (!std::isfinite(v) || v <= 0.0)
    throw InputError(fmt::format("{} {} is not a positive finite number; {}", option, v, hint));
  return v;
}

}  // namespace

RigOverrides RigCli::overrides() const {
  RigOverrides o;
  if (interaxial) o.interaxial = positive(*interaxial, "--interaxial", "give the eye separation in meters, e.g. 0.064");
  if (max_disparity)
    o.max_disparity_px = positive(*max_disparity, "--max-disparity", "give the disparity at infinity in pixels, e.g. 30");
  if (convergence)
    o.convergence = positive(*convergence, "--convergence", "give the zero-parallax distance in meters, e.g. 2.0");
  if (resolution) {
    ivec2 r{0, 0};
    try {
      r = parse_resolution(*resolution);
    } catch (const InputError& e) {
      // "resolution X is ..." as the option that gave it.
      const std::string what = e.what();
      throw InputError(what.rfind("resolution ", 0) == 0 ? "--" + what : "--resolution: " + what);
    }
    o.width = r.x;
    o.height = r.y;
  }
  if (vfov_deg) {
    if (!std::isfinite(*vfov_deg) || *vfov_deg <= 0.0 || *vfov_deg >= 180.0)
      throw InputError(fmt::format("--vfov {} is out of range; give degrees in (0, 180)", *vfov_deg));
    o.vfov = degrees_to_radians(*vfov_deg);
  }
  return o;
}

size_t pipeline_column(const std::vector<std::string>& names) {
  size_t width = 16;
  for (const std::string& n : names) width = std::max(width, n.size());
  return width;
}

void add_scenes_dir_option(CLI::App& app, std::string& dir) {
  dir = scenes::default_scenes_dir().string();
  app.add_option("--scenes-dir", dir, "Folder where built-in scenes are generated and cached (env STEREOBENCH_SCENES)")
      ->capture_default_str();
}

CLI::Option* add_lights_option(CLI::App& app, std::optional<int>& lights) {
  return app.add_option("--lights", lights,
                        "Keep only the scene's first N lights (in file order), e.g. for light-count sweeps "
                        "(default: all)");
}

std::string table_number(double v, int decimals, double scale) {
  if (std::isnan(v)) return "-";
  if (std::isinf(v)) return "inf";
  return fmt::format("{:.{}f}", v * scale, decimals);
}

std::string describe_lights(size_t used, size_t in_file) {
  if (used == in_file) return fmt::format("{} light{}", used, used == 1 ? "" : "s");
  return fmt::format("first {} of {} lights", used, in_file);
}

std::map<std::string, std::string> parse_key_values(const std::vector<std::string>& items, const char* option) {
  std::map<std::string, std::string> out;
  for (const std::string& item : items) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InputError(fmt::format("{} '{}' is not NAME=VALUE", option, item));
    const std::string name = item.substr(0, eq);
    if (const auto it = out.find(name); it != out.end())
      throw InputError(fmt::format("{} gives {} twice ({} and {}); give each name once", option, name, it->second,
                                   item.substr(eq + 1)));
    out[name] = item.substr(eq + 1);
  }
  return out;
}

std::vector<std::string> split_list(const std::vector<std::string>& items, const char* option) {
  std::vector<std::string> out;
  for (const std::string& item : items) {
    if (item.empty()) throw InputError(fmt::format("{} is given an empty value; give one or more names", option));
    size_t begin = 0;
    while (true) {
      const size_t comma = item.find(',', begin);
      const std::string entry = item.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin);
      if (entry.empty())
        throw InputError(fmt::format("{} '{}' has an empty entry (a doubled, leading or trailing comma); separate "
                                     "the names with single commas",
                                     option, item));
      out.push_back(entry);
      if (comma == std::string::npos) break;
      begin = comma + 1;
    }
  }
  return out;
}

int checked_threads(int threads) {
  if (threads < 0 || threads > 1024)
    throw InputError(fmt::format("--threads {} is out of range; give 0 (all cores) or 1..1024", threads));
  // The task scheduler runs at most one thread per core; more would be recorded but not run.
  const int cores = tbb::info::default_concurrency();
  if (threads > cores) {
    fmt::print(stderr, "note: --threads {} is more than the {} core{} here; using {}\n", threads, cores,
               cores == 1 ? "" : "s", cores);
    return cores;
  }
  return threads;
}

namespace {

/// The same file twice, by path or (both existing) by identity: a link or another spelling.
bool same_file(const std::string& x, const std::string& y) {
  namespace fs = std::filesystem;
  std::error_code ex, ey;
  const fs::path cx = fs::weakly_canonical(fs::absolute(x, ex), ex);
  const fs::path cy = fs::weakly_canonical(fs::absolute(y, ey), ey);
  if (!ex && !ey && cx == cy) return true;
  return fs::exists(x, ex) && fs::exists(y, ey) && fs::equivalent(x, y, ex);
}

/// Whether an option names a file that one run could overwrite: not empty, not "-" (standard
/// output), not a device or pipe (/dev/null twice is fine).
bool names_file(const NamedPath& p) {
  if (p.path->empty() || *p.path == "-") return false;
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(*p.path, ec);
  return !std::filesystem::exists(st) || std::filesystem::is_regular_file(st) || std::filesystem::is_directory(st);
}

}  // namespace

void remove_earlier_output(const std::filesystem::path& path, const std::string& what) {
  if (path.empty() || path == "-") return;
  try {
    (void)io::remove_output_file(path);
  } catch (const IoError& e) {
    throw IoError(fmt::format("{}: {}", what, e.what()));
  }
}

void remove_earlier_outputs(std::initializer_list<NamedPath> outputs) { remove_earlier_outputs_sparing({}, outputs); }

void remove_earlier_outputs_sparing(std::initializer_list<NamedPath> inputs, std::initializer_list<NamedPath> outputs) {
  std::optional<IoError> first;
  for (const NamedPath& o : outputs) {
    if (!names_file(o)) continue;
    if (std::any_of(inputs.begin(), inputs.end(),
                    [&](const NamedPath& in) { return names_file(in) && same_file(*o.path, *in.path); }))
      continue;
    try {
      remove_earlier_output(*o.path, o.name);
    } catch (const IoError& e) {
      if (!first) first = e;  // the others are still removed
    }
  }
  if (first) throw *first;
}

void write_for_option(const std::string& option, const std::function<void()>& write) {
  try {
    write();
  } catch (const IoError& e) {
    // The advice once: most messages of the writers already say what to do.
    const std::string what = e.what();
    const bool advised = what.find("; give ") != std::string::npos || what.find("; make ") != std::string::npos ||
                         what.find("; check ") != std::string::npos || what.find("; free ") != std::string::npos;
    throw IoError(advised ? fmt::format("{}: {}", option, what)
                          : fmt::format("{}: {}; give {} a path you can write", option, what, option));
  }
}

void write_option_file(const std::string& option, const std::string& path, const std::string& text) {
  write_for_option(option, [&] { io::write_text_atomically(path, text); });
}

void discard_outputs(std::initializer_list<NamedPath> outputs) noexcept {
  for (const NamedPath& o : outputs) {
    if (o.path->empty() || *o.path == "-") continue;
    try {
      (void)io::remove_output_file(*o.path);
    } catch (const std::exception&) {  // best effort: the run's own error is the one to report
    }
  }
}

void write_all_or_none(std::initializer_list<NamedPath> outputs, const std::function<void()>& write) {
  try {
    write();
  } catch (...) {
    discard_outputs(outputs);
    throw;
  }
}

void check_output_folder(const std::string& folder, const char* option) {
  if (const auto why = io::folder_cannot_be_made(folder))
    throw IoError(fmt::format("{} {}: {}; give a folder you can write", option, folder, *why));
}

void prepare_output_folder(const std::string& folder, const char* option) {
  if (const auto why = io::unwritable_folder(folder))
    throw IoError(fmt::format("{} {}: {}; give a folder you can write", option, folder, *why));
}

void refuse_replacing_inputs(const std::filesystem::path& scene_file, const Scene& scene,
                             const std::filesystem::path& out, const std::vector<std::string>& prefixes,
                             const std::string& run) {
  namespace fs = std::filesystem;
  std::error_code ec;
  for (fs::directory_iterator it(out, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (std::none_of(prefixes.begin(), prefixes.end(), [&](const std::string& p) { return name.starts_with(p); }))
      continue;
    std::error_code same;
    if (fs::equivalent(it->path(), scene_file, same))
      throw InputError(fmt::format("--scene {}: the scene file is this {}'s output {}; give another --out",
                                   scene_file.string(), run, it->path().string()));
    for (const std::string& read : scene.files_read)
      if (fs::equivalent(it->path(), read, same))
        throw InputError(fmt::format("--scene {}: the file {} the scene reads (a buffer or an image) is this {}'s "
                                     "output {}; give another --out",
                                     scene_file.string(), read, run, it->path().string()));
  }
}

void in_output_folder(const std::string& folder, const char* option, const std::function<void()>& work) {
  const std::filesystem::path made = io::outermost_missing_folder(folder);  // the outermost folder this call makes
  prepare_output_folder(folder, option);
  try {
    work();
  } catch (...) {
    io::remove_if_no_file(made);
    throw;
  }
}

void print_to(std::FILE* stream, const std::string& text) {
  errno = 0;
  const bool written = std::fwrite(text.data(), 1, text.size(), stream) == text.size();
  if (!written || std::fflush(stream) != 0 || std::ferror(stream) != 0)
    throw IoError(fmt::format("cannot write to standard {}: {}", stream == stderr ? "error" : "output",
                              errno != 0 ? std::strerror(errno) : "write error"));
}

void print_to_stdout(const std::string& text) { print_to(stdout, text + "\n"); }

void prepare_output_file_folder(const std::string& file, const char* option) {
  if (file.empty() || file == "-" || io::written_in_place(file)) return;
  const std::filesystem::path target = io::follow_links(file);
  std::error_code ec;
  if (target != std::filesystem::path(file) && !target.parent_path().empty() &&
      !std::filesystem::is_directory(target.parent_path(), ec))
    throw IoError(fmt::format("{} {}: it is a link to {}, whose folder does not exist; make that folder, or give "
                              "another path",
                              option, file, target.string()));
  const std::filesystem::path folder = std::filesystem::path(file).parent_path();
  if (folder.empty()) return;  // the current folder
  // A missing folder is made for the probe and removed again; the write makes it for good
  // (io::write_atomically), so a run refused after this check leaves no empty folder behind.
  if (const std::optional<std::string> why = io::folder_cannot_be_made(folder))
    throw IoError(
        fmt::format("{} {}: its folder {}: {}; give a path you can write", option, file, folder.string(), *why));
}

void refuse_overwriting(std::initializer_list<NamedPath> inputs, std::initializer_list<NamedPath> outputs) {
  for (auto out = outputs.begin(); out != outputs.end(); ++out) {
    if (!names_file(*out)) continue;
    for (const NamedPath& in : inputs)
      if (names_file(in) && same_file(*out->path, *in.path))
        throw InputError(fmt::format("{} {} names the same file as {} ({}); it would be overwritten: give the output "
                                     "another name",
                                     out->name, *out->path, in.name, *in.path));
    for (auto earlier = outputs.begin(); earlier != out; ++earlier)
      if (names_file(*earlier) && same_file(*out->path, *earlier->path))
        throw InputError(
            fmt::format("{} and {} both name {}; give each output its own file", earlier->name, out->name, *out->path));
  }
}

void warn_scene_far_from_origin(const RenderScene& scene) {
  const Bounds3 b = scene.scene().bounds();
  if (b.empty()) return;
  const double size = glm::length(dvec3(b.extent()));
  const double reach = std::max({std::fabs(double(b.lo.x)), std::fabs(double(b.lo.y)), std::fabs(double(b.lo.z)),
                                 std::fabs(double(b.hi.x)), std::fabs(double(b.hi.y)), std::fabs(double(b.hi.z))});
  // The shadow-ray offset follows the float resolution of the largest coordinate: beyond a
  // thousandth of the scene's size, shadows of small objects and thin detail are lost.
  const double offset = scene.ray_epsilon();
  if (!(offset > 1e-3 * size)) return;
  print_warning(fmt::format(
      "scene '{}' reaches {:g} m from the origin and is {:g} m across: positions are floats, so shadow rays start "
      "{:.3g} m off the surfaces there and small objects lose their shadows and detail; move the scene near the "
      "origin (subtract its centre, ({:g}, {:g}, {:g}) m, in the file)",
      scene.scene().name, reach, size, offset, 0.5 * (double(b.lo.x) + b.hi.x), 0.5 * (double(b.lo.y) + b.hi.y),
      0.5 * (double(b.lo.z) + b.hi.z)));
}

void warn_if_no_surface_seen(const Image& left, const Image& right, const StereoRig& rig) {
  const auto background = [](const Image& eye) {
    if (!eye.has_plane(planes::primid)) return false;
    const uint32_t* prim = eye.data_u32(planes::primid);
    return std::all_of(prim, prim + eye.pixel_count(), [](uint32_t p) { return p == kNoPrimitiveId; });
  };
  if (!background(left) || !background(right)) return;
  const RigParams& p = rig.params();
  print_warning(fmt::format(
      "neither eye sees a surface: every pixel is background. The eyes stand {:g} m either side of the centre camera "
      "(interaxial {:g} m, convergence {:g} m); for a scene of another scale give --interaxial and --convergence in "
      "its units, and check that the camera looks at the scene (`stereobench scenes info`)",
      0.5 * p.interaxial, p.interaxial, p.convergence));
}

void warn_geometry_before_near_plane(const RenderScene& scene, const StereoRig& rig, const Executor& executor) {
  const uint64_t left = pixels_before_near_plane(scene, rig.eye(Eye::left), executor);
  const uint64_t right = pixels_before_near_plane(scene, rig.eye(Eye::right), executor);
  if (left == 0 && right == 0) return;
  print_warning(fmt::format(
      "{} pixels of the left eye and {} of the right see geometry nearer than the camera's near plane (znear {:g} m): "
      "rasterizing pipelines clip it, ray tracing and the ground truths show it, so their images differ there for "
      "the camera's sake; lower the camera's znear in the scene",
      left, right, rig.params().znear));
}

}  // namespace sb::cli
