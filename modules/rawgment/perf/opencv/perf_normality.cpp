// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "perf_precomp.hpp"

namespace opencv_test {
namespace {

typedef perf::TestBaseWithParam<tuple<int, int>> ShapiroWilkBatch;

// Batched Shapiro-Wilk: the per-pixel normality test of a burst (series of n values, one per column).
PERF_TEST_P(ShapiroWilkBatch, shapiroWilkBatch,
            testing::Combine(testing::Values(16, 64), testing::Values(10000, 100000)))
{
    const int n = get<0>(GetParam());
    const int series = get<1>(GetParam());
    Mat samples(n, series, CV_64F);
    RNG rng(5);
    rng.fill(samples, RNG::NORMAL, 100, 3);
    std::vector<ShapiroWilkResult> results;

    TEST_CYCLE() shapiroWilkBatch(samples, results, SW_SERIES_IN_COLUMNS);

    SANITY_CHECK_NOTHING();
}

} // namespace
} // namespace opencv_test
