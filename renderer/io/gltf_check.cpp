// Structural glTF JSON check with JSON-pointer error messages.
#include "renderer/io/gltf_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <set>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "renderer/error.hpp"
#include "renderer/scene.hpp"

namespace sb::io {

namespace {

using nlohmann::json;

/// Walks the document with the current JSON pointer and the sizes of the top-level arrays.
class Checker {
 public:
  Checker(const json& doc, std::string file) : doc_(doc), file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& path, const std::string& what) const {
    throw InputError(fmt::format("{}: {}: {}", file_, path.empty() ? "/" : path, what));
  }

  [[nodiscard]] size_t array_size(std::string_view top) const {
    if (top == "lights") {
      const json* ext = find(doc_, "extensions");
      const json* khr = ext ? find(*ext, "KHR_lights_punctual") : nullptr;
      const json* lights = khr ? find(*khr, "lights") : nullptr;
      return lights && lights->is_array() ? lights->size() : 0;
    }
    const json* a = find(doc_, std::string(top));
    return a && a->is_array() ? a->size() : 0;
  }

  static const json* find(const json& obj, const std::string& key) {
    if (!obj.is_object()) return nullptr;
    auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
  }

  const json& require_object(const json& v, const std::string& path) const {
    if (!v.is_object()) fail(path, fmt::format("expected a JSON object, found {}", v.type_name()));
    return v;
  }

  const json& require_array(const json& v, const std::string& path) const {
    if (!v.is_array()) fail(path, fmt::format("expected a JSON array, found {}", v.type_name()));
    return v;
  }

  /// An optional member of `obj`; when `required` is set its absence is a fault.
  const json* member(const json& obj, const std::string& key, const std::string& path,
                     bool required = false) const {
    const json* v = find(obj, key);
    if (!v && required) fail(path + "/" + key, "required property is missing");
    return v;
  }

  uint64_t integer(const json& v, const std::string& path, uint64_t lo = 0,
                   uint64_t hi = (uint64_t{1} << 53)) const {
    if (!v.is_number_integer() || (v.is_number_integer() && !v.is_number_unsigned() && v.get<int64_t>() < 0)) {
      if (v.is_number_integer()) fail(path, fmt::format("must be a non-negative integer, found {}", v.dump()));
      fail(path, fmt::format("must be an integer, found {} {}", v.type_name(), v.dump()));
    }
    const uint64_t x = v.get<uint64_t>();
    if (x < lo || x > hi) fail(path, fmt::format("value {} is out of range [{}, {}]", x, lo, hi));
    return x;
  }

  double number(const json& v, const std::string& path) const {
    if (!v.is_number()) fail(path, fmt::format("must be a number, found {} {}", v.type_name(), v.dump()));
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail(path, "must be finite");
    return x;
  }

  /// A number in [lo, hi]; `what` says what the range means.
  double number_in(const json& v, const std::string& path, double lo, double hi, std::string_view what) const {
    const double x = number(v, path);
    if (x < lo || x > hi) fail(path, fmt::format("value {:g} is out of range [{:g}, {:g}] ({})", x, lo, hi, what));
    return x;
  }

  /// A number greater than zero.
  double positive(const json& v, const std::string& path, std::string_view what) const {
    const double x = number(v, path);
    if (!(x > 0.0)) fail(path, fmt::format("value {:g} must be positive ({})", x, what));
    return x;
  }

  void boolean(const json& v, const std::string& path) const {
    if (!v.is_boolean()) fail(path, fmt::format("must be true or false, found {} {}", v.type_name(), v.dump()));
  }

  const std::string& string(const json& v, const std::string& path) const {
    if (!v.is_string()) fail(path, fmt::format("must be a string, found {} {}", v.type_name(), v.dump()));
    return v.get_ref<const std::string&>();
  }

  void number_array(const json& v, const std::string& path, size_t len) const {
    require_array(v, path);
    if (v.size() != len) fail(path, fmt::format("must have {} elements, found {}", len, v.size()));
    for (size_t i = 0; i < v.size(); ++i) number(v[i], fmt::format("{}/{}", path, i));
  }

  /// An index into the top-level array `top`.
  void index(const json& v, const std::string& path, std::string_view top) const {
    const uint64_t i = integer(v, path);
    const size_t n = array_size(top);
    if (i >= n)
      fail(path, fmt::format("refers to {}[{}] but the file has {} {}", top, i, n, top));
  }

  void opt_index(const json& obj, const std::string& key, const std::string& path,
                 std::string_view top, bool required = false) const {
    if (const json* v = member(obj, key, path, required)) index(*v, path + "/" + key, top);
  }

  void opt_integer(const json& obj, const std::string& key, const std::string& path,
                   uint64_t lo = 0, uint64_t hi = (uint64_t{1} << 53), bool required = false) const {
    if (const json* v = member(obj, key, path, required)) integer(*v, path + "/" + key, lo, hi);
  }

  void opt_number(const json& obj, const std::string& key, const std::string& path,
                  bool required = false) const {
    if (const json* v = member(obj, key, path, required)) number(*v, path + "/" + key);
  }

  void opt_bool(const json& obj, const std::string& key, const std::string& path) const {
    if (const json* v = member(obj, key, path)) boolean(*v, path + "/" + key);
  }

  void opt_string(const json& obj, const std::string& key, const std::string& path,
                  bool required = false) const {
    if (const json* v = member(obj, key, path, required)) string(*v, path + "/" + key);
  }

  void opt_number_array(const json& obj, const std::string& key, const std::string& path,
                        size_t len) const {
    if (const json* v = member(obj, key, path)) number_array(*v, path + "/" + key, len);
  }

  /// An optional array of `len` numbers, each in [lo, hi].
  void opt_number_array_in(const json& obj, const std::string& key, const std::string& path, size_t len, double lo,
                           double hi, std::string_view what) const {
    const json* v = member(obj, key, path);
    if (!v) return;
    number_array(*v, path + "/" + key, len);
    for (size_t i = 0; i < len; ++i) number_in((*v)[i], fmt::format("{}/{}/{}", path, key, i), lo, hi, what);
  }

  void opt_object(const json& obj, const std::string& key, const std::string& path) const {
    if (const json* v = member(obj, key, path)) require_object(*v, path + "/" + key);
  }

  /// Calls `each(element, path)` for every element of the top-level array `key`, which must hold objects.
  template <class F>
  void each(const json& obj, const std::string& key, const std::string& path, F&& f) const {
    const json* arr = member(obj, key, path);
    if (!arr) return;
    const std::string apath = path + "/" + key;
    require_array(*arr, apath);
    for (size_t i = 0; i < arr->size(); ++i) {
      const std::string p = fmt::format("{}/{}", apath, i);
      f(require_object((*arr)[i], p), p);
    }
  }

  void texture_info(const json& obj, const std::string& key, const std::string& path) const {
    const json* t = member(obj, key, path);
    if (!t) return;
    const std::string p = path + "/" + key;
    require_object(*t, p);
    opt_index(*t, "index", p, "textures", true);
    opt_integer(*t, "texCoord", p, 0, 255);
    const json* ext = find(*t, "extensions");
    if (const json* tt = ext && ext->is_object() ? find(*ext, "KHR_texture_transform") : nullptr) {
      const std::string tp = p + "/extensions/KHR_texture_transform";
      require_object(*tt, tp);
      opt_number_array(*tt, "offset", tp, 2);
      opt_number(*tt, "rotation", tp);
      opt_number_array(*tt, "scale", tp, 2);
      opt_integer(*tt, "texCoord", tp, 0, 255);
    }
  }

  /// Whether the file uses `extension`.
  [[nodiscard]] bool uses(const std::string& extension) const {
    const json* used = find(doc_, "extensionsUsed");
    return used && std::find(used->begin(), used->end(), extension) != used->end();
  }

  /// The accessor types glTF 2.0 §3.7.2.1 allows the attributes read here, widened by
  /// KHR_mesh_quantization where the file uses it: POSITION VEC3 of floats (quantized: 8- or
  /// 16-bit integers, normalized or not), NORMAL VEC3 of floats (quantized: normalized signed 8 or
  /// 16 bits), TEXCOORD_n VEC2 of floats or normalized unsigned 8 or 16 bits (quantized: any 8- or
  /// 16-bit integers).
  /// An accessor's index, component type, normalized flag and type, as checked before.
  struct AccessorKind {
    size_t index = 0;
    uint64_t component = 0;
    bool normalized = false;
    std::string type;
  };
  [[nodiscard]] AccessorKind accessor_kind(const json& index) const {
    AccessorKind k;
    k.index = index.get<size_t>();
    const json& a = (*find(doc_, "accessors"))[k.index];
    k.component = find(a, "componentType")->get<uint64_t>();
    const json* nm = find(a, "normalized");
    k.normalized = nm && nm->get<bool>();
    k.type = find(a, "type")->get<std::string>();
    return k;
  }

  /// Checks that accessor `index` (read at `path`) has glTF type `type` and a component type
  /// allowed there: FLOAT where `with_float`, else one of `normalized_ints` with normalized set, or
  /// one of `plain_ints` without; `allowed` says the same in words.
  void typed_accessor(const json& index, const std::string& path, std::string_view type, bool with_float,
                      std::initializer_list<uint64_t> normalized_ints, std::initializer_list<uint64_t> plain_ints,
                      std::string_view allowed) const {
    const auto [ai, c, normalized, t] = accessor_kind(index);
    const auto among = [c](std::initializer_list<uint64_t> set) { return std::find(set.begin(), set.end(), c) != set.end(); };
    const bool ok = (with_float && c == 5126) || (normalized ? among(normalized_ints) : among(plain_ints));
    if (t != type || !ok)
      fail(path, fmt::format("accessor {} is {} of component type {}{}; it must be {} {}", ai, t, c,
                             normalized ? " (normalized)" : "", type, allowed));
  }

  void attribute_type(const std::string& name, const json& accessor_index, const std::string& prim_path) const {
    if (name.rfind("JOINTS_", 0) == 0)
      typed_accessor(accessor_index, prim_path + "/attributes/" + name, "VEC4", false, {}, {5121, 5123},
                     "of UNSIGNED_BYTE (5121) or UNSIGNED_SHORT (5123), not normalized (joint indices)");
    if (name.rfind("WEIGHTS_", 0) == 0)
      typed_accessor(accessor_index, prim_path + "/attributes/" + name, "VEC4", true, {5121, 5123}, {},
                     "of FLOAT (5126), or of normalized UNSIGNED_BYTE (5121) or UNSIGNED_SHORT (5123)");
    const bool position = name == "POSITION", normal = name == "NORMAL", uv = name.rfind("TEXCOORD_", 0) == 0;
    if (!position && !normal && !uv) return;
    const auto [ai, c, normalized, t] = accessor_kind(accessor_index);
    const bool quantized = uses("KHR_mesh_quantization");
    const bool small_int = c == 5120 || c == 5121 || c == 5122 || c == 5123;
    bool ok = c == 5126;
    std::string allowed = "of FLOAT (5126)";
    if (uv) {
      ok = ok || (quantized ? small_int : normalized && (c == 5121 || c == 5123));
      allowed = quantized ? "of FLOAT, or of 8- or 16-bit integers (KHR_mesh_quantization)"
                          : "of FLOAT (5126), or of normalized UNSIGNED_BYTE (5121) or UNSIGNED_SHORT (5123)";
    } else if (quantized) {
      ok = ok || (position ? small_int : normalized && (c == 5120 || c == 5122));
      allowed = position ? "of FLOAT, or of 8- or 16-bit integers (KHR_mesh_quantization)"
                         : "of FLOAT, or of normalized BYTE or SHORT (KHR_mesh_quantization)";
    }
    if (t != (uv ? "VEC2" : "VEC3") || !ok)
      fail(prim_path + "/attributes/" + name,
           fmt::format("accessor {} is {} of component type {}{}; {} must be {} {}{}", ai, t, c,
                       normalized ? " (normalized)" : "", name, uv ? "VEC2" : "VEC3", allowed,
                       quantized || uv ? "" : " (integer types need KHR_mesh_quantization)"));
  }

  /// Where a stereobench extras object sits: its keys differ.
  enum class ExtrasOf { scene, node };

  void extras(const json& obj, const std::string& path, ExtrasOf of) const {
    const json* e = member(obj, "extras", path);
    if (!e || !e->is_object()) return;  // extras may be anything; only ours is checked
    const json* sb = find(*e, "stereobench");
    if (!sb) return;
    const std::string p = path + "/extras/stereobench";
    require_object(*sb, p);
    // The namespace is this suite's: a misspelt key would otherwise leave its default in place
    // without a word. The scene's keys (the generators write generator, seed and params) and the
    // camera node's are told apart.
    static const std::set<std::string> scene_keys{"background", "ambient", "generator", "seed", "params"};
    static const std::set<std::string> node_keys{"interaxial", "convergence", "width", "height"};
    const std::set<std::string>& known = of == ExtrasOf::scene ? scene_keys : node_keys;
    const std::set<std::string>& other = of == ExtrasOf::scene ? node_keys : scene_keys;
    for (const auto& [key, value] : sb->items()) {
      if (known.count(key)) continue;
      if (other.count(key))
        fail(p + "/" + key, fmt::format("'{}' belongs in the {}'s extras.stereobench, not the {}'s; move it there",
                                        key, of == ExtrasOf::scene ? "camera node" : "scene",
                                        of == ExtrasOf::scene ? "scene" : "node"));
      std::string names;
      for (const std::string& k : known) names += (names.empty() ? "" : ", ") + k;
      fail(p + "/" + key, fmt::format("unknown key '{}'; a {}'s extras.stereobench holds {}", key,
                                      of == ExtrasOf::scene ? "scene" : "camera node", names));
    }
    if (const json* v = member(*sb, "interaxial", p))
      if (positive(*v, p + "/interaxial", "the eye separation in metres") > kMaxSceneCoordinate)
        fail(p + "/interaxial", fmt::format("value {:g} m is beyond the {:g} m a scene may span; give the eye "
                                            "separation in metres, e.g. 0.064",
                                            v->get<double>(), kMaxSceneCoordinate));
    if (const json* v = member(*sb, "convergence", p))
      positive(*v, p + "/convergence", "the zero-parallax distance in metres");
    opt_integer(*sb, "width", p, 1, 16384);
    opt_integer(*sb, "height", p, 1, 16384);
    opt_number_array_in(*sb, "background", p, 3, 0.0, 1e6, "linear radiance");
    if (const json* v = member(*sb, "ambient", p)) number_in(*v, p + "/ambient", 0.0, 1e6, "the ambient term");
  }

  void run() const {
    require_object(doc_, "");
    const json* asset = member(doc_, "asset", "", true);
    require_object(*asset, "/asset");
    const std::string& version = string(*member(*asset, "version", "/asset", true), "/asset/version");
    if (version.rfind("2.", 0) != 0)
      fail("/asset/version", fmt::format("glTF version '{}' is not supported; only 2.x files load", version));
    // A file that needs a later 2.x than 2.0 must not be loaded by a 2.0 reader (glTF 2.0, asset).
    if (const json* min = member(*asset, "minVersion", "/asset")) {
      const std::string& needed = string(*min, "/asset/minVersion");
      int major = 0, minor = 0, end = 0;
      if (std::sscanf(needed.c_str(), "%d.%d%n", &major, &minor, &end) != 2 ||
          static_cast<size_t>(end) != needed.size() || major < 0 || minor < 0)
        fail("/asset/minVersion", fmt::format("'{}' is not a glTF version <major>.<minor>", needed));
      if (major > 2 || (major == 2 && minor > 0))
        fail("/asset/minVersion", fmt::format("the file needs glTF {} at least; this reader reads glTF 2.0, and the "
                                              "format says such a file must not be loaded; export it for glTF 2.0",
                                              needed));
    }

    for (const char* key : {"extensionsUsed", "extensionsRequired"})
      if (const json* a = member(doc_, key, "")) {
        require_array(*a, std::string("/") + key);
        for (size_t i = 0; i < a->size(); ++i) string((*a)[i], fmt::format("/{}/{}", key, i));
      }
    if (const json* required = find(doc_, "extensionsRequired")) {
      const std::vector<std::string>& supported = supported_gltf_extensions();
      for (size_t i = 0; i < required->size(); ++i) {
        const std::string& e = (*required)[i].get_ref<const std::string&>();
        if (std::find(supported.begin(), supported.end(), e) == supported.end())
          fail(fmt::format("/extensionsRequired/{}", i),
               fmt::format("extension '{}' is required by the file but not supported (supported: {}); export the "
                           "file without it (e.g. without mesh compression)",
                           e, fmt::join(supported, ", ")));
      }
    }

    // The top-level arrays first: an index into one that is not an array would read as an index
    // past its end.
    for (const char* key : {"accessors", "animations", "buffers", "bufferViews", "cameras", "images", "materials",
                            "meshes", "nodes", "samplers", "scenes", "skins", "textures"})
      if (const json* a = member(doc_, key, "")) require_array(*a, std::string("/") + key);
    if (const json* ext = find(doc_, "extensions"))
      if (const json* khr = find(*ext, "KHR_lights_punctual"))
        if (const json* lights = find(*khr, "lights")) require_array(*lights, "/extensions/KHR_lights_punctual/lights");

    opt_index(doc_, "scene", "", "scenes");
    each(doc_, "scenes", "", [&](const json& s, const std::string& p) {
      if (const json* nodes = member(s, "nodes", p)) {
        require_array(*nodes, p + "/nodes");
        for (size_t i = 0; i < nodes->size(); ++i) index((*nodes)[i], fmt::format("{}/nodes/{}", p, i), "nodes");
      }
      extras(s, p, ExtrasOf::scene);
    });

    each(doc_, "nodes", "", [&](const json& n, const std::string& p) {
      if (const json* ch = member(n, "children", p)) {
        require_array(*ch, p + "/children");
        for (size_t i = 0; i < ch->size(); ++i) index((*ch)[i], fmt::format("{}/children/{}", p, i), "nodes");
      }
      opt_index(n, "mesh", p, "meshes");
      opt_index(n, "camera", p, "cameras");
      opt_index(n, "skin", p, "skins");
      if (const json* w = member(n, "weights", p)) {
        require_array(*w, p + "/weights");
        for (size_t i = 0; i < w->size(); ++i) number((*w)[i], fmt::format("{}/weights/{}", p, i));
      }
      if (find(n, "matrix"))
        for (const char* trs : {"translation", "rotation", "scale"})
          if (find(n, trs))
            fail(p + "/" + trs, "the node has a matrix too; glTF gives a node either a matrix or translation, "
                                "rotation and scale, not both; keep one");
      if (const json* m = member(n, "matrix", p)) {
        number_array(*m, p + "/matrix", 16);
        // Column-major: the last row is elements 3, 7, 11 and 15. A projective row would divide
        // positions by w, which the renderer's affine transforms never do.
        const double row[4] = {(*m)[3].get<double>(), (*m)[7].get<double>(), (*m)[11].get<double>(),
                               (*m)[15].get<double>()};
        // Within float rounding: an exporter may write 1 as 0.99999994.
        constexpr double kTolerance = 1e-6;
        if (std::abs(row[0]) > kTolerance || std::abs(row[1]) > kTolerance || std::abs(row[2]) > kTolerance ||
            std::abs(row[3] - 1.0) > kTolerance)
          fail(p + "/matrix", fmt::format("its last row (elements 3, 7, 11 and 15; glTF matrices are column-major) is "
                                          "({:g}, {:g}, {:g}, {:g}), not (0, 0, 0, 1): a node matrix must be affine, "
                                          "decomposable into translation, rotation and scale; fix the matrix or give "
                                          "translation, rotation and scale instead",
                                          row[0], row[1], row[2], row[3]));
      }
      opt_number_array(n, "translation", p, 3);
      if (const json* r = member(n, "rotation", p)) {
        number_array(*r, p + "/rotation", 4);
        double largest = 0.0;  // zero length; the squares would underflow below 1e-154
        for (const json& c : *r) largest = std::max(largest, std::abs(c.get<double>()));
        if (!(largest > 0.0))
          fail(p + "/rotation", "the quaternion has length zero; a rotation is a unit quaternion [x, y, z, w], "
                                "e.g. [0, 0, 0, 1] for none");
      }
      opt_number_array(n, "scale", p, 3);
      if (const json* ext = member(n, "extensions", p)) {
        require_object(*ext, p + "/extensions");
        if (const json* l = find(*ext, "KHR_lights_punctual")) {
          const std::string lp = p + "/extensions/KHR_lights_punctual";
          require_object(*l, lp);
          opt_index(*l, "light", lp, "lights", true);
        }
        if (const json* inst = find(*ext, "EXT_mesh_gpu_instancing")) {
          // Each attribute an accessor of one instance's translation, rotation or scale; all of
          // one count (checked as they are read).
          const std::string ip = p + "/extensions/EXT_mesh_gpu_instancing";
          require_object(*inst, ip);
          const json* attributes = member(*inst, "attributes", ip);
          if (!attributes) fail(ip, "has no 'attributes'; give TRANSLATION, ROTATION and/or SCALE accessors");
          require_object(*attributes, ip + "/attributes");
          for (const auto& [name, accessor] : attributes->items()) {
            if (name != "TRANSLATION" && name != "ROTATION" && name != "SCALE") continue;  // custom _ATTRIBUTES
            index(accessor, ip + "/attributes/" + name, "accessors");
          }

        }
      }
      extras(n, p, ExtrasOf::node);
    });

    // glTF 2.0 §3.5.3: the nodes form disjoint strict trees; no node is the child of two.
    if (const json* nodes = find(doc_, "nodes")) {
      std::vector<std::string> parent_of(nodes->size());
      for (size_t ni = 0; ni < nodes->size(); ++ni)
        if (const json* ch = find((*nodes)[ni], "children"))
          for (size_t i = 0; i < ch->size(); ++i) {
            const auto c = (*ch)[i].get<size_t>();
            const std::string here = fmt::format("/nodes/{}/children/{}", ni, i);
            if (!parent_of[c].empty())
              fail(here, fmt::format("node {} is already a child at {}; a glTF node has one parent at most", c,
                                     parent_of[c]));
            parent_of[c] = here;
          }
    }

    each(doc_, "skins", "", [&](const json& sk, const std::string& p) {
      const json* joints = member(sk, "joints", p, true);
      require_array(*joints, p + "/joints");
      if (joints->empty()) fail(p + "/joints", "is empty; glTF requires a skin to have at least one joint");
      for (size_t i = 0; i < joints->size(); ++i) index((*joints)[i], fmt::format("{}/joints/{}", p, i), "nodes");
      opt_index(sk, "inverseBindMatrices", p, "accessors");
      opt_index(sk, "skeleton", p, "nodes");
    });

    each(doc_, "meshes", "", [&](const json& m, const std::string& p) {
      const json* prims = member(m, "primitives", p, true);
      require_array(*prims, p + "/primitives");
      each(m, "primitives", p, [&](const json& prim, const std::string& pp) {
        const json* attrs = member(prim, "attributes", pp, true);
        require_object(*attrs, pp + "/attributes");
        for (auto it = attrs->begin(); it != attrs->end(); ++it)
          index(it.value(), pp + "/attributes/" + it.key(), "accessors");
        opt_index(prim, "indices", pp, "accessors");
        opt_index(prim, "material", pp, "materials");
        opt_integer(prim, "mode", pp, 0, 6);
        each(prim, "targets", pp, [&](const json& t, const std::string& tp) {
          for (auto it = t.begin(); it != t.end(); ++it) index(it.value(), tp + "/" + it.key(), "accessors");
        });
      });
    });

    each(doc_, "accessors", "", [&](const json& a, const std::string& p) {
      opt_index(a, "bufferView", p, "bufferViews");
      opt_integer(a, "byteOffset", p);
      const uint64_t ct = integer(*member(a, "componentType", p, true), p + "/componentType");
      if (ct != 5120 && ct != 5121 && ct != 5122 && ct != 5123 && ct != 5125 && ct != 5126)
        fail(p + "/componentType",
             fmt::format("{} is not a glTF component type (5120 BYTE, 5121 UNSIGNED_BYTE, 5122 SHORT, "
                         "5123 UNSIGNED_SHORT, 5125 UNSIGNED_INT, 5126 FLOAT)", ct));
      opt_bool(a, "normalized", p);
      if (const json* nm = find(a, "normalized"); nm && nm->get<bool>() && (ct == 5126 || ct == 5125))
        fail(p + "/normalized", fmt::format("is true for component type {}; only 8- and 16-bit integers are "
                                            "normalized",
                                            ct == 5126 ? "FLOAT" : "UNSIGNED_INT"));
      opt_integer(a, "count", p, 1, (uint64_t{1} << 53), true);
      const std::string& type = string(*member(a, "type", p, true), p + "/type");
      if (type != "SCALAR" && type != "VEC2" && type != "VEC3" && type != "VEC4" && type != "MAT2" &&
          type != "MAT3" && type != "MAT4")
        fail(p + "/type", fmt::format("'{}' is not a glTF accessor type (SCALAR, VEC2..4, MAT2..4)", type));
      if (const json* sp = member(a, "sparse", p)) {
        // The reader keeps a sparse count and its byte offsets in 32-bit signed integers; a larger
        // value would be cut to another one silently.
        constexpr uint64_t kSparseMax = 0x7FFFFFFF;
        const std::string sp_path = p + "/sparse";
        require_object(*sp, sp_path);
        opt_integer(*sp, "count", sp_path, 1, kSparseMax, true);
        const json* idx = member(*sp, "indices", sp_path, true);
        require_object(*idx, sp_path + "/indices");
        opt_index(*idx, "bufferView", sp_path + "/indices", "bufferViews", true);
        opt_integer(*idx, "byteOffset", sp_path + "/indices", 0, kSparseMax);
        const uint64_t ict = integer(*member(*idx, "componentType", sp_path + "/indices", true),
                                     sp_path + "/indices/componentType");
        if (ict != 5121 && ict != 5123 && ict != 5125)
          fail(sp_path + "/indices/componentType",
               fmt::format("{} is not an index type (5121, 5123, 5125)", ict));
        const json* val = member(*sp, "values", sp_path, true);
        require_object(*val, sp_path + "/values");
        opt_index(*val, "bufferView", sp_path + "/values", "bufferViews", true);
        opt_integer(*val, "byteOffset", sp_path + "/values", 0, kSparseMax);
      }
    });

    each(doc_, "buffers", "", [&](const json& b, const std::string& p) {
      opt_string(b, "uri", p);
      opt_integer(b, "byteLength", p, 1, (uint64_t{1} << 53), true);
    });

    // The attributes' accessor types, now that the accessors are known to be well formed.
    each(doc_, "meshes", "", [&](const json& m, const std::string& p) {
      each(m, "primitives", p, [&](const json& prim, const std::string& pp) {
        const json& attrs = *find(prim, "attributes");
        for (auto it = attrs.begin(); it != attrs.end(); ++it) attribute_type(it.key(), it.value(), pp);
      });
    });
    // The same for EXT_mesh_gpu_instancing's attributes (their indices were checked with the nodes).
    each(doc_, "nodes", "", [&](const json& n, const std::string& p) {
      const json* ext = find(n, "extensions");
      const json* inst = ext ? find(*ext, "EXT_mesh_gpu_instancing") : nullptr;
      if (!inst) return;
      const bool quantized = uses("KHR_mesh_quantization");
      const std::initializer_list<uint64_t> none{}, small{5120, 5121, 5122, 5123};
      for (const auto& [name, accessor] : find(*inst, "attributes")->items()) {
        const std::string where = p + "/extensions/EXT_mesh_gpu_instancing/attributes/" + name;
        if (name == "ROTATION")
          typed_accessor(accessor, where, "VEC4", true, {5120, 5122}, none,
                         "of FLOAT (5126), or of normalized BYTE (5120) or SHORT (5122)");
        else if (name == "TRANSLATION" || name == "SCALE")
          typed_accessor(accessor, where, "VEC3", true, quantized ? small : none, quantized ? small : none,
                         "of FLOAT (5126), or of 8- or 16-bit integers with KHR_mesh_quantization");
      }
    });

    each(doc_, "bufferViews", "", [&](const json& v, const std::string& p) {
      opt_index(v, "buffer", p, "buffers", true);
      opt_integer(v, "byteOffset", p);
      opt_integer(v, "byteLength", p, 1, (uint64_t{1} << 53), true);
      opt_integer(v, "byteStride", p, 4, 252);
      if (const json* st = find(v, "byteStride"); st && st->get<uint64_t>() % 4 != 0)
        fail(p + "/byteStride", fmt::format("{} is not a multiple of 4", st->get<uint64_t>()));
      opt_integer(v, "target", p);
      // The view lies within its buffer's declared length (both were checked above).
      const auto offset = find(v, "byteOffset") ? find(v, "byteOffset")->get<uint64_t>() : uint64_t{0};
      const auto length = find(v, "byteLength")->get<uint64_t>();
      const json& buffer = (*find(doc_, "buffers"))[find(v, "buffer")->get<size_t>()];
      const auto size = find(buffer, "byteLength")->get<uint64_t>();
      if (offset > size || length > size - offset)
        fail(p, fmt::format("bytes [{}, {}) lie outside buffer {} of {} bytes", offset, offset + length,
                            find(v, "buffer")->get<size_t>(), size));
    });

    // Accessors start at a multiple of their component size, in the view and in the buffer.
    each(doc_, "accessors", "", [&](const json& a, const std::string& p) {
      const json* view = find(a, "bufferView");
      if (!view) return;
      const uint64_t ct = find(a, "componentType")->get<uint64_t>();
      const uint64_t size = ct == 5120 || ct == 5121 ? 1 : ct == 5122 || ct == 5123 ? 2 : 4;
      const uint64_t offset = find(a, "byteOffset") ? find(a, "byteOffset")->get<uint64_t>() : 0;
      const json& bv = (*find(doc_, "bufferViews"))[view->get<size_t>()];
      const uint64_t view_offset = find(bv, "byteOffset") ? find(bv, "byteOffset")->get<uint64_t>() : 0;
      if (offset % size != 0 || (view_offset + offset) % size != 0)
        fail(p + "/byteOffset", fmt::format("the accessor starts at byte {} of its buffer (bufferView {} at {}, plus "
                                            "{}), not a multiple of its component size {}",
                                            view_offset + offset, view->get<size_t>(), view_offset, offset, size));
    });

    each(doc_, "materials", "", [&](const json& m, const std::string& p) {
      if (const json* pbr = member(m, "pbrMetallicRoughness", p)) {
        const std::string pp = p + "/pbrMetallicRoughness";
        require_object(*pbr, pp);
        opt_number_array_in(*pbr, "baseColorFactor", pp, 4, 0.0, 1.0, "glTF colour factors are linear, 0..1");
        for (const char* f : {"metallicFactor", "roughnessFactor"})
          if (const json* v = member(*pbr, f, pp)) number_in(*v, pp + "/" + f, 0.0, 1.0, "glTF factors are 0..1");
        texture_info(*pbr, "baseColorTexture", pp);
        texture_info(*pbr, "metallicRoughnessTexture", pp);
      }
      texture_info(m, "normalTexture", p);
      texture_info(m, "occlusionTexture", p);
      texture_info(m, "emissiveTexture", p);
      opt_number_array_in(m, "emissiveFactor", p, 3, 0.0, 1.0, "glTF colour factors are linear, 0..1");
      opt_bool(m, "doubleSided", p);
      opt_string(m, "alphaMode", p);
      if (const json* mode = find(m, "alphaMode")) {
        const std::string& text = mode->get_ref<const std::string&>();
        if (text != "OPAQUE" && text != "MASK" && text != "BLEND")
          fail(p + "/alphaMode", fmt::format("is \"{}\"; glTF allows OPAQUE, MASK or BLEND", text));
      }
      if (const json* cutoff = member(m, "alphaCutoff", p))
        if (number(*cutoff, p + "/alphaCutoff") < 0.0)
          fail(p + "/alphaCutoff", fmt::format("value {:g} is negative; glTF alphaCutoff is at least 0", cutoff->get<double>()));
    });

    each(doc_, "textures", "", [&](const json& t, const std::string& p) {
      opt_index(t, "source", p, "images");
      opt_index(t, "sampler", p, "samplers");
    });

    each(doc_, "images", "", [&](const json& im, const std::string& p) {
      opt_string(im, "uri", p);
      opt_index(im, "bufferView", p, "bufferViews");
      opt_string(im, "mimeType", p);
      if (!find(im, "uri") && !find(im, "bufferView"))
        fail(p, "image has neither 'uri' nor 'bufferView'");
      if (find(im, "uri") && find(im, "bufferView"))
        fail(p, "image has both 'uri' and 'bufferView'; give one");
      if (find(im, "bufferView") && !find(im, "mimeType"))
        fail(p + "/mimeType", "is required for an image in a bufferView (image/png or image/jpeg)");
    });

    each(doc_, "animations", "", [&](const json& a, const std::string& p) {
      const json* samplers = member(a, "samplers", p, true);
      require_array(*samplers, p + "/samplers");
      each(a, "samplers", p, [&](const json& s, const std::string& sp) {
        opt_index(s, "input", sp, "accessors", true);
        opt_index(s, "output", sp, "accessors", true);
        opt_string(s, "interpolation", sp);
      });
      require_array(*member(a, "channels", p, true), p + "/channels");
      each(a, "channels", p, [&](const json& c, const std::string& cp) {
        const uint64_t sampler = integer(*member(c, "sampler", cp, true), cp + "/sampler");
        if (sampler >= samplers->size())
          fail(cp + "/sampler", fmt::format("refers to sampler {} but the animation has {}", sampler, samplers->size()));
        const json& target = require_object(*member(c, "target", cp, true), cp + "/target");
        opt_index(target, "node", cp + "/target", "nodes");
        opt_string(target, "path", cp + "/target", true);
      });
    });

    each(doc_, "samplers", "", [&](const json& s, const std::string& p) {
      // glTF 2.0 §5.26's enums (the reader cuts other values to 32 bits and may meet one of them).
      const auto one_of = [&](const char* key, std::initializer_list<uint64_t> allowed, const char* names) {
        if (const json* v = member(s, key, p)) {
          const uint64_t x = integer(*v, p + "/" + key);
          if (std::find(allowed.begin(), allowed.end(), x) == allowed.end())
            fail(p + "/" + key, fmt::format("{} is not one of {}", x, names));
        }
      };
      one_of("magFilter", {9728, 9729}, "9728 NEAREST, 9729 LINEAR");
      one_of("minFilter", {9728, 9729, 9984, 9985, 9986, 9987},
             "9728 NEAREST, 9729 LINEAR, 9984..9987 the mipmap filters");
      one_of("wrapS", {33071, 33648, 10497}, "33071 CLAMP_TO_EDGE, 33648 MIRRORED_REPEAT, 10497 REPEAT");
      one_of("wrapT", {33071, 33648, 10497}, "33071 CLAMP_TO_EDGE, 33648 MIRRORED_REPEAT, 10497 REPEAT");
    });

    each(doc_, "cameras", "", [&](const json& c, const std::string& p) {
      const std::string& type = string(*member(c, "type", p, true), p + "/type");
      if (type == "perspective") {
        const json* per = member(c, "perspective", p, true);
        const std::string pp = p + "/perspective";
        require_object(*per, pp);
        const double yfov = number(*member(*per, "yfov", pp, true), pp + "/yfov");
        if (yfov <= 0.0 || yfov >= 3.14159265358979)
          fail(pp + "/yfov", fmt::format("vertical field of view {} rad is outside (0, pi)", yfov));
        const double znear = number(*member(*per, "znear", pp, true), pp + "/znear");
        if (znear <= 0.0) fail(pp + "/znear", fmt::format("znear {} must be positive", znear));
        if (const json* ar = member(*per, "aspectRatio", pp))
          if (number(*ar, pp + "/aspectRatio") <= 0.0) fail(pp + "/aspectRatio", "must be positive");
        if (const json* zf = member(*per, "zfar", pp))
          if (number(*zf, pp + "/zfar") <= znear) fail(pp + "/zfar", "must be greater than znear");
      } else if (type == "orthographic") {
        const std::string op = p + "/orthographic";
        const json& o = require_object(*member(c, "orthographic", p, true), op);
        for (const char* k : {"xmag", "ymag"})
          if (number(*member(o, k, op, true), op + "/" + k) == 0.0) fail(op + "/" + k, "must not be zero");
        const double znear = number(*member(o, "znear", op, true), op + "/znear");
        if (znear < 0.0) fail(op + "/znear", fmt::format("znear {} must not be negative", znear));
        if (number(*member(o, "zfar", op, true), op + "/zfar") <= znear)
          fail(op + "/zfar", "must be greater than znear");
      } else {
        fail(p + "/type", fmt::format("'{}' is not a camera type (perspective, orthographic)", type));
      }
    });

    if (const json* ext = member(doc_, "extensions", "")) {
      require_object(*ext, "/extensions");
      if (const json* khr = find(*ext, "KHR_lights_punctual")) {
        const std::string kp = "/extensions/KHR_lights_punctual";
        require_object(*khr, kp);
        each(*khr, "lights", kp, [&](const json& l, const std::string& p) {
          const std::string& type = string(*member(l, "type", p, true), p + "/type");
          if (type != "point" && type != "directional" && type != "spot")
            fail(p + "/type", fmt::format("'{}' is not a light type (point, directional, spot)", type));
          opt_string(l, "name", p);
          opt_number_array_in(l, "color", p, 3, 0.0, 1.0, "KHR_lights_punctual colours are linear RGB, 0..1");
          // Shading is in single precision: an intensity beyond a float's range is infinite there.
          if (const json* i = member(l, "intensity", p))
            number_in(*i, p + "/intensity", 0.0, 1e30,
                      "candela for point and spot lights, lux for directional ones; not negative, and within "
                      "single precision");
          if (const json* r = member(l, "range", p))
            if (number(*r, p + "/range") <= 0.0) fail(p + "/range", "must be positive");
          if (type == "spot") {
            const json* s = member(l, "spot", p, true);
            require_object(*s, p + "/spot");
            // KHR_lights_punctual: 0 <= inner < outer <= pi/2 (defaults 0 and pi/4).
            constexpr double kHalfPi = 1.5707963267948966;
            double inner = 0.0, outer = kHalfPi / 2.0;
            if (const json* i = member(*s, "innerConeAngle", p + "/spot"))
              inner = number_in(*i, p + "/spot/innerConeAngle", 0.0, kHalfPi, "radians from the spot's axis");
            if (const json* o = member(*s, "outerConeAngle", p + "/spot"))
              outer = number_in(*o, p + "/spot/outerConeAngle", 0.0, kHalfPi, "radians from the spot's axis");
            if (!(inner < outer))
              fail(p + "/spot",
                   fmt::format("innerConeAngle {:g} must be less than outerConeAngle {:g} (radians), as glTF requires; "
                               "give the spot a soft edge (Blender: a Spot Blend above 0) or lower innerConeAngle",
                               inner, outer));
          }
        });
      }
    }
  }

 private:
  const json& doc_;
  std::string file_;
};

}  // namespace

const std::vector<std::string>& supported_gltf_extensions() {
  static const std::vector<std::string> supported = {"EXT_mesh_gpu_instancing", "KHR_lights_punctual",
                                                     "KHR_mesh_quantization", "KHR_texture_transform"};
  return supported;
}

void check_gltf_json(const nlohmann::json& doc, const std::string& file) { Checker(doc, file).run(); }

}  // namespace sb::io
