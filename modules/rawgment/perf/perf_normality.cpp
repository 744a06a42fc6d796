// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Shapiro-Wilk on the paper's calibration set: 24 patches x 24x24 pixels = 13,824 positions per
// illumination, two illuminations, so 27,648 pixel series of a 100-frame burst (n = 100).
//   batch        : shapiroWilkBatch(), coefficients once, parallel
//   single_loop  : a loop over shapiroWilk(), as a user without the batch form would write it
// scripts/bench_shapiro_scipy.py times scipy.stats.shapiro on the same shape and prints the ratio.
#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/rawgment/normality.hpp>

namespace {

const int kSeries = 27648;
const int kLength = 100;

//! Frames in rows, pixel positions in columns: the layout of a burst gathered at patch pixels.
const cv::Mat& calibrationSet()
{
    static const cv::Mat data = [] {
        cv::Mat m(kLength, kSeries, CV_64FC1);
        cv::RNG rng(2023);
        rng.fill(m, cv::RNG::NORMAL, 1000, 30);
        return m;
    }();
    return data;
}

void BM_ShapiroWilk_batch(benchmark::State& state)
{
    const cv::Mat& data = calibrationSet();
    std::vector<cv::rawgment::ShapiroWilkResult> results;
    for (auto _ : state) {
        cv::rawgment::shapiroWilkBatch(data, results, cv::rawgment::SW_SERIES_IN_COLUMNS);
        benchmark::DoNotOptimize(results.data());
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations() * kSeries);
}

void BM_ShapiroWilk_single_loop(benchmark::State& state)
{
    const cv::Mat& data = calibrationSet();
    std::vector<cv::rawgment::ShapiroWilkResult> results(kSeries);
    for (auto _ : state) {
        for (int s = 0; s < kSeries; ++s)
            results[s] = cv::rawgment::shapiroWilk(data.col(s));
        benchmark::DoNotOptimize(results.data());
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations() * kSeries);
}

BENCHMARK(BM_ShapiroWilk_batch)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ShapiroWilk_single_loop)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace

BENCHMARK_MAIN();
