// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "perf_precomp.hpp"

namespace opencv_test {
namespace {

typedef perf::TestBaseWithParam<tuple<Size, MatType>> Augment;

// The augmentation's hot path: a darkening with a gain change, the noise of Eq. 13 on every pixel.
PERF_TEST_P(Augment, colorJitter,
            testing::Combine(testing::Values(Size(1000, 750), Size(4000, 3000)),
                             testing::Values(CV_16UC1, CV_32FC1)))
{
    const Size size = get<0>(GetParam());
    const int type = get<1>(GetParam());
    const Mat src = perfMosaic(size, type);
    const NoiseModel model(0.4, 0.5, 2);
    const ColorJitter jitter = ColorJitter::exposureChange(0.25, 2);
    Mat dst(size, type);
    RawFormat dstFormat;
    declare.in(src).out(dst);

    TEST_CYCLE() colorJitter(src, perfFormat(), model, jitter, NoiseOptions(), 7, dst, dstFormat);

    SANITY_CHECK_NOTHING();
}

typedef perf::TestBaseWithParam<Size> Scenes;

// A whole scene of the paper's training: shift, scale, jitter and a 13-pixel motion blur.
PERF_TEST_P(Scenes, applyScene, testing::Values(Size(1000, 750), Size(4000, 3000)))
{
    const Size size = GetParam();
    const Mat src = perfMosaic(size, CV_16UC1);
    const NoiseModel model(0.4, 0.5, 2);
    Scene scene;
    scene.shift = Point(8, -6);
    scene.scale = 1.02;
    scene.jitter = ColorJitter::exposureChange(0.5, 1.5);
    scene.motionKernel = linearMotionKernel(13, 30);
    Mat dst;
    RawFormat dstFormat;
    declare.in(src);

    TEST_CYCLE() applyScene(src, perfFormat(), model, scene, 7, dst, dstFormat);

    SANITY_CHECK_NOTHING();
}

} // namespace
} // namespace opencv_test
