// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "test_common.hpp"

#include <opencv2/rawgment.hpp>

#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

namespace cv {
namespace rawgment {
namespace {

//! Restores the automatic choice when a test ends, whatever it forced.
struct AutoPathAfterwards
{
    ~AutoPathAfterwards() { setCpuPath(CpuPath::AUTO); }
};

TEST(Cpu, pathsAreNamedCheckedAndForced)
{
    const AutoPathAfterwards restore;
    const std::vector<CpuPath> paths = availableCpuPaths();
    ASSERT_FALSE(paths.empty());
    EXPECT_EQ(paths.front(), CpuPath::BASELINE) << "every CPU runs the baseline";
    EXPECT_TRUE(isCpuPathAvailable(CpuPath::AUTO));
    EXPECT_EQ(cpuPathName(CpuPath::SSE42), "sse4.2");
    EXPECT_EQ(cpuPathName(CpuPath::AVX512), "avx512");
    for (CpuPath p : paths) {
        setCpuPath(p);
        EXPECT_EQ(activeCpuPath(), p) << cpuPathName(p);
    }
    setCpuPath(CpuPath::AUTO);
    EXPECT_EQ(activeCpuPath(), paths.back()) << "AUTO takes the best path the CPU runs";
    for (CpuPath p : {CpuPath::SSE42, CpuPath::AVX2, CpuPath::AVX512})
        if (!isCpuPathAvailable(p))
            EXPECT_CV_ERROR_CONTAINS(setCpuPath(p), "this CPU cannot run " + cpuPathName(p));
    EXPECT_CV_ERROR_CONTAINS(setCpuPath(static_cast<CpuPath>(9)), "9 is not a CpuPath");
}

//! The outputs of every dispatched hot loop, through the public functions that run them.
std::vector<Mat> everyDispatchedLoop()
{
    std::vector<Mat> outs;
    const SensorSimulator sensor(test::referenceSensorParams(), Size(134, 98));
    const RawFormat format = sensor.rawFormat(4.0);
    Mat scene(sensor.size(), CV_32F);
    RNG(3).fill(scene, RNG::UNIFORM, 20, 3000);
    Mat src;
    sensor.capture(scene, 4.0, 1.0, 11, 0, src); // the simulator's Gaussian draws
    outs.push_back(src);
    const NoiseModel plain(0.4, 0.5, 2.0);
    // The dark-frame components add a row term and shading to the vector rows, and Tukey draws to the
    // jitter's vector rows and to the scalar rows of blur and scale (NoiseModel); POISSON takes the
    // jitter's split and noise kernels around the vector draws.
    NoiseModel dark = plain;
    dark.rowSigmaD2 = 0.2;
    dark.rowSigmaR2 = 0.4;
    dark.tukeyRead = true;
    dark.tukeyLambda = -0.05;
    dark.darkShadingPerGain.create(sensor.size(), CV_32FC1);
    dark.darkShadingOffset.create(sensor.size(), CV_32FC1);
    RNG(4).fill(dark.darkShadingPerGain, RNG::NORMAL, 0, 1);
    RNG(5).fill(dark.darkShadingOffset, RNG::NORMAL, 0, 2);
    NoiseModel rowsAndShading = dark;
    rowsAndShading.tukeyRead = false;
    Mat srcFloat;
    src.convertTo(srcFloat, CV_32F);
    NoiseOptions poisson;
    poisson.shotSampling = ShotNoiseSampling::POISSON;
    NoiseOptions localMean;
    localMean.priorMean = PriorMeanEstimate::LOCAL_MEAN;
    localMean.blurNoiseSum = BlurNoiseSum::FROM_BLURRED_MEAN;
    for (const NoiseModel& model : {plain, rowsAndShading, dark})
        for (const Mat& input : {src, srcFloat})
            for (NoiseAlignment a :
                 {NoiseAlignment::NONE, NoiseAlignment::IGNORE_PRIOR, NoiseAlignment::ACCOUNT_PRIOR})
                for (const NoiseOptions& base : {NoiseOptions(), poisson, localMean}) {
                    NoiseOptions noise = base;
                    noise.alignment = a;
                    Mat out;
                    RawFormat f;
                    // Brightening and darkening sites, a gain change; without brightness (ACCOUNT_PRIOR's
                    // variance is then a line per site) and with it (a share per pixel).
                    ColorJitter jitter;
                    jitter.contrast = Vec4d(0.3, 1.4, 0.25, 0.5);
                    jitter.gainRatio = 2;
                    for (double brightness : {0.0, -15.0}) {
                        jitter.brightness = brightness;
                        colorJitter(input, format, model, jitter, noise, 5, out, f);
                        outs.push_back(out);
                    }
                    motionBlur(input, format, model, linearMotionKernel(13, 30), noise, 6, out);
                    outs.push_back(out);
                    scaleMosaic(input, format, model, 1.07, noise, 7, out);
                    outs.push_back(out);
                }
    for (int depth : {CV_64F, CV_32F}) {
        BurstStatistics stats(format, 4, depth);
        for (int t = 0; t < 6; ++t) {
            Mat frame;
            sensor.capture(scene, 4.0, 1.0, 12, t, frame);
            stats.add(frame);
        }
        Mat mean, variance;
        stats.mean(mean);
        stats.variance(variance);
        outs.push_back(mean);
        outs.push_back(variance);
    }
    return outs;
}

TEST(Cpu, everyPathGivesTheSameBits)
{
    // The promise of cpu.hpp: the path changes speed only. Odd widths leave a tail after the full vectors.
    const AutoPathAfterwards restore;
    const std::vector<CpuPath> paths = availableCpuPaths();
    setCpuPath(CpuPath::BASELINE);
    const std::vector<Mat> reference = everyDispatchedLoop();
    for (CpuPath p : paths) {
        setCpuPath(p);
        const std::vector<Mat> outs = everyDispatchedLoop();
        ASSERT_EQ(outs.size(), reference.size());
        for (size_t i = 0; i < outs.size(); ++i) {
            ASSERT_EQ(outs[i].type(), reference[i].type());
            EXPECT_EQ(0, std::memcmp(outs[i].data, reference[i].data, outs[i].total() * outs[i].elemSize()))
                << cpuPathName(p) << " differs from the baseline in output " << i;
        }
    }
    if (paths.size() < 4)
        std::cout << "[ NOTE     ] this CPU runs " << paths.size()
                  << " of the 4 paths; the others were not compared\n";
}

} // namespace
} // namespace rawgment
} // namespace cv
