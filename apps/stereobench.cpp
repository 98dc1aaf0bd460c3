// stereobench: the command-line tool. Maps subcommands to library calls and errors to exit codes.
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <regex>
#include <string>
#include <system_error>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "apps/commands.hpp"
#include "renderer/error.hpp"
#include "renderer/io/gltf_loader.hpp"
#include "renderer/io/image_io.hpp"
#include "renderer/memory.hpp"
#include "renderer/text.hpp"
#include "sb_version.hpp"
#include "validation/process.hpp"

namespace {

/// The command line as typed, each argument a shell would split or expand single-quoted (for
/// provenance).
std::string command_line(int argc, char** argv) {
  std::string out;
  for (int i = 0; i < argc; ++i) out += (i > 0 ? " " : "") + sb::shell_quote(argv[i]);
  return out;
}

/// Calls `check` on `app` and on each of its commands, at every depth.
void for_each_command(CLI::App& app, void (*check)(CLI::App&)) {
  check(app);
  for (CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) for_each_command(*sub, check);
}

/// An empty file or folder option (an unset shell variable, say) would read or write the current
/// folder, or silently drop the output, and an empty value would be taken as not given: refused.
/// --cache is not among them: '' turns the ground-truth cache off.
void refuse_empty_values(CLI::App& app) {
  const auto refuse = [&](std::initializer_list<const char*> names, const char* what) {
    for (const char* name : names) {
      CLI::Option* option = app.get_option_no_throw(name);
      if (!option) continue;
      const std::string message =
          option->get_required()
              ? fmt::format("is empty; give {}", what)
              : fmt::format("is empty; give {}, or leave the option out for its default", what);
      option->check(CLI::Validator(
          [message](const std::string& value) { return value.empty() ? message : std::string(); }, "", "non-empty"));
    }
  };
  refuse({"--out", "--scenes-dir", "--store", "--results", "--history", "--json", "--junit", "--diff", "--ssim-map",
          "--mask", "--gate-config", "--config", "--baseline", "--gltf-clip", "--partition"},
         "a name");
  refuse({"--bvh", "--time-limit", "--sbatch-arg"}, "a value");
}

/// Options that name a file to write (--json, --junit, sweep collect's merged file): a folder
/// there would be found only when the file is written, after all the work; refused at once.
void refuse_folder_as_file(CLI::App& app) {
  for (const char* name : {"--json", "--junit", "out"}) {
    CLI::Option* file = app.get_option_no_throw(name);
    if (!file || (std::string(name) == "out" && !file->get_positional())) continue;
    file->check(CLI::Validator(
        [](const std::string& value) {
          std::error_code ec;
          if (value != "-" && std::filesystem::is_directory(value, ec))
            return value + " is a folder; give the name of the file to write";
          // A folder not made yet: its parent folders would be made before the write found it.
          if (!value.empty() && value.back() == '/')
            return value + " names a folder (it ends in '/'); give the name of the file to write";
          return std::string();
        },
        "", "not a folder"));
  }
}

/// Folder options: '-' stands for standard output elsewhere (--json -, sweep csv's --out), which
/// cannot hold a folder; taken as a folder name it would make a folder named '-'. Refused, with the
/// way to mean such a folder.
void refuse_dash_folder(CLI::App& app) {
  for (const char* name : {"--out", "--scenes-dir", "--store"}) {
    CLI::Option* folder = app.get_option_no_throw(name);
    // sweep csv's --out is the one file among them: '-' is standard output there.
    if (!folder || (std::string(name) == "--out" && app.get_name() == "csv")) continue;
    folder->check(CLI::Validator(
        [](const std::string& value) {
          return value == "-" ? std::string("names a folder, and '-' (standard output) cannot be one; give a folder "
                                            "name (./- for a folder named '-')")
                              : std::string();
        },
        "", "a folder"));
  }
}

/// Numeric options take decimal numbers only. The parser would also read C's other forms
/// (0x10 as 16, 0b11, 0o17, 010 as octal 8, digit separators), so a resolution or hash pasted
/// into --vfov or --repetitions would run silently with another value. Leading zeros are dropped
/// (010 is ten). "inf" and "nan" pass on to the option's own range check, which names them.
void refuse_non_decimal_numbers(CLI::App& app) {
  static const std::regex integer(R"([+-]?[0-9]+)");
  static const std::regex real(R"([+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?|[+-]?(inf|infinity|nan))",
                               std::regex::icase);
  for (CLI::Option* option : app.get_options()) {
    const std::string type = option->get_type_name();
    const bool is_integer = type.starts_with("INT") || type.starts_with("UINT");
    if (!is_integer && !type.starts_with("FLOAT")) continue;
    option->transform(CLI::Validator(
        [is_integer](std::string& value) {
          if (!std::regex_match(value, is_integer ? integer : real))
            return fmt::format("'{}' is not a decimal {}", value, is_integer ? "integer" : "number");
          const size_t digits = value.find_first_not_of("+-");
          size_t zeros = digits;
          while (zeros + 1 < value.size() && value[zeros] == '0' && std::isdigit(static_cast<unsigned char>(value[zeros + 1])))
            ++zeros;
          value.erase(digits, zeros - digits);
          return std::string();
        },
        "", "decimal"));
  }
}

/// CLI11's usage messages in the words of the others: what was wrong and what to do.
std::string usage_error_message(const std::string& what) {
  std::smatch m;
  // "--resolution: At Most 1 required but received 2"
  if (std::regex_match(what, m, std::regex(R"((\S+): At Most 1 required but received (\d+))")))
    return fmt::format("{} is given {} times; give it once", m[1].str(), m[2].str());
  // "--threads: 1 required INT missing", "--shards: 1 required UINT:UINT in [1 - 1001] missing"
  if (std::regex_match(what, m, std::regex(R"((-\S+): (\d+) required (.+) missing)"))) {
    const std::string type = m[3].str(), base = type.substr(0, type.find_first_of(": "));
    const std::string placeholder = base == "INT" || base == "UINT" ? "N" : base == "FLOAT" ? "X" : "VALUE";
    std::string values;
    for (int i = 0; i < std::stoi(m[2].str()) && i < 4; ++i) values += " " + placeholder;
    return fmt::format("{} needs {} after it ({}); give {}{}", m[1].str(),
                       m[2].str() == "1" ? std::string("a value") : m[2].str() + " values", type, m[1].str(), values);
  }
  // "inputs is required", "--results is required"
  if (std::regex_match(what, m, std::regex(R"((\S+) is required)")))
    return m[1].str().starts_with("-") ? fmt::format("{} is required; give it", m[1].str())
                                       : fmt::format("the argument {} is missing; give it", m[1].str());
  // "--interaxial excludes --max-disparity"
  if (std::regex_match(what, m, std::regex(R"((-\S+) excludes (-\S+))")))
    return fmt::format("{} and {} exclude each other; give one of them", m[1].str(), m[2].str());
  // "The following argument was not expected: --bogus"
  if (std::regex_match(what, m, std::regex(R"(The following arguments? (?:was|were) not expected: (.+))")))
    return fmt::format("unexpected argument(s) {}: an option this command does not have, or a value given "
                       "without its option",
                       m[1].str());
  return what;
}

/// When parsing stopped for want of a subcommand: the first word after the commands given that
/// names none of the next level's, with those names; or, when the words given end at a command
/// that needs one of its own (`stereobench sweep`), those commands. "" when a word is an option
/// or every word is a command that needs none.
std::string unknown_command_message(const CLI::App& app, int argc, char** argv) {
  const CLI::App* level = &app;
  std::string path = "stereobench";
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word.empty() || word[0] == '-') return "";
    std::vector<std::string> names;
    const CLI::App* next = nullptr;
    for (const CLI::App* s : level->get_subcommands([](const CLI::App*) { return true; })) {
      names.push_back(s->get_name());
      if (s->get_name() == word) next = s;
    }
    if (names.empty()) return "";
    if (!next) return fmt::format("'{}' is not a command of {}; its commands: {}", word, path, fmt::join(names, ", "));
    level = next;
    path += " " + word;
  }
  if (level->get_require_subcommand_min() == 0) return "";
  std::vector<std::string> names;
  for (const CLI::App* s : level->get_subcommands([](const CLI::App*) { return true; })) names.push_back(s->get_name());
  return fmt::format("{} needs a command: {}; `{} COMMAND --help` explains each", path, fmt::join(names, ", "), path);
}

/// The exit code once standard output has taken everything printed: `code`, or 4 with a message
/// when it could not (a full disk behind a redirection, a closed pipe), so that output that never
/// arrived does not end in success.
int after_flushing_stdout(int code) {
  errno = 0;
  if (std::fflush(stdout) == 0 && std::ferror(stdout) == 0) return code;
  std::fprintf(stderr, "stereobench: error: cannot write to standard output: %s; check where it goes (a full disk, "
               "a closed pipe)\n", errno != 0 ? std::strerror(errno) : "write error");
  return static_cast<int>(sb::ExitCode::environment);
}

}  // namespace

int main(int argc, char** argv) {
  sb::keep_freed_memory();
  // Line by line, also into a file or pipe: progress and warnings on standard error then fall
  // between the lines of standard output in the order they were printed (a log of `2>&1`).
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  // Ctrl-C, `kill`, a job's end: running tools are stopped and temporary files removed.
  sb::validation::install_stop_handler();
  CLI::App app{"stereobench: offline validation and benchmarking of accelerated stereo rendering.\n"
               "Renders stereo pairs with every pipeline of the source papers, measures the synthesized\n"
               "right eye against ground truth, and reports quality, holes and time.",
               "stereobench"};
  app.require_subcommand(1);
  app.option_defaults()->always_capture_default();
  app.set_version_flag("--version",
                       fmt::format("stereobench {}\n  {}\n  OpenImageIO {}", SB_VERSION_STRING,
                                   sb::io::gltf_loader_version(), sb::io::oiio_version()));
  sb::cli::register_scenes_command(app);
  sb::cli::register_render_command(app);
  sb::cli::register_bench_command(app);
  sb::cli::register_validate_command(app);
  sb::cli::register_sweep_command(app);
  sb::cli::register_gate_command(app);
  sb::cli::register_nightly_command(app);
  sb::cli::register_compare_command(app);
  sb::cli::register_reference_command(app, command_line(argc, argv));
  sb::cli::register_report_command(app);
  sb::cli::register_path_command(app);
  for (void (*check)(CLI::App&) : {refuse_empty_values, refuse_folder_as_file, refuse_dash_folder,
                                    refuse_non_decimal_numbers})
    for_each_command(app, check);

  try {
    app.parse(argc, argv);
  } catch (const sb::cli::VerdictExit& verdict) {
    return after_flushing_stdout(verdict.code);
  } catch (const CLI::Success& e) {
    return after_flushing_stdout(app.exit(e));  // --help, --version: 4 when they could not be written
  } catch (const CLI::ParseError& e) {
    // Usage errors read like every other error: one "stereobench: error:" line, then where to look.
    std::string message = unknown_command_message(app, argc, argv);
    if (message.empty()) message = usage_error_message(e.what());
    // Only decimal numbers reach the conversion (refuse_non_decimal_numbers): one that fails to
    // convert does not fit the option's integer type.
    if (dynamic_cast<const CLI::ConversionError*>(&e) != nullptr && message.starts_with("Could not convert: ")) {
      std::string option_value = message.substr(19);  // "--lights = 99999999999"
      if (const size_t eq = option_value.find(" = "); eq != std::string::npos) option_value.replace(eq, 3, " ");
      message = option_value + " is too large in magnitude for the option to hold; give a smaller number";
    }
    std::fprintf(stderr, "stereobench: error: %s\n", message.c_str());
    std::fprintf(stderr, "Run `stereobench --help` (or `stereobench SUBCOMMAND --help`) for usage.\n");
    sb::cli::discard_gate_reports_after_usage_error(app);
    return static_cast<int>(sb::ExitCode::bad_input);
  } catch (const sb::Error& e) {
    std::fprintf(stderr, "stereobench: error: %s\n", e.what());
    return static_cast<int>(e.code());
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "stereobench: error: out of memory; try a smaller scene or resolution\n");
    return static_cast<int>(sb::ExitCode::environment);
  } catch (const std::filesystem::filesystem_error& e) {
    // A path the file system refused where no command checked it first (a link loop, a folder
    // without permission): named, with its reason.
    std::string paths = e.path1().string();
    if (!e.path2().empty()) paths += " and " + e.path2().string();
    if (paths.empty())  // e.g. the working folder, deleted while the command ran
      std::fprintf(stderr, "stereobench: error: %s; check the working folder and the paths given\n", e.what());
    else
      std::fprintf(stderr, "stereobench: error: cannot use %s: %s; check that path (a link that loops, a folder "
                   "without permission, a full disk)\n", paths.c_str(), e.code().message().c_str());
    return static_cast<int>(sb::ExitCode::environment);
  } catch (const std::system_error& e) {
    // What the operating system refused, e.g. printing to a full disk ("cannot write to file").
    std::fprintf(stderr, "stereobench: error: %s; check where the output goes (a full disk, a closed pipe)\n",
                 e.what());
    return static_cast<int>(sb::ExitCode::environment);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "stereobench: internal error: %s\n", e.what());
    return static_cast<int>(sb::ExitCode::environment);
  }
  return after_flushing_stdout(0);
}
