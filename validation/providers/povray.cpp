// `povray`: the right eye rendered by POV-Ray 3.7 from an SDL export (DESIGN §6.1,
// docs/truth_povray.md). The executable is `povray` on PATH, or the one the environment variable
// STEREOBENCH_POVRAY names.
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <optional>
#include <regex>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/image_io.hpp"
#include "renderer/text.hpp"
#include "validation/process.hpp"
#include "validation/providers/povray_export.hpp"
#include "validation/providers/providers.hpp"

namespace sb::validation {
namespace {

/// Bumped whenever the provider's command line or settings change (the SDL export has its own
/// revision, povray::kExportRevision; both make up revision()).
constexpr const char* kProviderRevision = "povray-provider-1";
constexpr const char* kExecutableVariable = "STEREOBENCH_POVRAY";
constexpr const char* kInstallHint = "install it with `ci/install-deps.sh povray`";

/// Lines of POV-Ray's output quoted in an error.
constexpr std::size_t kQuotedLines = 15;

/// A command to run: the executable, its arguments, and how it runs (working folder, environment
/// changes; stdout and stderr go into one text, as the tool wrote them).
struct Command {
  std::filesystem::path executable;
  std::vector<std::string> args;  ///< argv[1..]
  ProcessOptions options;

  Command() { options.stderr_to = ChildOutput::to_stdout; }
  [[nodiscard]] ProcessResult run() const {
    std::vector<std::string> argv{executable.string()};
    argv.insert(argv.end(), args.begin(), args.end());
    return run_process(argv, options);
  }
};

/// Shell-quoted form of the command (for records and messages; not used to run it).
std::string quoted(const Command& c) {
  std::vector<std::string> argv{c.executable.string()};
  argv.insert(argv.end(), c.args.begin(), c.args.end());
  return shell_command(argv, c.options);
}

/// The distinct warning lines of a POV-Ray log (at most `limit`).
std::vector<std::string> warning_lines(const std::string& log, std::size_t limit) {
  std::vector<std::string> out;
  std::stringstream in(log);
  std::string line;
  while (std::getline(in, line)) {
    if (line.find("Warning") == std::string::npos) continue;
    if (std::find(out.begin(), out.end(), line) != out.end()) continue;
    out.push_back(line);
    if (out.size() >= limit) break;
  }
  return out;
}

/// What `povray --version` said.
struct ToolInfo {
  std::filesystem::path executable;
  std::string version;  ///< "POV-Ray 3.7.0.10"
  std::string banner;   ///< the full version line, e.g. "POV-Ray 3.7.0.10.unofficial"
};

class PovrayProvider final : public TruthProvider {
 public:
  PovrayProvider() {
    const char* named = std::getenv(kExecutableVariable);
    if (named && *named) {
      requested_ = named;
      from_variable_ = true;
    }
  }

  std::string name() const override { return "povray"; }
  std::string description() const override {
    return "POV-Ray 3.7 from an SDL export (mesh2, exact inverse-square lights, no anti-aliasing); executable "
           "from $STEREOBENCH_POVRAY or PATH";
  }

  std::optional<std::string> unavailable_reason() const override {
    probe();
    return reason_;
  }

  std::string tool_version() const override {
    probe();
    if (reason_) throw ToolError(*reason_);
    return info_.version;
  }

  std::string revision() const override { return fmt::format("{}+{}", kProviderRevision, povray::kExportRevision); }

  void check_scene(const Scene& scene, const std::filesystem::path& /*scene_file*/) const override {
    povray::check_exportable(scene);
  }

  std::optional<std::string> prepare(const TruthRequest& request) const override {
    return quoted(set_up(request, std::chrono::steady_clock::now()).cmd);
  }

  TruthRender render(const TruthRequest& request) const override {
    const auto start = std::chrono::steady_clock::now();
    const Setup setup = set_up(request, start);
    const EyeCamera& eye = setup.eye;
    const std::filesystem::path& dir = setup.dir;
    const std::filesystem::path& image_file = setup.image_file;
    const std::filesystem::path& log_file = setup.log_file;
    const povray::ExportResult& exported = setup.exported;
    const Command& cmd = setup.cmd;
    const std::chrono::milliseconds limit = setup.limit;
    const double export_seconds = setup.export_seconds;
    std::error_code ec;

    const ProcessResult run = cmd.run();
    const double render_seconds = seconds_since(start) - export_seconds;
    const std::string& log = run.out;
    const bool have_image = std::filesystem::is_regular_file(image_file, ec);
    const bool failed = run.timed_out || !run.ok() || !have_image;
    const std::string log_note = keep_tool_output(log_file, log, failed);
    if (failed) {
      // What a stopped or failed render leaves (a cut image, the state file of its progress) is
      // no use to a rerun and may fill the disk it failed on.
      for (const char* left : {"right.exr", "right.pov-state"}) std::filesystem::remove(dir / left, ec);
    }
    // The half-float image and the state file beside it, with room to spare.
    const std::string disk_note =
        failed ? low_disk_note(dir, std::uintmax_t{16} * eye.width * eye.height + (std::uintmax_t{1} << 20)) : "";
    if (run.timed_out)
      throw ToolError(fmt::format(
          "POV-Ray did not finish rendering '{}' within {} and was stopped; {}; the scene file is kept there, rerun "
          "it with: {}\nlast lines of its output ({}{}):{}",
          exported.sdl_file.string(), format_limit(limit), tool_timeout_hint(), quoted(cmd), log_file.string(),
          log_note, quoted_output(log, kQuotedLines)));
    if (failed) {
      std::string failure = "no image written";
      if (run.signal != 0)
        failure = fmt::format("killed by signal {}", run.signal);
      else if (run.exit_code != 0)
        failure = fmt::format("exit status {}", run.exit_code);
      throw ToolError(fmt::format(
          "POV-Ray failed ({}) rendering '{}'{}; the scene file is kept there, rerun it with: {}\nlast lines of its "
          "output ({}{}):{}",
          failure, exported.sdl_file.string(), disk_note, quoted(cmd), log_file.string(), log_note,
          quoted_output(log, kQuotedLines)));
    }

    Image raw;
    try {
      raw = io::read_exr(image_file);
    } catch (const Error& e) {
      throw ToolError(fmt::format("POV-Ray wrote '{}' but it cannot be read: {}", image_file.string(), e.what()));
    }
    if (raw.width() != eye.width || raw.height() != eye.height || !raw.has_plane(planes::rgb))
      throw ToolError(fmt::format("POV-Ray wrote '{}' as {}x{} with planes [{}]; expected {}x{} with rgb",
                                  image_file.string(), raw.width(), raw.height(), raw.plane_list(), eye.width,
                                  eye.height));
    TruthRender out;
    out.provider = name();
    out.tool_version = info_.version;
    out.right = Image(eye.width, eye.height);
    const std::span<const float> src = raw.plane(planes::rgb).f32();
    std::copy(src.begin(), src.end(), out.right.add_plane(planes::rgb).f32().begin());
    out.command = quoted(cmd);
    out.settings = exported.settings;
    out.settings["provider_revision"] = kProviderRevision;
    out.settings["executable"] = info_.executable.string();
    out.settings["executable_from"] = from_variable_ ? kExecutableVariable : "PATH";
    out.settings["tool_banner"] = info_.banner;
    out.settings["options"] = cmd.args;
    out.settings["antialias"] = false;
    out.settings["radiosity"] = false;
    out.settings["output"] = "OpenEXR half float (11-bit significand: relative rounding error <= 2^-11 = 4.9e-4)";
    out.settings["threads"] = setup.threads;
    out.settings["work_dir"] = dir.string();
    out.settings["export_seconds"] = export_seconds;
    out.settings["render_seconds"] = render_seconds;
    out.settings["export_warnings"] = exported.warnings;
    out.settings["povray_warnings"] = warning_lines(log, 20);
    out.seconds = seconds_since(start);
    return out;
  }

 private:
  /// What a render runs, made ready in the request's work folder: the scene exported, POV-Ray's
  /// private configuration written, a stale image removed, and the command.
  struct Setup {
    EyeCamera eye;
    std::filesystem::path dir, image_file, log_file;
    povray::ExportResult exported;
    Command cmd;
    std::chrono::milliseconds limit{0};
    int threads = 1;
    double export_seconds = 0.0;
  };
  Setup set_up(const TruthRequest& request, std::chrono::steady_clock::time_point start) const {
    probe();
    if (reason_) throw ToolError(*reason_);
    const std::chrono::milliseconds limit = tool_timeout();  // InputError for a malformed value

    const EyeCamera eye = request.rig.eye(Eye::right);
    std::error_code ec;
    const std::filesystem::path dir = std::filesystem::absolute(request.work_dir, ec);
    if (ec) throw IoError(fmt::format("work folder '{}': {}", request.work_dir.string(), ec.message()));
    std::filesystem::create_directories(dir, ec);
    if (ec) throw IoError(fmt::format("cannot create the POV-Ray work folder '{}': {}", dir.string(), ec.message()));

    // A stale image from an earlier run must never be read as this run's output.
    const std::filesystem::path image_file = dir / "right.exr";
    const std::filesystem::path log_file = dir / "povray.log";
    std::filesystem::remove(image_file, ec);
    if (ec) throw IoError(fmt::format("cannot remove the old render '{}': {}", image_file.string(), ec.message()));

    // Export.
    const povray::ExportResult exported = povray::export_scene(request.scene.scene(), eye, dir);
    const double export_seconds = seconds_since(start);

    // A private configuration: POV-Ray reads its INI from $POVINI (else ./povray.ini, then the
    // user's and the system's) and its I/O permissions from $HOME/.povray/3.7/povray.conf after
    // the system's; pointing both into the work folder keeps a user's own settings out.
    io::write_text_atomically(dir / "povray.ini", "; stereobench povray provider: every option is on the command line\n");
    io::write_text_atomically(dir / ".povray" / "3.7" / "povray.conf",
                              "; stereobench povray provider: read and write only in the work folder\n"
                              "[File I/O Security]\nrestricted\n[Shellout Security]\nforbidden\n"
                              "[Permitted Paths]\nread+write = .\n");

    const int threads = request.threads > 0 ? request.threads
                                            : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    Command cmd;
    cmd.executable = info_.executable;
    cmd.options.cwd = dir;
    cmd.options.unset_env = {"DISPLAY"};
    cmd.options.set_env = {{"POVINI", (dir / "povray.ini").string()}, {"HOME", dir.string()}};
    cmd.options.timeout = limit;
    cmd.args = {"+I" + exported.sdl_file.filename().string(),
                "+O" + image_file.filename().string(),
                "+FE",  // OpenEXR, half float, linear
                fmt::format("+W{}", eye.width),
                fmt::format("+H{}", eye.height),
                "-A",   // no anti-aliasing: one ray through each pixel centre
                "-J",   // no jitter
                "-UA",  // no alpha channel: the background colour is written
                "-D",   // no display window
                "-P",   // no pause
                "-V",   // not verbose
                "-GS",  // no statistics
                "-GR",  // no render progress
                "-C",   // no continued trace
                "+Q9",
                fmt::format("+WT{}", threads)};
    return Setup{eye, dir, image_file, log_file, exported, cmd, limit, threads, export_seconds};
  }

  static double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  }

  /// Finds the executable and asks it for its version, once.
  void probe() const {
    std::call_once(probed_, [this] {
      const std::optional<std::filesystem::path> exe = find_program(requested_);
      if (!exe) {
        reason_ = from_variable_
                      ? fmt::format("{}='{}' is not an executable file (nor a command on PATH); point it at POV-Ray "
                                    "3.7's `povray`, or unset it to use povray from PATH ({})",
                                    kExecutableVariable, requested_, kInstallHint)
                      : fmt::format("povray not found on PATH; {} (or set {} to its path)", kInstallHint,
                                    kExecutableVariable);
        return;
      }
      info_.executable = *exe;
      Command cmd;
      cmd.executable = *exe;
      cmd.args = {"--version"};
      cmd.options.unset_env = {"DISPLAY"};
      cmd.options.timeout = kShortCommandTimeout;
      ProcessResult result;
      try {
        result = cmd.run();
      } catch (const Error& e) {
        reason_ = fmt::format("'{}' cannot be run: {}", exe->string(), e.what());
        return;
      }
      if (result.timed_out) {
        reason_ = fmt::format("'{} --version' did not answer within {} and was stopped; {}", exe->string(),
                              format_limit(kShortCommandTimeout), kInstallHint);
        return;
      }
      static const std::regex version_line(R"(POV-Ray (\d+)\.(\d+)(\.\d+)*\S*)");
      std::smatch m;
      if (!std::regex_search(result.out, m, version_line)) {
        reason_ = fmt::format("'{} --version' did not report a POV-Ray version (it {}); {}; its output:{}",
                              exe->string(), result.describe(), kInstallHint, quoted_output(result.out, 5));
        return;
      }
      info_.banner = m.str(0);
      std::string numeric = m.str(0).substr(8);
      const std::size_t end = numeric.find_first_not_of("0123456789.");
      if (end != std::string::npos) numeric.resize(end);
      while (!numeric.empty() && numeric.back() == '.') numeric.pop_back();
      info_.version = "POV-Ray " + numeric;
      const int major = std::stoi(m.str(1)), minor = std::stoi(m.str(2));
      if (major < 3 || (major == 3 && minor < 7))
        reason_ = fmt::format("'{}' is {}, the povray provider needs POV-Ray 3.7 or newer; {}", exe->string(),
                              info_.banner, kInstallHint);
    });
  }

  std::string requested_ = "povray";
  bool from_variable_ = false;
  mutable std::once_flag probed_;
  mutable std::optional<std::string> reason_;
  mutable ToolInfo info_;
};

}  // namespace

std::unique_ptr<TruthProvider> make_povray_provider() { return std::make_unique<PovrayProvider>(); }

}  // namespace sb::validation
