// The truth cache and content hashes: a cached ground truth is rendered once per content, its key
// follows everything that changes the image, a damaged entry is rendered again, and the built-in
// provider is never cached.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <functional>
#include <limits>
#include <optional>
#include <thread>

#include "renderer/error.hpp"
#include "renderer/stages/eye_image.hpp"
#include "support/render_support.hpp"
#include "support/scratch_dir.hpp"
#include "validation/content_hash.hpp"
#include "validation/truth.hpp"
#include "validation/truth_cache.hpp"

namespace sb::validation {
namespace {

/// A provider that paints a constant image and counts its renders.
class CountingProvider final : public TruthProvider {
 public:
  explicit CountingProvider(std::string name = "counting", bool available = true)
      : name_(std::move(name)), available_(available) {}
  std::string name() const override { return name_; }
  std::string description() const override { return "test provider"; }
  std::optional<std::string> unavailable_reason() const override {
    return available_ ? std::nullopt : std::optional<std::string>("not installed here");
  }
  std::string tool_version() const override { return "counting 1.0"; }
  std::string revision() const override { return revision_; }
  void check_scene(const Scene& /*scene*/, const std::filesystem::path& /*scene_file*/) const override {
    if (refusal) throw InputError(*refusal);
  }
  TruthRender render(const TruthRequest& request) const override {
    check_scene(request.scene.scene(), request.scene_file);
    ++renders;
    if (during_render) during_render();
    TruthRender r;
    r.provider = name_;
    r.tool_version = tool_version();
    r.right = make_eye_image(request.rig.params().width, request.rig.params().height);
    for (int y = 0; y < r.right.height(); ++y)
      for (int x = 0; x < r.right.width(); ++x) r.right.set_rgb(x, y, {0.25f, 0.5f, float(x) / 64.0f});
    if (bad_sample) r.right.set_rgb(1, 1, {*bad_sample, 0.5f, 0.5f});
    r.settings = {{"constant", true}};
    r.command = "counting --render";
    r.seconds = 0.5;
    return r;
  }
  mutable int renders = 0;
  std::string revision_ = "r1";
  std::optional<float> bad_sample;  ///< a value the render puts in one sample (NaN, inf, negative)
  std::optional<std::string> refusal;  ///< check_scene's InputError message, when set
  std::function<void()> during_render;  ///< called as the render runs, when set

 private:
  std::string name_;
  bool available_;
};

TEST(Sha256, MatchesTheStandardTestVector) {
  Sha256 sha;
  const std::string abc = "abc";
  sha.add(std::as_bytes(std::span<const char>(abc.data(), abc.size())));
  EXPECT_EQ(sha.hex(), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST(Sha256, FileHashMatchesByteHashAndMissingFileIsAnIoError) {
  test::ScratchDir dir;
  std::ofstream(dir / "f.txt", std::ios::binary) << "abc";
  EXPECT_EQ(hash_file(dir / "f.txt"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_THROW((void)hash_file(dir / "missing.txt"), IoError);
}

TEST(SceneHash, FollowsContentNotNames) {
  Scene a = test::load_builtin("box-wall");
  Scene b = a;
  b.name = "renamed";
  b.path = "/elsewhere.gltf";
  EXPECT_EQ(hash_scene(a), hash_scene(b));
  b.lights[0].intensity *= 1.0001f;
  EXPECT_NE(hash_scene(a), hash_scene(b));
  Scene c = a;
  c.meshes[0].positions[0].x += 1e-6f;
  EXPECT_NE(hash_scene(a), hash_scene(c));
  Scene d = a;
  d.background.y += 0.01f;
  EXPECT_NE(hash_scene(a), hash_scene(d));
}

/// A scratch folder, box-wall prepared for rendering, and a cache in the folder.
class TruthCacheTest : public ::testing::Test {
 protected:
  test::ScratchDir dir;
  const Scene scene = test::load_builtin("box-wall");
  const RenderScene prepared{scene};
  const TruthCache cache{dir / "cache"};

  /// A request for the right eye at width x height, working in dir/work.
  [[nodiscard]] TruthRequest request_at(int width, int height) const {
    return {prepared, scene.path, test::rig_at(scene, width, height), dir / "work", 1};
  }
};

TEST(TruthWarnings, WhatTheSettingsSayDiffersIsSaid) {
  // Kept in the settings (and so also for a truth from the cache), and printed by validate: they
  // explain a disagreement that was otherwise only in the JSON.
  validation::TruthRender povray;
  povray.provider = "povray";
  povray.settings = {{"export_warnings", {"mesh 'quad': texture 'image0' clamps to its edge but is read outside"}}};
  EXPECT_EQ(validation::truth_warnings(povray),
            std::vector<std::string>{"povray truth: mesh 'quad': texture 'image0' clamps to its edge but is read outside"});
  validation::TruthRender blender;
  blender.provider = "blender";
  blender.settings = {{"textures_wrapped_on_both_axes", {2}}};
  ASSERT_EQ(validation::truth_warnings(blender).size(), 1u);
  EXPECT_NE(validation::truth_warnings(blender)[0].find("texture(s) [2] repeat along one axis"), std::string::npos);
  blender.settings = {{"textures_wrapped_on_both_axes", nlohmann::json::array()}, {"export_warnings", 3}};
  EXPECT_TRUE(validation::truth_warnings(blender).empty());
}

TEST(TruthWarnings, AnOverExposedTruthIsSaid) {
  // Where most pixels clip at 255, a comparison cannot see a pipeline's error there: said, with
  // the usual cause (photometric light units) and what to do.
  validation::TruthRender full;
  full.provider = "full";
  full.right = Image(10, 10);
  Plane& rgb = full.right.add_plane(planes::rgb);
  float* v = rgb.data_f32();
  for (size_t i = 0; i < 100; ++i)
    for (size_t c = 0; c < 3; ++c) v[i * 3 + c] = i < 30 && c == 1 ? 1.0f : 0.5f;  // 30 % clip in green
  EXPECT_DOUBLE_EQ(validation::clipped_fraction(full.right), 0.30);
  const std::vector<std::string> warnings = validation::truth_warnings(full);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("full truth: 30.0 % of the right eye's pixels are over-exposed"), std::string::npos)
      << warnings[0];
  EXPECT_NE(warnings[0].find("Lighting Mode 'Unitless'"), std::string::npos) << warnings[0];
  // A quarter or less: nothing said.
  for (size_t i = 25; i < 30; ++i) v[i * 3 + 1] = 0.99f;
  EXPECT_DOUBLE_EQ(validation::clipped_fraction(full.right), 0.25);
  EXPECT_TRUE(validation::truth_warnings(full).empty());
}

TEST_F(TruthCacheTest, RendersOncePerContentAndKeysFollowTheRig) {
  CountingProvider provider;
  const TruthRequest request = request_at(64, 36);

  const ResolvedTruth first = resolve_truth(provider, request, &cache);
  EXPECT_FALSE(first.cached);
  EXPECT_EQ(provider.renders, 1);
  const ResolvedTruth second = resolve_truth(provider, request, &cache);
  EXPECT_TRUE(second.cached);
  EXPECT_EQ(provider.renders, 1);
  EXPECT_EQ(second.key, first.key);
  EXPECT_EQ(hash_image(second.render.right), hash_image(rgb_plane_only(first.render.right)));
  EXPECT_EQ(second.render.settings, first.render.settings);
  EXPECT_EQ(second.render.command, "counting --render");
  EXPECT_EQ(second.render.tool_version, "counting 1.0");

  RigOverrides wider;
  wider.width = 64;
  wider.height = 36;
  wider.interaxial = 0.07;
  const TruthRequest other_rig{prepared, scene.path, resolve_rig(scene, wider), dir / "work", 1};
  EXPECT_NE(truth_key(provider, other_rig), first.key);
  provider.revision_ = "r2";
  EXPECT_NE(truth_key(provider, request), first.key) << "a new provider revision must not reuse old renders";
}

TEST_F(TruthCacheTest, DamagedEntryIsRenderedAgain) {
  CountingProvider provider;
  const TruthRequest request = request_at(64, 36);
  const ResolvedTruth first = resolve_truth(provider, request, &cache);
  {
    std::fstream f(cache.image_path("counting", first.key), std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(-16, std::ios::end);
    f.write("garbage-garbage!", 16);
  }
  const ResolvedTruth again = resolve_truth(provider, request, &cache);
  EXPECT_FALSE(again.cached);
  EXPECT_EQ(provider.renders, 2);
  EXPECT_TRUE(resolve_truth(provider, request, &cache).cached);
}

TEST_F(TruthCacheTest, ASceneTheProviderNowRefusesIsNotServedFromTheCache) {
  // An entry an older provider rendered before it learnt to refuse the scene (Blender with nodes
  // outside the loaded glTF scene) is not passed off as the truth: the check comes before the lookup.
  CountingProvider provider;
  const TruthRequest request = request_at(64, 36);
  const ResolvedTruth first = resolve_truth(provider, request, &cache);
  ASSERT_TRUE(std::filesystem::is_regular_file(cache.image_path("counting", first.key)));
  provider.refusal = "cannot render this scene";
  try {
    (void)resolve_truth(provider, request, &cache);
    ADD_FAILURE() << "a cached render of a refused scene was served";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "cannot render this scene");
  }
  EXPECT_EQ(provider.renders, 1);
}

TEST_F(TruthCacheTest, AnEntryMadeForAnotherRequestIsNoHit) {
  // An entry copied by hand under another key, or from another provider's folder, is rendered
  // again instead of being passed off as this request's truth.
  CountingProvider provider;
  const TruthRequest small = request_at(64, 36);
  const TruthRequest large = request_at(96, 54);
  const std::string small_key = resolve_truth(provider, small, &cache).key;
  const std::string large_key = truth_key(provider, large);
  const auto json_of = [](std::filesystem::path exr) { return exr.replace_extension(".json"); };
  std::filesystem::copy_file(cache.image_path("counting", small_key), cache.image_path("counting", large_key));
  std::filesystem::copy_file(json_of(cache.image_path("counting", small_key)),
                             json_of(cache.image_path("counting", large_key)));
  const ResolvedTruth large_truth = resolve_truth(provider, large, &cache);
  EXPECT_FALSE(large_truth.cached);
  EXPECT_EQ(large_truth.render.right.width(), 96);
  EXPECT_EQ(provider.renders, 2);

  CountingProvider other("other");
  const std::string other_key = truth_key(other, small);
  std::filesystem::create_directories(dir / "cache" / "other");
  std::filesystem::copy_file(cache.image_path("counting", small_key), cache.image_path("other", other_key));
  std::filesystem::copy_file(json_of(cache.image_path("counting", small_key)),
                             json_of(cache.image_path("other", other_key)));
  EXPECT_FALSE(resolve_truth(other, small, &cache).cached);
  EXPECT_EQ(other.renders, 1);
}

/// A provider that leaves a file in the work folder, waits, and reads it back, as an external tool
/// writes its passes and then reads them: another render in the same folder meanwhile would swap
/// them.
class WorkFileProvider final : public TruthProvider {
 public:
  std::string name() const override { return "workfile"; }
  std::string description() const override { return "test provider"; }
  std::optional<std::string> unavailable_reason() const override { return std::nullopt; }
  std::string tool_version() const override { return "workfile 1.0"; }
  std::string revision() const override { return "r1"; }
  TruthRender render(const TruthRequest& request) const override {
    const std::string mine = std::to_string(request.rig.params().width);
    { std::ofstream(request.work_dir / "pass.txt") << mine; }
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    std::string read;
    std::ifstream(request.work_dir / "pass.txt") >> read;
    if (read != mine) swapped = true;
    TruthRender r;
    r.provider = name();
    r.tool_version = tool_version();
    r.right = make_eye_image(request.rig.params().width, request.rig.params().height);
    return r;
  }
  mutable std::atomic<bool> swapped{false};
};

TEST_F(TruthCacheTest, RunsSharingAWorkFolderTakeTurns) {
  WorkFileProvider provider;
  const TruthRequest a = request_at(64, 36);
  const TruthRequest b = request_at(96, 54);
  std::thread other([&] { (void)resolve_truth(provider, b, &cache); });
  const ResolvedTruth mine = resolve_truth(provider, a, &cache);
  other.join();
  EXPECT_FALSE(provider.swapped) << "two renders used the work folder at once";
  EXPECT_EQ(mine.render.right.width(), 64);
}

TEST_F(TruthCacheTest, AnImageWithNoRadianceInItIsAToolErrorAndIsNotStored) {
  const TruthRequest request = request_at(64, 36);
  for (const float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(), -0.5f}) {
    CountingProvider provider;
    provider.bad_sample = bad;
    try {
      (void)resolve_truth(provider, request, &cache);
      ADD_FAILURE() << bad << " passed";
    } catch (const ToolError& e) {
      EXPECT_NE(std::string(e.what()).find("it was not stored in the cache"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(std::filesystem::exists(cache.image_path("counting", truth_key(provider, request)))) << bad;
  }
  // The tool mended: rendered and stored.
  CountingProvider provider;
  EXPECT_FALSE(resolve_truth(provider, request, &cache).cached);
  EXPECT_TRUE(resolve_truth(provider, request, &cache).cached);
}

TEST_F(TruthCacheTest, AFolderInPlaceOfTheEntryFailsBeforeTheProviderRenders) {
  CountingProvider provider;
  const TruthRequest request = request_at(64, 36);
  std::filesystem::create_directories(cache.image_path("counting", truth_key(provider, request)));
  try {
    (void)resolve_truth(provider, request, &cache);
    ADD_FAILURE() << "a folder in place of the entry must fail";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("is a folder; remove it"), std::string::npos) << e.what();
  }
  EXPECT_EQ(provider.renders, 0);
}

TEST_F(TruthCacheTest, ARenderTheCacheCannotKeepIsUsedAllTheSame) {
  // The cache's disk filled while the external tool rendered (here: a folder took the record's
  // name). The render was lost and the validation ended with exit 4; the cache is only a saving.
  CountingProvider provider;
  const TruthRequest request = request_at(64, 36);
  std::filesystem::path meta = cache.image_path("counting", truth_key(provider, request));
  meta.replace_extension(".json");
  provider.during_render = [&] { std::filesystem::create_directories(meta / "inside"); };
  testing::internal::CaptureStderr();
  const ResolvedTruth r = resolve_truth(provider, request, &cache);
  const std::string said = testing::internal::GetCapturedStderr();
  EXPECT_FALSE(r.cached);
  EXPECT_EQ(r.render.right.width(), 64);
  EXPECT_NE(said.find("warning: the counting render is not kept in the ground-truth cache"), std::string::npos)
      << said;
  EXPECT_NE(said.find(meta.string()), std::string::npos) << said;
  EXPECT_FALSE(std::filesystem::exists(cache.image_path("counting", r.key))) << "an image without its record stayed";
}

TEST_F(TruthCacheTest, AnUnusableCacheFailsBeforeTheProviderRenders) {
  // A file where the cache folder should be: the external render would be lost when storing it.
  { std::ofstream(dir / "not-a-folder") << "x"; }
  const TruthCache unusable(dir / "not-a-folder");
  CountingProvider provider;
  const TruthRequest request = request_at(64, 36);
  try {
    (void)resolve_truth(provider, request, &unusable);
    ADD_FAILURE() << "an unusable cache must fail";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("the ground-truth cache " + (dir / "not-a-folder").string() +
                                         " cannot hold counting renders"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(provider.renders, 0);
}

TEST_F(TruthCacheTest, FullProviderIsNeverCachedAndUnavailableProviderIsAToolError) {
  const TruthRequest request = request_at(64, 36);
  const auto full = make_truth_provider("full");
  EXPECT_FALSE(resolve_truth(*full, request, &cache).cached);
  EXPECT_FALSE(resolve_truth(*full, request, &cache).cached);
  EXPECT_FALSE(std::filesystem::exists(dir / "cache" / "full"));

  const CountingProvider missing("missing", false);
  try {
    (void)resolve_truth(missing, request, &cache);
    FAIL() << "an unavailable provider must not pass";
  } catch (const ToolError& e) {
    EXPECT_NE(std::string(e.what()).find("unavailable"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)make_truth_provider("mitsuba"), InputError);
}

TEST(FullProvider, EqualsPlainRtRightEye) {
  const Scene scene = test::load_builtin("spheres");
  const RenderScene prepared(scene);
  const StereoRig rig = test::rig_at(scene, 96, 54);
  const TruthRequest request{prepared, scene.path, rig, {}, 2};
  const TruthRender truth = make_truth_provider("full")->render(request);
  const StereoResult plain = test::render_with("plain-rt", prepared, rig, 1);
  EXPECT_EQ(rgb_plane_only(truth.right), rgb_plane_only(plain.right));
}

}  // namespace
}  // namespace sb::validation
