// Google Benchmark micro-benchmarks of the hot kernels: rasterizing a G-buffer, shading it, and
// tracing a whole eye, on a built-in scene at 960x540. Run `build/tests/sb_kernels_bench`.
#include <benchmark/benchmark.h>

#include <memory>

#include "renderer/raster/rasterizer.hpp"
#include "renderer/render_scene.hpp"
#include "renderer/stages/eye_image.hpp"
#include "renderer/stages/lighting.hpp"
#include "renderer/stages/trace.hpp"
#include "support/render_support.hpp"

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
    state.counters["rays/s"] = benchmark::Counter(static_cast<double>(counts.primary_rays + counts.shadow_rays),
                                                  benchmark::Counter::kIsRate);
  }
}

BENCHMARK(BM_Rasterize)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ShadeGBuffer)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_TraceEye)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace sb

BENCHMARK_MAIN();
