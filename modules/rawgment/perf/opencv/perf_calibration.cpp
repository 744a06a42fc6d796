// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "perf_precomp.hpp"

namespace opencv_test {
namespace {

typedef perf::TestBaseWithParam<tuple<Size, int>> Burst;

// Burst statistics: every frame of a 16-frame burst added, then the mean and the variance read.
PERF_TEST_P(Burst, BurstStatistics,
            testing::Combine(testing::Values(Size(1000, 750), Size(4000, 3000)),
                             testing::Values(CV_64F, CV_32F)))
{
    const Size size = get<0>(GetParam());
    const int stateDepth = get<1>(GetParam());
    std::vector<Mat> frames;
    for (int i = 0; i < 16; ++i)
        frames.push_back(perfMosaic(size, CV_16UC1) + Scalar::all(i));
    Mat mean, variance;

    TEST_CYCLE()
    {
        BurstStatistics stats(perfFormat(), 8, stateDepth);
        for (const Mat& frame : frames)
            stats.add(frame);
        stats.mean(mean);
        stats.variance(variance);
    }

    SANITY_CHECK_NOTHING();
}

} // namespace
} // namespace opencv_test
