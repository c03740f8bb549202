// The blur planner's CPU time (src/blur/blur_plan.h): plan_auto() runs when a GaussianBlur is made with
// method auto, so it must stay far below a frame (docs/BLUR.md). It is measured here rather than bounded in
// the test suite, where a wall-clock limit fails on a shared, busy machine
// (tests/blur_plan_test.cpp keeps the functional checks of the plans). CPU time, no device.
#include <benchmark/benchmark.h>

#include "blur/blur_plan.h"

namespace glint::bench {
namespace {

// Arg: sigma in tenths of a pixel, at 3840x2160 and the default error bound 1e-2.
void BM_BlurPlanAuto(benchmark::State& state) {
  const double sigma = double(state.range(0)) / 10.0;
  for (auto _ : state) {
    blur_plan::Plan plan = blur_plan::plan_auto(sigma, 3840, 2160, 1e-2);
    benchmark::DoNotOptimize(plan);
  }
}
BENCHMARK(BM_BlurPlanAuto)
    ->Arg(5)
    ->Arg(50)
    ->Arg(240)
    ->Arg(480)
    ->Arg(640)
    ->ArgName("sigma_x10")
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace glint::bench
