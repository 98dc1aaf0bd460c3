// `stereobench compare`: metrics of two image files, idiff-style thresholds with the exit codes of
// DESIGN §2, the JSON record, the pictures, and clear errors for inputs that cannot be compared.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <fstream>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <tuple>
#include <cstring>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "renderer/color.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/image_io.hpp"
#include "support/run_cli.hpp"
#include "support/scratch_dir.hpp"
#include "validation/image_files.hpp"
#include "validation/metric_images.hpp"
#include "validation/metrics.hpp"

namespace sb {
namespace {

namespace fs = std::filesystem;
using test::CliRun;
using validation::Srgb8Image;

/// A 48 x 32 pattern; `noise` adds up to +-noise codes per channel at every `every`-th pixel.
Srgb8Image picture(int noise = 0, int every = 1, int w = 48, int h = 32) {
  Srgb8Image im{w, h, std::vector<uint8_t>(size_t(w) * size_t(h) * 3)};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        int v = int(std::lround(127.5 + 100.0 * std::sin(0.2 * x + 0.8 * c) * std::cos(0.15 * y)));
        const int i = y * w + x;
        if (noise > 0 && i % every == 0) v += ((i * 37 + c * 11) % (2 * noise + 1)) - noise;
        im.rgb[(size_t(i)) * 3 + size_t(c)] = uint8_t(std::clamp(v, 0, 255));
      }
  return im;
}

std::string q(const std::filesystem::path& p) { return "'" + p.string() + "'"; }

CliRun compare(const std::string& args) { return test::run_cli("compare " + args); }

/// Runs stereobench with stderr discarded, to read what it prints on stdout alone.
std::string stdout_of(const std::string& args) {
  const std::string cmd = std::string(SB_CLI_PATH) + " " + args + " 2>/dev/null";
  FILE* pipe = ::popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 1024> buf{};
  while (pipe && std::fgets(buf.data(), buf.size(), pipe)) out += buf.data();
  if (pipe) ::pclose(pipe);
  return out;
}

class Compare : public ::testing::Test {
 protected:
  void SetUp() override {
    validation::write_png(dir_ / "a.png", picture());
    // 1 in 7 pixels off by up to 6 codes.
    validation::write_png(dir_ / "b.png", picture(6, 7));
  }
  std::filesystem::path path(const std::string& name) const { return dir_ / name; }
  std::string ab() const { return q(path("a.png")) + " " + q(path("b.png")); }

  test::ScratchDir dir_{"compare"};
};

TEST_F(Compare, IdenticalImagesPass) {
  const CliRun r = compare(q(path("a.png")) + " " + q(path("a.png")) + " --fail-psnr 60 --fail-ssim 0.999");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("inf dB"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("0 (identical)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("verdict: PASS"), std::string::npos) << r.out;
}

TEST_F(Compare, ThresholdsGiveFailAndWarnExitCodes) {
  // The metrics of this pair, from the library: the limits below are placed around them.
  const validation::ImageMetrics m = validation::compare_images(picture(), picture(6, 7));
  ASSERT_GT(m.psnr, 30.0);
  ASSERT_LT(m.psnr, 60.0);
  ASSERT_GT(m.error_fraction, 0.0);
  const std::string psnr_above = std::to_string(m.psnr + 1.0), psnr_below = std::to_string(m.psnr - 1.0);

  CliRun r = compare(ab() + " --fail-psnr " + psnr_below + " --warn-psnr " + psnr_below);
  EXPECT_EQ(r.code, 0) << r.out;
  r = compare(ab() + " --warn-psnr " + psnr_above);
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("warning: PSNR"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("verdict: WARN"), std::string::npos) << r.out;
  r = compare(ab() + " --fail-psnr " + psnr_above + " --warn-psnr " + psnr_above);
  EXPECT_EQ(r.code, 2) << r.out;  // a failure outranks a warning
  EXPECT_NE(r.out.find("failure: PSNR"), std::string::npos) << r.out;
  // A limit just above the measured value, where the value's usual digits round up to it: the
  // message shows the digits that tell them apart (it printed "PSNR 39.4200 dB < --fail-psnr
  // 39.42" for 39.41995). PSNR is printed with 4 decimals, SSIM with 6; the one whose rounding goes
  // up is tried, both if both do.
  int tried = 0;
  for (const auto& [name, option, value, digits] :
       {std::tuple{"PSNR", "--fail-psnr", m.psnr, 4}, std::tuple{"SSIM", "--fail-ssim", m.ssim, 6}}) {
    const std::string rounded = fmt::format("{:.{}f}", value, digits);
    const double limit = value + 1e-12 * std::max(1.0, value);
    if (std::strtod(rounded.c_str(), nullptr) < limit) continue;  // rounds down: no collision to show
    ++tried;
    r = compare(ab() + " " + option + " " + fmt::format("{:.17g}", limit));
    EXPECT_EQ(r.code, 2) << r.out;
    const size_t at = r.out.find(fmt::format("failure: {} ", name));
    ASSERT_NE(at, std::string::npos) << r.out;
    EXPECT_LT(std::strtod(r.out.c_str() + at + 10 + std::strlen(name), nullptr), limit) << r.out;
  }
  EXPECT_GT(tried, 0) << "neither metric rounds up; pick another picture pair";
  r = compare(ab() + " --fail-ssim 1");
  EXPECT_EQ(r.code, 2) << r.out;
  r = compare(ab() + " --warn-ssim 1 --fail-ssim 0.5");
  EXPECT_EQ(r.code, 1) << r.out;
  r = compare(ab() + " --fail-percent 0");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("error pixels"), std::string::npos) << r.out;
  r = compare(ab() + " --fail-percent 100 --warn-percent 100");
  EXPECT_EQ(r.code, 0) << r.out;
  // Differences of up to 6 codes are no error pixels at --error-threshold 6.
  r = compare(ab() + " --fail-percent 0 --error-threshold 6");
  EXPECT_EQ(r.code, 0) << r.out;
  // Impossible limits are usage errors.
  for (const char* bad :
       {" --fail-ssim 2", " --warn-percent 101", " --fail-psnr -1", " --error-threshold 256", " --eye middle"}) {
    r = compare(ab() + bad);
    EXPECT_EQ(r.code, 3) << bad << ": " << r.out;
  }
  // So is a warning level beyond its failure level (it could never warn before failing).
  for (const char* bad : {" --warn-psnr 10 --fail-psnr 20", " --warn-ssim 0.5 --fail-ssim 0.9",
                          " --warn-percent 5 --fail-percent 1"}) {
    r = compare(ab() + bad);
    EXPECT_EQ(r.code, 3) << bad << ": " << r.out;
    EXPECT_NE(r.out.find("lies beyond --fail-"), std::string::npos) << bad << ": " << r.out;
  }
}

TEST_F(Compare, MismatchedAndMissingInputsAreBadInput) {
  validation::write_png(path("small.png"), picture(0, 1, 40, 30));
  CliRun r = compare(q(path("a.png")) + " " + q(path("small.png")));
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find("48x32"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("40x30"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("small.png"), std::string::npos) << r.out;

  r = compare(q(path("a.png")) + " " + q(path("nothere.png")));
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find("nothere.png: no such file"), std::string::npos) << r.out;

  std::vector<uint8_t> grey(48 * 32, 128);
  io::write_file_atomically(path("grey.png"), io::encode_png(grey.data(), 48, 32, 1));
  r = compare(q(path("a.png")) + " " + q(path("grey.png")));
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find("channel"), std::string::npos) << r.out;

  r = compare(q(path("a.png")));
  EXPECT_EQ(r.code, 3) << r.out;  // B is required

  // NaN in a float file tagged sRGB is refused as in an EXR (it was read as 0, black, and passed).
  if (std::system("command -v oiiotool >/dev/null 2>&1") == 0) {
    Image nan_image(48, 32);
    float* v = nan_image.add_plane(planes::rgb).data_f32();
    for (int i = 0; i < 48 * 32 * 3; ++i) v[i] = 0.5f;
    v[(10 * 48 + 20) * 3 + 1] = std::numeric_limits<float>::quiet_NaN();
    io::write_exr(path("nan.exr"), nan_image);
    ASSERT_EQ(std::system(("oiiotool " + q(path("nan.exr")) + " -d float --iscolorspace sRGB -o " + q(path("nan.tif")))
                              .c_str()),
              0);
    r = compare(q(path("a.png")) + " " + q(path("nan.tif")));
    EXPECT_EQ(r.code, 3) << r.out;
    EXPECT_NE(r.out.find("nan.tif has a NaN sample at pixel (20, 10)"), std::string::npos) << r.out;
  }

  // A device is no image: /dev/zero was read without end (the run spun until killed).
  r = test::run_shell("timeout 30 " + std::string(SB_CLI_PATH) + " compare /dev/zero " + q(path("a.png")));
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find("/dev/zero is a device, pipe or socket, not an image file"), std::string::npos) << r.out;
}

TEST_F(Compare, AStoppedComparisonLeavesNoOutputs) {
  const std::string outputs =
      " --json " + q(path("v.json")) + " --diff " + q(path("d.png")) + " --ssim-map " + q(path("s.png"));
  const auto none_left = [&](const char* json) {
    for (const char* name : {json, "d.png", "s.png"}) EXPECT_FALSE(fs::exists(path(name))) << name;
  };
  // A warning writes all three; bad input then removes them, so that the earlier verdict cannot be
  // read as this run's.
  ASSERT_EQ(compare(ab() + outputs + " --warn-psnr 90").code, 1);
  validation::write_png(path("small.png"), picture(0, 1, 40, 30));
  CliRun r = compare(q(path("a.png")) + " " + q(path("small.png")) + outputs);
  EXPECT_EQ(r.code, 3) << r.out;
  none_left("v.json");
  // An output that cannot be written (its folder is a file) is exit 4 and leaves the others unwritten.
  ASSERT_EQ(compare(ab() + outputs).code, 0);
  std::ofstream(path("file")) << "x\n";
  r = compare(ab() + " --diff " + q(path("d.png")) + " --ssim-map " + q(path("s.png")) + " --json " +
              q(path("file") / "v.json"));
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("--json " + (path("file") / "v.json").string()), std::string::npos) << r.out;
  none_left("file/v.json");
  // A file that fails only when written (/dev/full: a full disk): the error names the option and
  // what to do, and the pictures go with it.
  r = compare(ab() + " --diff " + q(path("d.png")) + " --ssim-map " + q(path("s.png")) + " --json /dev/full");
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("--json: cannot write /dev/full: No space left on device"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("give --json a path you can write"), std::string::npos) << r.out;
  for (const char* name : {"d.png", "s.png"}) EXPECT_FALSE(fs::exists(path(name))) << name;
  // A summary that standard output cannot take (a full disk behind a redirection) is exit 4 too,
  // and the files go with it (they stayed, the JSON's verdict beside an exit 4).
  r = test::run_shell("(" + std::string(SB_CLI_PATH) + " compare " + ab() + outputs + " --fail-psnr 90 > /dev/full)");
  EXPECT_EQ(r.code, 4) << r.out;
  EXPECT_NE(r.out.find("cannot write to standard output: No space left on device"), std::string::npos) << r.out;
  none_left("v.json");
  // So do the pictures' options (their errors named neither the option nor what to do), through a
  // link named as a picture.
  fs::create_symlink("/dev/full", path("full.png"));
  for (const char* option : {"--diff", "--ssim-map"}) {
    r = compare(ab() + " " + option + " " + q(path("full.png")));
    EXPECT_EQ(r.code, 4) << r.out;
    EXPECT_NE(r.out.find(std::string(option) + ": cannot write " + path("full.png").string() +
                         ": No space left on device"),
              std::string::npos)
        << r.out;
    EXPECT_NE(r.out.find(std::string("give ") + option + " a path you can write"), std::string::npos) << r.out;
  }
  // A picture name the run refuses is not its output: the file stays.
  std::ofstream(path("photo.jpg")) << "a photo\n";
  r = compare(ab() + " --diff " + q(path("photo.jpg")));
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_EQ(test::read_text(path("photo.jpg")), "a photo\n");
  // Through a link, the file it names is the output: written through it, and removed by a stopped
  // run while the link stays (it used to be replaced by a plain file, or removed itself).
  std::filesystem::create_symlink("real.json", path("link.json"));
  ASSERT_EQ(compare(ab() + " --json " + q(path("link.json"))).code, 0);
  EXPECT_TRUE(std::filesystem::is_symlink(path("link.json")));
  EXPECT_NE(test::read_text(path("real.json")).find("\"verdict\""), std::string::npos);
  r = compare(q(path("a.png")) + " " + q(path("small.png")) + " --json " + q(path("link.json")));
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_TRUE(std::filesystem::is_symlink(path("link.json")));
  EXPECT_FALSE(std::filesystem::exists(path("real.json")));
}

TEST_F(Compare, JsonRecord) {
  const CliRun r = compare(ab() + " --json " + q(path("out/metrics.json")) + " --warn-ssim 1");
  EXPECT_EQ(r.code, 1) << r.out;
  const nlohmann::json j = nlohmann::json::parse(test::read_text(path("out/metrics.json")));
  const validation::ImageMetrics m = validation::compare_images(picture(), picture(6, 7));
  EXPECT_EQ(j["metrics_version"], validation::kMetricsVersion);
  EXPECT_EQ(j["metrics"], validation::to_json(m));
  EXPECT_EQ(j["a"]["width"], 48);
  EXPECT_EQ(j["b"]["path"], path("b.png").string());
  EXPECT_TRUE(j["mask"].is_null());
  EXPECT_EQ(j["verdict"], "warn");
  EXPECT_EQ(j["exit_code"], 1);
  EXPECT_EQ(j["thresholds"]["warn_ssim"], 1.0);
  EXPECT_TRUE(j["thresholds"]["fail_psnr"].is_null());
  ASSERT_EQ(j["warnings"].size(), 1u);

  // --json - puts the record alone on stdout; identical images give PSNR "inf".
  const nlohmann::json same =
      nlohmann::json::parse(stdout_of("compare " + q(path("a.png")) + " " + q(path("a.png")) + " --json -"));
  EXPECT_EQ(same["metrics"]["psnr"], "inf");
  EXPECT_EQ(same["metrics"]["mse"], 0.0);
  EXPECT_EQ(same["verdict"], "pass");
}

TEST_F(Compare, MaskAndPictures) {
  // Mask: the left half.
  std::vector<uint8_t> mask(48 * 32, 0);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 24; ++x) mask[size_t(y) * 48 + size_t(x)] = 255;
  io::write_file_atomically(path("mask.png"), io::encode_png(mask.data(), 48, 32, 1));
  const CliRun r = compare(ab() + " --mask " + q(path("mask.png")) + " --json " + q(path("m.json")) + " --diff " +
                           q(path("pics/diff.png")) + " --ssim-map " + q(path("pics/ssim.png")));
  EXPECT_EQ(r.code, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(test::read_text(path("m.json")));
  EXPECT_EQ(j["mask"]["pixels"], 24 * 32);
  EXPECT_EQ(j["metrics"]["pixels"], 24 * 32);
  validation::RegionMask region = validation::read_region_mask(path("mask.png"));
  const Srgb8Image a = picture(), b = picture(6, 7);
  EXPECT_EQ(j["metrics"], validation::to_json(validation::compare_images(a, b, &region)));
  // The pictures are the library's, written as PNG.
  EXPECT_EQ(validation::read_srgb8_file(path("pics/diff.png")).image.rgb,
            validation::difference_image(a, b, &region).rgb);
  EXPECT_EQ(validation::read_srgb8_file(path("pics/ssim.png")).image.rgb,
            validation::ssim_image(validation::ssim_map(a, b), &region).rgb);

  // An empty mask is refused rather than reported as a perfect match.
  std::fill(mask.begin(), mask.end(), uint8_t{0});
  io::write_file_atomically(path("empty.png"), io::encode_png(mask.data(), 48, 32, 1));
  const CliRun e = compare(ab() + " --mask " + q(path("empty.png")));
  EXPECT_EQ(e.code, 3) << e.out;
  EXPECT_NE(e.out.find("empty"), std::string::npos) << e.out;
}

TEST_F(Compare, StereoExrNeedsAnEye) {
  const auto linear = [](const Srgb8Image& s) {
    Image im(s.width, s.height);
    float* v = im.add_plane(planes::rgb).data_f32();
    for (size_t i = 0; i < s.rgb.size(); ++i) v[i] = srgb8_to_linear(s.rgb[i]);
    return im;
  };
  io::write_exr_stereo(path("pair.exr"), linear(picture(6, 7)), linear(picture()));
  CliRun r = compare(q(path("pair.exr")) + " " + q(path("a.png")));
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find("--eye left|right"), std::string::npos) << r.out;
  // The right eye is exactly a.png after encoding.
  r = compare(q(path("pair.exr")) + " " + q(path("a.png")) + " --eye right --fail-psnr 1000");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("inf dB"), std::string::npos) << r.out;
  r = compare(q(path("pair.exr")) + " " + q(path("a.png")) + " --eye left --fail-psnr 1000");
  EXPECT_EQ(r.code, 2) << r.out;

  // OpenEXR multi-view, the default view unnamed: a pair too (its unnamed channels were taken for
  // the whole image, whatever --eye said). Left a flat grey, right a.png's pattern.
  if (std::system("command -v oiiotool >/dev/null 2>&1") == 0) {
    ASSERT_EQ(std::system(("oiiotool --pattern constant:color=0.2,0.2,0.2 48x32 3 -d float " + q(path("a.png")) +
                           " --ch R,G,B --colorconvert sRGB linear -d float --chappend "
                           "--chnames R,G,B,right.R,right.G,right.B -o " + q(path("mv.exr")))
                              .c_str()),
              0);
    r = compare(q(path("mv.exr")) + " " + q(path("a.png")));
    EXPECT_EQ(r.code, 3) << r.out;
    EXPECT_NE(r.out.find("--eye left|right"), std::string::npos) << r.out;
    r = compare(q(path("mv.exr")) + " " + q(path("a.png")) + " --eye right --fail-psnr 50");
    EXPECT_EQ(r.code, 0) << r.out;
    r = compare(q(path("mv.exr")) + " " + q(path("a.png")) + " --eye left --fail-psnr 50");
    EXPECT_EQ(r.code, 2) << r.out;
    // One eye alone, tagged: read with --eye for it (it was refused as a pair without its other eye).
    ASSERT_EQ(std::system(("oiiotool " + q(path("a.png")) + " --ch R,G,B --colorconvert sRGB linear -d float "
                           "--chnames left.R,left.G,left.B -o " + q(path("left-only.exr")))
                              .c_str()),
              0);
    r = compare(q(path("left-only.exr")) + " " + q(path("a.png")) + " --eye left --fail-psnr 50");
    EXPECT_EQ(r.code, 0) << r.out;
    r = compare(q(path("left-only.exr")) + " " + q(path("a.png")) + " --eye right");
    EXPECT_EQ(r.code, 3) << r.out;
    EXPECT_NE(r.out.find("left-only.exr holds no right eye (channels: "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("); it holds the left eye"), std::string::npos) << r.out;
  }

  // A damaged pair reports the damage, not that it is a pair.
  fs::copy_file(path("pair.exr"), path("cut.exr"));
  fs::resize_file(path("cut.exr"), fs::file_size(path("cut.exr")) - 64);
  r = compare(q(path("cut.exr")) + " " + q(path("a.png")) + " --eye right");
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find(path("cut.exr").string()), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("holds a stereo pair"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("read_exr_stereo"), std::string::npos) << "an internal name: " << r.out;
}

TEST_F(Compare, OutputsNeverOverwriteInputs) {
  const std::string before = test::read_text(path("a.png"));
  // Each used to succeed, replacing an input (or one picture the other) without a word.
  const std::pair<std::string, std::string> cases[] = {
      {" --diff " + q(path("a.png")), "--diff " + path("a.png").string() + " names the same file as image A"},
      {" --json " + q(dir_.path() / "." / "b.png"), "names the same file as image B"},
      {" --diff " + q(path("d.png")) + " --ssim-map " + q(dir_.path() / "." / "d.png"),
       "--diff and --ssim-map both name"},
      {" --diff " + q(path("d.exr")), "--diff " + path("d.exr").string() + ": the picture is written as PNG"},
  };
  for (const auto& [args, expect] : cases) {
    const CliRun r = compare(ab() + args);
    EXPECT_EQ(r.code, 3) << args << "\n" << r.out;
    EXPECT_NE(r.out.find(expect), std::string::npos) << args << "\nexpected: " << expect << "\ngot: " << r.out;
  }
  EXPECT_EQ(test::read_text(path("a.png")), before);
  EXPECT_FALSE(fs::exists(path("d.png")));
}

TEST_F(Compare, GreyExrCountsAsGrey) {
  // A one-channel EXR (here named y) is grey, as a grey PNG is: it used to be refused for lacking R, G, B.
  std::vector<uint8_t> codes(48 * 32);
  Image grey(48, 32);
  float* v = grey.add_plane("y", 1, PlaneType::f32).data_f32();
  for (size_t i = 0; i < codes.size(); ++i) {
    codes[i] = uint8_t(i % 251);
    v[i] = srgb8_to_linear(codes[i]);
  }
  io::write_exr(path("grey.exr"), grey);
  io::write_file_atomically(path("grey.png"), io::encode_png(codes.data(), 48, 32, 1));
  CliRun r = compare(q(path("grey.exr")) + " " + q(path("grey.png")) + " --fail-psnr 1000");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("inf dB"), std::string::npos) << r.out;
  // Grey against colour is still refused, naming the channel counts.
  r = compare(q(path("grey.exr")) + " " + q(path("a.png")));
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find("has 1 colour channel(s)"), std::string::npos) << r.out;
  // Grey with an alpha channel: the alpha is not read, as in a grey + alpha PNG.
  float* a = grey.add_plane(std::string(planes::alpha), 1, PlaneType::f32).data_f32();
  std::fill(a, a + codes.size(), 0.5f);
  io::write_exr(path("grey-alpha.exr"), grey);
  r = compare(q(path("grey-alpha.exr")) + " " + q(path("grey.png")) + " --fail-psnr 1000");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("inf dB"), std::string::npos) << r.out;
  // As a mask it is its grey channel: alpha 0.5 everywhere would make the whole image the region.
  Image ids(48, 32);
  uint32_t* id = ids.add_plane("id", 1, PlaneType::u32).data_u32();
  for (size_t i = 0; i < codes.size(); ++i) id[i] = i < 48 ? 7u : 0u;  // the top row
  io::write_exr(path("ids.exr"), ids);
  r = compare(q(path("grey.exr")) + " " + q(path("grey.png")) + " --mask " + q(path("ids.exr")));
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("48 of 1536 pixels"), std::string::npos) << "an integer mask channel counts: " << r.out;
  // A mask of an alpha channel alone is that channel.
  Image coverage(48, 32);
  float* alpha = coverage.add_plane(std::string(planes::alpha), 1, PlaneType::f32).data_f32();
  for (size_t i = 0; i < codes.size(); ++i) alpha[i] = i < 96 ? 1.0f : 0.0f;  // the top two rows
  io::write_exr(path("alpha.exr"), coverage);
  r = compare(q(path("grey.exr")) + " " + q(path("grey.png")) + " --mask " + q(path("alpha.exr")));
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("96 of 1536 pixels"), std::string::npos) << r.out;
}

TEST(CompareHelp, ExplainsMetricsAndExitCodes) {
  const CliRun h = test::run_cli("compare --help");
  EXPECT_EQ(h.code, 0);
  for (const char* s : {"--fail-psnr", "--warn-percent", "--ssim-map", "--eye", "Exit codes", "scikit-image", "sRGB"})
    EXPECT_NE(h.out.find(s), std::string::npos) << s << "\n" << h.out;
}

}  // namespace
}  // namespace sb
