// The LED locator's per-frame kernel (src/video/cell_sums.h) on a 1080p frame: the SSE2
// path against the plain loop, 16 px cells (the detector's default), every cell; and the
// frame's cv::integral (the library's way to cell sums; it gives no peaks) for scale.
// Microseconds per frame.
//
// Run: build/bench/video_kernels_bench
#include <cstdint>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "cell_sums.h"

namespace {

using liftoff::video::internal::CellGrid;

cv::Mat Frame1080p() {
  cv::Mat frame(1080, 1920, CV_8UC3);
  cv::RNG rng(3);
  rng.fill(frame, cv::RNG::UNIFORM, 0, 256);
  return frame;
}

template <typename Kernel>
void RunCells(benchmark::State& state, Kernel kernel) {
  const cv::Mat frame = Frame1080p();
  const CellGrid grid = CellGrid::Make(frame.cols, frame.rows, 16, 1);
  std::vector<float> sums(static_cast<size_t>(grid.cells()));
  std::vector<uint8_t> peaks(sums.size());
  for (auto _ : state) {
    kernel(frame, grid, sums.data(), peaks.data());
    benchmark::DoNotOptimize(sums.data());
    benchmark::DoNotOptimize(peaks.data());
  }
  state.counters["cells"] = grid.cells();
}

#if defined(__SSE2__)
void BM_CellsSse2(benchmark::State& state) {
  RunCells(state, liftoff::video::internal::MeasureCellsSse2);
}
BENCHMARK(BM_CellsSse2)->Name("Cells1080p/sse2")->Unit(benchmark::kMicrosecond);
#endif

void BM_CellsPlain(benchmark::State& state) {
  RunCells(state, liftoff::video::internal::MeasureCellsPlain);
}
BENCHMARK(BM_CellsPlain)->Name("Cells1080p/plain_loop")->Unit(benchmark::kMicrosecond);

void BM_Integral(benchmark::State& state) {
  const cv::Mat frame = Frame1080p();
  cv::Mat integral;
  for (auto _ : state) {
    cv::integral(frame, integral, CV_32S);
    benchmark::DoNotOptimize(integral.data);
  }
}
BENCHMARK(BM_Integral)->Name("Cells1080p/cv_integral_sums_only")->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
