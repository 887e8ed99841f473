// The 3D camera's figures: MuJoCo offscreen render time per frame (headless EGL; Mesa's
// llvmpipe on a machine without a GPU) at 480p and 720p, without anti-aliasing (the
// default) against 4-sample MSAA, with the glossy floor's reflection pass, and the whole
// ci3d set's wall time is printed by `liftoff synth --set ci3d`.
//
// Run: build/bench/synth3d_bench   (time per iteration = per frame, wall clock: llvmpipe
// renders on its own threads)
#include <memory>

#include <benchmark/benchmark.h>

#include "liftoff/synth/egl_context.h"
#include "liftoff/synth/scene3d.h"

namespace {

using namespace liftoff;
using namespace liftoff::synth;

synth::EglContext* Context() {
  static auto context = EglContext::Create();
  return context.ok() ? context->get() : nullptr;
}

void BM_Render3d(benchmark::State& state) {
  if (Context() == nullptr) {
    state.SkipWithError("no headless OpenGL (EGL) on this machine");
    return;
  }
  Scene3dOptions options;
  options.view = CameraView::kOblique;
  options.width_px = state.range(0) == 720 ? 1280 : 640;
  options.height_px = static_cast<int>(state.range(0));
  options.msaa_samples = static_cast<int>(state.range(1));
  options.floor = state.range(2) != 0 ? FloorKind::kGlossy : FloorKind::kTextured;
  auto renderer = SceneRenderer3d::Create(options, Foot::kA);
  if (!renderer.ok()) {
    state.SkipWithError(renderer.status().ToString().c_str());
    return;
  }
  (*renderer)->Render({0, 0}, false);  // compiles the shaders
  double lift_m = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize((*renderer)->Render({lift_m, 0.4}, true).data);
    lift_m = lift_m > 0.01 ? 0 : lift_m + 0.0005;
  }
  state.SetLabel(std::to_string(options.width_px) + "x" + std::to_string(options.height_px) +
                 (options.msaa_samples > 0 ? " msaa" + std::to_string(options.msaa_samples) : " no msaa") +
                 (options.floor == FloorKind::kGlossy ? ", glossy floor" : ""));
}
// {height, msaa samples, glossy}
BENCHMARK(BM_Render3d)
    ->Args({480, 0, 0})
    ->Args({480, 4, 0})
    ->Args({480, 0, 1})
    ->Args({720, 0, 0})
    ->Args({720, 4, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(1.0);

}  // namespace

BENCHMARK_MAIN();
