// `stereobench compare A B`: the metrics of DESIGN §6.2 for any two image files, with idiff-style
// pass / warn / fail thresholds, a JSON record, and difference and SSIM map pictures.
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <iterator>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "renderer/error.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/json_text.hpp"
#include "renderer/text.hpp"
#include "validation/image_files.hpp"
#include "validation/metric_images.hpp"
#include "validation/metrics.hpp"

namespace sb::cli {

namespace {

namespace fs = std::filesystem;
using validation::ImageMetrics;

struct CompareArgs {
  std::string a, b;
  std::string eye;
  std::string mask;
  std::string json;
  std::string diff;
  std::string ssim_map;
  int error_threshold = 2;
  std::optional<double> fail_psnr, fail_ssim, fail_percent;
  std::optional<double> warn_psnr, warn_ssim, warn_percent;
};

/// One threshold test: the metric's value against a limit, failing below (PSNR, SSIM) or above
/// (error percentage) it.
struct Limit {
  const char* option;
  std::optional<double> value;
  bool below;  ///< true: bad when the metric is below the limit
};

std::string format_psnr(double psnr) { return std::isinf(psnr) ? std::string("inf") : fmt::format("{:.4f}", psnr); }

void check_limit(const std::optional<double>& v, const char* option, double lo, double hi, const char* what) {
  if (v && (!std::isfinite(*v) || *v < lo || *v > hi))
    throw InputError(fmt::format("{} {} is out of range; give {} in [{}, {}]", option, *v, what, lo, hi));
}

/// `value` with `digits` decimals, or as many more as it takes for the text to fall on the side of
/// `limit` that `value` lies on (below it, or above): 39.41995 against 39.42 reads 39.41995, not
/// 39.4200.
std::string beside_limit(double value, double limit, int digits, bool below) {
  std::string text;
  for (int d = digits; d <= 17; ++d) {
    text = fmt::format("{:.{}f}", value, d);
    const double shown = std::strtod(text.c_str(), nullptr);
    if (below ? shown < limit : shown > limit) break;
  }
  return text;
}

/// Reasons the metrics violate the given limits, e.g. "PSNR 23.1000 dB < --fail-psnr 30".
std::vector<std::string> violations(const ImageMetrics& m, const Limit& psnr, const Limit& ssim, const Limit& percent) {
  std::vector<std::string> out;
  if (psnr.value && m.psnr < *psnr.value)
    out.push_back(fmt::format("PSNR {} dB < {} {}",
                              std::isinf(m.psnr) ? format_psnr(m.psnr) : beside_limit(m.psnr, *psnr.value, 4, true),
                              psnr.option, *psnr.value));
  if (ssim.value && m.ssim < *ssim.value)
    out.push_back(fmt::format("SSIM {} < {} {}", beside_limit(m.ssim, *ssim.value, 6, true), ssim.option, *ssim.value));
  const double percent_value = 100.0 * m.error_fraction;
  if (percent.value && percent_value > *percent.value)
    out.push_back(fmt::format("error pixels {} % > {} {}", beside_limit(percent_value, *percent.value, 4, false),
                              percent.option, *percent.value));
  return out;
}

/// Refuses a picture name that does not end in .png (the pictures are PNG whatever the name says).
void check_picture_names(const CompareArgs& a) {
  const std::pair<const char*, const std::string*> pictures[] = {{"--diff", &a.diff}, {"--ssim-map", &a.ssim_map}};
  for (const auto& [option, path] : pictures) {
    if (!path->empty() && lowercase(fs::path(*path).extension().string()) != ".png")
      throw InputError(fmt::format("{} {}: the picture is written as PNG; give a file name ending in .png", option,
                                   *path));
  }
}

nlohmann::json file_record(const std::string& path, const validation::Srgb8File& f) {
  nlohmann::json j{{"path", path},
                   {"width", f.image.width},
                   {"height", f.image.height},
                   {"colour_channels", f.colour_channels},
                   {"encoding", f.encoding}};
  j["eye"] = f.eye.empty() ? nlohmann::json(nullptr) : nlohmann::json(f.eye);
  return j;
}

nlohmann::json optional_number(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

int run_compare(const CompareArgs& a) {
  // An output naming an input or another output, or a picture not named .png, is refused; then an
  // earlier run's outputs at these paths go, before anything else is checked: a comparison stopped
  // by bad input or an unwritable output (exit 3 or 4) leaves none, so none can be read as this
  // run's verdict.
  const std::initializer_list<NamedPath> outputs = {
      {"--json", &a.json}, {"--diff", &a.diff}, {"--ssim-map", &a.ssim_map}};
  refuse_overwriting({{"image A", &a.a}, {"image B", &a.b}, {"--mask", &a.mask}}, outputs);
  check_picture_names(a);  // a name this run would refuse to write is not its output to remove
  remove_earlier_outputs(outputs);
  if (a.error_threshold < 0 || a.error_threshold > 255)
    throw InputError(
        fmt::format("--error-threshold {} is out of range; give 8-bit codes in 0..255 (default 2)", a.error_threshold));
  for (const auto* o : {&a.fail_psnr, &a.warn_psnr})
    check_limit(*o, o == &a.fail_psnr ? "--fail-psnr" : "--warn-psnr", 0.0, 1000.0, "decibels");
  for (const auto* o : {&a.fail_ssim, &a.warn_ssim})
    check_limit(*o, o == &a.fail_ssim ? "--fail-ssim" : "--warn-ssim", -1.0, 1.0, "an SSIM");
  for (const auto* o : {&a.fail_percent, &a.warn_percent})
    check_limit(*o, o == &a.fail_percent ? "--fail-percent" : "--warn-percent", 0.0, 100.0, "a percentage");
  // A warning level on the far side of its failure level could never be reached before the failure.
  const auto ordered = [](const std::optional<double>& warn, const std::optional<double>& fail, bool at_least,
                          const char* metric) {
    if (warn && fail && (at_least ? *warn < *fail : *warn > *fail))
      throw InputError(fmt::format("--warn-{0} {1} lies beyond --fail-{0} {2}: a comparison would fail before it "
                                   "warned; give a warning level {3} the failure level, or drop one of them",
                                   metric, *warn, *fail, at_least ? "at or above" : "at or below"));
  };
  ordered(a.warn_psnr, a.fail_psnr, true, "psnr");
  ordered(a.warn_ssim, a.fail_ssim, true, "ssim");
  ordered(a.warn_percent, a.fail_percent, false, "percent");

  for (const NamedPath& o : outputs) prepare_output_file_folder(*o.path, o.name);

  // Inputs: both images (and the mask) must have one size and one kind of colour.
  const validation::Srgb8File fa = validation::read_srgb8_file(a.a, a.eye);
  const validation::Srgb8File fb = validation::read_srgb8_file(a.b, a.eye);
  if (fa.image.width != fb.image.width || fa.image.height != fb.image.height)
    throw InputError(fmt::format("the images differ in size: A {} is {}x{}, B {} is {}x{}; compare images of one size",
                                 a.a, fa.image.width, fa.image.height, a.b, fb.image.width, fb.image.height));
  if (fa.colour_channels != fb.colour_channels)
    throw InputError(
        fmt::format("the images differ in channels: A {} has {} colour channel(s), B {} has {}; "
                    "compare grey with grey or colour with colour",
                    a.a, fa.colour_channels, a.b, fb.colour_channels));
  std::optional<validation::RegionMask> mask;
  if (!a.mask.empty()) {
    mask = validation::read_region_mask(a.mask, a.eye);
    if (mask->width != fa.image.width || mask->height != fa.image.height)
      throw InputError(fmt::format("mask {} is {}x{} but the images are {}x{}; give a mask of the image size", a.mask,
                                   mask->width, mask->height, fa.image.width, fa.image.height));
    if (mask->count() == 0)
      throw InputError(fmt::format("mask {} is empty (no non-zero pixel); there is nothing to compare", a.mask));
  }
  const validation::RegionMask* region = mask ? &*mask : nullptr;

  validation::MetricOptions options;
  options.error_threshold = a.error_threshold;
  // The SSIM map is computed once, for the metrics and the picture.
  validation::SsimMap ssim;
  const validation::RegionMask* const regions[] = {region};
  const ImageMetrics m =
      validation::compare_regions(fa.image, fb.image, regions, options, a.ssim_map.empty() ? nullptr : &ssim).front();
  const bool ssim_limited = a.fail_ssim || a.warn_ssim;
  if (ssim_limited && std::isnan(m.ssim))
    throw InputError(
        fmt::format("SSIM is undefined here ({}x{} images{}): it needs images of at least 11x11 and "
                    "region pixels outside the 5-pixel border; drop --fail-ssim/--warn-ssim",
                    fa.image.width, fa.image.height, region ? " with this mask" : ""));

  // Verdict in the manner of idiff: any failure fails, else any warning warns.
  const std::vector<std::string> failures =
      violations(m, {"--fail-psnr", a.fail_psnr, true}, {"--fail-ssim", a.fail_ssim, true},
                 {"--fail-percent", a.fail_percent, false});
  const std::vector<std::string> warnings =
      violations(m, {"--warn-psnr", a.warn_psnr, true}, {"--warn-ssim", a.warn_ssim, true},
                 {"--warn-percent", a.warn_percent, false});
  const ExitCode code = !failures.empty()   ? ExitCode::gate_failure
                        : !warnings.empty() ? ExitCode::gate_warning
                                            : ExitCode::ok;
  const char* verdict = code == ExitCode::gate_failure ? "fail" : code == ExitCode::gate_warning ? "warn" : "pass";

  nlohmann::json record;
  record["metrics_version"] = validation::kMetricsVersion;
  record["a"] = file_record(a.a, fa);
  record["b"] = file_record(a.b, fb);
  record["mask"] =
      a.mask.empty() ? nlohmann::json(nullptr) : nlohmann::json{{"path", a.mask}, {"pixels", mask->count()}};
  record["metrics"] = validation::to_json(m);
  record["thresholds"] = {
      {"fail_psnr", optional_number(a.fail_psnr)},       {"fail_ssim", optional_number(a.fail_ssim)},
      {"fail_percent", optional_number(a.fail_percent)}, {"warn_psnr", optional_number(a.warn_psnr)},
      {"warn_ssim", optional_number(a.warn_ssim)},       {"warn_percent", optional_number(a.warn_percent)}};
  record["verdict"] = verdict;
  record["failures"] = failures;
  record["warnings"] = warnings;
  record["exit_code"] = static_cast<int>(code);

  // The human summary, printed after the outputs are written; on stderr when stdout carries the
  // JSON.
  std::string text;
  const auto out = std::back_inserter(text);
  const auto describe = [](const std::string& path, const validation::Srgb8File& f) {
    return fmt::format("{} ({}{})", path, f.encoding, f.eye.empty() ? "" : ", " + f.eye + " eye");
  };
  fmt::format_to(out, "A: {}\nB: {}\n", describe(a.a, fa), describe(a.b, fb));
  if (region)
    fmt::format_to(out, "region: mask {}, {} of {} pixels\n", a.mask, m.pixels, fa.image.pixel_count());
  else
    fmt::format_to(out, "region: the whole image, {}x{} = {} pixels\n", fa.image.width, fa.image.height, m.pixels);
  fmt::format_to(out, "  {:<14} {:.6f}\n", "MSE", m.mse);
  fmt::format_to(out, "  {:<14} {} dB\n", "PSNR", format_psnr(m.psnr));
  if (std::isnan(m.ssim))
    fmt::format_to(out, "  {:<14} undefined (needs 11x11 images and region pixels outside the 5-pixel border)\n", "SSIM");
  else
    fmt::format_to(out, "  {:<14} {:.6f} (over {} pixels)\n", "SSIM", m.ssim, m.ssim_pixels);
  fmt::format_to(out, "  {:<14} {:.4f} % ({} pixels with a channel difference > {}/255)\n", "error pixels",
             100.0 * m.error_fraction, m.error_pixels, m.error_threshold);
  if (m.max_error == 0)
    fmt::format_to(out, "  {:<14} 0 (identical)\n", "max error");
  else
    fmt::format_to(out, "  {:<14} {}/255 at ({}, {})\n", "max error", m.max_error, m.max_x, m.max_y);
  for (const std::string& w : warnings) fmt::format_to(out, "warning: {}\n", w);  // a verdict line, beside failure: and verdict:
  for (const std::string& f : failures) fmt::format_to(out, "failure: {}\n", f);
  fmt::format_to(out, "verdict: {}\n",
             code == ExitCode::gate_failure   ? "FAIL"
             : code == ExitCode::gate_warning ? "WARN"
                                              : "PASS");
  if (!a.diff.empty()) fmt::format_to(out, "wrote {}\n", a.diff);
  if (!a.ssim_map.empty()) fmt::format_to(out, "wrote {}\n", a.ssim_map);
  if (!a.json.empty() && a.json != "-") fmt::format_to(out, "wrote {}\n", a.json);
  try {
    // Pictures first, so that a failing comparison still leaves them to look at.
    if (!a.diff.empty())
      write_for_option("--diff", [&] {
        validation::write_png(a.diff, validation::difference_image(fa.image, fb.image, region));
      });
    if (!a.ssim_map.empty())
      write_for_option("--ssim-map", [&] { validation::write_png(a.ssim_map, validation::ssim_image(ssim, region)); });
    if (a.json == "-")
      print_to_stdout(io::json_text(record, 2));
    else if (!a.json.empty())
      write_option_file("--json", a.json, io::json_text(record, 2) + "\n");
    // A summary standard output cannot take (a full disk behind a redirection) fails the run
    // too: its files go with it, as the help promises for exit 4. With --json - the summary goes
    // to standard error, as a courtesy: the JSON on standard output is the run's result.
    if (a.json != "-") print_to(stdout, text);
  } catch (const std::exception&) {
    // An output that cannot be written takes the others of this run with it.
    discard_outputs(outputs);
    throw;
  }

  if (a.json == "-") std::fputs(text.c_str(), stderr);
  return static_cast<int>(code);
}

constexpr const char* kCompareFooter = R"(
Metrics (DESIGN 6.2) are computed on 8-bit sRGB images:
  EXR and other linear float files are clamped to [0,1], encoded with the exact sRGB curve and
  rounded; 8-bit PNG/JPEG files are taken as stored (16-bit samples rounded to 8 bits), unless
  the file says its samples are linear (a PNG with gAMA 1.0, a TIFF tagged linear): those are
  encoded like EXR. The encoding each image was read with is printed beside its name. Grey
  images count as R=G=B; an alpha channel is ignored. Both images must have the same size and
  both be grey or both colour.
  MSE    sum of squared channel differences / (3 * pixels), on the 0..255 scale
  PSNR   10 log10(255^2 / MSE); "inf" for identical images
  SSIM   Wang et al. 2004: 11x11 Gaussian window (sigma 1.5), K1 0.01, K2 0.03, L 255, per
         channel then averaged, mean over the pixels at least 5 pixels from the border
         (undefined for images smaller than 11x11); agrees with scikit-image's
         structural_similarity to 1e-4
  error pixels  pixels whose largest channel difference exceeds --error-threshold codes
With --mask every metric is over the mask's non-zero pixels only (SSIM: those outside the border).
A stereo EXR (left./right. layers, parts named left/right, or OpenEXR multi-view with the default
view unnamed) needs --eye to pick the eye (for A, B and the mask alike); a file of one tagged eye
reads with --eye for it; --eye is ignored for single-image files.
Pictures: --diff maps each pixel's largest channel difference d on a fixed scale log2(1+d)/8 from
black (0) through violet, red, orange and yellow to pale yellow (255); --ssim-map shows SSIM 1 as
white and darkens through yellow, orange, red and violet to black at SSIM 0 (scale sqrt(1-SSIM));
the 5-pixel border without SSIM is grey. With --mask, pixels outside it are dimmed and its outline
is cyan.

Thresholds (as in OpenImageIO's idiff): the comparison fails when PSNR < --fail-psnr, SSIM <
--fail-ssim or the error-pixel percentage > --fail-percent, and warns on the --warn-* limits.

Exit codes: 0 pass, 1 warnings only, 2 failure, 3 bad input or usage (a missing, damaged or
non-image input file, a size or channel mismatch, an empty mask, a stereo EXR without --eye, an
SSIM limit where SSIM is undefined),
4 I/O failure (an existing input that cannot be opened, an output that cannot be written) or too
little memory (images whose comparison would not fit in what this process may use).
Exit 3 or 4 leaves no --json, --diff or --ssim-map file (an earlier one at that path is removed),
unless the command line itself cannot be read, names an input as an output or a picture not
ending in .png; on 0, 1 and 2 all are written.)";

}  // namespace

void register_compare_command(CLI::App& root) {
  auto a = std::make_shared<CompareArgs>();
  CLI::App* c = root.add_subcommand(
      "compare", "Compare two images: MSE, PSNR, SSIM, error pixels; pass/warn/fail thresholds, maps");
  c->add_option("A", a->a, "First image (EXR, PNG, ...)")->required();
  c->add_option("B", a->b, "Second image, e.g. the reference (EXR, PNG, ...); the metrics are symmetric")->required();
  c->add_option("--eye", a->eye, "Eye to take from a stereo EXR")->check(CLI::IsMember({"left", "right"}));
  c->add_option("--mask,-m", a->mask,
                "Compare only where this image (PNG, EXR, ...) is non-zero in a colour channel (alpha is not\n"
                "looked at; in an EXR, R, G and B, or its one channel)");
  c->add_option("--error-threshold", a->error_threshold,
                "An error pixel differs by more than this many 8-bit codes in some channel")
      ->capture_default_str();
  c->add_option("--json", a->json, "Write the metrics record as JSON to this file ('-': stdout, summary on stderr)");
  c->add_option("--diff", a->diff, "Write the difference heat map PNG here");
  c->add_option("--ssim-map", a->ssim_map, "Write the SSIM map PNG here");
  const char* g = "Thresholds";
  c->add_option("--fail-psnr", a->fail_psnr, "Fail when PSNR (dB) is below this")->group(g);
  c->add_option("--fail-ssim", a->fail_ssim, "Fail when SSIM is below this")->group(g);
  c->add_option("--fail-percent", a->fail_percent, "Fail when more than this percentage of pixels are error pixels")
      ->group(g);
  c->add_option("--warn-psnr", a->warn_psnr, "Warn when PSNR (dB) is below this")->group(g);
  c->add_option("--warn-ssim", a->warn_ssim, "Warn when SSIM is below this")->group(g);
  c->add_option("--warn-percent", a->warn_percent, "Warn when more than this percentage of pixels are error pixels")
      ->group(g);
  c->footer(kCompareFooter);
  c->callback([a] {
    // A warning or failure verdict is the command's result, not an error: main() returns its code.
    if (const int code = run_compare(*a); code != 0) throw VerdictExit{code};
  });
}

}  // namespace sb::cli
