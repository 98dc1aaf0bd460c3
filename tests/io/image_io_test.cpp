// Tests of image file I/O: bit-exact stereo EXR round trips, metadata, foreign EXR layouts (half
// float, plain RGBA, Blender and multi-view names, multi-part), sRGB PNG previews, in-memory PNG
// encoding and decoding, and the error paths (missing, corrupt and unwritable files).
#include <gtest/gtest.h>

#include <memory>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "renderer/color.hpp"
#include "renderer/error.hpp"
#include "renderer/image.hpp"
#include "renderer/io/atomic_file.hpp"
#include "renderer/io/image_io.hpp"
#include "renderer/io/line_file.hpp"

#include "support/file_size_limit.hpp"
#include "support/scoped_env.hpp"
#include "support/scratch_dir.hpp"

namespace sb {
namespace {

namespace fs = std::filesystem;

/// A fresh scratch folder per test.
class ImageIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scratch_ = std::make_unique<test::ScratchDir>();
    dir_ = scratch_->path();
  }
  void TearDown() override { scratch_.reset(); }
  [[nodiscard]] fs::path path(const std::string& name) const { return dir_ / name; }
  /// Names of the entries in the test folder.
  [[nodiscard]] std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

  std::unique_ptr<test::ScratchDir> scratch_;
  fs::path dir_;
};

/// A float with random bits that is not NaN (covers infinities, denormals and -0).
float random_float(std::mt19937& rng) {
  for (;;) {
    const float f = std::bit_cast<float>(static_cast<uint32_t>(rng()));
    if (!std::isnan(f)) return f;
  }
}

/// An image with every standard plane plus generic float and uint32 planes, random content.
Image random_image(int width, int height, uint32_t seed) {
  std::mt19937 rng(seed);
  Image image(width, height);
  for (const std::string_view name : {planes::rgb, planes::depth, planes::normal, planes::albedo}) {
    for (float& v : image.add_plane(name).f32()) v = random_float(rng);
  }
  const auto primid = image.add_plane(planes::primid).u32();
  for (std::size_t i = 0; i < primid.size(); ++i) primid[i] = i % 3 == 0 ? kNoPrimitive : static_cast<uint32_t>(rng());
  primid[0] = kNoPrimitive;
  primid[1] = 0;
  const auto source = image.add_plane(planes::source).u32();
  for (std::size_t i = 0; i < source.size(); ++i) source[i] = static_cast<uint32_t>(i % kSourceCount);
  // Other planes, in the order a reader restores them (by name).
  for (float& v : image.add_plane("feature", 5, PlaneType::f32).f32()) v = random_float(rng);
  for (float& v : image.add_plane("motion", 2, PlaneType::f32).f32()) v = random_float(rng);
  for (uint32_t& v : image.add_plane("sample_count", 1, PlaneType::u32).u32()) v = static_cast<uint32_t>(rng());
  return image;
}

std::vector<std::string> channel_names(const fs::path& file) {
  std::vector<std::string> names;
  for (const auto& ch : io::read_channel_info(file)) names.push_back(ch.name);
  return names;
}

std::string format_of(const fs::path& file, const std::string& channel) {
  for (const auto& ch : io::read_channel_info(file))
    if (ch.name == channel) return ch.format;
  return "<missing>";
}

bool has_oiiotool() { return std::system("oiiotool --version > /dev/null 2>&1") == 0; }

void run(const std::string& command) { ASSERT_EQ(std::system(command.c_str()), 0) << command; }

void write_bytes(const fs::path& file, const std::vector<unsigned char>& bytes) {
  std::ofstream out(file, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

std::vector<unsigned char> read_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Expects `f` to throw an error of type E whose message contains `needle`.
template <typename E, typename F>
void expect_error(F&& f, const std::string& needle) {
  try {
    f();
    ADD_FAILURE() << "expected an exception mentioning '" << needle << "'";
  } catch (const E& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << "message: " << e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "wrong exception type, message: " << e.what();
  }
}

// ---- EXR round trips ------------------------------------------------------------------------

TEST_F(ImageIoTest, StereoExrRoundTripIsBitExactForEveryPlaneType) {
  const Image left = random_image(37, 23, 1);
  const Image right = random_image(37, 23, 2);
  const fs::path file = path("pair.exr");
  io::write_exr_stereo(file, left, right);

  const auto [read_left, read_right] = io::read_exr_stereo(file);
  EXPECT_TRUE(read_left == left) << "planes read: " << read_left.plane_list();
  EXPECT_TRUE(read_right == right) << "planes read: " << read_right.plane_list();
  EXPECT_EQ(read_left.plane(planes::primid).u32()[0], kNoPrimitive);

  // Channel names and per-channel formats follow the OpenEXR layer conventions.
  const std::vector<std::string> names = channel_names(file);
  for (const std::string eye : {"left.", "right."}) {
    for (const std::string ch : {"R", "G", "B", "Z", "N.X", "N.Y", "N.Z", "albedo.R", "albedo.G", "albedo.B", "primid",
                                 "source", "motion.R", "motion.G", "sample_count", "feature.0", "feature.4"})
      EXPECT_NE(std::find(names.begin(), names.end(), eye + ch), names.end()) << eye + ch;
    EXPECT_EQ(format_of(file, eye + "R"), "float");
    EXPECT_EQ(format_of(file, eye + "Z"), "float");
    EXPECT_EQ(format_of(file, eye + "primid"), "uint");
    EXPECT_EQ(format_of(file, eye + "source"), "uint");
    EXPECT_EQ(format_of(file, eye + "sample_count"), "uint");
  }
  EXPECT_EQ(io::read_exr_metadata(file).at("compression"), "zip");
  EXPECT_EQ(entries(), std::vector<std::string>{"pair.exr"});  // no temporary left behind
}

TEST_F(ImageIoTest, MonoExrUsesUnprefixedChannelsAndRoundTrips) {
  const Image image = random_image(16, 9, 3);
  const fs::path file = path("mono.exr");
  io::write_exr(file, image);
  const std::vector<std::string> names = channel_names(file);
  for (const std::string ch : {"R", "G", "B", "Z", "N.X", "albedo.B", "primid", "source"})
    EXPECT_NE(std::find(names.begin(), names.end(), ch), names.end()) << ch;
  EXPECT_TRUE(io::read_exr(file) == image);
  // A mono file is not a stereo pair, and a stereo file is not a mono image.
  expect_error<InputError>([&] { (void)io::read_exr_stereo(file); }, "no stereo pair");
  io::write_exr_stereo(path("pair.exr"), image, image);
  expect_error<InputError>([&] { (void)io::read_exr(path("pair.exr")); }, "read_exr_stereo");
}

TEST_F(ImageIoTest, PlaneOrderIsRestoredCanonically) {
  Image image(4, 3);
  image.add_plane("zeta", 1, PlaneType::f32).fill(2.0f);
  image.add_plane(planes::source).fill(static_cast<uint32_t>(Source::traced));
  image.add_plane(planes::rgb).fill(0.25f);
  image.add_plane("beta", 3, PlaneType::u32).fill(9u);
  io::write_exr(path("order.exr"), image);
  const Image read = io::read_exr(path("order.exr"));
  EXPECT_EQ(read.plane_list(), "rgb, source, beta, zeta");  // standard planes first, then by name
  EXPECT_EQ(read.plane("beta").at_u32(3, 2, 2), 9u);
  EXPECT_EQ(read.plane("zeta").f32()[5], 2.0f);
  EXPECT_EQ(read.plane(planes::source).u32()[11], static_cast<uint32_t>(Source::traced));
}

TEST_F(ImageIoTest, SameImageGivesByteIdenticalExrFiles) {
  const Image image = random_image(21, 13, 14);
  io::write_exr_stereo(path("a.exr"), image, image, {{"stereobench/rig", "{}"}});
  io::write_exr_stereo(path("b.exr"), image, image, {{"stereobench/rig", "{}"}});
  EXPECT_EQ(read_bytes(path("a.exr")), read_bytes(path("b.exr")));
  // No time stamp: OpenImageIO would otherwise add the current time to every file.
  EXPECT_EQ(io::read_exr_metadata(path("a.exr")).count("DateTime"), 0u);
}

TEST_F(ImageIoTest, MetadataRoundTrips) {
  const std::string rig_json = R"({"interaxial":0.064,"convergence":2.0,"width":37,"name":"caf\u00e9 \"quoted\""})";
  const io::ImageMetadata metadata = {
      {"stereobench/rig", rig_json},
      {"stereobench/provenance", std::string(10000, 'x')},
      {"stereobench:colon", "a value"},
      {"stereobench/utf8", "Wi\xc3\x9fmann"},
  };
  const Image image = random_image(5, 4, 4);
  io::write_exr_stereo(path("meta.exr"), image, image, metadata);
  const io::ImageMetadata read = io::read_exr_metadata(path("meta.exr"));
  for (const auto& [key, value] : metadata) {
    ASSERT_TRUE(read.count(key)) << key;
    EXPECT_EQ(read.at(key), value) << key;
  }
}

TEST_F(ImageIoTest, ReservedOrInvalidMetadataKeysAreRejectedBeforeWriting) {
  const Image image = random_image(4, 4, 5);
  expect_error<InputError>([&] { io::write_exr(path("a.exr"), image, {{"compression", "none"}}); }, "compression");
  expect_error<InputError>([&] { io::write_exr(path("a.exr"), image, {{"", "x"}}); }, "invalid");
  expect_error<InputError>([&] { io::write_exr(path("a.exr"), image, {{"stereobench/x", ""}}); }, "empty");
  expect_error<InputError>([&] { io::write_exr(path("a.exr"), image, {}, {io::ExrFloatFormat::f32, "lzw"}); }, "lzw");
  EXPECT_TRUE(entries().empty());
}

TEST_F(ImageIoTest, UnwritableImagesAreInputErrors) {
  expect_error<InputError>([&] { io::write_exr(path("e.exr"), Image(0, 0)); }, "empty");
  expect_error<InputError>([&] { io::write_exr(path("e.exr"), Image(3, 3)); }, "no planes");
  expect_error<InputError>([&] { io::write_exr_stereo(path("e.exr"), random_image(4, 4, 1), random_image(5, 4, 2)); },
                           "differ in size");
  EXPECT_TRUE(entries().empty());
}

TEST_F(ImageIoTest, HalfFloatExrFromOwnWriterReadsExactly) {
  // Values representable in half precision survive the round trip exactly.
  Image image(8, 4);
  auto rgb = image.add_plane(planes::rgb).f32();
  for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<float>(i) / 64.0f - 0.5f;
  image.add_plane(planes::depth).fill(1000.5f);  // 11 significant bits: exact in half
  image.add_plane(planes::primid).fill(0xFFFFFFF0u);
  io::write_exr(path("half.exr"), image, {}, {io::ExrFloatFormat::f16, "piz"});
  EXPECT_EQ(format_of(path("half.exr"), "R"), "half");
  EXPECT_EQ(format_of(path("half.exr"), "primid"), "uint");  // ids are never narrowed
  EXPECT_TRUE(io::read_exr(path("half.exr")) == image);
}

TEST_F(ImageIoTest, PlainRgbaHalfExrFromAnotherToolIsRead) {
  if (!has_oiiotool()) GTEST_SKIP() << "oiiotool (Debian package openimageio-tools) is not installed";
  // What POV-Ray's +FE writes: plain R, G, B, A in half float.
  const fs::path file = path("povray.exr");
  run("oiiotool --pattern constant:color=0.25,0.5,1,0.75 5x3 4 -d half -o " + file.string());
  EXPECT_EQ(format_of(file, "R"), "half");
  const Image image = io::read_exr(file);
  EXPECT_EQ(image.width(), 5);
  EXPECT_EQ(image.height(), 3);
  EXPECT_EQ(image.plane_list(), "rgb, alpha");
  EXPECT_EQ(image.rgb_at(4, 2), (std::array<float, 3>{0.25f, 0.5f, 1.0f}));
  EXPECT_EQ(image.plane(planes::alpha).at_f32(0, 0), 0.75f);

  // A plain float RGB file too.
  run("oiiotool --pattern constant:color=0.125,2,3 2x2 3 -d float -o " + path("plain.exr").string());
  EXPECT_EQ(io::read_exr(path("plain.exr")).rgb_at(1, 1), (std::array<float, 3>{0.125f, 2.0f, 3.0f}));

  // A data window smaller than the display window lands at its offset; the rest stays zero.
  run("oiiotool --pattern constant:color=1,2,3 2x2 3 -d float --origin +1+1 --fullsize 4x3+0+0 -o " +
      path("window.exr").string());
  const Image window = io::read_exr(path("window.exr"));
  EXPECT_EQ(window.width(), 4);
  EXPECT_EQ(window.height(), 3);
  EXPECT_EQ(window.rgb_at(1, 1), (std::array<float, 3>{1, 2, 3}));
  EXPECT_EQ(window.rgb_at(2, 2), (std::array<float, 3>{1, 2, 3}));
  EXPECT_EQ(window.rgb_at(0, 0), (std::array<float, 3>{0, 0, 0}));
  EXPECT_EQ(window.rgb_at(3, 1), (std::array<float, 3>{0, 0, 0}));

  // A data window beyond the largest image side, around a small display window, is named as such
  // (it is what would be read: the message named the display window's size).
  run("oiiotool --pattern constant:color=1,2,3 70000x1 3 -d half --fullsize 4x3+0+0 -o " + path("wide.exr").string());
  try {
    (void)io::read_exr(path("wide.exr"));
    ADD_FAILURE() << "a 70000-pixel data window was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("part 0 has a data window of 70000x1; each side must be in 1..65536"),
              std::string::npos)
        << e.what();
  }
}

TEST_F(ImageIoTest, BlenderMultilayerNamesMapToStandardPlanes) {
  if (!has_oiiotool()) GTEST_SKIP() << "oiiotool (Debian package openimageio-tools) is not installed";
  const fs::path file = path("blender.exr");
  run("oiiotool --pattern constant:color=0.1,0.2,0.3,1,5,0,0,1,0.5,0.5,0.5,7 3x2 12 -d half "
      "--chnames ViewLayer.Combined.R,ViewLayer.Combined.G,ViewLayer.Combined.B,ViewLayer.Combined.A,"
      "ViewLayer.Depth.Z,ViewLayer.Normal.X,ViewLayer.Normal.Y,ViewLayer.Normal.Z,"
      "ViewLayer.DiffCol.R,ViewLayer.DiffCol.G,ViewLayer.DiffCol.B,ViewLayer.Emit.R -o " +
      file.string());
  const Image image = io::read_exr(file);
  EXPECT_EQ(image.plane_list(), "rgb, alpha, depth, normal, albedo, viewlayer_emit");
  EXPECT_EQ(image.plane(planes::depth).at_f32(2, 1), 5.0f);
  EXPECT_EQ(image.plane(planes::normal).at_f32(0, 0, 2), 1.0f);
  EXPECT_EQ(image.plane(planes::albedo).at_f32(1, 1, 1), 0.5f);
  EXPECT_EQ(image.plane("viewlayer_emit").at_f32(0, 1), 7.0f);
}

TEST_F(ImageIoTest, MultiViewAndMultiPartStereoFilesAreRead) {
  if (!has_oiiotool()) GTEST_SKIP() << "oiiotool (Debian package openimageio-tools) is not installed";
  // OpenEXR multi-view: the default (left) view's channels carry no view name.
  const fs::path multiview = path("multiview.exr");
  run("oiiotool --pattern constant:color=1,2,3,4,5,6 2x2 6 -d float --chnames R,G,B,right.R,right.G,right.B -o " +
      multiview.string());
  const auto [left, right] = io::read_exr_stereo(multiview);
  EXPECT_EQ(left.rgb_at(1, 1), (std::array<float, 3>{1, 2, 3}));
  EXPECT_EQ(right.rgb_at(1, 1), (std::array<float, 3>{4, 5, 6}));
  // It is a pair to every reader: read as one image it gave the default view and dropped the other.
  EXPECT_TRUE(io::exr_holds_stereo_pair(multiview));
  expect_error<InputError>([&] { (void)io::read_exr(multiview); }, "holds a stereo pair");

  // Two parts named left and right.
  const fs::path parts = path("parts.exr");
  run("oiiotool --pattern constant:color=1,2,3 2x2 3 -d float --sattrib oiio:subimagename left "
      "--pattern constant:color=7,8,9 2x2 3 -d float --sattrib oiio:subimagename right --siappend -o " +
      parts.string());
  const auto [part_left, part_right] = io::read_exr_stereo(parts);
  EXPECT_EQ(part_left.rgb_at(0, 0), (std::array<float, 3>{1, 2, 3}));
  EXPECT_EQ(part_right.rgb_at(0, 0), (std::array<float, 3>{7, 8, 9}));
}

// ---- Errors on reading ----------------------------------------------------------------------

TEST_F(ImageIoTest, MissingFileSaysItDoesNotExist) {
  const fs::path file = path("nowhere.exr");
  expect_error<InputError>([&] { (void)io::read_exr(file); }, file.string() + " does not exist");
  expect_error<InputError>([&] { (void)io::read_exr_stereo(file); }, "does not exist");
  expect_error<InputError>([&] { (void)io::read_exr_metadata(file); }, "does not exist");
  expect_error<InputError>([&] { (void)io::read_image(path("nowhere.png")); }, "does not exist");
}

TEST_F(ImageIoTest, RandomBytesAreAnInputErrorNamingTheFile) {
  std::mt19937 rng(7);
  std::vector<unsigned char> garbage(4096);
  for (auto& b : garbage) b = static_cast<unsigned char>(rng());
  for (const std::string name : {"garbage.exr", "garbage.png", "garbage.jpg", "garbage"}) {
    write_bytes(path(name), garbage);
    expect_error<InputError>([&] { (void)io::read_exr(path(name)); }, path(name).string());
    expect_error<InputError>([&] { (void)io::read_image(path(name)); }, path(name).string());
  }
  expect_error<InputError>([&] { (void)io::decode_image(garbage, "scene.glb image 2"); }, "scene.glb image 2");
}

TEST_F(ImageIoTest, TruncatedExrIsAnInputErrorNamingTheFile) {
  const Image image = random_image(64, 48, 8);
  io::write_exr_stereo(path("full.exr"), image, image);
  const std::vector<unsigned char> bytes = read_bytes(path("full.exr"));
  for (const std::size_t keep : {bytes.size() / 2, bytes.size() - 100, std::size_t{200}, std::size_t{8}}) {
    const fs::path cut = path("cut-" + std::to_string(keep) + ".exr");
    write_bytes(cut, {bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(keep)});
    expect_error<InputError>([&] { (void)io::read_exr_stereo(cut); }, cut.string());
  }
}

TEST_F(ImageIoTest, TruncatedPngIsAnInputError) {
  std::vector<uint8_t> pixels(32 * 32 * 3);
  std::mt19937 rng(9);
  for (auto& p : pixels) p = static_cast<uint8_t>(rng());
  const std::vector<unsigned char> png = io::encode_png(pixels.data(), 32, 32, 3);
  const std::vector<unsigned char> cut(png.begin(), png.begin() + static_cast<std::ptrdiff_t>(png.size() / 2));
  expect_error<InputError>([&] { (void)io::decode_image(cut, "half.png"); }, "half.png");
  expect_error<InputError>([&] { (void)io::decode_image({}, "empty.png"); }, "empty.png");
  // libpng reports the fault and OpenImageIO quotes it again: the message says each report once,
  // on one line (it read "Read error: hit end of file PNG read error: IDAT: Read error: ...").
  try {
    (void)io::decode_image(cut, "half.png");
    ADD_FAILURE() << "a truncated PNG decoded";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    const std::string head = "cannot decode image half.png: ";
    ASSERT_EQ(m.rfind(head, 0), 0u) << m;
    // libpng's report of the fault ("Read error: hit end of file" with this libpng) once.
    const std::string fault = "Read error";
    ASSERT_NE(m.find(fault), std::string::npos) << m;
    EXPECT_EQ(m.find(fault, m.find(fault) + 1), std::string::npos) << m;
  }
}

/// The PNG CRC-32 (ISO 3309) of `bytes`.
uint32_t png_crc(const unsigned char* bytes, std::size_t n) {
  uint32_t c = 0xffffffffu;
  for (std::size_t i = 0; i < n; ++i) {
    c ^= bytes[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return c ^ 0xffffffffu;
}

TEST_F(ImageIoTest, APngDeclaringMoreRowsThanItHoldsFailsBeforeTouchingTheirMemory) {
  // A real 16x16 PNG whose header is rewritten to declare 12000x4000: decoded as float that would
  // be 550 MiB, but the file holds 16 rows.
  std::vector<uint8_t> pixels(16 * 16 * 3, 128);
  std::vector<unsigned char> png = io::encode_png(pixels.data(), 16, 16, 3);
  ASSERT_GT(png.size(), 33u);
  ASSERT_EQ(std::string(png.begin() + 12, png.begin() + 16), "IHDR");
  const auto put32 = [&](std::size_t at, uint32_t v) {
    for (int k = 0; k < 4; ++k) png[at + static_cast<std::size_t>(k)] = static_cast<unsigned char>(v >> (24 - 8 * k));
  };
  put32(16, 12000);
  put32(20, 4000);
  put32(29, png_crc(png.data() + 12, 17));  // chunk type and 13 data bytes
  // The peak resident size is reset first (Linux: 5 to clear_refs), so that an earlier peak of
  // this process (the whole binary run at once) cannot hide the growth.
  std::ofstream("/proc/self/clear_refs") << "5";
  rusage before{};
  ASSERT_EQ(getrusage(RUSAGE_SELF, &before), 0);
  expect_error<InputError>([&] { (void)io::decode_image(png, "tall.png"); }, "cannot decode image tall.png");
  rusage after{};
  ASSERT_EQ(getrusage(RUSAGE_SELF, &after), 0);
  // ru_maxrss is the peak resident size in KiB. Decoding the whole declared size first touched all
  // 550 MiB before the missing rows were noticed; a band of 256 rows is 35 MiB.
  EXPECT_LT(after.ru_maxrss - before.ru_maxrss, 96L * 1024L);
}

TEST_F(ImageIoTest, AnImageOfManyBandsDecodesWhole) {
  // 12000 x 600 RGB: bands of 256 rows (about 64 MiB of floats each rounded down to 256 rows),
  // the third one short; every sample where it belongs.
  constexpr int kW = 12000, kH = 600;
  std::vector<uint8_t> pixels(static_cast<std::size_t>(kW) * kH * 3);
  std::mt19937 rng(17);
  for (auto& p : pixels) p = static_cast<uint8_t>(rng());
  const io::DecodedImage decoded = io::decode_image(io::encode_png(pixels.data(), kW, kH, 3), "bands.png");
  ASSERT_EQ(decoded.width, kW);
  ASSERT_EQ(decoded.height, kH);
  ASSERT_EQ(decoded.values.size(), pixels.size());
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < pixels.size(); ++i)
    wrong += std::abs(decoded.values[i] - static_cast<float>(pixels[i]) / 255.0f) > 1e-6f ? 1 : 0;
  EXPECT_EQ(wrong, 0u);
}

// ---- Errors on writing ----------------------------------------------------------------------

TEST_F(ImageIoTest, WritingBelowARegularFileIsAnIoErrorAndLeavesNothing) {
  write_bytes(path("blocker"), {1, 2, 3});
  const Image image = random_image(4, 4, 10);
  EXPECT_THROW(io::write_exr_stereo(path("blocker") / "pair.exr", image, image), IoError);
  EXPECT_THROW(io::write_exr(path("blocker") / "sub" / "mono.exr", image), IoError);
  EXPECT_THROW(io::write_png_preview(path("blocker") / "preview.png", image), IoError);
  EXPECT_THROW(io::write_png_rgb8(path("blocker") / "rgb.png", std::vector<uint8_t>(12), 2, 2), IoError);
  EXPECT_EQ(entries(), std::vector<std::string>{"blocker"});
  EXPECT_EQ(read_bytes(path("blocker")), (std::vector<unsigned char>{1, 2, 3}));
}

TEST_F(ImageIoTest, FailureInsideWriteAtomicallyLeavesNoFileAndNoTemporary) {
  const fs::path file = path("out.bin");
  fs::path seen_tmp;
  EXPECT_THROW(io::write_atomically(file,
                                    [&](const fs::path& tmp) {
                                      seen_tmp = tmp;
                                      std::ofstream(tmp) << "partial content";
                                      throw std::runtime_error("simulated failure half-way");
                                    }),
               IoError);
  EXPECT_FALSE(seen_tmp.empty());
  EXPECT_FALSE(fs::exists(seen_tmp));
  EXPECT_TRUE(entries().empty());

  // An existing file under the final name is left untouched, and typed errors pass through.
  write_bytes(file, {42});
  EXPECT_THROW(io::write_atomically(file,
                                    [&](const fs::path& tmp) {
                                      std::ofstream(tmp) << "new";
                                      throw InputError("simulated bad input");
                                    }),
               InputError);
  EXPECT_EQ(entries(), std::vector<std::string>{"out.bin"});
  EXPECT_EQ(read_bytes(file), std::vector<unsigned char>{42});
}

TEST_F(ImageIoTest, ALineFileIsWholeUnderItsFinalNameOnlyOnceFinished) {
  // Lines go to the partial file as they come; the final name appears with the last.
  {
    io::LineFile lines(path("frames.jsonl.partial"));
    lines.append("{\"frame\": 0}");
    lines.append("{\"frame\": 1}");
    EXPECT_EQ(lines.lines(), 2u);
    EXPECT_FALSE(fs::exists(path("frames.jsonl")));
    std::ifstream partial(path("frames.jsonl.partial"));
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(partial), {}), "{\"frame\": 0}\n{\"frame\": 1}\n");
    // A second writer of the same partial file is refused while the first holds it.
    EXPECT_THROW(io::LineFile second(path("frames.jsonl.partial")), InputError);
    lines.finish(path("frames.jsonl"));
  }
  EXPECT_EQ(entries(), std::vector<std::string>{"frames.jsonl"});

  // A run that ends before its first line leaves no partial file; one with lines keeps them.
  { io::LineFile none(path("empty.jsonl.partial")); }
  EXPECT_FALSE(fs::exists(path("empty.jsonl.partial")));
  {
    io::LineFile cut(path("cut.jsonl.partial"));
    cut.append("{}");
  }
  EXPECT_TRUE(fs::exists(path("cut.jsonl.partial")));

  // A link at the final name is followed: the file it names is replaced, the link kept.
  fs::create_directories(path("real"));
  std::ofstream(path("real") / "frames.jsonl") << "earlier\n";
  fs::create_symlink(path("real") / "frames.jsonl", path("linked.jsonl"));
  {
    io::LineFile lines(path("linked.jsonl.partial"));
    lines.append("new");
    lines.finish(path("linked.jsonl"));
  }
  EXPECT_TRUE(fs::is_symlink(path("linked.jsonl")));
  std::ifstream through(path("linked.jsonl"));
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(through), {}), "new\n");
}

TEST_F(ImageIoTest, ALineThatDoesNotFitLeavesNoPartOfItInTheLineFile) {
  // A disk that filled mid-line left the part that fit: a line no reader can parse after the whole
  // ones. The part is cut off again and the file still takes lines once there is room.
  io::LineFile lines(path("frames.jsonl.partial"));
  lines.append("{\"frame\": 0}");
  const std::string whole = "{\"frame\": 0}\n";
  {
    const test::FileSizeLimit limit(whole.size() + 5);
    ASSERT_TRUE(limit.ok());
    EXPECT_THROW(lines.append("{\"frame\": 1, \"long\": true}"), IoError);
  }
  EXPECT_EQ(lines.lines(), 1u);
  const auto text = [&] {
    std::ifstream partial(path("frames.jsonl.partial"));
    return std::string(std::istreambuf_iterator<char>(partial), {});
  };
  EXPECT_EQ(text(), whole) << "the part of the line that fit stayed";
  lines.append("{\"frame\": 1}");
  EXPECT_EQ(text(), whole + "{\"frame\": 1}\n");
}

TEST_F(ImageIoTest, AKilledWritesTemporaryGoesWhenTheFileIsWrittenAgain) {
  // Left by a killed write of out.json: no process holds its lock any more. The staging name
  // (a write killed between creating its file and locking it) goes once it is a minute old.
  const std::vector<std::string> stale = {".out.json.tmp-4242-7", ".out.json.tmp-1-0", ".out.json.tmp-4242-8.new"};
  // A write of out.json still running (here or on another machine): it holds its file's lock.
  const std::string running = ".out.json.tmp-777-3";
  const std::vector<std::string> kept = {
      running,
      ".other.json.tmp-4242-0",    // another file's, left for its own next write
      ".out.json.tmp-host-4242-0",  // not a temporary name of ours
      ".out.json.tmp-12",
      ".out.json.tmp-4242-7.new",  // a write between creating and naming its locked file, just now
      ".out.json.tmp-4242-7.newer",
      "out.json.tmp-4242-0",
      "notes.txt"};
  for (const std::string& name : stale) std::ofstream(path(name)) << "partial";
  for (const std::string& name : kept) std::ofstream(path(name)) << "partial";
  fs::last_write_time(path(".out.json.tmp-4242-8.new"), fs::file_time_type::clock::now() - std::chrono::minutes(2));
  const int fd = ::open(path(running).c_str(), O_RDONLY | O_CLOEXEC);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);

  io::write_text_atomically(path("out.json"), "whole");
  for (const std::string& name : stale) EXPECT_FALSE(fs::exists(path(name))) << name;
  for (const std::string& name : kept) EXPECT_TRUE(fs::exists(path(name))) << name;
  std::ifstream in(path("out.json"));
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "whole");

  // A write's own temporary file is locked while the write runs: another write of the same file
  // at that moment (another process, or another thread as here) leaves it alone.
  io::write_atomically(path("out.json"), [&](const fs::path& tmp) {
    std::ofstream(tmp) << "second";
    io::write_text_atomically(path("out.json"), "nested");
    EXPECT_TRUE(fs::exists(tmp));
  });
  std::ifstream again(path("out.json"));
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(again), {}), "second");
  ::close(fd);
}

TEST_F(ImageIoTest, ConcurrentWritesOfOneFileNeverRemoveEachOthersTemporaries) {
  // Each write removes the unlocked temporaries of its file before it starts: those of writes
  // running beside it are locked from the moment they exist, so every write completes.
  constexpr int kWriters = 4;
  constexpr int kWrites = 150;
  std::atomic<int> failures{0};
  std::vector<std::thread> writers;
  for (int w = 0; w < kWriters; ++w)
    writers.emplace_back([&, w] {
      for (int i = 0; i < kWrites; ++i) {
        try {
          io::write_text_atomically(path("shared.json"), std::string(4096, static_cast<char>('a' + w)));
        } catch (const std::exception&) {
          ++failures;
        }
      }
    });
  for (std::thread& t : writers) t.join();
  EXPECT_EQ(failures.load(), 0);
  EXPECT_EQ(entries(), std::vector<std::string>{"shared.json"});
  std::ifstream in(path("shared.json"));
  const std::string text{std::istreambuf_iterator<char>(in), {}};
  ASSERT_EQ(text.size(), 4096u);
  EXPECT_EQ(text, std::string(4096, text.front()));
}

TEST_F(ImageIoTest, AWritableFolderIsWritableToThreadsProbingAtOnceAndDespiteAnOldProbe) {
  // Sweep jobs are threads of one process: their probes of one cache folder must not collide.
  // A probe file a killed run left behind (same name scheme, any pid) does not matter either.
  std::ofstream(path(".stereobench-probe-" + std::to_string(::getpid()))) << "left behind";
  constexpr int kProbers = 4;
  constexpr int kProbes = 200;
  std::atomic<int> refusals{0};
  std::vector<std::thread> probers;
  for (int t = 0; t < kProbers; ++t)
    probers.emplace_back([&] {
      for (int i = 0; i < kProbes; ++i)
        if (io::unwritable_folder(dir_)) ++refusals;
    });
  for (std::thread& t : probers) t.join();
  EXPECT_EQ(refusals.load(), 0);
  EXPECT_EQ(entries(), std::vector<std::string>{".stereobench-probe-" + std::to_string(::getpid())})
      << "a probe leaves nothing behind";
}

TEST_F(ImageIoTest, WritingThroughALinkReplacesItsTargetAndKeepsTheLink) {
  write_bytes(path("target.json"), {1});
  fs::create_symlink("target.json", path("link.json"));
  io::write_text_atomically(path("link.json"), "new");
  EXPECT_TRUE(fs::is_symlink(path("link.json")));
  EXPECT_EQ(read_bytes(path("target.json")), (std::vector<unsigned char>{'n', 'e', 'w'}));
  // A dangling link names the file to create.
  fs::create_symlink("later.json", path("dangling.json"));
  io::write_text_atomically(path("dangling.json"), "x");
  EXPECT_TRUE(fs::is_symlink(path("dangling.json")));
  EXPECT_EQ(read_bytes(path("later.json")), std::vector<unsigned char>{'x'});
}

TEST_F(ImageIoTest, ADeviceIsWrittenInPlaceNotReplaced) {
  // /dev/full accepts the open and fails the write: an IoError, and the device stays a device
  // (renaming a file over it used to replace it with a regular file and report success).
  if (!fs::is_character_file("/dev/full")) GTEST_SKIP() << "no /dev/full here";
  fs::create_symlink("/dev/full", path("full"));
  EXPECT_THROW(io::write_text_atomically(path("full"), std::string(100000, 'x')), IoError);
  EXPECT_TRUE(fs::is_symlink(path("full")));
  EXPECT_TRUE(fs::is_character_file("/dev/full"));
  fs::create_symlink("/dev/null", path("null"));
  io::write_text_atomically(path("null"), "discarded");
  EXPECT_TRUE(fs::is_symlink(path("null"))) << "the link to /dev/null was replaced by a file";
  EXPECT_TRUE(fs::is_character_file(path("null")));
}

TEST_F(ImageIoTest, AStreamsStagedFileIsCleanedUpAsAFilesTemporaryIs) {
  // A stream is written through a file staged in the temporary folder ($TMPDIR): a killed write
  // left it there, and the next write to a stream of that name removes it; a running write's
  // locked file stays.
  const fs::path staging = path("tmp");
  fs::create_directories(staging);
  /// Sets $TMPDIR for the test's span and restores it on every way out.
  struct TmpdirFor {
    explicit TmpdirFor(const fs::path& dir) : had(std::getenv("TMPDIR") != nullptr) {
      if (had) saved = std::getenv("TMPDIR");
      ::setenv("TMPDIR", dir.c_str(), 1);
    }
    TmpdirFor(const TmpdirFor&) = delete;
    TmpdirFor& operator=(const TmpdirFor&) = delete;
    ~TmpdirFor() {
      if (had) ::setenv("TMPDIR", saved.c_str(), 1);
      else ::unsetenv("TMPDIR");
    }
    bool had;
    std::string saved;
  };
  std::ofstream(staging / ".null.tmp-4242-7") << "partial";
  std::ofstream(staging / ".null.tmp-777-3") << "partial";
  fs::create_symlink("/dev/null", path("null"));
  {
    const TmpdirFor tmpdir(staging);
    const int fd = ::open((staging / ".null.tmp-777-3").c_str(), O_RDONLY | O_CLOEXEC);
    ASSERT_GE(fd, 0);
    const bool locked = ::flock(fd, LOCK_EX | LOCK_NB) == 0;
    if (locked) io::write_text_atomically(path("null"), "discarded");
    ::close(fd);
    ASSERT_TRUE(locked);
  }
  EXPECT_TRUE(fs::is_character_file(path("null")));
  std::vector<std::string> left;
  for (const fs::directory_entry& e : fs::directory_iterator(staging)) left.push_back(e.path().filename().string());
  EXPECT_EQ(left, std::vector<std::string>{".null.tmp-777-3"});
}

TEST_F(ImageIoTest, AnOpenFileOfTheProcessIsAppendedToNotReplaced) {
  // `--json /dev/stdout >> log`: /dev/stdout leads to /proc/self/fd/1, here a regular file. It used
  // to be resolved to that file and replaced by a rename, losing what the log held.
  write_bytes(path("log"), {'o', 'l', 'd'});
  const int fd = ::open(path("log").c_str(), O_WRONLY | O_APPEND);
  ASSERT_GE(fd, 0);
  struct stat before {}, after {};
  ASSERT_EQ(::stat(path("log").c_str(), &before), 0);
  io::write_text_atomically("/proc/self/fd/" + std::to_string(fd), "new");
  ::close(fd);
  EXPECT_EQ(read_bytes(path("log")), (std::vector<unsigned char>{'o', 'l', 'd', 'n', 'e', 'w'}));
  ASSERT_EQ(::stat(path("log").c_str(), &after), 0);
  EXPECT_EQ(after.st_ino, before.st_ino) << "the file was replaced";
  EXPECT_EQ(entries(), std::vector<std::string>{"log"});
  // The same file through its thread's table, and through its process id's.
  const int again = ::open(path("log").c_str(), O_WRONLY | O_APPEND);
  ASSERT_GE(again, 0);
  const std::string tid = std::to_string(::gettid()), pid = std::to_string(::getpid());
  for (const std::string& name :
       std::vector<std::string>{"/proc/self/task/" + tid + "/fd/", "/proc/thread-self/fd/", "/proc/" + pid + "/fd/"})
    io::write_text_atomically(name + std::to_string(again), "+");
  ::close(again);
  EXPECT_EQ(read_bytes(path("log")), (std::vector<unsigned char>{'o', 'l', 'd', 'n', 'e', 'w', '+', '+', '+'}));
  ASSERT_EQ(::stat(path("log").c_str(), &after), 0);
  EXPECT_EQ(after.st_ino, before.st_ino) << "the file was replaced";
  // A stereo EXR (its writer seeks) reaches a pipe whole.
  int pipe_fds[2];
  ASSERT_EQ(::pipe(pipe_fds), 0);
  const Image image = random_image(4, 4, 21);
  std::vector<unsigned char> received;
  std::thread reader([&] {
    unsigned char buf[4096];
    for (ssize_t n; (n = ::read(pipe_fds[0], buf, sizeof buf)) > 0;) received.insert(received.end(), buf, buf + n);
  });
  io::write_exr("/proc/self/fd/" + std::to_string(pipe_fds[1]), image);
  ::close(pipe_fds[1]);
  reader.join();
  ::close(pipe_fds[0]);
  write_bytes(path("piped.exr"), received);
  EXPECT_TRUE(io::read_exr(path("piped.exr")) == image);
}

TEST_F(ImageIoTest, AStreamWhoseCopyCannotBeMadeNamesTheTemporaryFolder) {
  // A stream is written through a copy in $TMPDIR. When that disk is full the message blamed the
  // stream ("cannot write /dev/stdout ... check free disk space") while its own disk had room.
  const fs::path staging = path("staging");
  fs::create_directories(staging);
  const test::ScopedEnv tmpdir("TMPDIR", staging.string());
  int pipe_fds[2];
  ASSERT_EQ(::pipe(pipe_fds), 0);
  const std::string stream = "/proc/self/fd/" + std::to_string(pipe_fds[1]);
  try {
    const test::FileSizeLimit limit(8);
    ASSERT_TRUE(limit.ok());
    io::write_text_atomically(stream, std::string(100, 'x'));
    ADD_FAILURE() << "the copy was written past the limit";
  } catch (const IoError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("cannot write " + stream + ": it is written through a copy made first in the temporary "
                       "folder " + staging.string()),
              std::string::npos)
        << msg;
    EXPECT_NE(msg.find("set TMPDIR to a folder with room"), std::string::npos) << msg;
    EXPECT_EQ(msg.find(".tmp-"), std::string::npos) << "the hidden copy's name: " << msg;
  }
  ::close(pipe_fds[1]);
  ::close(pipe_fds[0]);
  EXPECT_TRUE(fs::is_empty(staging)) << "the copy stayed";
}

TEST_F(ImageIoTest, OverwritingAnExistingExrReplacesItCompletely) {
  io::write_exr(path("x.exr"), random_image(8, 8, 11));
  const Image second = random_image(3, 2, 12);
  io::write_exr(path("x.exr"), second);
  EXPECT_TRUE(io::read_exr(path("x.exr")) == second);
  EXPECT_EQ(entries(), std::vector<std::string>{"x.exr"});
}

// ---- PNG ------------------------------------------------------------------------------------

/// The sRGB OETF in double precision, clamped and rounded: the reference for the previews.
int reference_srgb8(double linear) {
  const double v = std::isnan(linear) ? 0.0 : std::clamp(linear, 0.0, 1.0);
  const double encoded = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
  return static_cast<int>(std::lround(encoded * 255.0));
}

TEST(ColorTest, SrgbFunctionsFollowThePiecewiseFormula) {
  EXPECT_EQ(linear_to_srgb8(0.0f), 0);
  EXPECT_EQ(linear_to_srgb8(0.0031308f), 10);  // 12.92 * 0.0031308 * 255 = 10.31
  EXPECT_EQ(linear_to_srgb8(0.5f), 188);       // 0.735357 * 255 = 187.52
  EXPECT_EQ(linear_to_srgb8(1.0f), 255);
  EXPECT_EQ(linear_to_srgb8(7.0f), 255);
  EXPECT_EQ(linear_to_srgb8(-0.25f), 0);
  EXPECT_EQ(linear_to_srgb8(std::numeric_limits<float>::quiet_NaN()), 0);
  EXPECT_EQ(linear_to_srgb8(std::numeric_limits<float>::infinity()), 255);
  EXPECT_NEAR(linear_to_srgb(0.0031308f), 0.04045f, 1e-6f);
  EXPECT_NEAR(srgb_to_linear(0.04045f), 0.0031308f, 1e-7f);
  EXPECT_NEAR(srgb_to_linear(0.5f), 0.21404114f, 1e-7f);
  for (int code = 0; code <= 255; ++code) {
    EXPECT_EQ(linear_to_srgb8(srgb8_to_linear(static_cast<uint8_t>(code))), code);
    EXPECT_NEAR(linear_to_srgb(srgb_to_linear(code / 255.0f)), code / 255.0f, 1e-6f);
  }
}

TEST_F(ImageIoTest, PngPreviewEqualsTheSrgbFormula) {
  const std::vector<float> inputs = {0.0f,  0.0031308f, 0.0031309f, 0.5f,  1.0f,  1.5f,   -0.2f,
                                     1e-4f, 0.2f,       0.99f,      0.18f, 1e30f, -1e30f, 0.0404f};
  Image image(static_cast<int>(inputs.size()), 2);
  Plane& rgb = image.add_plane(planes::rgb);
  Plane& depth = image.add_plane(planes::depth);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < image.width(); ++x) {
      for (int c = 0; c < 3; ++c) rgb.at_f32(x, y, c) = inputs[static_cast<std::size_t>((x + c + y) % image.width())];
      depth.at_f32(x, y) = inputs[static_cast<std::size_t>(x)];
    }
  io::write_png_preview(path("rgb.png"), image);
  io::write_png_preview(path("depth.png"), image, planes::depth);

  const io::DecodedImage png = io::read_image(path("rgb.png"));
  ASSERT_EQ(png.width, image.width());
  ASSERT_EQ(png.height, 2);
  ASSERT_EQ(png.channels, 3);
  EXPECT_TRUE(png.srgb);
  EXPECT_EQ(png.format, "png");
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < image.width(); ++x)
      for (int c = 0; c < 3; ++c) {
        const float value = png.values[(static_cast<std::size_t>(y) * static_cast<std::size_t>(png.width) +
                                        static_cast<std::size_t>(x)) *
                                           3 +
                                       static_cast<std::size_t>(c)];
        EXPECT_EQ(std::lround(value * 255.0f), reference_srgb8(rgb.at_f32(x, y, c))) << "input " << rgb.at_f32(x, y, c);
      }

  const io::DecodedImage gray = io::read_image(path("depth.png"));
  ASSERT_EQ(gray.channels, 1);
  for (int x = 0; x < image.width(); ++x)
    EXPECT_EQ(std::lround(gray.values[static_cast<std::size_t>(x)] * 255.0f),
              reference_srgb8(inputs[static_cast<std::size_t>(x)]));
}

TEST_F(ImageIoTest, PngPreviewRejectsUnsuitablePlanes) {
  Image image(4, 4);
  image.add_plane(planes::primid);
  image.add_plane("motion", 2, PlaneType::f32);
  expect_error<InputError>([&] { io::write_png_preview(path("p.png"), image); }, "no plane 'rgb'");
  expect_error<InputError>([&] { io::write_png_preview(path("p.png"), image, planes::primid); }, "primid");
  expect_error<InputError>([&] { io::write_png_preview(path("p.png"), image, "motion"); }, "1 or 3 float");
  expect_error<InputError>([&] { io::write_png_rgb8(path("p.png"), std::vector<uint8_t>(11), 2, 2); }, "needs");
  EXPECT_TRUE(entries().empty());
}

TEST_F(ImageIoTest, PngRgb8IsWrittenVerbatim) {
  const std::vector<uint8_t> rgb = {0, 1, 2, 253, 254, 255, 10, 20, 30, 40, 50, 60};
  io::write_png_rgb8(path("rgb8.png"), rgb, 2, 2);
  const io::DecodedImage png = io::read_image(path("rgb8.png"));
  ASSERT_EQ(png.values.size(), rgb.size());
  for (std::size_t i = 0; i < rgb.size(); ++i) EXPECT_EQ(std::lround(png.values[i] * 255.0f), rgb[i]);
}

TEST_F(ImageIoTest, EncodePngRoundTripsAndIsDeterministic) {
  std::mt19937 rng(13);
  for (int channels = 1; channels <= 4; ++channels) {
    const int width = 19 + channels;
    const int height = 7;
    std::vector<uint8_t> pixels(static_cast<std::size_t>(width * height * channels));
    for (auto& p : pixels) p = static_cast<uint8_t>(rng());
    const std::vector<unsigned char> a = io::encode_png(pixels.data(), width, height, channels);
    const std::vector<unsigned char> b = io::encode_png(pixels.data(), width, height, channels);
    ASSERT_GT(a.size(), 8u);
    EXPECT_EQ(a, b) << "two encodings of the same pixels differ";
    EXPECT_EQ(std::vector<unsigned char>(a.begin(), a.begin() + 4), (std::vector<unsigned char>{0x89, 'P', 'N', 'G'}));

    // The name carries no extension: the format is found from the bytes. Alpha (2 and 4
    // channels) must come back straight, not premultiplied.
    const io::DecodedImage decoded = io::decode_image(a, "texture without extension");
    EXPECT_EQ(decoded.width, width);
    EXPECT_EQ(decoded.height, height);
    EXPECT_EQ(decoded.channels, channels);
    EXPECT_TRUE(decoded.srgb);
    ASSERT_EQ(decoded.values.size(), pixels.size());
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      ASSERT_EQ(std::lround(decoded.values[i] * 255.0f), pixels[i]) << "sample " << i;
      ASSERT_NEAR(decoded.values[i], static_cast<float>(pixels[i]) / 255.0f, 1e-7f) << "sample " << i;
    }
  }
  EXPECT_THROW((void)io::encode_png(nullptr, 2, 2, 3), InputError);
  const uint8_t one = 0;
  EXPECT_THROW((void)io::encode_png(&one, 0, 1, 1), InputError);
  EXPECT_THROW((void)io::encode_png(&one, 1, 1, 5), InputError);
}

TEST_F(ImageIoTest, DecodeImageReadsExrFromMemoryAsLinear) {
  Image image(3, 2);
  image.add_plane(planes::rgb).fill(0.75f);
  io::write_exr(path("tex.exr"), image);
  const std::vector<unsigned char> bytes = read_bytes(path("tex.exr"));
  const io::DecodedImage decoded = io::decode_image(bytes, "embedded.exr");
  EXPECT_EQ(decoded.format, "openexr");
  EXPECT_FALSE(decoded.srgb);
  EXPECT_EQ(decoded.channels, 3);
  for (const float v : decoded.values) EXPECT_EQ(v, 0.75f);
}

TEST_F(ImageIoTest, DecodeImageReadsJpegFromMemoryAsSrgb) {
  if (!has_oiiotool()) GTEST_SKIP() << "oiiotool (Debian package openimageio-tools) is not installed";
  run("oiiotool --pattern constant:color=0.2,0.4,0.6 16x8 3 -d uint8 -o " + path("tex.jpg").string());
  const io::DecodedImage decoded = io::decode_image(read_bytes(path("tex.jpg")), "scene.gltf image 0");
  EXPECT_EQ(decoded.format, "jpeg");
  EXPECT_TRUE(decoded.srgb);
  EXPECT_EQ(decoded.width, 16);
  EXPECT_EQ(decoded.height, 8);
  ASSERT_EQ(decoded.channels, 3);
  EXPECT_NEAR(decoded.values[0], 0.2f, 2.0f / 255.0f);  // lossy, but a flat colour survives closely
  EXPECT_NEAR(decoded.values[2], 0.6f, 2.0f / 255.0f);
}

TEST(ImageIoVersionTest, OiioVersionIsReported) {
  const std::string version = io::oiio_version();
  EXPECT_EQ(std::count(version.begin(), version.end(), '.'), 2) << version;
  EXPECT_NE(version, "0.0.0");
}

}  // namespace
}  // namespace sb
