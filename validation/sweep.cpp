// Loading and expanding sweep definitions.
#include "validation/sweep.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string_view>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <toml++/toml.h>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/json_text.hpp"
#include "renderer/pipeline.hpp"
#include "renderer/rig.hpp"
#include "renderer/scene.hpp"
#include "renderer/text.hpp"
#include "scenes/catalog.hpp"
#include "scenes/generators.hpp"
#include "validation/content_hash.hpp"
#include "validation/truth.hpp"

namespace sb::validation {

namespace fs = std::filesystem;
using nlohmann::json;

std::string number_text(double value) { return fmt::format("{}", value); }

std::string scene_label(const std::string& name, const std::map<std::string, double>& params) {
  std::string label = name;
  std::string sep = ":";
  for (const auto& [key, value] : params) {
    label += sep + key + "=" + number_text(value);
    sep = ",";
  }
  return label;
}

std::string cell_id(const SweepCell& cell) {
  const std::string e = cell.max_disparity_px ? "e=" + number_text(*cell.max_disparity_px) + "px"
                        : cell.interaxial_m   ? "e=" + number_text(*cell.interaxial_m) + "m"
                                              : std::string("e=default");
  std::string id = fmt::format("{}|{}|{}|{}|{}|{}", cell.scene.label, e,
                               cell.convergence_m ? "c=" + number_text(*cell.convergence_m) + "m" : "c=default",
                               cell.resolution ? cell.resolution->label : "res=default",
                               cell.lights ? fmt::format("lights={}", *cell.lights) : "lights=all", cell.truth);
  if (cell.frame) id += fmt::format("|frame={}", *cell.frame);
  return id;
}

std::optional<std::string> cell_id_from_json(const json& cell) {
  if (!cell.is_object()) throw InputError(fmt::format("cell is {}, not an object", cell.type_name()));
  for (const char* key : {"scene", "scene_params", "interaxial_m", "max_disparity_px", "convergence_m", "lights",
                          "resolution", "truth"})
    if (!cell.contains(key)) return std::nullopt;
  const auto field = [&cell](const char* key) -> const json& { return cell.at(key); };
  const auto bad = [](const char* key, const json& v, const char* want) {
    std::string shown = v.dump();
    if (shown.size() > 40) shown = shown.substr(0, 37) + "...";
    return InputError(fmt::format("cell.{} is {}; it must be {}", key, shown, want));
  };
  // An axis the definition left to the scene is null; a value is positive and finite.
  const auto positive = [&](const char* key, std::optional<double>& out) {
    const json& v = field(key);
    if (v.is_null()) return;
    if (!v.is_number() || !(v.get<double>() > 0.0 && std::isfinite(v.get<double>())))
      throw bad(key, v, "a positive number, or null (the scene's default)");
    out = v.get<double>();
  };
  const auto text = [&](const char* key, bool nullable) -> std::optional<std::string> {
    const json& v = field(key);
    if (nullable && v.is_null()) return std::nullopt;
    if (!v.is_string() || v.get_ref<const std::string&>().empty())
      throw bad(key, v, nullable ? "a non-empty string, or null" : "a non-empty string");
    return v.get<std::string>();
  };
  SweepCell c;
  const std::string scene = *text("scene", false);
  const json& params = field("scene_params");
  if (!params.is_object()) throw bad("scene_params", params, "an object of numbers");
  std::map<std::string, double> values;
  for (const auto& [key, value] : params.items()) {
    if (!value.is_number() || !std::isfinite(value.get<double>()))
      throw InputError(fmt::format("cell.scene_params.{} is {}; it must be a finite number", key, value.dump()));
    values[key] = value.get<double>();
  }
  c.scene.label = scene_label(scene, values);
  positive("interaxial_m", c.interaxial_m);
  positive("max_disparity_px", c.max_disparity_px);
  positive("convergence_m", c.convergence_m);
  if (const json& v = field("lights"); !v.is_null()) {
    if (!v.is_number_integer() || v.get<long long>() < 1) throw bad("lights", v, "an integer of at least 1, or null (all)");
    c.lights = v.get<int>();
  }
  if (const auto it = cell.find("frame"); it != cell.end()) {
    if (!it->is_number_integer() || it->get<long long>() < 0 || it->get<long long>() > 100000)
      throw bad("frame", *it, "a frame number, 0..100000");
    c.frame = it->get<int>();
  }
  if (const std::optional<std::string> r = text("resolution", true)) c.resolution = SweepResolution{*r, 0, 0};
  c.truth = *text("truth", false);
  return cell_id(c);
}

namespace {

/// Reports problems at a place in the definition: "<file>:<line>: <key path>: <what>".
class Where {
 public:
  explicit Where(fs::path file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const toml::source_region& at, const std::string& key_path, const std::string& what) const {
    throw InputError(fmt::format("{}:{}: {}: {}", file_.string(), at.begin.line, key_path, what));
  }
  [[noreturn]] void fail(const toml::node& at, const std::string& key_path, const std::string& what) const {
    fail(at.source(), key_path, what);
  }
  /// A warning at a place, in the same form.
  [[nodiscard]] std::string note(const toml::node& at, const std::string& key_path, const std::string& what) const {
    return fmt::format("{}:{}: {}: {}", file_.string(), at.source().begin.line, key_path, what);
  }
  [[nodiscard]] const fs::path& file() const { return file_; }
  /// A path written in the definition: absolute as given, otherwise relative to its folder; made
  /// absolute, so that results name the file wherever they are read (the gate's reproduce commands).
  [[nodiscard]] fs::path beside(const std::string& path) const {
    const fs::path p(path);
    return (p.is_absolute() ? p : fs::absolute(file_.parent_path() / p)).lexically_normal();
  }

 private:
  fs::path file_;
};

/// InputError for every key of `table` not among `valid`, naming it, its line and the valid keys.
void check_keys(const Where& where, const toml::table& table, const std::string& prefix,
                const std::vector<std::string>& valid) {
  for (auto&& [key, node] : table) {
    const std::string name(key.str());
    if (std::find(valid.begin(), valid.end(), name) != valid.end()) continue;
    where.fail(key.source(), prefix.empty() ? name : prefix + "." + name,
               fmt::format("unknown key; valid keys{}: {}",
                           prefix.empty() ? " at the top level" : " in [" + prefix + "]", fmt::join(valid, ", ")));
  }
}

const char* type_name(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a float";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::array: return "an array";
    case toml::node_type::table: return "a table";
    default: return "a date or time";
  }
}

const toml::table& table_at(const Where& where, const toml::node& node, const std::string& path) {
  if (!node.is_table()) where.fail(node, path, fmt::format("must be a table, not {}", type_name(node)));
  return *node.as_table();
}

std::string string_at(const Where& where, const toml::node& node, const std::string& path) {
  if (!node.is_string()) where.fail(node, path, fmt::format("must be a string, not {}", type_name(node)));
  return node.as_string()->get();
}

double number_at(const Where& where, const toml::node& node, const std::string& path) {
  if (node.is_integer()) return static_cast<double>(node.as_integer()->get());
  if (node.is_floating_point()) return node.as_floating_point()->get();
  where.fail(node, path, fmt::format("must be a number, not {}", type_name(node)));
}

int64_t integer_at(const Where& where, const toml::node& node, const std::string& path) {
  if (!node.is_integer()) where.fail(node, path, fmt::format("must be an integer, not {}", type_name(node)));
  return node.as_integer()->get();
}

bool bool_at(const Where& where, const toml::node& node, const std::string& path) {
  if (!node.is_boolean()) where.fail(node, path, fmt::format("must be true or false, not {}", type_name(node)));
  return node.as_boolean()->get();
}

/// The entries of an axis: an array (non-empty) or a single value standing for a one-entry axis.
std::vector<const toml::node*> axis_entries(const Where& where, const toml::node& node, const std::string& path) {
  std::vector<const toml::node*> out;
  if (const toml::array* a = node.as_array()) {
    if (a->empty())
      where.fail(node, path,
                 "is empty; give at least one value, or leave the key out for its default (docs/sweeps.md)");
    // Refused before its entries are read and checked: such an axis alone makes too many cells.
    if (a->size() > kMaxSweepCells)
      where.fail(node, path,
                 fmt::format("lists {} values, more than the {} cells a sweep may hold; split it into several "
                             "definitions",
                             a->size(), kMaxSweepCells));
    for (const toml::node& e : *a) out.push_back(&e);
  } else {
    out.push_back(&node);
  }
  return out;
}

/// A positive finite length or disparity.
double positive_at(const Where& where, const toml::node& node, const std::string& path, const char* hint) {
  const double v = number_at(where, node, path);
  if (!std::isfinite(v) || v <= 0.0) where.fail(node, path, fmt::format("{} is not a positive number; {}", v, hint));
  return v;
}

/// A numeric axis of positive values up to `largest`; repeated values are an error (they would
/// give cells with one id).
std::vector<std::optional<double>> positive_axis(const Where& where, const toml::node& node, const std::string& path,
                                                 const char* hint, double largest) {
  std::vector<std::optional<double>> out;
  std::set<double> seen;
  for (const toml::node* e : axis_entries(where, node, path)) {
    const double v = positive_at(where, *e, path, hint);
    if (v > largest)
      where.fail(*e, path, fmt::format("{} is beyond the largest value a rig takes, {:g}; {}", number_text(v), largest,
                                       hint));
    if (!seen.insert(v).second) where.fail(*e, path, fmt::format("lists {} twice", number_text(v)));
    out.push_back(v);
  }
  return out;
}

SweepScene parse_scene_entry(const Where& where, const toml::node& node, const std::string& path) {
  const std::string text = string_at(where, node, path);
  if (text.find('|') != std::string::npos)
    where.fail(node, path, fmt::format("'{}' contains '|', which separates the parts of a cell id; rename the file", text));
  if (!scenes::is_scene_file_spec(text)) {
    try {
      return parse_builtin_scene(text);
    } catch (const InputError& e) {
      where.fail(node, path, e.what());
    }
  }
  SweepScene s;
  s.builtin = false;
  s.label = text;
  s.name = text;
  s.file = where.beside(text);
  std::error_code ec;
  if (fs::is_directory(s.file, ec))
    where.fail(node, path, fmt::format("scene file {} is a folder; give a .gltf/.glb file", s.file.string()));
  if (!fs::is_regular_file(s.file, ec))
    where.fail(node, path,
               fmt::format("scene file {} does not exist (paths are relative to the definition's folder); give an "
                           "existing .gltf/.glb or a built-in scene name (see `stereobench scenes list`)",
                           s.file.string()));
  return s;
}

void parse_pipelines(const Where& where, const toml::node& node, SweepDefinition& d) {
  const std::string path = "sweep.pipelines";
  std::vector<std::string> given;  // as written, 'all' included
  std::vector<std::string> names;  // 'all' expanded
  for (const toml::node* e : axis_entries(where, node, path)) {
    const std::string name = string_at(where, *e, path);
    if (name != "all" && std::find(given.begin(), given.end(), name) != given.end())
      where.fail(*e, path, fmt::format("lists '{}' twice", name));
    given.push_back(name);
    // Checked entry by entry, so that a message names this entry's line.
    try {
      if (name != "all") (void)parse_pipeline_entry(name).options();  // a variant's fixed options
      names = expand_all_pipelines(given, "");                       // a name 'all' already includes
      (void)parse_pipeline_entries(names, "");                       // variants whose files would coincide
    } catch (const InputError& err) {
      where.fail(*e, path, err.what());
    }
  }
  d.pipelines = names;
}

/// A pipeline option's value as the pipeline reads it (text).
std::string option_text(const Where& where, const toml::node& node, const std::string& path) {
  if (node.is_string()) return node.as_string()->get();
  if (node.is_boolean()) return node.as_boolean()->get() ? "true" : "false";
  if (node.is_integer()) return std::to_string(node.as_integer()->get());
  if (node.is_floating_point()) return number_text(node.as_floating_point()->get());
  where.fail(node, path, fmt::format("must be a string, number or boolean, not {}", type_name(node)));
}

const std::vector<std::string> kTopKeys = {"sweep", "timing", "options", "output", "path", "gate"};
const std::vector<std::string> kPathKeys = {"frames", "camera_keys", "spin", "gltf_animation", "gltf_clip", "bvh"};
const std::vector<std::string> kSpinKeys = {"axis", "degrees_per_frame", "pivot", "mesh_prefix"};
const std::vector<std::string> kSweepKeys = {"name",          "description",      "scenes",        "pipelines",
                                             "baseline",      "interaxial_m",     "max_disparity_px",
                                             "convergence_m", "resolutions",      "lights",        "truths"};
const std::vector<std::string> kTimingKeys = {"repetitions", "warmup"};
const std::vector<std::string> kOutputKeys = {"images", "exr"};
const std::vector<std::string> kGateKeys = {"config"};

/// `count` finite numbers from an array, e.g. a point [x, y, z] in meters.
std::vector<double> numbers_at(const Where& where, const toml::node& node, const std::string& path, size_t count,
                               const char* example) {
  const toml::array* a = node.as_array();
  if (!a || a->size() != count)
    where.fail(node, path,
               fmt::format("must be an array of {} numbers, e.g. {}, not {}", count, example,
                           a ? fmt::format("{} values", a->size()) : std::string(type_name(node))));
  std::vector<double> out;
  for (const toml::node& e : *a) {
    const double v = number_at(where, e, path);
    if (!std::isfinite(v)) where.fail(e, path, fmt::format("{} is not a finite number", v));
    out.push_back(v);
  }
  return out;
}

dvec3 point_at(const Where& where, const toml::node& node, const std::string& path, const char* example) {
  const std::vector<double> v = numbers_at(where, node, path, 3, example);
  return {v[0], v[1], v[2]};
}

/// The [path] table: frames, camera key poses, a spin and the BVH update.
void parse_path(const Where& where, const toml::node& node, SweepDefinition& d) {
  const toml::table& table = table_at(where, node, "path");
  check_keys(where, table, "path", kPathKeys);
  PathSpec path;
  const toml::node* frames = table.get("frames");
  if (!frames) where.fail(node, "path.frames", "is missing; a [path] needs the number of frames, e.g. frames = 30");
  const int64_t n = integer_at(where, *frames, "path.frames");
  if (n < 1 || n > 100000) where.fail(*frames, "path.frames", fmt::format("{} is outside 1..100000", n));
  path.frames = static_cast<int>(n);
  if (const toml::node* keys = table.get("camera_keys")) {
    const toml::array* a = keys->as_array();
    if (!a || a->empty())
      where.fail(*keys, "path.camera_keys",
                 "must be a non-empty array of key poses [px, py, pz, tx, ty, tz] (position and target, meters)");
    for (const toml::node& e : *a) {
      const std::vector<double> v =
          numbers_at(where, e, "path.camera_keys", 6, "[0, 1.6, 4, 0, 1, 0] (position, then target, meters)");
      const CameraKey key{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
      if (const auto why = camera_key_problem(key)) where.fail(e, "path.camera_keys", fmt::format("a key pose: {}", *why));
      path.camera_keys.push_back(key);
    }
  }
  if (const toml::node* spin_node = table.get("spin")) {
    const toml::table& spin = table_at(where, *spin_node, "path.spin");
    check_keys(where, spin, "path.spin", kSpinKeys);
    Spin s;
    if (const toml::node* v = spin.get("axis")) {
      s.axis = point_at(where, *v, "path.spin.axis", "[0, 1, 0]");
      if (glm::length(s.axis) < 1e-12) where.fail(*v, "path.spin.axis", "is zero; give a direction such as [0, 1, 0]");
    }
    if (const toml::node* v = spin.get("degrees_per_frame")) {
      s.degrees_per_frame = number_at(where, *v, "path.spin.degrees_per_frame");
      if (!(std::abs(s.degrees_per_frame) <= 360.0))
        where.fail(*v, "path.spin.degrees_per_frame",
                   fmt::format("{} is not within ±360 (degrees turned between two frames)", s.degrees_per_frame));
    }
    if (const toml::node* v = spin.get("pivot")) {
      s.pivot = point_at(where, *v, "path.spin.pivot", "[0, 0.5, 0]");
      if (!within_scene_range(*s.pivot))
        where.fail(*v, "path.spin.pivot",
                   fmt::format("({:g}, {:g}, {:g}) lies beyond the ±{:g} m a scene may span; give a point in the "
                               "scene, in metres",
                               s.pivot->x, s.pivot->y, s.pivot->z, kMaxSceneCoordinate));
    }
    if (const toml::node* v = spin.get("mesh_prefix")) s.mesh_prefix = string_at(where, *v, "path.spin.mesh_prefix");
    path.spin = s;
  }
  if (const toml::node* v = table.get("gltf_animation")) path.gltf_animation = bool_at(where, *v, "path.gltf_animation");
  if (const toml::node* v = table.get("gltf_clip")) {
    path.gltf_clip = string_at(where, *v, "path.gltf_clip");
    if (path.gltf_clip.empty()) where.fail(*v, "path.gltf_clip", "is empty; name a glTF animation, or drop the key");
    // A clip plays the scene's animation; saying gltf_animation = false beside it contradicts it.
    if (table.get("gltf_animation") != nullptr && !path.gltf_animation)
      where.fail(*v, "path.gltf_clip", "chooses a glTF animation, but gltf_animation = false; drop one");
    path.gltf_animation = true;
  }
  if (const toml::node* v = table.get("bvh")) {
    const std::string bvh = string_at(where, *v, "path.bvh");
    if (bvh != "refit" && bvh != "rebuild")
      where.fail(*v, "path.bvh", fmt::format("'{}' is neither \"refit\" nor \"rebuild\"", bvh));
    d.path_refit = bvh == "refit";
    // Nothing moves without a spin or an animation: a BVH update asked for would never be done.
    if (!path.spin && !path.gltf_animation)
      where.fail(*v, "path.bvh", "needs path.spin or path.gltf_animation (nothing else moves the scene's meshes); "
                 "drop the key");
  }
  try {
    path.validate();
  } catch (const InputError& e) {
    where.fail(node, "path", e.what());
  }
  if (const auto unshown = path.unshown_keys_warning("path.frames ="))
    d.warnings.push_back(where.note(*frames, "path.frames", *unshown));
  d.path = path;
}

}  // namespace

SweepScene parse_builtin_scene(const std::string& text) {
  const size_t colon = text.find(':');
  SweepScene s;
  s.builtin = true;
  s.name = text.substr(0, colon);
  const scenes::GeneratorInfo& info = scenes::find_generator(s.name);
  if (colon != std::string::npos) {
    const std::string list = text.substr(colon + 1);
    if (list.empty()) throw InputError(fmt::format("scene '{}': nothing after ':'; give name:key=value,key=value", text));
    size_t start = 0;
    while (start <= list.size()) {
      const size_t comma = std::min(list.find(',', start), list.size());
      const std::string item = list.substr(start, comma - start);
      start = comma + 1;
      const size_t eq = item.find('=');
      if (eq == std::string::npos || eq == 0)
        throw InputError(fmt::format("scene '{}': '{}' is not key=value", text, item));
      const std::string key = item.substr(0, eq), value_text = item.substr(eq + 1);
      const scenes::GeneratorParam* param = nullptr;
      for (const scenes::GeneratorParam& p : info.params)
        if (p.name == key) param = &p;
      if (!param) {
        std::vector<std::string> known;
        for (const scenes::GeneratorParam& p : info.params) known.push_back(p.name);
        throw InputError(fmt::format("scene '{}': '{}' has no parameter '{}' (its parameters: {})", text, s.name, key,
                                     known.empty() ? std::string("none") : fmt::format("{}", fmt::join(known, ", "))));
      }
      // Decimal only (stod would read 0x10 as 16); -0 is 0, one scene and one label.
      const std::optional<double> parsed = parse_finite(value_text);
      if (!parsed) throw InputError(fmt::format("scene '{}': {}={} is not a decimal number", text, key, value_text));
      const double value = *parsed == 0.0 ? 0.0 : *parsed;
      if (value < param->min_value || value > param->max_value)
        throw InputError(fmt::format("scene '{}': {}={} is outside {}..{}", text, key, value_text,
                                     number_text(param->min_value), number_text(param->max_value)));
      if (param->integer && value != std::floor(value))
        throw InputError(fmt::format("scene '{}': {} must be a whole number, not {}", text, key, value_text));
      if (!s.params.emplace(key, value).second)
        throw InputError(fmt::format("scene '{}': parameter '{}' given twice", text, key));
      if (comma == list.size()) break;
    }
  }
  s.label = scene_label(s.name, s.params);
  return s;
}

SweepDefinition parse_sweep(const std::string& text, const fs::path& file) {
  const Where where(file);
  toml::table root;
  try {
    root = toml::parse(text, file.string());
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}:{}:{}: not valid TOML: {}; mend the syntax there (the format: docs/sweeps.md)",
                                 file.string(), e.source().begin.line, e.source().begin.column, e.description()));
  }
  check_keys(where, root, "", kTopKeys);

  SweepDefinition d;
  d.file = file;
  d.sha256 = Sha256().add(text).hex();
  d.name = file.stem().string();

  const toml::node* sweep_node = root.get("sweep");
  if (!sweep_node)
    throw InputError(fmt::format("{}: no [sweep] table; a definition needs at least [sweep] with a name (see "
                                 "docs/sweeps.md)",
                                 file.string()));
  const toml::table& sweep = table_at(where, *sweep_node, "sweep");
  check_keys(where, sweep, "sweep", kSweepKeys);

  if (const toml::node* n = sweep.get("name")) {
    d.name = string_at(where, *n, "sweep.name");
    // It names the default output folder out/sweeps/<name>: "." and ".." would be another folder.
    if (d.name.empty() || d.name == "." || d.name == ".." || has_control_character(d.name) ||
        d.name.find_first_of("/\\") != std::string::npos)
      where.fail(*n, "sweep.name",
                 "must be a non-empty name without '/', '\\' or control characters, other than '.' and '..'");
  }
  if (const toml::node* n = sweep.get("description")) d.description = string_at(where, *n, "sweep.description");
  // The name goes into every results line, the folder marker and nightly's history, which are
  // JSON: a file name in another encoding could not be told apart from others there.
  if (!io::is_utf8(d.name))
    throw InputError(fmt::format("{}: the sweep is named by its file, whose name is not UTF-8; rename the file, or "
                                 "give the sweep a name (name = \"...\" in [sweep])",
                                 file.string()));

  // Scenes.
  d.scenes = {parse_builtin_scene("spheres")};
  if (const toml::node* n = sweep.get("scenes")) {
    d.scenes.clear();
    // What each scene seen is known by: its label, its file, its generator with every parameter
    // resolved (looked up, not compared pair by pair: an axis may be long).
    std::set<std::string> labels;
    std::map<fs::path, std::string> files;
    std::map<std::pair<std::string, std::map<std::string, double>>, std::string> generated;
    for (const toml::node* e : axis_entries(where, *n, "sweep.scenes")) {
      SweepScene s = parse_scene_entry(where, *e, "sweep.scenes");
      if (!labels.insert(s.label).second) where.fail(*e, "sweep.scenes", fmt::format("lists '{}' twice", s.label));
      if (!s.builtin) {
        const auto [it, fresh] = files.emplace(s.file, s.label);
        if (!fresh)
          where.fail(*e, "sweep.scenes",
                     fmt::format("lists one scene file twice: '{}' and '{}' are both {}", it->second, s.label,
                                 s.file.string()));
      } else {
        const auto [it, fresh] = generated.emplace(
            std::make_pair(s.name, scenes::resolve_params(scenes::find_generator(s.name), s.params)), s.label);
        if (!fresh)
          where.fail(*e, "sweep.scenes",
                     fmt::format("lists one scene twice: '{}' and '{}' differ only by parameters at their defaults",
                                 it->second, s.label));
      }
      d.scenes.push_back(std::move(s));
    }
  }

  // Pipelines and the baseline.
  d.pipelines = pipeline_names();
  if (const toml::node* n = sweep.get("pipelines")) parse_pipelines(where, *n, d);
  if (const toml::node* n = sweep.get("baseline")) {
    d.baseline = string_at(where, *n, "sweep.baseline");
    try {
      const PipelineEntry base = parse_pipeline_entry(d.baseline);
      (void)base.options();
      // Listed under another spelling of the same variant (its options in another order), the
      // baseline is that entry, as for `bench --baseline`.
      if (const auto same = find_same_variant(parse_pipeline_entries(d.pipelines, ""), base)) d.baseline = *same;
    } catch (const InputError& err) {
      where.fail(*n, "sweep.baseline", err.what());
    }
  } else {
    (void)find_pipeline(d.baseline);
  }
  d.baseline_listed = std::find(d.pipelines.begin(), d.pipelines.end(), d.baseline) != d.pipelines.end();
  if (!d.baseline_listed) {
    d.pipelines.push_back(d.baseline);
    try {
      (void)parse_pipeline_entries(d.pipelines, "");
    } catch (const InputError& err) {
      // The baseline is missing from the list, so the baseline or the list (or both) was given.
      const toml::node* at = sweep.get("baseline") ? sweep.get("baseline") : sweep.get("pipelines");
      where.fail(*at, at == sweep.get("baseline") ? "sweep.baseline" : "sweep.pipelines", err.what());
    }
  }
  std::sort(d.pipelines.begin(), d.pipelines.end());

  // Rig axes.
  const toml::node* interaxial = sweep.get("interaxial_m");
  const toml::node* disparity = sweep.get("max_disparity_px");
  if (interaxial && disparity)
    where.fail(*disparity, "sweep.max_disparity_px",
               fmt::format("the interaxial is already given in meters (sweep.interaxial_m, line {}); give it one "
                           "way only",
                           interaxial->source().begin.line));
  if (interaxial)
    d.interaxial_m = positive_axis(where, *interaxial, "sweep.interaxial_m",
                                   "give eye separations in meters, e.g. 0.064", kMaxSceneCoordinate);
  if (disparity)
    d.max_disparity_px =
        positive_axis(where, *disparity, "sweep.max_disparity_px", "give disparities at infinity in pixels, e.g. 30",
                      kMaxDisparityPx);
  if (const toml::node* n = sweep.get("convergence_m"))
    d.convergence_m = positive_axis(where, *n, "sweep.convergence_m",
                                    "give zero-parallax distances in meters, e.g. 2.0", kMaxSceneCoordinate);
  if (const toml::node* n = sweep.get("resolutions")) {
    d.resolutions.clear();
    std::set<std::string> seen;
    for (const toml::node* e : axis_entries(where, *n, "sweep.resolutions")) {
      const std::string given = string_at(where, *e, "sweep.resolutions");
      ivec2 size{0, 0};
      try {
        size = parse_resolution(given);
      } catch (const InputError& err) {
        where.fail(*e, "sweep.resolutions", err.what());
      }
      SweepResolution r{fmt::format("{}x{}", size.x, size.y), size.x, size.y};
      if (!seen.insert(r.label).second)
        where.fail(*e, "sweep.resolutions", fmt::format("lists {} twice ('{}' is {})", r.label, given, r.label));
      d.resolutions.emplace_back(r);
    }
  }
  if (const toml::node* n = sweep.get("lights")) {
    d.lights.clear();
    std::set<int64_t> seen;
    for (const toml::node* e : axis_entries(where, *n, "sweep.lights")) {
      const int64_t v = integer_at(where, *e, "sweep.lights");
      if (v < 1 || v > 100000)
        where.fail(*e, "sweep.lights", fmt::format("{} is outside 1..100000 (a count of the scene's lights)", v));
      if (!seen.insert(v).second) where.fail(*e, "sweep.lights", fmt::format("lists {} twice", v));
      d.lights.emplace_back(static_cast<int>(v));
    }
  }
  if (const toml::node* n = sweep.get("truths")) {
    d.truths.clear();
    const std::vector<std::string> known = truth_provider_names();
    for (const toml::node* e : axis_entries(where, *n, "sweep.truths")) {
      const std::string name = string_at(where, *e, "sweep.truths");
      if (std::find(known.begin(), known.end(), name) == known.end())
        where.fail(*e, "sweep.truths",
                   fmt::format("unknown ground-truth provider '{}' (providers: {})", name, fmt::join(known, ", ")));
      if (std::find(d.truths.begin(), d.truths.end(), name) != d.truths.end())
        where.fail(*e, "sweep.truths", fmt::format("lists '{}' twice", name));
      d.truths.push_back(name);
    }
  }

  // Timing.
  if (const toml::node* n = root.get("timing")) {
    const toml::table& timing = table_at(where, *n, "timing");
    check_keys(where, timing, "timing", kTimingKeys);
    if (const toml::node* r = timing.get("repetitions")) {
      const int64_t v = integer_at(where, *r, "timing.repetitions");
      if (v < 1 || v > 10000) where.fail(*r, "timing.repetitions", fmt::format("{} is outside 1..10000", v));
      d.repetitions = static_cast<int>(v);
    }
    if (const toml::node* w = timing.get("warmup")) {
      const int64_t v = integer_at(where, *w, "timing.warmup");
      if (v < 0 || v > 10000) where.fail(*w, "timing.warmup", fmt::format("{} is outside 0..10000", v));
      d.warmup = static_cast<int>(v);
    }
  }

  // Pipeline options, checked against what each pipeline declares.
  if (const toml::node* n = root.get("options")) {
    const toml::table& options = table_at(where, *n, "options");
    for (auto&& [key, node] : options) {
      const std::string pipeline(key.str());
      const std::string path = "options." + pipeline;
      std::vector<PipelineEntry> runs;  // the pipeline and its variants
      for (const std::string& entry : d.pipelines)
        if (entry_pipeline_name(entry) == pipeline) runs.push_back(parse_pipeline_entry(entry));
      if (runs.empty() && pipeline != entry_pipeline_name(pipeline))
        where.fail(key.source(), path,
                   fmt::format("a table of options is named by a pipeline, not a variant: a variant's options are "
                               "fixed in its entry ('{}'), and [options.{}] applies to {} and all its variants",
                               pipeline, entry_pipeline_name(pipeline), entry_pipeline_name(pipeline)));
      if (runs.empty())
        where.fail(key.source(), path,
                   fmt::format("options for a pipeline the sweep does not run; its pipelines: {}",
                               fmt::join(d.pipelines, ", ")));
      // Checked as they accumulate, the way the cells will read them: an error names the option
      // that made the table invalid, and the last check covers the whole table.
      std::map<std::string, std::string> values;
      for (auto&& [option, value] : table_at(where, node, path)) {
        const std::string option_path = path + "." + std::string(option.str());
        values[std::string(option.str())] = option_text(where, value, option_path);
        try {
          (void)PipelineOptions(runs.front().pipeline->info(), values);
          for (const PipelineEntry& run : runs) (void)run.options(values);  // under a variant's own
        } catch (const InputError& err) {
          where.fail(option.source(), option_path, err.what());
        }
      }
      d.options[pipeline] = values;
    }
  }

  if (const toml::node* n = root.get("path")) parse_path(where, *n, d);

  // Output.
  if (const toml::node* n = root.get("output")) {
    const toml::table& output = table_at(where, *n, "output");
    check_keys(where, output, "output", kOutputKeys);
    if (const toml::node* v = output.get("images")) d.images = bool_at(where, *v, "output.images");
    if (const toml::node* v = output.get("exr")) d.exr = bool_at(where, *v, "output.exr");
    if (d.exr && !d.images)
      where.fail(*output.get("exr"), "output.exr", "EXR images need output.images = true");
  }

  // The cells are expanded (and listed, merged, sharded) in memory, about 1 kB each.
  {
    const size_t interaxials = d.max_disparity_px.front().has_value() ? d.max_disparity_px.size() : d.interaxial_m.size();
    const double cells = static_cast<double>(d.scenes.size()) * static_cast<double>(interaxials) *
                         static_cast<double>(d.convergence_m.size()) * static_cast<double>(d.resolutions.size()) *
                         static_cast<double>(d.lights.size()) * static_cast<double>(d.truths.size()) *
                         static_cast<double>(d.path ? d.path->frames : 1);
    if (cells > static_cast<double>(kMaxSweepCells))
      throw InputError(fmt::format(
          "{}: the sweep has {:.0f} cells ({} scene(s) x {} interaxial(s) x {} convergence(s) x {} resolution(s) x {} "
          "light count(s) x {} truth(s) x {} frame(s)), more than the {} a sweep may hold; split it into several "
          "definitions",
          file.string(), cells, d.scenes.size(), interaxials, d.convergence_m.size(), d.resolutions.size(),
          d.lights.size(), d.truths.size(), d.path ? d.path->frames : 1, kMaxSweepCells));
  }

  // The gate config `stereobench nightly` applies unless told otherwise.
  if (const toml::node* n = root.get("gate")) {
    const toml::table& gate = table_at(where, *n, "gate");
    check_keys(where, gate, "gate", kGateKeys);
    if (const toml::node* v = gate.get("config")) {
      const std::string name = string_at(where, *v, "gate.config");
      if (name.empty()) where.fail(*v, "gate.config", "must name a gate config file (TOML), e.g. \"gate-nightly.toml\"");
      d.gate_config = where.beside(name);
    }
  }
  return d;
}

SweepDefinition load_sweep(const fs::path& file) {
  std::error_code ec;
  if (!fs::exists(file, ec))
    throw InputError(fmt::format("{}: sweep definition does not exist; give a TOML file such as ci/smoke.toml",
                                 file.string()));
  return parse_sweep(io::read_file(file), file);
}

std::vector<SweepCell> expand_cells(const SweepDefinition& d) {
  // One interaxial axis: meters, max disparity, or the scene default.
  struct Interaxial {
    std::optional<double> meters, pixels;
  };
  std::vector<Interaxial> interaxials;
  if (d.max_disparity_px.front().has_value()) {
    for (const auto& v : d.max_disparity_px) interaxials.push_back({std::nullopt, v});
  } else {
    for (const auto& v : d.interaxial_m) interaxials.push_back({v, std::nullopt});
  }

  std::vector<std::optional<int>> frames{std::nullopt};
  if (d.path) {
    frames.clear();
    for (int k = 0; k < d.path->frames; ++k) frames.emplace_back(k);
  }

  std::vector<SweepCell> cells;
  for (const SweepScene& scene : d.scenes)
    for (const Interaxial& e : interaxials)
      for (const auto& c : d.convergence_m)
        for (const auto& r : d.resolutions)
          for (const auto& l : d.lights)
            for (const std::string& truth : d.truths)
              for (const auto& frame : frames) {
                SweepCell cell;
                cell.index = cells.size();
                cell.scene = scene;
                cell.interaxial_m = e.meters;
                cell.max_disparity_px = e.pixels;
                cell.convergence_m = c;
                cell.resolution = r;
                cell.lights = l;
                cell.truth = truth;
                cell.frame = frame;
                cell.id = cell_id(cell);
                cells.push_back(std::move(cell));
              }
  return cells;
}

json cell_to_json(const SweepCell& cell) {
  const auto opt = [](const std::optional<double>& v) { return v ? json(*v) : json(nullptr); };
  json out = {{"scene", cell.scene.name},
              {"scene_params", cell.scene.params.empty() ? json::object() : json(cell.scene.params)},
              {"interaxial_m", opt(cell.interaxial_m)},
              {"max_disparity_px", opt(cell.max_disparity_px)},
              {"convergence_m", opt(cell.convergence_m)},
              {"resolution", cell.resolution ? json(cell.resolution->label) : json(nullptr)},
              {"lights", cell.lights ? json(*cell.lights) : json(nullptr)},
              {"truth", cell.truth}};
  if (cell.frame) out["frame"] = *cell.frame;
  return out;
}

}  // namespace sb::validation
