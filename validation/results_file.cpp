// Appending, reading, merging and exporting sweep results files.
#include "validation/results_file.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string_view>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/json_text.hpp"
#include "renderer/io/unique_fd.hpp"
#include "validation/metrics.hpp"
#include "validation/sweep.hpp"

namespace sb::validation {

namespace fs = std::filesystem;
using nlohmann::json;

json finite_json(const json& value) {
  if (value.is_number_float()) {
    const double v = value.get<double>();
    if (std::isnan(v)) return nullptr;
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    return value;
  }
  if (value.is_object()) {
    json out = json::object();
    for (auto it = value.begin(); it != value.end(); ++it) out[it.key()] = finite_json(it.value());
    return out;
  }
  if (value.is_array()) {
    json out = json::array();
    for (const json& item : value) out.push_back(finite_json(item));
    return out;
  }
  return value;
}

namespace {

std::string line_of(const json& cell) {
  return io::json_text(finite_json(cell)) + "\n";
}

[[noreturn]] void io_fail(const fs::path& file, const char* what, const char* kind = "results file") {
  throw IoError(fmt::format("{}: cannot {} the {}: {}; check the folder's permissions and free space", file.string(),
                            what, kind, std::strerror(errno)));
}

/// The hidden lock file beside a results file.
fs::path lock_path(const fs::path& results) {
  return results.parent_path() / ("." + results.filename().string() + ".lock");
}

/// Cuts an unterminated tail (a line torn by a killed writer) so that the next line starts on a
/// line of its own. The caller holds the exclusive lock.
void cut_torn_tail(int fd, const fs::path& file, const char* kind) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) io_fail(file, "inspect", kind);
  off_t end = st.st_size;
  if (end == 0) return;
  char last = 0;
  if (::pread(fd, &last, 1, end - 1) != 1) io_fail(file, "read", kind);
  if (last == '\n') return;
  // Scan back for the last line break.
  char buf[4096];
  off_t keep = 0;
  for (off_t pos = end; pos > 0 && keep == 0;) {
    const off_t start = std::max<off_t>(0, pos - static_cast<off_t>(sizeof buf));
    const ssize_t n = ::pread(fd, buf, static_cast<size_t>(pos - start), start);
    if (n != pos - start) io_fail(file, "read", kind);
    for (ssize_t i = n - 1; i >= 0; --i)
      if (buf[i] == '\n') {
        keep = start + i + 1;
        break;
      }
    pos = start;
  }
  if (::ftruncate(fd, keep) != 0) io_fail(file, "truncate a torn line of", kind);
}

std::string field(const json& v) {
  if (v.is_null()) return "";
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number_float()) return fmt::format("{}", v.get<double>());
  return v.dump();
}

std::string csv_quote(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

/// What a field may hold.
enum class Kind {
  object,
  object_or_null,
  array,
  string,
  integer,
  number,
  metric,
  number_or_null,
  integer_or_null,
  string_or_null
};

const char* describe(Kind k) {
  switch (k) {
    case Kind::object: return "an object";
    case Kind::object_or_null: return "an object or null";
    case Kind::array: return "an array";
    case Kind::string: return "a string";
    case Kind::integer: return "an integer";
    case Kind::number: return "a number";
    case Kind::metric: return "a number, \"inf\" or null";
    case Kind::number_or_null: return "a number or null";
    case Kind::integer_or_null: return "an integer or null";
    case Kind::string_or_null: return "a string or null";
  }
  return "?";
}

bool matches(const json& v, Kind k) {
  switch (k) {
    case Kind::object: return v.is_object();
    case Kind::object_or_null: return v.is_object() || v.is_null();
    case Kind::array: return v.is_array();
    case Kind::string: return v.is_string();
    case Kind::integer: return v.is_number_integer();
    case Kind::number: return v.is_number();
    case Kind::metric: return v.is_number() || v.is_null() || (v.is_string() && (v == "inf" || v == "-inf"));
    case Kind::number_or_null: return v.is_number() || v.is_null();
    case Kind::integer_or_null: return v.is_number_integer() || v.is_null();
    case Kind::string_or_null: return v.is_string() || v.is_null();
  }
  return false;
}

/// The value at a dotted path ("cell.scene"), or nullptr when a step is missing.
const json* find(const json& root, std::string_view dotted) {
  const json* at = &root;
  while (!dotted.empty()) {
    const size_t dot = dotted.find('.');
    const std::string key(dotted.substr(0, dot));
    if (!at->is_object()) return nullptr;
    const auto it = at->find(key);
    if (it == at->end()) return nullptr;
    at = &*it;
    dotted = dot == std::string_view::npos ? std::string_view() : dotted.substr(dot + 1);
  }
  return at;
}

/// Checks a field; `prefix` names the enclosing object for the message ("pipelines.repro-rt.").
void require(const json& root, const std::string& where, const std::string& prefix, std::string_view dotted,
             Kind kind, bool optional = false) {
  const json* v = find(root, dotted);
  if (v == nullptr) {
    if (optional) return;
    throw InputError(fmt::format("{}: field '{}{}' is missing; the line is not a sweep cell record (docs/sweeps.md)",
                                 where, prefix, dotted));
  }
  if (!matches(*v, kind))
    throw InputError(fmt::format("{}: field '{}{}' is {} but must be {}", where, prefix, dotted,
                                 v->dump().substr(0, 80), describe(kind)));
}

/// Checks that a numeric field, where present, lies in [lo, hi] (a metric or time no measurement
/// gives marks a damaged or hand-edited line); the metric strings "inf" and "-inf" count as
/// infinities. Other types are left to `require`.
void require_within(const json& root, const std::string& where, const std::string& prefix, std::string_view dotted,
                    double lo, double hi) {
  const json* v = find(root, dotted);
  if (v == nullptr || !(v->is_number() || *v == "inf" || *v == "-inf")) return;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const double x = v->is_number() ? v->get<double>() : *v == "inf" ? kInf : -kInf;
  if (!(x >= lo && x <= hi))
    throw InputError(fmt::format("{}: field '{}{}' is {}, outside [{}, {}] where every measurement lies; the line is "
                                 "damaged or edited by hand",
                                 where, prefix, dotted, v->dump(), lo, hi));
}

/// Checks that every member of an object of stage times (stage -> seconds), where present, is a
/// time no measurement is outside of: a number in [0, max]. The object itself is `require`d.
void require_times(const json& root, const std::string& where, const std::string& prefix, std::string_view dotted) {
  const json* v = find(root, dotted);
  if (v == nullptr || !v->is_object()) return;
  for (const auto& [stage, t] : v->items())
    if (!t.is_number() || !(t.get<double>() >= 0.0 && t.get<double>() <= std::numeric_limits<double>::max()))
      throw InputError(fmt::format("{}: field '{}{}.{}' holds {}, not a time in seconds; the line is damaged or "
                                   "edited by hand",
                                   where, prefix, dotted, stage, t.dump().substr(0, 80)));
}

/// PSNR is a function of MSE on 8-bit codes (10 log10(255^2 / MSE), inf where MSE is 0, null where
/// it is null): a line whose two disagree (a PSNR of "inf" beside an MSE of 0.5) is damaged or
/// edited by hand, and the gate would judge the PSNR. Checked where both are present.
void require_psnr_of_mse(const json& root, const std::string& where, const std::string& prefix,
                         const std::string& metrics) {
  const json* psnr = find(root, metrics + ".psnr");
  const json* mse = find(root, metrics + ".mse");
  if (psnr == nullptr || mse == nullptr) return;
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const double expected = mse->is_number() ? psnr_from_mse(mse->get<double>()) : kNaN;
  const double given = psnr->is_number() ? psnr->get<double>() : *psnr == "inf" ? kInf : *psnr == "-inf" ? -kInf : kNaN;
  const bool agree = std::isnan(expected) ? std::isnan(given)
                     : std::isinf(expected)
                         ? given == expected
                         : std::isfinite(given) && std::abs(given - expected) <= 1e-6 * std::max(1.0, expected);
  if (!agree)
    throw InputError(fmt::format("{}: field '{}{}.psnr' is {}, but its mse {} gives {}; the line is damaged or edited "
                                 "by hand",
                                 where, prefix, metrics, psnr->dump(), mse->dump(),
                                 std::isnan(expected) ? std::string("null")
                                 : std::isinf(expected) ? std::string("\"inf\"")
                                                        : fmt::format("{:.6f}", expected)));
}

/// The metrics at `metrics` (psnr, ssim, an optional mse): each a number, "inf" or null, within what a
/// measurement gives (on 8-bit codes MSE is at most 255^2, so PSNR = 10 log10(255^2 / MSE) is at
/// least 0, inf when equal), the PSNR the one its MSE gives.
void require_metrics(const json& root, const std::string& where, const std::string& prefix, const std::string& metrics) {
  for (const char* m : {"psnr", "ssim", "mse"})
    require(root, where, prefix, metrics + "." + m, Kind::metric, m == std::string("mse"));
  require_within(root, where, prefix, metrics + ".psnr", 0.0, std::numeric_limits<double>::infinity());
  require_within(root, where, prefix, metrics + ".ssim", -1.0, 1.0);
  require_within(root, where, prefix, metrics + ".mse", 0.0, 255.0 * 255.0);
  require_psnr_of_mse(root, where, prefix, metrics);
}

/// A field of a results line: its dotted path, what it may hold, whether it may be absent.
struct Field {
  const char* path;
  Kind kind;
  bool optional = false;
};

/// The fields of a cell, in the order they are checked (a container before its members).
constexpr Field kCellFields[] = {
    {"sweep", Kind::string},
    {"definition_sha256", Kind::string, true},
    {"wall_s", Kind::number_or_null, true},
    {"cell_id", Kind::string},
    {"cell_index", Kind::integer},
    {"cell_count", Kind::integer, true},
    {"cell", Kind::object},
    {"cell.scene", Kind::string},
    {"cell.resolution", Kind::string_or_null},  // null: the scene's own size (no resolutions axis)
    {"cell.truth", Kind::string},
    {"cell.lights", Kind::integer_or_null, true},
    {"rig", Kind::object},
    {"rig.width", Kind::integer},
    {"rig.height", Kind::integer},
    {"rig.interaxial_m", Kind::number},
    {"rig.convergence_m", Kind::number},
    {"rig.max_disparity_px", Kind::number},
    {"scene.triangles", Kind::integer_or_null, true},
    {"out", Kind::string, true},
    {"shard", Kind::object, true},
    {"shard.index", Kind::integer, true},
    {"shard.count", Kind::integer, true},
    {"baseline", Kind::string},
    {"pipelines", Kind::object},
};

/// The fields of each entry of `pipelines`.
constexpr Field kPipelineFields[] = {
    {"validation", Kind::object},
    {"validation.metrics.psnr", Kind::metric},
    {"validation.metrics.ssim", Kind::metric},
    {"validation.metrics.mse", Kind::metric},
    {"validation.metrics.error_fraction", Kind::metric},
    {"validation.holes.hole_fraction", Kind::number_or_null},
    {"validation.holes.not_reprojected.recall", Kind::number_or_null, true},
    {"validation.holes.not_reprojected.precision", Kind::number_or_null, true},
    {"validation.total_s", Kind::number_or_null, true},
    {"validation.timings_s", Kind::object, true},
    {"validation.scene.triangles", Kind::integer_or_null, true},
    {"timing", Kind::object, true},
};

/// The value at a dotted path, or null when a step is missing.
json value_at(const json& root, std::string_view dotted) {
  const json* v = find(root, dotted);
  return v ? *v : json(nullptr);
}

}  // namespace

ResultsWriterLock::ResultsWriterLock(const fs::path& results, const std::vector<size_t>& cells) {
  std::error_code ec;
  if (results.has_parent_path() && !fs::is_directory(results.parent_path(), ec)) {
    fs::create_directories(results.parent_path(), ec);
    if (ec || !fs::is_directory(results.parent_path()))
      throw IoError(fmt::format("cannot create the folder {} of the results file {}: {}; give --out (or --results) "
                                "a folder you can write",
                                results.parent_path().string(), results.string(),
                                ec ? ec.message() : "a file of that name is in the way"));
  }
  // Through links to the file itself, so that two spellings of one results file share the lock.
  const fs::path real = fs::weakly_canonical(fs::absolute(io::follow_links(results), ec), ec);
  const fs::path path = lock_path(ec ? results : real);
  fd_.reset(::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666));  // the umask decides
  if (!fd_.valid())
    throw IoError(fmt::format("cannot open {}, the lock file of {}: {}; give --out (or --results) a folder you can "
                              "write",
                              path.string(), results.string(), std::strerror(errno)));
  for (const size_t cell : cells) {
    struct flock lock {};
    lock.l_type = F_WRLCK;
    lock.l_whence = SEEK_SET;
    lock.l_start = static_cast<off_t>(cell);
    lock.l_len = 1;
    if (::fcntl(fd_.get(), F_OFD_SETLK, &lock) == 0) continue;
    const int err = errno;
    fd_.reset();
    if (err != EAGAIN && err != EACCES)
      throw IoError(fmt::format("{}: cannot lock it: {}", path.string(), std::strerror(err)));
    throw InputError(fmt::format("{} is being written by another stereobench run, which holds cell {} of this run; "
                                 "two runs would record those cells twice: wait for it to end, or give another --out "
                                 "(or --results)",
                                 results.string(), cell));
  }
}

namespace {

/// The results file opened for appending, it and its folder created when missing.
io::UniqueFd open_for_append(const fs::path& file, const char* kind) {
  std::error_code ec;
  if (file.has_parent_path()) fs::create_directories(file.parent_path(), ec);
  io::UniqueFd fd(::open(file.c_str(), O_RDWR | O_APPEND | O_CREAT | O_CLOEXEC, 0666));  // the umask decides
  if (fd.get() < 0) io_fail(file, "open", kind);
  return fd;
}

}  // namespace

void create_results_file(const fs::path& file, const char* kind) {
  const io::UniqueFd fd = open_for_append(file, kind);
  if (::fsync(fd.get()) != 0) io_fail(file, "flush", kind);
}

void append_result(const fs::path& file, const json& cell, const char* kind) {
  const std::string line = line_of(cell);
  const io::UniqueFd fd = open_for_append(file, kind);
  if (::flock(fd.get(), LOCK_EX) != 0) io_fail(file, "lock", kind);
  cut_torn_tail(fd.get(), file, kind);
  // One write of the whole line; a short write is completed, and a failed one (a full disk) is
  // undone, so that no part of the line stays behind.
  const off_t before = ::lseek(fd.get(), 0, SEEK_END);
  const auto fail = [&](const char* what) {
    const int saved = errno;
    if (before >= 0) (void)!::ftruncate(fd.get(), before);
    errno = saved;
    io_fail(file, what, kind);
  };
  size_t done = 0;
  while (done < line.size()) {
    const ssize_t n = ::write(fd.get(), line.data() + done, line.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail("append to");
    done += static_cast<size_t>(n);
  }
  if (::fsync(fd.get()) != 0) fail("flush");
  (void)::flock(fd.get(), LOCK_UN);
}

void read_json_lines(const fs::path& file, const std::string& torn_note, const std::string& parse_hint,
                     std::vector<std::string>& warnings,
                     const std::function<void(json&& line, size_t line_no, const std::string& where)>& take) {
  std::error_code ec;
  if (!fs::exists(file, ec)) return;
  const std::string text = io::read_file(file);
  size_t start = 0, line_no = 0;
  while (start < text.size()) {
    ++line_no;
    const size_t nl = text.find('\n', start);
    if (nl == std::string::npos) {
      warnings.push_back(fmt::format("{}:{}: unterminated last line {}", file.string(), line_no, torn_note));
      break;
    }
    const std::string line = text.substr(start, nl - start);
    start = nl + 1;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::string where = fmt::format("{}:{}", file.string(), line_no);
    json parsed;
    try {
      parsed = io::parse_json(line);
    } catch (const io::JsonTextError& e) {
      throw InputError(fmt::format("{}: not a JSON line ({}); {}", where, e.what(), parse_hint));
    }
    take(std::move(parsed), line_no, where);
  }
}

void check_cell_record(const json& line, const std::string& where) {
  if (!line.is_object())
    throw InputError(fmt::format("{}: a results line must be a JSON object, not {}", where, line.type_name()));
  require(line, where, "", "kind", Kind::string);
  if (line["kind"] != kSweepCellKind)
    throw InputError(fmt::format("{}: kind is {} but a results file holds \"{}\" records", where,
                                 line["kind"].dump(), kSweepCellKind));
  require(line, where, "", "schema_version", Kind::integer);
  const long long version = line["schema_version"].get<long long>();
  if (version > kSweepSchemaVersion)
    throw InputError(fmt::format("{}: schema_version {} is newer than this stereobench reads ({}); use the "
                                 "stereobench that wrote the file",
                                 where, version, kSweepSchemaVersion));
  if (version != kSweepSchemaVersion)
    throw InputError(fmt::format("{}: schema_version {} is not a known version (expected {})", where, version,
                                 kSweepSchemaVersion));
  for (const Field& f : kCellFields) require(line, where, "", f.path, f.kind, f.optional);
  require_within(line, where, "", "wall_s", 0.0, std::numeric_limits<double>::max());
  if (line["cell_id"].get<std::string>().empty()) throw InputError(fmt::format("{}: cell_id is empty", where));
  // The gate keys baselines and rule globs by the id and reads the scene from the fields: the two
  // must tell the same cell.
  std::optional<std::string> id;
  try {
    id = cell_id_from_json(line["cell"]);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}; the line is damaged or edited by hand", where, e.what()));
  }
  if (id && *id != line["cell_id"])
    throw InputError(fmt::format("{}: cell_id {} does not match the cell's fields, which give \"{}\"; the line is "
                                 "damaged or edited by hand",
                                 where, line["cell_id"].dump(), *id));
  if (line["cell_index"].get<long long>() < 0)
    throw InputError(fmt::format("{}: cell_index {} is negative; cells are numbered from 0", where,
                                 line["cell_index"].dump()));
  if (line.contains("cell_count") && line["cell_index"].get<long long>() >= line["cell_count"].get<long long>())
    throw InputError(fmt::format("{}: cell_index {} is not below cell_count {}; the line is damaged or edited by hand",
                                 where, line["cell_index"].dump(), line["cell_count"].dump()));
  if (const auto shard = line.find("shard"); shard != line.end()) {
    const json index = shard->value("index", json()), count = shard->value("count", json());
    if (!index.is_number_unsigned() || !count.is_number_unsigned() || index.get<uint64_t>() >= count.get<uint64_t>() ||
        line["cell_index"].get<uint64_t>() % count.get<uint64_t>() != index.get<uint64_t>())
      throw InputError(fmt::format("{}: shard {} is not a shard I/N (0 <= I < N) that holds cell_index {}; the line is "
                                   "damaged or edited by hand",
                                   where, shard->dump(), line["cell_index"].dump()));
  }
  for (const char* f : {"rig.interaxial_m", "rig.convergence_m", "rig.max_disparity_px"})
    if (const double x = find(line, f)->get<double>(); !(x > 0.0 && std::isfinite(x)))
      throw InputError(fmt::format("{}: field '{}' is {}; a rig's interaxial, convergence and max disparity are "
                                   "positive; the line is damaged or edited by hand",
                                   where, f, find(line, f)->dump()));
  if (line["rig"]["width"].get<long long>() <= 0 || line["rig"]["height"].get<long long>() <= 0)
    throw InputError(fmt::format("{}: rig.width and rig.height must be positive, not {}x{}", where,
                                 line["rig"]["width"].dump(), line["rig"]["height"].dump()));
  const json& pipelines = line["pipelines"];
  if (pipelines.empty())
    throw InputError(fmt::format("{}: 'pipelines' is empty; a cell validates at least one", where));
  if (!pipelines.contains(line["baseline"].get<std::string>()))
    throw InputError(fmt::format("{}: baseline {} is not among the cell's pipelines", where, line["baseline"].dump()));
  for (const auto& [name, p] : pipelines.items()) {
    const std::string prefix = "pipelines." + name + ".";
    if (!p.is_object()) throw InputError(fmt::format("{}: field 'pipelines.{}' must be an object", where, name));
    for (const Field& f : kPipelineFields) require(p, where, prefix, f.path, f.kind, f.optional);
    constexpr double kMax = std::numeric_limits<double>::max();
    require_metrics(p, where, prefix, "validation.metrics");
    for (const char* f : {"validation.metrics.error_fraction", "validation.holes.hole_fraction",
                          "validation.holes.not_reprojected.recall", "validation.holes.not_reprojected.precision"})
      require_within(p, where, prefix, f, 0.0, 1.0);
    require_within(p, where, prefix, "validation.total_s", 0.0, kMax);
    require_times(p, where, prefix, "validation.timings_s");
    // A left eye synthesized in part is measured as the right eye is.
    require(p, where, prefix, "validation.left_eye", Kind::object_or_null, true);
    if (const json* left = find(p, "validation.left_eye"); left != nullptr && left->is_object())
      require_metrics(p, where, prefix, "validation.left_eye.metrics");
    // The metrics per region (reprojected, filled, true disocclusions), which the report shows.
    require(p, where, prefix, "validation.regions", Kind::object, true);
    if (const json* regions = find(p, "validation.regions"))
      for (const auto& [region, r] : regions->items()) {
        const std::string at = "validation.regions." + region;
        if (region.empty() || region.find('.') != std::string::npos)
          throw InputError(fmt::format("{}: field '{}validation.regions' names a region '{}', which no measurement "
                                       "gives; the line is damaged or edited by hand",
                                       where, prefix, region));
        if (!r.is_object())
          throw InputError(fmt::format("{}: field '{}{}' is {}, not a region's metrics (an object); the line is "
                                       "damaged or edited by hand",
                                       where, prefix, at, r.dump().substr(0, 80)));
        require(p, where, prefix, at + ".pixels", Kind::integer);
        require_within(p, where, prefix, at + ".pixels", 0.0, std::numeric_limits<double>::max());
        require_metrics(p, where, prefix, at);
      }
    if (p.contains("timing")) {
      for (const char* t : {"median_s", "min_s", "max_s", "speedup_median", "right_over_left_median"}) {
        require(p, where, prefix, std::string("timing.") + t, Kind::number_or_null, true);
        require_within(p, where, prefix, std::string("timing.") + t, 0.0, kMax);
      }
      require(p, where, prefix, "timing.repetitions", Kind::integer, true);
      if (const json* n = find(p, "timing.repetitions"); n != nullptr && n->get<long long>() < 1)
        throw InputError(fmt::format("{}: field '{}timing.repetitions' is {}, but a timed pipeline ran at least once; "
                                     "the line is damaged or edited by hand",
                                     where, prefix, n->dump()));
      require(p, where, prefix, "timing.samples_s", Kind::array, true);
      if (const json* samples = find(p, "timing.samples_s"))
        for (const json& t : *samples)
          if (!t.is_number() || !(t.get<double>() >= 0.0 && t.get<double>() <= kMax))
            throw InputError(fmt::format("{}: field '{}timing.samples_s' holds {}, not a time in seconds; the line is "
                                         "damaged or edited by hand",
                                         where, prefix, t.dump()));
      require(p, where, prefix, "timing.stages_median_s", Kind::object, true);
      require_times(p, where, prefix, "timing.stages_median_s");
      // min <= median <= max of the same samples.
      const json* lo = find(p, "timing.min_s");
      const json* mid = find(p, "timing.median_s");
      const json* hi = find(p, "timing.max_s");
      if (lo && mid && hi && lo->is_number() && mid->is_number() && hi->is_number() &&
          !(lo->get<double>() <= mid->get<double>() && mid->get<double>() <= hi->get<double>()))
        throw InputError(fmt::format("{}: fields '{}timing.min_s', 'median_s' and 'max_s' are {}, {} and {}, not in "
                                     "order; the line is damaged or edited by hand",
                                     where, prefix, lo->dump(), mid->dump(), hi->dump()));
      // Every repetition leaves one sample: the medians and the rank test are taken over them.
      const json* samples = find(p, "timing.samples_s");
      const json* repetitions = find(p, "timing.repetitions");
      if (samples && repetitions && static_cast<long long>(samples->size()) != repetitions->get<long long>())
        throw InputError(fmt::format("{}: field '{}timing.samples_s' holds {} time(s) but timing.repetitions is {}; "
                                     "the line is damaged or edited by hand",
                                     where, prefix, samples->size(), repetitions->dump()));
    }
  }
  require(line, where, "", "images", Kind::object_or_null, true);  // null: a sweep without images
  if (line.contains("images") && line["images"].is_object()) {
    for (const char* key : {"left_png", "truth_png", "disocclusions_png"})
      require(line, where, "", std::string("images.") + key, Kind::string_or_null, true);
    require(line, where, "", "images.pipelines", Kind::object, true);
    if (line["images"].contains("pipelines"))
      for (const auto& [name, imgs] : line["images"]["pipelines"].items()) {
        if (!imgs.is_object())
          throw InputError(fmt::format("{}: field 'images.pipelines.{}' must be an object", where, name));
        for (const auto& [key, v] : imgs.items())
          if (!v.is_string() && !v.is_null())
            throw InputError(fmt::format("{}: field 'images.pipelines.{}.{}' must be a path (string) or null", where,
                                         name, key));
      }
  }
}

std::vector<std::string> recorded_pipelines(const json& cell) {
  std::vector<std::string> names;
  if (const auto p = cell.find("pipelines"); p != cell.end() && p->is_object())
    for (const auto& [name, record] : p->items()) names.push_back(name);
  return names;
}

namespace {

/// Holds cells read one after another (one results file, or the shards collected into one) to one
/// sweep as one build ran it: the first cell's sweep and definition, pipelines and cell count, and
/// for each scene one content (a scene edited between shards would mix two scenes in one sweep).
class OneSweep {
 public:
  /// `where`: the cell's place in messages ("file:line"); `name`: how a later message names this
  /// cell's place when it is the first ("line 3", or the file).
  void check(const json& cell, const std::string& where, const std::string& name) {
    if (!first_) {
      first_ = cell;  // a copy: the caller's cells move
      first_name_ = name;
    }
    const json& first = *first_;
    if (cell["sweep"] != first["sweep"] ||
        cell.value("definition_sha256", "") != first.value("definition_sha256", ""))
      throw InputError(fmt::format(
          "{}: a cell of sweep '{}' (definition sha256 {}), but {} is of sweep '{}' (sha256 {}); a results file "
          "holds the cells of one sweep definition (the shards of one definition merge with `stereobench sweep "
          "collect`)",
          where, cell["sweep"].get<std::string>(), cell.value("definition_sha256", "?").substr(0, 12), first_name_,
          first["sweep"].get<std::string>(), first.value("definition_sha256", "?").substr(0, 12)));
    // Every cell of a definition validates every pipeline of it: a cell without one would let the
    // gate pass that pipeline there unchecked.
    if (recorded_pipelines(cell) != recorded_pipelines(first))
      throw InputError(fmt::format("{}: the cell validates pipelines {}, but {} of the same definition validates {}; "
                                   "every cell of a sweep validates every pipeline — cells run by builds with other "
                                   "pipelines (where the definition lists \"all\"), or a file edited by hand",
                                   where, fmt::join(recorded_pipelines(cell), ", "), first_name_,
                                   fmt::join(recorded_pipelines(first), ", ")));
    if (cell.value("cell_count", json()) != first.value("cell_count", json()))
      throw InputError(fmt::format("{}: cell_count {}, but {} of the same definition says {}; cells run by builds "
                                   "that expand the definition differently, or a file edited by hand",
                                   where, cell.value("cell_count", json()).dump(), first_name_,
                                   first.value("cell_count", json()).dump()));
    // By the scene's label (name and parameters): the variants of one generator are scenes of
    // their own, each with its content.
    const json content = value_at(cell, "scene.content_sha256");
    if (!content.is_string()) return;  // lines from before content hashes
    std::map<std::string, double> params;
    for (const auto& [key, value] : cell["cell"]["scene_params"].items()) params[key] = value.get<double>();
    const std::string label = scene_label(cell["cell"]["scene"].get<std::string>(), params);
    const auto [seen, fresh] = scenes_.try_emplace(label, content.get<std::string>(), where);
    if (!fresh && seen->second.first != content.get<std::string>())
      throw InputError(fmt::format("{}: the cell was measured on scene '{}' with content sha256 {}, but {} on content "
                                   "{}: the scene changed between the runs of one sweep; rerun the cells of one of "
                                   "the two (delete their results) on the scene as it is now",
                                   where, label, content.get<std::string>().substr(0, 12),
                                   seen->second.second, seen->second.first.substr(0, 12)));
  }

 private:
  std::optional<json> first_;
  std::string first_name_;
  std::map<std::string, std::pair<std::string, std::string>> scenes_;  // label -> content, where first seen
};

}  // namespace

ResultsFile read_results(const fs::path& file) {
  ResultsFile out;
  std::map<std::string, size_t> seen;        // cell_id -> line
  std::map<std::string, size_t> seen_index;  // cell_index -> line
  OneSweep one;
  read_json_lines(
      file, "(a sweep killed while writing it) skipped; its cell runs again when the sweep resumes",
      "a results file holds one JSON object per line", out.warnings,
      [&](json&& cell, size_t line_no, const std::string& where) {
        check_cell_record(cell, where);
        // One definition per file: resuming, collecting, gating and reporting all speak of one sweep.
        one.check(cell, where, fmt::format("line {}", line_no));
        require_unique_id(seen, cell["cell_id"].get<std::string>(), line_no, where, "cell_id",
                          "a results file holds each cell once — remove one of the lines, or merge shards with "
                          "`stereobench sweep collect`");
        require_unique_id(seen_index, cell["cell_index"].dump(), line_no, where, "cell_index",
                          "two cells cannot share an index: the file is damaged or was joined by hand — rerun the "
                          "sweep, or merge shards with `stereobench sweep collect`");
        out.cells.push_back(std::move(cell));
        out.lines.push_back(line_no);
      });
  return out;
}

namespace {

void rebase_strings(json& value, const fs::path& from, const fs::path& to) {
  if (value.is_object() || value.is_array()) {
    for (json& v : value) rebase_strings(v, from, to);
  } else if (value.is_string()) {
    const fs::path p = value.get<std::string>();
    if (!p.empty() && p.is_relative()) value = (from / p).lexically_normal().lexically_relative(to).generic_string();
  }
}

fs::path folder_of(const fs::path& file) { return fs::absolute(file).lexically_normal().parent_path(); }

}  // namespace

void require_unique_id(std::map<std::string, size_t>& seen, const std::string& id, size_t line_no,
                       const std::string& where, const char* key, const std::string& advice) {
  if (auto [it, fresh] = seen.emplace(id, line_no); !fresh)
    throw InputError(
        fmt::format("{}: {} '{}' appears twice (also on line {}); {}", where, key, id, it->second, advice));
}

std::optional<CellCoverage> cell_coverage(const std::vector<const json*>& cells) {
  std::set<uint64_t> indices;
  CellCoverage c;
  for (const json* r : cells) {
    const auto count = [&](const char* key) -> std::optional<uint64_t> {
      const auto it = r->find(key);
      if (it == r->end() || !it->is_number_integer() || it->get<int64_t>() < 0) return std::nullopt;
      return it->get<uint64_t>();
    };
    const std::optional<uint64_t> index = count("cell_index"), total = count("cell_count");
    if (!index || !total) return std::nullopt;
    c.expected = std::max(c.expected, *total);
    indices.insert(*index);
  }
  c.present = indices.size();
  return c;
}

void rebase_image_paths(json& cell, const fs::path& from, const fs::path& to) {
  const fs::path a = fs::absolute(from).lexically_normal(), b = fs::absolute(to).lexically_normal();
  if (a == b) return;
  if (cell.contains("images")) rebase_strings(cell["images"], a, b);
  // Each pipeline's validation record names its images too.
  if (const auto p = cell.find("pipelines"); p != cell.end() && p->is_object())
    for (auto& [name, record] : p->items())
      if (record.is_object())
        if (const auto v = record.find("validation"); v != record.end() && v->is_object() && v->contains("images"))
          rebase_strings((*v)["images"], a, b);
}

std::vector<json> collect_results(const std::vector<fs::path>& files, const fs::path& out,
                                  std::vector<std::string>* warnings) {
  struct Seen {
    json cell;
    fs::path file;
  };
  std::map<std::string, Seen> by_id;
  std::map<uint64_t, std::string> id_of_index;
  std::string sweep, sha;
  fs::path first;
  OneSweep one;
  for (const fs::path& file : files) {
    std::error_code ec;
    if (!fs::exists(file, ec))
      throw InputError(fmt::format("{}: results file does not exist; give the shards' results.jsonl files",
                                   file.string()));
    ResultsFile r = read_results(file);
    if (warnings) warnings->insert(warnings->end(), r.warnings.begin(), r.warnings.end());
    if (r.cells.empty()) continue;
    // read_results holds each file to one definition: its first cell speaks for the file.
    const std::string file_sweep = r.cells.front()["sweep"], file_sha = r.cells.front().value("definition_sha256", "");
    if (first.empty()) {
      sweep = file_sweep;
      sha = file_sha;
      first = file;
    } else if (file_sweep != sweep || file_sha != sha) {
      throw InputError(fmt::format("{} holds cells of sweep '{}' (definition {}), {} of sweep '{}' (definition {}); "
                                   "collect only shards of one definition",
                                   file.string(), file_sweep, file_sha.substr(0, 12), first.string(), sweep,
                                   sha.substr(0, 12)));
    }
    const fs::path from = folder_of(file), to = folder_of(out);
    for (size_t i = 0; i < r.cells.size(); ++i) {
      json& cell = r.cells[i];
      // The shards as one file: one set of pipelines, one cell count, one content per scene.
      one.check(cell, fmt::format("{}:{}", file.string(), r.lines[i]),
                fmt::format("{} line {}", file.string(), r.lines[i]));
      rebase_image_paths(cell, from, to);
      const std::string id = cell["cell_id"];
      const uint64_t index = cell["cell_index"];
      if (auto it = by_id.find(id); it != by_id.end()) {
        if (it->second.cell != cell)
          throw InputError(fmt::format("cell_id '{}' is recorded differently in {} and {}; keep one of the two "
                                       "results (or rerun the cell) before collecting",
                                       id, it->second.file.string(), file.string()));
        continue;
      }
      if (auto [it, fresh] = id_of_index.emplace(index, id); !fresh)
        throw InputError(fmt::format("cell_index {} is both '{}' and '{}' ({}); the files come from different "
                                     "definitions",
                                     index, it->second, id, file.string()));
      by_id.emplace(id, Seen{std::move(cell), file});
    }
  }
  std::vector<json> cells;
  for (const auto& [index, id] : id_of_index) cells.push_back(by_id.at(id).cell);
  // The shards' cells as a whole: a shard left out (or one not finished) leaves a merge that the
  // gate's sweep_complete check fails; said here, where the files are chosen.
  if (warnings && !cells.empty()) {
    const json count = value_at(cells.front(), "cell_count");
    if (count.is_number_unsigned() && cells.size() < count.get<uint64_t>()) {
      // The indices are distinct and below the count (read_results), so the first few missing
      // are found within as many steps past the cells held, whatever the count.
      const uint64_t total = count.get<uint64_t>(), missing_count = total - cells.size();
      std::vector<std::string> missing;
      for (uint64_t i = 0; i < total && missing.size() < 8; ++i)
        if (!id_of_index.count(i)) missing.push_back(std::to_string(i));
      warnings->push_back(fmt::format("the {} file(s) hold {} of the sweep's {} cells (missing cell_index {}{}): a "
                                      "shard is left out or unfinished; the gate fails the merge until every cell is "
                                      "in it",
                                      files.size(), cells.size(), total, fmt::join(missing, ", "),
                                      missing_count > missing.size()
                                          ? fmt::format(" and {} more", missing_count - missing.size())
                                          : ""));
    }
  }
  return cells;
}

std::string results_text(const std::vector<json>& cells) {
  std::string text;
  for (const json& cell : cells) text += line_of(cell);
  return text;
}

std::string results_csv(const std::vector<json>& cells) {
  std::string out;
  for (const char* column : kCsvColumns) out += (out.empty() ? "" : ",") + std::string(column);
  out += "\r\n";
  // Rows in the cells' order, whichever order parallel jobs finished them in.
  std::vector<const json*> ordered;
  for (const json& cell : cells) ordered.push_back(&cell);
  // A cell without an integer index (read_results refuses one) would sort last.
  const auto index_of = [](const json* cell) {
    const json i = value_at(*cell, "cell_index");
    return i.is_number_integer() ? i.get<int64_t>() : std::numeric_limits<int64_t>::max();
  };
  std::stable_sort(ordered.begin(), ordered.end(),
                   [&](const json* a, const json* b) { return index_of(a) < index_of(b); });
  for (const json* each : ordered) {
    const json& cell = *each;
    std::string params;
    const json scene_params = value_at(cell, "cell.scene_params");
    if (scene_params.is_object())
      for (const auto& [key, value] : scene_params.items())
        params += (params.empty() ? "" : ";") + key + "=" + field(value);
    const json pipelines = value_at(cell, "pipelines");
    if (!pipelines.is_object()) continue;
    for (const auto& [name, p] : pipelines.items()) {
      const json row[] = {value_at(cell, "cell_index"),
                          value_at(cell, "cell_id"),
                          value_at(cell, "sweep"),
                          value_at(cell, "cell.scene"),
                          params,
                          value_at(cell, "rig.width"),
                          value_at(cell, "rig.height"),
                          value_at(cell, "rig.interaxial_m"),
                          value_at(cell, "rig.max_disparity_px"),
                          value_at(cell, "rig.convergence_m"),
                          value_at(p, "validation.scene.lights"),
                          value_at(cell, "animation.frame"),
                          value_at(cell, "animation.bvh_update_s"),
                          value_at(cell, "cell.truth"),
                          name,
                          value_at(cell, "baseline"),
                          value_at(p, "validation.metrics.psnr"),
                          value_at(p, "validation.metrics.ssim"),
                          value_at(p, "validation.metrics.mse"),
                          value_at(p, "validation.metrics.error_fraction"),
                          value_at(p, "validation.holes.hole_fraction"),
                          value_at(p, "validation.holes.not_reprojected.recall"),
                          value_at(p, "validation.holes.not_reprojected.precision"),
                          value_at(p, "timing.median_s"),
                          value_at(p, "timing.speedup_median"),
                          value_at(p, "timing.right_over_left_median")};
      static_assert(std::size(row) == std::size(kCsvColumns));
      std::string line;
      for (size_t i = 0; i < std::size(row); ++i) line += (i ? "," : "") + csv_quote(field(row[i]));
      out += line + "\r\n";
    }
  }
  return out;
}

}  // namespace sb::validation
