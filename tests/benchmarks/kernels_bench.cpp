// Google Benchmark micro-benchmarks of the hot kernels: rasterizing a G-buffer, shading it, and
// tracing a whole eye, on a built-in scene at 960x540; the adaptive grid warp of the repro-*
// pipelines and repro-rt's hole fill at 1920x1080 on temple and bistro. Run `build/tests/sb_kernels_bench`.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <memory>
#include <string>

#include "renderer/error.hpp"
#include "renderer/memory.hpp"
#include "renderer/raster/rasterizer.hpp"
#include "renderer/render_scene.hpp"
#include "renderer/stages/eye_image.hpp"
#include "renderer/stages/grid_warp.hpp"
#include "renderer/stages/lighting.hpp"
#include "renderer/stages/raster_eye.hpp"
#include "renderer/stages/trace.hpp"
#include "support/render_support.hpp"
#include "validation/metrics.hpp"

namespace sb {
namespace {

/// The scene, prepared once for every benchmark.
struct Fixture {
  Scene scene = test::load_builtin("bistro");
  RenderScene prepared{scene};
  StereoRig rig = test::rig_at(scene, 960, 540);
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

void BM_Rasterize(benchmark::State& state) {
  Fixture& f = fixture();
  const Executor executor(static_cast<int>(state.range(0)));
  const EyeCamera cam = f.rig.eye(Eye::left);
  for (auto _ : state) benchmark::DoNotOptimize(rasterize(f.prepared.geometry(), cam, executor));
  state.counters["triangles"] = static_cast<double>(f.scene.triangle_count());
}

void BM_ShadeGBuffer(benchmark::State& state) {
  Fixture& f = fixture();
  const Executor executor(static_cast<int>(state.range(0)));
  const EyeCamera cam = f.rig.eye(Eye::left);
  const GBuffer g = rasterize(f.prepared.geometry(), cam, executor);
  Image image = make_eye_image(cam.width, cam.height);
  for (auto _ : state) {
    TraceCounts counts;
    shade_gbuffer(f.prepared, cam, g, executor, image, counts);
    state.counters["shadow_rays"] = static_cast<double>(counts.shadow_rays);
  }
}

void BM_TraceEye(benchmark::State& state) {
  Fixture& f = fixture();
  const Executor executor(static_cast<int>(state.range(0)));
  const EyeCamera cam = f.rig.eye(Eye::left);
  Image image = make_eye_image(cam.width, cam.height);
  for (auto _ : state) {
    TraceCounts counts;
    trace_eye(f.prepared, cam, executor, image, counts);
    // One iteration's rays, which every iteration casts alike: a per-iteration rate (kIsRate alone
    // divides one iteration's count by all iterations' time).
    state.counters["rays/s"] = benchmark::Counter(static_cast<double>(counts.primary_rays + counts.shadow_rays),
                                                  benchmark::Counter::kIsIterationInvariantRate);
  }
}

/// A scene's left eye at 1920x1080, rasterized once, and its warping grid: the input of the warp
/// into the right eye (repro-rt's grid_warp stage without the source-frustum search).
struct WarpFixture {
  explicit WarpFixture(const std::string& name) : scene(test::load_builtin(name)) {
    const Executor executor(0);
    StereoResult r;
    left = raster_eye(prepared, rig, Eye::left, RasterOptions{}, executor, r);
    settings.interaxial = rig.params().interaxial;
    settings.focal_px = rig.eye(Eye::left).f_px;
    settings.opening_px = WarpOptions{}.discontinuity_px;
    grid = build_warp_grid(left.plane(planes::depth).f32(), left.width(), left.height(), settings, executor);
  }
  Scene scene;
  RenderScene prepared{scene};
  StereoRig rig = test::rig_at(scene, 1920, 1080);
  Image left;
  GridSettings settings;  ///< repro-rt's defaults
  WarpGrid grid;
};

/// temple (half the cells at native resolution) or bistro (five in six).
WarpFixture& warp_fixture(const std::string& name) {
  static std::map<std::string, std::unique_ptr<WarpFixture>> fixtures;
  std::unique_ptr<WarpFixture>& f = fixtures[name];
  if (!f) f = std::make_unique<WarpFixture>(name);
  return *f;
}

/// The grid metric: per-cell depth range, parallax and subdivision.
void BM_GridMetric(benchmark::State& state, const std::string& scene) {
  WarpFixture& f = warp_fixture(scene);
  const Executor executor(static_cast<int>(state.range(0)));
  for (auto _ : state)
    benchmark::DoNotOptimize(
        build_warp_grid(f.left.plane(planes::depth).f32(), f.left.width(), f.left.height(), f.settings, executor));
}

/// The warp with disocclusion detection, into a right eye made as repro-rt makes it.
void BM_GridWarp(benchmark::State& state, const std::string& scene) {
  WarpFixture& f = warp_fixture(scene);
  const Executor executor(static_cast<int>(state.range(0)));
  const EyeCamera left = f.rig.eye(Eye::left), right = f.rig.eye(Eye::right);
  WarpStats stats;
  for (auto _ : state) {
    Image target = make_eye_image(right.width, right.height, PlaneInit::unset);
    benchmark::DoNotOptimize(
        grid_warp(f.grid, f.left, left, right, f.rig.params().interaxial, WarpOptions{}, executor, target, stats));
  }
  state.counters["triangles"] = static_cast<double>(stats.triangles);
  state.counters["subdivided"] = static_cast<double>(f.grid.subdivided_count());
}

/// repro-rt's hole fill: the pixels the warp left uncovered or discarded (without the
/// source-frustum search), traced from the right eye and shaded into the warped image.
void BM_HoleFill(benchmark::State& state, const std::string& scene) {
  WarpFixture& f = warp_fixture(scene);
  const Executor executor(static_cast<int>(state.range(0)));
  const EyeCamera left = f.rig.eye(Eye::left), right = f.rig.eye(Eye::right);
  Image target = make_eye_image(right.width, right.height, PlaneInit::unset);
  WarpStats stats;
  const std::vector<uint8_t> states =
      grid_warp(f.grid, f.left, left, right, f.rig.params().interaxial, WarpOptions{}, executor, target, stats);
  TraceCounts counts;
  for (auto _ : state) {
    counts = TraceCounts{};
    trace_unless(f.prepared, right, executor, states, static_cast<uint8_t>(WarpPixel::covered), target, counts,
                 Source::reshaded_traced);
  }
  state.counters["holes"] = static_cast<double>(counts.pixels_traced);
  state.counters["shadow_rays"] = static_cast<double>(counts.shadow_rays);
}

/// Two 8-bit images of a size: uniform noise and the same noise with every code shifted.
std::pair<validation::Srgb8Image, validation::Srgb8Image> noise_pair(int width, int height) {
  validation::Srgb8Image a{width, height, std::vector<uint8_t>(size_t(width) * size_t(height) * 3)};
  uint32_t state = 12345u;
  for (uint8_t& v : a.rgb) {
    state = state * 1664525u + 1013904223u;
    v = static_cast<uint8_t>(state >> 24);
  }
  validation::Srgb8Image b = a;
  for (uint8_t& v : b.rgb) v = static_cast<uint8_t>(v / 2 + 40);
  return {std::move(a), std::move(b)};
}

/// SSIM map of a 3840 x 2160 pair (DESIGN §6.2), the largest comparison a sweep makes.
void BM_Ssim4k(benchmark::State& state) {
  const auto [a, b] = noise_pair(3840, 2160);
  for (auto _ : state) benchmark::DoNotOptimize(validation::ssim_map(a, b).mean);
}

/// Every metric of a 3840 x 2160 pair (MSE, PSNR, SSIM, error pixels, max error).
void BM_CompareImages4k(benchmark::State& state) {
  const auto [a, b] = noise_pair(3840, 2160);
  for (auto _ : state) benchmark::DoNotOptimize(validation::compare_images(a, b).ssim);
}

BENCHMARK(BM_Ssim4k)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_CompareImages4k)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Rasterize)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ShadeGBuffer)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_TraceEye)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_GridMetric, temple, std::string("temple"))->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_GridWarp, temple, std::string("temple"))->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_GridWarp, bistro, std::string("bistro"))->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_HoleFill, temple, std::string("temple"))->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_HoleFill, bistro, std::string("bistro"))->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace sb

int main(int argc, char** argv) {
  // As the stereobench program does: repetitions reuse freed frame buffers instead of faulting in
  // fresh pages (which costs the grid warp at 1920x1080 about as much as the warp itself).
  sb::keep_freed_memory();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  // The scenes are generated into the build tree's cache on first use: a cache that cannot be
  // written (a read-only tree) or a scene that cannot be loaded is said, not an abort.
  try {
    benchmark::RunSpecifiedBenchmarks();
  } catch (const sb::Error& e) {
    std::fprintf(stderr, "sb_kernels_bench: %s\n", e.what());
    return 4;
  }
  benchmark::Shutdown();
  return 0;
}
